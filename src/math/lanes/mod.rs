//! Sixteen lanes of arithmetic side by side, for estimators that trace sixteen paths at once
//! (`estimator::pt::wavefront`).
//!
//! Every lane operation is the IEEE operation of its scalar counterpart (no fused
//! multiply-adds, no approximate reciprocals), so a formula evaluated on lanes gives, in each
//! lane, exactly the bits the same formula gives on `f32`. That is what lets the wavefront
//! path tracer produce the scalar path tracer's image bit for bit: `Real` is implemented by
//! both `f32` and `F32x16`, and the shared formulas (frames, warps, ray offsets, MIS weights)
//! are written once against it.
//!
//! Two backends with the same types and semantics: `avx512` (one register per vector, used
//! when the build enables AVX-512F, as `-C target-cpu=native` does on the development
//! machine) and `portable` (arrays and loops, everywhere else). The tests check each
//! operation of both against the scalar one, NaNs, infinities and signed zeros included.

mod mask;
pub mod portable;
mod real;
mod vec3;

#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
pub mod avx512;

pub use mask::{Mask8, Mask16};
pub use real::Real;
pub use vec3::V3;

#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
pub use avx512::{F32x16, F64x8, U32x16, U64x8};
#[cfg(not(all(target_arch = "x86_64", target_feature = "avx512f")))]
pub use portable::{F32x16, F64x8, U32x16, U64x8};

/// Lanes per vector.
pub const LANES: usize = 16;

/// True when the lane types compile to AVX-512 registers; false when they are the portable
/// arrays (correct, but slower than scalar code).
pub const NATIVE: bool = cfg!(all(target_arch = "x86_64", target_feature = "avx512f"));

/// Sixteen lanes of `T` as an array (lanes that a vector type does not cover: ids, flags).
pub type Lanes<T> = [T; LANES];

#[cfg(test)]
mod tests;
