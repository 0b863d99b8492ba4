//! Outputs appear atomically (temporary file, fsync, rename) and are never half-written.

use std::fs::{self, File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Writes arbitrary bytes atomically (same temp-then-rename rule); used by write_image and by other
/// writers (stats JSON, checkpoints).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let temp = temp_path(path)?;
    // Created separately so that a failure here (missing directory, no permission) leaves nothing to
    // clean up, and so we never remove a file we did not create.
    let file = create_new(&temp).map_err(|e| Error::io(path, e))?;
    fill_and_rename(file, &temp, path, bytes).map_err(|e| {
        // Best effort: the error worth reporting is the one that made us give up.
        let _ = fs::remove_file(&temp);
        Error::io(path, e)
    })
}

/// Checks that a file can be created at `path` (any extension) without touching `path` itself.
pub fn check_writable(path: &Path) -> Result<()> {
    if path.is_dir() {
        return Err(Error::invalid(format!("{}: is a directory, expected a file name", path.display())));
    }
    let probe = temp_path(path)?;
    create_new(&probe).map_err(|e| Error::io(path, e))?;
    fs::remove_file(&probe).map_err(|e| Error::io(&probe, e))
}

/// `.{file_name}.tmp{pid}-{n}` next to `path`: the same directory keeps the final rename atomic (no
/// cross-device copy), the pid separates processes and the counter separates threads of this one.
fn temp_path(path: &Path) -> Result<PathBuf> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name =
        path.file_name().ok_or_else(|| Error::invalid(format!("{}: output path has no file name", path.display())))?;
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let temp_name = format!(".{}.tmp{}-{n}", name.to_string_lossy(), std::process::id());
    Ok(path.with_file_name(temp_name))
}

/// `create_new` so that a stale file with the same name (a pid reused after a crash) is never clobbered.
fn create_new(path: &Path) -> std::io::Result<File> {
    OpenOptions::new().write(true).create_new(true).open(path)
}

/// Writes and fsyncs before renaming, so that the rename cannot publish a file whose data is still only
/// in the page cache; the handle is closed before the rename, which Windows requires.
fn fill_and_rename(mut file: File, temp: &Path, path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    file.write_all(bytes)?;
    file.sync_all()?;
    drop(file);
    fs::rename(temp, path)
}
