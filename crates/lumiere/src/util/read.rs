//! Every input file goes through [`read_regular_file`]: only regular files are read (a FIFO, a
//! device, a directory, a socket or a terminal is refused without blocking), and never more than
//! the size the file had when it was opened. Compressed inputs are inflated only up to a memory cap.

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

use crate::error::shown_bytes;

/// Reads the regular file at `path` whole, refusing anything else *before* reading from it.
///
/// * The type is checked before the file is opened (following symlinks): a FIFO, a character or
///   block device (`/dev/zero`, `/dev/urandom`, a terminal), a directory or a socket is refused
///   with an error saying what it is ("is a FIFO, not a regular file"), so that no read can block
///   forever or grow without end.
/// * On unix the file is opened with `O_NONBLOCK | O_NOCTTY`, so that a file swapped for a FIFO
///   between the check and the open cannot block the open either, and its type is checked again
///   on the open descriptor.
/// * At most the size the file had when opened is read: a file that grows while it is read is
///   cut there. A file larger than the memory this process can get is refused.
pub fn read_regular_file(path: &Path) -> io::Result<Vec<u8>> {
    refuse_special(&std::fs::metadata(path)?)?;
    let mut file = open_without_blocking(path)?;
    let metadata = file.metadata()?;
    refuse_special(&metadata)?;
    let size = metadata.len();
    if let Some(available) = available_memory()
        && size > available
    {
        return Err(io::Error::new(
            io::ErrorKind::OutOfMemory,
            format!(
                "is {}, more than the {} of memory available; refusing it",
                shown_bytes(size),
                shown_bytes(available)
            ),
        ));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
    (&mut file).take(size).read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// An error unless `metadata` is a regular file's, saying what the file is instead.
pub fn refuse_special(metadata: &std::fs::Metadata) -> io::Result<()> {
    let kind = metadata.file_type();
    if kind.is_file() {
        return Ok(());
    }
    let what = if kind.is_dir() { "a directory" } else { special_kind(&kind) };
    Err(io::Error::new(io::ErrorKind::InvalidInput, format!("is {what}, not a regular file")))
}

#[cfg(unix)]
fn special_kind(kind: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if kind.is_fifo() {
        "a FIFO"
    } else if kind.is_char_device() {
        "a character device"
    } else if kind.is_block_device() {
        "a block device"
    } else if kind.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn special_kind(_: &std::fs::FileType) -> &'static str {
    "a special file"
}

#[cfg(unix)]
fn open_without_blocking(path: &Path) -> io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt;
    // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer. It changes nothing
    // for reads of regular files. O_NOCTTY: a terminal opened by a race never becomes ours.
    std::fs::OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY).open(path)
}

#[cfg(not(unix))]
fn open_without_blocking(path: &Path) -> io::Result<File> {
    File::open(path)
}

/// Reads an input file whole through [`read_regular_file`], gunzipping it when its name ends with
/// `.gz` (see [`gunzip`]; inflation stops at a quarter of [`available_memory`]).
pub fn read_input(path: &Path) -> io::Result<Vec<u8>> {
    read_input_with_memory(path, available_memory())
}

/// [`read_input`] with the memory available given (`None`: unknown, 16 GiB is assumed), so that
/// tests can exercise the caps without allocating gigabytes.
pub fn read_input_with_memory(path: &Path, available: Option<u64>) -> io::Result<Vec<u8>> {
    let raw = read_regular_file(path)?;
    if !path.extension().is_some_and(|extension| extension.eq_ignore_ascii_case("gz")) {
        return Ok(raw);
    }
    // A few kilobytes of gzip can expand to gigabytes: stop at a quarter of the free memory, which
    // leaves room for the mesh parsed from the text.
    gunzip(&raw, available.unwrap_or(16 << 30) / 4)
}

/// Inflates a gzip stream of one or more members, refusing to produce more than `limit` bytes.
///
/// Zero bytes after the last member are padding (some tools write whole blocks) and are ignored,
/// as GNU gzip does. Any other bytes after a member must start another member; otherwise the file
/// is refused, saying how many bytes follow the stream and where.
pub fn gunzip(raw: &[u8], limit: u64) -> io::Result<Vec<u8>> {
    if raw.is_empty() {
        return Err(io::Error::new(io::ErrorKind::InvalidData, "is empty, not a gzip stream"));
    }
    // A member's last 4 bytes hold its size modulo 2^32: for the usual one-member file, the size
    // of the text. Reserving it (up to the limit; it is only a hint) allocates the buffer once,
    // instead of doubling it, which holds the old and the new buffer at once.
    let last_size = raw.last_chunk::<4>().map_or(0, |size| u64::from(u32::from_le_bytes(*size)));
    let mut bytes = Vec::new();
    let _ = bytes.try_reserve_exact(usize::try_from(last_size.min(limit)).unwrap_or(0));
    let mut rest = raw;
    loop {
        let offset = raw.len() - rest.len();
        let mut member = flate2::bufread::GzDecoder::new(&mut rest);
        let room = limit.saturating_sub(bytes.len() as u64);
        (&mut member).take(room.saturating_add(1)).read_to_end(&mut bytes).map_err(|error| {
            let what =
                if offset == 0 { "not a valid gzip file".to_string() } else { format!("gzip member at byte {offset}") };
            io::Error::new(error.kind(), format!("{what}: {error}"))
        })?;
        if bytes.len() as u64 > limit {
            return Err(io::Error::new(
                io::ErrorKind::OutOfMemory,
                format!(
                    "decompresses to more than {}, over a quarter of the free memory; refusing it",
                    shown_bytes(limit)
                ),
            ));
        }
        drop(member);
        if rest.iter().all(|&b| b == 0) {
            return Ok(bytes);
        }
        if !rest.starts_with(&[0x1f, 0x8b]) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "{} bytes after the end of the gzip stream (from byte {}) are not gzip data; the file is corrupt \
                     or has something appended",
                    rest.len(),
                    raw.len() - rest.len()
                ),
            ));
        }
    }
}

/// Requests smaller than this are not checked against the memory left ([`available_for`]):
/// reading it costs three /proc files, and fuzzing parses millions of tiny files.
const UNCHECKED_BYTES: u128 = 16 << 20;

/// The memory this process can still get ([`available_memory`]), to check a request of `needed`
/// bytes against; `None` for a request below 16 MiB, not worth the reading, or where it is unknown.
pub fn available_for(needed: u128) -> Option<u64> {
    if needed < UNCHECKED_BYTES { None } else { available_memory() }
}

/// Memory this process can still get: `MemAvailable` from /proc/meminfo, capped by what is left
/// of the address-space limit (`ulimit -v`, from /proc/self/limits, less `VmSize` from
/// /proc/self/status); `None` where neither is known.
pub fn available_memory() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|info| {
        let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
        Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
    });
    let address_space = std::fs::read_to_string("/proc/self/limits").ok().and_then(|limits| {
        let line = limits.lines().find(|l| l.starts_with("Max address space"))?;
        // "Max address space  <soft> <hard> bytes"; "unlimited" does not parse and gives None.
        let limit = line.split_whitespace().nth(3)?.parse::<u64>().ok()?;
        let used = std::fs::read_to_string("/proc/self/status").ok().and_then(|status| {
            let line = status.lines().find(|l| l.starts_with("VmSize:"))?;
            Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
        });
        Some(limit.saturating_sub(used.unwrap_or(0)))
    });
    match (meminfo, address_space) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}
