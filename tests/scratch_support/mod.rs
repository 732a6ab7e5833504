//! Scratch folders for tests that write files: fresh when made, removed when the test ends.
#![allow(dead_code)]

use std::ops::Deref;
use std::path::{Path, PathBuf};

/// A fresh, empty folder under the system's temporary folder, named after the test and the
/// process, removed with everything in it when dropped. A test that fails (panics) leaves
/// its folder behind, for a look at what it wrote.
pub struct ScratchDir {
    path: PathBuf,
}

impl ScratchDir {
    /// `mltbench-{name}-{process id}`, emptied if an earlier run left it.
    pub fn new(name: &str) -> ScratchDir {
        let path = std::env::temp_dir().join(format!("mltbench-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("create scratch folder");
        ScratchDir { path }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Deref for ScratchDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for ScratchDir {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.path);
        }
    }
}
