//! Image files out: sRGB PNG, linear EXR and PFM, always written atomically.
//!
//! Every writer encodes the whole file in memory first and hands the bytes to [`write_atomically`], so
//! a crash, a full disk or a killed process never leaves a half-written image where a previous good
//! one used to be: readers see either the old file or the complete new one.

use crate::error::{shown_bytes, shown_path};
use std::io::Cursor;
use std::path::Path;
use std::sync::OnceLock;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::util::write::{check_writable, write_atomically};

/// How a PNG stores linear radiance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PngEncoding {
    /// sRGB transfer curve, rounded to nearest 8-bit value (the default for viewing).
    #[default]
    Srgb,
    /// gKit's convention: floor(255 * clamp(c, 0, 1)), no gamma, for side-by-side comparisons with gKit renders.
    GkitLinear,
}

/// How PNG maps radiance above 1 into the displayable range (EXR and PFM keep linear values).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Tonemap {
    /// Clip each channel to `[0, 1]`: the lab's images, exact for values already in range.
    #[default]
    Clamp,
    /// A filmic curve: Narkowicz's 2015 fit of the ACES reference rendering transform, applied per
    /// channel to `0.6 × exposed radiance` (the scale of his fit); highlights roll off smoothly
    /// instead of clipping.
    Aces,
}

impl Tonemap {
    #[inline]
    fn apply(self, c: f32) -> f32 {
        match self {
            Tonemap::Clamp => c,
            Tonemap::Aces => {
                // The curve passes 1 near x = 7.24 and stays above it: capping x at 16 changes
                // no result but keeps its squares finite (from x ~ 1e19 they overflowed, and
                // inf / inf turned the brightest pixels black).
                let x = (0.6 * c.max(0.0)).min(16.0);
                (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
            }
        }
    }
}

/// What a PNG shows of linear radiance: `radiance × 2^exposure`, tone mapped, then encoded.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PngStyle {
    pub encoding: PngEncoding,
    /// Exposure in stops (EV): each +1 doubles the radiance before tone mapping.
    pub exposure: f32,
    pub tonemap: Tonemap,
}

impl PngStyle {
    /// The widest exposure either way, in stops: `2^64` brings the faintest normal radiance an
    /// f32 holds near 1, and takes the brightest far past white.
    pub const MAX_EXPOSURE: f32 = 64.0;
}

impl From<PngEncoding> for PngStyle {
    fn from(encoding: PngEncoding) -> Self {
        PngStyle { encoding, ..PngStyle::default() }
    }
}

/// The file formats we write, chosen by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Png,
    Exr,
    Pfm,
}

/// Named in the error for an unsupported extension, so the user sees the choices.
const SUPPORTED: &str = ".png, .exr, .pfm";

/// Writes `pixels` (linear RGB, `width * height`, row 0 = top of the picture) to `path`, choosing the
/// format from the extension (case-insensitive): `.png` (8-bit, `png` encoding), `.exr` (linear 32-bit
/// float RGB), `.pfm` (linear float, Portable Float Map). Any other extension -> Error::invalid naming the
/// supported ones. The file appears atomically: bytes go to a temporary file in the same directory, which
/// is renamed over `path` only after a complete write (and fsync of the file); on any failure the temporary
/// file is removed and `path` is untouched.
pub fn write_image(path: &Path, width: u32, height: u32, pixels: &[Vec3], png: impl Into<PngStyle>) -> Result<()> {
    write_atomically(path, &encode_image(path, width, height, pixels, png)?)
}

/// The bytes [`write_image`] writes to `path`, without writing them: for a caller that may give
/// up while a large image encodes (Python's Ctrl-C), leaving the file as it was.
pub fn encode_image(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[Vec3],
    png: impl Into<PngStyle>,
) -> Result<Vec<u8>> {
    let format = format_of(path)?;
    check_dimensions(width, height, pixels.len())?;
    check_encoding_memory(path, width, height, format.encoding_bytes_per_pixel())?;
    match format {
        Format::Png => encode_png(path, width, height, pixels, png.into()),
        Format::Exr => encode_exr(path, width, height, pixels),
        Format::Pfm => encode_pfm(path, width, height, pixels),
    }
}

impl Format {
    /// The most an encoder holds at once per pixel, besides the pixels: the PFM's file; the PNG's
    /// 8-bit values and its compressed stream (deflate's stored blocks at worst: 3 bytes and a
    /// little); the EXR's file (12 bytes uncompressed at worst), which its buffer may double while
    /// it grows, and its blocks on the way.
    fn encoding_bytes_per_pixel(self) -> u64 {
        match self {
            Format::Pfm => 12,
            Format::Png => 8,
            Format::Exr => 40,
        }
    }
}

/// Refuses, before encoding, an image whose encoding (`bytes_per_pixel`) would not fit in the
/// memory left: an error naming it, not the allocator's abort (a renderer's film was checked
/// before its render, but an image written from Python, or after other processes took the
/// memory, was not).
fn check_encoding_memory(path: &Path, width: u32, height: u32, bytes_per_pixel: u64) -> Result<()> {
    let needed = width as u128 * height as u128 * bytes_per_pixel as u128;
    let Some(available) = crate::util::read::available_for(needed) else { return Ok(()) };
    if needed <= available as u128 {
        return Ok(());
    }
    Err(Error::invalid(format!(
        "{}: encoding a {width}x{height} image needs about {} of memory, but only {} is available",
        shown_path(path),
        shown_bytes(needed),
        shown_bytes(available)
    )))
}

/// Checks before a long render that `path` has a supported extension and its directory exists and is writable
/// (create and delete a probe temp file), so a render does not run for minutes and then fail.
pub fn check_output_path(path: &Path) -> Result<()> {
    // The target's kind first: a folder (`-o renders/`) is named as one, not as a name without
    // an extension.
    check_writable(path)?;
    format_of(path).map(|_| ())
}

/// sRGB encoding of one linear channel to 8 bits (IEC 61966-2-1), clamped; NaN -> 0.
///
/// Exact (identical to rounding the f64 formula), at the cost of one table lookup and one comparison:
/// a 4096-bucket table gives the code at each bucket's lower edge, and since the curve's steepest slope
/// (12.92 * 255 codes per unit) crosses less than one code per bucket, at most one threshold can lie
/// inside a bucket, which the comparison resolves.
pub fn linear_to_srgb8(c: f32) -> u8 {
    if c.is_nan() || c <= 0.0 {
        return 0;
    }
    if c >= 1.0 {
        return 255;
    }
    let table = srgb_table();
    // c < 1, so c * 4096 < 4096 exactly (the product of an f32 below 1 and a power of two is exact).
    let code = table.bucket_code[(c * SRGB_BUCKETS as f32) as usize];
    code + u8::from(c >= table.threshold[usize::from(code)])
}

/// Number of buckets over [0, 1); must stay above 12.92 * 255 ≈ 3295 for one comparison to suffice.
const SRGB_BUCKETS: usize = 4096;

/// Precomputed data for [`linear_to_srgb8`].
struct SrgbTable {
    /// `threshold[k]`: the smallest f32 that encodes to code k + 1; `threshold[255]` is +inf.
    threshold: [f32; 256],
    /// The code of each bucket's lower edge `i / SRGB_BUCKETS`.
    bucket_code: [u8; SRGB_BUCKETS],
}

/// Built once on first use; 5 KB, shared by all threads.
fn srgb_table() -> &'static SrgbTable {
    static TABLE: OnceLock<SrgbTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut threshold = [f32::INFINITY; 256];
        for (k, t) in threshold.iter_mut().take(255).enumerate() {
            *t = srgb_threshold(k as u8 + 1);
        }
        let mut bucket_code = [0u8; SRGB_BUCKETS];
        for (i, code) in bucket_code.iter_mut().enumerate() {
            let edge = i as f32 / SRGB_BUCKETS as f32;
            *code = threshold.partition_point(|&t| t <= edge) as u8;
        }
        SrgbTable { threshold, bucket_code }
    })
}

/// The smallest f32 whose exact sRGB value rounds to at least `code` (i.e. reaches `code - 0.5`).
///
/// Starts from the inverse curve in f64, then nudges by single ulps so that the table agrees with the
/// forward formula even where the f64 -> f32 rounding of the inverse lands on the wrong side.
fn srgb_threshold(code: u8) -> f32 {
    let target = (f64::from(code) - 0.5) / 255.0;
    let mut t = srgb_to_linear_f64(target) as f32;
    while srgb_f64(f64::from(t)) < target {
        t = t.next_up();
    }
    while srgb_f64(f64::from(t.next_down())) >= target {
        t = t.next_down();
    }
    t
}

/// The IEC 61966-2-1 forward curve, in f64 so that the table is exact.
fn srgb_f64(c: f64) -> f64 {
    if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Inverse of [`srgb_f64`]; only seeds the threshold search.
fn srgb_to_linear_f64(v: f64) -> f64 {
    if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

/// gKit's 8-bit convention; NaN -> 0 and +inf -> 255 like the sRGB path.
fn gkit_linear8(c: f32) -> u8 {
    if c.is_nan() { 0 } else { (255.0 * c.clamp(0.0, 1.0)) as u8 }
}

/// Picks the format from the extension, case-insensitively.
fn format_of(path: &Path) -> Result<Format> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(Format::Png),
        Some("exr") => Ok(Format::Exr),
        Some("pfm") => Ok(Format::Pfm),
        Some(other) => Err(Error::invalid(format!(
            "{}: .{other} is not an image format lumiere writes (supported: {SUPPORTED})",
            shown_path(path)
        ))),
        None => Err(Error::invalid(format!(
            "{}: the file name has no extension, so the image format is unknown (supported: {SUPPORTED})",
            shown_path(path)
        ))),
    }
}

/// Refuses empty images and buffers that do not match the stated size, before anything is encoded.
fn check_dimensions(width: u32, height: u32, len: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::invalid(format!("image size {width}x{height} has a zero dimension")));
    }
    let expected = (width as usize).checked_mul(height as usize);
    if expected != Some(len) {
        return Err(Error::invalid(format!("image is {width}x{height} but {len} pixels were given")));
    }
    Ok(())
}

fn encode_png(path: &Path, width: u32, height: u32, pixels: &[Vec3], style: PngStyle) -> Result<Vec<u8>> {
    let encode: fn(f32) -> u8 = match style.encoding {
        PngEncoding::Srgb => linear_to_srgb8,
        PngEncoding::GkitLinear => gkit_linear8,
    };
    let scale = style.exposure.exp2();
    let map = |c: f32| encode(style.tonemap.apply(if style.exposure == 0.0 { c } else { c * scale }));
    let raw: Vec<u8> = pixels.iter().flat_map(|p| p.to_array().map(map)).collect();
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    // The sRGB chunk tells viewers how to show the values; gKit's linear bytes get none, since they
    // are not sRGB-encoded.
    if style.encoding == PngEncoding::Srgb {
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    let failed = |e: png::EncodingError| Error::invalid(format!("{}: cannot encode PNG: {e}", shown_path(path)));
    let mut writer = encoder.write_header().map_err(failed)?;
    writer.write_image_data(&raw).map_err(failed)?;
    writer.finish().map_err(failed)?;
    Ok(bytes)
}

/// The exr crate's default lossless encoding (run-length coded tiles of 64x64), with its tiles
/// stored in increasing order: by default the order is left unspecified and its parallel writer
/// stores each tile as it finishes, so two writes of one image gave different bytes.
fn exr_encoding() -> exr::prelude::Encoding {
    exr::prelude::Encoding { line_order: exr::prelude::LineOrder::Increasing, ..exr::prelude::Encoding::FAST_LOSSLESS }
}

/// 32-bit float RGB with the exr crate's default lossless compression, so values survive bit for bit.
fn encode_exr(path: &Path, width: u32, height: u32, pixels: &[Vec3]) -> Result<Vec<u8>> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let w = width as usize;
    let channels = SpecificChannels::rgb(|pos: Vec2<usize>| {
        let p = pixels[pos.y() * w + pos.x()];
        (p.x, p.y, p.z)
    });
    let mut cursor = Cursor::new(Vec::new());
    Image::from_encoded_channels((w, height as usize), exr_encoding(), channels)
        .write()
        .to_buffered(&mut cursor)
        .map_err(|e| Error::invalid(format!("{}: cannot encode EXR: {e}", shown_path(path))))?;
    Ok(cursor.into_inner())
}

/// The name of the EXR layer that holds the image before denoising, beside the denoised one.
pub const NOISY_LAYER: &str = "noisy";

/// The channels of a colour: the image's own, and those of a colour layer (`albedo`, `noisy`).
pub const RGB_CHANNELS: &[&str] = &["R", "G", "B"];

/// One set of extra channels of an EXR file: an arbitrary output (AOV) beside the image.
#[derive(Clone, Copy, Debug)]
pub struct ExrLayer<'a> {
    /// The prefix of its channels (`albedo` gives `albedo.R`, `albedo.G`, `albedo.B`).
    pub name: &'a str,
    /// The channel names after the prefix, one per component used (`["R", "G", "B"]`, `["Z"]`).
    pub channels: &'a [&'a str],
    /// Per pixel, row 0 at the top; channel `i` reads component `i`.
    pub pixels: &'a [Vec3],
}

/// Writes an EXR with the image as `R`, `G`, `B` and each layer's channels beside it (32-bit
/// float, lossless), atomically. Denoisers and compositors read the layers by name.
pub fn write_exr_with_layers(path: &Path, width: u32, height: u32, pixels: &[Vec3], layers: &[ExrLayer]) -> Result<()> {
    use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, Image, WritableImage};
    if format_of(path)? != Format::Exr {
        return Err(Error::invalid(format!("{}: extra layers (AOVs) need an .exr output", shown_path(path))));
    }
    check_dimensions(width, height, pixels.len())?;
    // Each layer's channels are copied out of their pixels before the file is encoded.
    let copies = 12 * (1 + layers.len() as u64);
    check_encoding_memory(path, width, height, Format::Exr.encoding_bytes_per_pixel() + copies)?;
    let main = ExrLayer { name: "", channels: RGB_CHANNELS, pixels };
    let mut channels = Vec::new();
    for layer in std::iter::once(&main).chain(layers) {
        check_dimensions(width, height, layer.pixels.len())?;
        for (component, channel) in layer.channels.iter().enumerate().take(3) {
            let name = if layer.name.is_empty() { channel.to_string() } else { format!("{}.{channel}", layer.name) };
            let samples: Vec<f32> = layer.pixels.iter().map(|p| p[component]).collect();
            channels.push(AnyChannel::new(name.as_str(), FlatSamples::F32(samples)));
        }
    }
    let mut cursor = Cursor::new(Vec::new());
    Image::from_encoded_channels((width as usize, height as usize), exr_encoding(), AnyChannels::sort(channels.into()))
        .write()
        .to_buffered(&mut cursor)
        .map_err(|e| Error::invalid(format!("{}: cannot encode EXR: {e}", shown_path(path))))?;
    write_atomically(path, &cursor.into_inner())
}

/// Portable Float Map: a negative scale means little-endian, and scanlines run bottom to top.
fn encode_pfm(path: &Path, width: u32, height: u32, pixels: &[Vec3]) -> Result<Vec<u8>> {
    let header = format!("PF\n{width} {height}\n-1.0\n");
    let size = header.len() + pixels.len() * 12;
    let mut bytes = Vec::new();
    bytes.try_reserve_exact(size).map_err(|_| {
        let message = format!("{}: out of memory for the PFM's {}", shown_path(path), shown_bytes(size as u128));
        Error::invalid(message)
    })?;
    bytes.extend_from_slice(header.as_bytes());
    for row in pixels.chunks_exact(width as usize).rev() {
        for value in row.iter().flat_map(|p| p.to_array()) {
            bytes.extend_from_slice(&value.to_le_bytes());
        }
    }
    Ok(bytes)
}
