//! Files out and in: EXR images, PNG previews, atomic writes.

pub mod atomic;
pub mod exr;
pub mod png;
pub mod tonemap;
