//! Criterion micro-benchmarks of the traversal kernels on fixed ray sets of the built-in scene
//! (one thread): closest hit and occlusion on the wide BVH, and shared-origin batches against
//! per-ray traversal for the rays of one shading point. `cargo bench`; `lumiere bench-bvh` and
//! `lumiere bench` measure whole scenes and renders.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use lumiere::accel::{OriginBatch, Region};
use lumiere::math::Ray;
use lumiere::scene::camera::Camera;
use lumiere::scene::{Scene, builtin};
use lumiere::world::World;
use lumiere_cli::bench::rays::make_ray_sets;

fn traversal(c: &mut Criterion) {
    let world = World::new(Scene::builtin().expect("built-in scene"), Default::default());
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().expect("orbiter"), 128, 96);
    let sets = make_ray_sets(&world, &camera, 0);
    for set in &sets {
        let name = format!("cornell {} {} ({} rays)", set.kind, set.query.name(), set.rays.len());
        c.bench_function(&name, |b| {
            b.iter(|| match set.query {
                lumiere_cli::bench::rays::Query::Closest => set.rays.iter().filter_map(|r| world.intersect(r)).count(),
                lumiere_cli::bench::rays::Query::Occluded => set.rays.iter().filter(|r| world.occluded(r)).count(),
            })
        });
    }

    // 256 segments from a floor point to the light, as soft shadows trace them.
    let origin = Vec3::new(0.3, 1e-4, 0.2);
    let light = &world.lights().lights()[0];
    let rays: Vec<Ray> = (0..256)
        .map(|i| {
            let (u, v) = ((i % 16) as f32 / 16.0 + 0.03, (i / 16) as f32 / 16.0 + 0.03);
            let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
            Ray::segment(origin, light.shadow_target(Vec3::new(1.0 - u - v, u, v)))
        })
        .collect();
    let shaft = Region::shaft(origin, light.shadow_targets).expect("a proper shaft");
    let mut batch = OriginBatch::default();
    c.bench_function("256 shadow rays: per-ray traversal", |b| {
        b.iter(|| rays.iter().filter(|r| world.occluded(r)).count())
    });
    c.bench_function("256 shadow rays: shared-origin batch (incl. prepare)", |b| {
        b.iter(|| {
            world.prepare_batch(&mut batch, origin, &shaft, rays.len() as u32);
            black_box(rays.iter().filter(|r| world.occluded_in_batch(&batch, r)).count())
        })
    });
}

criterion_group!(benches, traversal);
criterion_main!(benches);
