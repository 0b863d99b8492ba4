//! Mip-maps and footprints: each texture's chain of halvings averages its texels in linear light,
//! a footprint of less than two texels reads the image itself bit for bit, and a camera ray whose
//! pixel covers many texels reads their mean, where the image alone would alias.

use std::path::PathBuf;

use glam::{Vec2, Vec3};
use image::{ImageFormat, Rgb, RgbImage};
use lumiere::integrators::{FOOTPRINT_SAMPLES, RayCone};
use lumiere::integrators::{Materials, Technique};
use lumiere::materials::Bsdf;
use lumiere::materials::Material;
use lumiere::render::RenderOptions;
use lumiere::render::aov::{Aov, render_aovs};
use lumiere::scene::Scene;
use lumiere::scene::camera::Camera;
use lumiere::scene::mesh::TriangleMesh;
use lumiere::textures::{Texture, TextureSet};
use lumiere::world::World;

use crate::common::{TempDir, TestRng};

/// The texture coordinates of the centre of texel (x, y) of a `width × height` level, row y from
/// the top.
fn centre(x: u32, y: u32, width: u32, height: u32) -> Vec2 {
    Vec2::new((x as f32 + 0.5) / width as f32, 1.0 - (y as f32 + 0.5) / height as f32)
}

fn close(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

/// Footprints (texels²) whose width in texels is `n`.
fn across(n: f32) -> f32 {
    n * n
}

#[test]
fn levels_halve_in_linear_light_down_to_one_texel() {
    // 4 × 2, texel (x, y) = x + 4y, with a colour per channel.
    let values: Vec<Vec3> = (0..8).map(|i| Vec3::new(i as f32, 10.0 * i as f32, 0.5) / 80.0).collect();
    let mut texture = Texture::from_linear(4, 2, values.clone(), None).unwrap();
    assert_eq!(texture.levels(), 1, "no chain before it is asked for");
    texture.build_mip_chain();
    assert_eq!(texture.levels(), 3, "4x2, 2x1, 1x1");
    let texel = |x: usize, y: usize| values[x + 4 * y];
    for x in 0..2u32 {
        let (x0, x1) = (2 * x as usize, 2 * x as usize + 1);
        let mean = (texel(x0, 0) + texel(x1, 0) + texel(x0, 1) + texel(x1, 1)) * 0.25;
        // Two to four texels across read level 1, at its texel centres exactly its texels.
        for width in [2.0, 3.0, 3.99] {
            let read = texture.sample_footprint(centre(x, 0, 2, 1), across(width));
            assert!(close(read, mean, 1e-7), "level 1 texel {x}: {read} against {mean}");
        }
    }
    let mean = values.iter().sum::<Vec3>() / 8.0;
    for width in [4.0, 100.0, 1e30, f32::INFINITY] {
        let read = texture.sample_footprint(Vec2::new(0.3, 0.8), across(width));
        assert!(close(read, mean, 1e-7), "{width} texels across: the last level, the mean");
    }
}

#[test]
fn odd_sizes_wrap_into_the_first_texel() {
    let values = vec![Vec3::splat(0.0), Vec3::splat(0.2), Vec3::splat(0.6)];
    let mut texture = Texture::from_linear(3, 1, values, None).unwrap();
    texture.build_mip_chain();
    assert_eq!(texture.levels(), 3, "3x1, 2x1, 1x1");
    let second = texture.sample_footprint(centre(1, 0, 2, 1), across(2.0));
    assert!(close(second, Vec3::splat(0.3), 1e-7), "texel 2 and texel 0 (wrapped): {second}");
}

#[test]
fn footprints_under_two_texels_read_the_image_bit_for_bit() {
    let dir = TempDir::new("mip_full_resolution");
    let path = dir.path("noise.png");
    let mut rng = TestRng(7);
    let image = RgbImage::from_fn(37, 23, |_, _| Rgb([0, 1, 2].map(|_| rng.below(256) as u8)));
    image.save_with_format(&path, ImageFormat::Png).unwrap();
    let (ids, set, warnings) = TextureSet::for_materials([Some(path.as_path())]);
    assert!(warnings.is_empty(), "{warnings:?}");
    let texture = set.get(ids[0].unwrap());
    assert_eq!(texture.levels(), 7, "37x23 down to 1x1: 19x12, 10x6, 5x3, 3x2, 2x1, 1x1");
    for _ in 0..2000 {
        let uv = Vec2::new(rng.range(-2.0, 3.0), rng.range(-2.0, 3.0));
        for footprint in [0.0, 0.25, 1.0, 3.99, -1.0, f32::NAN] {
            assert_eq!(texture.sample_footprint(uv, footprint), texture.sample(uv), "{uv} {footprint}");
        }
    }
}

/// Black and white checks of one texel, `size` by `size`, saved as a PNG in `dir`: every 2×2 block
/// holds two of each, whose linear mean is a half.
fn checks(dir: &TempDir, size: u32) -> PathBuf {
    let path = dir.path(&format!("checks{size}.png"));
    RgbImage::from_fn(size, size, |x, y| Rgb([if (x + y) % 2 == 0 { 255 } else { 0 }; 3]))
        .save_with_format(&path, ImageFormat::Png)
        .unwrap();
    path
}

/// The linear value of the 8-bit code nearest a linear half: 188 (0.5029).
fn nearest_half() -> f32 {
    lumiere::textures::srgb_to_linear(188.0 / 255.0)
}

#[test]
fn an_eight_bit_level_keeps_the_code_nearest_the_linear_mean() {
    let dir = TempDir::new("mip_codes");
    let path = checks(&dir, 8);
    let (ids, set, _) = TextureSet::for_materials([Some(path.as_path())]);
    let texture = set.get(ids[0].unwrap());
    let half = nearest_half();
    for width in [2.0, 5.0, 8.0, 1e6] {
        let read = texture.sample_footprint(Vec2::new(0.37, 0.61), across(width));
        // To within the rounding of the bilinear weights, which sum to 1 within an ulp.
        assert!(close(read, Vec3::splat(half), 1e-6), "{width} texels across: {read}, not code 188's {half}");
    }
}

#[test]
fn ray_cones_start_at_the_pinhole_and_widen_at_sampled_bounces() {
    let pixel = 0.002;
    let jittered = RayCone::camera(pixel, true);
    let share = 1.0 / FOOTPRINT_SAMPLES.sqrt();
    assert_eq!(jittered.width, 0.0);
    assert!((jittered.width_at(10.0) - 10.0 * pixel * share).abs() < 1e-9, "an eighth of the pixel");
    assert_eq!(RayCone::camera(pixel, false).width_at(10.0), 10.0 * pixel, "pixel centres: the whole pixel");

    let mut cone = jittered;
    cone.advance(2.0);
    cone.advance(3.0);
    assert!((cone.width - 5.0 * pixel * share).abs() < 1e-9, "linear along a straight path");
    // A cosine lobe at normal incidence (density 1/π): a cone of solid angle π/n, angle 2/√n.
    cone.scatter(std::f32::consts::FRAC_1_PI);
    let widened = cone.width_at(1.0) - cone.width;
    assert!((widened - 2.0 * share).abs() < 1e-6, "{widened}");
    // A sharper lobe, an infinite density or NaN keep the wider angle.
    for pdf in [1e6, f32::INFINITY, f32::NAN] {
        cone.scatter(pdf);
        assert!((cone.width_at(1.0) - cone.width - widened).abs() < 1e-6, "{pdf}");
    }
}

/// A square of side 2 at z = 0 whose texture coordinates run 0 to 1 across it, seen face on from
/// z = 1 by a `pixels`² camera whose view the square just fills.
fn textured_square(texture: PathBuf, pixels: u32) -> (World, Camera) {
    let corners =
        [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0)];
    let mesh = TriangleMesh {
        positions: corners.to_vec(),
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material_ids: vec![0, 0],
        texcoords: corners.iter().map(|p| Vec2::new((p.x + 1.0) / 2.0, (p.y + 1.0) / 2.0)).collect(),
        texcoord_indices: vec![[0, 1, 2], [0, 2, 3]],
        ..Default::default()
    };
    let material = Material { map_kd: Some(texture), kd: Vec3::ONE, ..Material::default_grey("checks") };
    let scene = Scene::from_parts("square".into(), mesh, vec![material], vec![]).expect("valid test scene");
    // A field of view of 90°: the square, 2 wide at distance 1, fills it.
    let camera = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 90.0, pixels, pixels).unwrap();
    (World::new(scene, Default::default()), camera)
}

#[test]
fn a_pixel_over_many_texels_reads_their_mean_and_not_one_of_them() {
    let dir = TempDir::new("mip_antialiasing");
    // 256² one-texel checks under 16² pixels: 16 texels across each pixel at the centre.
    let (world, camera) = textured_square(checks(&dir, 256), 16);
    let half = nearest_half();
    // Pixel centres (`--spp 1`): the cone is the whole pixel.
    let options = RenderOptions { spp: 1, ..RenderOptions::new(Technique::Materials(Materials)) };
    let albedo = &render_aovs(&world, &camera, &options, &[Aov::Albedo])[0];
    for (i, value) in albedo.iter().enumerate() {
        assert!(close(*value, Vec3::splat(half), 1e-6), "pixel {i}: {value}, not the checks' mean {half}");
    }
    // A footprint of width 0 reads the image alone: at the centre of texel (100, 155), a check.
    // Texture coordinates (100.5/256, 100.5/256) lie at -0.21484375 on both axes of the square,
    // under film position (1 - 0.21484375, 1 + 0.21484375) times 8.
    let ray = camera.ray(6.28125, 9.71875);
    let hit = world.intersect(&ray).unwrap();
    let surface = world.surface(&ray, &hit);
    let level0 = world.bsdf_in_cone(&surface, ray.dir, 0.0).albedo();
    assert!(level0.x < 1e-3 || level0.x > 0.999, "a footprint of width 0 reads the image: {level0}");
}
