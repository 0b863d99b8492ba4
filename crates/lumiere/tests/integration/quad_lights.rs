//! Quad lights: which light triangles pair into one convex quad, and that the shaft to a quad keeps
//! every triangle that can block a segment towards either of its triangles.

use glam::{Quat, Vec3};
use lumiere::accel::{BuildPreset, OriginBatch, Region};
use lumiere::materials::Material;
use lumiere::math::Ray;
use lumiere::scene::Scene;
use lumiere::scene::mesh::TriangleMesh;
use lumiere::world::World;

use crate::common::TestRng;

/// A world of triangles, those flagged emissive lights.
fn world_of(triangles: &[([Vec3; 3], bool)]) -> World {
    let mut mesh = TriangleMesh::default();
    for (corners, emits) in triangles {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(corners);
        mesh.indices.push([base, base + 1, base + 2]);
        mesh.material_ids.push(u32::from(*emits));
    }
    let materials = vec![
        Material { kd: Vec3::splat(0.5), ..Material::default_grey("diffuse") },
        Material { ke: Vec3::splat(4.0), ..Material::default_grey("light") },
    ];
    World::new(
        Scene::from_parts("test".into(), mesh, materials, vec![]).expect("valid test scene"),
        BuildPreset::Default,
    )
}

/// How the lights of `triangles` pair: for each light, the index of its quad.
fn quads(triangles: &[([Vec3; 3], bool)]) -> Vec<Option<u32>> {
    let world = world_of(triangles);
    let lights = world.lights();
    (0..lights.lights().len() as u32).map(|light| lights.quad_of(light).map(|(q, _)| q)).collect()
}

#[test]
fn only_coplanar_convex_pairs_sharing_an_edge_make_quads() {
    let v = |x: f32, z: f32| Vec3::new(x, 2.0, z);
    // A square split along its diagonal, facing down.
    let square = [([v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0)], true), ([v(0.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)], true)];
    assert_eq!(quads(&square), [Some(0), Some(0)]);
    // The same square folded along the diagonal.
    let folded = [square[0], ([v(0.0, 0.0), v(1.0, 1.0), Vec3::new(0.0, 2.5, 1.0)], true)];
    assert_eq!(quads(&folded), [None, None]);
    // A dart: coplanar, sharing an edge, but concave.
    let dart = [square[0], ([v(0.0, 0.0), v(1.0, 1.0), v(0.8, 0.5)], true)];
    assert_eq!(quads(&dart), [None, None]);
    // Both triangles on one side of the shared edge.
    let overlapping = [square[0], ([v(0.0, 0.0), v(1.0, 1.0), v(0.9, 0.1)], true)];
    assert_eq!(quads(&overlapping), [None, None]);
    // Three lights around one edge pair on none of it; a diffuse neighbour is no light.
    let fan = [square[0], square[1], ([v(0.0, 0.0), v(1.0, 1.0), v(2.0, 0.0)], true)];
    assert_eq!(quads(&fan), [None, None, None]);
    let half_lit = [square[0], (square[1].0, false)];
    assert_eq!(quads(&half_lit), [None]);
    // Two squares apart: each pairs with its own half, whatever the light order.
    let shifted = |t: ([Vec3; 3], bool)| (t.0.map(|p| p + 2.0 * Vec3::X), true);
    let two = [square[0], shifted(square[0]), square[1], shifted(square[1])];
    assert_eq!(quads(&two), [Some(0), Some(1), Some(0), Some(1)]);
    // The built-in Cornell box's light is one quad.
    let world = World::new(Scene::builtin().unwrap(), BuildPreset::Default);
    let pairs: Vec<_> = (0..2).map(|light| world.lights().quad_of(light).map(|(q, _)| q)).collect();
    assert_eq!(pairs, [Some(0), Some(0)]);
}

/// Random quad lights (rotated anywhere) over random blockers: shadow segments from random
/// receivers towards points of both triangles, tested against the batch gathered in the shaft to
/// the quad, get the answers of ordinary traversal but for a vanishing fraction of edge-grazing
/// rays (the batch's Plücker test and the traversal's watertight test round differently).
#[test]
fn shafts_to_quads_keep_every_blocker() {
    let mut rng = TestRng(4242);
    let (mut rays, mut differ, mut blocked, mut batched) = (0usize, 0usize, 0usize, 0usize);
    for scene_index in 0..60 {
        let rotation = Quat::from_axis_angle(rng.direction(), rng.range(0.0, std::f32::consts::TAU));
        let at = |p: Vec3| rotation * p;
        // A convex quad in the plane y = 4, facing down (towards the receivers).
        let (w, d, skew) = (rng.range(0.3, 3.0), rng.range(0.3, 3.0), rng.range(-1.0, 1.0));
        let corners =
            [Vec3::new(0.0, 4.0, 0.0), Vec3::new(w, 4.0, 0.0), Vec3::new(w + skew, 4.0, d), Vec3::new(skew, 4.0, d)]
                .map(at);
        let mut triangles =
            vec![([corners[0], corners[1], corners[2]], true), ([corners[0], corners[2], corners[3]], true)];
        // Small blockers, most of them near the light, where the shaft is narrowest.
        for _ in 0..150 {
            let centre = Vec3::new(rng.range(-1.0, 4.0), rng.range(0.5, 3.95), rng.range(-1.0, 4.0));
            let size = rng.range(0.02, 0.5);
            triangles.push(([0, 1, 2].map(|_| at(centre + size * rng.direction())), false));
        }
        let world = world_of(&triangles);
        let lights = world.lights();
        let Some((_, quad)) = lights.quad_of(0) else { panic!("scene {scene_index}: the quad light did not pair") };
        let mut batch = OriginBatch::default();
        for _ in 0..12 {
            let origin = at(rng.vec3(-3.0, 5.0) * Vec3::new(1.0, 0.0, 1.0) + Vec3::Y * rng.range(-1.0, 3.5));
            let Some(region) = Region::shaft_to_quad(origin, quad.corners, quad.plane) else { continue };
            world.prepare_batch(&mut batch, origin, &region, 64);
            batched += usize::from(batch.candidate_blocks().is_some());
            for light in &lights.lights()[..2] {
                for _ in 0..32 {
                    let (a, b) = (rng.f32(), rng.f32());
                    let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                    let segment = Ray::segment(origin, light.shadow_target(Vec3::new(1.0 - a - b, a, b)));
                    let expected = world.occluded(&segment);
                    rays += 1;
                    blocked += usize::from(expected);
                    differ += usize::from(world.occluded_in_batch(&batch, &segment) != expected);
                }
            }
        }
    }
    assert!(batched > 400, "only {batched} batches gathered candidates");
    assert!(blocked * 20 > rays && blocked * 10 < rays * 9, "{blocked} of {rays} segments blocked: no test");
    assert!(differ * 10_000 <= rays, "{differ} of {rays} segments differ");
}

/// "Strictly convex" is strict: a triangle split in two along a median makes four corners of
/// which one is straight (180°, a turn of exactly 0), and pairs into no quad, whichever way it
/// faces and whichever half comes first.
#[test]
fn a_triangle_split_along_a_median_is_no_quad() {
    let v = |x: f32, z: f32| Vec3::new(x, 2.0, z);
    // (0, 0), (2, 0), (0, 2) split at (1, 1), the middle of its long side; facing down.
    let halves = [[v(0.0, 0.0), v(2.0, 0.0), v(1.0, 1.0)], [v(0.0, 0.0), v(1.0, 1.0), v(0.0, 2.0)]];
    let flip = |[a, b, c]: [Vec3; 3]| [a, c, b];
    for facing in [halves, halves.map(flip)] {
        for order in [[0, 1], [1, 0]] {
            let triangles = order.map(|k| (facing[k], true));
            assert_eq!(quads(&triangles), [None, None], "{triangles:?}");
        }
    }
    // The same halves with the far corner moved out by a little are a convex quad.
    let kite = [([v(0.0, 0.0), v(2.0, 0.0), v(1.1, 1.1)], true), ([v(0.0, 0.0), v(1.1, 1.1), v(0.0, 2.0)], true)];
    assert_eq!(quads(&kite), [Some(0), Some(0)]);
}

/// The quad's plane keeps every shadow target of both its triangles on it or in front of it, as
/// its documentation says (nothing behind the plane may block a segment): for quads rotated
/// anywhere, where the targets of the second triangle often lie a few ulps behind the plane
/// through the first's, and the plane must move back for them.
#[test]
fn quad_planes_keep_every_shadow_target_in_front() {
    let mut rng = TestRng(4343);
    let mut moved = 0;
    for _ in 0..300 {
        let rotation = Quat::from_axis_angle(rng.direction(), rng.range(0.0, std::f32::consts::TAU));
        let (w, d, skew) = (rng.range(0.3, 3.0), rng.range(0.3, 3.0), rng.range(-1.0, 1.0));
        let offset = rng.vec3(-5.0, 5.0);
        let corners =
            [Vec3::new(0.0, 4.0, 0.0), Vec3::new(w, 4.0, 0.0), Vec3::new(w + skew, 4.0, d), Vec3::new(skew, 4.0, d)]
                .map(|p| rotation * p + offset);
        let world =
            world_of(&[([corners[0], corners[1], corners[2]], true), ([corners[0], corners[2], corners[3]], true)]);
        let lights = world.lights();
        let Some((_, quad)) = lights.quad_of(0) else { panic!("{corners:?}: no quad") };
        let n = quad.plane.truncate();
        for light in &lights.lights()[..2] {
            for t in light.shadow_targets {
                let distance = n.dot(t) + quad.plane.w;
                assert!(distance >= 0.0, "{corners:?}: target {t} lies {distance} behind the plane");
            }
        }
        moved += usize::from(quad.plane.w != -n.dot(lights.lights()[0].shadow_targets[0]));
    }
    // The test has teeth only if the plane had to move for some quads.
    assert!(moved > 30, "the plane moved for {moved} quads only");
}
