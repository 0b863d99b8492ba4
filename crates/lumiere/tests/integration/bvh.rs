//! The BVH against brute force on seeded random meshes: same closest triangle, same t, same
//! occlusion answers, for every build preset; plus the structural validator.

use crate::common::{TestRng, grid_cube};
use glam::Vec3;
use lumiere::accel::simd::portable::F32xN;
use lumiere::accel::{Accel, BuildPreset, Bvh, Bvh4, Hit, Isa, TraversalStats, VisitOrder, WideBvh};
use lumiere::geometry::triangle::{WatertightRay, intersect_triangle, is_degenerate};
use lumiere::math::{Frame, Ray};

fn brute_force(positions: &[Vec3], indices: &[[u32; 3]], ray: &Ray) -> Option<Hit> {
    brute_force_filtered(positions, indices, ray, &|_, _, _| true)
}

/// Brute force keeping only the hits `keep(triangle, u, v)` accepts: the closest of those (equal
/// `t`: the lower id, which is visited first).
fn brute_force_filtered(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    ray: &Ray,
    keep: &dyn Fn(u32, f32, f32) -> bool,
) -> Option<Hit> {
    let wray = WatertightRay::new(ray);
    let mut best: Option<Hit> = None;
    for (id, tri) in indices.iter().enumerate() {
        let [a, b, c] = tri.map(|i| positions[i as usize]);
        if is_degenerate(a, b, c) {
            continue;
        }
        let tmax = best.map_or(ray.tmax, |b| b.t);
        if let Some(h) = intersect_triangle(&wray, tmax, a, b, c)
            && best.is_none_or(|b| h.t < b.t)
            && keep(id as u32, h.u, h.v)
        {
            best = Some(Hit { t: h.t, triangle: id as u32, u: h.u, v: h.v });
        }
    }
    best
}

/// Kinds of random meshes, each stressing the build differently.
fn random_mesh(rng: &mut TestRng, kind: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let count = match kind {
        0 => 0,
        1 => 1,
        _ => 1 + rng.below(600),
    };
    let scale = if kind == 5 { 1e18 } else { 1.0 };
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for i in 0..count {
        let centre = rng.vec3(-10.0, 10.0);
        let size = rng.range(0.01, 2.0);
        let mut corners =
            [centre + rng.vec3(-size, size), centre + rng.vec3(-size, size), centre + rng.vec3(-size, size)];
        match kind {
            // Degenerate: zero-area (repeated vertex) and collinear triangles mixed in.
            3 if i % 3 == 0 => corners[2] = corners[0],
            3 if i % 3 == 1 => corners[2] = corners[0] + 0.5 * (corners[1] - corners[0]),
            // Coplanar: everything on the plane z = 1.
            4 => corners.iter_mut().for_each(|p| p.z = 1.0),
            // Many overlapping coplanar triangles sharing one centroid (the origin).
            6 => corners = [Vec3::new(-size, -size, 0.0), Vec3::new(size, -size, 0.0), Vec3::new(0.0, 2.0 * size, 0.0)],
            _ => {}
        }
        let base = positions.len() as u32;
        positions.extend(corners.iter().map(|&p| p * scale));
        indices.push([base, base + 1, base + 2]);
    }
    (positions, indices)
}

/// The 4-wide layout with the portable kernel: must answer exactly like the SSE one.
type PortableBvh4 = WideBvh<4, F32xN<4>>;
/// An 8-wide layout (built for blocks of 8) with the portable kernel: the layout, the collapse and
/// the leaf encoding are generic in the width, and must stay so.
type PortableBvh8 = WideBvh<8, F32xN<8>>;

/// Every preset and every traversal path (binary scalar, 4-wide SIMD, counted variants, the
/// portable kernel at widths 4 and 8, and the accel of every ISA this CPU runs: 8-wide AVX2 and
/// AVX-512 where present) must give brute force's answer bit for bit: same triangle, same t and
/// barycentrics, same occlusion.
fn check_against_brute_force(positions: &[Vec3], indices: &[[u32; 3]], rays: &[Ray], context: &str) {
    for preset in BuildPreset::ALL {
        let bvh = Bvh::build(positions, indices, preset);
        bvh.validate().unwrap_or_else(|e| panic!("{context} {preset:?}: {e}"));
        let wide = Bvh4::from_binary(&bvh);
        let portable = PortableBvh4::from_binary(&bvh);
        let bvh8 = Bvh::build_for_width::<8>(positions, indices, preset);
        bvh8.validate().unwrap_or_else(|e| panic!("{context} {preset:?} for width 8: {e}"));
        let wide8 = PortableBvh8::from_binary(&bvh8);
        let accels: Vec<Accel> =
            Isa::supported().into_iter().map(|isa| Accel::build(positions, indices, preset, isa)).collect();
        let mut stats = TraversalStats::default();
        for ray in rays {
            let expected = brute_force(positions, indices, ray);
            let paths = [
                ("binary", bvh.intersect(ray), bvh.occluded(ray)),
                ("wide", wide.intersect(ray), wide.occluded(ray)),
                ("wide counted", wide.intersect_counted(ray, &mut stats), wide.occluded_counted(ray, &mut stats)),
                ("wide portable", portable.intersect(ray), portable.occluded(ray)),
                ("8-wide portable", wide8.intersect(ray), wide8.occluded(ray)),
            ];
            for (path, hit, occluded) in paths {
                assert_eq!(hit, expected, "{context} {preset:?} {path} {ray:?}");
                assert_eq!(occluded, expected.is_some(), "{context} {preset:?} {path} occlusion {ray:?}");
            }
            for accel in &accels {
                let isa = accel.isa();
                assert_eq!(accel.intersect(ray), expected, "{context} {preset:?} {isa} {ray:?}");
                assert_eq!(accel.intersect_counted(ray, &mut stats), expected, "{context} {preset:?} {isa} counted");
                assert_eq!(accel.occluded(ray), expected.is_some(), "{context} {preset:?} {isa} occlusion {ray:?}");
                assert_eq!(accel.occluded_counted(ray, &mut stats), expected.is_some(), "{context} {isa} counted");
            }
        }
        // A tree of one node over at most four blocks is tested block by block, visiting no node.
        assert!(rays.is_empty() || indices.is_empty() || stats.blocks > 0, "{context}: counters count blocks");
        assert!(rays.is_empty() || wide.nodes().len() == 1 || stats.nodes > 0, "{context}: counters count nodes");
        check_packets(&accels, positions, indices, rays, &format!("{context} {preset:?}"));
    }
}

/// Packets of 16 (the rays in order, so mixed keys as well as shared ones), every lane live and
/// then every third lane dead, must answer like brute force lane by lane on every ISA.
fn check_packets(accels: &[Accel], positions: &[Vec3], indices: &[[u32; 3]], rays: &[Ray], context: &str) {
    for chunk in rays.chunks(16) {
        let mut packet = [chunk[0]; 16];
        packet[..chunk.len()].copy_from_slice(chunk);
        let expected: Vec<Option<Hit>> = packet.iter().map(|ray| brute_force(positions, indices, ray)).collect();
        let all = (1u32 << chunk.len()) - 1;
        for live in [all, all & 0b1011_0110_1101_1011] {
            for accel in accels {
                let isa = accel.isa();
                let hits = accel.intersect_packet(&packet, live);
                let blocked = accel.occluded_packet(&packet, live);
                for lane in 0..16 {
                    if live & (1 << lane) == 0 {
                        assert_eq!(hits[lane], None, "{context} {isa}: a dead lane has a hit");
                        continue;
                    }
                    let ray = &packet[lane];
                    assert_eq!(hits[lane], expected[lane], "{context} {isa} packet lane {lane} {ray:?}");
                    let occluded = blocked & (1 << lane) != 0;
                    assert_eq!(occluded, expected[lane].is_some(), "{context} {isa} packet occlusion {lane} {ray:?}");
                }
            }
        }
    }
}

/// Bundles of 16 nearly parallel rays (a block of camera rays; shadow rays from nearby points to
/// one target), which share a packet key and so walk the BVH as packets: the same hits as brute
/// force, through shared edges and vertices, with short and long `tmax`.
#[test]
fn coherent_packets_match_brute_force() {
    let mut rng = TestRng(77);
    for mesh_index in 0..120 {
        let kind = mesh_index % 7;
        let (positions, indices) = random_mesh(&mut rng, kind);
        if indices.is_empty() {
            continue;
        }
        let scale = if kind == 5 { 1e18 } else { 1.0 };
        let mut rays = Vec::new();
        for bundle in 0..8 {
            let target = positions[indices[rng.below(indices.len())][rng.below(3)] as usize];
            let origin = rng.vec3(-15.0, 15.0) * scale;
            let spread = rng.range(0.0, 0.5) * scale;
            for lane in 0..16 {
                let ray = if bundle % 2 == 0 {
                    // Camera-like: one origin, directions fanning around a vertex (lane 0 through it).
                    let aim = if lane == 0 { target } else { target + rng.vec3(-spread, spread) };
                    Ray::new(origin, aim - origin)
                } else {
                    // Shadow-like: nearby origins, one end point (a vertex: rays through shared edges).
                    let from = origin + rng.vec3(-spread, spread);
                    let mut ray = Ray::new(from, target - from);
                    ray.tmax = if lane % 3 == 0 { 0.999 } else { 1.0 };
                    ray
                };
                rays.push(ray);
            }
        }
        // A NaN direction among coherent rays is traced alone (and hits nothing).
        rays[5].dir.y = f32::NAN;
        let accels: Vec<Accel> = Isa::supported()
            .into_iter()
            .map(|isa| Accel::build(&positions, &indices, BuildPreset::default(), isa))
            .collect();
        check_packets(&accels, &positions, &indices, &rays, &format!("mesh {mesh_index} kind {kind}"));
    }
}

#[test]
fn random_meshes_match_brute_force_for_every_preset() {
    let mut rng = TestRng(2024);
    for mesh_index in 0..350 {
        let kind = mesh_index % 7;
        let (positions, indices) = random_mesh(&mut rng, kind);
        let scale = if kind == 5 { 1e18 } else { 1.0 };
        let rays: Vec<Ray> = (0..64)
            .map(|i| {
                let origin = rng.vec3(-15.0, 15.0) * scale;
                let mut ray = if i % 2 == 0 && !indices.is_empty() {
                    // Aim at a random vertex so that many rays hit.
                    let target = positions[indices[rng.below(indices.len())][0] as usize];
                    Ray::new(origin, target - origin)
                } else {
                    Ray::new(origin, rng.direction())
                };
                if i % 5 == 0 {
                    ray.tmax = rng.range(0.0, 20.0) * scale;
                }
                ray
            })
            .collect();
        check_against_brute_force(&positions, &indices, &rays, &format!("mesh {mesh_index} kind {kind}"));
    }
}

/// The default build on one thread and on three, after checking that they have the same nodes and
/// that the first is valid.
fn built_on_one_thread_and_three(positions: &[Vec3], indices: &[[u32; 3]]) -> (Bvh, Bvh) {
    let build_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
        pool.install(|| Bvh::build(positions, indices, BuildPreset::Default))
    };
    let (one, three) = (build_on(1), build_on(3));
    assert_eq!(one.nodes(), three.nodes(), "the layout depends on the thread count");
    assert_eq!(one.validate(), Ok(()));
    (one, three)
}

/// The trees built on one thread and on three give the same hits, and brute force's.
fn check_threads_agree_with_brute_force(
    one: &Bvh,
    three: &Bvh,
    positions: &[Vec3],
    indices: &[[u32; 3]],
    rays: &[Ray],
    context: &str,
) {
    for ray in rays {
        assert_eq!(one.intersect(ray), three.intersect(ray), "{context} {ray:?}");
    }
    check_against_brute_force(positions, indices, rays, context);
}

/// Trees large enough to be built in parallel (subtrees of 4,096 triangles and more split on rayon,
/// then written into one array) are the same node for node on one thread and on three, keep their
/// structure valid, and answer like brute force; some of the triangles are degenerate, so the
/// build's compaction runs too.
#[test]
fn large_trees_are_the_same_on_any_thread_count_and_match_brute_force() {
    let mut rng = TestRng(77);
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for i in 0..20_000u32 {
        let centre = rng.vec3(-10.0, 10.0);
        let size = rng.range(0.01, 0.5);
        let mut corners = [0; 3].map(|_| centre + rng.vec3(-size, size));
        if i % 97 == 0 {
            corners[2] = corners[0];
        }
        positions.extend(corners);
        indices.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let (one, three) = built_on_one_thread_and_three(&positions, &indices);
    let rays: Vec<Ray> = (0..400)
        .map(|i| {
            let origin = rng.vec3(-15.0, 15.0);
            if i % 2 == 0 {
                let target = positions[indices[rng.below(indices.len())][1] as usize];
                Ray::new(origin, target - origin)
            } else {
                Ray::new(origin, rng.direction())
            }
        })
        .collect();
    check_threads_agree_with_brute_force(&one, &three, &positions, &indices, &rays, "20,000 triangles");
}

/// A room of large triangles (walls, floor, long slanted boards) filled with small ones, the
/// staircase's shape: spatial splits cut the large triangles (more leaf slots than triangles, none
/// for the fast preset, which makes none), the cut tree is valid, the same on one thread and on
/// three, cheaper by the SAH, and answers like brute force, rays along the cuts included.
#[test]
fn spatial_splits_cut_large_triangles_and_answer_like_brute_force() {
    let mut rng = TestRng(4242);
    let mut positions: Vec<Vec3> = Vec::new();
    let mut indices: Vec<[u32; 3]> = Vec::new();
    let mut triangle = |corners: [Vec3; 3]| {
        let base = positions.len() as u32;
        positions.extend(corners);
        indices.push([base, base + 1, base + 2]);
    };
    let c = 10.0;
    for axis in 0..3 {
        for side in [-c, c] {
            let point = |u: f32, v: f32| {
                let mut p = [0.0; 3];
                (p[axis], p[(axis + 1) % 3], p[(axis + 2) % 3]) = (side, u, v);
                Vec3::from_array(p)
            };
            triangle([point(-c, -c), point(c, -c), point(c, c)]);
            triangle([point(-c, -c), point(c, c), point(-c, c)]);
        }
    }
    for _ in 0..60 {
        let (a, b) = (rng.vec3(-c, c), rng.vec3(-c, c));
        triangle([a, b, a + rng.vec3(-0.5, 0.5)]);
    }
    for _ in 0..6_000 {
        let centre = rng.vec3(-c, c);
        triangle([0; 3].map(|_| centre + rng.vec3(-0.2, 0.2)));
    }
    let (one, three) = built_on_one_thread_and_three(&positions, &indices);
    assert!(one.slot_count() > one.triangle_count(), "no triangle was cut");
    let fast = Bvh::build(&positions, &indices, BuildPreset::Fast);
    assert_eq!(fast.slot_count(), fast.triangle_count(), "the fast preset cut triangles");
    assert!(one.sah_cost() < 0.9 * fast.sah_cost(), "SAH cost {} against {} uncut", one.sah_cost(), fast.sah_cost());
    let rays: Vec<Ray> = (0..300)
        .map(|i| {
            let origin = rng.vec3(-0.9 * c, 0.9 * c);
            match i % 3 {
                0 => Ray::new(origin, positions[indices[rng.below(indices.len())][0] as usize] - origin),
                // Parallel to a wall, close to it: along the planes that cut the walls.
                1 => Ray::new(Vec3::new(origin.x, origin.y, c - 1e-3), Vec3::new(rng.range(-1.0, 1.0), 1.0, 0.0)),
                _ => Ray::new(origin, rng.direction()),
            }
        })
        .collect();
    check_threads_agree_with_brute_force(
        &one,
        &three,
        &positions,
        &indices,
        &rays,
        "a room of large and small triangles",
    );
}

/// A triangle wider than f32's range (its box's extent overflows to infinity, and so do the areas
/// the build and the collapse weigh) among small ones and huge scattered ones: the trees are
/// built and collapsed (the collapse plan once panicked on infinite costs) and answer like brute
/// force.
#[test]
fn boxes_wider_than_the_f32_range_build_and_answer_like_brute_force() {
    let mut rng = TestRng(99);
    let mut positions = vec![
        Vec3::new(-3e38, -3e38, 0.0),
        Vec3::new(3e38, -3e38, 0.0),
        Vec3::new(0.0, 3e38, 1e38),
        Vec3::new(-1e-30, 0.0, 0.0),
        Vec3::new(1e-30, 0.0, 0.0),
        Vec3::new(0.0, 1e-30, 0.0),
    ];
    for _ in 0..300 {
        let centre = rng.vec3(-1e37, 1e37);
        positions.extend([0; 3].map(|_| centre + rng.vec3(-1e36, 1e36)));
    }
    let indices: Vec<[u32; 3]> = (0..positions.len() as u32 / 3).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    let rays: Vec<Ray> = (0..200)
        .map(|i| {
            let origin = rng.vec3(-2e37, 2e37) + Vec3::new(0.0, 0.0, 5e37);
            if i % 2 == 0 {
                Ray::new(origin, positions[indices[rng.below(indices.len())][0] as usize] - origin)
            } else {
                Ray::new(origin, rng.direction())
            }
        })
        .collect();
    check_against_brute_force(&positions, &indices, &rays, "boxes wider than the f32 range");
}

#[test]
fn closed_mesh_rays_through_vertices_and_edges_never_leak() {
    let (positions, indices) = grid_cube(6);
    let mut rng = TestRng(5);
    let origin = Vec3::new(0.1, -0.2, 0.05);
    let mut rays: Vec<Ray> = positions.iter().map(|&p| Ray::new(origin, p - origin)).collect();
    rays.extend((0..500).map(|_| Ray::new(origin, rng.direction())));
    for preset in BuildPreset::ALL {
        let bvh = Bvh::build(&positions, &indices, preset);
        let wide = Bvh4::from_binary(&bvh);
        for ray in &rays {
            assert!(bvh.intersect(ray).is_some() && wide.intersect(ray).is_some(), "{preset:?}: {ray:?} escaped");
            assert!(bvh.occluded(ray) && wide.occluded(ray), "{preset:?}: {ray:?} escaped");
        }
        for isa in Isa::supported() {
            let accel = Accel::build(&positions, &indices, preset, isa);
            assert!(
                rays.iter().all(|r| accel.intersect(r).is_some() && accel.occluded(r)),
                "{preset:?} {isa}: a ray escaped"
            );
        }
    }
    check_against_brute_force(&positions, &indices, &rays, "grid cube");
}

/// The Cornell box (32 triangles: one 8-wide node over four blocks) is tested block by block
/// without its node, by single rays from inside and outside, some through its vertices: brute force's
/// answers on every ISA, every block tested, no node.
#[test]
fn a_one_node_tree_tested_block_by_block_answers_like_brute_force() {
    let mesh = lumiere::scene::Scene::builtin().unwrap().mesh;
    let (positions, indices) = (&mesh.positions, &mesh.indices);
    let mut rng = TestRng(32);
    let inside = Vec3::new(0.0, 1.0, 0.0);
    let mut rays: Vec<Ray> = positions.iter().map(|&p| Ray::new(inside, p - inside)).collect();
    rays.extend((0..2000).map(|_| Ray::new(inside + rng.vec3(-0.9, 0.9), rng.direction())));
    rays.extend((0..2000).map(|_| {
        let origin = rng.vec3(-5.0, 5.0);
        Ray::new(origin, positions[indices[rng.below(indices.len())][1] as usize] - origin)
    }));
    for ray in rays.iter_mut().step_by(3) {
        ray.tmax = rng.range(0.0, 2.0);
    }
    let expected: Vec<Option<Hit>> = rays.iter().map(|ray| brute_force(positions, indices, ray)).collect();
    let hits = expected.iter().filter(|hit| hit.is_some()).count();
    assert!(hits > rays.len() / 2, "most rays hit ({hits} of {})", rays.len());
    for isa in Isa::supported().into_iter().filter(|&isa| isa >= Isa::Avx2) {
        let accel = Accel::build(positions, indices, BuildPreset::default(), isa);
        for (ray, &expected) in rays.iter().zip(&expected) {
            let mut stats = TraversalStats::default();
            assert_eq!(accel.intersect_counted(ray, &mut stats), expected, "{isa} {ray:?}");
            assert_eq!(accel.intersect(ray), expected, "{isa} {ray:?}");
            assert_eq!((stats.nodes, stats.blocks), (0, 4), "{isa}: every block, no node");
            assert_eq!(accel.occluded(ray), expected.is_some(), "{isa} occlusion {ray:?}");
        }
    }
}

#[test]
fn sah_cost_is_sane_and_better_presets_are_not_worse() {
    let (positions, indices) = grid_cube(40);
    let costs: Vec<f64> = BuildPreset::ALL.iter().map(|&p| Bvh::build(&positions, &indices, p).sah_cost()).collect();
    assert!(costs.iter().all(|&c| c > 1.0 && c.is_finite()), "{costs:?}");
    // A single leaf over everything would cost the triangle count; the tree must be far better.
    assert!(costs[1] < indices.len() as f64 / 20.0, "{costs:?}");
    assert!(costs[2] <= costs[0] * 1.02, "high quality {} vs fast {}", costs[2], costs[0]);
}

/// Shared-origin batches (shafts towards a triangle, hemispheres) answer exactly like traversal
/// for rays away from triangle edges, and agree on all but a vanishing fraction of edge-grazing rays.
#[test]
fn origin_batches_agree_with_traversal() {
    use lumiere::accel::{OriginBatch, Region};
    let mut rng = TestRng(77);
    let (mut rays, mut differ, mut batched) = (0usize, 0usize, 0usize);
    for mesh_index in 0..120 {
        let (positions, indices) = random_mesh(&mut rng, 2 + mesh_index % 3);
        let wide = Bvh4::from_binary(&Bvh::build(&positions, &indices, BuildPreset::Default));
        let wide8 = PortableBvh8::build(&positions, &indices, BuildPreset::Default);
        let (mut batch, mut batch8) = (OriginBatch::default(), OriginBatch::default());
        let mut accels: Vec<(Accel, OriginBatch)> = Isa::supported()
            .into_iter()
            .map(|isa| (Accel::build(&positions, &indices, BuildPreset::Default, isa), OriginBatch::default()))
            .collect();
        for _ in 0..8 {
            let origin = rng.vec3(-12.0, 12.0);
            let corners = [rng.vec3(-12.0, 12.0), rng.vec3(-12.0, 12.0), rng.vec3(-12.0, 12.0)];
            let normal = rng.direction();
            let frame = Frame::from_normal(normal);
            // A shaft, a hemisphere, or one quarter of a hemisphere split in quarters (as ambient
            // occlusion traces them).
            let quarter = (rng.f32() < 0.5).then(|| rng.below(4));
            let (region, shaft) = match Region::shaft(origin, corners) {
                Some(r) if rng.f32() < 0.5 => (r, true),
                _ => match quarter {
                    Some(_) => (Region::hemisphere_in_quarters(origin, &frame, 50.0), false),
                    None => (Region::hemisphere(origin, normal), false),
                },
            };
            let part = if shaft { 0 } else { quarter.unwrap_or(0) };
            batch.prepare(&wide, origin, &region, 64);
            batch.select_part(part);
            batched += usize::from(batch.candidate_blocks().is_some());
            // The candidates are the triangles that survive culling, packed as the tree's leaf
            // blocks allow (four kept side by side go in as they are): every walk of a tree of one
            // width gathers as many blocks, whatever its kernel.
            batch8.prepare(&wide8, origin, &region, 64);
            batch8.select_part(part);
            for (accel, accel_batch) in &mut accels {
                accel.prepare_batch(accel_batch, origin, &region, 64);
                accel_batch.select_part(part);
                let same_width = if accel.isa().width() == 4 { &batch } else { &batch8 };
                assert_eq!(accel_batch.candidate_blocks(), same_width.candidate_blocks(), "mesh {mesh_index}");
            }
            // The rays of this origin, 16 to a group, for the ray-major test.
            let mut group = [[0.0f32; 16]; 3];
            let mut group_answers = 0u32;
            for k in 0..64 {
                let ray = if shaft {
                    let (a, b) = (rng.f32(), rng.f32());
                    let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                    let target = corners[0] + a * (corners[1] - corners[0]) + b * (corners[2] - corners[0]);
                    Ray::segment(origin, target)
                } else {
                    let d = rng.direction();
                    let d = if d.dot(normal) < 0.0 { -d } else { d };
                    match quarter {
                        // Folded into the quarter; some on its sides, or strayed out of it by a
                        // rounding error, as the sines and cosines of its directions can be.
                        Some(q) => {
                            let local = frame.to_local(d);
                            let signs = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)][q];
                            let (mut x, mut y) = (local.x.abs() * signs.0, local.y.abs() * signs.1);
                            match k % 8 {
                                0 => x = 0.0,
                                1 => y = -1e-7 * signs.1,
                                _ => {}
                            }
                            Ray::new(origin, frame.to_world(Vec3::new(x, y, local.z)))
                        }
                        None => Ray::new(origin, d),
                    }
                };
                rays += 1;
                let occluded = batch.occluded(&wide, &ray);
                differ += usize::from(occluded != wide.occluded(&ray));
                assert_eq!(batch8.occluded(&wide8, &ray), occluded, "mesh {mesh_index}: 8-wide batch {ray:?}");
                for (accel, accel_batch) in &accels {
                    let isa = accel.isa();
                    assert_eq!(accel.occluded_in_batch(accel_batch, &ray), occluded, "mesh {mesh_index}: {isa} batch");
                }
                let lane = k % 16;
                [group[0][lane], group[1][lane], group[2][lane]] = ray.dir.to_array();
                group_answers |= u32::from(occluded) << lane;
                if lane == 15 {
                    // All rays of a group share `tmax` (1 for segments, infinity for directions).
                    for (accel, accel_batch) in &accels {
                        let (isa, live) = (accel.isa(), 0xFFFF);
                        let blocked = accel.occluded_lanes_in_batch(accel_batch, &group, ray.tmax, live);
                        assert_eq!(blocked & live, group_answers, "mesh {mesh_index}: {isa} ray-major batch");
                    }
                    group_answers = 0;
                }
            }
        }
    }
    assert!(batched > 300, "only {batched} batches used candidates");
    assert!(differ * 10_000 <= rays, "{differ} of {rays} rays differ");
}

/// Rays sharing an origin, walked together (as ambient occlusion's probes are where a scene is
/// too large for a batch): every lane answers as brute force does, on every ISA, for any mix of
/// directions (zero and negative-zero components, the axes, both ways), origins on triangles'
/// corners and edges, rays and segments, and any live lanes (dead ones answer 0).
#[test]
fn rays_from_one_origin_walked_together_match_brute_force() {
    let mut rng = TestRng(4242);
    let mut blocked_lanes = 0;
    for mesh_index in 0..60 {
        let (positions, indices) = random_mesh(&mut rng, 2 + mesh_index % 5);
        let accels: Vec<Accel> = Isa::supported()
            .into_iter()
            .map(|isa| Accel::build(&positions, &indices, BuildPreset::Default, isa))
            .collect();
        for _ in 0..6 {
            let origin = match rng.below(3) {
                0 if !positions.is_empty() => positions[rng.below(positions.len())],
                1 if positions.len() >= 2 => positions[0].lerp(positions[1], 0.5),
                _ => rng.vec3(-12.0, 12.0) * if mesh_index % 5 == 3 { 1e18 } else { 1.0 },
            };
            let segment = rng.f32() < 0.5;
            let directions: [Vec3; 16] = std::array::from_fn(|lane| {
                let mut d = match lane % 4 {
                    0 => [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z][rng.below(6)],
                    _ => rng.direction(),
                };
                match lane % 8 {
                    1 => d.x = 0.0,
                    3 => d.y = -0.0,
                    _ => {}
                }
                if segment { d * rng.range(0.5, 30.0) } else { d }
            });
            let dirs: [[f32; 16]; 3] = std::array::from_fn(|axis| directions.map(|d| d[axis]));
            let tmax = if segment { 1.0 } else { f32::INFINITY };
            let live = if rng.f32() < 0.5 { 0xFFFF } else { rng.below(1 << 16) as u32 };
            let mut expected = 0u32;
            for (lane, &dir) in directions.iter().enumerate() {
                let hit =
                    live & (1 << lane) != 0 && brute_force(&positions, &indices, &Ray { origin, dir, tmax }).is_some();
                expected |= u32::from(hit) << lane;
            }
            blocked_lanes += expected.count_ones();
            for accel in &accels {
                let isa = accel.isa();
                for order in [VisitOrder::NearestFirst, VisitOrder::FarthestFirst] {
                    let blocked = accel.simd(|| accel.occluded_from_origin(origin, &dirs, tmax, live, order));
                    assert_eq!(blocked, expected, "mesh {mesh_index}: {isa} {order:?} from {origin:?}, live {live:#x}");
                }
            }
        }
    }
    assert!(blocked_lanes > 300, "only {blocked_lanes} lanes blocked: the test asks too little");
}

/// A shaft from a floor to a light above, cut by the floor's plane (`Region::above`): the floor's
/// own triangles, which the shaft's sides keep where they meet at the origin, are left out, and
/// every segment to the light answers as in the whole shaft, and as brute force does.
#[test]
fn shafts_cut_by_the_surface_leave_out_the_receiver_and_answer_the_same() {
    use lumiere::accel::{OriginBatch, Region};
    use lumiere::math::offset_ray_origin;
    // A floor of 4x4 quads at y = 0 over [-2, 2]², a blocker at y = 1, a light triangle at y = 2.
    let (mut positions, mut indices) = (Vec::new(), Vec::new());
    for i in 0..4 {
        for j in 0..4 {
            let (x, z) = (i as f32 - 2.0, j as f32 - 2.0);
            let base = positions.len() as u32;
            positions.extend([
                Vec3::new(x, 0.0, z),
                Vec3::new(x + 1.0, 0.0, z),
                Vec3::new(x + 1.0, 0.0, z + 1.0),
                Vec3::new(x, 0.0, z + 1.0),
            ]);
            indices.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        }
    }
    let base = positions.len() as u32;
    positions.extend([Vec3::new(-0.6, 1.0, -0.4), Vec3::new(0.5, 1.0, -0.3), Vec3::new(0.0, 1.0, 0.7)]);
    indices.push([base, base + 1, base + 2]);
    let light = [Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, -0.5), Vec3::new(0.0, 2.0, 0.5)];
    let wide = Bvh4::from_binary(&Bvh::build(&positions, &indices, BuildPreset::Default));
    let mut rng = TestRng(31);
    let (mut whole, mut cut) = (OriginBatch::default(), OriginBatch::default());
    let (mut blocked, mut visible) = (0, 0);
    for _ in 0..40 {
        let p = Vec3::new(rng.range(-1.9, 1.9), 0.0, rng.range(-1.9, 1.9));
        let origin = offset_ray_origin(p, Vec3::Y);
        let shaft = Region::shaft(origin, light).expect("the light is above the floor");
        whole.prepare(&wide, origin, &shaft, 64);
        cut.prepare(&wide, origin, &shaft.above(origin, Vec3::Y), 64);
        let (whole_blocks, cut_blocks) = (whole.candidate_blocks().unwrap(), cut.candidate_blocks().unwrap());
        // The floor's triangles around the origin fill a block of their own; the blocker, where
        // the shaft meets it, the only other.
        assert!(cut_blocks <= 1 && cut_blocks < whole_blocks, "{whole_blocks} blocks -> {cut_blocks} from {origin:?}");
        for _ in 0..64 {
            let (a, b) = (rng.f32(), rng.f32());
            let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
            let ray = Ray::segment(origin, light[0] + a * (light[1] - light[0]) + b * (light[2] - light[0]));
            let expected = brute_force(&positions, &indices, &ray).is_some();
            assert_eq!(cut.occluded(&wide, &ray), expected, "{ray:?}");
            assert_eq!(whole.occluded(&wide, &ray), expected, "{ray:?}");
            if expected { blocked += 1 } else { visible += 1 }
        }
    }
    assert!(blocked > 200 && visible > 200, "{blocked} blocked, {visible} visible: the test asks too little");
}

/// A closed mesh seen from inside: no batched ray escapes, through vertices and edges included.
#[test]
fn origin_batches_never_leak_through_a_closed_mesh() {
    use lumiere::accel::{OriginBatch, Region};
    let (positions, indices) = grid_cube(2);
    let wide = Bvh4::from_binary(&Bvh::build(&positions, &indices, BuildPreset::Default));
    let origin = Vec3::new(0.1, -0.2, 0.05);
    let mut batch = OriginBatch::default();
    for normal in [Vec3::X, Vec3::NEG_Y, Vec3::new(0.3, 0.4, -0.5).normalize()] {
        batch.prepare(&wide, origin, &Region::hemisphere(origin, normal), 64);
        assert!(batch.candidate_blocks().is_some());
        for &p in &positions {
            let dir = p - origin;
            if dir.dot(normal) > 0.0 {
                assert!(batch.occluded(&wide, &Ray::new(origin, dir)), "ray to vertex {p:?} escaped");
            }
        }
    }
}

/// A quarter of a hemisphere whose sides run along the edges of a closed mesh: its directions that
/// stray out of it by a rounding error (as ambient occlusion's can) still hit the triangles just
/// beyond its sides, which touch the sides without entering the quarter: the sides keep them.
#[test]
fn hemisphere_quarters_keep_what_their_stray_directions_hit() {
    use lumiere::accel::{OriginBatch, Region};
    let (positions, indices) = grid_cube(2);
    let wide = Bvh4::from_binary(&Bvh::build(&positions, &indices, BuildPreset::Default));
    // About +y, the frame's other axes are x and -z: the sides are the planes x = 0 and z = 0,
    // which hold edges of the cube's grids.
    let origin = Vec3::new(0.0, 0.3, 0.0);
    let frame = Frame::from_normal(Vec3::Y);
    let mut rng = TestRng(9);
    let mut batch = OriginBatch::default();
    batch.prepare(&wide, origin, &Region::hemisphere_in_quarters(origin, &frame, 4.0), 64);
    for quarter in 0..4 {
        batch.select_part(quarter);
        assert!(batch.candidate_blocks().is_some());
        let (x, y) = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)][quarter];
        for k in 0..256 {
            let (along, up) = (rng.range(0.0, 1.0), rng.range(0.05, 1.0));
            let local =
                if k % 2 == 0 { Vec3::new(-1e-6 * x, along * y, up) } else { Vec3::new(along * x, -1e-6 * y, up) };
            let ray = Ray::new(origin, frame.to_world(local));
            assert!(batch.occluded(&wide, &ray), "quarter {quarter}: {ray:?} escaped");
        }
    }
}

/// A direction component of -0.0 is a zero component like +0.0: a ray from inside that slab
/// enters the boxes around it (its reciprocal is a huge negative number, so the slab test must
/// take the entry plane from the reciprocal's sign, not from `d >= 0`).
#[test]
fn negative_zero_directions_enter_boxes() {
    // A floor of many triangles, so that the tree has boxes to enter.
    let (mut positions, mut indices) = (Vec::new(), Vec::new());
    for i in 0..8 {
        for j in 0..8 {
            let (x, y) = (i as f32, j as f32);
            let base = positions.len() as u32;
            positions.extend([Vec3::new(x, y, 0.0), Vec3::new(x + 1.0, y, 0.0), Vec3::new(x, y + 1.0, 0.0)]);
            indices.push([base, base + 1, base + 2]);
        }
    }
    for dir in [Vec3::new(-0.0, -0.0, -1.0), Vec3::new(-0.0, 0.0, -1.0), Vec3::new(0.0, -0.0, -1.0)] {
        for origin in [Vec3::new(2.25, 3.25, 5.0), Vec3::new(6.1, 0.2, 1.0)] {
            let ray = Ray::new(origin, dir);
            let expected = brute_force(&positions, &indices, &ray);
            assert!(expected.is_some());
            let bvh = Bvh::build(&positions, &indices, BuildPreset::Default);
            assert_eq!(bvh.intersect(&ray), expected, "binary {ray:?}");
            for isa in Isa::supported() {
                let accel = Accel::build(&positions, &indices, BuildPreset::Default, isa);
                assert_eq!(accel.intersect(&ray), expected, "{isa} {ray:?}");
                assert!(accel.occluded(&ray), "{isa} {ray:?}");
                assert_eq!(accel.intersect_packet(&[ray; 16], 0xffff)[3], expected, "{isa} packet {ray:?}");
            }
        }
    }
}

/// Cutouts: the filtered queries of every ISA against brute force with the same filter, which
/// refuses whole triangles (a third of the ids) and parts of others (by barycentrics), so that rays
/// must go on past refused hits to farther ones. A filter that refuses nothing gives the plain answers.
#[test]
fn filtered_queries_match_brute_force_on_every_isa() {
    let keep = |id: u32, u: f32, v: f32| !id.is_multiple_of(3) && (id.is_multiple_of(2) || u + 0.5 * v < 0.45);
    let keep_all = |_: u32, _: f32, _: f32| true;
    let mut rng = TestRng(77);
    let mut refused_nearer = 0;
    for mesh_index in 0..60 {
        let (positions, indices) = random_mesh(&mut rng, 2 + mesh_index % 5);
        let accels: Vec<Accel> = Isa::supported()
            .into_iter()
            .map(|isa| Accel::build(&positions, &indices, BuildPreset::default(), isa))
            .collect();
        for i in 0..64 {
            let origin = rng.vec3(-15.0, 15.0);
            let target = positions[indices[rng.below(indices.len())][i % 3] as usize];
            let mut ray =
                if i % 4 == 3 { Ray::new(origin, rng.direction()) } else { Ray::new(origin, target - origin) };
            if i % 5 == 0 {
                ray.tmax = rng.range(0.0, 20.0);
            }
            let expected = brute_force_filtered(&positions, &indices, &ray, &keep);
            let plain = brute_force(&positions, &indices, &ray);
            refused_nearer += usize::from(plain.is_some() && plain != expected);
            for accel in &accels {
                let isa = accel.isa();
                assert_eq!(accel.intersect_filtered(&ray, &keep), expected, "mesh {mesh_index} {isa} {ray:?}");
                assert_eq!(
                    accel.occluded_filtered(&ray, &keep),
                    expected.is_some(),
                    "mesh {mesh_index} {isa} occlusion"
                );
                assert_eq!(accel.intersect_filtered(&ray, &keep_all), plain, "mesh {mesh_index} {isa} keep all");
                assert_eq!(accel.occluded_filtered(&ray, &keep_all), plain.is_some(), "mesh {mesh_index} {isa}");
            }
        }
    }
    // The filter must matter: many rays have their nearest hit refused.
    assert!(refused_nearer > 300, "only {refused_nearer} rays had a refused hit");
}
