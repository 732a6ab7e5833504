//! The lane types in AVX-512 registers: the same operations as `portable`, one instruction
//! (or a few) each.
//!
//! SAFETY (every `unsafe` block in this file): the module is compiled only when AVX-512F is
//! enabled for the whole build (`cfg` in `lanes/mod.rs`), so each intrinsic is available;
//! loads and stores go through arrays of exactly one vector's size, and gathers read only
//! indices clamped into their slice.

use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Sub};

use super::{Mask8, Mask16};

/// Sixteen f32 lanes.
#[derive(Clone, Copy)]
pub struct F32x16(__m512);

/// Sixteen u32 lanes (wrapping arithmetic).
#[derive(Clone, Copy)]
pub struct U32x16(__m512i);

/// Eight f64 lanes (half of a sixteen-lane vector, widened).
#[derive(Clone, Copy)]
pub struct F64x8(__m512d);

/// Eight u64 lanes (wrapping arithmetic).
#[derive(Clone, Copy)]
pub struct U64x8(__m512i);

/// Binary operators that are one intrinsic.
macro_rules! binary_ops {
    ($ty:ident, $( $tr:ident $method:ident $intrinsic:ident ),* $(,)?) => {
        $(
            impl $tr for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $method(self, o: $ty) -> $ty {
                    $ty(unsafe { $intrinsic(self.0, o.0) })
                }
            }
        )*
    };
}

binary_ops!(F32x16,
    Add add _mm512_add_ps,
    Sub sub _mm512_sub_ps,
    Mul mul _mm512_mul_ps,
    Div div _mm512_div_ps,
);
binary_ops!(U32x16,
    Add add _mm512_add_epi32,
    Sub sub _mm512_sub_epi32,
    Mul mul _mm512_mullo_epi32,
    BitAnd bitand _mm512_and_si512,
    BitOr bitor _mm512_or_si512,
    BitXor bitxor _mm512_xor_si512,
);
binary_ops!(F64x8,
    Add add _mm512_add_pd,
    Sub sub _mm512_sub_pd,
    Mul mul _mm512_mul_pd,
    Div div _mm512_div_pd,
);
binary_ops!(U64x8,
    Add add _mm512_add_epi64,
    BitAnd bitand _mm512_and_si512,
    BitOr bitor _mm512_or_si512,
    BitXor bitxor _mm512_xor_si512,
);

/// Wrapping 64-bit products: one instruction with AVX-512DQ, three 32-bit products without.
impl Mul for U64x8 {
    type Output = U64x8;
    #[inline(always)]
    fn mul(self, o: U64x8) -> U64x8 {
        #[cfg(target_feature = "avx512dq")]
        {
            U64x8(unsafe { _mm512_mullo_epi64(self.0, o.0) })
        }
        #[cfg(not(target_feature = "avx512dq"))]
        {
            // a·b mod 2⁶⁴ = lo(a)·lo(b) + ((lo(a)·hi(b) + hi(a)·lo(b)) << 32).
            unsafe {
                let lo = _mm512_mul_epu32(self.0, o.0);
                let cross = _mm512_add_epi64(
                    _mm512_mul_epu32(self.0, _mm512_srli_epi64::<32>(o.0)),
                    _mm512_mul_epu32(_mm512_srli_epi64::<32>(self.0), o.0),
                );
                U64x8(_mm512_add_epi64(lo, _mm512_slli_epi64::<32>(cross)))
            }
        }
    }
}

const SIGN: u32 = 0x8000_0000;

impl Neg for F32x16 {
    type Output = F32x16;
    #[inline(always)]
    fn neg(self) -> F32x16 {
        F32x16::from_bits(self.to_bits() ^ U32x16::splat(SIGN))
    }
}

impl F32x16 {
    #[inline(always)]
    pub fn splat(v: f32) -> F32x16 {
        F32x16(unsafe { _mm512_set1_ps(v) })
    }

    #[inline(always)]
    pub fn from_array(a: [f32; 16]) -> F32x16 {
        F32x16(unsafe { _mm512_loadu_ps(a.as_ptr()) })
    }

    #[inline(always)]
    pub fn to_array(self) -> [f32; 16] {
        let mut a = [0.0f32; 16];
        unsafe { _mm512_storeu_ps(a.as_mut_ptr(), self.0) };
        a
    }

    #[inline(always)]
    pub fn sqrt(self) -> F32x16 {
        F32x16(unsafe { _mm512_sqrt_ps(self.0) })
    }

    #[inline(always)]
    pub fn abs(self) -> F32x16 {
        F32x16(unsafe { _mm512_abs_ps(self.0) })
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
        F32x16(unsafe { _mm512_max_ps(self.0, o.0) })
    }

    /// Lane-wise `if self < o { self } else { o }` (o where either is NaN): `vminps`.
    #[inline(always)]
    pub fn min_lt(self, o: F32x16) -> F32x16 {
        F32x16(unsafe { _mm512_min_ps(self.0, o.0) })
    }

    #[inline(always)]
    pub fn lt(self, o: F32x16) -> Mask16 {
        Mask16(unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn le(self, o: F32x16) -> Mask16 {
        Mask16(unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn gt(self, o: F32x16) -> Mask16 {
        Mask16(unsafe { _mm512_cmp_ps_mask::<_CMP_GT_OQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn ge(self, o: F32x16) -> Mask16 {
        Mask16(unsafe { _mm512_cmp_ps_mask::<_CMP_GE_OQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn eq(self, o: F32x16) -> Mask16 {
        Mask16(unsafe { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(self.0, o.0) })
    }

    /// `!=`: true where either lane is NaN.
    #[inline(always)]
    pub fn ne(self, o: F32x16) -> Mask16 {
        Mask16(unsafe { _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn is_nan(self) -> Mask16 {
        Mask16(unsafe { _mm512_cmp_ps_mask::<_CMP_UNORD_Q>(self.0, self.0) })
    }

    #[inline(always)]
    pub fn is_finite(self) -> Mask16 {
        self.abs().lt(F32x16::splat(f32::INFINITY))
    }

    /// Lane-wise `if m { a } else { b }`.
    #[inline(always)]
    pub fn select(m: Mask16, a: F32x16, b: F32x16) -> F32x16 {
        F32x16(unsafe { _mm512_mask_blend_ps(m.0, b.0, a.0) })
    }

    #[inline(always)]
    pub fn to_bits(self) -> U32x16 {
        U32x16(unsafe { _mm512_castps_si512(self.0) })
    }

    #[inline(always)]
    pub fn from_bits(b: U32x16) -> F32x16 {
        F32x16(unsafe { _mm512_castsi512_ps(b.0) })
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty. A table of at most sixteen entries is read
    /// into one register and permuted (a few cycles, where a gather takes twenty or more:
    /// small scenes' per-shape tables, small lights' triangles).
    #[inline(always)]
    pub fn gather(table: &[f32], idx: U32x16, m: Mask16) -> F32x16 {
        let last = table.len() - 1;
        let idx = idx.min(U32x16::splat(last.min(u32::MAX as usize) as u32));
        F32x16(unsafe {
            if table.len() <= 16 {
                // SAFETY: the load reads only the table's entries (the mask stops at its
                // length; masked-off elements are not accessed).
                let all = _mm512_maskz_loadu_ps(((1u32 << table.len()) - 1) as u16, table.as_ptr());
                _mm512_maskz_permutexvar_ps(m.0, idx.0, all)
            } else {
                _mm512_mask_i32gather_ps::<4>(_mm512_setzero_ps(), m.0, idx.0, table.as_ptr())
            }
        })
    }

    /// Stores the lanes of `m`, in lane order, at the start of `dst`, which must have room
    /// for sixteen: the places after the stored lanes may be overwritten.
    #[inline(always)]
    pub fn compress_store(self, m: Mask16, dst: &mut [f32]) {
        assert!(dst.len() >= 16);
        // Compressed in a register, then stored whole: a compressing store to memory is
        // microcoded on some processors (Zen 4), about ten times slower.
        unsafe { _mm512_storeu_ps(dst.as_mut_ptr(), _mm512_maskz_compress_ps(m.0, self.0)) };
    }

    /// Lane i of the result is lane `idx[i] mod 16` of `self`.
    #[inline(always)]
    pub fn permute(self, idx: U32x16) -> F32x16 {
        F32x16(unsafe { _mm512_permutexvar_ps(idx.0, self.0) })
    }

    /// Lane i of the result is lane `idx[i] mod 8` of `self` (only lanes 0–7 are read).
    #[inline(always)]
    pub fn permute_low8(self, idx: U32x16) -> F32x16 {
        self.permute(idx & U32x16::splat(7))
    }

    /// Lanes 0–7 and 8–15 widened to f64 (exact).
    #[inline(always)]
    pub fn to_f64_halves(self) -> (F64x8, F64x8) {
        unsafe {
            let lo = _mm512_castps512_ps256(self.0);
            let hi = _mm256_castpd_ps(_mm512_extractf64x4_pd::<1>(_mm512_castps_pd(self.0)));
            (F64x8(_mm512_cvtps_pd(lo)), F64x8(_mm512_cvtps_pd(hi)))
        }
    }

    /// Two f64 halves rounded to f32 (`as f32`: to nearest, ties to even).
    #[inline(always)]
    pub fn from_f64_halves(lo: F64x8, hi: F64x8) -> F32x16 {
        unsafe {
            let lo = _mm256_castps_pd(_mm512_cvtpd_ps(lo.0));
            let hi = _mm256_castps_pd(_mm512_cvtpd_ps(hi.0));
            let both = _mm512_insertf64x4::<1>(_mm512_castpd256_pd512(lo), hi);
            F32x16(_mm512_castpd_ps(both))
        }
    }

    /// Each lane `as u32`: towards zero, NaN and negatives to 0, saturating at u32::MAX.
    #[inline(always)]
    pub fn to_u32(self) -> U32x16 {
        // The maximum with +0 sends NaN and negatives to 0; the unsigned truncation gives
        // u32::MAX for anything above it (its out-of-range value), as `as u32` saturates.
        let v = self.max_gt(F32x16::splat(0.0));
        U32x16(unsafe { _mm512_cvttps_epu32(v.0) })
    }
}

impl U32x16 {
    #[inline(always)]
    pub fn splat(v: u32) -> U32x16 {
        U32x16(unsafe { _mm512_set1_epi32(v as i32) })
    }

    #[inline(always)]
    pub fn from_array(a: [u32; 16]) -> U32x16 {
        U32x16(unsafe { _mm512_loadu_epi32(a.as_ptr() as *const i32) })
    }

    #[inline(always)]
    pub fn to_array(self) -> [u32; 16] {
        let mut a = [0u32; 16];
        unsafe { _mm512_storeu_epi32(a.as_mut_ptr() as *mut i32, self.0) };
        a
    }

    #[inline(always)]
    pub fn shl<const N: u32>(self) -> U32x16 {
        U32x16(unsafe { _mm512_slli_epi32::<N>(self.0) })
    }

    #[inline(always)]
    pub fn shr<const N: u32>(self) -> U32x16 {
        U32x16(unsafe { _mm512_srli_epi32::<N>(self.0) })
    }

    /// Stores the lanes of `m`, in lane order, at the start of `dst`, which must have room
    /// for sixteen: the places after the stored lanes may be overwritten.
    #[inline(always)]
    pub fn compress_store(self, m: Mask16, dst: &mut [u32]) {
        assert!(dst.len() >= 16);
        unsafe {
            let packed = _mm512_maskz_compress_epi32(m.0, self.0);
            _mm512_storeu_si512(dst.as_mut_ptr() as *mut __m512i, packed)
        };
    }

    /// Unsigned minimum.
    #[inline(always)]
    pub fn min(self, o: U32x16) -> U32x16 {
        U32x16(unsafe { _mm512_min_epu32(self.0, o.0) })
    }

    /// Unsigned maximum.
    #[inline(always)]
    pub fn max(self, o: U32x16) -> U32x16 {
        U32x16(unsafe { _mm512_max_epu32(self.0, o.0) })
    }

    #[inline(always)]
    pub fn eq(self, o: U32x16) -> Mask16 {
        Mask16(unsafe { _mm512_cmpeq_epu32_mask(self.0, o.0) })
    }

    /// Unsigned `<`.
    #[inline(always)]
    pub fn lt(self, o: U32x16) -> Mask16 {
        Mask16(unsafe { _mm512_cmplt_epu32_mask(self.0, o.0) })
    }

    #[inline(always)]
    pub fn select(m: Mask16, a: U32x16, b: U32x16) -> U32x16 {
        U32x16(unsafe { _mm512_mask_blend_epi32(m.0, b.0, a.0) })
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty; a table of at most sixteen entries is permuted
    /// (as `F32x16::gather`).
    #[inline(always)]
    pub fn gather(table: &[u32], idx: U32x16, m: Mask16) -> U32x16 {
        let last = table.len() - 1;
        let idx = idx.min(U32x16::splat(last.min(u32::MAX as usize) as u32));
        U32x16(unsafe {
            if table.len() <= 16 {
                // SAFETY: as `F32x16::gather`'s small tables.
                let all = _mm512_maskz_loadu_epi32(
                    ((1u32 << table.len()) - 1) as u16,
                    table.as_ptr() as *const i32,
                );
                _mm512_maskz_permutexvar_epi32(m.0, idx.0, all)
            } else {
                _mm512_mask_i32gather_epi32::<4>(
                    _mm512_setzero_si512(),
                    m.0,
                    idx.0,
                    table.as_ptr() as *const i32,
                )
            }
        })
    }

    /// Each lane as f32 (`as f32`).
    #[inline(always)]
    pub fn to_f32(self) -> F32x16 {
        F32x16(unsafe { _mm512_cvtepu32_ps(self.0) })
    }

    /// Lanes 0–7 and 8–15 widened to u64.
    #[inline(always)]
    pub fn to_u64_halves(self) -> (U64x8, U64x8) {
        unsafe {
            let lo = _mm512_castsi512_si256(self.0);
            let hi = _mm512_extracti64x4_epi64::<1>(self.0);
            (
                U64x8(_mm512_cvtepu32_epi64(lo)),
                U64x8(_mm512_cvtepu32_epi64(hi)),
            )
        }
    }

    /// The low 32 bits of each u64 lane of `lo` (lanes 0–7) and `hi` (lanes 8–15).
    #[inline(always)]
    pub fn from_u64_halves(lo: U64x8, hi: U64x8) -> U32x16 {
        unsafe {
            let lo = _mm512_cvtepi64_epi32(lo.0);
            let hi = _mm512_cvtepi64_epi32(hi.0);
            U32x16(_mm512_inserti64x4::<1>(_mm512_castsi256_si512(lo), hi))
        }
    }
}

impl F64x8 {
    #[inline(always)]
    pub fn splat(v: f64) -> F64x8 {
        F64x8(unsafe { _mm512_set1_pd(v) })
    }

    /// `table[idx]` in the lanes of `m` (indices past the end read the last entry), 0
    /// elsewhere. `table` must not be empty.
    #[inline(always)]
    pub fn gather(table: &[f64], idx: U64x8, m: Mask8) -> F64x8 {
        let last = U64x8::splat(table.len() as u64 - 1);
        let idx = U64x8(unsafe { _mm512_min_epu64(idx.0, last.0) });
        F64x8(unsafe {
            _mm512_mask_i64gather_pd::<8>(_mm512_setzero_pd(), m.0, idx.0, table.as_ptr())
        })
    }

    #[inline(always)]
    pub fn from_array(a: [f64; 8]) -> F64x8 {
        F64x8(unsafe { _mm512_loadu_pd(a.as_ptr()) })
    }

    #[inline(always)]
    pub fn to_array(self) -> [f64; 8] {
        let mut a = [0.0f64; 8];
        unsafe { _mm512_storeu_pd(a.as_mut_ptr(), self.0) };
        a
    }

    #[inline(always)]
    pub fn lt(self, o: F64x8) -> Mask8 {
        Mask8(unsafe { _mm512_cmp_pd_mask::<_CMP_LT_OQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn le(self, o: F64x8) -> Mask8 {
        Mask8(unsafe { _mm512_cmp_pd_mask::<_CMP_LE_OQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn gt(self, o: F64x8) -> Mask8 {
        Mask8(unsafe { _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn eq(self, o: F64x8) -> Mask8 {
        Mask8(unsafe { _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(self.0, o.0) })
    }

    #[inline(always)]
    pub fn select(m: Mask8, a: F64x8, b: F64x8) -> F64x8 {
        F64x8(unsafe { _mm512_mask_blend_pd(m.0, b.0, a.0) })
    }

    #[inline(always)]
    pub fn sqrt(self) -> F64x8 {
        F64x8(unsafe { _mm512_sqrt_pd(self.0) })
    }

    /// The magnitude of `self` with the sign of `sign` (`f64::copysign`).
    #[inline(always)]
    pub fn copysign(self, sign: F64x8) -> F64x8 {
        unsafe {
            let bits = |v: __m512d| _mm512_castpd_si512(v);
            let s = _mm512_set1_epi64(i64::MIN);
            let magnitude = _mm512_andnot_si512(s, bits(self.0));
            let sign = _mm512_and_si512(s, bits(sign.0));
            F64x8(_mm512_castsi512_pd(_mm512_or_si512(magnitude, sign)))
        }
    }
}

impl Neg for F64x8 {
    type Output = F64x8;
    #[inline(always)]
    fn neg(self) -> F64x8 {
        unsafe {
            let flipped =
                _mm512_xor_si512(_mm512_castpd_si512(self.0), _mm512_set1_epi64(i64::MIN));
            F64x8(_mm512_castsi512_pd(flipped))
        }
    }
}

impl U64x8 {
    #[inline(always)]
    pub fn splat(v: u64) -> U64x8 {
        U64x8(unsafe { _mm512_set1_epi64(v as i64) })
    }

    #[inline(always)]
    pub fn from_array(a: [u64; 8]) -> U64x8 {
        U64x8(unsafe { _mm512_loadu_epi64(a.as_ptr() as *const i64) })
    }

    #[inline(always)]
    pub fn to_array(self) -> [u64; 8] {
        let mut a = [0u64; 8];
        unsafe { _mm512_storeu_epi64(a.as_mut_ptr() as *mut i64, self.0) };
        a
    }

    #[inline(always)]
    pub fn shl<const N: u32>(self) -> U64x8 {
        U64x8(unsafe { _mm512_slli_epi64::<N>(self.0) })
    }

    #[inline(always)]
    pub fn shr<const N: u32>(self) -> U64x8 {
        U64x8(unsafe { _mm512_srli_epi64::<N>(self.0) })
    }

    #[inline(always)]
    pub fn rotl<const N: i32>(self) -> U64x8 {
        U64x8(unsafe { _mm512_rol_epi64::<N>(self.0) })
    }

    #[inline(always)]
    pub fn select(m: Mask8, a: U64x8, b: U64x8) -> U64x8 {
        U64x8(unsafe { _mm512_mask_blend_epi64(m.0, b.0, a.0) })
    }
}

debug_as_array!(F32x16, U32x16, F64x8, U64x8);
