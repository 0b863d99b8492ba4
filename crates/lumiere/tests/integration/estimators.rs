//! Monte Carlo estimators against scenes with known answers. Standard errors come from the samples
//! themselves (independent seeds); seeds are fixed, so a failure reproduces.

use glam::Vec3;
use lumiere::accel::BuildPreset;
use lumiere::integrators::{Direct, LightSampling, Path, PathStrategy, Technique};
use lumiere::materials::Material;
use lumiere::render::{RenderOptions, render};
use lumiere::sampler::SamplerKind;
use lumiere::scene::Scene;
use lumiere::scene::camera::Camera;
use lumiere::scene::mesh::{NO_INDEX, TriangleMesh};
use lumiere::world::World;

use crate::common::mean_and_error;

/// Builds a scene from quads `(corners, material)`, each split into two triangles `(a,b,c), (a,c,d)`.
fn scene_of_quads(quads: &[([Vec3; 4], usize)], materials: Vec<Material>) -> World {
    world_of(mesh_of_quads(quads), materials)
}

/// The triangles of [`scene_of_quads`], without normals or texture coordinates.
fn mesh_of_quads(quads: &[([Vec3; 4], usize)]) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    for (corners, material) in quads {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(corners);
        mesh.indices.push([base, base + 1, base + 2]);
        mesh.indices.push([base, base + 2, base + 3]);
        mesh.material_ids.extend([*material as u32; 2]);
    }
    mesh
}

fn world_of(mesh: TriangleMesh, materials: Vec<Material>) -> World {
    let scene = Scene::from_parts("test".into(), mesh, materials, vec![]).expect("valid test scene");
    World::new(scene, BuildPreset::Default)
}

fn diffuse(kd: f32) -> Material {
    Material { kd: Vec3::splat(kd), ..Material::default_grey("diffuse") }
}

fn emitter(ke: f32) -> Material {
    Material { ke: Vec3::splat(ke), ..Material::default_grey("light") }
}

/// A horizontal quad at height `y`, `[-s, s]^2`, wound so that its normal points down if `down`.
fn horizontal(y: f32, s: f32, down: bool) -> [Vec3; 4] {
    let q = [Vec3::new(-s, y, -s), Vec3::new(-s, y, s), Vec3::new(s, y, s), Vec3::new(s, y, -s)];
    if down { [q[0], q[3], q[2], q[1]] } else { q }
}

/// The value of the single pixel of a 1x1 image whose ray goes from `eye` to `target`.
fn estimate(world: &World, eye: Vec3, target: Vec3, options: &RenderOptions) -> f32 {
    let camera = Camera::look_at(eye, target, Vec3::Y, 1.0, 1, 1).unwrap();
    render(world, &camera, options, &|_| {}).unwrap().image.pixels[0].x
}

fn ao_options(samples: u32, seed: u64) -> RenderOptions {
    RenderOptions { seed, ..RenderOptions::new(Technique::ambient_occlusion(samples)) }
}

#[test]
fn ao_of_an_open_plane_is_exactly_one() {
    let world = scene_of_quads(&[(horizontal(0.0, 10.0, false), 0)], vec![diffuse(0.5)]);
    let camera = Camera::look_at(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, Vec3::Y, 60.0, 16, 12).unwrap();
    let out = render(&world, &camera, &ao_options(64, 1), &|_| {}).unwrap();
    // Every sample of every pixel that sees the plane escapes: zero variance.
    let on_plane: Vec<f32> = out.image.pixels.iter().map(|p| p.x).filter(|&v| v > 0.0).collect();
    assert!(on_plane.len() > 100);
    assert!(on_plane.iter().all(|&v| v == 1.0), "{on_plane:?}");
}

#[test]
fn ao_inside_a_closed_box_is_exactly_zero() {
    let (positions, indices) = crate::common::grid_cube(3);
    let mesh = TriangleMesh { material_ids: vec![0; indices.len()], positions, indices, ..Default::default() };
    let scene = Scene::from_parts("box".into(), mesh, vec![diffuse(0.5)], vec![]).unwrap();
    let world = World::new(scene, BuildPreset::Default);
    let camera = Camera::look_at(Vec3::new(0.1, 0.2, 0.3), Vec3::new(1.0, -0.5, -1.0), Vec3::Y, 90.0, 16, 16).unwrap();
    let out = render(&world, &camera, &ao_options(64, 2), &|_| {}).unwrap();
    assert!(out.image.pixels.iter().all(|p| p.x == 0.0));
}

/// Cosine-weighted visibility at distance `h` from the foot of a wall of height `wall` and (nearly)
/// infinite length: `1 - F`, with the form factor to an infinite strip `F = (1 - h/sqrt(h^2+H^2))/2`.
#[test]
fn ao_beside_a_wall_matches_the_strip_form_factor() {
    let (h, wall, far) = (1.0f32, 1.0f32, 1.0e4f32);
    let floor = horizontal(0.0, far, false);
    let wall_quad =
        [Vec3::new(h, 0.0, -far), Vec3::new(h, wall, -far), Vec3::new(h, wall, far), Vec3::new(h, 0.0, far)];
    let world = scene_of_quads(&[(floor, 0), (wall_quad, 0)], vec![diffuse(0.5)]);
    let expected = 1.0 - 0.5 * (1.0 - h / (h * h + wall * wall).sqrt()) as f64;
    let (eye, target) = (Vec3::new(-0.5, 2.0, 0.0), Vec3::ZERO);
    let (mean, error) = mean_and_error(32, |seed| estimate(&world, eye, target, &ao_options(4096, seed)));
    assert!((mean - expected).abs() < 4.0 * error, "AO {mean} +- {error}, expected {expected}");
    assert!(error < 0.002, "standard error {error}");

    // The error falls like 1/sqrt(N): 16x the samples, about 4x smaller RMSE.
    let rmse = |n: u32| {
        let sq: f64 =
            (100..132).map(|s| (estimate(&world, eye, target, &ao_options(n, s)) as f64 - expected).powi(2)).sum();
        (sq / 32.0).sqrt()
    };
    let ratio = rmse(64) / rmse(1024);
    assert!((2.5..6.4).contains(&ratio), "RMSE ratio {ratio} for 16x the samples");
}

/// Form factor from a point to a parallel square of half-side `a` centred `h` above it: four corner
/// rectangles, each `(1/pi) X/sqrt(1+X^2) atan(X/sqrt(1+X^2))` with `X = a/h`.
fn square_form_factor(a: f64, h: f64) -> f64 {
    let x = a / h;
    let s = x / (1.0 + x * x).sqrt();
    4.0 / std::f64::consts::PI * s * s.atan()
}

fn direct_options(samples: u32, seed: u64, sampler: SamplerKind, light_sampling: LightSampling) -> RenderOptions {
    RenderOptions { seed, sampler, ..RenderOptions::new(Technique::Direct(Direct { samples, light_sampling })) }
}

/// Outgoing radiance of a white Lambertian floor under a square light: `Kd * Le * F`.
#[test]
fn direct_light_under_a_square_emitter_matches_the_form_factor() {
    let (a, h, le, kd) = (0.5f32, 1.0f32, 10.0f32, 0.8f32);
    let floor = horizontal(0.0, 20.0, false);
    let light = horizontal(h, a, true);
    let world = scene_of_quads(&[(floor, 0), (light, 1)], vec![diffuse(kd), emitter(le)]);
    let expected = (kd * le) as f64 * square_form_factor(a as f64, h as f64);
    assert_direct_light_converges(&world, Vec3::new(0.0, 0.4, 3.0), Vec3::ZERO, expected, 1e-4);
}

/// Direct light at `target`, seen from `eye`, with both samplers and both light samplings (32
/// seeds of 1024 samples): each converges to `expected`, within four standard errors or four times
/// `floor` of it (what the reference itself may be off by), with a standard error under 1% of it.
fn assert_direct_light_converges(world: &World, eye: Vec3, target: Vec3, expected: f64, floor: f64) {
    for sampler in [SamplerKind::Independent, SamplerKind::Sobol] {
        for light_sampling in [LightSampling::PerLight, LightSampling::Power] {
            let options = |seed| direct_options(1024, seed, sampler, light_sampling);
            let (mean, error) = mean_and_error(32, |seed| estimate(world, eye, target, &options(seed)));
            let context = format!("{sampler:?} {light_sampling:?}");
            assert!(
                (mean - expected).abs() < 4.0 * error.max(floor * expected),
                "{context}: {mean} +- {error}, expected {expected}"
            );
            assert!(error < 0.01 * expected, "{context}: standard error {error}");
        }
    }
}

/// Two lights of different power sharing the square: power sampling spends samples in proportion
/// and stays unbiased; by symmetry each triangle carries half the form factor.
#[test]
fn power_light_sampling_is_unbiased_with_unequal_lights() {
    let (a, h, kd) = (0.5f32, 1.0f32, 0.8f32);
    let q = horizontal(h, a, true);
    let mut mesh = TriangleMesh::default();
    mesh.positions.extend_from_slice(&horizontal(0.0, 20.0, false));
    mesh.positions.extend_from_slice(&q);
    mesh.indices = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
    mesh.material_ids = vec![0, 0, 1, 2];
    let materials = vec![diffuse(kd), emitter(5.0), emitter(40.0)];
    let scene = Scene::from_parts("two".into(), mesh, materials, vec![]).unwrap();
    let world = World::new(scene, BuildPreset::Default);
    let expected = kd as f64 * (5.0 + 40.0) * 0.5 * square_form_factor(a as f64, h as f64);
    let options = |seed| direct_options(512, seed, SamplerKind::Independent, LightSampling::Power);
    let (mean, error) =
        mean_and_error(48, |seed| estimate(&world, Vec3::new(0.0, 0.4, 3.0), Vec3::ZERO, &options(seed)));
    assert!((mean - expected).abs() < 4.0 * error, "{mean} +- {error}, expected {expected}");
}

/// At equal N, the Sobol sampler's error is clearly below the independent sampler's.
#[test]
fn sobol_lowers_the_error_of_soft_shadows() {
    let (a, h, le, kd) = (0.5f32, 1.0f32, 10.0f32, 0.8f32);
    let world = scene_of_quads(
        &[(horizontal(0.0, 20.0, false), 0), (horizontal(h, a, true), 1)],
        vec![diffuse(kd), emitter(le)],
    );
    let expected = (kd * le) as f64 * square_form_factor(a as f64, h as f64);
    let rmse = |sampler| {
        let sq: f64 = (0..64)
            .map(|s| {
                let options = direct_options(64, s, sampler, LightSampling::PerLight);
                (estimate(&world, Vec3::new(0.0, 0.4, 3.0), Vec3::ZERO, &options) as f64 - expected).powi(2)
            })
            .sum();
        (sq / 64.0).sqrt()
    };
    let (independent, sobol) = (rmse(SamplerKind::Independent), rmse(SamplerKind::Sobol));
    assert!(sobol < 0.75 * independent, "Sobol RMSE {sobol} vs independent {independent}");
}

/// A plastic floor (diffuse under a GGX layer): its BSDF depends on `wi`, so that the direct
/// estimator evaluates it per light sample instead of as one Lambertian `f`.
fn plastic() -> Material {
    Material { ks: Vec3::splat(0.5), ns: 20.0, illum: 2, ..diffuse(0.4) }
}

/// The receiver of the glossy tests, away from the world's origin: a receiver at the origin (as in
/// the tests above) has shadow segments `target - origin` equal to `target + origin`.
const RECEIVER: Vec3 = Vec3::new(3.0, 0.0, 2.0);

/// A square light of half-size 0.3 at height 1 facing down (the winding of `horizontal(.., true)`),
/// 0.6 behind the receiver, so that the mirror direction of a view from `RECEIVER + (0, 1.5, 1)`,
/// `(0, 1.5, -1)`, meets it and the camera's ray to the receiver passes beside it.
fn light_behind_the_receiver() -> [Vec3; 4] {
    let (h, s, cz) = (1.0, 0.3, -0.6);
    [Vec3::new(-s, h, cz - s), Vec3::new(s, h, cz - s), Vec3::new(s, h, cz + s), Vec3::new(-s, h, cz + s)]
        .map(|c| c + RECEIVER)
}

/// A glossy floor under a square light placed in its mirror direction: both light-sampling
/// strategies, with both samplers, converge to the outgoing radiance
/// `∫ f(wo, wi) Le cos θ cos θ' / d² dA` over the light, here by midpoint quadrature in f64 with
/// the material's own `eval`. The Lambertian tests above never reach the per-sample BSDF path.
#[test]
fn direct_light_on_a_glossy_floor_matches_quadrature_of_its_bsdf() {
    use lumiere::materials::{Bsdf, MaterialKind};
    use lumiere::math::Frame;
    let le = 10.0f32;
    let plastic = plastic();
    assert!(matches!(plastic.kind(), MaterialKind::Plastic { .. }));
    let light = light_behind_the_receiver();
    let world = scene_of_quads(&[(horizontal(0.0, 20.0, false), 0), (light, 1)], vec![plastic.clone(), emitter(le)]);
    let eye = RECEIVER + Vec3::new(0.0, 1.5, 1.0);
    let bsdf = plastic.bsdf(plastic.kd);
    assert!(bsdf.lambertian_eval(Vec3::Z).is_none(), "the floor's BSDF must depend on wi");
    let frame = Frame::from_normal(Vec3::Y);
    let wo = frame.to_local((eye - RECEIVER).normalize());
    let (corner, side) = ((light[0] - RECEIVER).as_dvec3(), (light[2].x - light[0].x) as f64);
    let cells = 400;
    let cell = side / cells as f64;
    let mut expected = 0.0f64;
    for i in 0..cells {
        for j in 0..cells {
            let p = corner + glam::DVec3::new((i as f64 + 0.5) * cell, 0.0, (j as f64 + 0.5) * cell);
            let d2 = p.length_squared();
            let wi = p / d2.sqrt();
            let f = bsdf.eval(wo, frame.to_local(wi.as_vec3())).x as f64;
            // cos θ at the floor and cos θ' at the light are both wi.y.
            expected += f * le as f64 * wi.y * wi.y / d2 * cell * cell;
        }
    }
    // The pixel's footprint (1°) moves the answer by far less than 1e-3 of it.
    assert_direct_light_converges(&world, eye, RECEIVER, expected, 1e-3);
}

/// The same light hidden from the receiver by an opaque square between them (but not from the
/// camera) leaves the floor black, glossy or diffuse, whatever the light sampling; without the
/// blocker the floor is lit. The receiver is away from the world's origin, so that a shadow segment
/// must really run from the receiver to its light point (`target - origin`, where `target + origin`
/// or `target / origin` lit nothing here).
#[test]
fn a_floor_whose_light_is_hidden_by_a_blocker_is_black() {
    // At height 0.5, the shaft from the receiver to the light spans x in [-0.15, 0.15] and z in
    // [-0.45, -0.15] around the receiver; the camera's ray crosses that height at z = +1/3.
    let blocker =
        [Vec3::new(-0.4, 0.5, -0.6), Vec3::new(-0.4, 0.5, 0.0), Vec3::new(0.4, 0.5, 0.0), Vec3::new(0.4, 0.5, -0.6)]
            .map(|c| c + RECEIVER);
    let eye = RECEIVER + Vec3::new(0.0, 1.5, 1.0);
    for floor in [plastic(), diffuse(0.8)] {
        let world = scene_of_quads(
            &[(horizontal(0.0, 20.0, false), 0), (light_behind_the_receiver(), 1), (blocker, 0)],
            vec![floor.clone(), emitter(10.0)],
        );
        for light_sampling in [LightSampling::PerLight, LightSampling::Power] {
            for samples in [1, 17, 64] {
                let options = direct_options(samples, 7, SamplerKind::Independent, light_sampling);
                let value = estimate(&world, eye, RECEIVER, &options);
                assert_eq!(value, 0.0, "{:?} floor, {light_sampling:?}, N = {samples}", floor.kind());
            }
        }
        // Without the blocker the same floor is lit.
        let world = scene_of_quads(
            &[(horizontal(0.0, 20.0, false), 0), (light_behind_the_receiver(), 1)],
            vec![floor.clone(), emitter(10.0)],
        );
        let options = direct_options(64, 7, SamplerKind::Independent, LightSampling::PerLight);
        assert!(estimate(&world, eye, RECEIVER, &options) > 0.0, "{:?} floor unblocked", floor.kind());
    }
}

/// A small floor whose shading normals lean 45 degrees towards a light that stands across its
/// plane: the part of the light below the floor's geometric plane lies above the shading normals'
/// horizon but cannot light the floor's top (light from there would pass through the floor). So
/// the floor, glossy or diffuse, must shine as under the light's part above the plane alone, by
/// direct lighting with either light sampling and by the path tracer (direct light only) with each
/// strategy. Direct lighting's batches leave the floor's own triangles out (their shaft is cut by
/// the surface), and the path tracer spawns a segment on the side it leaves by: only the tests of
/// the geometric normal keep that light out.
#[test]
fn light_below_the_geometric_surface_does_not_leak_through_shading_normals() {
    let receiver =
        [Vec3::new(-0.2, 0.0, -0.2), Vec3::new(-0.2, 0.0, 0.2), Vec3::new(0.2, 0.0, 0.2), Vec3::new(0.2, 0.0, -0.2)];
    // A light in the plane x = 1 facing -x, over heights `bottom..0.25`.
    let light = |bottom: f32| {
        [
            Vec3::new(1.0, bottom, -0.5),
            Vec3::new(1.0, bottom, 0.5),
            Vec3::new(1.0, 0.25, 0.5),
            Vec3::new(1.0, 0.25, -0.5),
        ]
    };
    let leaning = Vec3::new(1.0, 1.0, 0.0).normalize();
    let world = |bottom: f32, floor: &Material| {
        let quads = [(receiver.map(|c| c + RECEIVER), 0), (light(bottom).map(|c| c + RECEIVER), 1)];
        let mut mesh = mesh_of_quads(&quads);
        mesh.normals = vec![leaning];
        mesh.normal_indices = vec![[0; 3], [0; 3], [NO_INDEX; 3], [NO_INDEX; 3]];
        world_of(mesh, vec![floor.clone(), emitter(10.0)])
    };
    let direct = |light_sampling| (Technique::Direct(Direct { samples: 256, light_sampling }), 1);
    let path = |strategy| (Technique::Path(Path { max_depth: 2, strategy, ..Path::default() }), 1024);
    let techniques = [
        direct(LightSampling::PerLight),
        direct(LightSampling::Power),
        path(PathStrategy::Mis),
        path(PathStrategy::LightsOnly),
        path(PathStrategy::BsdfOnly),
    ];
    // Seen from above both normals; the camera's ray passes beside the light.
    let eye = RECEIVER + Vec3::new(0.5, 1.5, 1.0);
    for floor in [plastic(), diffuse(0.8)] {
        let (across, above) = (world(-1.0, &floor), world(0.0, &floor));
        for (technique, spp) in techniques {
            let options = |seed| RenderOptions { seed, spp, ..RenderOptions::new(technique) };
            let (leaked, leaked_error) = mean_and_error(32, |seed| estimate(&across, eye, RECEIVER, &options(seed)));
            let (lit, lit_error) = mean_and_error(32, |seed| estimate(&above, eye, RECEIVER, &options(seed)));
            let context = format!("{:?} floor, {technique:?}", floor.kind());
            assert!(lit > 0.0 && lit_error < 0.1 * lit, "{context}: the light's upper part gives {lit} +- {lit_error}");
            let bound = 4.0 * (leaked_error.powi(2) + lit_error.powi(2)).sqrt();
            assert!(
                (leaked - lit).abs() < bound,
                "{context}: {leaked} +- {leaked_error} with the light across the plane, {lit} +- {lit_error} above it"
            );
        }
    }
}
