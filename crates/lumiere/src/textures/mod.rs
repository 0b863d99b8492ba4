//! Textures: image files decoded once, when the world is built, into linear RGB (8-bit files keep
//! their codes and decode them through a table at each lookup; alpha where the file has one), and
//! looked up with bilinear filtering and repeat wrapping.
//!
//! * **Files.** PNG, JPEG, BMP and TGA (8 or 16 bits per channel, grey or colour, with or
//!   without alpha), recognised from their content (TGA, which has no signature, from its
//!   extension).
//! * **Colour.** These formats store sRGB-encoded values; each channel is decoded with the exact
//!   sRGB curve (IEC 61966-2-1: linear below 0.04045, a 2.4 power above), so texture values are
//!   reflectances, like `Kd`. Alpha is linear coverage and is kept as is, for cutouts (`map_d`,
//!   [`Texture::sample_coverage`]).
//! * **Coordinates.** OBJ's texture origin is the bottom-left corner: `v = 0` is the *last* row of
//!   the image, `v = 1` the first. Texel `(x, y)` (column, row from the top) has its centre at
//!   `u = (x + ½) / width`, `v = 1 − (y + ½) / height`. Outside `[0, 1)` coordinates repeat; at the
//!   borders, bilinear filtering blends with the opposite edge, as repeat wrapping implies.
//!   NaN, infinite and huge coordinates read a valid texel and never panic.
//! * **Loading.** [`TextureSet::load`] decodes every distinct file once, in parallel; a file that
//!   cannot be read or decoded costs one warning naming it, and the materials that use it keep
//!   their `Kd`. Image sizes are checked against [`MAX_TEXELS`] from the header, before decoding,
//!   and so is the memory each decoding takes, against what is left (in file order, so that
//!   which files fit never depends on the threads): a file that does not fit is one warning.
//!
//! How `World` uses it (simplified; `World::new` decodes, `World::bsdf` looks up):
//!
//! ```ignore
//! let (texture_of_material, textures, warnings) =
//!     TextureSet::for_materials(scene.materials.iter().map(|m| m.map_kd.as_deref()));
//! // at a hit with material m and interpolated texture coordinates uv:
//! let base = match texture_of_material[m] { Some(id) => textures.sample(id, uv), None => material.kd };
//! let bsdf = material.bsdf(base);
//! ```

mod embedded;

pub use embedded::EmbeddedImages;

use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use glam::{Vec2, Vec3};
use image::{DynamicImage, ImageDecoder, ImageFormat, ImageReader, Limits};
use rayon::prelude::*;

use crate::util::hash::hash_bytes;
use crate::util::memory::prefetch;

/// The most texels (width × height) an image may have: 2²⁶, e.g. 8192 × 8192, which takes 1 GiB
/// as `f32` RGBA. Larger images are refused from their header, before any decoding.
pub const MAX_TEXELS: u64 = 1 << 26;

/// The largest texture file read, in bytes (a compressed image of [`MAX_TEXELS`] is far smaller).
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// An image decoded to linear `f32` RGB, with its alpha channel when the file has one.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: u32,
    height: u32,
    /// Row-major from the top row of the image, as stored in the file.
    rgb: Texels,
    alpha: Option<Vec<f32>>,
}

/// The colour of every texel: the 8-bit sRGB codes of most files, decoded through the table at
/// each lookup (the same `f32` values, in a third of the memory: path tracing reads texels at
/// random, and their cache misses were most of a textured scene's shading), or linear `f32` (16-bit
/// files, [`Texture::from_linear`]).
#[derive(Clone, Debug, PartialEq)]
enum Texels {
    /// RGB codes and a padding byte, so that a texel is one aligned 4-byte load.
    Srgb8 {
        codes: Vec<[u8; 4]>,
        table: &'static [f32; 256],
    },
    Linear(Vec<Vec3>),
}

impl Texels {
    #[inline]
    fn get(&self, i: usize) -> Vec3 {
        match self {
            Texels::Srgb8 { codes, table } => {
                let [r, g, b, _] = codes[i];
                Vec3::new(table[r as usize], table[g as usize], table[b as usize])
            }
            Texels::Linear(rgb) => rgb[i],
        }
    }

    #[inline]
    fn prefetch(&self, i: usize) {
        match self {
            Texels::Srgb8 { codes, .. } => prefetch(&codes[i]),
            Texels::Linear(rgb) => prefetch(&rgb[i]),
        }
    }

    /// The values the file stores for texel `i`, without sRGB decoding: data such as a mask or a
    /// roughness is not a colour. 8-bit codes are kept, over 255; 16-bit texels were decoded when
    /// loaded, and the encoding curve gives their file values back (to within rounding), so that
    /// data reads the same at either depth.
    #[inline]
    fn stored(&self, i: usize) -> Vec3 {
        match self {
            Texels::Srgb8 { codes, .. } => {
                let [r, g, b, _] = codes[i];
                Vec3::new(r.into(), g.into(), b.into()) / 255.0
            }
            Texels::Linear(rgb) => rgb[i].to_array().map(linear_to_srgb).into(),
        }
    }

    /// Texel `i` read as a scalar through `channel`: one of its [`Texels::stored`] values, or
    /// their luminance (a coverage mask without an alpha channel).
    #[inline]
    fn scalar(&self, i: usize, channel: Channel) -> f32 {
        let stored = self.stored(i);
        match channel {
            Channel::Red => stored.x,
            Channel::Green => stored.y,
            Channel::Blue => stored.z,
            Channel::Luminance => stored.dot(Vec3::new(0.2126, 0.7152, 0.0722)),
        }
    }

    fn memory_bytes(&self) -> usize {
        match self {
            Texels::Srgb8 { codes, .. } => codes.len() * 4,
            Texels::Linear(rgb) => rgb.len() * std::mem::size_of::<Vec3>(),
        }
    }
}

impl Texture {
    /// Decodes the bytes of the file `name`: a PNG, JPEG or BMP is recognised from its content, a
    /// TGA (whose format has no signature) by its extension. Images of more than [`MAX_TEXELS`]
    /// texels are refused from the header alone. The error is a short reason, without the file
    /// name.
    pub fn decode_named(bytes: &[u8], name: Option<&Path>) -> Result<Texture, String> {
        Header::read(bytes, name)?.decode(bytes)
    }

    /// A texture from linear texel values, row-major from the top row; `None` when the sizes do
    /// not match, the image is empty, or it exceeds [`MAX_TEXELS`].
    pub fn from_linear(width: u32, height: u32, rgb: Vec<Vec3>, alpha: Option<Vec<f32>>) -> Option<Texture> {
        let n = width as u64 * height as u64;
        let sizes_fit = rgb.len() as u64 == n && alpha.as_ref().is_none_or(|a| a.len() as u64 == n);
        (sizes_fit && check_size(width, height).is_ok()).then_some(Texture {
            width,
            height,
            rgb: Texels::Linear(rgb),
            alpha,
        })
    }

    /// Converts a decoded image, whatever its channels and depth, to linear RGB(A).
    fn from_image(image: DynamicImage) -> Texture {
        let (width, height) = (image.width(), image.height());
        let has_alpha = image.color().has_alpha();
        let mut alpha = Vec::new();
        let rgb = if image.color().bytes_per_pixel() > image.color().channel_count() {
            // 16 bits per channel (PNG): decode each value exactly.
            let decode = |c: u16| srgb_to_linear(c as f32 / 65535.0);
            let pixels = image.into_rgba16();
            let rgb = pixels
                .pixels()
                .map(|p| {
                    if has_alpha {
                        alpha.push(p[3] as f32 / 65535.0);
                    }
                    Vec3::new(decode(p[0]), decode(p[1]), decode(p[2]))
                })
                .collect();
            Texels::Linear(rgb)
        } else {
            let pixels = image.into_rgba8();
            let codes = pixels
                .pixels()
                .map(|p| {
                    if has_alpha {
                        alpha.push(p[3] as f32 / 255.0);
                    }
                    [p[0], p[1], p[2], 0]
                })
                .collect();
            Texels::Srgb8 { codes, table: srgb_table() }
        };
        Texture { width, height, rgb, alpha: has_alpha.then_some(alpha) }
    }

    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }

    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Whether the file had an alpha channel ([`Texture::sample_alpha`] is 1 everywhere otherwise).
    #[inline]
    pub fn has_alpha(&self) -> bool {
        self.alpha.is_some()
    }

    /// The bytes the texels take in memory.
    pub fn memory_bytes(&self) -> usize {
        self.rgb.memory_bytes() + self.alpha.as_ref().map_or(0, |a| a.len() * 4)
    }

    /// The linear colour of texel `(x, y)`, column `x` and row `y` counted from the top of the
    /// image as stored in the file; coordinates wrap around.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        self.rgb.get(self.index(x as i64, y as i64))
    }

    /// The bilinearly filtered colour at texture coordinates `uv` (OBJ convention: `v = 0` is the
    /// bottom of the image), with repeat wrapping.
    #[inline]
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        let [(i00, w00), (i10, w10), (i01, w01), (i11, w11)] = self.footprint(uv);
        let rgb = &self.rgb;
        rgb.get(i00) * w00 + rgb.get(i10) * w10 + rgb.get(i01) * w01 + rgb.get(i11) * w11
    }

    /// Starts loading the texels [`Texture::sample`] reads at `uv`, so that a lookup issued later
    /// does not wait for memory: the first texel of each of its two rows (the second texel of a
    /// row lies in the same cache line, except at a line's end or where the row wraps).
    #[inline]
    pub fn prefetch(&self, uv: Vec2) {
        let [(i00, _), _, (i01, _), _] = self.footprint(uv);
        self.rgb.prefetch(i00);
        self.rgb.prefetch(i01);
    }

    /// The bilinearly filtered alpha at `uv`; 1 (opaque) for images without alpha.
    #[inline]
    pub fn sample_alpha(&self, uv: Vec2) -> f32 {
        let Some(alpha) = &self.alpha else { return 1.0 };
        self.footprint(uv).iter().map(|&(i, w)| alpha[i] * w).sum()
    }

    /// The bilinearly filtered coverage at `uv`, for cutouts (`map_d`): the alpha channel where the
    /// file has one, otherwise the image read as a scalar (the luminance of the grey levels the
    /// file stores, as a mask is drawn), as renderers read a `map_d` file.
    #[inline]
    pub fn sample_coverage(&self, uv: Vec2) -> f32 {
        if self.alpha.is_some() {
            return self.sample_alpha(uv);
        }
        self.sample_channel(uv, Channel::Luminance)
    }

    /// The bilinearly filtered values the file stores at `uv` (not decoded from sRGB): data such
    /// as a normal map's directions.
    #[inline]
    pub fn sample_stored(&self, uv: Vec2) -> Vec3 {
        self.footprint(uv).iter().map(|&(i, w)| self.rgb.stored(i) * w).fold(Vec3::ZERO, |sum, value| sum + value)
    }

    /// The values the file stores for every texel (not decoded from sRGB), in storage order: for
    /// what a texture holds as a whole, such as whether it has a normal map's colours.
    pub fn stored_texels(&self) -> impl Iterator<Item = Vec3> + '_ {
        (0..self.width as usize * self.height as usize).map(|i| self.rgb.stored(i))
    }

    /// The bilinearly filtered value of `channel` at `uv`, read from the values the file stores
    /// (not decoded from sRGB): a material parameter painted by the texture, such as a roughness.
    #[inline]
    pub fn sample_channel(&self, uv: Vec2, channel: Channel) -> f32 {
        self.footprint(uv).iter().map(|&(i, w)| self.rgb.scalar(i, channel) * w).sum()
    }

    /// The four texels around `uv` and their bilinear weights (which sum to 1).
    #[inline]
    fn footprint(&self, uv: Vec2) -> [(usize, f32); 4] {
        // Continuous texel coordinates, with texel centres at integers; rows from the top.
        let x = wrap_unit(uv.x) * self.width as f32 - 0.5;
        let y = (1.0 - wrap_unit(uv.y)) * self.height as f32 - 0.5;
        let (x0, y0) = (floor(x), floor(y));
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        [
            (self.index(x0, y0), (1.0 - fx) * (1.0 - fy)),
            (self.index(x0 + 1, y0), fx * (1.0 - fy)),
            (self.index(x0, y0 + 1), (1.0 - fx) * fy),
            (self.index(x0 + 1, y0 + 1), fx * fy),
        ]
    }

    /// The storage index of texel `(x, y)`, wrapped into the image.
    #[inline]
    fn index(&self, x: i64, y: i64) -> usize {
        wrap_texel(y, self.height) * self.width as usize + wrap_texel(x, self.width)
    }
}

/// `i.rem_euclid(n)`. The footprint's texels lie in `-1 ..= n` (the coordinates come wrapped into
/// `[0, 1]`), which two comparisons wrap: the integer division was a quarter of the staircase's
/// render, eight of them per lookup.
#[inline]
fn wrap_texel(i: i64, n: u32) -> usize {
    let n = i64::from(n);
    let wrapped = if i < 0 {
        i + n
    } else if i >= n {
        i - n
    } else {
        i
    };
    if (0..n).contains(&wrapped) { wrapped as usize } else { i.rem_euclid(n) as usize }
}

/// `t.floor()` for a finite `t`, without the libm call it compiles to on x86-64's baseline (SSE2
/// has no rounding instruction): truncate, and step down for negative non-integers. Values of
/// magnitude `2^23` and above are integers already. The result's sign of zero may differ from
/// `floor`'s (`-0.0` gives `0.0`), which no use here can see.
#[inline]
fn floor(t: f32) -> f32 {
    if t.abs() >= 8_388_608.0 {
        return t;
    }
    let truncated = t as i32 as f32;
    if truncated > t { truncated - 1.0 } else { truncated }
}

/// `t` wrapped into `[0, 1]` (repeat); 0 for NaN and infinities. The result can be exactly 1 for
/// tiny negative `t` (`1 − 1e-9` rounds up), which the index wrapping handles.
#[inline]
fn wrap_unit(t: f32) -> f32 {
    if t.is_finite() { t - floor(t) } else { 0.0 }
}

/// What a texture file's header says, read before decoding it: its format and size (an image of
/// more than [`MAX_TEXELS`] texels is refused here), and what decoding it will take in memory.
struct Header {
    format: ImageFormat,
    width: u32,
    height: u32,
    bytes_per_pixel: u64,
    sixteen_bits: bool,
    has_alpha: bool,
}

impl Header {
    fn read(bytes: &[u8], name: Option<&Path>) -> Result<Header, String> {
        let reader = ImageReader::new(Cursor::new(bytes)).with_guessed_format().map_err(|e| e.to_string())?;
        let named_tga =
            name.and_then(|name| name.extension()).is_some_and(|extension| extension.eq_ignore_ascii_case("tga"));
        let format = match reader.format() {
            Some(format @ (ImageFormat::Png | ImageFormat::Jpeg | ImageFormat::Bmp)) => format,
            Some(other) => return Err(format!("{other:?} images are not supported (PNG, JPEG, BMP and TGA are)")),
            None if named_tga => ImageFormat::Tga,
            None => return Err("not a PNG, JPEG, BMP or TGA image".to_string()),
        };
        let decoder = ImageReader::with_format(Cursor::new(bytes), format).into_decoder().map_err(|e| e.to_string())?;
        let (width, height) = decoder.dimensions();
        check_size(width, height)?;
        let colour = decoder.color_type();
        let (bytes_per_pixel, channels) = (u64::from(colour.bytes_per_pixel()), u64::from(colour.channel_count()));
        let (sixteen_bits, has_alpha) = (bytes_per_pixel > channels, colour.has_alpha());
        Ok(Header { format, width, height, bytes_per_pixel, sixteen_bits, has_alpha })
    }

    /// The most memory decoding takes at once: the decoder's image, its copy as RGBA (none when
    /// it is RGBA already), and the texels kept (linear `f32` RGB for 16-bit files, 8-bit codes
    /// otherwise, and alpha where the file has it). A 16-bit RGBA file of 8192 × 8192 texels:
    /// 1.5 GiB, as `/usr/bin/time` measured its render's peak.
    fn decoding_bytes(&self) -> u64 {
        let rgba_size = if self.sixteen_bits { 8 } else { 4 };
        let copy = if self.bytes_per_pixel == rgba_size { 0 } else { rgba_size };
        let kept = if self.sixteen_bits { 12 } else { 4 } + if self.has_alpha { 4 } else { 0 };
        u64::from(self.width) * u64::from(self.height) * (self.bytes_per_pixel + copy + kept)
    }

    fn decode(&self, bytes: &[u8]) -> Result<Texture, String> {
        let mut reader = ImageReader::with_format(Cursor::new(bytes), self.format);
        let mut limits = Limits::default();
        limits.max_image_width = Some(self.width);
        limits.max_image_height = Some(self.height);
        // Room for the decoded image at 16 bits per channel and the decoder's own buffers.
        limits.max_alloc = Some(MAX_TEXELS * 8 + (64 << 20));
        reader.limits(limits);
        let image = reader.decode().map_err(|e| e.to_string())?;
        Ok(Texture::from_image(image))
    }
}

/// Refuses empty images and those of more than [`MAX_TEXELS`] texels.
fn check_size(width: u32, height: u32) -> Result<(), String> {
    let texels = width as u64 * height as u64;
    if texels == 0 {
        return Err(format!("the image is {width}×{height}, without pixels"));
    }
    if texels > MAX_TEXELS {
        return Err(format!(
            "the image is {width}×{height} = {texels} pixels, over the limit of {MAX_TEXELS} ({} MiB as linear RGBA); \
             refusing to decode it",
            (MAX_TEXELS * 16) >> 20
        ));
    }
    Ok(())
}

/// The exact sRGB decoding curve (IEC 61966-2-1) for an encoded value in `[0, 1]`.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    let c = c as f64;
    let linear = if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
    linear as f32
}

/// The sRGB encoding curve, the inverse of [`srgb_to_linear`], for a linear value in `[0, 1]`.
fn linear_to_srgb(l: f32) -> f32 {
    let l = l as f64;
    let encoded = if l <= 0.0031308 { l * 12.92 } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 };
    encoded as f32
}

/// The linear values of the 256 8-bit sRGB codes, computed once.
fn srgb_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|code| srgb_to_linear(code as f32 / 255.0)))
}

/// Which of a texture's channels a scalar lookup reads ([`Texture::sample_channel`]; MTL's
/// `-imfchan r|g|b|l`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channel {
    Red,
    Green,
    Blue,
    /// The luminance of the stored red, green and blue: a grey image's level (MTL's default for
    /// scalar maps).
    Luminance,
}

/// Names one texture of a [`TextureSet`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureId(u32);

impl TextureId {
    /// The texture's position in its set.
    #[inline]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// The decoded textures of a scene, each file once.
#[derive(Clone, Debug, Default)]
pub struct TextureSet {
    textures: Vec<Texture>,
    paths: Vec<PathBuf>,
    /// The stable hash of each file's bytes, taken as it was decoded: a checkpoint's fingerprint
    /// of the scene holds it, so that a render does not resume over an edited texture.
    contents: Vec<u64>,
}

impl TextureSet {
    /// Decodes every distinct path of `paths` once (files in parallel) and returns the textures
    /// that decoded, with one warning for each path that did not, in the order of `paths`:
    /// `texture "PATH": REASON; the material's Kd is used instead`.
    pub fn load<P: AsRef<Path> + Sync>(paths: &[P]) -> (TextureSet, Vec<String>) {
        TextureSet::load_or(paths, TextureUse::Diffuse.instead(), &EmbeddedImages::default())
    }

    /// [`TextureSet::load`] with `available` bytes of memory, instead of what the system reports
    /// ([`crate::util::read::available_memory`]): for tests of a machine short of memory.
    pub fn load_with_memory<P: AsRef<Path> + Sync>(paths: &[P], available: u64) -> (TextureSet, Vec<String>) {
        TextureSet::load_within(paths, TextureUse::Diffuse.instead(), Some(available), &EmbeddedImages::default())
    }

    /// [`TextureSet::load`], whose warnings end with `instead` (what the material does without
    /// the texture), reading the names of `embedded` images from it instead of from files.
    fn load_or<P: AsRef<Path> + Sync>(
        paths: &[P],
        instead: &str,
        embedded: &EmbeddedImages,
    ) -> (TextureSet, Vec<String>) {
        TextureSet::load_within(paths, instead, crate::util::read::available_memory(), embedded)
    }

    /// [`TextureSet::load_or`] with `available` bytes of memory (`None`: not known). Each file is
    /// read and its header checked in order, its decoding's memory ([`Header::decoding_bytes`])
    /// set aside from what is left; a file that does not fit is refused with a warning, where
    /// decoding it would have aborted the process. Then the files that fit decode in parallel.
    /// Which files fit depends on the order alone, never on the threads.
    fn load_within<P: AsRef<Path> + Sync>(
        paths: &[P],
        instead: &str,
        available: Option<u64>,
        embedded: &EmbeddedImages,
    ) -> (TextureSet, Vec<String>) {
        // A set beside the list: a scene may name tens of thousands of textures.
        let mut seen = HashSet::new();
        let distinct: Vec<&Path> = paths.iter().map(AsRef::as_ref).filter(|path| seen.insert(*path)).collect();
        let mut left = available;
        let read: Vec<_> = distinct.iter().map(|path| read_within(path, embedded, &mut left)).collect();
        let decoded: Vec<Result<(Texture, u64), String>> = read
            .into_par_iter()
            .map(|file| file.and_then(|(bytes, header)| Ok((header.decode(&bytes)?, hash_bytes(&bytes)))))
            .collect();
        let mut set = TextureSet::default();
        let mut warnings = Vec::new();
        for (path, result) in distinct.into_iter().zip(decoded) {
            match result {
                Ok((texture, contents)) => {
                    set.textures.push(texture);
                    set.paths.push(path.to_path_buf());
                    set.contents.push(contents);
                }
                Err(reason) => warnings.push(unusable(path, &reason, instead)),
            }
        }
        (set, warnings)
    }

    /// The textures of a scene's materials: give each material's diffuse texture path (`map_kd`,
    /// already resolved relative to its MTL file, or the name of one of the scene's `embedded`
    /// images), get for each material the id of its texture (`None` for no texture or one that
    /// failed), the set, and the warnings of [`TextureSet::load`].
    pub fn for_materials<'a>(
        map_kd: impl IntoIterator<Item = Option<&'a Path>>,
        embedded: &EmbeddedImages,
    ) -> (Vec<Option<TextureId>>, TextureSet, Vec<String>) {
        TextureSet::for_use(TextureUse::Diffuse, map_kd, embedded)
    }

    /// As [`TextureSet::for_materials`], for each material's coverage texture (`map_d`, for
    /// cutouts): a file that fails leaves its material opaque.
    pub fn for_cutouts<'a>(
        map_d: impl IntoIterator<Item = Option<&'a Path>>,
        embedded: &EmbeddedImages,
    ) -> (Vec<Option<TextureId>>, TextureSet, Vec<String>) {
        TextureSet::for_use(TextureUse::Coverage, map_d, embedded)
    }

    /// As [`TextureSet::for_materials`], for textures of any use: one optional path per
    /// material, and the warnings of [`TextureSet::load`] ending with what the material does
    /// without a texture of that use.
    pub fn for_use<'a>(
        texture_use: TextureUse,
        paths: impl IntoIterator<Item = Option<&'a Path>>,
        embedded: &EmbeddedImages,
    ) -> (Vec<Option<TextureId>>, TextureSet, Vec<String>) {
        let paths: Vec<Option<&Path>> = paths.into_iter().collect();
        let distinct: Vec<&Path> = paths.iter().flatten().copied().collect();
        let (set, warnings) = TextureSet::load_or(&distinct, texture_use.instead(), embedded);
        let id_of: HashMap<&Path, TextureId> =
            set.paths.iter().enumerate().map(|(i, path)| (path.as_path(), TextureId(i as u32))).collect();
        let ids = paths.iter().map(|path| path.and_then(|p| id_of.get(p).copied())).collect();
        (ids, set, warnings)
    }

    /// The warnings [`TextureSet::for_use`] would give for the `files` (each with its use) that
    /// are missing, not regular files or too large: the checks that need no decoding, so they
    /// cost no more than a file's metadata (what `lumiere info` shows). Images `embedded` in the
    /// scene file are not files: they are checked when they are decoded.
    pub fn unreadable_files<'a>(
        files: impl IntoIterator<Item = (TextureUse, Option<&'a Path>)>,
        embedded: &EmbeddedImages,
    ) -> Vec<String> {
        let mut warnings = Vec::new();
        let mut seen = HashSet::new();
        for (texture_use, path) in files {
            let Some(path) = path else { continue };
            if embedded.contains(path) || !seen.insert((texture_use, path)) {
                continue;
            }
            if let Err(reason) = check_file(path) {
                warnings.push(unusable(path, &reason, texture_use.instead()));
            }
        }
        warnings
    }

    /// The id of the texture decoded from `path`, if it decoded.
    pub fn id_of(&self, path: &Path) -> Option<TextureId> {
        self.paths.iter().position(|p| p == path).map(|i| TextureId(i as u32))
    }

    #[inline]
    pub fn get(&self, id: TextureId) -> &Texture {
        &self.textures[id.index()]
    }

    /// The stable hash ([`hash_bytes`]) of the bytes of the file texture `id` was decoded from.
    pub fn contents_hash(&self, id: TextureId) -> u64 {
        self.contents[id.index()]
    }

    /// Starts loading the texels of texture `id` that a lookup at `uv` reads (see
    /// [`Texture::prefetch`]).
    #[inline]
    pub fn prefetch(&self, id: TextureId, uv: Vec2) {
        self.get(id).prefetch(uv);
    }

    /// The bilinearly filtered colour of texture `id` at `uv` (see [`Texture::sample`]).
    #[inline]
    pub fn sample(&self, id: TextureId, uv: Vec2) -> Vec3 {
        self.get(id).sample(uv)
    }

    pub fn len(&self) -> usize {
        self.textures.len()
    }

    pub fn is_empty(&self) -> bool {
        self.textures.is_empty()
    }

    /// The bytes all texels take in memory.
    pub fn memory_bytes(&self) -> usize {
        self.textures.iter().map(Texture::memory_bytes).sum()
    }
}

/// What a texture is for, which decides what its material does without it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureUse {
    /// The base colour (`map_Kd`, glTF's `baseColorTexture`).
    Diffuse,
    /// A cutout's coverage (`map_d`, glTF's alpha).
    Coverage,
    /// A material's metallic weight or roughness (`map_Pm`, `map_Pr`, glTF's
    /// `metallicRoughnessTexture`).
    Parameters,
    /// A normal or bump map (glTF's `normalTexture`, MTL `norm`, `bump`, `map_Bump`).
    Normals,
}

impl TextureUse {
    /// What a material does without its texture: the end of each warning about a file that
    /// cannot be used.
    fn instead(self) -> &'static str {
        match self {
            TextureUse::Diffuse => "the material's Kd is used instead",
            TextureUse::Coverage => "the material stays opaque",
            TextureUse::Parameters => "the material's metallic and roughness values are used instead",
            TextureUse::Normals => "the surface keeps its interpolated normals",
        }
    }
}

/// The warning about texture file `path`: quoted and escaped like a string literal (not cut: the
/// user must find the file), so that a control character from the MTL file cannot garble the line.
fn unusable(path: &Path, reason: &str, instead: &str) -> String {
    format!("texture {:?}: {}; {instead}", path.to_string_lossy(), crate::error::one_line(reason))
}

/// The checks on a texture file that its metadata answers: it is there, a regular file, and not
/// larger than [`MAX_FILE_BYTES`].
fn check_file(path: &Path) -> Result<(), String> {
    let metadata = std::fs::metadata(path).map_err(|e| e.to_string())?;
    crate::util::read::refuse_special(&metadata).map_err(|e| e.to_string())?;
    if metadata.len() > MAX_FILE_BYTES {
        return Err(format!("the file has {} bytes, over the limit of {MAX_FILE_BYTES}", metadata.len()));
    }
    Ok(())
}

/// Reads one texture file (or takes the bytes of an image `embedded` under that name) and its
/// header, and sets aside from `left` (bytes of memory, where known) what the file and its
/// decoding take; the error is a reason without the file name.
fn read_within<'e>(
    path: &Path,
    embedded: &'e EmbeddedImages,
    left: &mut Option<u64>,
) -> Result<(Cow<'e, [u8]>, Header), String> {
    let bytes = match embedded.get(path) {
        Some(bytes) => Cow::Borrowed(bytes),
        None => {
            check_file(path)?;
            Cow::Owned(crate::util::read::read_regular_file(path).map_err(|e| e.to_string())?)
        }
    };
    let header = Header::read(&bytes, Some(path))?;
    if let Some(left) = left {
        let needed = bytes.len() as u64 + header.decoding_bytes();
        if needed > *left {
            let mib = |bytes: u64| bytes.div_ceil(1 << 20);
            return Err(format!(
                "decoding its {}×{} texels needs about {} MiB of memory, but only {} MiB is left",
                header.width,
                header.height,
                mib(needed),
                mib(*left)
            ));
        }
        *left -= needed;
    }
    Ok((bytes, header))
}

#[cfg(test)]
mod tests {
    use super::{floor, wrap_texel};

    #[test]
    fn floor_is_f32_floor() {
        let mut values = vec![0.0f32, -0.0, 0.5, -0.5, 1.0, -1.0, 2.999_999_8, -2.999_999_8, 1e-30, -1e-30];
        values.extend([8_388_607.5f32, -8_388_607.5, 8_388_608.0, -8_388_609.0, 1e30, -1e30, f32::MAX, f32::MIN]);
        values.extend((0..10_000).map(|i| (i as f32 - 5000.0) * 0.37));
        for t in values {
            assert_eq!(floor(t), t.floor(), "{t}");
        }
    }

    #[test]
    fn wrap_texel_is_rem_euclid() {
        for n in [1u32, 2, 3, 7, 1024] {
            for i in -3 * i64::from(n) - 2..3 * i64::from(n) + 2 {
                assert_eq!(wrap_texel(i, n), i.rem_euclid(i64::from(n)) as usize, "{i} mod {n}");
            }
        }
    }
}
