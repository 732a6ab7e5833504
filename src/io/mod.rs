//! Files out and in: EXR images, PNG previews, atomic writes, output checks.

pub mod atomic;
pub mod exr;
pub mod outputs;
pub mod png;
pub mod tonemap;
