//! An orthonormal frame (s, t, n): BSDFs work in the local frame where n = +z.

use glam::Vec3;

use crate::math::lanes::{Real, V3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// A frame around a unit normal, built without branches on the normal's direction
    /// (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
    #[inline]
    pub fn from_normal(n: Vec3) -> Self {
        let f = LaneFrame::from_normal(V3::from(n));
        Frame {
            s: f.s.into(),
            t: f.t.into(),
            n,
        }
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

/// `Frame` over `Real`: one frame, or sixteen in lanes, with the same arithmetic.
#[derive(Clone, Copy, Debug)]
pub struct LaneFrame<T> {
    pub s: V3<T>,
    pub t: V3<T>,
    pub n: V3<T>,
}

impl<T: Real> LaneFrame<T> {
    /// As `Frame::from_normal` (Duff et al. 2017).
    #[inline(always)]
    pub fn from_normal(n: V3<T>) -> Self {
        let one = T::splat(1.0);
        let sign = one.copysign(n.z);
        let a = T::splat(-1.0) / (sign + n.z);
        let b = n.x * n.y * a;
        let s = V3::new(one + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = V3::new(b, sign + n.y * n.y * a, -n.y);
        LaneFrame { s, t, n }
    }

    #[inline(always)]
    pub fn to_local(&self, v: V3<T>) -> V3<T> {
        V3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline(always)]
    pub fn to_world(&self, v: V3<T>) -> V3<T> {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_invert() {
        let normals = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::new(1e-7, 0.0, -1.0).normalize(),
        ];
        for n in normals {
            let f = Frame::from_normal(n);
            assert!((f.s.length() - 1.0).abs() < 1e-5);
            assert!((f.t.length() - 1.0).abs() < 1e-5);
            assert!(
                f.s.dot(f.t).abs() < 1e-5 && f.s.dot(n).abs() < 1e-5 && f.t.dot(n).abs() < 1e-5
            );
            // right-handed: s × t = n
            assert!((f.s.cross(f.t) - n).length() < 1e-5);
            let v = Vec3::new(0.2, 0.7, -0.1);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }
}
