//! Stanford PLY meshes: ascii, binary little- and big-endian.

use std::path::Path;

use super::TriangleMesh;
use crate::error::Result;

/// Reads a PLY file into a mesh in object space.
pub fn read_ply(path: &Path) -> Result<TriangleMesh> {
    let _ = path;
    todo!("ply reader")
}
