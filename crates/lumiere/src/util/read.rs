//! Inputs are read whole, and compressed ones inflated only up to a memory cap.

use std::io::{self, Read};
use std::path::Path;

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
