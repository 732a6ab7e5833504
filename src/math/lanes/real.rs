//! `Real`: what a formula needs to run on one `f32` or on sixteen lanes with the same bits.
//!
//! Branches become selects: a formula written against `Real` computes both sides and picks
//! per lane with `select`, which on `f32` is an ordinary `if`.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use super::{Mask16, portable};

/// A boolean per lane: `bool` for `f32`, `Mask16` for sixteen lanes.
pub trait LaneMask:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
}

impl LaneMask for bool {}
impl LaneMask for Mask16 {}

/// IEEE single-precision arithmetic on one value or on lanes.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: LaneMask;

    fn splat(v: f32) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// The magnitude of `self` with the sign of `sign`.
    fn copysign(self, sign: Self) -> Self;
    fn lt(self, o: Self) -> Self::Mask;
    fn le(self, o: Self) -> Self::Mask;
    fn gt(self, o: Self) -> Self::Mask;
    fn ge(self, o: Self) -> Self::Mask;
    fn eq(self, o: Self) -> Self::Mask;
    /// `!=` (true where either is NaN).
    fn ne(self, o: Self) -> Self::Mask;
    fn is_finite(self) -> Self::Mask;
    /// `if m { a } else { b }`.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// `if self > o { self } else { o }`.
    fn max_gt(self, o: Self) -> Self;
    /// `if self < o { self } else { o }`.
    fn min_lt(self, o: Self) -> Self;
    /// One float from `self` towards the sign of `dir` (the next float up for dir > 0,
    /// down for dir < 0); `self` unchanged where `dir` is ±0 or `self` is not finite. −0
    /// counts as +0, so both step to the same neighbour.
    fn step_towards(self, dir: Self) -> Self;
}

impl Real for f32 {
    type Mask = bool;

    #[inline(always)]
    fn splat(v: f32) -> f32 {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> f32 {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f32 {
        f32::abs(self)
    }
    #[inline(always)]
    fn copysign(self, sign: f32) -> f32 {
        f32::copysign(self, sign)
    }
    #[inline(always)]
    fn lt(self, o: f32) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: f32) -> bool {
        self <= o
    }
    #[inline(always)]
    fn gt(self, o: f32) -> bool {
        self > o
    }
    #[inline(always)]
    fn ge(self, o: f32) -> bool {
        self >= o
    }
    #[inline(always)]
    fn eq(self, o: f32) -> bool {
        self == o
    }
    #[inline(always)]
    fn ne(self, o: f32) -> bool {
        self != o
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
    #[inline(always)]
    fn select(m: bool, a: f32, b: f32) -> f32 {
        if m { a } else { b }
    }
    #[inline(always)]
    fn max_gt(self, o: f32) -> f32 {
        if self > o { self } else { o }
    }
    #[inline(always)]
    fn min_lt(self, o: f32) -> f32 {
        if self < o { self } else { o }
    }
    #[inline(always)]
    fn step_towards(self, dir: f32) -> f32 {
        // next_float_down(v) = −next_float_up(−v): step |v| up or down in the direction of
        // dir with the sign folded in. u = v·sign(dir) (as bits, no rounding); −0 counts as
        // +0. Branch-free: offset directions are random.
        let flip = if dir < 0.0 { 0x8000_0000u32 } else { 0 };
        let u = f32::from_bits(self.to_bits() ^ flip);
        let u = if u == 0.0 { 0.0 } else { u };
        let bits = u.to_bits();
        let up = if u >= 0.0 {
            bits.wrapping_add(1)
        } else {
            bits.wrapping_sub(1)
        };
        let stepped = f32::from_bits(up ^ flip);
        if dir == 0.0 || !self.is_finite() {
            self
        } else {
            stepped
        }
    }
}

/// `Real` for a sixteen-lane type with the inherent methods of the lane backends.
macro_rules! real_lanes {
    ($ty:ty, $u:ty) => {
        impl Real for $ty {
            type Mask = Mask16;

            #[inline(always)]
            fn splat(v: f32) -> Self {
                <$ty>::splat(v)
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$ty>::sqrt(self)
            }
            #[inline(always)]
            fn abs(self) -> Self {
                <$ty>::abs(self)
            }
            #[inline(always)]
            fn copysign(self, sign: Self) -> Self {
                <$ty>::copysign(self, sign)
            }
            #[inline(always)]
            fn lt(self, o: Self) -> Mask16 {
                <$ty>::lt(self, o)
            }
            #[inline(always)]
            fn le(self, o: Self) -> Mask16 {
                <$ty>::le(self, o)
            }
            #[inline(always)]
            fn gt(self, o: Self) -> Mask16 {
                <$ty>::gt(self, o)
            }
            #[inline(always)]
            fn ge(self, o: Self) -> Mask16 {
                <$ty>::ge(self, o)
            }
            #[inline(always)]
            fn eq(self, o: Self) -> Mask16 {
                <$ty>::eq(self, o)
            }
            #[inline(always)]
            fn ne(self, o: Self) -> Mask16 {
                <$ty>::ne(self, o)
            }
            #[inline(always)]
            fn is_finite(self) -> Mask16 {
                <$ty>::is_finite(self)
            }
            #[inline(always)]
            fn select(m: Mask16, a: Self, b: Self) -> Self {
                <$ty>::select(m, a, b)
            }
            #[inline(always)]
            fn max_gt(self, o: Self) -> Self {
                <$ty>::max_gt(self, o)
            }
            #[inline(always)]
            fn min_lt(self, o: Self) -> Self {
                <$ty>::min_lt(self, o)
            }
            #[inline(always)]
            fn step_towards(self, dir: Self) -> Self {
                // `f32::step_towards`, lane by lane in integer arithmetic.
                let zero = <$ty>::splat(0.0);
                let flip = <$u>::select(dir.lt(zero), <$u>::splat(0x8000_0000), <$u>::splat(0));
                let u = <$ty>::from_bits(self.to_bits() ^ flip);
                let u = <$ty>::select(u.eq(zero), zero, u);
                let bits = u.to_bits();
                let one = <$u>::splat(1);
                let up = <$u>::select(u.ge(zero), bits + one, bits - one);
                let stepped = <$ty>::from_bits(up ^ flip);
                <$ty>::select(dir.eq(zero) | !self.is_finite(), self, stepped)
            }
        }
    };
}

real_lanes!(portable::F32x16, portable::U32x16);
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
real_lanes!(super::avx512::F32x16, super::avx512::U32x16);
#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    not(target_feature = "avx512f")
))]
real_lanes!(super::avx2::F32x16, super::avx2::U32x16);
