//! `V3<T>`: a 3-vector over `Real`, with glam's `Vec3` arithmetic operation for operation
//! (the same products and sums in the same order), so `V3<F32x16>` lanes and `Vec3`
//! results agree bit for bit.

use std::ops::{Add, Mul, Neg, Sub};

use glam::Vec3;

use super::Real;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3<T> {
    pub x: T,
    pub y: T,
    pub z: T,
}

impl<T: Real> V3<T> {
    #[inline(always)]
    pub fn new(x: T, y: T, z: T) -> V3<T> {
        V3 { x, y, z }
    }

    #[inline(always)]
    pub fn splat(v: f32) -> V3<T> {
        let s = T::splat(v);
        V3 { x: s, y: s, z: s }
    }

    /// (x·x' + y·y') + z·z', as `Vec3::dot`.
    #[inline(always)]
    pub fn dot(self, o: V3<T>) -> T {
        (self.x * o.x) + (self.y * o.y) + (self.z * o.z)
    }

    /// As `Vec3::cross`.
    #[inline(always)]
    pub fn cross(self, o: V3<T>) -> V3<T> {
        V3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    #[inline(always)]
    pub fn length_squared(self) -> T {
        self.dot(self)
    }

    #[inline(always)]
    pub fn length(self) -> T {
        self.dot(self).sqrt()
    }

    /// `self · (1 / |self|)`, as `Vec3::normalize`.
    #[inline(always)]
    pub fn normalize(self) -> V3<T> {
        self * (T::splat(1.0) / self.length())
    }

    #[inline(always)]
    pub fn abs(self) -> V3<T> {
        V3 {
            x: self.x.abs(),
            y: self.y.abs(),
            z: self.z.abs(),
        }
    }

    /// Each component divided by `s` (as `Vec3 / f32`: a division, not a reciprocal).
    #[inline(always)]
    pub fn div_scalar(self, s: T) -> V3<T> {
        V3 {
            x: self.x / s,
            y: self.y / s,
            z: self.z / s,
        }
    }

    /// Component-wise product.
    #[inline(always)]
    pub fn mul_v(self, o: V3<T>) -> V3<T> {
        V3 {
            x: self.x * o.x,
            y: self.y * o.y,
            z: self.z * o.z,
        }
    }

    /// `if m { a } else { b }` per lane.
    #[inline(always)]
    pub fn select(m: T::Mask, a: V3<T>, b: V3<T>) -> V3<T> {
        V3 {
            x: T::select(m, a.x, b.x),
            y: T::select(m, a.y, b.y),
            z: T::select(m, a.z, b.z),
        }
    }

    /// All three components finite.
    #[inline(always)]
    pub fn is_finite(self) -> T::Mask {
        self.x.is_finite() & self.y.is_finite() & self.z.is_finite()
    }
}

impl<T: Real> Add for V3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn add(self, o: V3<T>) -> V3<T> {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<T: Real> Sub for V3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn sub(self, o: V3<T>) -> V3<T> {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<T: Real> Mul<T> for V3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn mul(self, s: T) -> V3<T> {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl<T: Real> Neg for V3<T> {
    type Output = V3<T>;
    #[inline(always)]
    fn neg(self) -> V3<T> {
        V3::new(-self.x, -self.y, -self.z)
    }
}

impl From<Vec3> for V3<f32> {
    #[inline(always)]
    fn from(v: Vec3) -> V3<f32> {
        V3::new(v.x, v.y, v.z)
    }
}

impl From<V3<f32>> for Vec3 {
    #[inline(always)]
    fn from(v: V3<f32>) -> Vec3 {
        Vec3::new(v.x, v.y, v.z)
    }
}
