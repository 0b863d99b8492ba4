//! The seams integrators are written against: the BSDF contract, light sampling, surface points
//! and their spawned rays, the sample stream and scene construction. Each is checked for what the
//! integrators rely on: pdfs that agree with the samples (chi-square), measures that match, rays
//! that leave on the right side, numbers that depend only on (pixel, sample, dimension, seed).

use std::f64::consts::PI;

use crate::common::{TestRng, assert_passes, sphere_param};
use glam::{Vec2, Vec3};
use lumiere::accel::BuildPreset;
use lumiere::lights::{LightSelection, LightSet};
use lumiere::materials::{Bsdf, BsdfFlags, Lambert, Material};
use lumiere::math::Ray;
use lumiere::sampler::{SampleStream, Sampler, SamplerKind};
use lumiere::sampling::chi2::{Chi2Test, chi2_discrete};
use lumiere::scene::Scene;
use lumiere::scene::mesh::TriangleMesh;
use lumiere::world::World;

/// The direction a sphere parameter `(x, y) = ((1 − cos θ)/2, φ/2π)` stands for.
fn direction_of(p: Vec2) -> Vec3 {
    let cos_theta = 1.0 - 2.0 * p.x as f64;
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * p.y as f64;
    Vec3::new((sin_theta * phi.cos()) as f32, (sin_theta * phi.sin()) as f32, cos_theta as f32)
}

// ---------------------------------------------------------------------------------------------
// BSDF contract

/// Lambert's `sample` draws directions with the density its `pdf` claims, over the whole sphere
/// (so directions below the surface would show as cells observed but never expected).
#[test]
fn lambert_samples_follow_its_pdf_over_the_sphere() {
    let bsdf = Lambert { reflectance: Vec3::new(0.8, 0.5, 0.2) };
    for (i, wo) in [Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.3, 0.9, 0.1).normalize()].into_iter().enumerate() {
        let result = Chi2Test::new(32, 64).run_warp(
            500_000,
            10 + i as u64,
            |u| bsdf.sample(wo, u).map(|s| sphere_param(s.wi)),
            |p| 4.0 * PI * bsdf.pdf(wo, direction_of(p)) as f64,
        );
        assert_passes(&format!("Lambert, wo {wo}"), result);
    }
}

/// A sample carries exactly `eval` and `pdf` of its own direction, and `f cos / pdf` is the albedo:
/// Lambert neither creates nor loses energy (a white furnace in one line).
#[test]
fn lambert_samples_agree_with_eval_and_pdf_and_conserve_energy() {
    let bsdf = Lambert { reflectance: Vec3::new(0.8, 0.5, 0.2) };
    let mut rng = TestRng(3);
    for _ in 0..10_000 {
        let wo = rng.direction();
        let u = Vec2::new(rng.f32(), rng.f32());
        let Some(s) = bsdf.sample(wo, u) else {
            assert!(wo.z <= 0.0, "no sample for wo {wo} above the surface");
            continue;
        };
        assert_eq!(s.f, bsdf.eval(wo, s.wi));
        assert_eq!(s.pdf, bsdf.pdf(wo, s.wi));
        assert!(s.flags.contains(BsdfFlags::REFLECTION | BsdfFlags::DIFFUSE));
        assert!(!s.flags.contains(BsdfFlags::SPECULAR));
        let weight = s.f * s.wi.z / s.pdf;
        assert!((weight - bsdf.albedo()).abs().max_element() < 1e-5, "f cos / pdf = {weight}");
    }
    // Reciprocity, and nothing below the surface.
    for _ in 0..1000 {
        let (a, b) = (rng.direction(), rng.direction());
        assert_eq!(bsdf.eval(a, b), bsdf.eval(b, a));
        if a.z <= 0.0 || b.z <= 0.0 {
            assert_eq!((bsdf.eval(a, b), bsdf.pdf(a, b)), (Vec3::ZERO, 0.0));
        }
    }
}

/// Lambert is one-sided, on the side of the normal: a direction exactly on the horizon (`z = 0`)
/// is not on it, so `wo` or `wi` there gives `f = 0`, and `wo` there a zero pdf, as below it.
#[test]
fn lambert_reflects_nothing_on_the_horizon() {
    let bsdf = Lambert { reflectance: Vec3::new(0.8, 0.5, 0.2) };
    let (up, flat) = (Vec3::new(0.0, 0.6, 0.8), Vec3::new(0.6, 0.8, 0.0));
    for (wo, wi) in [(up, flat), (flat, up), (flat, flat)] {
        assert_eq!((bsdf.eval(wo, wi), bsdf.pdf(wo, wi)), (Vec3::ZERO, 0.0), "wo {wo}, wi {wi}");
    }
}

/// `u.x = 1`, on the closed square the warps accept, maps to a direction on the horizon, where the
/// cosine density is 0. A sample must have a positive pdf, so Lambert returns none there.
#[test]
fn lambert_gives_no_sample_on_the_horizon() {
    let bsdf = Lambert { reflectance: Vec3::new(0.8, 0.5, 0.2) };
    for k in 0..=16 {
        let u = Vec2::new(1.0, k as f32 / 16.0);
        assert_eq!(bsdf.sample(Vec3::new(0.0, 0.6, 0.8), u), None, "u {u}");
    }
}

// ---------------------------------------------------------------------------------------------
// Lights

/// A floor and two emitting triangles of different power facing down onto it, and one facing up.
fn light_scene() -> Scene {
    let positions = vec![
        // floor
        Vec3::new(-5.0, 0.0, -5.0),
        Vec3::new(5.0, 0.0, -5.0),
        Vec3::new(0.0, 0.0, 5.0),
        // a dim light, facing down (winding seen from below is counter-clockwise)
        Vec3::new(-1.0, 2.0, -1.0),
        Vec3::new(1.0, 2.0, -1.0),
        Vec3::new(0.0, 2.0, 1.0),
        // a bright light, smaller and higher, facing down
        Vec3::new(-0.5, 3.0, 0.0),
        Vec3::new(0.5, 3.0, 0.0),
        Vec3::new(0.0, 3.5, 0.5),
    ];
    let mesh = TriangleMesh {
        positions,
        indices: vec![[0, 2, 1], [3, 4, 5], [6, 7, 8]],
        material_ids: vec![0, 1, 2],
        ..Default::default()
    };
    let light = |name: &str, ke: f32| Material { ke: Vec3::splat(ke), ..Material::default_grey(name) };
    let materials = vec![Material::default_grey("floor"), light("dim", 2.0), light("bright", 50.0)];
    Scene::from_parts("lights".into(), mesh, materials, vec![]).unwrap()
}

#[test]
fn the_triangle_to_light_map_names_each_emitter() {
    let lights = LightSet::new(&light_scene());
    assert_eq!(lights.lights().len(), 2);
    assert_eq!(
        (lights.light_of(0), lights.light_of(1), lights.light_of(2), lights.light_of(3)),
        (None, Some(0), Some(1), None)
    );
}

#[test]
fn a_light_whose_power_overflows_f32_leaves_the_others_choosable() {
    // Ke 1e38 on the dim light: pi * area * Ke summed over three channels overflows f32; its
    // weight is taken in f64, and power choice still works (it picks the huge light almost always).
    let mut scene = light_scene();
    scene.materials[1].ke = Vec3::splat(1e38);
    let lights = LightSet::new(&scene);
    let (index, pmf) = lights.choose(LightSelection::Power, 0.75).expect("power choice is available");
    assert_eq!(index, 0);
    assert!(pmf > 0.99 && pmf <= 1.0, "{pmf}");
    assert!(lights.choice_pmf(LightSelection::Power, 1) > 0.0);
}

#[test]
fn emission_that_is_negative_or_not_finite_is_refused() {
    for ke in [Vec3::new(1.0, -1.0, 1.0), Vec3::new(f32::NAN, 1.0, 1.0), Vec3::splat(f32::INFINITY)] {
        let scene = light_scene();
        let mut materials = scene.materials.clone();
        materials[2].ke = ke;
        let error = Scene::from_parts("lights".into(), scene.mesh.clone(), materials, vec![]).unwrap_err();
        let message = error.to_string();
        assert!(message.contains("material 'bright'") && message.contains("not negative"), "{message}");
        // Set afterwards (`--emission`, Python's `emission=`), the same values are refused too.
        let mut scene = light_scene();
        let message = scene.set_emission("bright", ke).unwrap_err().to_string();
        assert!(message.contains("material 'bright'") && message.contains("not negative"), "{message}");
    }
}

/// Scenes made from arrays (Python) get the checks the file loaders make: a colour or a normal
/// that is not finite is refused, naming it.
#[test]
fn colours_and_normals_that_are_not_finite_are_refused() {
    let scene = light_scene();
    let mut materials = scene.materials.clone();
    materials[2].kd = Vec3::new(0.5, f32::NAN, 0.5);
    let error = Scene::from_parts("lights".into(), scene.mesh.clone(), materials, vec![]).unwrap_err();
    assert!(error.to_string().contains("material 'bright': colour 0.5 NaN 0.5 must be finite"), "{error}");
    let mut mesh = scene.mesh.clone();
    mesh.normals = vec![Vec3::Z; mesh.positions.len()];
    mesh.normal_indices = mesh.indices.clone();
    assert!(Scene::from_parts("lights".into(), mesh.clone(), scene.materials.clone(), vec![]).is_ok());
    mesh.normals[1] = Vec3::new(0.0, f32::INFINITY, 0.0);
    let error = Scene::from_parts("lights".into(), mesh, scene.materials.clone(), vec![]).unwrap_err();
    assert_eq!(error.to_string(), "lights: normal 1 is not finite");
}

/// Power choice gives each light its share of the total flux, `π A Σ Ke` over the channels: both
/// when the sums fit in `f32` and when one light's overflows and is taken in `f64`. The frequency
/// test above compares choices with `choice_pmf` only, and the overflow test only asks that the
/// huge light wins, so neither sees a weight that is off by a factor.
#[test]
fn power_choice_follows_each_lights_flux_even_past_f32() {
    for ke in [2.0f32, 1e38] {
        let mut scene = light_scene();
        scene.materials[1].ke = Vec3::splat(ke);
        let lights = LightSet::new(&scene);
        let flux: Vec<f64> = lights
            .lights()
            .iter()
            .map(|l| {
                let [a, b, c] = l.vertices.map(|v| v.as_dvec3());
                let emission = l.emission.as_dvec3();
                PI * 0.5 * (b - a).cross(c - a).length() * (emission.x + emission.y + emission.z)
            })
            .collect();
        let total: f64 = flux.iter().sum();
        for (index, flux) in flux.iter().enumerate() {
            let (pmf, expected) = (lights.choice_pmf(LightSelection::Power, index as u32) as f64, flux / total);
            assert!(
                (pmf - expected).abs() <= 1e-5 * expected,
                "Ke {ke}, light {index}: pmf {pmf}, expected {expected}"
            );
        }
    }
}

/// Light choice by power and uniformly: observed frequencies match `choice_pmf`.
#[test]
fn light_choice_frequencies_match_their_pmf() {
    let lights = LightSet::new(&light_scene());
    let mut rng = TestRng(5);
    for selection in [LightSelection::Uniform, LightSelection::Power] {
        let mut counts = [0u64; 2];
        for _ in 0..200_000 {
            let (index, pmf) = lights.choose(selection, rng.f32()).unwrap();
            assert_eq!(pmf, lights.choice_pmf(selection, index));
            counts[index as usize] += 1;
        }
        let pmf = [0, 1].map(|i| lights.choice_pmf(selection, i) as f64);
        assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-6);
        let p = chi2_discrete(&pmf, &counts).unwrap_or_else(|e| panic!("{selection:?}: {e}"));
        println!("{selection:?}: p = {p:.4}");
    }
}

/// The solid angle of triangle `[a, b, c]` seen from `p` (Van Oosterom and Strackee 1983).
fn solid_angle(p: Vec3, [a, b, c]: [Vec3; 3]) -> f64 {
    let (a, b, c) = ((a - p).as_dvec3(), (b - p).as_dvec3(), (c - p).as_dvec3());
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c)).abs();
    let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * numerator.atan2(denominator)
}

/// Light samples carry their density per unit solid angle, light choice included: `E[1/pdf]` is
/// the solid angle the lights subtend (in closed form), for either selection and whether the
/// choice has a number of its own (`sample_li`) or reuses the point's (`sample_li_reusing`); and
/// every sample's `pdf` equals `pdf_li` at its point.
#[test]
fn light_sample_pdfs_are_per_unit_solid_angle() {
    let lights = LightSet::new(&light_scene());
    let p = Vec3::new(0.2, 0.0, 0.1);
    let expected: f64 = lights.lights().iter().map(|l| solid_angle(p, l.vertices)).sum();
    for selection in [LightSelection::Uniform, LightSelection::Power] {
        for reusing in [false, true] {
            let mut rng = TestRng(7);
            let n = 400_000;
            let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let (u_light, u) = (rng.f32(), Vec2::new(rng.f32(), rng.f32()));
                let s = if reusing {
                    lights.sample_li_reusing(selection, p, u)
                } else {
                    lights.sample_li(selection, p, u_light, u)
                };
                let s = s.expect("both lights face p");
                let on_light = pdf_at(&lights, selection, p, s.light, s.target);
                assert!(
                    (s.pdf - on_light).abs() <= 1e-3 * on_light,
                    "{selection:?}: pdf {} vs pdf_li {on_light}",
                    s.pdf
                );
                let w = 1.0 / s.pdf as f64;
                sum += w;
                sum_sq += w * w;
            }
            let mean = sum / n as f64;
            let error = ((sum_sq / n as f64 - mean * mean) / n as f64).sqrt();
            println!("{selection:?}, reusing {reusing}: E[1/pdf] = {mean} +- {error}, solid angle {expected}");
            assert!(
                (mean - expected).abs() < 4.0 * error,
                "{selection:?}, reusing {reusing}: E[1/pdf] = {mean} +- {error}, expected {expected}"
            );
        }
    }
}

/// With the choice reusing the point's number, the points still fall uniformly on each light:
/// the barycentric parameters (`invert_uniform_triangle_sample`) of the points on either light
/// are uniform on the square, and each light is chosen as often as `choice_pmf` says.
#[test]
fn reused_light_choice_leaves_the_points_uniform_on_each_light() {
    use lumiere::sampling::warp::invert_uniform_triangle_sample;
    let lights = LightSet::new(&light_scene());
    let p = Vec3::new(0.2, 0.0, 0.1);
    for selection in [LightSelection::Uniform, LightSelection::Power] {
        let mut rng = TestRng(9);
        let mut points = [Vec::new(), Vec::new()];
        for _ in 0..400_000 {
            let s = lights.sample_li_reusing(selection, p, Vec2::new(rng.f32(), rng.f32())).unwrap();
            let [a, b, c] = lights.lights()[s.light as usize].shadow_targets;
            points[s.light as usize].push(invert_uniform_triangle_sample(barycentrics(s.target, a, b, c)));
        }
        let counts = [points[0].len() as u64, points[1].len() as u64];
        let pmf = [0, 1].map(|i| lights.choice_pmf(selection, i) as f64);
        assert_passes(&format!("{selection:?}: choice"), chi2_discrete(&pmf, &counts));
        for (light, on_light) in points.into_iter().enumerate() {
            let result = Chi2Test::new(16, 16).run_points(on_light.into_iter().map(Some), |_| 1.0);
            assert_passes(&format!("{selection:?}: points on light {light}"), result);
        }
    }
}

/// The barycentric coordinates of `y` (on the triangle's plane) in `[a, b, c]`.
fn barycentrics(y: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let (y, a, b, c) = (y.as_dvec3(), a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    let n = (b - a).cross(c - a);
    let area = n.length_squared();
    let (wb, wc) = ((y - a).cross(c - a).dot(n) / area, (b - a).cross(y - a).dot(n) / area);
    Vec3::new((1.0 - wb - wc) as f32, wb as f32, wc as f32)
}

/// `pdf_li` at the point `y` of `light`, seen from `p`.
fn pdf_at(lights: &LightSet, selection: LightSelection, p: Vec3, light: u32, y: Vec3) -> f32 {
    lights.pdf_li(selection, light, (y - p).normalize(), p.distance(y))
}

/// A light seen from behind gives no sample: emission is one-sided.
#[test]
fn lights_do_not_emit_backwards() {
    let lights = LightSet::new(&light_scene());
    let above = Vec3::new(0.0, 10.0, 0.0);
    for k in 0..100 {
        let u = Vec2::new(k as f32 / 100.0, 0.37);
        assert!(lights.sample_li_on(0, above, u).is_none());
        assert_eq!(pdf_at(&lights, LightSelection::Uniform, above, 0, Vec3::new(0.0, 2.0, 0.0)), 0.0);
    }
}

/// An area light's own geometry, exactly, for the dim light of `light_scene` (corners
/// (-1, 2, -1), (1, 2, -1), (0, 2, 1), facing down, `Ke` 2, area 2): the centroid is the mean of
/// the corners, barycentrics (1, 0, 0), (0, 1, 0), (0, 0, 1) read the three shadow targets, which
/// lie a few ulps below the corners, the hard-shadow target is their centroid, and the flux is
/// `π A Ke`. Other tests see these only through renders, ratios and statistics, which a centroid
/// off by a factor of 9 (`/ 3` read as `* 3`) passed.
#[test]
fn an_area_lights_centroid_targets_and_power_are_exact() {
    let lights = LightSet::new(&light_scene());
    let light = lights.lights()[0];
    assert_eq!((light.normal, light.area, light.emission), (Vec3::NEG_Y, 2.0, Vec3::splat(2.0)));
    assert_eq!(light.centroid(), Vec3::new(0.0, 2.0, -1.0 / 3.0));
    for (k, b) in [Vec3::X, Vec3::Y, Vec3::Z].into_iter().enumerate() {
        assert_eq!(light.shadow_target(b), light.shadow_targets[k], "barycentrics {b}");
        let moved = light.shadow_targets[k] - light.vertices[k];
        assert!(moved.x == 0.0 && moved.z == 0.0 && moved.y < 0.0 && moved.y > -1e-4, "target {k} moved {moved}");
    }
    let hard = light.hard_shadow_target();
    assert!(hard.y < 2.0 && hard.distance(light.centroid()) < 1e-4, "hard-shadow target {hard}");
    let flux = (PI * 2.0 * 2.0) as f32;
    assert_eq!(light.power(), Vec3::splat(flux));
    assert!((light.power_weight() - 3.0 * PI * 4.0).abs() < 1e-5, "{}", light.power_weight());
}

/// Emission is one-sided and the side is strict: a direction along the light's plane (a cosine
/// of exactly 0) gets nothing, as one behind it does; one just below the plane gets `Ke`.
#[test]
fn lights_emit_nothing_along_their_plane() {
    let lights = LightSet::new(&light_scene());
    let light = lights.lights()[0];
    assert_eq!(light.radiance_towards(Vec3::NEG_Y), Vec3::splat(2.0));
    assert_eq!(light.radiance_towards(Vec3::new(0.6, -0.01, 0.8).normalize()), Vec3::splat(2.0));
    for w in [Vec3::Y, Vec3::X, Vec3::new(0.6, 0.0, -0.8)] {
        assert_eq!(light.radiance_towards(w), Vec3::ZERO, "towards {w}");
    }
}

/// `u` = 1, the closed end of the unit interval, stays in the list of lights by either selection
/// (the alias table reads it as the largest number below 1): uniform choice picks the last light,
/// with its probability and a remapped number below 1, never an index one past the end.
#[test]
fn light_choice_at_u_one_stays_in_the_list() {
    let lights = LightSet::new(&light_scene());
    let (index, pmf, remapped) = lights.choose_remapped(LightSelection::Uniform, 1.0).unwrap();
    assert_eq!((index, pmf), (1, 0.5));
    assert!((0.0..1.0).contains(&remapped), "remapped {remapped}");
    let (index, _, remapped) = lights.choose_remapped(LightSelection::Power, 1.0).unwrap();
    assert!(index < 2 && (0.0..1.0).contains(&remapped), "power: light {index}, remapped {remapped}");
    let below = Vec3::new(0.2, 0.0, 0.1);
    let sample = lights.sample_li_reusing(LightSelection::Uniform, below, Vec2::new(1.0, 0.5)).expect("a sample");
    assert_eq!(sample.light, 1);
}

/// A scene without emitters has no light to choose, by either selection (and so no light
/// sample). Uniform choice must not read the count 0 as lights to pick from: `n − 1` would wrap
/// around and hand out light 0 of an empty list, with probability 1/0.
#[test]
fn a_scene_without_lights_offers_no_light_choice() {
    let mut scene = light_scene();
    for material in &mut scene.materials {
        material.ke = Vec3::ZERO;
    }
    let lights = LightSet::new(&scene);
    assert!(lights.is_empty());
    for selection in [LightSelection::Uniform, LightSelection::Power] {
        for u in [0.0, 0.5, 1.0f32.next_down()] {
            assert_eq!(lights.choose_remapped(selection, u), None, "{selection:?}, u {u}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Surface points

/// Rays spawned from a hit point leave on the side they head to and never hit their own
/// triangle, for directions on both sides, at every scale of coordinates.
#[test]
fn spawned_rays_leave_on_their_side_and_miss_their_own_triangle() {
    let mut rng = TestRng(11);
    for scale in [1e-3f32, 1.0, 1e3, 1e5] {
        let corners = [rng.vec3(-1.0, 1.0), rng.vec3(-1.0, 1.0), rng.vec3(-1.0, 1.0)];
        let mesh = TriangleMesh {
            positions: corners.iter().map(|&c| c * scale).collect(),
            indices: vec![[0, 1, 2]],
            material_ids: vec![0],
            ..Default::default()
        };
        let scene = Scene::from_parts("one".into(), mesh, vec![Material::default_grey("m")], vec![]).unwrap();
        let world = World::new(scene, BuildPreset::Default);
        let [a, b, c] = world.scene().mesh.vertices(0);
        let centre = (a + b + c) / 3.0;
        for _ in 0..2000 {
            let eye = centre + rng.direction() * 3.0 * scale;
            let ray = Ray::new(eye, (centre + (rng.vec3(-0.1, 0.1) * scale) - eye).normalize());
            let Some(hit) = world.intersect(&ray) else { continue };
            let surface = world.surface(&ray, &hit);
            for dir in [rng.direction(), -rng.direction()] {
                let spawned = surface.spawn_ray(dir);
                let side = surface.ng.dot(spawned.origin - surface.p);
                assert!(side * surface.ng.dot(dir) >= 0.0, "origin on the wrong side at scale {scale}");
                assert!(world.intersect(&spawned).is_none(), "self-hit at scale {scale}");
                let segment = surface.spawn_segment(surface.p + dir * scale);
                assert!(!world.occluded(&segment), "segment self-hit at scale {scale}");
            }
        }
    }
}

/// The surface points of a packet's hits, computed together in the ISA's lanes, have the bits of
/// `World::surface` one hit at a time: on faces with and without vertex normals and texture
/// coordinates, a degenerate face, hits from both sides, barycentrics outside the triangle, and
/// lanes without a hit (default points), for every ISA this CPU has.
#[test]
fn surface_points_in_lanes_have_the_bits_of_one_at_a_time() {
    let dir = crate::common::TempDir::new("seams-surface-lanes");
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.5\nv 2 2 2\nv 3 3 3\nv 4 4 4\n\
               vn 0 0 1\nvn 0.2 0 1\nvn 0 -0.3 1\nvn 0 0 -1\nvt 0 0\nvt 1 0\nvt 0.5 1\n\
               f 1/1/1 2/2/2 3/3/3\nf 2/2/4 4/1/1 3/3/2\nf 1 2 4\nf 5 6 7\nf 1//4 3//4 4//3\n";
    let scene = Scene::load(&dir.write("mixed.obj", obj)).unwrap();
    let triangles = scene.mesh.indices.len() as u32;
    let mut rng = TestRng(23);
    for isa in lumiere::accel::Isa::supported() {
        let world = World::with_isa(scene.clone(), BuildPreset::Default, isa);
        for _ in 0..2_000 {
            let rays: [Ray; 16] = std::array::from_fn(|_| {
                let dir = if rng.below(50) == 0 { Vec3::ZERO } else { rng.direction() };
                Ray::new(rng.vec3(-2.0, 2.0), dir)
            });
            let hits: [Option<lumiere::accel::Hit>; 16] = std::array::from_fn(|_| {
                (rng.below(8) != 0).then(|| lumiere::accel::Hit {
                    t: 1.0,
                    triangle: rng.below(triangles as usize) as u32,
                    u: rng.range(-0.2, 1.1),
                    v: rng.range(-0.2, 1.1),
                })
            });
            let together = world.surfaces(&rays, &hits);
            for lane in 0..16 {
                let alone = hits[lane].map_or_else(Default::default, |hit| world.surface(&rays[lane], &hit));
                let bits = |s: &lumiere::geometry::surface::SurfacePoint| {
                    let floats = [s.p.to_array(), s.ng.to_array(), s.ns.to_array()].concat();
                    (
                        floats.iter().chain(&s.uv.to_array()).map(|x| x.to_bits()).collect::<Vec<_>>(),
                        s.triangle,
                        s.material,
                        s.front_face,
                    )
                };
                assert_eq!(
                    bits(&together[lane]),
                    bits(&alone),
                    "{isa}: lane {lane}, hit {:?}, ray {:?}",
                    hits[lane],
                    rays[lane]
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Sample stream

/// The stream takes one dimension per draw, in order, and camera sample `s` of a set of `n`
/// points owns sampler indices `s·n .. s·n + n`: the numbers are a pure function of
/// (pixel, sample, dimension, seed).
#[test]
fn the_sample_stream_numbers_dimensions_in_order() {
    for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
        let sampler = Sampler::new(kind, 42);
        let (pixel, sample) = (1234, 5);
        let mut stream = SampleStream::new(&sampler, pixel, sample);
        let first = stream.next_2d();
        let set = stream.next_points(16);
        let third = stream.next_1d();
        assert_eq!(first, sampler.get_2d(pixel, sample, 0));
        for k in 0..16 {
            assert_eq!(set.get_2d(k), sampler.get_2d(pixel, sample * 16 + k, 1));
            assert_eq!(set.get_1d(k), sampler.get_1d(pixel, sample * 16 + k, 1));
        }
        assert_eq!(third, sampler.get_1d(pixel, sample, 2));
        let mut again = SampleStream::new(&sampler, pixel, sample);
        assert_eq!(again.next_2d(), first, "a stream replays");
    }
}

// ---------------------------------------------------------------------------------------------
// Scenes

#[test]
fn scene_files_are_loaded_by_extension_or_refused_naming_it() {
    let dir = crate::common::TempDir::new("seams-load");
    let obj = dir.write("UPPER.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_eq!(Scene::load(&obj).unwrap().mesh.triangle_count(), 1);
    for (name, expected) in [
        ("model.stl", ".stl scenes are not supported"),
        ("model.fbx", ".fbx scenes are not supported"),
        ("noextension", "no extension"),
        // Not "no extension": the name has one, and what it lacks is the one inside.
        ("scene.gz", "a gzip file whose name does not say what it holds"),
    ] {
        let path = dir.write(name, "v 0 0 0\n");
        let message = Scene::load(&path).unwrap_err().to_string();
        assert!(message.contains(expected) && message.contains(name), "{name}: {message}");
        let supported = [".obj", ".gltf", ".glb", ".ply"];
        assert!(supported.iter().all(|s| message.contains(s)), "the message names what is supported: {message}");
    }
    // The extension chooses the loader, and the loader checks what the file holds.
    let obj_text = dir.write("model.ply", "v 0 0 0\n");
    let message = Scene::load(&obj_text).unwrap_err().to_string();
    assert!(message.ends_with("model.ply:1: not a PLY file: its first line is not \"ply\""), "{message}");
    let message = Scene::load(&dir.write("model.gltf", "v 0 0 0\n")).unwrap_err().to_string();
    assert!(message.ends_with("model.gltf: not glTF JSON: expected value at line 1 column 1"), "{message}");
}

#[test]
fn scenes_from_parts_refuse_parts_that_do_not_fit() {
    let mesh = |indices: Vec<[u32; 3]>, material_ids: Vec<u32>| TriangleMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        indices,
        material_ids,
        ..Default::default()
    };
    let grey = || vec![Material::default_grey("m")];
    assert!(Scene::from_parts("ok".into(), mesh(vec![[0, 1, 2]], vec![0]), grey(), vec![]).is_ok());
    for (parts, expected) in [
        (mesh(vec![[0, 1, 3]], vec![0]), "vertex index 3 out of range"),
        (mesh(vec![[0, 1, 2]], vec![1]), "material id 1 out of range"),
        (mesh(vec![[0, 1, 2]], vec![]), "1 triangles but 0 material ids"),
    ] {
        let message = Scene::from_parts("bad".into(), parts, grey(), vec![]).unwrap_err().to_string();
        assert!(message.contains(expected), "{message}");
    }
}
