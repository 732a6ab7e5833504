//! The lane types in AVX2 registers, for machines without AVX-512: each sixteen-lane
//! vector is two 8-lane registers (each eight-lane f64 or u64 vector two 4-lane ones), with
//! the operations of `portable`, lane for lane and bit for bit.
//!
//! AVX2 has no mask registers, so masks stay bit sets (`Mask16`, as everywhere): a
//! comparison gathers its lanes' sign bits (`movemask`), a select spreads the bits back into
//! a vector mask first. Operations AVX2 lacks are composed of exact steps: unsigned
//! conversions, unsigned 64-bit minima, rotations; `compress_store` goes lane by lane.
//!
//! SAFETY (every `unsafe` block in this file): the module is compiled only when AVX2 is
//! enabled for the whole build (`cfg` in `lanes/mod.rs`), so each intrinsic is available;
//! loads and stores go through arrays of exactly one vector's size, and gathers read only
//! lanes of their mask, at indices clamped into their slice.

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Sub};

use super::{Mask8, Mask16};

/// Sixteen f32 lanes: lanes 0–7 in `lo`, 8–15 in `hi`.
#[derive(Clone, Copy)]
pub struct F32x16 {
    lo: __m256,
    hi: __m256,
}

/// Sixteen u32 lanes (wrapping arithmetic).
#[derive(Clone, Copy)]
pub struct U32x16 {
    lo: __m256i,
    hi: __m256i,
}

/// Eight f64 lanes (half of a sixteen-lane vector, widened): lanes 0–3 in `lo`.
#[derive(Clone, Copy)]
pub struct F64x8 {
    lo: __m256d,
    hi: __m256d,
}

/// Eight u64 lanes (wrapping arithmetic).
#[derive(Clone, Copy)]
pub struct U64x8 {
    lo: __m256i,
    hi: __m256i,
}

/// Binary operators that are one intrinsic per half.
macro_rules! binary_ops {
    ($ty:ident, $( $tr:ident $method:ident $intrinsic:ident ),* $(,)?) => {
        $(
            impl $tr for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $method(self, o: $ty) -> $ty {
                    unsafe { $ty { lo: $intrinsic(self.lo, o.lo), hi: $intrinsic(self.hi, o.hi) } }
                }
            }
        )*
    };
}

binary_ops!(F32x16,
    Add add _mm256_add_ps,
    Sub sub _mm256_sub_ps,
    Mul mul _mm256_mul_ps,
    Div div _mm256_div_ps,
);
binary_ops!(U32x16,
    Add add _mm256_add_epi32,
    Sub sub _mm256_sub_epi32,
    Mul mul _mm256_mullo_epi32,
    BitAnd bitand _mm256_and_si256,
    BitOr bitor _mm256_or_si256,
    BitXor bitxor _mm256_xor_si256,
);
binary_ops!(F64x8,
    Add add _mm256_add_pd,
    Sub sub _mm256_sub_pd,
    Mul mul _mm256_mul_pd,
    Div div _mm256_div_pd,
);
binary_ops!(U64x8,
    Add add _mm256_add_epi64,
    BitAnd bitand _mm256_and_si256,
    BitOr bitor _mm256_or_si256,
    BitXor bitxor _mm256_xor_si256,
);

/// Wrapping 64-bit products from 32-bit ones: a·b mod 2⁶⁴ = lo(a)·lo(b) +
/// ((lo(a)·hi(b) + hi(a)·lo(b)) << 32).
#[inline(always)]
fn mul_u64(a: __m256i, b: __m256i) -> __m256i {
    unsafe {
        let lo = _mm256_mul_epu32(a, b);
        let cross = _mm256_add_epi64(
            _mm256_mul_epu32(a, _mm256_srli_epi64::<32>(b)),
            _mm256_mul_epu32(_mm256_srli_epi64::<32>(a), b),
        );
        _mm256_add_epi64(lo, _mm256_slli_epi64::<32>(cross))
    }
}

impl Mul for U64x8 {
    type Output = U64x8;
    #[inline(always)]
    fn mul(self, o: U64x8) -> U64x8 {
        U64x8 {
            lo: mul_u64(self.lo, o.lo),
            hi: mul_u64(self.hi, o.hi),
        }
    }
}

/// The vector mask of eight 32-bit lanes: lane i all ones where bit i of `bits` is set.
#[inline(always)]
fn lanes32(bits: u32) -> __m256i {
    unsafe {
        let select = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        _mm256_cmpeq_epi32(
            _mm256_and_si256(_mm256_set1_epi32(bits as i32), select),
            select,
        )
    }
}

/// The vector mask of four 64-bit lanes: lane i all ones where bit i of `bits` is set.
#[inline(always)]
fn lanes64(bits: u8) -> __m256i {
    unsafe {
        let select = _mm256_setr_epi64x(1, 2, 4, 8);
        _mm256_cmpeq_epi64(
            _mm256_and_si256(_mm256_set1_epi64x(bits as i64), select),
            select,
        )
    }
}

/// The two halves' vector masks of a sixteen-lane mask.
#[inline(always)]
fn halves32(m: Mask16) -> (__m256i, __m256i) {
    (lanes32(m.0 as u32 & 0xff), lanes32(m.0 as u32 >> 8))
}

/// The two halves' vector masks of an eight-lane mask.
#[inline(always)]
fn halves64(m: Mask8) -> (__m256i, __m256i) {
    (lanes64(m.0 & 0xf), lanes64(m.0 >> 4))
}

/// A sixteen-lane mask from two halves' comparison results (all ones or zero per lane).
#[inline(always)]
fn mask16(lo: __m256, hi: __m256) -> Mask16 {
    unsafe { Mask16((_mm256_movemask_ps(lo) as u32 | (_mm256_movemask_ps(hi) as u32) << 8) as u16) }
}

/// An eight-lane mask from two halves' comparison results.
#[inline(always)]
fn mask8(lo: __m256d, hi: __m256d) -> Mask8 {
    unsafe { Mask8((_mm256_movemask_pd(lo) as u32 | (_mm256_movemask_pd(hi) as u32) << 4) as u8) }
}

/// Unsigned 64-bit `min(a, b)` (AVX2 compares 64-bit lanes signed only).
#[inline(always)]
fn min_u64(a: __m256i, b: __m256i) -> __m256i {
    unsafe {
        let sign = _mm256_set1_epi64x(i64::MIN);
        let a_greater = _mm256_cmpgt_epi64(_mm256_xor_si256(a, sign), _mm256_xor_si256(b, sign));
        _mm256_blendv_epi8(a, b, a_greater)
    }
}

/// Eight u64 lanes' low 32 bits, in the low 128 bits.
#[inline(always)]
fn low_words(v: __m256i) -> __m128i {
    unsafe {
        let even = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
        _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(v, even))
    }
}

const SIGN: u32 = 0x8000_0000;

/// For each 8-bit mask, the lanes it selects in order (then zeros): the permutation that packs
/// those lanes at the front of a half (`compress_store`).
static COMPRESS: [[u32; 8]; 256] = {
    let mut table = [[0u32; 8]; 256];
    let mut bits = 0;
    while bits < 256 {
        let (mut lane, mut k) = (0, 0);
        while lane < 8 {
            if bits & (1 << lane) != 0 {
                table[bits][k] = lane as u32;
                k += 1;
            }
            lane += 1;
        }
        bits += 1;
    }
    table
};

/// `COMPRESS[bits]` in a register.
#[inline(always)]
fn compress_index(bits: u8) -> __m256i {
    unsafe { _mm256_loadu_si256(COMPRESS[bits as usize].as_ptr() as *const __m256i) }
}

impl Neg for F32x16 {
    type Output = F32x16;
    #[inline(always)]
    fn neg(self) -> F32x16 {
        F32x16::from_bits(self.to_bits() ^ U32x16::splat(SIGN))
    }
}

/// One f32 comparison of both halves (predicate as `_mm256_cmp_ps`'s).
macro_rules! compare_ps {
    ($a:expr, $b:expr, $pred:ident) => {
        unsafe {
            mask16(
                _mm256_cmp_ps::<$pred>($a.lo, $b.lo),
                _mm256_cmp_ps::<$pred>($a.hi, $b.hi),
            )
        }
    };
}

/// One f64 comparison of both halves.
macro_rules! compare_pd {
    ($a:expr, $b:expr, $pred:ident) => {
        unsafe {
            mask8(
                _mm256_cmp_pd::<$pred>($a.lo, $b.lo),
                _mm256_cmp_pd::<$pred>($a.hi, $b.hi),
            )
        }
    };
}

impl F32x16 {
    #[inline(always)]
    fn both(lo: __m256, hi: __m256) -> F32x16 {
        F32x16 { lo, hi }
    }

    #[inline(always)]
    pub fn splat(v: f32) -> F32x16 {
        unsafe { F32x16::both(_mm256_set1_ps(v), _mm256_set1_ps(v)) }
    }

    #[inline(always)]
    pub fn from_array(a: [f32; 16]) -> F32x16 {
        unsafe {
            F32x16::both(
                _mm256_loadu_ps(a.as_ptr()),
                _mm256_loadu_ps(a.as_ptr().add(8)),
            )
        }
    }

    #[inline(always)]
    pub fn to_array(self) -> [f32; 16] {
        let mut a = [0.0f32; 16];
        unsafe {
            _mm256_storeu_ps(a.as_mut_ptr(), self.lo);
            _mm256_storeu_ps(a.as_mut_ptr().add(8), self.hi);
        }
        a
    }

    #[inline(always)]
    pub fn sqrt(self) -> F32x16 {
        unsafe { F32x16::both(_mm256_sqrt_ps(self.lo), _mm256_sqrt_ps(self.hi)) }
    }

    #[inline(always)]
    pub fn abs(self) -> F32x16 {
        F32x16::from_bits(self.to_bits() & U32x16::splat(!SIGN))
    }

    /// The magnitude of `self` with the sign of `sign` (`f32::copysign`).
    #[inline(always)]
    pub fn copysign(self, sign: F32x16) -> F32x16 {
        let s = U32x16::splat(SIGN);
        F32x16::from_bits((self.to_bits() & U32x16::splat(!SIGN)) | (sign.to_bits() & s))
    }

    /// Lane-wise `if self > o { self } else { o }` (o where either is NaN): `vmaxps`.
    #[inline(always)]
    pub fn max_gt(self, o: F32x16) -> F32x16 {
        unsafe { F32x16::both(_mm256_max_ps(self.lo, o.lo), _mm256_max_ps(self.hi, o.hi)) }
    }

    /// Lane-wise `if self < o { self } else { o }` (o where either is NaN): `vminps`.
    #[inline(always)]
    pub fn min_lt(self, o: F32x16) -> F32x16 {
        unsafe { F32x16::both(_mm256_min_ps(self.lo, o.lo), _mm256_min_ps(self.hi, o.hi)) }
    }

    #[inline(always)]
    pub fn lt(self, o: F32x16) -> Mask16 {
        compare_ps!(self, o, _CMP_LT_OQ)
    }

    #[inline(always)]
    pub fn le(self, o: F32x16) -> Mask16 {
        compare_ps!(self, o, _CMP_LE_OQ)
    }

    #[inline(always)]
    pub fn gt(self, o: F32x16) -> Mask16 {
        compare_ps!(self, o, _CMP_GT_OQ)
    }

    #[inline(always)]
    pub fn ge(self, o: F32x16) -> Mask16 {
        compare_ps!(self, o, _CMP_GE_OQ)
    }

    #[inline(always)]
    pub fn eq(self, o: F32x16) -> Mask16 {
        compare_ps!(self, o, _CMP_EQ_OQ)
    }

    /// `!=`: true where either lane is NaN.
    #[inline(always)]
    pub fn ne(self, o: F32x16) -> Mask16 {
        compare_ps!(self, o, _CMP_NEQ_UQ)
    }

    #[inline(always)]
    pub fn is_nan(self) -> Mask16 {
        compare_ps!(self, self, _CMP_UNORD_Q)
    }

    #[inline(always)]
    pub fn is_finite(self) -> Mask16 {
        self.abs().lt(F32x16::splat(f32::INFINITY))
    }

    /// Lane-wise `if m { a } else { b }`.
    #[inline(always)]
    pub fn select(m: Mask16, a: F32x16, b: F32x16) -> F32x16 {
        let (lo, hi) = halves32(m);
        unsafe {
            F32x16::both(
                _mm256_blendv_ps(b.lo, a.lo, _mm256_castsi256_ps(lo)),
                _mm256_blendv_ps(b.hi, a.hi, _mm256_castsi256_ps(hi)),
            )
        }
    }

    #[inline(always)]
    pub fn to_bits(self) -> U32x16 {
        unsafe {
            U32x16 {
                lo: _mm256_castps_si256(self.lo),
                hi: _mm256_castps_si256(self.hi),
            }
        }
    }

    #[inline(always)]
    pub fn from_bits(b: U32x16) -> F32x16 {
        unsafe { F32x16::both(_mm256_castsi256_ps(b.lo), _mm256_castsi256_ps(b.hi)) }
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty.
    #[inline(always)]
    pub fn gather(table: &[f32], idx: U32x16, m: Mask16) -> F32x16 {
        let last = table.len() - 1;
        let idx = idx.min(U32x16::splat(last.min(u32::MAX as usize) as u32));
        let (lo, hi) = halves32(m);
        let p = table.as_ptr();
        unsafe {
            let zero = _mm256_setzero_ps();
            let gather = |i, m| _mm256_mask_i32gather_ps::<4>(zero, p, i, _mm256_castsi256_ps(m));
            F32x16::both(gather(idx.lo, lo), gather(idx.hi, hi))
        }
    }

    /// Stores the lanes of `m`, in lane order, at the start of `dst`, which must have room
    /// for sixteen: the places after the stored lanes may be overwritten.
    #[inline(always)]
    pub fn compress_store(self, m: Mask16, dst: &mut [f32]) {
        assert!(dst.len() >= 16);
        let (lo, hi) = (m.0 as u8, (m.0 >> 8) as u8);
        unsafe {
            let at = dst.as_mut_ptr();
            _mm256_storeu_ps(at, _mm256_permutevar8x32_ps(self.lo, compress_index(lo)));
            let after = at.add(lo.count_ones() as usize);
            _mm256_storeu_ps(after, _mm256_permutevar8x32_ps(self.hi, compress_index(hi)));
        }
    }

    /// Lane i of the result is lane `idx[i] mod 16` of `self`.
    #[inline(always)]
    pub fn permute(self, idx: U32x16) -> F32x16 {
        unsafe {
            // Each half's indices pick from both halves (low three bits), then bit 3 chooses:
            // shifted into the sign bit, which is all `blendv` reads.
            let half = |i: __m256i| {
                let from_lo = _mm256_permutevar8x32_ps(self.lo, i);
                let from_hi = _mm256_permutevar8x32_ps(self.hi, i);
                let high = _mm256_slli_epi32::<28>(i);
                _mm256_blendv_ps(from_lo, from_hi, _mm256_castsi256_ps(high))
            };
            F32x16::both(half(idx.lo), half(idx.hi))
        }
    }

    /// Lane i of the result is lane `idx[i] mod 8` of `self` (only lanes 0–7 are read): one
    /// instruction per half, where `permute` needs four.
    #[inline(always)]
    pub fn permute_low8(self, idx: U32x16) -> F32x16 {
        unsafe {
            F32x16::both(
                _mm256_permutevar8x32_ps(self.lo, idx.lo),
                _mm256_permutevar8x32_ps(self.lo, idx.hi),
            )
        }
    }

    /// Lanes 0–7 and 8–15 widened to f64 (exact).
    #[inline(always)]
    pub fn to_f64_halves(self) -> (F64x8, F64x8) {
        unsafe {
            let widen = |v: __m256| F64x8 {
                lo: _mm256_cvtps_pd(_mm256_castps256_ps128(v)),
                hi: _mm256_cvtps_pd(_mm256_extractf128_ps::<1>(v)),
            };
            (widen(self.lo), widen(self.hi))
        }
    }

    /// Two f64 halves rounded to f32 (`as f32`: to nearest, ties to even).
    #[inline(always)]
    pub fn from_f64_halves(lo: F64x8, hi: F64x8) -> F32x16 {
        unsafe {
            let narrow = |v: F64x8| _mm256_set_m128(_mm256_cvtpd_ps(v.hi), _mm256_cvtpd_ps(v.lo));
            F32x16::both(narrow(lo), narrow(hi))
        }
    }

    /// Each lane `as u32`: towards zero, NaN and negatives to 0, saturating at u32::MAX.
    #[inline(always)]
    pub fn to_u32(self) -> U32x16 {
        // The maximum with +0 sends NaN and negatives to 0. AVX2 converts to signed
        // integers only: values from 2³¹ are converted after subtracting 2³¹ (exact there),
        // and values from 2³² saturate.
        let v = self.max_gt(F32x16::splat(0.0));
        unsafe {
            let two31 = _mm256_set1_ps(2147483648.0);
            let two32 = _mm256_set1_ps(4294967296.0);
            let sign = _mm256_set1_epi32(i32::MIN);
            let half = |v: __m256| {
                let small = _mm256_cvttps_epi32(v);
                let large = _mm256_xor_si256(_mm256_cvttps_epi32(_mm256_sub_ps(v, two31)), sign);
                let is_large = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(v, two31));
                let over = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(v, two32));
                _mm256_or_si256(_mm256_blendv_epi8(small, large, is_large), over)
            };
            U32x16 {
                lo: half(v.lo),
                hi: half(v.hi),
            }
        }
    }
}

impl U32x16 {
    #[inline(always)]
    pub fn splat(v: u32) -> U32x16 {
        unsafe {
            let s = _mm256_set1_epi32(v as i32);
            U32x16 { lo: s, hi: s }
        }
    }

    #[inline(always)]
    pub fn from_array(a: [u32; 16]) -> U32x16 {
        unsafe {
            let p = a.as_ptr() as *const __m256i;
            U32x16 {
                lo: _mm256_loadu_si256(p),
                hi: _mm256_loadu_si256(p.add(1)),
            }
        }
    }

    #[inline(always)]
    pub fn to_array(self) -> [u32; 16] {
        let mut a = [0u32; 16];
        unsafe {
            let p = a.as_mut_ptr() as *mut __m256i;
            _mm256_storeu_si256(p, self.lo);
            _mm256_storeu_si256(p.add(1), self.hi);
        }
        a
    }

    #[inline(always)]
    pub fn shl<const N: u32>(self) -> U32x16 {
        unsafe {
            let n = _mm_cvtsi32_si128(N as i32);
            U32x16 {
                lo: _mm256_sll_epi32(self.lo, n),
                hi: _mm256_sll_epi32(self.hi, n),
            }
        }
    }

    #[inline(always)]
    pub fn shr<const N: u32>(self) -> U32x16 {
        unsafe {
            let n = _mm_cvtsi32_si128(N as i32);
            U32x16 {
                lo: _mm256_srl_epi32(self.lo, n),
                hi: _mm256_srl_epi32(self.hi, n),
            }
        }
    }

    /// Stores the lanes of `m`, in lane order, at the start of `dst`, which must have room
    /// for sixteen: the places after the stored lanes may be overwritten.
    #[inline(always)]
    pub fn compress_store(self, m: Mask16, dst: &mut [u32]) {
        assert!(dst.len() >= 16);
        let (lo, hi) = (m.0 as u8, (m.0 >> 8) as u8);
        unsafe {
            let at = dst.as_mut_ptr() as *mut __m256i;
            let store = |to: *mut __m256i, v: __m256i, bits: u8| {
                _mm256_storeu_si256(to, _mm256_permutevar8x32_epi32(v, compress_index(bits)))
            };
            store(at, self.lo, lo);
            store(
                dst.as_mut_ptr().add(lo.count_ones() as usize) as *mut __m256i,
                self.hi,
                hi,
            );
        }
    }

    /// Unsigned minimum.
    #[inline(always)]
    pub fn min(self, o: U32x16) -> U32x16 {
        unsafe {
            U32x16 {
                lo: _mm256_min_epu32(self.lo, o.lo),
                hi: _mm256_min_epu32(self.hi, o.hi),
            }
        }
    }

    /// Unsigned maximum.
    #[inline(always)]
    pub fn max(self, o: U32x16) -> U32x16 {
        unsafe {
            U32x16 {
                lo: _mm256_max_epu32(self.lo, o.lo),
                hi: _mm256_max_epu32(self.hi, o.hi),
            }
        }
    }

    #[inline(always)]
    pub fn eq(self, o: U32x16) -> Mask16 {
        unsafe {
            let c = |a, b| _mm256_castsi256_ps(_mm256_cmpeq_epi32(a, b));
            mask16(c(self.lo, o.lo), c(self.hi, o.hi))
        }
    }

    /// Unsigned `<` (AVX2 compares signed: both sides' sign bits flipped first).
    #[inline(always)]
    pub fn lt(self, o: U32x16) -> Mask16 {
        unsafe {
            let sign = _mm256_set1_epi32(i32::MIN);
            let c = |a, b| {
                _mm256_castsi256_ps(_mm256_cmpgt_epi32(
                    _mm256_xor_si256(b, sign),
                    _mm256_xor_si256(a, sign),
                ))
            };
            mask16(c(self.lo, o.lo), c(self.hi, o.hi))
        }
    }

    #[inline(always)]
    pub fn select(m: Mask16, a: U32x16, b: U32x16) -> U32x16 {
        let (lo, hi) = halves32(m);
        unsafe {
            U32x16 {
                lo: _mm256_blendv_epi8(b.lo, a.lo, lo),
                hi: _mm256_blendv_epi8(b.hi, a.hi, hi),
            }
        }
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty.
    #[inline(always)]
    pub fn gather(table: &[u32], idx: U32x16, m: Mask16) -> U32x16 {
        let last = table.len() - 1;
        let idx = idx.min(U32x16::splat(last.min(u32::MAX as usize) as u32));
        let (lo, hi) = halves32(m);
        let p = table.as_ptr() as *const i32;
        unsafe {
            let zero = _mm256_setzero_si256();
            let gather = |i, m| _mm256_mask_i32gather_epi32::<4>(zero, p, i, m);
            U32x16 {
                lo: gather(idx.lo, lo),
                hi: gather(idx.hi, hi),
            }
        }
    }

    /// Each lane as f32 (`as f32`). AVX2 converts signed integers only: the upper and lower
    /// 16 bits convert exactly, and their sum (exact upper part times 2¹⁶ plus the lower)
    /// is rounded once, as `as f32` rounds.
    #[inline(always)]
    pub fn to_f32(self) -> F32x16 {
        unsafe {
            let low16 = _mm256_set1_epi32(0xffff);
            let scale = _mm256_set1_ps(65536.0);
            let half = |v: __m256i| {
                let upper = _mm256_cvtepi32_ps(_mm256_srli_epi32::<16>(v));
                let lower = _mm256_cvtepi32_ps(_mm256_and_si256(v, low16));
                _mm256_add_ps(_mm256_mul_ps(upper, scale), lower)
            };
            F32x16::both(half(self.lo), half(self.hi))
        }
    }

    /// Lanes 0–7 and 8–15 widened to u64.
    #[inline(always)]
    pub fn to_u64_halves(self) -> (U64x8, U64x8) {
        unsafe {
            let widen = |v: __m256i| U64x8 {
                lo: _mm256_cvtepu32_epi64(_mm256_castsi256_si128(v)),
                hi: _mm256_cvtepu32_epi64(_mm256_extracti128_si256::<1>(v)),
            };
            (widen(self.lo), widen(self.hi))
        }
    }

    /// The low 32 bits of each u64 lane of `lo` (lanes 0–7) and `hi` (lanes 8–15).
    #[inline(always)]
    pub fn from_u64_halves(lo: U64x8, hi: U64x8) -> U32x16 {
        unsafe {
            let narrow = |v: U64x8| _mm256_set_m128i(low_words(v.hi), low_words(v.lo));
            U32x16 {
                lo: narrow(lo),
                hi: narrow(hi),
            }
        }
    }
}

impl F64x8 {
    #[inline(always)]
    pub fn splat(v: f64) -> F64x8 {
        unsafe {
            let s = _mm256_set1_pd(v);
            F64x8 { lo: s, hi: s }
        }
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty.
    #[inline(always)]
    pub fn gather(table: &[f64], idx: U64x8, m: Mask8) -> F64x8 {
        let last = U64x8::splat(table.len() as u64 - 1);
        let (lo, hi) = halves64(m);
        let p = table.as_ptr();
        unsafe {
            let zero = _mm256_setzero_pd();
            let gather = |i, last, m| {
                _mm256_mask_i64gather_pd::<8>(zero, p, min_u64(i, last), _mm256_castsi256_pd(m))
            };
            F64x8 {
                lo: gather(idx.lo, last.lo, lo),
                hi: gather(idx.hi, last.hi, hi),
            }
        }
    }

    #[inline(always)]
    pub fn from_array(a: [f64; 8]) -> F64x8 {
        unsafe {
            F64x8 {
                lo: _mm256_loadu_pd(a.as_ptr()),
                hi: _mm256_loadu_pd(a.as_ptr().add(4)),
            }
        }
    }

    #[inline(always)]
    pub fn to_array(self) -> [f64; 8] {
        let mut a = [0.0f64; 8];
        unsafe {
            _mm256_storeu_pd(a.as_mut_ptr(), self.lo);
            _mm256_storeu_pd(a.as_mut_ptr().add(4), self.hi);
        }
        a
    }

    #[inline(always)]
    pub fn lt(self, o: F64x8) -> Mask8 {
        compare_pd!(self, o, _CMP_LT_OQ)
    }

    #[inline(always)]
    pub fn le(self, o: F64x8) -> Mask8 {
        compare_pd!(self, o, _CMP_LE_OQ)
    }

    #[inline(always)]
    pub fn gt(self, o: F64x8) -> Mask8 {
        compare_pd!(self, o, _CMP_GT_OQ)
    }

    #[inline(always)]
    pub fn eq(self, o: F64x8) -> Mask8 {
        compare_pd!(self, o, _CMP_EQ_OQ)
    }

    #[inline(always)]
    pub fn select(m: Mask8, a: F64x8, b: F64x8) -> F64x8 {
        let (lo, hi) = halves64(m);
        unsafe {
            F64x8 {
                lo: _mm256_blendv_pd(b.lo, a.lo, _mm256_castsi256_pd(lo)),
                hi: _mm256_blendv_pd(b.hi, a.hi, _mm256_castsi256_pd(hi)),
            }
        }
    }

    #[inline(always)]
    pub fn sqrt(self) -> F64x8 {
        unsafe {
            F64x8 {
                lo: _mm256_sqrt_pd(self.lo),
                hi: _mm256_sqrt_pd(self.hi),
            }
        }
    }

    /// The magnitude of `self` with the sign of `sign` (`f64::copysign`).
    #[inline(always)]
    pub fn copysign(self, sign: F64x8) -> F64x8 {
        unsafe {
            let s = _mm256_set1_pd(-0.0);
            let half = |m, g| _mm256_or_pd(_mm256_andnot_pd(s, m), _mm256_and_pd(s, g));
            F64x8 {
                lo: half(self.lo, sign.lo),
                hi: half(self.hi, sign.hi),
            }
        }
    }
}

impl Neg for F64x8 {
    type Output = F64x8;
    #[inline(always)]
    fn neg(self) -> F64x8 {
        unsafe {
            let s = _mm256_set1_pd(-0.0);
            F64x8 {
                lo: _mm256_xor_pd(self.lo, s),
                hi: _mm256_xor_pd(self.hi, s),
            }
        }
    }
}

impl U64x8 {
    #[inline(always)]
    pub fn splat(v: u64) -> U64x8 {
        unsafe {
            let s = _mm256_set1_epi64x(v as i64);
            U64x8 { lo: s, hi: s }
        }
    }

    #[inline(always)]
    pub fn from_array(a: [u64; 8]) -> U64x8 {
        unsafe {
            let p = a.as_ptr() as *const __m256i;
            U64x8 {
                lo: _mm256_loadu_si256(p),
                hi: _mm256_loadu_si256(p.add(1)),
            }
        }
    }

    #[inline(always)]
    pub fn to_array(self) -> [u64; 8] {
        let mut a = [0u64; 8];
        unsafe {
            let p = a.as_mut_ptr() as *mut __m256i;
            _mm256_storeu_si256(p, self.lo);
            _mm256_storeu_si256(p.add(1), self.hi);
        }
        a
    }

    #[inline(always)]
    pub fn shl<const N: u32>(self) -> U64x8 {
        unsafe {
            let n = _mm_cvtsi32_si128(N as i32);
            U64x8 {
                lo: _mm256_sll_epi64(self.lo, n),
                hi: _mm256_sll_epi64(self.hi, n),
            }
        }
    }

    #[inline(always)]
    pub fn shr<const N: u32>(self) -> U64x8 {
        unsafe {
            let n = _mm_cvtsi32_si128(N as i32);
            U64x8 {
                lo: _mm256_srl_epi64(self.lo, n),
                hi: _mm256_srl_epi64(self.hi, n),
            }
        }
    }

    /// Rotation left by N bits (0 ≤ N < 64): two shifts (a shift by 64 gives 0).
    #[inline(always)]
    pub fn rotl<const N: i32>(self) -> U64x8 {
        unsafe {
            let left = _mm_cvtsi32_si128(N);
            let right = _mm_cvtsi32_si128(64 - N);
            let rot = |v| _mm256_or_si256(_mm256_sll_epi64(v, left), _mm256_srl_epi64(v, right));
            U64x8 {
                lo: rot(self.lo),
                hi: rot(self.hi),
            }
        }
    }

    #[inline(always)]
    pub fn select(m: Mask8, a: U64x8, b: U64x8) -> U64x8 {
        let (lo, hi) = halves64(m);
        unsafe {
            U64x8 {
                lo: _mm256_blendv_epi8(b.lo, a.lo, lo),
                hi: _mm256_blendv_epi8(b.hi, a.hi, hi),
            }
        }
    }
}

debug_as_array!(F32x16, U32x16, F64x8, U64x8);
