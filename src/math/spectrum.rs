//! Colour: mltbench renders in linear sRGB, three channels, like Mitsuba 3's `*_rgb` variants.

use std::ops::{Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Sub};

/// A linear-sRGB triple: radiance, reflectance or throughput.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rgb(pub [f32; 3]);

impl Rgb {
    pub const BLACK: Rgb = Rgb([0.0; 3]);
    pub const WHITE: Rgb = Rgb([1.0; 3]);

    pub const fn new(r: f32, g: f32, b: f32) -> Self {
        Rgb([r, g, b])
    }

    pub const fn splat(v: f32) -> Self {
        Rgb([v; 3])
    }

    pub fn r(&self) -> f32 {
        self.0[0]
    }
    pub fn g(&self) -> f32 {
        self.0[1]
    }
    pub fn b(&self) -> f32 {
        self.0[2]
    }

    pub fn is_black(&self) -> bool {
        self.0.iter().all(|&c| c == 0.0)
    }

    /// True when every channel is finite and non-negative: what a radiance sample must be.
    pub fn is_valid_radiance(&self) -> bool {
        self.0.iter().all(|&c| c.is_finite() && c >= 0.0)
    }

    pub fn max_component(&self) -> f32 {
        self.0[0].max(self.0[1]).max(self.0[2])
    }

    pub fn mean(&self) -> f32 {
        (self.0[0] + self.0[1] + self.0[2]) / 3.0
    }

    /// Relative luminance of linear sRGB (ITU-R BT.709 primaries).
    pub fn luminance(&self) -> f32 {
        0.2126 * self.0[0] + 0.7152 * self.0[1] + 0.0722 * self.0[2]
    }

    pub fn map(self, f: impl Fn(f32) -> f32) -> Rgb {
        Rgb([f(self.0[0]), f(self.0[1]), f(self.0[2])])
    }
}

impl Index<usize> for Rgb {
    type Output = f32;
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}

impl IndexMut<usize> for Rgb {
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i]
    }
}

macro_rules! channelwise {
    ($trait:ident, $method:ident, $op:tt, $assign_trait:ident, $assign_method:ident) => {
        impl $trait for Rgb {
            type Output = Rgb;
            fn $method(self, o: Rgb) -> Rgb {
                Rgb([self.0[0] $op o.0[0], self.0[1] $op o.0[1], self.0[2] $op o.0[2]])
            }
        }
        impl $trait<f32> for Rgb {
            type Output = Rgb;
            fn $method(self, s: f32) -> Rgb {
                Rgb([self.0[0] $op s, self.0[1] $op s, self.0[2] $op s])
            }
        }
        impl $assign_trait for Rgb {
            fn $assign_method(&mut self, o: Rgb) {
                *self = *self $op o;
            }
        }
        impl $assign_trait<f32> for Rgb {
            fn $assign_method(&mut self, s: f32) {
                *self = *self $op s;
            }
        }
    };
}

channelwise!(Add, add, +, AddAssign, add_assign);
channelwise!(Mul, mul, *, MulAssign, mul_assign);
channelwise!(Div, div, /, DivAssign, div_assign);

impl Sub for Rgb {
    type Output = Rgb;
    fn sub(self, o: Rgb) -> Rgb {
        Rgb([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
}

impl Mul<Rgb> for f32 {
    type Output = Rgb;
    fn mul(self, c: Rgb) -> Rgb {
        c * self
    }
}
