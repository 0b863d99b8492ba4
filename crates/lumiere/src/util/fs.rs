//! File-system rules shared by every reader and writer: outputs appear atomically (temporary file,
//! fsync, rename) and never half-written; compressed inputs are inflated only up to a memory cap.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Read, Write};
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

/// Reads an input file whole, gunzipping it when its name ends with `.gz` (multi-member streams included).
pub fn read_input(path: &Path) -> io::Result<Vec<u8>> {
    let raw = std::fs::read(path)?;
    if !path.extension().is_some_and(|extension| extension.eq_ignore_ascii_case("gz")) {
        return Ok(raw);
    }
    // A few kilobytes of gzip can expand to gigabytes: stop at a quarter of the free memory, which
    // leaves room for the mesh parsed from the text.
    let limit = available_memory().unwrap_or(16 << 30) / 4;
    let mut bytes = Vec::new();
    flate2::read::MultiGzDecoder::new(&raw[..]).take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(io::Error::other(format!(
            "decompresses to more than {:.1} GiB, over a quarter of the free memory; refusing it",
            limit as f64 / (1u64 << 30) as f64
        )));
    }
    Ok(bytes)
}

/// Memory this process can still get: `MemAvailable` from /proc/meminfo, capped by the
/// address-space limit (`ulimit -v`) from /proc/self/limits; `None` where neither is known.
pub fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|info| {
        let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
        Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
    });
    let address_space = std::fs::read_to_string("/proc/self/limits").ok().and_then(|limits| {
        let line = limits.lines().find(|l| l.starts_with("Max address space"))?;
        // "Max address space  <soft> <hard> bytes"; "unlimited" does not parse and gives None.
        line.split_whitespace().nth(3)?.parse::<u64>().ok()
    });
    match (meminfo, address_space) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}
