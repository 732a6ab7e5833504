//! Atomic file writes: write a temporary file beside the target, then rename it over.
//! A crash or Ctrl-C leaves either the old file or the new one, never half a file.
//!
//! The temporary file lives in the target's directory (a rename is only atomic within one
//! file system), is flushed and fsync'ed before the rename, and the directory is fsync'ed
//! after it so the new name survives a power cut. On any error the temporary file is
//! removed and the target is left untouched.

use std::fs::{self, File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Distinguishes temporary files of concurrent writers in one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically: `write` fills a buffered temporary file, which then replaces
/// `path`. Errors from `write` are returned unchanged; I/O errors name `path`.
pub fn write_atomically<F>(path: &Path, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let (temp_path, file) = create_temp(path)?;
    let result = fill_and_sync(path, file, write)
        .and_then(|()| fs::rename(&temp_path, path).map_err(|e| Error::io(path, e)));
    if result.is_err() {
        // Best effort: the write already failed, the temporary file must not linger.
        let _ = fs::remove_file(&temp_path);
        return result;
    }
    sync_parent(path);
    Ok(())
}

/// Fails, naming `path`, when `path` could not be written: its folder is missing or not
/// writable, or it names a folder. Checked before a long render, so that its result is not
/// lost at the end. Creates and removes a temporary file beside `path`.
pub fn check_writable(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::io(
            path,
            std::io::Error::new(std::io::ErrorKind::IsADirectory, "is a folder"),
        ));
    }
    let (temp_path, file) = create_temp(path)?;
    drop(file);
    fs::remove_file(&temp_path).map_err(|e| Error::io(&temp_path, e))
}

/// Writes `bytes` to `path` atomically.
pub fn write_file_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomically(path, |w| w.write_all(bytes).map_err(|e| Error::io(path, e)))
}

fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Creates a new, uniquely named temporary file beside `path`.
fn create_temp(path: &Path) -> Result<(PathBuf, File)> {
    let name = path.file_name().ok_or_else(|| {
        Error::io(
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"),
        )
    })?;
    let dir = parent_dir(path);
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut temp_name = std::ffi::OsString::from(".");
        temp_name.push(name);
        temp_name.push(format!(".tmp-{}-{n}", std::process::id()));
        let temp_path = dir.join(temp_name);
        match OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp_path)
        {
            Ok(file) => return Ok((temp_path, file)),
            // A leftover from a killed process with the same pid: try the next name.
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(Error::io(path, e)),
        }
    }
}

fn fill_and_sync<F>(path: &Path, file: File, write: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(|e| Error::io(path, e.into_error()))?;
    file.sync_all().map_err(|e| Error::io(path, e))
}

/// Makes the rename durable. Failing to do so loses nothing but durability, and some
/// platforms cannot open directories, so errors are ignored.
fn sync_parent(path: &Path) {
    if let Ok(dir) = File::open(parent_dir(path)) {
        let _ = dir.sync_all();
    }
}
