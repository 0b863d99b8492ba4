//! Camera rays shaded as packets give each pixel the bits its single ray gives.

use glam::Vec3;
use lumiere::accel::{Isa, OriginBatch};
use lumiere::integrators::{CameraPacket, Integrator, PACKET, Path, SampleContext, Shadows};
use lumiere::materials::MaterialKind;
use lumiere::math::Ray;
use lumiere::sampler::{SampleStream, Sampler, SamplerKind};
use lumiere::scene::camera::Camera;
use lumiere::scene::{Scene, builtin};
use lumiere::world::World;

/// Hard shadows light a packet's diffuse receivers together (SoA) and the others one at a time:
/// on the built-in box with every other material made glossy, so that packets mix the two, each
/// lane of each 4x4 block has the bits of `radiance` for its ray.
#[test]
fn hard_shadow_packets_shade_mixed_materials_as_single_rays_do() {
    let mut scene = Scene::builtin().unwrap();
    for material in scene.materials.iter_mut().step_by(2) {
        material.illum = 2;
        material.ns = 20.0;
    }
    assert!(scene.materials.iter().any(|m| matches!(m.kind(), MaterialKind::Plastic { .. })));
    assert!(scene.materials.iter().any(|m| m.kind() == MaterialKind::Lambert));
    let world = World::new(scene, Default::default());
    let (width, height) = (64u32, 48u32);
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), width, height);
    let sampler = Sampler::new(SamplerKind::Independent, 1);
    let mut ctx = context(&sampler);
    let (mut lit, mut compared) = (0, 0);
    for by in (0..height).step_by(4) {
        for bx in (0..width).step_by(4) {
            let rays = block_rays(&camera, bx, by);
            let streams = std::array::from_fn(|lane| SampleStream::new(&sampler, lane as u32, 0));
            let packet = CameraPacket { rays, streams, live: u32::MAX >> (32 - PACKET) };
            let together = Shadows.radiance_packet(&world, &packet, &mut ctx);
            for lane in 0..PACKET {
                let alone = Shadows.radiance(&world, &rays[lane], &mut ctx);
                assert_same_bits(together[lane], alone, &format!("block ({bx}, {by}) lane {lane}"));
                lit += usize::from(alone.max_element() > 0.0);
                compared += 1;
            }
        }
    }
    assert!(lit * 2 > compared, "{lit} of {compared} pixels lit");
}

/// Path tracing follows a block's paths in lockstep (every path's next hit, then every vertex,
/// then every shadow segment), and from AVX2 up scatters a bounce's diffuse vertices together, in
/// one vectorised loop. On the built-in box with glossy, glass and metal walls, for full blocks and
/// blocks with lanes left out, at several samples and depths (Russian roulette included), on every
/// ISA, each lane has the bits of its path traced alone with SSE2, vertex by vertex.
#[test]
fn paths_traced_in_lockstep_have_the_bits_of_paths_traced_alone() {
    let mut scene = Scene::builtin().unwrap();
    for (i, material) in scene.materials.iter_mut().enumerate().filter(|(_, m)| m.ke == Vec3::ZERO) {
        match i % 4 {
            0 => (material.illum, material.ns) = (2, 20.0),
            1 => (material.illum, material.ni) = (7, 1.5),
            2 => (material.metallic, material.roughness) = (Some(1.0), Some(0.3)),
            _ => {}
        }
    }
    let kinds: Vec<MaterialKind> = scene.materials.iter().map(|m| m.kind()).collect();
    assert!(kinds.iter().any(|k| matches!(k, MaterialKind::Plastic { .. })));
    assert!(kinds.iter().any(|k| matches!(k, MaterialKind::Dielectric { .. })));
    assert!(kinds.iter().any(|k| matches!(k, MaterialKind::Conductor { .. })));
    assert!(kinds.contains(&MaterialKind::Lambert));
    let alone_world = World::with_isa(scene.clone(), Default::default(), Isa::Sse2);
    let worlds: Vec<World> =
        Isa::supported().into_iter().map(|isa| World::with_isa(scene.clone(), Default::default(), isa)).collect();
    let (width, height) = (32u32, 24u32);
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), width, height);
    let sampler = Sampler::new(SamplerKind::Sobol, 3);
    let mut ctx = context(&sampler);
    let all = u32::MAX >> (32 - PACKET);
    let (mut lit, mut compared) = (0, 0);
    for path in [Path::default(), Path { max_depth: 0, ..Path::default() }] {
        for sample in 0..3 {
            for by in (0..height).step_by(4) {
                for bx in (0..width).step_by(4) {
                    let rays = block_rays(&camera, bx, by);
                    let pixel = |lane: usize| (by + lane as u32 / 4) * width + bx + lane as u32 % 4;
                    let streams = std::array::from_fn(|lane| SampleStream::new(&sampler, pixel(lane), sample));
                    // Every other block leaves lanes out, a different set each time.
                    let live =
                        if (bx + by) % 8 == 0 { all } else { all & (0x9E37_79B9u32.rotate_left(bx + by + sample)) };
                    let packet = CameraPacket { rays, streams, live };
                    for world in &worlds {
                        let together = path.radiance_packet(world, &packet, &mut ctx);
                        for lane in 0..PACKET {
                            if live & (1 << lane) == 0 {
                                assert_eq!(together[lane], Vec3::ZERO, "a lane left out is black");
                                continue;
                            }
                            ctx.stream = streams[lane];
                            let alone = path.radiance(&alone_world, &rays[lane], &mut ctx);
                            let isa = world.isa();
                            let what = format!("{isa}, {path:?}, sample {sample}, block ({bx}, {by}) lane {lane}");
                            assert_same_bits(together[lane], alone, &what);
                            lit += usize::from(alone.max_element() > 0.0);
                            compared += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(lit * 2 > compared, "{lit} of {compared} paths found light");
}

/// The camera rays through the centres of the 4x4 pixels from `(bx, by)`, lane `dy * 4 + dx`.
fn block_rays(camera: &Camera, bx: u32, by: u32) -> [Ray; PACKET] {
    let xs: [f32; PACKET] = std::array::from_fn(|lane| (bx + lane as u32 % 4) as f32 + 0.5);
    let ys: [f32; PACKET] = std::array::from_fn(|lane| (by + lane as u32 / 4) as f32 + 0.5);
    camera.rays(&xs, &ys)
}

fn assert_same_bits(together: Vec3, alone: Vec3, what: &str) {
    assert_eq!(together.to_array().map(f32::to_bits), alone.to_array().map(f32::to_bits), "{what}");
}

/// A sample context drawing from `sampler` that is never told to stop.
fn context(sampler: &Sampler) -> SampleContext<'_> {
    SampleContext { stream: SampleStream::new(sampler, 0, 0), batch: OriginBatch::default(), rays: 0, stop: &|| false }
}
