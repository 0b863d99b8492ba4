//! Cutouts (`map_d`): rays pass through a surface where its coverage texture is below one half, in
//! every query and every technique. A fully opaque mask must give the bytes of no mask, and a fully
//! clear one the bytes of a scene without that surface, on every ISA: the per-ray paths that
//! cutouts take must answer like the packets and batches they replace. A hashed veil (glTF's
//! `BLEND`) must give the same bytes on every ISA and cover its share.

use std::path::PathBuf;

use glam::{Vec2, Vec3};
use image::{GrayImage, ImageFormat, Luma, Rgba, RgbaImage};
use lumiere::accel::{BuildPreset, Isa};
use lumiere::integrators::{AmbientOcclusion, Hits, Materials, Path as PathTracer, Shadows, Technique};
use lumiere::materials::{CoverageTest, Cut, Material};
use lumiere::math::Ray;
use lumiere::render::{RenderOptions, render};
use lumiere::scene::Scene;
use lumiere::scene::camera::Camera;
use lumiere::scene::mesh::TriangleMesh;
use lumiere::world::World;

use crate::common::TempDir;

/// The blocker's side: a square at this height, from -B to B in x and z, between the floor and
/// the light. Its texture coordinates run from 0 to 1 across it.
const B: f32 = 0.6;
const BLOCKER_Y: f32 = 0.75;

/// A floor (triangles 0, 1), a square light facing down (2, 3) and, unless `without_blocker`, a
/// blocker square (4, 5) whose material has the coverage texture `map_d`.
fn scene(map_d: Option<PathBuf>, without_blocker: bool) -> Scene {
    let floor =
        [Vec3::new(-2.0, 0.0, -2.0), Vec3::new(-2.0, 0.0, 2.0), Vec3::new(2.0, 0.0, 2.0), Vec3::new(2.0, 0.0, -2.0)];
    let (a, h) = (0.3, 1.5);
    let light = [Vec3::new(-a, h, -a), Vec3::new(a, h, -a), Vec3::new(a, h, a), Vec3::new(-a, h, a)];
    let y = BLOCKER_Y;
    let blocker = [Vec3::new(-B, y, -B), Vec3::new(B, y, -B), Vec3::new(B, y, B), Vec3::new(-B, y, B)];
    let mut mesh = TriangleMesh {
        positions: floor.iter().chain(&light).chain(&blocker).copied().collect(),
        indices: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7], [8, 9, 10], [8, 10, 11]],
        material_ids: vec![0, 0, 1, 1, 2, 2],
        texcoords: blocker.iter().map(|p| Vec2::new((p.x + B) / (2.0 * B), (p.z + B) / (2.0 * B))).collect(),
        texcoord_indices: vec![[0, 1, 2], [0, 2, 3], [0, 1, 2], [0, 2, 3], [0, 1, 2], [0, 2, 3]],
        ..Default::default()
    };
    if without_blocker {
        for list in [&mut mesh.indices, &mut mesh.texcoord_indices] {
            list.truncate(4);
        }
        mesh.material_ids.truncate(4);
    }
    let materials = vec![
        Material { kd: Vec3::splat(0.8), ..Material::default_grey("floor") },
        Material { ke: Vec3::splat(10.0), kd: Vec3::ZERO, ..Material::default_grey("light") },
        Material { kd: Vec3::new(0.7, 0.5, 0.3), map_d, ..Material::default_grey("blocker") },
    ];
    Scene::from_parts("cutout".into(), mesh, materials, vec![]).expect("valid test scene")
}

/// A coverage mask of `width` x 1 grey values, saved as a PNG.
fn grey_mask(dir: &TempDir, name: &str, values: &[u8]) -> PathBuf {
    let path = dir.path(name);
    let image = GrayImage::from_fn(values.len() as u32, 1, |x, _| Luma([values[x as usize]]));
    image.save_with_format(&path, ImageFormat::Png).unwrap();
    path
}

fn techniques() -> Vec<(Technique, u32)> {
    vec![
        (Technique::Hits(Hits), 1),
        (Technique::Materials(Materials), 1),
        (Technique::Shadows(Shadows), 1),
        (Technique::direct(16), 1),
        (Technique::direct(3), 2),
        (Technique::AmbientOcclusion(AmbientOcclusion { samples: 8, distance: f32::INFINITY }), 1),
        (Technique::AmbientOcclusion(AmbientOcclusion { samples: 3, distance: 0.5 }), 2),
        (Technique::Path(PathTracer::default()), 4),
    ]
}

/// Every technique's image of `scene` on `isa`.
fn images(scene: &Scene, isa: Isa) -> Vec<Vec<Vec3>> {
    let world = World::with_isa(scene.clone(), BuildPreset::Default, isa);
    assert!(world.warnings().is_empty(), "{:?}", world.warnings());
    images_of(&world)
}

fn images_of(world: &World) -> Vec<Vec<Vec3>> {
    let camera = Camera::look_at(Vec3::new(0.3, 3.0, 2.5), Vec3::ZERO, Vec3::Y, 55.0, 40, 30).unwrap();
    techniques()
        .into_iter()
        .map(|(technique, spp)| {
            let options = RenderOptions { spp, seed: 3, ..RenderOptions::new(technique) };
            render(world, &camera, &options, &|_| {}).unwrap().image.pixels
        })
        .collect()
}

#[test]
fn an_opaque_mask_renders_the_bytes_of_no_mask_on_every_isa() {
    let dir = TempDir::new("cutout-opaque");
    let opaque = scene(Some(grey_mask(&dir, "white.png", &[255, 255, 255])), false);
    let plain = scene(None, false);
    for isa in Isa::supported() {
        let (got, expected) = (images(&opaque, isa), images(&plain, isa));
        for (k, (g, e)) in got.iter().zip(&expected).enumerate() {
            assert!(g == e, "{isa}: technique {:?} differs with an opaque mask", techniques()[k].0);
        }
    }
}

#[test]
fn a_clear_mask_renders_the_bytes_of_no_blocker_on_every_isa() {
    let dir = TempDir::new("cutout-clear");
    let clear = scene(Some(grey_mask(&dir, "black.png", &[0, 0])), false);
    let without = scene(None, true);
    let with = scene(None, false);
    for isa in Isa::supported() {
        let (got, expected) = (images(&clear, isa), images(&without, isa));
        for (k, (g, e)) in got.iter().zip(&expected).enumerate() {
            assert!(g == e, "{isa}: technique {:?} differs with a clear mask", techniques()[k].0);
        }
        // The blocker shows without its mask (in every image but the hit mask, which the floor fills
        // either way, and the short-range AO, which sees nothing above either surface): the
        // comparison above can fail.
        let differ = images(&with, isa).iter().zip(&expected).filter(|(a, b)| a != b).count();
        assert_eq!(differ, techniques().len() - 2, "{isa}: the blocker is invisible");
    }
}

/// glTF's `BLEND` without a texture: the blocker covers half of itself, each point kept or cut by a
/// hash of the hit, so the image is the same bytes on every ISA, and about half the pixels that
/// see the blocker without a veil see it through one.
#[test]
fn a_hashed_veil_renders_the_same_bytes_on_every_isa_and_covers_its_share() {
    let mut veil = scene(None, false);
    veil.materials[2].map_d_test = CoverageTest { alpha_only: true, scale: 0.5, cut: Cut::Hashed };
    let isas = Isa::supported();
    let first = images(&veil, isas[0]);
    for &isa in &isas[1..] {
        for (k, (g, e)) in images(&veil, isa).iter().zip(&first).enumerate() {
            assert!(g == e, "{isa}: technique {:?} differs from {}'s", techniques()[k].0, isas[0]);
        }
    }
    // The materials image (pixel centres) from above: where the blocker shows without a veil, the
    // veil's image shows either it or the floor, about half of each.
    let camera = Camera::look_at(Vec3::new(0.0, 3.0, 0.01), Vec3::ZERO, Vec3::Y, 40.0, 120, 120).unwrap();
    let options = RenderOptions::new(Technique::Materials(Materials));
    let [veiled, with, without] = [veil, scene(None, false), scene(None, true)].map(|scene| {
        let world = World::new(scene, BuildPreset::Default);
        render(&world, &camera, &options, &|_| {}).unwrap().image.pixels
    });
    let covered: Vec<bool> = (0..with.len())
        .filter(|&p| with[p] != without[p])
        .map(|p| {
            assert!(veiled[p] == with[p] || veiled[p] == without[p], "pixel {p}: {}", veiled[p]);
            veiled[p] == with[p]
        })
        .collect();
    let share = covered.iter().filter(|&&c| c).count() as f64 / covered.len() as f64;
    // At least 2,000 pixels: the share's standard deviation is at most 0.011; allow five of them.
    assert!(covered.len() > 2000, "only {} pixels see the blocker", covered.len());
    assert!((share - 0.5).abs() < 0.056, "{share} of {} pixels see the veil", covered.len());
}

#[test]
fn an_emitter_ignores_its_mask_with_a_warning() {
    // Lights are sampled over whole triangles; a ray must find the whole triangle too, or light
    // sampling and BSDF sampling would disagree about where the light is.
    let dir = TempDir::new("cutout-emitter");
    let mut masked = scene(None, false);
    masked.materials[1].map_d = Some(grey_mask(&dir, "black.png", &[0, 0]));
    let plain = scene(None, false);
    for isa in Isa::supported() {
        let world = World::with_isa(masked.clone(), BuildPreset::Default, isa);
        assert_eq!(world.warnings(), ["material 'light': map_d is ignored on an emitter; it stays opaque"]);
        // A name with a terminal's escape sequence is quoted escaped, as in every other warning.
        let mut escaped = masked.clone();
        escaped.materials[1].name = "lamp\x1b[31mRED".into();
        let warnings = World::with_isa(escaped, BuildPreset::Default, isa).warnings().to_vec();
        assert_eq!(warnings, ["material \"lamp\\u{1b}[31mRED\": map_d is ignored on an emitter; it stays opaque"]);
        let got = images_of(&world);
        for (k, (g, e)) in got.iter().zip(&images(&plain, isa)).enumerate() {
            assert!(g == e, "{isa}: technique {:?} differs with a clear mask on the light", techniques()[k].0);
        }
    }
}

/// The point of the blocker at texture coordinate `u` (and v = 1/2).
fn blocker_point(u: f32) -> Vec3 {
    Vec3::new(-B + 2.0 * B * u, BLOCKER_Y, 0.0)
}

/// Rays straight down through the blocker at `u`, and segments from the floor below it up to the
/// light: which pass (hit the floor, reach the light) and which stop at the blocker.
fn passes_at(world: &World, u: f32) -> bool {
    let p = blocker_point(u);
    // From just above the blocker (below the light), straight down.
    let down = world.intersect(&Ray::new(p + 0.1 * Vec3::Y, -Vec3::Y)).expect("the floor is below");
    assert!(down.triangle < 2 || down.triangle >= 4, "u = {u}: hit the light");
    let through = down.triangle < 2;
    let up = Ray::segment(Vec3::new(p.x, 1e-3, p.z), Vec3::new(p.x, 1.2, p.z));
    assert_eq!(world.occluded(&up), !through, "u = {u}: a camera ray and a shadow ray disagree");
    let packet = world.occluded_packet(&[up; 16], 0xFFFF);
    assert_eq!(packet, if through { 0 } else { 0xFFFF }, "u = {u}: packets disagree");
    through
}

#[test]
fn rays_pass_where_the_coverage_is_below_one_half() {
    let dir = TempDir::new("cutout-half");
    // Texel centres at u = 1/4 (clear) and 3/4 (opaque); repeat wrapping blends the two near u = 0 and 1.
    let grey = grey_mask(&dir, "half.png", &[0, 255]);
    let alpha = dir.path("alpha.png");
    // White everywhere, so only the alpha channel can cut: it must win over the colour.
    RgbaImage::from_fn(2, 1, |x, _| Rgba([255, 255, 255, if x == 0 { 0 } else { 255 }]))
        .save_with_format(&alpha, ImageFormat::Png)
        .unwrap();
    for mask in [grey, alpha] {
        for isa in Isa::supported() {
            let world = World::with_isa(scene(Some(mask.clone()), false), BuildPreset::Default, isa);
            // Bilinear coverage at u: 0.1 -> 0.3 (the wrapped opaque texel weighs 0.3), 0.2 -> 0.1,
            // 0.3 -> 0.1, 0.45 -> 0.4, 0.55 -> 0.6, 0.8 -> 0.9.
            for (u, expected) in [(0.1, true), (0.2, true), (0.3, true), (0.45, true), (0.55, false), (0.8, false)] {
                assert_eq!(passes_at(&world, u), expected, "{isa} {}: u = {u}", mask.display());
            }
        }
    }
}

#[test]
fn the_mask_moves_with_its_placement() {
    let dir = TempDir::new("cutout-placed");
    let half = grey_mask(&dir, "half.png", &[0, 255]);
    let mut placed = scene(Some(half), false);
    // `map_d -o 0.5 0 half.png`: the blocker reads its mask half a turn along u.
    placed.materials[2].map_d_transform.offset = Vec2::new(0.5, 0.0);
    for isa in Isa::supported() {
        let world = World::with_isa(placed.clone(), BuildPreset::Default, isa);
        // As at u + 1/2 unplaced: 0.2 -> 0.7 (coverage 0.7), 0.3 -> 0.8 (0.9), 0.8 -> 0.3 (0.1),
        // 0.55 -> 0.05 (0.4).
        for (u, expected) in [(0.2, false), (0.3, false), (0.8, true), (0.55, true)] {
            assert_eq!(passes_at(&world, u), expected, "{isa}: u = {u}");
        }
    }
}

#[test]
fn map_d_resolves_next_to_the_mtl_and_a_missing_file_leaves_the_surface_opaque() {
    let dir = TempDir::new("cutout-mtl");
    std::fs::create_dir_all(dir.path("masks")).unwrap();
    grey_mask(&dir, "masks/leaf.png", &[0, 255]);
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
               usemtl leaf\nf 1/1 2/2 3/3\nusemtl missing\nf 1/1 3/3 4/4\n";
    let mtl = "newmtl leaf\nKd 0.5 0.5 0.5\nmap_d -clamp off masks/leaf.png\nnewmtl missing\nmap_d nowhere.png\n";
    std::fs::write(dir.path("s.obj"), obj).unwrap();
    std::fs::write(dir.path("m.mtl"), mtl).unwrap();
    let scene = lumiere::scene::load::load(&dir.path("s.obj")).unwrap();
    let map_d = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap().map_d.clone();
    assert_eq!(map_d("leaf").as_deref(), Some(dir.path("masks/leaf.png").as_path()));
    assert_eq!(map_d("missing").as_deref(), Some(dir.path("nowhere.png").as_path()));
    assert!(!scene.warnings.iter().any(|w| w.contains("map_d")), "map_d is honoured: {:?}", scene.warnings);
    let world = World::new(scene, BuildPreset::Default);
    let warnings = world.warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("nowhere.png") && warnings[0].contains("the material stays opaque"), "{warnings:?}");
    // Through the leaf's clear half (u < 1/2 on the first triangle) rays pass; the missing mask's
    // triangle stays opaque.
    let down = |x: f32, y: f32| world.intersect(&Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z)).map(|h| h.triangle);
    assert_eq!(down(0.3, 0.1), None);
    assert_eq!(down(0.9, 0.1), Some(0));
    assert_eq!(down(0.1, 0.9), Some(1));
}
