//! Hard shadows count their rays: one camera ray a pixel and one shadow ray for each light
//! triangle that can reach the point, one pixel at a time and as a packet.

use glam::Vec3;
use lumiere::accel::{BuildPreset, OriginBatch};
use lumiere::integrators::{CameraPacket, Integrator, PACKET, SampleContext, Shadows};
use lumiere::materials::Material;
use lumiere::sampler::{SampleStream, Sampler, SamplerKind};
use lumiere::scene::Scene;
use lumiere::scene::camera::Camera;
use lumiere::scene::mesh::TriangleMesh;
use lumiere::world::World;

/// A wide diffuse floor at `y = 0` under a square light at `y = 1` facing down (two triangles).
fn floor_under_a_light() -> World {
    let (s, a) = (10.0f32, 0.5f32);
    let floor = [Vec3::new(-s, 0.0, -s), Vec3::new(-s, 0.0, s), Vec3::new(s, 0.0, s), Vec3::new(s, 0.0, -s)];
    let light = [Vec3::new(-a, 1.0, -a), Vec3::new(a, 1.0, -a), Vec3::new(a, 1.0, a), Vec3::new(-a, 1.0, a)];
    let mut mesh = TriangleMesh::default();
    for (corners, material) in [(floor, 0u32), (light, 1)] {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(&corners);
        mesh.indices.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        mesh.material_ids.extend([material; 2]);
    }
    let materials = vec![
        Material { kd: Vec3::splat(0.5), ..Material::default_grey("floor") },
        Material { ke: Vec3::splat(4.0), ..Material::default_grey("light") },
    ];
    World::new(Scene::from_parts("floor".into(), mesh, materials, vec![]).unwrap(), BuildPreset::Default)
}

#[test]
fn hard_shadows_count_a_camera_ray_and_a_shadow_ray_per_light_triangle() {
    let world = floor_under_a_light();
    assert_eq!(world.lights().lights().len(), 2);
    // Looking down at the floor from under the light: every pixel sees the lit floor.
    let camera = Camera::look_at(Vec3::new(0.0, 0.5, 0.0), Vec3::ZERO, Vec3::Z, 30.0, 4, 4).unwrap();
    let xs: [f32; PACKET] = std::array::from_fn(|lane| (lane % 4) as f32 + 0.5);
    let ys: [f32; PACKET] = std::array::from_fn(|lane| (lane / 4) as f32 + 0.5);
    let rays = camera.rays(&xs, &ys);
    let sampler = Sampler::new(SamplerKind::Independent, 1);
    let mut ctx = SampleContext {
        stream: SampleStream::new(&sampler, 0, 0),
        batch: OriginBatch::default(),
        rays: 0,
        stop: &|| false,
    };
    for ray in &rays {
        ctx.rays = 0;
        let radiance = Shadows.radiance(&world, ray, &mut ctx);
        assert!(radiance.x > 0.0, "{radiance}");
        assert_eq!(ctx.rays, 3, "one camera ray and two shadow rays");
    }
    let streams = std::array::from_fn(|lane| SampleStream::new(&sampler, lane as u32, 0));
    let live = u32::MAX >> (32 - PACKET);
    ctx.rays = 0;
    let radiance = Shadows.radiance_packet(&world, &CameraPacket { rays, streams, live }, &mut ctx);
    assert!(radiance.iter().all(|r| r.x > 0.0), "{radiance:?}");
    assert_eq!(ctx.rays, 3 * PACKET as u64);
}
