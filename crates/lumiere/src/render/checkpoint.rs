//! Checkpoints: the exact accumulation state of a progressive render, so that a render killed at
//! any moment and resumed ends with the same image bytes as one never interrupted.
//!
//! Layout (little-endian): magic `LUMCKPT1`, u32 version, u64 scene and options fingerprints, u32
//! width, height and samples per pixel, u64 seed, rays and discarded samples, f64 elapsed seconds,
//! then per pixel four f64 (radiance sums and luminance second moment), then (since version 2) the
//! options as readable text (u32 length, UTF-8 `key: value` lines, see
//! [`super::fingerprint::options_description`]), then a u64 hash of all the preceding bytes. Files
//! are written atomically; a truncated or altered file is refused.

use crate::error::shown_path;
use std::path::Path;
use std::time::Duration;

use crate::error::{Error, Result};
use crate::render::RenderStats;
use crate::render::film::{Film, out_of_memory};
use crate::util::hash::hash_bytes;
use crate::util::write::write_atomically;

const MAGIC: &[u8; 8] = b"LUMCKPT1";
const VERSION: u32 = 2;
/// The longest options text a checkpoint may carry (a sanity bound for hostile files).
const MAX_OPTIONS_BYTES: usize = 1 << 16;
const HEADER_BYTES: usize = 8 + 4 + 8 + 8 + 4 + 4 + 4 + 8 + 8 + 8 + 8;

/// A saved render: its film, totals, and what it was rendered from.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    pub scene_fingerprint: u64,
    pub options_fingerprint: u64,
    pub seed: u64,
    /// The options as readable `key: value` lines, whose hash is `options_fingerprint`.
    pub options: String,
    pub film: Film,
    pub stats: RenderStats,
}

impl Checkpoint {
    pub fn encode(&self) -> Result<Vec<u8>> {
        let film = &self.film;
        let bytes = HEADER_BYTES + film.pixel_count() * 32 + 4 + self.options.len() + 8;
        let mut out = Vec::new();
        // Fallible: a checkpoint as large as the film must not abort a render that fits.
        out.try_reserve_exact(bytes)
            .map_err(|_| out_of_memory(film.width, film.height, bytes, "the checkpoint's encoding"))?;
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&self.scene_fingerprint.to_le_bytes());
        out.extend_from_slice(&self.options_fingerprint.to_le_bytes());
        for v in [film.width, film.height, film.samples] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [self.seed, self.stats.rays, film.discarded] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.stats.elapsed.as_secs_f64().to_le_bytes());
        for (sum, sq) in film.moments() {
            for v in sum.into_iter().chain([sq]) {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        out.extend_from_slice(&(self.options.len() as u32).to_le_bytes());
        out.extend_from_slice(self.options.as_bytes());
        let hash = hash_bytes(&out);
        out.extend_from_slice(&hash.to_le_bytes());
        Ok(out)
    }

    pub fn save(&self, path: &Path) -> Result<()> {
        write_atomically(path, &self.encode()?)
    }

    /// Refuses a `path` that holds a file other than a checkpoint, before a render that saves its
    /// checkpoint there: a slip (`--checkpoint notes.txt`) would replace that file. A missing or
    /// empty file is taken (nothing to lose), and so is anything but a regular file, which the
    /// writer refuses itself ([`crate::util::write::check_writable`]).
    pub fn check_replaceable(path: &Path) -> Result<()> {
        use std::io::Read;
        if !std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.len() > 0) {
            return Ok(());
        }
        let mut head = Vec::with_capacity(MAGIC.len());
        let read = std::fs::File::open(path).and_then(|file| file.take(MAGIC.len() as u64).read_to_end(&mut head));
        read.map_err(|e| Error::io(path, e))?;
        if head != MAGIC {
            return Err(Error::invalid(format!(
                "{}: the file exists and is not a lumiere checkpoint, which the render would replace; remove it or name another checkpoint",
                shown_path(path)
            )));
        }
        Ok(())
    }

    pub fn load(path: &Path) -> Result<Checkpoint> {
        let bytes = crate::util::read::read_regular_file(path).map_err(|e| Error::io(path, e))?;
        Checkpoint::decode(&bytes, path)
    }

    /// Parses checkpoint bytes; `path` names the file in errors. Never panics on bad input.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<Checkpoint> {
        let bad = |what: &str| Error::invalid(format!("{}: not a valid lumiere checkpoint ({what})", shown_path(path)));
        if bytes.len() < HEADER_BYTES + 8 || &bytes[..8] != MAGIC {
            return Err(bad("no checkpoint header"));
        }
        let (body, hash) = bytes.split_at(bytes.len() - 8);
        if hash_bytes(body).to_le_bytes() != hash {
            return Err(bad("truncated or corrupted: its checksum does not match"));
        }
        let mut reader = Reader { bytes: &body[8..] };
        match reader.u32() {
            VERSION => {}
            1 => return Err(bad("version 1, written by an older lumiere; render it again")),
            other => return Err(bad(&format!("unsupported version {other}"))),
        }
        let (scene_fingerprint, options_fingerprint) = (reader.u64(), reader.u64());
        let (width, height, samples) = (reader.u32(), reader.u32(), reader.u32());
        let (seed, rays, discarded) = (reader.u64(), reader.u64(), reader.u64());
        let elapsed = reader.f64();
        // In u128: width * height * 32 overflows u64 for the largest u32 sizes.
        let pixels = width as u128 * height as u128;
        let pixel_bytes = pixels * 32;
        if width == 0 || height == 0 || (reader.bytes.len() as u128) < pixel_bytes + 4 {
            return Err(bad("its size does not match its pixel data"));
        }
        let (pixel_data, text) = reader.bytes.split_at(pixel_bytes as usize);
        let (length, text) = text.split_at(4);
        let length = u32::from_le_bytes(length.try_into().unwrap_or_default()) as usize;
        if length != text.len() || length > MAX_OPTIONS_BYTES {
            return Err(bad("its size does not match its pixel data"));
        }
        let Ok(options) = String::from_utf8(text.to_vec()) else {
            return Err(bad("its options are not text"));
        };
        reader.bytes = pixel_data;
        let Ok(elapsed) = Duration::try_from_secs_f64(elapsed) else {
            return Err(bad("invalid elapsed time"));
        };
        let moments = std::iter::from_fn(|| Some(([reader.f64(), reader.f64(), reader.f64()], reader.f64())));
        let film = Film::from_moments(width, height, samples, discarded, moments)?;
        // The checksum finds accidents, not forgeries: a film no render can hold is refused too.
        // Kept samples are finite and at least +0 in every channel, so are their sums and
        // squared luminances, and a film of no samples holds zeros (a NaN or negative sum gave
        // a NaN pixel reported as "relative error 0", sums over 0 samples an AO of 1.5).
        let possible = |v: f64| v.is_finite() && v >= 0.0 && (samples > 0 || v == 0.0);
        if let Some(pixel) = film.moments().position(|(sum, sq)| !sum.into_iter().chain([sq]).all(possible)) {
            let what = if samples == 0 { "sums in a film of no samples" } else { "a negative or non-finite sum" };
            return Err(bad(&format!("pixel {pixel} holds {what}")));
        }
        let stats = RenderStats { rays, elapsed };
        Ok(Checkpoint { scene_fingerprint, options_fingerprint, seed, options, film, stats })
    }
}

/// Reads fixed-size fields; the caller has checked the length, so reads never run out.
struct Reader<'a> {
    bytes: &'a [u8],
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        let n = N.min(self.bytes.len());
        out[..n].copy_from_slice(&self.bytes[..n]);
        self.bytes = &self.bytes[n..];
        out
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }
}

/// An option's value as a user names it, for the refusal's message: the technique's record
/// (`AmbientOcclusion(AmbientOcclusion { samples: 2, distance: 0.5 })`) as its flags
/// (`--mode ao --samples 2 --ao-distance 0.5`; settings no flag sets, in parentheses), the
/// sampler's as its `--sampler` name.
/// Anything else, or a description from another version that does not parse, stays as written.
/// Only the message is reworded: the description itself keeps the records' Debug text, since it
/// is what a checkpoint's options fingerprint hashes, and checkpoints already written must resume.
fn readable(key: &str, value: &str) -> String {
    match key {
        "technique" => {
            let (variant, rest) = value.split_once('(').unwrap_or((value, ""));
            let mode = match variant {
                "Hits" => "hits",
                "Materials" => "materials",
                "Shadows" => "shadows",
                "Direct" => "direct",
                "AmbientOcclusion" => "ao",
                "Path" => "path",
                _ => return value.to_string(),
            };
            let fields = rest.split_once('{').and_then(|(_, fields)| fields.rsplit_once('}')).map_or("", |(f, _)| f);
            let (mut flags, mut others) = (format!("--mode {mode}"), Vec::new());
            for (name, value) in fields.split(", ").filter_map(|field| field.trim().split_once(": ")) {
                let value = kebab_case(value);
                match name {
                    "samples" => flags += &format!(" --samples {value}"),
                    "light_sampling" => flags += &format!(" --light-sampling {value}"),
                    // No limit, the default, is no flag (`--ao-distance` takes finite values).
                    "distance" if value == "inf" => {}
                    "distance" => flags += &format!(" --ao-distance {value}"),
                    "max_depth" => flags += &format!(" --max-depth {value}"),
                    _ => others.push(format!("{} {value}", name.replace('_', "-"))),
                }
            }
            if others.is_empty() { flags } else { format!("{flags} ({})", others.join(", ")) }
        }
        "sampler" => value.to_ascii_lowercase(),
        _ => value.to_string(),
    }
}

/// A Debug value as a flag's value: an enum variant's CamelCase name in kebab case (`PerLight` ->
/// `per-light`, the `--light-sampling` value), anything else (a number) as it is.
fn kebab_case(value: &str) -> String {
    if !value.starts_with(|c: char| c.is_ascii_uppercase()) {
        return value.to_string();
    }
    let mut out = String::new();
    for (i, c) in value.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('-');
        }
        out.push(c.to_ascii_lowercase());
    }
    out
}

/// The longest option value a refused resume quotes.
const QUOTED_VALUE_CHARS: usize = 120;

/// The lines of two option descriptions that differ, as `key (checkpoint: …; now: …)`, in the
/// order of the current description; a value too long to read in a one-line message (the
/// camera's matrices) is only said to differ.
pub fn differing_options(saved: &str, now: &str) -> Vec<String> {
    let parse = |text: &str| -> Vec<(String, String)> {
        text.lines().filter_map(|l| l.split_once(": ")).map(|(k, v)| (k.to_string(), v.to_string())).collect()
    };
    let (saved, now) = (parse(saved), parse(now));
    let value = |list: &[(String, String)], key: &str| {
        list.iter().find(|(k, _)| k == key).map_or("(none)".to_string(), |(_, v)| v.clone())
    };
    let mut keys: Vec<&str> = now.iter().map(|(k, _)| k.as_str()).collect();
    keys.extend(saved.iter().map(|(k, _)| k.as_str()).filter(|k| !now.iter().any(|(n, _)| n == k)));
    keys.into_iter()
        .filter_map(|key| {
            let (a, b) = (value(&saved, key), value(&now, key));
            (a != b).then(|| {
                let (a, b) = (readable(key, &a), readable(key, &b));
                if a.len().max(b.len()) > QUOTED_VALUE_CHARS {
                    format!("{key} (differs from the checkpoint's)")
                } else {
                    format!("{key} (checkpoint: {a}; now: {b})")
                }
            })
        })
        .collect()
}
