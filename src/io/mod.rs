//! Files out and in: EXR images, PNG previews, atomic writes, output checks.

pub mod atomic;
pub mod exr;
pub mod outputs;
pub mod png;
pub mod strategy_images;
pub mod texture_file;
pub mod tonemap;

use std::path::Path;

use crate::error::{Error, Location, Result};

/// Refuses an input that is not a regular file (symbolic links followed) before it is
/// opened: reading a FIFO blocks until something writes to it, a device may never end.
pub fn check_input_file(path: &Path) -> Result<()> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_file() {
        return Ok(());
    }
    Err(Error::input(Location::file(path), not_a_file(&meta)))
}

/// Why something that exists cannot be read as a file.
pub fn not_a_file(meta: &std::fs::Metadata) -> &'static str {
    if meta.is_dir() {
        "is a directory, not a file"
    } else {
        "is not a regular file (a FIFO, socket or device): not read"
    }
}
