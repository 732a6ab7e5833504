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
//! Three backends with the same types and semantics: `avx512` (one register per vector, used
//! when the build enables AVX-512F), `avx2` (two registers per vector, when the build enables
//! AVX2 but not AVX-512F; `-C target-cpu=native` picks whichever the machine has) and
//! `portable` (arrays and loops, everywhere else). The tests check each
//! operation of both against the scalar one, NaNs, infinities and signed zeros included.

/// `Debug` for register-backed lane types: their lanes as an array (`to_array`).
#[cfg(all(
    target_arch = "x86_64",
    any(target_feature = "avx512f", target_feature = "avx2")
))]
macro_rules! debug_as_array {
    ($($ty:ident),*) => {
        $(impl std::fmt::Debug for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}({:?})", stringify!($ty), self.to_array())
            }
        })*
    };
}

mod mask;
pub mod portable;
mod real;
mod vec3;

#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
pub mod avx512;

#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    not(target_feature = "avx512f")
))]
pub mod avx2;

pub use mask::{Mask8, Mask16};
pub use real::Real;
pub use vec3::V3;

#[cfg(all(
    target_arch = "x86_64",
    target_feature = "avx2",
    not(target_feature = "avx512f")
))]
pub use avx2::{F32x16, F64x8, U32x16, U64x8};
#[cfg(all(target_arch = "x86_64", target_feature = "avx512f"))]
pub use avx512::{F32x16, F64x8, U32x16, U64x8};
#[cfg(not(all(
    target_arch = "x86_64",
    any(target_feature = "avx512f", target_feature = "avx2")
)))]
pub use portable::{F32x16, F64x8, U32x16, U64x8};

/// Lanes per vector.
pub const LANES: usize = 16;

/// True when the lane types compile to vector registers (AVX-512 or AVX2); false when they
/// are the portable arrays (correct, but slower than scalar code).
pub const NATIVE: bool = cfg!(all(
    target_arch = "x86_64",
    any(target_feature = "avx512f", target_feature = "avx2")
));

/// Sixteen lanes of `T` as an array (lanes that a vector type does not cover: ids, flags).
pub type Lanes<T> = [T; LANES];

#[cfg(test)]
mod tests;
