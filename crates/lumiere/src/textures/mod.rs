//! Textures: image files decoded once, when the world is built, into linear RGB (8-bit files keep
//! their codes and decode them through a table at each lookup; alpha where the file has one), with
//! a mip chain for the colours (`mip.rs`), looked up with bilinear filtering and repeat wrapping.
//!
//! * **Colour.** PNG and JPEG store sRGB-encoded values; each channel is decoded with the exact
//!   sRGB curve (IEC 61966-2-1: linear below 0.04045, a 2.4 power above), so texture values are
//!   reflectances, like `Kd`. Alpha is linear coverage and is kept as is, for cutouts (`map_d`,
//!   [`Texture::sample_coverage`]).
//! * **Coordinates.** OBJ's texture origin is the bottom-left corner: `v = 0` is the *last* row of
//!   the image, `v = 1` the first. Texel `(x, y)` (column, row from the top) has its centre at
//!   `u = (x + ½) / width`, `v = 1 − (y + ½) / height`. Outside `[0, 1)` coordinates repeat; at the
//!   borders, bilinear filtering blends with the opposite edge, as repeat wrapping implies.
//!   NaN, infinite and huge coordinates read a valid texel and never panic.
//! * **Footprints.** [`Texture::sample`] reads the image itself; [`Texture::sample_footprint`]
//!   reads the mip level of a footprint so many texels wide (the path tracer's ray cones,
//!   `integrators::RayCone`), the image itself for footprints under two texels.
//! * **Loading.** [`TextureSet::load`] decodes every distinct file once, in parallel; a file that
//!   cannot be read or decoded costs one warning naming it, and the materials that use it keep
//!   their `Kd`. Image sizes are checked against [`MAX_TEXELS`] from the header, before decoding.
//!   [`TextureSet::for_materials`] builds the colour textures' mip chains; cutouts have none.

mod level;
mod mip;

use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use glam::{Vec2, Vec3};
use image::{DynamicImage, ImageFormat, ImageReader, Limits};
use rayon::prelude::*;

use level::{Level, Texels};

/// The most texels (width × height) an image may have: 2²⁶, e.g. 8192 × 8192, which takes 1 GiB
/// as `f32` RGBA. Larger images are refused from their header, before any decoding.
pub const MAX_TEXELS: u64 = 1 << 26;

/// The largest texture file read, in bytes (a compressed image of [`MAX_TEXELS`] is far smaller).
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// An image decoded to linear `f32` RGB with its mip chain (`mip.rs`), and its alpha channel when
/// the file has one (full resolution only: cutouts test it at level 0).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// The image as decoded, then its halvings down to one texel.
    levels: Vec<Level>,
    /// Row-major from the top row of the image, as stored in the file.
    alpha: Option<Vec<f32>>,
}

impl Texture {
    /// Decodes a PNG or JPEG file's bytes (the format is recognised from its content), refusing
    /// images of more than [`MAX_TEXELS`] texels from the header alone. The error is a short
    /// reason, without the file name.
    pub fn decode(bytes: &[u8]) -> Result<Texture, String> {
        let reader = ImageReader::new(Cursor::new(bytes)).with_guessed_format().map_err(|e| e.to_string())?;
        let format = match reader.format() {
            Some(format @ (ImageFormat::Png | ImageFormat::Jpeg)) => format,
            Some(other) => return Err(format!("{other:?} images are not supported (PNG and JPEG are)")),
            None => return Err("not a PNG or JPEG image".to_string()),
        };
        let (width, height) = reader.into_dimensions().map_err(|e| e.to_string())?;
        check_size(width, height)?;
        let mut reader = ImageReader::with_format(Cursor::new(bytes), format);
        let mut limits = Limits::default();
        limits.max_image_width = Some(width);
        limits.max_image_height = Some(height);
        // Room for the decoded image at 16 bits per channel and the decoder's own buffers.
        limits.max_alloc = Some(MAX_TEXELS * 8 + (64 << 20));
        reader.limits(limits);
        let image = reader.decode().map_err(|e| e.to_string())?;
        Ok(Texture::from_image(image))
    }

    /// A texture from linear texel values, row-major from the top row; `None` when the sizes do
    /// not match, the image is empty, or it exceeds [`MAX_TEXELS`].
    pub fn from_linear(width: u32, height: u32, rgb: Vec<Vec3>, alpha: Option<Vec<f32>>) -> Option<Texture> {
        let n = width as u64 * height as u64;
        let sizes_fit = rgb.len() as u64 == n && alpha.as_ref().is_none_or(|a| a.len() as u64 == n);
        (sizes_fit && check_size(width, height).is_ok())
            .then(|| Texture::new(width, height, Texels::Linear(rgb), alpha))
    }

    /// The texture of the decoded image `rgb`, without a mip chain yet.
    fn new(width: u32, height: u32, rgb: Texels, alpha: Option<Vec<f32>>) -> Texture {
        Texture { levels: vec![Level { width, height, rgb }], alpha }
    }

    /// Builds the mip chain (`mip.rs`), for [`Texture::sample_footprint`]; a third more memory. Until
    /// then the texture has one level, which every level of detail reads.
    pub fn build_mip_chain(&mut self) {
        if self.levels.len() == 1 {
            let halvings = mip::halvings(&self.levels[0]);
            self.levels.extend(halvings);
        }
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
        Texture::new(width, height, rgb, has_alpha.then_some(alpha))
    }

    #[inline]
    pub fn width(&self) -> u32 {
        self.levels[0].width
    }

    #[inline]
    pub fn height(&self) -> u32 {
        self.levels[0].height
    }

    /// The number of images in the mip chain: 1 before [`Texture::build_mip_chain`], then
    /// 1 + ⌈log₂ max(w, h)⌉.
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Whether the file had an alpha channel ([`Texture::sample_alpha`] is 1 everywhere otherwise).
    #[inline]
    pub fn has_alpha(&self) -> bool {
        self.alpha.is_some()
    }

    /// The bytes the texels take in memory, the mip chain's included.
    pub fn memory_bytes(&self) -> usize {
        self.levels.iter().map(|level| level.rgb.memory_bytes()).sum::<usize>()
            + self.alpha.as_ref().map_or(0, |a| a.len() * 4)
    }

    /// The linear colour of texel `(x, y)`, column `x` and row `y` counted from the top of the
    /// image as stored in the file; coordinates wrap around.
    #[inline]
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        let image = &self.levels[0];
        image.rgb.get(image.index(x as i64, y as i64))
    }

    /// The bilinearly filtered colour at texture coordinates `uv` (OBJ convention: `v = 0` is the
    /// bottom of the image), with repeat wrapping.
    #[inline]
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        self.levels[0].bilinear(uv)
    }

    /// The bilinearly filtered colour at `uv` of the mip level (`mip.rs`) a footprint of
    /// `texels_squared` texels² of the image is read from: [`Texture::sample`] for footprints of
    /// one texel or less (and NaN), the last level for those wider than the image.
    #[inline]
    pub fn sample_footprint(&self, uv: Vec2, texels_squared: f32) -> Vec3 {
        let level = (mip::level_of_footprint(texels_squared) as usize).min(self.levels.len() - 1);
        self.levels[level].bilinear(uv)
    }

    /// The bilinearly filtered alpha at `uv`; 1 (opaque) for images without alpha.
    #[inline]
    pub fn sample_alpha(&self, uv: Vec2) -> f32 {
        let Some(alpha) = &self.alpha else { return 1.0 };
        self.levels[0].footprint(uv).iter().map(|&(i, w)| alpha[i] * w).sum()
    }

    /// The bilinearly filtered coverage at `uv`, for cutouts (`map_d`): the alpha channel where the
    /// file has one, otherwise the image read as a scalar (the luminance of the grey levels the
    /// file stores, as a mask is drawn), as renderers read a `map_d` file.
    #[inline]
    pub fn sample_coverage(&self, uv: Vec2) -> f32 {
        if self.alpha.is_some() {
            return self.sample_alpha(uv);
        }
        let image = &self.levels[0];
        image.footprint(uv).iter().map(|&(i, w)| image.rgb.scalar(i) * w).sum()
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
}

impl TextureSet {
    /// Decodes every distinct path of `paths` once (files in parallel) and returns the textures
    /// that decoded, with one warning for each path that did not, in the order of `paths`:
    /// `texture "PATH": REASON; the material's Kd is used instead`.
    pub fn load<P: AsRef<Path> + Sync>(paths: &[P]) -> (TextureSet, Vec<String>) {
        TextureSet::load_or(paths, "the material's Kd is used instead")
    }

    /// [`TextureSet::load`], whose warnings end with `instead` (what the material does without
    /// the texture).
    fn load_or<P: AsRef<Path> + Sync>(paths: &[P], instead: &str) -> (TextureSet, Vec<String>) {
        let mut distinct: Vec<&Path> = Vec::new();
        for path in paths {
            if !distinct.contains(&path.as_ref()) {
                distinct.push(path.as_ref());
            }
        }
        let decoded: Vec<Result<Texture, String>> = distinct.par_iter().map(|path| read_texture(path)).collect();
        let mut set = TextureSet::default();
        let mut warnings = Vec::new();
        for (path, result) in distinct.into_iter().zip(decoded) {
            match result {
                Ok(texture) => {
                    set.textures.push(texture);
                    set.paths.push(path.to_path_buf());
                }
                Err(reason) => warnings.push(format!("texture \"{}\": {reason}; {instead}", path.display())),
            }
        }
        (set, warnings)
    }

    /// The textures of a scene's materials: give each material's diffuse texture path (`map_kd`,
    /// already resolved relative to its MTL file), get for each material the id of its texture
    /// (`None` for no texture or one that failed), the set, and the warnings of [`TextureSet::load`].
    pub fn for_materials<'a>(
        map_kd: impl IntoIterator<Item = Option<&'a Path>>,
    ) -> (Vec<Option<TextureId>>, TextureSet, Vec<String>) {
        let (ids, mut set, warnings) = TextureSet::per_material(map_kd, "the material's Kd is used instead");
        // Colours are looked up at each path vertex's footprint; cutouts only at full resolution.
        set.textures.par_iter_mut().for_each(Texture::build_mip_chain);
        (ids, set, warnings)
    }

    /// As [`TextureSet::for_materials`], for each material's coverage texture (`map_d`, for
    /// cutouts): a file that fails leaves its material opaque.
    pub fn for_cutouts<'a>(
        map_d: impl IntoIterator<Item = Option<&'a Path>>,
    ) -> (Vec<Option<TextureId>>, TextureSet, Vec<String>) {
        TextureSet::per_material(map_d, "the material stays opaque")
    }

    /// One optional texture path per material → each material's texture id, the set, and the
    /// warnings of [`TextureSet::load_or`].
    fn per_material<'a>(
        paths: impl IntoIterator<Item = Option<&'a Path>>,
        instead: &str,
    ) -> (Vec<Option<TextureId>>, TextureSet, Vec<String>) {
        let paths: Vec<Option<&Path>> = paths.into_iter().collect();
        let distinct: Vec<&Path> = paths.iter().flatten().copied().collect();
        let (set, warnings) = TextureSet::load_or(&distinct, instead);
        let ids = paths.iter().map(|path| path.and_then(|p| set.id_of(p))).collect();
        (ids, set, warnings)
    }

    /// The id of the texture decoded from `path`, if it decoded.
    pub fn id_of(&self, path: &Path) -> Option<TextureId> {
        self.paths.iter().position(|p| p == path).map(|i| TextureId(i as u32))
    }

    #[inline]
    pub fn get(&self, id: TextureId) -> &Texture {
        &self.textures[id.index()]
    }

    /// The file texture `id` was decoded from.
    pub fn path(&self, id: TextureId) -> &Path {
        &self.paths[id.index()]
    }

    /// The bilinearly filtered colour of texture `id` at `uv` (see [`Texture::sample`]).
    #[inline]
    pub fn sample(&self, id: TextureId, uv: Vec2) -> Vec3 {
        self.get(id).sample(uv)
    }

    /// The colour of texture `id` at `uv` under a footprint (see [`Texture::sample_footprint`]).
    #[inline]
    pub fn sample_footprint(&self, id: TextureId, uv: Vec2, texels_squared: f32) -> Vec3 {
        self.get(id).sample_footprint(uv, texels_squared)
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

/// Reads and decodes one texture file; the error is a reason without the file name.
fn read_texture(path: &Path) -> Result<Texture, String> {
    let metadata = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !metadata.is_file() {
        return Err("not a regular file".to_string());
    }
    if metadata.len() > MAX_FILE_BYTES {
        return Err(format!("the file has {} bytes, over the limit of {MAX_FILE_BYTES}", metadata.len()));
    }
    let bytes = crate::util::read::read_regular_file(path).map_err(|e| e.to_string())?;
    Texture::decode(&bytes)
}
