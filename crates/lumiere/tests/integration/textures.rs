//! Textures: PNG, JPEG, BMP and TGA files written here with the `image` crate, decoded to linear values with
//! the exact sRGB curve, looked up bilinearly with repeat wrapping and OBJ's bottom-left origin;
//! files that cannot be used cost one warning each and no texture.

use std::path::{Path, PathBuf};

use crate::common::TempDir;
use glam::{Vec2, Vec3};
use image::{ImageFormat, Rgb, RgbImage, Rgba, RgbaImage};
use lumiere::materials::{CoverageTest, Cut, Relief};
use lumiere::render::fingerprint::scene_fingerprint;
use lumiere::scene::Scene;
use lumiere::textures::{EmbeddedImages, MAX_TEXELS, Texture, TextureSet, srgb_to_linear};
use lumiere::util::hash::hash_bytes;
use lumiere::world::World;

/// The sRGB decoding curve, written independently in f64.
fn linear(code: u8) -> f32 {
    let c = code as f64 / 255.0;
    (if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }) as f32
}

fn linear_rgb(p: [u8; 3]) -> Vec3 {
    Vec3::new(linear(p[0]), linear(p[1]), linear(p[2]))
}

/// The texture coordinates of the centre of texel (x, y), row y counted from the top of the image.
fn centre(x: u32, y: u32, width: u32, height: u32) -> Vec2 {
    Vec2::new((x as f32 + 0.5) / width as f32, 1.0 - (y as f32 + 0.5) / height as f32)
}

fn close(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

/// A 4 × 3 image whose every texel has its own colour, with codes on both sides of the sRGB
/// curve's linear segment.
fn test_image() -> RgbImage {
    RgbImage::from_fn(4, 3, |x, y| {
        Rgb([(x * 60 + y * 7) as u8, (255 - x * 50 - y * 30) as u8, [0, 10, 128][y as usize]])
    })
}

/// A 2x1 image of 16-bit channels, codes the 8-bit range cannot hold (40,000, 1,000, 65,535).
fn deep_image() -> image::ImageBuffer<Rgb<u16>, Vec<u16>> {
    image::ImageBuffer::from_fn(2, 1, |x, _| Rgb([x as u16 * 40_000, 1000, 65_535]))
}

fn load_one(path: &Path) -> Texture {
    let (set, warnings) = TextureSet::load(&[path]);
    assert!(warnings.is_empty(), "{warnings:?}");
    set.get(set.id_of(path).unwrap()).clone()
}

#[test]
fn png_texel_centres_read_the_srgb_decoded_values() {
    let dir = TempDir::new("textures-png");
    let image = test_image();
    let path = dir.path("grid.png");
    image.save_with_format(&path, ImageFormat::Png).unwrap();
    let texture = load_one(&path);
    assert_eq!((texture.width(), texture.height(), texture.has_alpha()), (4, 3, false));
    for (x, y, p) in image.enumerate_pixels() {
        let expected = linear_rgb(p.0);
        assert!(close(texture.texel(x, y), expected, 1e-7), "texel ({x}, {y})");
        let got = texture.sample(centre(x, y, 4, 3));
        assert!(close(got, expected, 1e-5), "centre of ({x}, {y}): {got} vs {expected}");
    }
    // Known values of the curve: its ends, the linear segment, and mid-grey.
    assert_eq!(srgb_to_linear(0.0), 0.0);
    assert_eq!(srgb_to_linear(1.0), 1.0);
    assert!((srgb_to_linear(10.0 / 255.0) - 10.0 / 255.0 / 12.92).abs() < 1e-9);
    assert!((srgb_to_linear(128.0 / 255.0) - 0.215_860_5).abs() < 1e-6);
}

/// BMP and TGA (which exporters of older scenes write) decode to the same texels as the PNG of
/// the same image: TGA run-length encoded or not, with or without alpha, bottom-up or top-down;
/// a TGA is known by its extension only.
#[test]
fn bmp_and_tga_files_decode_to_the_png_texels() {
    let dir = TempDir::new("textures-bmp-tga");
    let image = test_image();
    let png = dir.path("grid.png");
    image.save_with_format(&png, ImageFormat::Png).unwrap();
    let expected = load_one(&png);
    let bmp = dir.path("grid.bmp");
    image.save_with_format(&bmp, ImageFormat::Bmp).unwrap();
    let tga = dir.path("grid.tga");
    image.save_with_format(&tga, ImageFormat::Tga).unwrap();
    let upper = dir.path("GRID-ALPHA.TGA");
    RgbaImage::from_fn(4, 3, |x, y| {
        let p = image.get_pixel(x, y).0;
        Rgba([p[0], p[1], p[2], (x * 80) as u8])
    })
    .save_with_format(&upper, ImageFormat::Tga)
    .unwrap();
    // Uncompressed TGAs written by hand (the encoder writes run-length ones): an 18-byte header
    // (type 2, 24 bits, no id, no colour map), then BGR rows, bottom-up as TGA's default, or
    // top-down with bit 5 of the image descriptor set.
    let uncompressed = |top_down: bool| {
        let mut bytes = vec![0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 4, 0, 3, 0, 24, if top_down { 0x20 } else { 0 }];
        let rows: Vec<u32> = if top_down { (0..3).collect() } else { (0..3).rev().collect() };
        for y in rows {
            for x in 0..4 {
                let [r, g, b] = image.get_pixel(x, y).0;
                bytes.extend([b, g, r]);
            }
        }
        bytes
    };
    let bottom_up = dir.write("bottom-up.tga", uncompressed(false));
    let top_down = dir.write("top-down.tga", uncompressed(true));
    for path in [&bmp, &tga, &upper, &bottom_up, &top_down] {
        let texture = load_one(path);
        assert_eq!((texture.width(), texture.height()), (4, 3), "{}", path.display());
        for (x, y, _) in image.enumerate_pixels() {
            assert_eq!(texture.texel(x, y), expected.texel(x, y), "{} texel ({x}, {y})", path.display());
        }
    }
    assert!(load_one(&upper).has_alpha());
    // Without its extension, a TGA is not recognised: one warning, no texture.
    let unnamed = dir.write("grid.img", std::fs::read(&tga).unwrap());
    let (set, warnings) = TextureSet::load(&[&unnamed]);
    assert!(set.is_empty() && warnings[0].contains("not a PNG, JPEG, BMP or TGA image"), "{warnings:?}");
}

#[test]
fn bilinear_filtering_repeat_wrapping_and_the_bottom_left_origin() {
    let dir = TempDir::new("textures-filter");
    let image = test_image();
    let path = dir.path("grid.png");
    image.save_with_format(&path, ImageFormat::Png).unwrap();
    let texture = load_one(&path);
    let texel = |x: u32, y: u32| linear_rgb(image.get_pixel(x, y).0);
    // Midway between two texel centres, horizontally and vertically: their mean.
    let between = (centre(1, 1, 4, 3) + centre(2, 1, 4, 3)) / 2.0;
    assert!(close(texture.sample(between), (texel(1, 1) + texel(2, 1)) / 2.0, 1e-5));
    let between = (centre(3, 0, 4, 3) + centre(3, 1, 4, 3)) / 2.0;
    assert!(close(texture.sample(between), (texel(3, 0) + texel(3, 1)) / 2.0, 1e-5));
    // At the centre of four texels: their mean.
    let middle = (centre(0, 1, 4, 3) + centre(1, 2, 4, 3)) / 2.0;
    let mean = (texel(0, 1) + texel(1, 1) + texel(0, 2) + texel(1, 2)) / 4.0;
    assert!(close(texture.sample(middle), mean, 1e-5));
    // A quarter of the way: weights 3/4 and 1/4.
    let quarter = centre(1, 1, 4, 3) + Vec2::new(0.25 / 4.0, 0.0);
    assert!(close(texture.sample(quarter), texel(1, 1) * 0.75 + texel(2, 1) * 0.25, 1e-5));
    // Repeat: u = 1.25 and u = -0.75 read u = 0.25; v likewise.
    for v in [0.1f32, 0.5, 0.77] {
        let at = texture.sample(Vec2::new(0.25, v));
        assert!(close(texture.sample(Vec2::new(1.25, v)), at, 1e-5), "v {v}");
        assert!(close(texture.sample(Vec2::new(-0.75, v)), at, 1e-5), "v {v}");
        assert!(close(texture.sample(Vec2::new(0.25, v + 3.0)), at, 1e-5), "v {v}");
    }
    // Across the seam, the last column blends with the first.
    let seam = texture.sample(Vec2::new(1.0, centre(0, 1, 4, 3).y));
    assert!(close(seam, (texel(3, 1) + texel(0, 1)) / 2.0, 1e-5));
    // OBJ's origin is the bottom-left: the bottom row's centres are at v = 0.5/3, the top's at
    // v = 1 − 0.5/3.
    for x in 0..4 {
        let u = (x as f32 + 0.5) / 4.0;
        assert!(close(texture.sample(Vec2::new(u, 0.5 / 3.0)), texel(x, 2), 1e-5), "bottom row, x {x}");
        assert!(close(texture.sample(Vec2::new(u, 1.0 - 0.5 / 3.0)), texel(x, 0), 1e-5), "top row, x {x}");
        // Just above v = 0 the bottom row dominates.
        let low = texture.sample(Vec2::new(u, 0.01));
        assert!((low - texel(x, 2)).length() < (low - texel(x, 0)).length(), "v = 0.01 leans to the bottom row");
    }
}

#[test]
fn absurd_coordinates_read_a_texel_without_panicking() {
    let texture = Texture::from_linear(3, 2, (0..6).map(|i| Vec3::splat(i as f32 / 5.0)).collect(), None).unwrap();
    let values = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30, 3e9, -1e-30, f32::MAX, f32::MIN, -0.0, 1.0];
    for u in values {
        for v in values {
            let c = texture.sample(Vec2::new(u, v));
            assert!(c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0 + 1e-6, "({u}, {v}) → {c}");
            assert_eq!(texture.sample_alpha(Vec2::new(u, v)), 1.0);
        }
    }
    assert!(Texture::from_linear(3, 2, vec![Vec3::ZERO; 5], None).is_none(), "sizes must match");
    assert!(Texture::from_linear(0, 0, vec![], None).is_none(), "empty");
}

/// A texture from linear values takes an alpha channel of exactly one value per texel, and
/// filters it as it filters colour.
#[test]
fn linear_textures_take_an_alpha_of_one_value_per_texel() {
    let rgb = || vec![Vec3::splat(0.5); 6];
    let alpha = vec![0.0, 0.25, 0.5, 0.75, 1.0, 0.5];
    let texture = Texture::from_linear(3, 2, rgb(), Some(alpha.clone())).expect("sizes match");
    assert!(texture.has_alpha());
    for (i, &a) in alpha.iter().enumerate() {
        let (x, y) = (i as u32 % 3, i as u32 / 3);
        let got = texture.sample_alpha(centre(x, y, 3, 2));
        assert!((got - a).abs() < 1e-6, "texel ({x}, {y}): {got} vs {a}");
    }
    assert!(Texture::from_linear(3, 2, rgb(), Some(vec![1.0; 5])).is_none(), "alpha too short");
    assert!(Texture::from_linear(3, 2, rgb(), Some(vec![1.0; 7])).is_none(), "alpha too long");
}

/// 8-bit files keep their codes, 4 bytes a texel (RGB and a padding byte), a third of the 12 of
/// linear `f32` RGB that 16-bit files and linear textures take; alpha adds 4 bytes a texel.
#[test]
fn eight_bit_textures_keep_their_codes_in_a_third_of_the_memory() {
    let dir = TempDir::new("textures-memory-bytes");
    let rgb8 = dir.path("rgb8.png");
    test_image().save_with_format(&rgb8, ImageFormat::Png).unwrap();
    let rgba8 = dir.path("rgba8.png");
    RgbaImage::from_fn(2, 2, |x, y| Rgba([10, 20, 30, (x + y) as u8]))
        .save_with_format(&rgba8, ImageFormat::Png)
        .unwrap();
    let rgb16 = dir.path("rgb16.png");
    deep_image().save_with_format(&rgb16, ImageFormat::Png).unwrap();
    assert_eq!(load_one(&rgb8).memory_bytes(), 4 * 3 * 4);
    assert_eq!(load_one(&rgba8).memory_bytes(), 2 * 2 * (4 + 4));
    assert_eq!(load_one(&rgb16).memory_bytes(), 2 * 12);
    let linear = Texture::from_linear(3, 2, vec![Vec3::ONE; 6], Some(vec![1.0; 6])).unwrap();
    assert_eq!(linear.memory_bytes(), 6 * (12 + 4));
    let (set, _) = TextureSet::load(&[&rgb8, &rgba8, &rgb16]);
    assert_eq!(set.memory_bytes(), 48 + 32 + 24);
}

/// Each id of a set names its own texture: the second of two different files reads the second
/// file's texels, not the first's.
#[test]
fn each_texture_id_reads_its_own_texture() {
    let dir = TempDir::new("textures-ids");
    let (first, second) = (dir.path("first.png"), dir.path("second.png"));
    RgbImage::from_pixel(1, 1, Rgb([255, 0, 0])).save_with_format(&first, ImageFormat::Png).unwrap();
    RgbImage::from_pixel(1, 1, Rgb([0, 0, 255])).save_with_format(&second, ImageFormat::Png).unwrap();
    let (set, warnings) = TextureSet::load(&[&first, &second]);
    assert!(warnings.is_empty(), "{warnings:?}");
    let (a, b) = (set.id_of(&first).unwrap(), set.id_of(&second).unwrap());
    assert_eq!((a.index(), b.index()), (0, 1));
    assert_eq!(set.sample(a, Vec2::splat(0.5)), Vec3::X);
    assert_eq!(set.sample(b, Vec2::splat(0.5)), Vec3::Z);
    assert_eq!(set.get(b).texel(0, 0), Vec3::Z);
}

#[test]
fn jpeg_textures_decode_to_linear_values() {
    let dir = TempDir::new("textures-jpeg");
    // Two flat 8 × 8 blocks (JPEG's unit), which survive compression at quality 100 almost exactly.
    let (left, right) = ([200u8, 120, 40], [30u8, 90, 220]);
    let image = RgbImage::from_fn(16, 8, |x, _| Rgb(if x < 8 { left } else { right }));
    let path = dir.path("blocks.jpg");
    let mut bytes = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut bytes, 100).encode_image(&image).unwrap();
    std::fs::write(&path, bytes).unwrap();
    let texture = load_one(&path);
    assert_eq!((texture.width(), texture.height()), (16, 8));
    // Within 2 codes of the sRGB values, measured in the encoded domain (chroma subsampling and
    // quantisation move flat blocks by a code or so).
    let encoded = |linear: f32| {
        let l = linear as f64;
        (if l <= 0.0031308 { l * 12.92 } else { 1.055 * l.powf(1.0 / 2.4) - 0.055 }) * 255.0
    };
    for (uv, expected) in [(Vec2::new(0.25, 0.5), left), (Vec2::new(0.75, 0.5), right)] {
        let got = texture.sample(uv);
        for c in 0..3 {
            let code = encoded(got[c]);
            assert!(
                (code - expected[c] as f64).abs() <= 2.0,
                "{uv}: channel {c} decodes to code {code}, wrote {}",
                expected[c]
            );
        }
    }
}

#[test]
fn alpha_is_kept_linear_and_sixteen_bit_pngs_decode_exactly() {
    let dir = TempDir::new("textures-alpha");
    let image = RgbaImage::from_fn(2, 2, |x, y| Rgba([255, 128, 0, [[0u8, 64], [191, 255]][y as usize][x as usize]]));
    let path = dir.path("alpha.png");
    image.save_with_format(&path, ImageFormat::Png).unwrap();
    let texture = load_one(&path);
    assert!(texture.has_alpha());
    for (x, y, p) in image.enumerate_pixels() {
        let uv = centre(x, y, 2, 2);
        assert!((texture.sample_alpha(uv) - p.0[3] as f32 / 255.0).abs() < 1e-5, "alpha at ({x}, {y})");
        assert!(close(texture.sample(uv), linear_rgb([255, 128, 0]), 1e-5));
    }
    let path = dir.path("deep.png");
    deep_image().save_with_format(&path, ImageFormat::Png).unwrap();
    let texture = load_one(&path);
    let expected = |c: u16| srgb_to_linear(c as f32 / 65535.0);
    assert!(close(texture.texel(1, 0), Vec3::new(expected(40_000), expected(1000), 1.0), 1e-7));
}

/// A 16-bit file's alpha is linear coverage too, read to its full depth: a cutout (`map_d`) drawn
/// at 16 bits cuts where its alpha says, with levels that 8 bits cannot hold.
#[test]
fn sixteen_bit_alpha_is_kept_linear_to_its_full_depth() {
    let dir = TempDir::new("textures-alpha16");
    let levels = [0u16, 1000, 32_768, 40_000, 65_535];
    let image = image::ImageBuffer::from_fn(5, 1, |x, _| Rgba([65_535u16, 0, 0, levels[x as usize]]));
    let path = dir.path("alpha16.png");
    image.save_with_format(&path, ImageFormat::Png).unwrap();
    let texture = load_one(&path);
    assert!(texture.has_alpha());
    for (x, &level) in levels.iter().enumerate() {
        let uv = centre(x as u32, 0, 5, 1);
        let expected = f32::from(level) / 65_535.0;
        let (alpha, coverage) = (texture.sample_alpha(uv), texture.sample_coverage(uv));
        assert!((alpha - expected).abs() < 1e-6, "texel {x}: alpha {alpha} vs {expected}");
        assert_eq!(coverage, alpha, "texel {x}: coverage is the alpha");
    }
}

#[test]
fn unusable_files_cost_one_warning_each_and_no_texture() {
    let dir = TempDir::new("textures-bad");
    let good = dir.path("good.png");
    test_image().save_with_format(&good, ImageFormat::Png).unwrap();
    let missing = dir.path("missing.png");
    let garbage = dir.write("garbage.jpg", b"this is not an image");
    let truncated = {
        let bytes = std::fs::read(&good).unwrap();
        dir.write("truncated.png", &bytes[..bytes.len() / 2])
    };
    // A JPEG cut after its first marker: the decoder's message ends with a newline.
    let truncated_jpeg = dir.write("truncated.jpg", b"\xff\xd8\xff\xe0\x00\x10JFIF\x00");
    std::fs::create_dir(dir.path("folder.png")).unwrap();
    let folder = dir.path("folder.png");
    // Materials: none, good, missing, good again, garbage, truncated twice, a folder, missing again.
    let map_kd: Vec<Option<PathBuf>> = vec![
        None,
        Some(good.clone()),
        Some(missing.clone()),
        Some(good.clone()),
        Some(garbage.clone()),
        Some(truncated),
        Some(truncated_jpeg),
        Some(folder),
        Some(missing.clone()),
    ];
    let (ids, set, warnings) =
        TextureSet::for_materials(map_kd.iter().map(|p| p.as_deref()), &EmbeddedImages::default());
    assert_eq!(set.len(), 1, "the good file, decoded once");
    let good_id = set.id_of(&good).unwrap();
    assert_eq!(set.contents_hash(good_id), hash_bytes(&std::fs::read(&good).unwrap()));
    assert_eq!(ids, vec![None, Some(good_id), None, Some(good_id), None, None, None, None, None]);
    assert_eq!(warnings.len(), 5, "one per distinct unusable file: {warnings:#?}");
    let names = ["missing.png", "garbage.jpg", "truncated.png", "truncated.jpg", "folder.png"];
    for (warning, name) in warnings.iter().zip(names) {
        assert!(warning.contains(&format!("\"{}\"", dir.path(name).display())), "names the file, quoted: {warning}");
        assert!(warning.contains("Kd is used instead"), "{warning}");
        assert!(!warning.contains(['\n', '\r']), "one line: {warning:?}");
    }
    assert!(warnings[4].contains("not a regular file"), "{}", warnings[4]);
    // A path with a control character (from an MTL line) is escaped, never printed raw.
    let odd = dir.path("odd\u{1b}[2Jname.png");
    let (_, _, warnings) = TextureSet::for_materials([Some(odd.as_path())], &EmbeddedImages::default());
    assert!(warnings[0].contains("odd\\u{1b}[2Jname.png") && !warnings[0].contains('\u{1b}'), "{}", warnings[0]);
}

/// Textures are decoded only while memory is left for them, in file order: one that does not fit
/// is a warning (its decoding would have aborted the process, as a 16-bit 8192 × 8192 file did
/// under a memory limit), and the same files fit in the same order whatever the threads.
#[test]
fn textures_that_do_not_fit_in_memory_are_refused_in_order() {
    let dir = TempDir::new("textures-memory");
    let image = image::ImageBuffer::<image::Rgb<u16>, _>::from_fn(64, 64, |x, y| {
        image::Rgb([x as u16 * 999, y as u16 * 999, 7])
    });
    let (first, second) = (dir.path("first.png"), dir.path("second.png"));
    image.save(&first).unwrap();
    image.save(&second).unwrap();
    // 64 × 64 texels of 6 bytes, copied as RGBA16 (8), kept as linear f32 RGB (12): 104 KiB each.
    let (set, warnings) = TextureSet::load_with_memory(&[&first, &second], 200 << 10);
    assert_eq!(set.len(), 1, "{warnings:?}");
    assert!(set.id_of(&first).is_some() && set.id_of(&second).is_none());
    assert_eq!(warnings.len(), 1);
    assert!(warnings[0].contains("second.png") && warnings[0].contains("64×64 texels needs about"), "{}", warnings[0]);
    assert!(
        warnings[0].contains("MiB of memory, but only") && warnings[0].contains("Kd is used instead"),
        "{}",
        warnings[0]
    );
    let (set, warnings) = TextureSet::load_with_memory(&[&first, &second], 1 << 20);
    assert_eq!((set.len(), warnings.len()), (2, 0), "{warnings:?}");
}

/// A PNG whose header claims 20000 × 20000 pixels is refused from the header, before decoding.
#[test]
fn absurd_image_sizes_are_refused_before_decoding() {
    let dir = TempDir::new("textures-huge");
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let chunk = |png: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
        png.extend((data.len() as u32).to_be_bytes());
        let mut crc = flate2::Crc::new();
        crc.update(kind);
        crc.update(data);
        png.extend(kind);
        png.extend(data);
        png.extend(crc.sum().to_be_bytes());
    };
    let mut header = Vec::new();
    header.extend(20_000u32.to_be_bytes());
    header.extend(20_000u32.to_be_bytes());
    header.extend([8, 2, 0, 0, 0]); // 8-bit RGB
    chunk(&mut png, b"IHDR", &header);
    chunk(&mut png, b"IDAT", &[]);
    chunk(&mut png, b"IEND", &[]);
    let path = dir.write("huge.png", png);
    // A TGA header of 65535 × 65535 true-colour pixels, then nothing.
    let mut tga = vec![0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0];
    tga.extend(65_535u16.to_le_bytes());
    tga.extend(65_535u16.to_le_bytes());
    tga.extend([24, 0]);
    let huge_tga = dir.write("huge.tga", tga);
    let (set, warnings) = TextureSet::load(&[&path, &huge_tga]);
    assert!(set.is_empty());
    assert_eq!(warnings.len(), 2);
    assert!(warnings[0].contains("20000×20000") && warnings[0].contains(&MAX_TEXELS.to_string()), "{}", warnings[0]);
    assert!(warnings[1].contains("65535×65535"), "{}", warnings[1]);
}

/// The staircase's textures, where `../shared` is present: all decode, each once.
#[test]
fn the_staircase_textures_decode() {
    let Some(folder) = crate::common::shared_scene("staircase/textures") else { return };
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&folder).unwrap().map(|e| e.unwrap().path()).collect();
    paths.sort();
    let (set, warnings) = TextureSet::load(&paths);
    assert!(warnings.is_empty(), "{warnings:#?}");
    assert_eq!(set.len(), paths.len());
    println!("{} textures, {} MiB as linear f32", set.len(), set.memory_bytes() >> 20);
}

/// Cutout coverage (`map_d`): the alpha channel where the file has one, otherwise the grey levels
/// as stored (no sRGB decoding), the same at 8 and 16 bits, and the luminance of a coloured mask.
#[test]
fn coverage_is_the_alpha_or_the_stored_grey_at_either_depth() {
    use image::{ImageBuffer, Luma};
    let dir = TempDir::new("textures-coverage");
    // Level 5 lies on the sRGB curve's linear segment (5/255 < 0.04045), the others on its power.
    let levels = [0u8, 5, 64, 128, 200, 255];
    let grey8 = dir.path("grey8.png");
    ImageBuffer::from_fn(6, 1, |x, _| Luma([levels[x as usize]])).save_with_format(&grey8, ImageFormat::Png).unwrap();
    let grey16 = dir.path("grey16.png");
    ImageBuffer::from_fn(6, 1, |x, _| Luma([u16::from(levels[x as usize]) * 257]))
        .save_with_format(&grey16, ImageFormat::Png)
        .unwrap();
    let rgba = dir.path("rgba.png");
    // Black colour, alpha from the levels: only the alpha may count.
    RgbaImage::from_fn(6, 1, |x, _| Rgba([0, 0, 0, levels[x as usize]]))
        .save_with_format(&rgba, ImageFormat::Png)
        .unwrap();
    for path in [&grey8, &grey16, &rgba] {
        let texture = load_one(path);
        for (x, &level) in levels.iter().enumerate() {
            let coverage = texture.sample_coverage(centre(x as u32, 0, 6, 1));
            let expected = f32::from(level) / 255.0;
            assert!((coverage - expected).abs() < 1e-4, "{}: texel {x}: {coverage} vs {expected}", path.display());
        }
    }
    // A coloured mask reads as the Rec. 709 luminance of its codes.
    let colour = dir.path("colour.png");
    RgbImage::from_fn(1, 1, |_, _| Rgb([255, 0, 0])).save_with_format(&colour, ImageFormat::Png).unwrap();
    assert!((load_one(&colour).sample_coverage(Vec2::splat(0.5)) - 0.2126).abs() < 1e-6);
}

/// A texture that paints a parameter (a roughness, a metallic weight) is data: each channel reads
/// the values the file stores, not sRGB-decoded, the same at 8 and 16 bits, and the luminance
/// channel reads a grey level as itself.
#[test]
fn a_channel_reads_the_stored_values_at_either_depth() {
    use image::ImageBuffer;
    use lumiere::textures::Channel;
    let dir = TempDir::new("textures-channels");
    let codes = |x: u32| [(x * 50) as u8, 255 - (x * 40) as u8, [5, 128, 200, 0][x as usize]];
    let eight = dir.path("eight.png");
    RgbImage::from_fn(4, 1, |x, _| Rgb(codes(x))).save_with_format(&eight, ImageFormat::Png).unwrap();
    let sixteen = dir.path("sixteen.png");
    ImageBuffer::from_fn(4, 1, |x, _| Rgb(codes(x).map(|c| u16::from(c) * 257)))
        .save_with_format(&sixteen, ImageFormat::Png)
        .unwrap();
    for path in [&eight, &sixteen] {
        let texture = load_one(path);
        for x in 0..4 {
            let stored = codes(x).map(|c| f32::from(c) / 255.0);
            let luminance = 0.2126 * stored[0] + 0.7152 * stored[1] + 0.0722 * stored[2];
            for (channel, expected) in [
                (Channel::Red, stored[0]),
                (Channel::Green, stored[1]),
                (Channel::Blue, stored[2]),
                (Channel::Luminance, luminance),
            ] {
                let value = texture.sample_channel(centre(x, 0, 4, 1), channel);
                assert!(
                    (value - expected).abs() < 1e-4,
                    "{}: texel {x} {channel:?}: {value} vs {expected}",
                    path.display()
                );
            }
        }
    }
}

/// A diffuse texture's `-s` and `-o` (MTL) move where the surface reads it, through everything
/// that shades (`World::lambert_reflectance` and `World::bsdf` share the lookup): `uv · s + o`.
#[test]
fn texture_placement_scales_and_offsets_the_lookup() {
    use lumiere::accel::BuildPreset;
    use lumiere::materials::Material;
    use lumiere::math::UvTransform;
    use lumiere::scene::Scene;
    use lumiere::scene::mesh::TriangleMesh;
    use lumiere::world::World;

    let dir = TempDir::new("texture-placement");
    let path = dir.path("four.png");
    test_image().save_with_format(&path, ImageFormat::Png).unwrap();
    let texture = load_one(&path);
    let mesh = TriangleMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        indices: vec![[0, 1, 2]],
        material_ids: vec![0],
        ..Default::default()
    };
    let placements = [
        UvTransform::default(),
        UvTransform { scale: Vec2::new(2.0, 3.0), offset: Vec2::ZERO },
        UvTransform { scale: Vec2::ONE, offset: Vec2::new(0.25, -1.0 / 3.0) },
        UvTransform { scale: Vec2::new(-1.0, 0.5), offset: Vec2::new(0.125, 0.5) },
    ];
    for placement in placements {
        let material =
            Material { map_kd: Some(path.clone()), map_kd_transform: placement, ..Material::default_grey("t") };
        let scene = Scene::from_parts("placed".into(), mesh.clone(), vec![material], vec![]).unwrap();
        let world = World::new(scene, BuildPreset::Default);
        for (x, y) in [(0, 0), (1, 2), (3, 1)] {
            let uv = centre(x, y, 4, 3);
            let got = world.lambert_reflectance(0, uv).expect("a diffuse material");
            assert_eq!(got, texture.sample(uv * placement.scale + placement.offset), "{placement:?} at {uv}");
        }
    }
    // The comparison can fail: a shift by one texel reads another texel's colour.
    let shifted = UvTransform { scale: Vec2::ONE, offset: Vec2::new(0.25, 0.0) };
    let uv = centre(1, 1, 4, 3);
    assert!(!close(texture.sample(shifted.apply(uv)), texture.sample(uv), 1e-3));
    assert!(close(texture.sample(shifted.apply(uv)), texture.sample(centre(2, 1, 4, 3)), 1e-6));
}

/// A TGA has no signature, so any bytes named `.tga` reach its decoder: cut and corrupted files
/// (and noise) give an error or an image, never a panic or a huge allocation.
#[test]
fn corrupt_tga_files_are_refused_without_panicking() {
    let image = test_image();
    let dir = TempDir::new("textures-tga-noise");
    let good = dir.path("good.tga");
    image.save_with_format(&good, ImageFormat::Tga).unwrap();
    let good = std::fs::read(&good).unwrap();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let name = std::path::Path::new("noise.tga");
    for case in 0..2000 {
        let mut bytes = good.clone();
        match case % 3 {
            0 => bytes.truncate(next() as usize % good.len()),
            1 => {
                for _ in 0..1 + next() % 4 {
                    let at = next() as usize % bytes.len();
                    bytes[at] = next() as u8;
                }
            }
            _ => bytes = (0..next() % 64).map(|_| next() as u8).collect(),
        }
        if let Ok(texture) = Texture::decode_named(&bytes, Some(name)) {
            assert!(u64::from(texture.width()) * u64::from(texture.height()) <= MAX_TEXELS);
        }
    }
}

/// A render resumes only over the textures it started with: the scene's fingerprint, which a
/// checkpoint stores, holds the bytes of each texture file, so an edited texture (or a missing one)
/// is another scene. It held only their names, and a resume blended two images without a word.
#[test]
fn the_scene_fingerprint_holds_the_texture_files_bytes() {
    let dir = TempDir::new("fingerprint-textures");
    dir.write("m.mtl", "newmtl wood\nmap_Kd wood.png\nnewmtl leaf\nmap_d mask.png\n");
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
               usemtl wood\nf 1/1 2/2 3/3\nusemtl leaf\nf 1/1 3/3 2/2\n";
    let scene = dir.write("s.obj", obj);
    let save = |name: &str, image: &RgbImage| image.save_with_format(dir.path(name), ImageFormat::Png).unwrap();
    let fingerprint = || scene_fingerprint(&World::new(Scene::load(&scene).unwrap(), Default::default()));
    save("wood.png", &test_image());
    save("mask.png", &test_image());
    let first = fingerprint();
    assert_eq!(fingerprint(), first, "the same files, the same fingerprint");
    let mut edited = test_image();
    edited.put_pixel(1, 1, Rgb([1, 2, 3]));
    save("wood.png", &edited);
    let wood_edited = fingerprint();
    save("mask.png", &edited);
    let both_edited = fingerprint();
    std::fs::remove_file(dir.path("wood.png")).unwrap();
    let wood_missing = fingerprint();
    let all = [first, wood_edited, both_edited, wood_missing];
    for (i, a) in all.iter().enumerate() {
        assert!(all[i + 1..].iter().all(|b| a != b), "{all:x?}");
    }
}

/// A texture's placement (`-s`, `-o`) is part of the scene's fingerprint: a render of tiles
/// placed one way does not resume with them placed another. The identity placement, written out
/// or not, is the same scene, so that the fingerprints of scenes without placements (and their
/// checkpoints) stay what they were.
#[test]
fn the_scene_fingerprint_holds_the_texture_placements() {
    let dir = TempDir::new("fingerprint-placements");
    test_image().save_with_format(dir.path("wood.png"), ImageFormat::Png).unwrap();
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl wood\nf 1/1 2/2 3/3\n";
    let scene = dir.write("s.obj", obj);
    let fingerprint = |map_kd: &str, map_d: &str| {
        dir.write("m.mtl", format!("newmtl wood\nmap_Kd {map_kd}wood.png\nmap_d {map_d}wood.png\n"));
        scene_fingerprint(&World::new(Scene::load(&scene).unwrap(), Default::default()))
    };
    let plain = fingerprint("", "");
    assert_eq!(fingerprint("-s 1 1 1 -o 0 0 0 ", "-s 1 1 -o 0 0 "), plain, "the identity placement written out");
    let placed = [
        plain,
        fingerprint("-s 2 2 1 ", ""),
        fingerprint("-o 0.5 0 0 ", ""),
        fingerprint("", "-s 2 2 1 "),
        fingerprint("", "-o 0.5 0 0 "),
    ];
    for (i, a) in placed.iter().enumerate() {
        assert!(placed[i + 1..].iter().all(|b| a != b), "{placed:x?}");
    }
}

/// How a mask cuts (glTF's `alphaMode MASK`: alpha alone, times a factor, against a cutoff) is
/// part of the scene's fingerprint; MTL's rule adds nothing, so that the fingerprints of OBJ
/// scenes with cutouts stay what they were.
#[test]
fn the_scene_fingerprint_holds_how_a_mask_cuts() {
    let dir = TempDir::new("fingerprint-mask-tests");
    test_image().save_with_format(dir.path("leaf.png"), ImageFormat::Png).unwrap();
    dir.write("m.mtl", "newmtl leaf\nmap_Kd leaf.png\nmap_d leaf.png\n");
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl leaf\nf 1/1 2/2 3/3\n";
    let scene = dir.write("s.obj", obj);
    let fingerprint = |test: Option<CoverageTest>| {
        let mut scene = Scene::load(&scene).unwrap();
        if let Some(test) = test {
            scene.materials[0].map_d_test = test;
        }
        scene_fingerprint(&World::new(scene, Default::default()))
    };
    let plain = fingerprint(None);
    assert_eq!(fingerprint(Some(CoverageTest::MTL)), plain);
    let tests = [
        plain,
        fingerprint(Some(CoverageTest { alpha_only: true, ..CoverageTest::MTL })),
        fingerprint(Some(CoverageTest { scale: 0.5, ..CoverageTest::MTL })),
        fingerprint(Some(CoverageTest { cut: Cut::Below(0.3), ..CoverageTest::MTL })),
        fingerprint(Some(CoverageTest { cut: Cut::Hashed, ..CoverageTest::MTL })),
    ];
    for (i, a) in tests.iter().enumerate() {
        assert!(tests[i + 1..].iter().all(|b| a != b), "{tests:x?}");
    }
}

/// The maps that paint a material's metallic weight and roughness, and its normal or bump map,
/// are part of the scene's fingerprint: their files' bytes, the channel each reads, its factor and
/// its placement, and whether a map holds directions or heights; so is a base colour texture's
/// factor.
#[test]
fn the_scene_fingerprint_holds_the_parameter_and_normal_maps() {
    use lumiere::textures::Channel;
    let dir = TempDir::new("fingerprint-parameter-maps");
    test_image().save_with_format(dir.path("orm.png"), ImageFormat::Png).unwrap();
    dir.write("m.mtl", "newmtl brass\nPm 1\nPr 0.5\nmap_Pr -imfchan g orm.png\n");
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl brass\nf 1/1 2/2 3/3\n";
    let scene = dir.write("s.obj", obj);
    let fingerprint = |edit: &dyn Fn(&mut lumiere::materials::Material)| {
        let mut scene = Scene::load(&scene).unwrap();
        edit(&mut scene.materials[0]);
        scene_fingerprint(&World::new(scene, Default::default()))
    };
    let plain = fingerprint(&|_| {});
    assert_eq!(fingerprint(&|_| {}), plain, "the same files, the same fingerprint");
    let normal_map = |scale, relief| lumiere::materials::NormalMap {
        path: dir.path("orm.png"),
        transform: Default::default(),
        scale,
        relief,
    };
    let heights = |channel| Relief::Heights { channel };
    let mut fingerprints = vec![
        plain,
        fingerprint(&|m| m.map_pr = None),
        fingerprint(&|m| m.map_pm = m.map_pr.take()),
        fingerprint(&|m| m.map_pr.as_mut().unwrap().channel = Channel::Blue),
        fingerprint(&|m| m.map_pr.as_mut().unwrap().scale = 0.5),
        fingerprint(&|m| m.map_pr.as_mut().unwrap().transform.offset.x = 0.5),
        fingerprint(&|m| m.normal_map = Some(normal_map(1.0, Relief::Directions))),
        fingerprint(&|m| m.normal_map = Some(normal_map(0.5, Relief::Directions))),
        fingerprint(&|m| m.normal_map = Some(normal_map(1.0, heights(Channel::Luminance)))),
        fingerprint(&|m| m.normal_map = Some(normal_map(1.0, heights(Channel::Red)))),
        fingerprint(&|m| m.map_kd_factor = Vec3::new(0.5, 1.0, 1.0)),
    ];
    let mut edited = test_image();
    edited.put_pixel(1, 1, Rgb([1, 2, 3]));
    edited.save_with_format(dir.path("orm.png"), ImageFormat::Png).unwrap();
    fingerprints.push(fingerprint(&|_| {}));
    std::fs::remove_file(dir.path("orm.png")).unwrap();
    fingerprints.push(fingerprint(&|_| {}));
    for (i, a) in fingerprints.iter().enumerate() {
        assert!(fingerprints[i + 1..].iter().all(|b| a != b), "{fingerprints:x?}");
    }
}

/// A textured material whose triangles lack texture coordinates reads its textures at
/// `u = v = 0` there: the scene names the material and how many of its triangles, once; a
/// material without textures, or one whose triangles all have coordinates, costs nothing.
#[test]
fn textured_triangles_without_texture_coordinates_are_named() {
    let dir = TempDir::new("texcoords-missing");
    dir.write(
        "m.mtl",
        "newmtl wood\nmap_Kd wood.png\nnewmtl rough\nmap_Pr r.png\nnewmtl bumpy\nbump b.png\nnewmtl plain\nKd 1 0 0\n\
         newmtl tiles\nmap_Kd tiles.png\n",
    );
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n\
               usemtl wood\nf 1/1 2/2 3/3\nf 1 2 3\nf 3 2 1\nusemtl rough\nf 1 2 3\nusemtl bumpy\nf 1 2 3\n\
               usemtl plain\nf 1 2 3\nusemtl tiles\nf 1/1 2/2 3/3\n";
    let scene = Scene::load(&dir.write("s.obj", obj)).unwrap();
    let named = |material: &str, without: usize, total: usize, relief: &str| {
        format!(
            "{}: material '{material}': {without} of its {total} triangles have no texture coordinates: its \
             textures are read at u = v = 0 there{relief}",
            dir.path("s.obj").display()
        )
    };
    let mut warnings: Vec<&String> = scene.warnings.iter().filter(|w| w.contains("texture coordinates")).collect();
    warnings.sort();
    let expected = [
        named("bumpy", 1, 1, ", and its normal or bump map is not applied"),
        named("rough", 1, 1, ""),
        named("wood", 2, 3, ""),
    ];
    assert_eq!(warnings, expected.iter().collect::<Vec<_>>(), "{:#?}", scene.warnings);
}
