//! Wavefront OBJ meshes (via tobj).

use std::path::Path;

use super::TriangleMesh;
use crate::error::Result;

/// Reads every object of an OBJ file into one mesh in object space.
pub fn read_obj(path: &Path) -> Result<TriangleMesh> {
    let _ = path;
    todo!("obj reader")
}
