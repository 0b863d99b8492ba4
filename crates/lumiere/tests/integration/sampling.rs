//! Warps, the alias table, the frame and the samplers, checked with the one chi-square harness
//! (`lumiere::sampling::chi2`) and with deterministic properties: pdfs integrate to 1, inverses
//! round-trip, frames are orthonormal, Sobol prefixes are stratified.

use std::f64::consts::PI;

use crate::common::{TestRng, assert_passes, hemisphere_param, sphere_param};
use glam::{DVec3, Vec2, Vec3};
use lumiere::math::Frame;
use lumiere::sampler::{Sampler, SamplerKind};
use lumiere::sampling::chi2::{Chi2Test, chi2_discrete, integrate_unit_square};
use lumiere::sampling::distrib::AliasTable;
use lumiere::sampling::warp::*;

/// Checks a direction warp's output is a unit vector before it is binned.
fn unit(w: Vec3) -> Vec3 {
    assert!((w.length() - 1.0).abs() < 1e-5, "not a unit vector: {w}");
    w
}

/// The uniform values every warp must handle: both ends, the largest f32 below 1, and a grid.
fn edge_and_grid_values() -> Vec<f32> {
    let mut values = vec![0.0, 1.0, 1.0 - f32::EPSILON / 2.0, 1e-7];
    values.extend((0..33).map(|i| i as f32 / 32.0));
    values
}

// ---------------------------------------------------------------------------------------------
// Direction warps

#[test]
fn cosine_hemisphere_chi2() {
    let test = Chi2Test::new(32, 64);
    let result = test.run_warp(
        1_000_000,
        1,
        |u| Some(hemisphere_param(unit(sample_cosine_hemisphere(u)))),
        |p| 2.0 * PI * cosine_hemisphere_pdf(p.x) as f64,
    );
    assert_passes("cosine hemisphere", result);
}

#[test]
fn uniform_hemisphere_chi2() {
    let test = Chi2Test::new(32, 64);
    let result = test.run_warp(
        1_000_000,
        2,
        |u| Some(hemisphere_param(unit(sample_uniform_hemisphere(u)))),
        |p| 2.0 * PI * uniform_hemisphere_pdf(p.x) as f64,
    );
    assert_passes("uniform hemisphere", result);
}

#[test]
fn uniform_sphere_chi2() {
    let test = Chi2Test::new(32, 64);
    let result = test.run_warp(
        1_000_000,
        3,
        |u| Some(sphere_param(unit(sample_uniform_sphere(u)))),
        |_| 4.0 * PI * uniform_sphere_pdf() as f64,
    );
    assert_passes("uniform sphere", result);
}

/// A wrong pdf is rejected with overwhelming confidence, not by luck of the seed.
#[test]
fn harness_rejects_wrong_pdf() {
    let test = Chi2Test { significance: 1e-12, ..Chi2Test::new(32, 64) };
    let result = test.run_warp(
        200_000,
        4,
        |u| Some(hemisphere_param(sample_cosine_hemisphere(u))),
        |p| 2.0 * PI * uniform_hemisphere_pdf(p.x) as f64,
    );
    let report = result.expect_err("the uniform pdf must not pass for cosine-weighted samples");
    assert!(report.contains("p = ") && report.contains("worst cells"), "{report}");
}

/// Samples where the claimed density is 0, or NaN samples, fail at once whatever the statistics.
#[test]
fn harness_rejects_samples_outside_the_support() {
    let test = Chi2Test::new(16, 16);
    let below = test.run_warp(
        10_000,
        5,
        |u| Some(sphere_param(sample_uniform_sphere(u))),
        |p| 4.0 * PI * uniform_hemisphere_pdf(1.0 - 2.0 * p.x) as f64,
    );
    assert!(below.expect_err("lower-hemisphere samples must fail").contains("density is 0"));
    let nan = test.run_warp(10_000, 6, |_| Some(Vec2::NAN), |_| 1.0);
    assert!(nan.expect_err("NaN samples must fail").contains("not finite"));
}

#[test]
fn direction_pdfs_integrate_to_one() {
    let steps = 512;
    let cosine = integrate_unit_square(|p| 2.0 * PI * cosine_hemisphere_pdf(p.x) as f64, steps);
    let hemisphere = integrate_unit_square(|p| 2.0 * PI * uniform_hemisphere_pdf(p.x) as f64, steps);
    let sphere = integrate_unit_square(|_| 4.0 * PI * uniform_sphere_pdf() as f64, steps);
    for (name, integral) in [("cosine", cosine), ("hemisphere", hemisphere), ("sphere", sphere)] {
        assert!((integral - 1.0).abs() < 1e-3, "{name} pdf integrates to {integral}");
    }
    // Below the horizon the hemisphere densities vanish, so they integrate to 1 over the sphere too.
    for cos_theta in [-1.0, -0.5, -1e-6] {
        assert_eq!(cosine_hemisphere_pdf(cos_theta), 0.0);
        assert_eq!(uniform_hemisphere_pdf(cos_theta), 0.0);
    }
}

#[test]
fn direction_warps_round_trip() {
    type Warp = (&'static str, fn(Vec2) -> Vec3, fn(Vec3) -> Vec2);
    let warps: [Warp; 3] = [
        ("cosine", sample_cosine_hemisphere, invert_cosine_hemisphere_sample),
        ("hemisphere", sample_uniform_hemisphere, invert_uniform_hemisphere_sample),
        ("sphere", sample_uniform_sphere, invert_uniform_sphere_sample),
    ];
    let n = 64;
    for (name, sample, invert) in warps {
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let back = invert(sample(u));
                assert!((back - u).abs().max_element() < 1e-4, "{name}: {u} -> {back}");
            }
        }
    }
}

#[test]
fn direction_warps_are_finite_with_positive_pdf_on_edges() {
    let values = edge_and_grid_values();
    for &a in &values {
        for &b in &values {
            let u = Vec2::new(a, b);
            let cosine = sample_cosine_hemisphere(u);
            let hemisphere = sample_uniform_hemisphere(u);
            let sphere = sample_uniform_sphere(u);
            for w in [cosine, hemisphere, sphere] {
                assert!(w.is_finite() && (w.length() - 1.0).abs() < 1e-5, "u {u} -> {w}");
            }
            assert!(hemisphere.z >= 0.0 && cosine.z >= 0.0, "u {u}: below the horizon");
            // Samplers never return u₁ = 1, the one value that reaches the horizon.
            if a < 1.0 {
                assert!(cosine_hemisphere_pdf(cosine.z) > 0.0, "u {u} -> {cosine} has pdf 0");
                assert!(uniform_hemisphere_pdf(hemisphere.z) > 0.0, "u {u} -> {hemisphere} has pdf 0");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Triangle warp

/// Triangles of different shapes: right, obtuse and tilted in 3D, a sliver.
const TRIANGLES: [[Vec3; 3]; 3] = [
    [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
    [Vec3::new(-2.0, 0.0, 1.0), Vec3::new(3.0, 0.5, 1.5), Vec3::new(0.2, 1.0, 0.8)],
    [Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.0, 0.0, 0.0), Vec3::new(2.5, 0.05, 0.0)],
];

fn triangle_area(t: &[Vec3; 3]) -> f64 {
    0.5 * (t[1] - t[0]).as_dvec3().cross((t[2] - t[0]).as_dvec3()).length()
}

/// The barycentrics `(b1, b2)` of a point of the triangle, recovered in f64 by least squares.
fn barycentrics_of(t: &[Vec3; 3], p: Vec3) -> (f64, f64) {
    let (e1, e2, d) = ((t[1] - t[0]).as_dvec3(), (t[2] - t[0]).as_dvec3(), (p - t[0]).as_dvec3());
    let (a11, a12, a22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (r1, r2) = (d.dot(e1), d.dot(e2));
    let det = a11 * a22 - a12 * a12;
    ((r1 * a22 - r2 * a12) / det, (r2 * a11 - r1 * a12) / det)
}

/// A point of the triangle as a point of the square: `(s, t) = (b1 + b2, b2 / (b1 + b2))`, which
/// maps the triangle onto the square without cutting cells (`db1 db2 = s ds dt`).
fn triangle_param(t: &[Vec3; 3], p: Vec3) -> Vec2 {
    let (b1, b2) = barycentrics_of(t, p);
    let s = (b1 + b2).clamp(0.0, 1.0);
    let v = if s > 0.0 { (b2 / (b1 + b2)).clamp(0.0, 1.0) } else { 0.0 };
    Vec2::new(s as f32, v as f32)
}

/// The density on the square of an area-measure pdf: `dA = 2·area·db1 db2 = 2·area·s ds dt`.
fn triangle_density(area: f64, p: Vec2) -> f64 {
    uniform_triangle_pdf(area as f32) as f64 * 2.0 * area * p.x as f64
}

#[test]
fn uniform_triangle_chi2() {
    for (k, tri) in TRIANGLES.iter().enumerate() {
        let area = triangle_area(tri);
        let test = Chi2Test::new(32, 32);
        let result = test.run_warp(
            500_000,
            10 + k as u64,
            |u| {
                let b = sample_uniform_triangle(u);
                Some(triangle_param(tri, b.x * tri[0] + b.y * tri[1] + b.z * tri[2]))
            },
            |p| triangle_density(area, p),
        );
        assert_passes(&format!("uniform triangle {k}"), result);
    }
}

#[test]
fn triangle_pdf_integrates_to_one_and_round_trips() {
    for tri in &TRIANGLES {
        let area = triangle_area(tri);
        let integral = integrate_unit_square(|p| triangle_density(area, p), 256);
        assert!((integral - 1.0).abs() < 1e-3, "triangle pdf integrates to {integral}");
    }
    let n = 64;
    for i in 0..n {
        for j in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let b = sample_uniform_triangle(u);
            let back = invert_uniform_triangle_sample(b);
            assert!((back - u).abs().max_element() < 1e-4, "{u} -> {b} -> {back}");
        }
    }
}

#[test]
fn triangle_barycentrics_are_valid_on_edges() {
    let values = edge_and_grid_values();
    for &a in &values {
        for &c in &values {
            let b = sample_uniform_triangle(Vec2::new(a, c));
            assert!(b.is_finite() && b.min_element() >= -1e-7 && b.max_element() <= 1.0, "{a}, {c} -> {b}");
            assert!((b.x + b.y + b.z - 1.0).abs() < 1e-6, "{a}, {c} -> {b} does not sum to 1");
            assert!(uniform_triangle_pdf(triangle_area(&TRIANGLES[1]) as f32) > 0.0);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Frame

#[test]
fn frame_is_right_handed_orthonormal() {
    let mut rng = TestRng(21);
    let tilt = |v: Vec3| v.normalize();
    let special = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
        tilt(Vec3::new(1e-4, 0.0, -1.0)),
        tilt(Vec3::new(0.0, -1e-7, -1.0)),
        tilt(Vec3::new(1e-3, 1e-3, -1.0)),
        tilt(Vec3::new(-1e-20, 1e-20, -1.0)),
        tilt(Vec3::new(1.0, 1.0, -1e-6)),
    ];
    let normals = special.into_iter().chain((0..100_000).map(|_| rng.direction()));
    for n in normals {
        let f = Frame::from_normal(n);
        let (x, y, z) = (f.x.as_dvec3(), f.y.as_dvec3(), f.z.as_dvec3());
        let errors = [x.dot(y), y.dot(z), z.dot(x), x.length() - 1.0, y.length() - 1.0, z.length() - 1.0];
        assert!(errors.iter().all(|e| e.abs() < 1e-5), "normal {n}: frame {f:?}, errors {errors:?}");
        assert!((x.cross(y) - z).length() < 1e-5, "normal {n}: frame {f:?} is not right-handed");
        assert_eq!(f.z, n);
        let v = Vec3::new(0.3, -0.7, 0.2);
        assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        assert!((f.to_local(n) - Vec3::Z).length() < 1e-5);
    }
}

#[test]
fn cosine_samples_in_a_frame_follow_its_normal() {
    let n = DVec3::new(0.3, -0.5, -0.8).normalize().as_vec3();
    let f = Frame::from_normal(n);
    let w = f.to_world(sample_cosine_hemisphere(Vec2::new(0.0, 0.25)));
    assert!((w - n).length() < 1e-6, "u₁ = 0 is the normal itself");
}

// ---------------------------------------------------------------------------------------------
// Alias table

/// 64 random weights, a quarter of them zero, including the first and the last.
fn weights_with_zeros(seed: u64) -> Vec<f32> {
    let mut rng = TestRng(seed);
    let mut w: Vec<f32> = (0..64).map(|_| if rng.f32() < 0.25 { 0.0 } else { rng.range(0.0, 10.0) }).collect();
    w[0] = 0.0;
    w[63] = 0.0;
    w[17] = 1e-4;
    w
}

fn pmf_of(weights: &[f32]) -> Vec<f64> {
    let sum: f64 = weights.iter().map(|&w| w as f64).sum();
    weights.iter().map(|&w| w as f64 / sum).collect()
}

#[test]
fn alias_table_chi2() {
    for seed in [31, 32] {
        let weights = weights_with_zeros(seed);
        let table = AliasTable::new(&weights).expect("positive weights");
        let mut rng = TestRng(seed + 100);
        let mut counts = vec![0u64; weights.len()];
        for _ in 0..1_000_000 {
            let s = table.sample(rng.f32());
            assert_eq!(s.pmf, table.pmf(s.index));
            counts[s.index] += 1;
        }
        assert_passes(&format!("alias table (weights seed {seed})"), chi2_discrete(&pmf_of(&weights), &counts));
    }
}

/// The remapped number of `sample_remapped` is uniform on [0, 1) whatever item was chosen, and
/// the choice is `sample`'s: (item, remapped number in 16 bins) follows `pmf(item) / 16`. A remap
/// that leaked the choice into the number (or skewed it) fails here.
#[test]
fn alias_table_remapped_number_is_uniform_given_the_choice() {
    const BINS: usize = 16;
    for seed in [35, 36] {
        let weights = weights_with_zeros(seed);
        let table = AliasTable::new(&weights).unwrap();
        let mut rng = TestRng(seed + 200);
        let mut counts = vec![0u64; weights.len() * BINS];
        for _ in 0..2_000_000 {
            let u = rng.f32();
            let (choice, remapped) = table.sample_remapped(u);
            assert_eq!(choice, table.sample(u), "u {u}");
            assert!((0.0..1.0).contains(&remapped), "u {u}: remapped {remapped}");
            counts[choice.index * BINS + (remapped * BINS as f32) as usize] += 1;
        }
        let pmf: Vec<f64> = pmf_of(&weights).iter().flat_map(|&p| [p / BINS as f64; BINS]).collect();
        assert_passes(&format!("alias table remap (weights seed {seed})"), chi2_discrete(&pmf, &counts));
    }
}

#[test]
fn alias_table_pmf_matches_weights_and_u_sweep() {
    let weights = weights_with_zeros(33);
    let table = AliasTable::new(&weights).unwrap();
    let pmf = pmf_of(&weights);
    assert_eq!(table.len(), weights.len());
    for (i, &p) in pmf.iter().enumerate() {
        assert!((table.pmf(i) as f64 - p).abs() <= 1e-6 * p, "pmf {i}: {} vs {p}", table.pmf(i));
    }
    assert!((pmf.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    // A deterministic sweep of u: each item's share of [0, 1) is its probability.
    let m = 1 << 20;
    let mut counts = vec![0usize; weights.len()];
    for k in 0..m {
        counts[table.sample((k as f32 + 0.5) / m as f32).index] += 1;
    }
    for (i, &c) in counts.iter().enumerate() {
        let share = c as f64 / m as f64;
        assert!((share - pmf[i]).abs() < 1e-4, "item {i}: share {share} vs pmf {}", pmf[i]);
        assert!(weights[i] > 0.0 || c == 0, "zero-weight item {i} drawn");
    }
}

#[test]
fn alias_table_edge_u_never_yields_zero_weights() {
    let tables = [weights_with_zeros(34), vec![0.0, 0.0, 5.0, 0.0], vec![1.0, 0.0], vec![0.0, 1.0], vec![2.5]];
    for weights in tables {
        let table = AliasTable::new(&weights).unwrap();
        for u in [0.0, 1e-30, 0.5, 0.99999994, 1.0] {
            let s = table.sample(u);
            assert!(s.index < weights.len() && weights[s.index] > 0.0, "{weights:?}, u {u} -> {s:?}");
            assert!(s.pmf > 0.0);
        }
    }
}

/// A table counts every item, zero-weight ones included, and is never empty: `new` refuses the
/// weights of an empty one, so a caller that checks `is_empty` before sampling always samples.
#[test]
fn alias_table_counts_every_item_and_is_never_empty() {
    for weights in [vec![2.5f32], vec![0.0, 1.0], weights_with_zeros(37)] {
        let table = AliasTable::new(&weights).unwrap();
        assert_eq!(table.len(), weights.len(), "{weights:?}");
        assert!(!table.is_empty(), "{weights:?}: a built table reads as empty");
    }
}

#[test]
fn alias_table_rejects_nothing_to_sample() {
    assert!(AliasTable::new::<f32>(&[]).is_none());
    assert!(AliasTable::new(&[0.0f32, 0.0]).is_none());
    assert!(AliasTable::new(&[1.0f32, -1.0]).is_none());
    assert!(AliasTable::new(&[1.0f32, f32::NAN]).is_none());
    assert!(AliasTable::new(&[1.0f32, f32::INFINITY]).is_none());
    let table = AliasTable::new(&[1.0f64, 3.0]).expect("f64 weights work too");
    assert_eq!((table.pmf(0), table.pmf(1)), (0.25, 0.75));
}

/// With a single item there is no choice to make: all of `u` is left over, and the remapped
/// number is `u` itself, up to the largest `f32` below 1 (the remap is linear on the item's
/// interval, here `[0, 1)`). A clamp tighter than `[0, 1)` would bend the top of the interval.
#[test]
fn alias_table_of_one_item_remaps_u_to_itself() {
    let table = AliasTable::new(&[2.5f32]).unwrap();
    let top = 1.0f32.next_down();
    let us = (0..=1000).map(|k| k as f32 / 1000.0 * top).chain([top, top.next_down(), top.next_down().next_down()]);
    for u in us {
        let (choice, remapped) = table.sample_remapped(u);
        assert_eq!((choice.index, choice.pmf), (0, 1.0));
        assert_eq!(remapped, u, "u {u}");
    }
}

/// `u` = 1, which the closed square of the warps allows, is read in the last bin, and its
/// remapped number stays a number in `[0, 1)`: it was 0 / 0 where the last bin keeps its own item
/// (one item, or a last item heavier than the mean).
#[test]
fn alias_table_reads_u_of_one_in_its_last_bin() {
    for weights in [&[1.0f32][..], &[1.0, 3.0], &[3.0, 1.0], &[1.0, 1.0, 1.0]] {
        let table = AliasTable::new(weights).unwrap();
        let (choice, remapped) = table.sample_remapped(1.0);
        let (last, _) = table.sample_remapped(1.0f32.next_down());
        assert_eq!(choice, last, "{weights:?}");
        assert!((0.0..1.0).contains(&remapped), "{weights:?}: remapped {remapped}");
    }
}

// ---------------------------------------------------------------------------------------------
// Multiple importance sampling

/// The power heuristic is `a² / (a² + b²)` (Veach's β = 2), the weights of the two techniques sum
/// to 1, and the edges its documentation promises hold: 0 for a zero density, even against another
/// zero one (where the ratio is 0/0), 1 for an infinite one, and no overflow for huge densities.
#[test]
fn power_heuristic_matches_its_closed_form_and_edges() {
    use lumiere::sampling::mis::power_heuristic;
    let mut rng = TestRng(131);
    for _ in 0..10_000 {
        let (a, b) = (rng.range(0.0, 10.0), rng.range(0.0, 10.0));
        let (a2, b2) = ((a as f64).powi(2), (b as f64).powi(2));
        let w = power_heuristic(a, b);
        assert!((w as f64 - a2 / (a2 + b2)).abs() < 1e-6, "w({a}, {b}) = {w}");
        assert!((w + power_heuristic(b, a) - 1.0).abs() < 1e-6, "w({a}, {b}) + w({b}, {a})");
    }
    assert_eq!(power_heuristic(0.0, 3.0), 0.0);
    assert_eq!(power_heuristic(0.0, 0.0), 0.0);
    // The guard treats an undefined density as zero too.
    assert_eq!(power_heuristic(f32::NAN, 1.0), 0.0);
    assert_eq!(power_heuristic(f32::INFINITY, 5.0), 1.0);
    assert_eq!(power_heuristic(3.0, f32::INFINITY), 0.0);
    assert_eq!(power_heuristic(1e30, 1e30), 0.5);
    assert_eq!(power_heuristic(1e-30, 1e-30), 0.5);
}

// ---------------------------------------------------------------------------------------------
// Samplers

const KINDS: [SamplerKind; 2] = [SamplerKind::Independent, SamplerKind::Sobol];

#[test]
fn samplers_are_deterministic_and_in_range() {
    let inputs: Vec<(u32, u32, u32)> = (0..5000u32)
        .map(|k| (k.wrapping_mul(2_654_435_761), k % 97, k % 13))
        .chain([(u32::MAX, u32::MAX, u32::MAX), (0, 0, 0), (0, u32::MAX, 0)])
        .collect();
    for kind in KINDS {
        let sampler = Sampler::new(kind, 7);
        let bits = |&(p, i, d): &(u32, u32, u32)| {
            let v = sampler.get_2d(p, i, d);
            (sampler.get_1d(p, i, d).to_bits(), v.x.to_bits(), v.y.to_bits())
        };
        let here: Vec<_> = inputs.iter().map(bits).collect();
        let there: Vec<_> = std::thread::scope(|s| s.spawn(|| inputs.iter().map(bits).collect()).join().unwrap());
        assert_eq!(here, there, "{kind:?}: another thread got other bits");
        for &(a, x, y) in &here {
            assert_eq!(a, x, "{kind:?}: get_1d is get_2d's x");
            for v in [f32::from_bits(x), f32::from_bits(y)] {
                assert!((0.0..1.0).contains(&v), "{kind:?}: {v} outside [0, 1)");
            }
        }
    }
}

#[test]
fn samplers_with_different_seeds_differ() {
    for kind in KINDS {
        let (a, b) = (Sampler::new(kind, 1), Sampler::new(kind, 2));
        let same = (0..1000).filter(|&k| a.get_2d(k, k % 16, 3) == b.get_2d(k, k % 16, 3)).count();
        assert!(same < 3, "{kind:?}: {same} of 1000 points equal across seeds");
    }
}

/// Every elementary interval `2^a × 2^b` with `a + b = k` holds exactly one of the first `2^k`
/// points of a pixel's dimension, and the 1D values fall one per `1/2^k` interval.
#[test]
fn sobol_prefixes_are_stratified() {
    for seed in [0, 1, 0xFFFF_FFFF_FFFF] {
        let sampler = Sampler::new(SamplerKind::Sobol, seed);
        for (pixel, dimension) in [(0, 0), (1, 0), (12_345, 1), (999_999, 7), (u32::MAX, 200)] {
            for k in [4u32, 6, 8] {
                let n = 1u32 << k;
                let points: Vec<Vec2> = (0..n).map(|i| sampler.get_2d(pixel, i, dimension)).collect();
                for a in 0..=k {
                    let (cx, cy) = (1u32 << a, 1u32 << (k - a));
                    let mut hit = vec![false; n as usize];
                    for p in &points {
                        let cell = (p.y * cy as f32) as u32 * cx + (p.x * cx as f32) as u32;
                        assert!(!hit[cell as usize], "seed {seed}, pixel {pixel}, dim {dimension}: {cx}×{cy} twice");
                        hit[cell as usize] = true;
                    }
                }
            }
        }
    }
}

#[test]
fn samplers_are_uniform_in_2d() {
    for kind in KINDS {
        let sampler = Sampler::new(kind, 42);
        let points = (0..4096u32).flat_map(|pixel| (0..64).map(move |i| Some(sampler.get_2d(pixel, i, 3))));
        assert_passes(&format!("{kind:?} 2D over 4096 pixels"), Chi2Test::new(32, 32).run_points(points, |_| 1.0));
    }
}

/// Pairs of values that should be independent — neighbouring pixels, neighbouring dimensions,
/// two seeds — are uniform on the square; correlated streams would pile up on a curve.
#[test]
fn samplers_are_decorrelated() {
    for kind in KINDS {
        let (s, other) = (Sampler::new(kind, 5), Sampler::new(kind, 6));
        for name in ["pixels", "dimensions", "seeds"] {
            let pair = |p: u32, i: u32| {
                let partner = match name {
                    "pixels" => s.get_1d(p + 1, i, 2),
                    "dimensions" => s.get_1d(p, i, 3),
                    _ => other.get_1d(p, i, 2),
                };
                Vec2::new(s.get_1d(p, i, 2), partner)
            };
            let points = (0..8192u32).flat_map(|p| (0..16).map(move |i| (p, i))).map(|(p, i)| Some(pair(p, i)));
            let result = Chi2Test::new(32, 32).run_points(points, |_| 1.0);
            assert_passes(&format!("{kind:?} decorrelated across {name}"), result);
        }
    }
}

/// Every (pixel, sample, dimension) draws its own numbers: among 16 pixels × 16 samples × 16
/// dimensions no 2D point repeats another (48 random bits: a chance repeat among 4096 points is
/// about 3e-8). A key combined with the address by `|` instead of `^` would give every two
/// addresses that differ only in bits the key sets the same numbers.
#[test]
fn no_two_addresses_draw_the_same_numbers() {
    for kind in KINDS {
        for seed in [0, 1, 5, 42] {
            let sampler = Sampler::new(kind, seed);
            let mut seen = std::collections::HashMap::new();
            for (pixel, index, dimension) in
                (0..16u32).flat_map(|p| (0..16u32).flat_map(move |i| (0..16u32).map(move |d| (p, i, d))))
            {
                let v = sampler.get_2d(pixel, index, dimension);
                if let Some(first) = seen.insert((v.x.to_bits(), v.y.to_bits()), (pixel, index, dimension)) {
                    panic!("{kind:?}, seed {seed}: {first:?} and {:?} both draw {v}", (pixel, index, dimension));
                }
            }
        }
    }
}

#[test]
fn fast_sin_cos_matches_libm() {
    use lumiere::sampling::warp::sin_cos_turns;
    let mut worst = 0.0f64;
    for i in 0..=1_000_000u32 {
        let t = i as f32 / 1_000_000.0;
        let (s, c) = sin_cos_turns(t);
        let angle = t as f64 * std::f64::consts::TAU;
        worst = worst.max((s as f64 - angle.sin()).abs()).max((c as f64 - angle.cos()).abs());
    }
    assert!(worst < 3e-7, "worst error {worst}");
}
