//! The watertight ray/triangle test against a double-precision reference, and on closed meshes.

use crate::common::{TestRng, grid_cube};
use glam::{DVec3, Vec3};
use lumiere::geometry::triangle::{WatertightRay, intersect_triangle};
use lumiere::math::Ray;

/// Möller-Trumbore in f64: (t, barycentric u, v) or None.
fn reference(o: DVec3, d: DVec3, p: [DVec3; 3]) -> Option<(f64, f64, f64)> {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 {
        return None;
    }
    let s = o - p[0];
    let u = s.dot(pv) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    let t = e2.dot(q) / det;
    Some((t, u, v))
}

#[test]
fn agrees_with_double_precision_reference() {
    let mut rng = TestRng(7);
    let (mut hits, mut checked) = (0, 0);
    for _ in 0..200_000 {
        let p = [rng.vec3(-1.0, 1.0), rng.vec3(-1.0, 1.0), rng.vec3(-1.0, 1.0)];
        let origin = rng.vec3(-3.0, 3.0);
        let dir = (rng.vec3(-0.5, 0.5) - origin) * rng.range(0.1, 4.0);
        let ray = Ray::new(origin, dir);
        let got = intersect_triangle(&WatertightRay::new(&ray), f32::INFINITY, p[0], p[1], p[2]);
        let Some((t, u, v)) = reference(origin.as_dvec3(), dir.as_dvec3(), p.map(Vec3::as_dvec3)) else { continue };
        // Only cases clearly inside or outside are decided; the edge band is tested separately.
        let margin = u.min(v).min(1.0 - u - v);
        let area = (p[1] - p[0]).cross(p[2] - p[0]).length() as f64;
        if margin.abs() < 1e-4 || area < 1e-3 || t.abs() < 1e-4 {
            continue;
        }
        checked += 1;
        let expect_hit = margin > 0.0 && t > 0.0;
        assert_eq!(got.is_some(), expect_hit, "ray {ray:?} triangle {p:?}: reference t={t} u={u} v={v}");
        if let Some(h) = got {
            hits += 1;
            assert!((h.t as f64 - t).abs() <= 1e-4 * t.abs().max(1.0), "t {} vs {t}", h.t);
            assert!((h.u as f64 - u).abs() < 1e-3 && (h.v as f64 - v).abs() < 1e-3, "uv {} {} vs {u} {v}", h.u, h.v);
        }
    }
    assert!(checked > 100_000 && hits > 5_000, "checked {checked}, hits {hits}");
}

#[test]
fn respects_tmax_and_ignores_hits_behind_the_origin() {
    let p = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    let toward = WatertightRay::new(&Ray::new(Vec3::new(0.0, 0.0, -2.0), Vec3::Z));
    assert_eq!(intersect_triangle(&toward, f32::INFINITY, p[0], p[1], p[2]).map(|h| h.t), Some(2.0));
    assert!(intersect_triangle(&toward, 1.999, p[0], p[1], p[2]).is_none());
    assert!(intersect_triangle(&toward, 2.0, p[0], p[1], p[2]).is_some(), "tmax is inclusive");
    let away = WatertightRay::new(&Ray::new(Vec3::new(0.0, 0.0, -2.0), Vec3::NEG_Z));
    assert!(intersect_triangle(&away, f32::INFINITY, p[0], p[1], p[2]).is_none());
}

/// Every ray leaving the inside of a closed mesh hits it, including rays aimed exactly at shared
/// vertices and edge midpoints, and rays along random directions.
#[test]
fn no_ray_slips_through_a_closed_mesh() {
    let (positions, indices) = grid_cube(8);
    let mut rng = TestRng(11);
    let mut origins = vec![Vec3::ZERO, Vec3::new(0.25, -0.5, 0.125)];
    origins.extend((0..6).map(|_| rng.vec3(-0.9, 0.9)));
    let mut targets: Vec<Vec3> = positions.clone();
    for t in &indices {
        for k in 0..3 {
            targets.push(0.5 * (positions[t[k] as usize] + positions[t[(k + 1) % 3] as usize]));
        }
    }
    let mut rays = 0;
    for &origin in &origins {
        let directions = targets.iter().map(|&t| t - origin).chain((0..2000).map(|_| rng.direction()));
        for dir in directions.collect::<Vec<_>>() {
            let ray = WatertightRay::new(&Ray::new(origin, dir));
            let hit = indices.iter().any(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                intersect_triangle(&ray, f32::INFINITY, a, b, c).is_some()
            });
            assert!(hit, "ray from {origin:?} along {dir:?} escaped the closed cube");
            rays += 1;
        }
    }
    assert!(rays > 20_000);
}

/// A long wall (1 x 20000) hit at distance ~2: its vertex depths (~1e4) dwarf the hit distance, so
/// the f32 distance cancels; the test must still find every hit, checked against an exact answer.
#[test]
fn long_slivers_far_beyond_the_hit_are_still_hit() {
    let far = 1.0e4f32;
    let p = [Vec3::new(1.0, 0.0, -far), Vec3::new(1.0, 1.0, -far), Vec3::new(1.0, 1.0, far), Vec3::new(1.0, 0.0, far)];
    let mut rng = TestRng(3);
    let mut checked = 0;
    for _ in 0..200_000 {
        let dir = rng.direction();
        let origin = Vec3::new(0.0, 1.0e-5, 0.0);
        // Exact answer: the plane x = 1 is reached at t = 1/dx, inside the wall if 0 <= y <= 1.
        let t = (1.0 - origin.x as f64) / dir.x as f64;
        let y = origin.y as f64 + t * dir.y as f64;
        let clearly_inside = dir.x > 0.01 && (0.01..0.99).contains(&y) && (t * dir.z as f64).abs() < 1e3;
        let clearly_outside = dir.x < 0.0 || !(-0.01..1.01).contains(&y);
        if !(clearly_inside || clearly_outside) {
            continue;
        }
        let ray = WatertightRay::new(&Ray::new(origin, dir));
        let hits: Vec<f32> = [(p[0], p[1], p[2]), (p[0], p[2], p[3])]
            .iter()
            .filter_map(|&(a, b, c)| intersect_triangle(&ray, f32::INFINITY, a, b, c))
            .map(|h| h.t)
            .collect();
        assert_eq!(!hits.is_empty(), clearly_inside, "dir {dir:?}: exact t {t}, y {y}, got {hits:?}");
        // f32 is kept where its estimated error is below 1/64 of t: on this extreme sliver the
        // distance is good to ~1e-3 (the point of the test is that no hit is lost).
        if let Some(&got) = hits.first() {
            assert!((got as f64 - t).abs() < 2e-3 * t, "t {got} vs {t}");
        }
        checked += 1;
    }
    assert!(checked > 100_000);
}

/// A ray through the shared diagonal of a large quad, where the distance also needs the f64
/// fallback: exactly one of the two triangles must still report the hit.
#[test]
fn shared_edge_of_a_large_quad_is_hit_when_the_distance_falls_back_to_f64() {
    let s = 20.0f32;
    let p = [Vec3::new(-s, 0.0, -s), Vec3::new(-s, 0.0, s), Vec3::new(s, 0.0, s), Vec3::new(s, 0.0, -s)];
    let mut rng = TestRng(9);
    for _ in 0..10_000 {
        let along = rng.range(-0.5, 0.5);
        let target = Vec3::new(along, 0.0, along);
        let eye = Vec3::new(rng.range(-1.0, 1.0), rng.range(0.1, 1.0), rng.range(2.0, 4.0));
        let ray = WatertightRay::new(&Ray::new(eye, target - eye));
        let hits = [(p[0], p[1], p[2]), (p[0], p[2], p[3])]
            .iter()
            .filter(|&&(a, b, c)| intersect_triangle(&ray, f32::INFINITY, a, b, c).is_some())
            .count();
        assert!(hits >= 1, "ray from {eye:?} through the diagonal at {target:?} slipped through");
    }
}

/// A ray exactly through an edge or a corner of a triangle hits it (the test is closed: edge
/// functions of exactly 0 count as inside), whichever corner comes first and for both windings:
/// an axis-aligned ray through a mesh on a grid meets such points, and rejecting them lets it slip
/// between the triangles sharing the edge. At a scale of 1e20 the f32 products overflow and the
/// whole test runs in f64, which must count them too.
#[test]
fn rays_exactly_on_an_edge_or_a_corner_hit() {
    for scale in [1.0, 1e20] {
        let corners =
            [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)].map(|p| p * scale);
        let midpoints = [0, 1, 2].map(|k| 0.5 * (corners[k] + corners[(k + 1) % 3]));
        for target in corners.into_iter().chain(midpoints) {
            for dir in [Vec3::Z, Vec3::NEG_Z] {
                let ray = WatertightRay::new(&Ray::new(target - 2.0 * scale * dir, dir));
                for first in 0..3 {
                    let [a, b, c] = [0, 1, 2].map(|k| corners[(first + k) % 3]);
                    for (a, b, c) in [(a, b, c), (a, c, b)] {
                        let hit = intersect_triangle(&ray, f32::INFINITY, a, b, c);
                        let t = hit.map(|h| h.t / scale);
                        assert_eq!(t, Some(2.0), "ray along {dir} at {target} on ({a}, {b}, {c})");
                    }
                }
            }
        }
    }
}

/// Where an edge function's two f32 products round to the same value, it is decided in f64: the
/// ray below passes 2^-46 (in edge-function units) on one side of the edge shared by two triangles,
/// so exactly the triangle on that side reports it, as exact arithmetic says. Taking the f32 zero
/// as "on the edge" would report both.
#[test]
fn an_edge_function_rounding_to_zero_is_decided_in_f64() {
    let e = f32::EPSILON; // 2^-23
    // Edge b-c: cx * by = -(1 + 2^-22 + 2^-46) rounds to -(1 + 2^-22) = cy * bx.
    let (b, c) = (Vec3::new(-1.0, -(1.0 + e), 0.0), Vec3::new(1.0 + e, 1.0 + 2.0 * e, 0.0));
    let (below, above) = (Vec3::new(1.0, -1.0, 0.0), Vec3::new(-1.0, 1.0, 0.0));
    let ray = WatertightRay::new(&Ray::new(Vec3::new(0.0, 0.0, -1.0), Vec3::Z));
    // In exact arithmetic the origin of the xy plane lies on `above`'s side of the edge.
    let exact = |p: Vec3, q: Vec3| p.x as f64 * q.y as f64 - p.y as f64 * q.x as f64;
    assert!(exact(c, b) < 0.0 && exact(c, b) > -1e-13, "the ray passes a hair from the edge");
    assert!(intersect_triangle(&ray, f32::INFINITY, below, b, c).is_none(), "the triangle on the far side");
    let hit = intersect_triangle(&ray, f32::INFINITY, above, c, b).expect("the triangle on the ray's side");
    assert_eq!(hit.t, 1.0);
}

#[test]
fn the_dominant_axis_is_the_first_of_the_largest_magnitudes() {
    use lumiere::geometry::triangle::dominant_axis;
    let cases = [
        (Vec3::new(3.0, -1.0, 2.0), 0),
        (Vec3::new(-1.0, -3.0, 2.0), 1),
        (Vec3::new(1.0, 2.0, -3.0), 2),
        // Ties go to the first axis, signs do not count.
        (Vec3::new(-2.0, 2.0, 2.0), 0),
        (Vec3::new(0.0, -2.0, 2.0), 1),
        (Vec3::ZERO, 0),
        // Comparisons with NaN are false: a NaN x never wins, a NaN y or z loses to z.
        (Vec3::new(f32::NAN, 1.0, 0.5), 1),
        (Vec3::new(1.0, f32::NAN, 0.5), 2),
    ];
    for (d, axis) in cases {
        assert_eq!(dominant_axis(d), axis, "{d}");
    }
}
