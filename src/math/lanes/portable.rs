//! The lane types as arrays and loops: the reference semantics of every lane operation, and
//! the backend on machines without AVX2 or AVX-512 (where it is correct but slower than scalar code).

use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Sub};

use super::{Mask8, Mask16};

/// Sixteen f32 lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct F32x16(pub [f32; 16]);

/// Sixteen u32 lanes (wrapping arithmetic).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(64))]
pub struct U32x16(pub [u32; 16]);

/// Eight f64 lanes (half of a sixteen-lane vector, widened).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct F64x8(pub [f64; 8]);

/// Eight u64 lanes (wrapping arithmetic).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(64))]
pub struct U64x8(pub [u64; 8]);

/// Element-wise binary operators of a lane type.
macro_rules! binary_ops {
    ($ty:ident, $n:expr, $( $tr:ident $method:ident $op:expr ),* $(,)?) => {
        $(
            impl $tr for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $method(self, o: $ty) -> $ty {
                    let f = $op;
                    $ty(std::array::from_fn(|i| f(self.0[i], o.0[i])))
                }
            }
        )*
    };
}

binary_ops!(F32x16, 16,
    Add add |a: f32, b: f32| a + b,
    Sub sub |a: f32, b: f32| a - b,
    Mul mul |a: f32, b: f32| a * b,
    Div div |a: f32, b: f32| a / b,
);
binary_ops!(U32x16, 16,
    Add add |a: u32, b: u32| a.wrapping_add(b),
    Sub sub |a: u32, b: u32| a.wrapping_sub(b),
    Mul mul |a: u32, b: u32| a.wrapping_mul(b),
    BitAnd bitand |a: u32, b: u32| a & b,
    BitOr bitor |a: u32, b: u32| a | b,
    BitXor bitxor |a: u32, b: u32| a ^ b,
);
binary_ops!(F64x8, 8,
    Add add |a: f64, b: f64| a + b,
    Sub sub |a: f64, b: f64| a - b,
    Mul mul |a: f64, b: f64| a * b,
    Div div |a: f64, b: f64| a / b,
);
binary_ops!(U64x8, 8,
    Add add |a: u64, b: u64| a.wrapping_add(b),
    Mul mul |a: u64, b: u64| a.wrapping_mul(b),
    BitAnd bitand |a: u64, b: u64| a & b,
    BitOr bitor |a: u64, b: u64| a | b,
    BitXor bitxor |a: u64, b: u64| a ^ b,
);

impl Neg for F32x16 {
    type Output = F32x16;
    #[inline(always)]
    fn neg(self) -> F32x16 {
        self.map(|a| -a)
    }
}

impl F32x16 {
    #[inline(always)]
    pub fn splat(v: f32) -> F32x16 {
        F32x16([v; 16])
    }

    #[inline(always)]
    pub fn from_array(a: [f32; 16]) -> F32x16 {
        F32x16(a)
    }

    #[inline(always)]
    pub fn to_array(self) -> [f32; 16] {
        self.0
    }

    #[inline(always)]
    fn map(self, f: impl Fn(f32) -> f32) -> F32x16 {
        F32x16(self.0.map(f))
    }

    #[inline(always)]
    fn compare(self, o: F32x16, f: impl Fn(f32, f32) -> bool) -> Mask16 {
        Mask16::from_fn(|i| f(self.0[i], o.0[i]))
    }

    #[inline(always)]
    pub fn sqrt(self) -> F32x16 {
        self.map(f32::sqrt)
    }

    #[inline(always)]
    pub fn abs(self) -> F32x16 {
        self.map(f32::abs)
    }

    /// The magnitude of `self` with the sign of `sign` (`f32::copysign`).
    #[inline(always)]
    pub fn copysign(self, sign: F32x16) -> F32x16 {
        F32x16(std::array::from_fn(|i| self.0[i].copysign(sign.0[i])))
    }

    /// Lane-wise `if self > o { self } else { o }` (o where either is NaN).
    #[inline(always)]
    pub fn max_gt(self, o: F32x16) -> F32x16 {
        F32x16::select(self.gt(o), self, o)
    }

    /// Lane-wise `if self < o { self } else { o }` (o where either is NaN).
    #[inline(always)]
    pub fn min_lt(self, o: F32x16) -> F32x16 {
        F32x16::select(self.lt(o), self, o)
    }

    #[inline(always)]
    pub fn lt(self, o: F32x16) -> Mask16 {
        self.compare(o, |a, b| a < b)
    }

    #[inline(always)]
    pub fn le(self, o: F32x16) -> Mask16 {
        self.compare(o, |a, b| a <= b)
    }

    #[inline(always)]
    pub fn gt(self, o: F32x16) -> Mask16 {
        self.compare(o, |a, b| a > b)
    }

    #[inline(always)]
    pub fn ge(self, o: F32x16) -> Mask16 {
        self.compare(o, |a, b| a >= b)
    }

    #[inline(always)]
    pub fn eq(self, o: F32x16) -> Mask16 {
        self.compare(o, |a, b| a == b)
    }

    /// `!=`: true where either lane is NaN.
    #[inline(always)]
    pub fn ne(self, o: F32x16) -> Mask16 {
        self.compare(o, |a, b| a != b)
    }

    #[inline(always)]
    pub fn is_nan(self) -> Mask16 {
        self.compare(self, |a, _| a.is_nan())
    }

    #[inline(always)]
    pub fn is_finite(self) -> Mask16 {
        self.compare(self, |a, _| a.is_finite())
    }

    /// Lane-wise `if m { a } else { b }`.
    #[inline(always)]
    pub fn select(m: Mask16, a: F32x16, b: F32x16) -> F32x16 {
        F32x16(std::array::from_fn(
            |i| if m.get(i) { a.0[i] } else { b.0[i] },
        ))
    }

    #[inline(always)]
    pub fn to_bits(self) -> U32x16 {
        U32x16(self.0.map(f32::to_bits))
    }

    #[inline(always)]
    pub fn from_bits(b: U32x16) -> F32x16 {
        F32x16(b.0.map(f32::from_bits))
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty.
    #[inline(always)]
    pub fn gather(table: &[f32], idx: U32x16, m: Mask16) -> F32x16 {
        let last = table.len() - 1;
        F32x16(std::array::from_fn(|i| {
            if m.get(i) {
                table[(idx.0[i] as usize).min(last)]
            } else {
                0.0
            }
        }))
    }

    /// Stores the lanes of `m`, in lane order, at the start of `dst`, which must have room
    /// for sixteen: the places after the stored lanes may be overwritten.
    #[inline(always)]
    pub fn compress_store(self, m: Mask16, dst: &mut [f32]) {
        assert!(dst.len() >= 16);
        for (k, i) in m.lanes().enumerate() {
            dst[k] = self.0[i];
        }
    }

    /// Lane i of the result is lane `idx[i] mod 16` of `self`.
    #[inline(always)]
    pub fn permute(self, idx: U32x16) -> F32x16 {
        F32x16(std::array::from_fn(|i| self.0[idx.0[i] as usize % 16]))
    }

    /// Lane i of the result is lane `idx[i] mod 8` of `self` (only lanes 0–7 are read).
    #[inline(always)]
    pub fn permute_low8(self, idx: U32x16) -> F32x16 {
        F32x16(std::array::from_fn(|i| self.0[idx.0[i] as usize % 8]))
    }

    /// Lanes 0–7 and 8–15 widened to f64 (exact).
    #[inline(always)]
    pub fn to_f64_halves(self) -> (F64x8, F64x8) {
        (
            F64x8(std::array::from_fn(|i| self.0[i] as f64)),
            F64x8(std::array::from_fn(|i| self.0[8 + i] as f64)),
        )
    }

    /// Two f64 halves rounded to f32 (`as f32`: to nearest, ties to even).
    #[inline(always)]
    pub fn from_f64_halves(lo: F64x8, hi: F64x8) -> F32x16 {
        F32x16(std::array::from_fn(|i| {
            if i < 8 {
                lo.0[i] as f32
            } else {
                hi.0[i - 8] as f32
            }
        }))
    }

    /// Each lane `as u32`: towards zero, NaN and negatives to 0, saturating at u32::MAX.
    #[inline(always)]
    pub fn to_u32(self) -> U32x16 {
        U32x16(self.0.map(|v| v as u32))
    }
}

impl U32x16 {
    #[inline(always)]
    pub fn splat(v: u32) -> U32x16 {
        U32x16([v; 16])
    }

    #[inline(always)]
    pub fn from_array(a: [u32; 16]) -> U32x16 {
        U32x16(a)
    }

    #[inline(always)]
    pub fn to_array(self) -> [u32; 16] {
        self.0
    }

    #[inline(always)]
    pub fn shl<const N: u32>(self) -> U32x16 {
        U32x16(self.0.map(|a| a << N))
    }

    #[inline(always)]
    pub fn shr<const N: u32>(self) -> U32x16 {
        U32x16(self.0.map(|a| a >> N))
    }

    /// Stores the lanes of `m`, in lane order, at the start of `dst`, which must have room
    /// for sixteen: the places after the stored lanes may be overwritten.
    #[inline(always)]
    pub fn compress_store(self, m: Mask16, dst: &mut [u32]) {
        assert!(dst.len() >= 16);
        for (k, i) in m.lanes().enumerate() {
            dst[k] = self.0[i];
        }
    }

    /// Unsigned minimum.
    #[inline(always)]
    pub fn min(self, o: U32x16) -> U32x16 {
        U32x16(std::array::from_fn(|i| self.0[i].min(o.0[i])))
    }

    /// Unsigned maximum.
    #[inline(always)]
    pub fn max(self, o: U32x16) -> U32x16 {
        U32x16(std::array::from_fn(|i| self.0[i].max(o.0[i])))
    }

    #[inline(always)]
    pub fn eq(self, o: U32x16) -> Mask16 {
        Mask16::from_fn(|i| self.0[i] == o.0[i])
    }

    /// Unsigned `<`.
    #[inline(always)]
    pub fn lt(self, o: U32x16) -> Mask16 {
        Mask16::from_fn(|i| self.0[i] < o.0[i])
    }

    #[inline(always)]
    pub fn select(m: Mask16, a: U32x16, b: U32x16) -> U32x16 {
        U32x16(std::array::from_fn(
            |i| if m.get(i) { a.0[i] } else { b.0[i] },
        ))
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty.
    #[inline(always)]
    pub fn gather(table: &[u32], idx: U32x16, m: Mask16) -> U32x16 {
        let last = table.len() - 1;
        U32x16(std::array::from_fn(|i| {
            if m.get(i) {
                table[(idx.0[i] as usize).min(last)]
            } else {
                0
            }
        }))
    }

    /// Each lane as f32 (`as f32`).
    #[inline(always)]
    pub fn to_f32(self) -> F32x16 {
        F32x16(self.0.map(|a| a as f32))
    }

    /// Lanes 0–7 and 8–15 widened to u64.
    #[inline(always)]
    pub fn to_u64_halves(self) -> (U64x8, U64x8) {
        (
            U64x8(std::array::from_fn(|i| self.0[i] as u64)),
            U64x8(std::array::from_fn(|i| self.0[8 + i] as u64)),
        )
    }

    /// The low 32 bits of each u64 lane of `lo` (lanes 0–7) and `hi` (lanes 8–15).
    #[inline(always)]
    pub fn from_u64_halves(lo: U64x8, hi: U64x8) -> U32x16 {
        U32x16(std::array::from_fn(|i| {
            if i < 8 {
                lo.0[i] as u32
            } else {
                hi.0[i - 8] as u32
            }
        }))
    }
}

impl F64x8 {
    #[inline(always)]
    pub fn splat(v: f64) -> F64x8 {
        F64x8([v; 8])
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty.
    #[inline(always)]
    pub fn gather(table: &[f64], idx: U64x8, m: Mask8) -> F64x8 {
        let last = table.len() - 1;
        F64x8(std::array::from_fn(|i| {
            if m.get(i) {
                table[(idx.0[i].min(last as u64)) as usize]
            } else {
                0.0
            }
        }))
    }

    #[inline(always)]
    pub fn from_array(a: [f64; 8]) -> F64x8 {
        F64x8(a)
    }

    #[inline(always)]
    pub fn to_array(self) -> [f64; 8] {
        self.0
    }

    #[inline(always)]
    pub fn lt(self, o: F64x8) -> Mask8 {
        Mask8::from_fn(|i| self.0[i] < o.0[i])
    }

    #[inline(always)]
    pub fn le(self, o: F64x8) -> Mask8 {
        Mask8::from_fn(|i| self.0[i] <= o.0[i])
    }

    #[inline(always)]
    pub fn gt(self, o: F64x8) -> Mask8 {
        Mask8::from_fn(|i| self.0[i] > o.0[i])
    }

    #[inline(always)]
    pub fn eq(self, o: F64x8) -> Mask8 {
        Mask8::from_fn(|i| self.0[i] == o.0[i])
    }

    #[inline(always)]
    pub fn select(m: Mask8, a: F64x8, b: F64x8) -> F64x8 {
        F64x8(std::array::from_fn(
            |i| if m.get(i) { a.0[i] } else { b.0[i] },
        ))
    }

    #[inline(always)]
    pub fn sqrt(self) -> F64x8 {
        F64x8(self.0.map(f64::sqrt))
    }

    /// The magnitude of `self` with the sign of `sign` (`f64::copysign`).
    #[inline(always)]
    pub fn copysign(self, sign: F64x8) -> F64x8 {
        F64x8(std::array::from_fn(|i| self.0[i].copysign(sign.0[i])))
    }
}

impl Neg for F64x8 {
    type Output = F64x8;
    #[inline(always)]
    fn neg(self) -> F64x8 {
        F64x8(self.0.map(|a| -a))
    }
}

impl U64x8 {
    #[inline(always)]
    pub fn splat(v: u64) -> U64x8 {
        U64x8([v; 8])
    }

    #[inline(always)]
    pub fn from_array(a: [u64; 8]) -> U64x8 {
        U64x8(a)
    }

    #[inline(always)]
    pub fn to_array(self) -> [u64; 8] {
        self.0
    }

    #[inline(always)]
    pub fn shl<const N: u32>(self) -> U64x8 {
        U64x8(self.0.map(|a| a << N))
    }

    #[inline(always)]
    pub fn shr<const N: u32>(self) -> U64x8 {
        U64x8(self.0.map(|a| a >> N))
    }

    #[inline(always)]
    pub fn rotl<const N: i32>(self) -> U64x8 {
        U64x8(self.0.map(|a| a.rotate_left(N as u32)))
    }

    #[inline(always)]
    pub fn select(m: Mask8, a: U64x8, b: U64x8) -> U64x8 {
        U64x8(std::array::from_fn(
            |i| if m.get(i) { a.0[i] } else { b.0[i] },
        ))
    }
}
