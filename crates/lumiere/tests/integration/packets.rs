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

use crate::common::TestRng;

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

/// Hard shadows test the segments towards a light's target read backwards, as rays from the
/// target, against candidates gathered once from there (`World::hard_shadow_batch`). On the
/// built-in box, on every ISA: segments from random points in front of each light (inside the
/// boxes too) are blocked exactly where the BVH, tracing them forwards, says they are, one at a
/// time and sixteen together; both answers are common. It fails if a blocker is left out of the
/// candidates, or if a segment's end is misplaced by the reversal.
#[test]
fn hard_shadow_segments_read_backwards_are_blocked_where_the_bvh_says() {
    for isa in Isa::supported() {
        let world = World::with_isa(Scene::builtin().unwrap(), Default::default(), isa);
        let bounds = world.scene().bounds();
        let mut rng = TestRng(0x5EED_0000 + isa as u64);
        for (index, light) in world.lights().lights().iter().enumerate() {
            let batch = world.hard_shadow_batch(index).expect("the box's candidates are gathered");
            let target = light.hard_shadow_target();
            let (mut blocked, mut clear) = (0, 0);
            let mut dirs = [[0.0f32; 16]; 3];
            let mut forward = [false; 16];
            let mut lane = 0;
            while blocked + clear < 16_000 {
                let p = bounds.min + (bounds.max - bounds.min) * rng.vec3(0.0, 1.0);
                let dir = p - target;
                if light.normal.dot(dir) <= 0.0 {
                    continue;
                }
                forward[lane] = world.occluded(&Ray::segment(p, target));
                let backward = world.occluded_in_batch(batch, &Ray { origin: target, dir, tmax: 1.0 });
                assert_eq!(forward[lane], backward, "{isa}: light {index}, segment from {p} to {target}");
                (dirs[0][lane], dirs[1][lane], dirs[2][lane]) = (dir.x, dir.y, dir.z);
                (blocked, clear) = if backward { (blocked + 1, clear) } else { (blocked, clear + 1) };
                lane += 1;
                if lane == 16 {
                    let together = world.simd(|| world.occluded_lanes_in_batch(batch, &dirs, 1.0, u32::from(u16::MAX)));
                    for (lane, &forward) in forward.iter().enumerate() {
                        assert_eq!(together & (1 << lane) != 0, forward, "{isa}: light {index}, lane {lane}");
                    }
                    lane = 0;
                }
            }
            assert!(blocked > 1000 && clear > 1000, "{isa}: light {index}: {blocked} blocked, {clear} clear");
        }
    }
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
