//! Folder helpers shared by the tests that write files.

use std::path::Path;

/// The file names in `dir`, sorted: atomic writes leave no temporary file behind.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
