//! Arbitrary output variables: the first hits of the render's own camera samples, averaged per
//! pixel, in the order asked.

use std::sync::atomic::AtomicBool;

use glam::Vec3;
use lumiere::integrators::Technique;
use lumiere::materials::Bsdf;
use lumiere::materials::Material;
use lumiere::render::RenderOptions;
use lumiere::render::aov::{Aov, render_aovs};
use lumiere::scene::camera::Camera;
use lumiere::scene::mesh::TriangleMesh;
use lumiere::scene::{Scene, builtin};
use lumiere::world::World;

#[test]
fn aov_names_parse_back() {
    for aov in [Aov::Albedo, Aov::Normal, Aov::Depth] {
        assert_eq!(Aov::parse(aov.name()).unwrap(), aov);
    }
    let error = Aov::parse("colour").unwrap_err().to_string();
    assert!(error.contains("unknown AOV \"colour\""), "{error}");
}

/// Averaged over 64 jittered samples, each AOV is close to what the ray through the pixel centre
/// sees, image-wide: the same mean depth and albedo (within a few percent: pixels across edges
/// differ), and normals of at most unit length.
#[test]
fn aovs_average_the_first_hits_of_the_pixel_samples() {
    let world = World::new(Scene::builtin().unwrap(), Default::default());
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), 24, 18);
    let options = RenderOptions { spp: 64, ..RenderOptions::new(Technique::direct(1)) };
    let asked = [Aov::Depth, Aov::Albedo, Aov::Normal];
    let aovs = render_aovs(&world, &camera, &options, &asked, &AtomicBool::new(false)).unwrap();
    let pixels = (camera.width * camera.height) as usize;
    assert!(aovs.iter().all(|buffer| buffer.len() == pixels));
    let (mut depth, mut albedo) = (0.0f64, Vec3::ZERO);
    for y in 0..camera.height {
        for x in 0..camera.width {
            let ray = camera.ray(x as f32 + 0.5, y as f32 + 0.5);
            if let Some(hit) = world.intersect(&ray) {
                depth += f64::from(hit.t * ray.dir.length());
                albedo += world.bsdf(&world.surface(&ray, &hit)).albedo();
            }
        }
    }
    let mean_depth = aovs[0].iter().map(|d| f64::from(d.x)).sum::<f64>();
    assert!(depth > 0.0 && (mean_depth / depth - 1.0).abs() < 0.03, "depth {mean_depth} where {depth}");
    let mean_albedo = aovs[1].iter().sum::<Vec3>();
    for c in 0..3 {
        assert!((mean_albedo[c] / albedo[c] - 1.0).abs() < 0.05, "albedo {mean_albedo} where {albedo}");
    }
    assert!(aovs[0].iter().all(|d| d.x == d.y && d.y == d.z), "depth is copied into y and z");
    let lengths: Vec<f32> = aovs[2].iter().map(|n| n.length()).collect();
    assert!(lengths.iter().all(|&l| l <= 1.0 + 1e-5), "normals are averages of unit vectors");
    assert!(lengths.iter().sum::<f32>() > 0.9 * pixels as f32, "most pixels see one flat wall");
    let reordered =
        render_aovs(&world, &camera, &options, &[Aov::Normal, Aov::Depth], &AtomicBool::new(false)).unwrap();
    assert_eq!(reordered, [aovs[2].clone(), aovs[0].clone()], "buffers come in the order asked");
}

/// A square facing the camera at distance 5, which the image's middle column of pixels straddles
/// (the square's edge runs through their centres): every depth is 0 (no sample hits) or the
/// square's distance, 5 on the axis and less than 5 / cos²(5°) at the corners (the field of view
/// is 10°). The depth was the mean over all samples, misses as 0: about 2.5 on that column, no
/// surface's distance.
#[test]
fn the_depth_of_a_pixel_on_a_silhouette_is_its_surfaces() {
    let corners =
        [Vec3::new(-9.0, -9.0, 0.0), Vec3::new(0.0, -9.0, 0.0), Vec3::new(0.0, 9.0, 0.0), Vec3::new(-9.0, 9.0, 0.0)];
    let mesh = TriangleMesh {
        positions: corners.to_vec(),
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material_ids: vec![0, 0],
        ..Default::default()
    };
    let scene = Scene::from_parts("edge".into(), mesh, vec![Material::default_grey("grey")], vec![]).unwrap();
    let world = World::new(scene, Default::default());
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 10.0, 9, 9).unwrap();
    let options = RenderOptions { spp: 16, ..RenderOptions::new(Technique::direct(1)) };
    let aovs = render_aovs(&world, &camera, &options, &[Aov::Depth], &AtomicBool::new(false)).unwrap();
    // Rounding may put the axis a few ulps short of 5.
    let (nearest, farthest) = (5.0 * (1.0 - 1e-5), 5.0 / (5f32.to_radians()).cos().powi(2));
    for (pixel, depth) in aovs[0].iter().enumerate() {
        assert!(depth.x == 0.0 || (nearest..=farthest).contains(&depth.x), "pixel {pixel}: depth {}", depth.x);
    }
    let middle_column: Vec<f32> = (0..9).map(|y| aovs[0][y * 9 + 4].x).collect();
    assert!(middle_column.iter().all(|&d| d >= nearest), "the edge's pixels: {middle_column:?}");
}

/// Each AOV is the average of its pixel's first hits, bit for bit as one ray at a time gives them
/// (the pass traces a pixel's samples as one packet): the jittered positions drawn as the render
/// draws them (the first dimension of each sample's stream), every sample's closest hit and
/// surface point alone, summed in sample order. On the built-in box and on the staircase (shading
/// normals, textures), with fewer samples than the pass's packet and with more.
#[test]
fn aovs_are_the_first_hits_of_single_rays_bit_for_bit() {
    use lumiere::sampler::{SampleStream, Sampler};
    let mut scenes =
        vec![(Scene::builtin().unwrap(), Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), 20, 15))];
    if let Some(path) = crate::common::shared_scene("staircase/staircase.obj.gz") {
        // Bitterli's camera (the scenes' README).
        let (eye, target) = (Vec3::new(0.0324209, 1.52673, 4.88197), Vec3::new(0.0247749, 1.571785, 3.883015));
        let up = Vec3::new(0.000344842, 0.998984, 0.0450537);
        scenes.push((Scene::load(&path).unwrap(), Camera::look_at(eye, target, up, 58.54, 18, 32).unwrap()));
    }
    for (scene, camera) in scenes {
        let world = World::new(scene, Default::default());
        for spp in [5, 40] {
            let options = RenderOptions { spp, seed: 3, ..RenderOptions::new(Technique::direct(1)) };
            let asked = [Aov::Albedo, Aov::Normal, Aov::Depth];
            let aovs = render_aovs(&world, &camera, &options, &asked, &AtomicBool::new(false)).unwrap();
            let sampler = Sampler::new(options.sampler, options.seed);
            let samples = spp.min(16);
            let mut hit_pixels = 0;
            for y in 0..camera.height {
                for x in 0..camera.width {
                    let (mut albedo, mut normal, mut depth, mut hits) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, 0u32);
                    for sample in 0..samples {
                        let mut stream = SampleStream::new(&sampler, y * camera.width + x, sample);
                        let jitter = stream.next_points(1).get_2d(0);
                        let ray = camera.ray(x as f32 + jitter.x, y as f32 + jitter.y);
                        let Some(hit) = world.intersect(&ray) else { continue };
                        let surface = world.surface(&ray, &hit);
                        albedo += world.bsdf(&surface).albedo();
                        normal += surface.ns;
                        depth += Vec3::splat(hit.t * ray.dir.length());
                        hits += 1;
                    }
                    hit_pixels += usize::from(hits > 0);
                    let pixel = (y * camera.width + x) as usize;
                    let expected = [albedo / samples as f32, normal / samples as f32, depth / hits.max(1) as f32];
                    for (buffer, value) in aovs.iter().zip(expected) {
                        assert_eq!(buffer[pixel].to_array().map(f32::to_bits), value.to_array().map(f32::to_bits));
                    }
                }
            }
            assert!(hit_pixels > 100, "{hit_pixels} pixels see the scene");
        }
    }
}
