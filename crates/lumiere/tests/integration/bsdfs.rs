//! The material lobes (GGX microfacets, Fresnel, conductor and mirror, smooth dielectric, plastic)
//! and the mapping from `Material` to them, checked for what a path tracer relies on: samples
//! follow the claimed pdf over the whole sphere (chi-square, fixed seeds, p-values printed with
//! `--nocapture`), samples carry `eval` and `pdf` of their own direction, pdfs integrate to at most
//! 1, reciprocity, no energy created (white furnace), and known closed forms (Fresnel at normal
//! incidence and Brewster's angle, total internal reflection, an index-1 interface that vanishes).

use std::f64::consts::PI;

use crate::common::{TestRng, assert_passes};
use glam::{DVec3, Vec2, Vec3};
use lumiere::materials::fresnel::{
    dielectric_f0, fresnel_dielectric, fresnel_dielectric_polarised, fresnel_schlick, refracted_cos,
};
use lumiere::materials::microfacet::{Ggx, MAX_ALPHA, MIN_ALPHA, reflect};
use lumiere::materials::{
    Bsdf, BsdfFlags, Conductor, DEFAULT_IOR, Dielectric, Lambert, Material, MaterialBsdf, MaterialKind, Mirror,
    Plastic, alpha_from_ns,
};
use lumiere::math::Frame;
use lumiere::sampling::chi2::{Chi2Test, integrate_unit_square};
use lumiere::scene::Scene;

const ROUGHNESSES: [f32; 3] = [0.05, 0.3, 0.8];

/// Viewing directions: along the normal, oblique (60°) and grazing (87°), off the axes.
fn viewing_directions() -> [(&'static str, Vec3); 3] {
    let at = |theta_deg: f64, phi: f64| {
        let t = theta_deg.to_radians();
        DVec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos()).as_vec3()
    };
    [("normal", Vec3::Z), ("oblique", at(60.0, 0.7)), ("grazing", at(87.0, 2.1))]
}

// ---------------------------------------------------------------------------------------------
// The whole sphere as the parameter square.
//
// `y = φ/2π`; `x` maps to the polar angle by `θ = (π/2)(1 + t|t|)`, `t = 2x − 1`. Its derivative
// vanishes at the horizon (`x = ½`, a cell edge for an even number of cells), so the density on
// the square, `pdf · sin θ · dθ/dx · 2π`, is continuous there even for lobes whose pdf jumps to 0
// below the horizon (GGX's does): Simpson's rule, which evaluates the density at cell edges, would
// otherwise assign half of that jump to the wrong cells. Near the poles `θ ≈ 2πx`: cells are
// narrow in angle where narrow lobes sit at normal incidence.

fn sphere_point(w: Vec3) -> Vec2 {
    let theta = (w.z as f64).clamp(-1.0, 1.0).acos();
    let s = 2.0 * theta / PI - 1.0;
    let t = s.signum() * s.abs().sqrt();
    let phi = (w.y as f64).atan2(w.x as f64).rem_euclid(2.0 * PI) / (2.0 * PI);
    Vec2::new(off_the_pole((0.5 * (t + 1.0)) as f32), (phi as f32).min(1.0))
}

/// Moves `x = 0` (the pole, where the Jacobian and so the density on the square are 0) by 1e-7:
/// a sample exactly on the axis (`u = 0` in most warps) is legitimate, and the harness would take
/// it for one drawn where the density vanishes.
fn off_the_pole(x: f32) -> f32 {
    x.max(1e-7)
}

/// The direction at a point of the square, and the Jacobian `dω / (dx dy)` there.
fn sphere_direction(p: Vec2) -> (Vec3, f64) {
    let t = 2.0 * p.x as f64 - 1.0;
    let theta = 0.5 * PI * (1.0 + t * t.abs());
    let phi = 2.0 * PI * p.y as f64;
    let w = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
    let jacobian = theta.sin() * (2.0 * PI * t.abs()) * (2.0 * PI);
    (w.as_vec3(), jacobian)
}

/// Chi-square test of a lobe's `sample` against its `pdf` over the whole sphere, for one `wo`.
/// `integration_steps` per cell and axis must resolve the lobe: a sharp lobe at a grazing angle
/// spans a fraction of one cell, where too coarse a rule misjudges the expected counts by percents.
fn lobe_chi2(bsdf: &impl Bsdf, wo: Vec3, seed: u64, integration_steps: usize) -> Result<f64, String> {
    let test = Chi2Test { integration_steps, ..Chi2Test::new(64, 64) };
    test.run_warp(
        1_000_000,
        seed,
        |u| bsdf.sample(wo, u).map(|s| sphere_point(s.wi)),
        |p| {
            let (wi, jacobian) = sphere_direction(p);
            bsdf.pdf(wo, wi) as f64 * jacobian
        },
    )
}

/// `∫ g(ω) dω` over the sphere by Simpson's rule in polar coordinates around `axis`, with the
/// polar angle `θ = π x²`: dense near the axis, where the lobes under test peak.
fn integrate_sphere(axis: Vec3, g: impl Fn(Vec3) -> f64, steps: usize) -> f64 {
    let frame = Frame::from_normal(axis.normalize());
    integrate_unit_square(
        |p| {
            let x = p.x as f64;
            let theta = PI * x * x;
            let phi = 2.0 * PI * p.y as f64;
            let local = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            g(frame.to_world(local.as_vec3())) * theta.sin() * (2.0 * PI * x) * (2.0 * PI)
        },
        steps,
    )
}

/// The mirror direction of `wo`, where reflection lobes peak.
fn mirrored(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

/// The non-delta lobes under test, by name: Lambert, and conductor and plastic at each roughness.
fn glossy_lobes() -> Vec<(String, MaterialBsdf)> {
    let mut lobes = vec![("lambert".to_string(), MaterialBsdf::Lambert(Lambert { reflectance: Vec3::splat(0.7) }))];
    for alpha in ROUGHNESSES {
        lobes.push((
            format!("conductor α {alpha}"),
            MaterialBsdf::Conductor(Conductor::new(Vec3::new(0.9, 0.6, 0.3), alpha)),
        ));
        lobes.push((
            format!("plastic α {alpha}"),
            MaterialBsdf::Plastic(Plastic::new(Vec3::new(0.7, 0.5, 0.3), Vec3::splat(0.25), alpha)),
        ));
    }
    lobes
}

// ---------------------------------------------------------------------------------------------
// GGX

/// `Ggx::new` keeps a roughness in [`MIN_ALPHA`, `MAX_ALPHA`] exactly and clamps the rest to the
/// nearer end, a NaN to the roughest, as it documents; `alpha()` reports the roughness kept. The
/// lobe tests read `alpha()` only to choose integration steps and, in the slow
/// `pdfs_integrate_to_at_most_one`, the expected `∫ pdf`: an `alpha()` returning a constant passed
/// every other fast test.
#[test]
fn ggx_keeps_its_roughness_within_range_and_clamps_the_rest() {
    for alpha in [MIN_ALPHA, 0.05, 0.3, 0.8, MAX_ALPHA] {
        assert_eq!(Ggx::new(alpha).alpha(), alpha, "α {alpha} is in range");
    }
    let clamped = [
        (0.0, MIN_ALPHA),
        (-0.5, MIN_ALPHA),
        (MIN_ALPHA.next_down(), MIN_ALPHA),
        (f32::NEG_INFINITY, MIN_ALPHA),
        (MAX_ALPHA.next_up(), MAX_ALPHA),
        (4.0, MAX_ALPHA),
        (f32::INFINITY, MAX_ALPHA),
        (f32::NAN, MAX_ALPHA),
    ];
    for (given, kept) in clamped {
        assert_eq!(Ggx::new(given).alpha(), kept, "α {given}");
        assert_eq!(Ggx::new(given), Ggx::new(kept), "α {given}");
    }
}

/// `∫ D(m) cos θm dωm = 1`: the projected microfacet area equals the macro-surface's. Integrated
/// in `θ` through `tan θ = α tan(πx/2)`, which spreads the peak of small `α` over the interval.
#[test]
fn ggx_d_is_normalised_over_projected_area() {
    for alpha in [MIN_ALPHA, 0.01, 0.05, 0.3, 0.8, 1.0] {
        let ggx = Ggx::new(alpha);
        let a = ggx.alpha() as f64;
        let integral = integrate_unit_square(
            |p| {
                let (theta, dtheta) = stretched_polar(p.x as f64, a);
                let phi = 2.0 * PI * p.y as f64;
                let m = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()).as_vec3();
                ggx.d(m) as f64 * theta.cos() * theta.sin() * dtheta * 2.0 * PI
            },
            2048,
        );
        assert!((integral - 1.0).abs() < 1e-3, "α {alpha}: ∫ D cos = {integral}");
    }
}

/// `θ = atan(α tan(πx/2))` and `dθ/dx`, written so that `x = 1` (the horizon) stays finite.
fn stretched_polar(x: f64, alpha: f64) -> (f64, f64) {
    let (s, c) = (0.5 * PI * x).sin_cos();
    let theta = (alpha * s).atan2(c);
    let dtheta = alpha * 0.5 * PI / (c * c + alpha * alpha * s * s);
    (theta, dtheta)
}

/// The inverse of [`stretched_polar`] for a microfacet normal, with `φ/2π`.
fn stretched_point(m: Vec3, alpha: f64) -> Vec2 {
    let theta = (m.z as f64).clamp(-1.0, 1.0).acos();
    let x = (theta.tan() / alpha).atan() / (0.5 * PI);
    let phi = (m.y as f64).atan2(m.x as f64).rem_euclid(2.0 * PI) / (2.0 * PI);
    Vec2::new(off_the_pole(x as f32), (phi as f32).min(1.0))
}

/// `∫ D_ωo(m) dωm = 1`: Smith's `Λ` is consistent with `D` (Heitz 2014, eq. 6), for viewing
/// directions from the normal to near the horizon.
#[test]
fn visible_normal_pdf_integrates_to_one() {
    for alpha in [0.01, 0.05, 0.3, 0.8, 1.0] {
        let ggx = Ggx::new(alpha);
        for (name, wo) in viewing_directions() {
            let integral = integrate_unit_square(
                |p| {
                    let (theta, dtheta) = stretched_polar(p.x as f64, alpha as f64);
                    let phi = 2.0 * PI * p.y as f64;
                    let m = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()).as_vec3();
                    ggx.visible_normal_pdf(wo, m) as f64 * theta.sin() * dtheta * 2.0 * PI
                },
                1024,
            );
            assert!((integral - 1.0).abs() < 3e-3, "α {alpha}, wo {name}: ∫ D_wo = {integral}");
        }
    }
}

/// Heitz's sampler draws visible normals with the density `D_ωo` claims, for each roughness and
/// viewing direction (chi-square in the stretched polar coordinates of the distribution).
#[test]
fn visible_normal_samples_follow_their_pdf() {
    for (i, alpha) in ROUGHNESSES.into_iter().enumerate() {
        let ggx = Ggx::new(alpha);
        for (j, (name, wo)) in viewing_directions().into_iter().enumerate() {
            let result = Chi2Test::new(32, 64).run_warp(
                1_000_000,
                100 + 10 * i as u64 + j as u64,
                |u| {
                    let m = ggx.sample_visible_normal(wo, u);
                    assert!((m.length() - 1.0).abs() < 1e-5 && m.z >= 0.0, "normal {m}");
                    Some(stretched_point(m, alpha as f64))
                },
                |p| {
                    let (theta, dtheta) = stretched_polar(p.x as f64, alpha as f64);
                    let phi = 2.0 * PI * p.y as f64;
                    let m = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()).as_vec3();
                    ggx.visible_normal_pdf(wo, m) as f64 * theta.sin() * dtheta * 2.0 * PI
                },
            );
            assert_passes(&format!("GGX visible normals, α {alpha}, wo {name}"), result);
        }
    }
}

/// The harness has the power to catch the classic mistake: visible-normal samples checked against
/// the pdf of plain normal sampling, `D(m) cos θm`, fail clearly for an oblique view.
#[test]
fn visible_normals_checked_against_the_wrong_pdf_fail() {
    let ggx = Ggx::new(0.3);
    let wo = viewing_directions()[1].1;
    let result = Chi2Test::new(32, 64).run_warp(
        200_000,
        7,
        |u| Some(stretched_point(ggx.sample_visible_normal(wo, u), 0.3)),
        |p| {
            let (theta, dtheta) = stretched_polar(p.x as f64, 0.3);
            let phi = 2.0 * PI * p.y as f64;
            let m = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()).as_vec3();
            (ggx.d(m) * m.z) as f64 * theta.sin() * dtheta * 2.0 * PI
        },
    );
    let report = result.expect_err("D cos θ is not the density of visible normals");
    println!("wrong pdf rejected: {}", report.lines().next().unwrap_or_default());
}

/// `invert_visible_normal_sample` undoes `sample_visible_normal`.
#[test]
fn visible_normal_sampling_round_trips() {
    let mut rng = TestRng(21);
    for alpha in [0.01, 0.05, 0.3, 0.8] {
        let ggx = Ggx::new(alpha);
        for _ in 0..20_000 {
            let wo = rng.direction();
            let wo = Vec3::new(wo.x, wo.y, wo.z.abs().max(0.05)).normalize();
            let u = Vec2::new(rng.range(0.001, 0.999), rng.range(0.001, 0.999));
            let m = ggx.sample_visible_normal(wo, u);
            let back = ggx.invert_visible_normal_sample(wo, m);
            let mut d = (back - u).abs();
            d.y = d.y.min(1.0 - d.y);
            // Azimuth is ill-conditioned at the disk's centre.
            let tolerance = if u.x < 1e-3 { 1e-1 } else { 2e-3 };
            assert!(d.max_element() < tolerance, "α {alpha}, wo {wo}, u {u} → m {m} → {back}");
        }
    }
}

/// GGX's Smith `Λ(ω)` for `α² = a2`, in f64 from its closed form.
fn ggx_lambda(a2: f64, w: DVec3) -> f64 {
    ((1.0 + a2 * (w.x * w.x + w.y * w.y) / (w.z * w.z)).sqrt() - 1.0) / 2.0
}

/// GGX's distribution of normals `D(m)` for `α² = a2`, in f64 from its closed form.
fn ggx_d(a2: f64, m: DVec3) -> f64 {
    let k = m.z * m.z + (m.x * m.x + m.y * m.y) / a2;
    1.0 / (PI * a2 * k * k)
}

/// A direction above the surface, at least 3° off the horizon (where f32 and f64 part ways).
fn upper_direction(rng: &mut TestRng) -> Vec3 {
    let w = rng.direction();
    Vec3::new(w.x, w.y, w.z.abs().max(0.05)).normalize()
}

/// Smith's terms against their closed forms, evaluated in f64 from the angles alone:
/// `Λ = (√(1 + α² tan²θ) − 1) / 2`, `G1 = 1 / (1 + Λ)`, `G2 = 1 / (1 + Λo + Λi)` (symmetric to the
/// last bit, between the separable `G1 G1` and the smaller `G1`), and `reflection()`'s value and
/// pdf against `D(h) G2 / (4 cos θo cos θi)` and `G1(ωo) D(h) / (4 cos θo)`. The sampling tests
/// cannot see a wrong value: a lobe samples its own pdf whatever `f` it returns, the white furnace
/// only bounds the albedo, and `g2` lies on no sampling path at all.
#[test]
fn smith_terms_and_reflection_values_match_their_closed_forms() {
    let mut rng = TestRng(111);
    for alpha in [0.05f64, 0.3, 0.8] {
        let ggx = Ggx::new(alpha as f32);
        let a2 = alpha * alpha;
        let (lambda, d) = (|w| ggx_lambda(a2, w), |m| ggx_d(a2, m));
        let close = |got: f32, expected: f64, what: &str| {
            assert!(
                (got as f64 - expected).abs() <= 2e-4 * expected.abs(),
                "α {alpha}: {what} = {got}, expected {expected}"
            );
        };
        for _ in 0..5000 {
            let (wo, wi) = (upper_direction(&mut rng), upper_direction(&mut rng));
            let (o, i) = (wo.as_dvec3(), wi.as_dvec3());
            let (lambda_o, lambda_i) = (lambda(o), lambda(i));
            close(ggx.lambda(wo), lambda_o, "Λ(ωo)");
            close(ggx.g1(wo), 1.0 / (1.0 + lambda_o), "G1(ωo)");
            let g2_exact = 1.0 / (1.0 + lambda_o + lambda_i);
            close(ggx.g2(wo, wi), g2_exact, "G2");
            assert_eq!(ggx.g2(wo, wi), ggx.g2(wi, wo), "G2 is symmetric");
            let (g1_o, g1_i, g2) = (ggx.g1(wo), ggx.g1(wi), ggx.g2(wo, wi));
            assert!(
                g2 >= g1_o * g1_i * (1.0 - 1e-6) && g2 <= g1_o.min(g1_i) * (1.0 + 1e-6),
                "G2 {g2}, G1 {g1_o} {g1_i}"
            );
            let h = (o + i).normalize();
            let r = ggx.reflection(wo, wi).expect("both above the surface");
            close(r.value, d(h) * g2_exact / (4.0 * o.z * i.z), "D G2 / (4 cos θo cos θi)");
            close(r.pdf, d(h) / ((1.0 + lambda_o) * 4.0 * o.z), "G1(ωo) D / (4 cos θo)");
        }
    }
}

/// Each lobe's `eval` and `pdf` against its documented closed form, evaluated in f64 from the
/// directions alone: Lambert's `kd / π` and `cos θi / π`; the conductor's
/// `F(ωo·h) D(h) G2 / (4 cos θo cos θi)` with Schlick's `F = F0 + (1 − F0)(1 − ωo·h)⁵`, and
/// `G1(ωo) D(h) / (4 cos θo)`; the plastic's `ks D G2 / (4 cos θo cos θi) + (1 − max ks) kd / π` and
/// its mixture pdf. The lobes' samples carry their own `eval` and `pdf` (so the chi-square tests
/// pass whatever value a lobe returns), the white furnace only bounds the albedo from above, and
/// `smith_terms_and_reflection_values_match_their_closed_forms` stops at `reflection()`: a
/// conductor, or either lobe of the plastic, 3% too dark, and Schlick's term with exponent 4
/// instead of 5, passed every other test.
#[test]
fn lobe_values_and_pdfs_match_their_closed_forms() {
    let mut rng = TestRng(112);
    let (kd, ks, f0) = (DVec3::new(0.7, 0.5, 0.3), DVec3::new(0.3, 0.2, 0.1), DVec3::new(0.9, 0.6, 0.3));
    let close = |got: Vec3, expected: DVec3, what: &str| {
        for c in 0..3 {
            assert!(
                (got[c] as f64 - expected[c]).abs() <= 2e-4 * expected[c].abs() + 1e-30,
                "{what}: channel {c} = {got}, expected {expected}"
            );
        }
    };
    let lambert = Lambert { reflectance: kd.as_vec3() };
    for alpha in [0.05f64, 0.3, 0.8] {
        let a2 = alpha * alpha;
        let (lambda, d) = (|w| ggx_lambda(a2, w), |m| ggx_d(a2, m));
        let conductor = Conductor::new(f0.as_vec3(), alpha as f32);
        let plastic = Plastic::new(kd.as_vec3(), ks.as_vec3(), alpha as f32);
        let diffuse = kd * (1.0 - ks.max_element());
        let specular_probability = ks.element_sum() / (ks.element_sum() + diffuse.element_sum());
        for _ in 0..5000 {
            let (wo, wi) = (upper_direction(&mut rng), upper_direction(&mut rng));
            let (o, i) = (wo.as_dvec3(), wi.as_dvec3());
            let h = (o + i).normalize();
            let mirror = d(h) / ((1.0 + lambda(o) + lambda(i)) * 4.0 * o.z * i.z);
            let mirror_pdf = d(h) / ((1.0 + lambda(o)) * 4.0 * o.z);
            let schlick = f0 + (DVec3::ONE - f0) * (1.0 - o.dot(h)).powi(5);
            let context = format!("α {alpha}, wo {wo}, wi {wi}");
            close(conductor.eval(wo, wi), schlick * mirror, &format!("conductor f, {context}"));
            close(Vec3::splat(conductor.pdf(wo, wi)), DVec3::splat(mirror_pdf), &format!("conductor pdf, {context}"));
            close(plastic.eval(wo, wi), ks * mirror + diffuse / PI, &format!("plastic f, {context}"));
            let plastic_pdf = specular_probability * mirror_pdf + (1.0 - specular_probability) * i.z / PI;
            close(Vec3::splat(plastic.pdf(wo, wi)), DVec3::splat(plastic_pdf), &format!("plastic pdf, {context}"));
            if alpha == 0.3 {
                close(lambert.eval(wo, wi), kd / PI, &format!("lambert f, {context}"));
                close(Vec3::splat(lambert.pdf(wo, wi)), DVec3::splat(i.z / PI), &format!("lambert pdf, {context}"));
            }
        }
    }
}

/// `reflection()` is `None` unless both directions lie above the surface, as it documents, for
/// the two pairs its sign tests alone would let through: both directions below (their half vector
/// is below too, where `D` is 0), and two directions above the surface whose cosines multiply to 0
/// in `f32` (1e-25 each), where `Λ` is infinite and the value `D G2 / (4 cos θo cos θi)` would be
/// `D / (∞ · 0)`, NaN.
#[test]
fn ggx_reflection_is_none_below_and_where_the_cosine_product_underflows() {
    let grazing = [Vec3::new(1.0, 0.0, 1e-25), Vec3::new(-0.6, 0.8, 1e-25)];
    assert!(grazing[0].z > 0.0 && grazing[1].z > 0.0 && grazing[0].z * grazing[1].z == 0.0);
    let below = [Vec3::new(0.3, -0.4, -0.866_025_4), Vec3::NEG_Z, Vec3::new(-0.6, 0.0, -0.8)];
    for alpha in ROUGHNESSES {
        let ggx = Ggx::new(alpha);
        assert_eq!(ggx.reflection(grazing[0], grazing[1]), None, "α {alpha}: cosines underflow");
        for a in below {
            for b in below {
                assert_eq!(ggx.reflection(a, b), None, "α {alpha}: {a} and {b} below");
            }
            assert_eq!(ggx.reflection(a, Vec3::Z), None, "α {alpha}: wo {a} below");
            assert_eq!(ggx.reflection(Vec3::Z, a), None, "α {alpha}: wi {a} below");
        }
    }
}

/// A view within 1e-19 of the normal samples the lobe of normal incidence. At normal incidence
/// (`u` read as the disk point `r = √u₁`), the sampled normal is the unstretched
/// `(α p, √(1 − u₁))`, so `cos θm = √(1 − u₁) / √(α² u₁ + 1 − u₁)` whatever `u₂`; a view tilted by
/// at most 1e-19 rad has that distribution to `f32` precision. The horizontal frame vector around
/// such a view was divided by the square root of a subnormal `|vh.xy|²`, which keeps only a few
/// bits, and came out of length 0.8 to 1.01 instead of 1, squashing or widening the lobe.
#[test]
fn visible_normals_next_to_normal_incidence_keep_the_lobe_of_normal_incidence() {
    let mut worst = 0.0f64;
    for alpha in ROUGHNESSES {
        let ggx = Ggx::new(alpha);
        let a2 = (alpha as f64).powi(2);
        for tilt in [1e-22f32, 3e-22, 1e-21, 3e-21, 1e-20, 1e-19] {
            let wo = Vec3::new(tilt, 0.5 * tilt, 1.0);
            assert_eq!(wo.length(), 1.0);
            for i in 0..16 {
                for j in 0..16 {
                    let u = Vec2::new((i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0);
                    let m = ggx.sample_visible_normal(wo, u);
                    let u1 = u.x as f64;
                    let expected = (1.0 - u1).sqrt() / (a2 * u1 + 1.0 - u1).sqrt();
                    worst = worst.max((m.z as f64 - expected).abs());
                    assert!(
                        (m.z as f64 - expected).abs() < 1e-5 && (m.length() - 1.0).abs() < 1e-5,
                        "α {alpha}, wo {wo}, u {u}: m {m}, expected cos θm {expected}"
                    );
                }
            }
        }
    }
    println!("worst |cos θm − expected|: {worst:e}");
}

// ---------------------------------------------------------------------------------------------
// Sampling agrees with pdf

/// `sample` draws with the density `pdf` claims, over the whole sphere (a sample below the surface
/// fails at once, since the density is 0 there), for every non-delta lobe, three roughnesses and
/// three viewing directions.
#[test]
fn lobe_samples_follow_their_pdf_over_the_sphere() {
    for (i, (name, bsdf)) in glossy_lobes().into_iter().enumerate() {
        for (j, (view, wo)) in viewing_directions().into_iter().enumerate() {
            let sharp = matches!(bsdf, MaterialBsdf::Conductor(c) if c.distribution.alpha() < 0.1)
                || matches!(bsdf, MaterialBsdf::Plastic(p) if p.distribution().alpha() < 0.1);
            let steps = if sharp { 64 } else { 16 };
            let result = lobe_chi2(&bsdf, wo, 1000 + 10 * i as u64 + j as u64, steps);
            assert_passes(&format!("{name}, wo {view}"), result);
        }
    }
}

/// A plastic that is mostly specular and one that is mostly diffuse, both rough and sharp: the
/// mixture's lobe choice agrees with its pdf whatever the weights.
#[test]
fn plastic_mixtures_follow_their_pdf() {
    let cases = [
        ("black base, white coat", Vec3::ZERO, Vec3::ONE, 0.3),
        ("white base, 4% coat", Vec3::ONE, Vec3::splat(0.04), 0.05),
        ("coloured coat", Vec3::new(0.2, 0.6, 0.1), Vec3::new(0.5, 0.1, 0.05), 0.8),
    ];
    for (i, (name, kd, ks, alpha)) in cases.into_iter().enumerate() {
        let bsdf = Plastic::new(kd, ks, alpha);
        let wo = viewing_directions()[1].1;
        assert_passes(&format!("plastic, {name}"), lobe_chi2(&bsdf, wo, 2000 + i as u64, 64));
    }
}

/// The plastic picks its specular lobe with the probability its documentation gives, the mean of
/// `ks` over the sum of the means of `ks` and of the scaled `kd`, and its diffuse lobe otherwise.
/// The mixture tests cannot see the choice: a plastic that picked its lobes in other proportions
/// would still sample the mixture density it claims, and only its variance would suffer. At normal
/// incidence a fraction `α² / (1 + α²)` of the specular samples falls below the horizon and is
/// rejected (see `pdfs_integrate_to_at_most_one`), so samples come in three kinds, counted by flags.
#[test]
fn plastic_picks_its_lobes_in_proportion_to_their_albedo_estimates() {
    let (kd, ks, alpha) = (Vec3::new(0.7, 0.5, 0.3), Vec3::new(0.3, 0.1, 0.05), 0.3f64);
    let plastic = Plastic::new(kd, ks, alpha as f32);
    let mean = |v: Vec3| (v.x as f64 + v.y as f64 + v.z as f64) / 3.0;
    let specular = mean(ks) / (mean(ks) + mean(kd * (1.0 - ks.max_element())));
    assert!((plastic.specular_probability() as f64 - specular).abs() < 1e-6, "{}", plastic.specular_probability());
    let kept = 1.0 / (1.0 + alpha * alpha);
    let expected = [specular * kept, 1.0 - specular, specular * (1.0 - kept)];
    let mut rng = TestRng(121);
    let mut counts = [0u64; 3];
    for _ in 0..200_000 {
        let kind = match plastic.sample(Vec3::Z, Vec2::new(rng.f32(), rng.f32())) {
            Some(s) if s.flags.contains(BsdfFlags::GLOSSY) => 0,
            Some(s) => {
                assert!(s.flags.contains(BsdfFlags::DIFFUSE), "{s:?}");
                1
            }
            None => 2,
        };
        counts[kind] += 1;
    }
    assert_passes("plastic lobe choice", lumiere::sampling::chi2::chi2_discrete(&expected, &counts));
}

/// A plastic samples wherever it reflects light, and only there: a black one (no base, no coat)
/// gives no sample at all (a sample of weight 0 would only cost the integrator a ray), a plastic
/// that is all base gives a diffuse sample for every `u`, and one that is all coat only glossy
/// samples, with positive pdfs. The other plastics under test have both lobes, where a wrong
/// test of the lobe probability or of the base colour goes unseen.
#[test]
fn plastic_samples_where_it_reflects_and_only_there() {
    let wo = viewing_directions()[1].1;
    let black = Plastic::new(Vec3::ZERO, Vec3::ZERO, 0.3);
    let base_only = Plastic::new(Vec3::new(0.7, 0.5, 0.3), Vec3::ZERO, 0.3);
    let coat_only = Plastic::new(Vec3::ZERO, Vec3::splat(0.5), 0.3);
    let mut glossy = 0;
    for i in 0..16 {
        for j in 0..16 {
            let u = Vec2::new((i as f32 + 0.5) / 16.0, (j as f32 + 0.5) / 16.0);
            assert_eq!(black.sample(wo, u), None, "black plastic, u {u}");
            let s = base_only.sample(wo, u).unwrap_or_else(|| panic!("base only, u {u}: no sample"));
            assert!(s.flags.contains(BsdfFlags::DIFFUSE) && s.pdf > 0.0, "base only, u {u}: {s:?}");
            if let Some(s) = coat_only.sample(wo, u) {
                assert!(s.flags.contains(BsdfFlags::GLOSSY) && s.pdf > 0.0, "coat only, u {u}: {s:?}");
                glossy += 1;
            }
        }
    }
    // At 60° with α 0.3, few reflected microfacet normals fall below the horizon.
    assert!(glossy > 200, "coat only: {glossy} samples of 256");
}

/// `1 − 2⁻²⁴`, the largest `f32` below 1 (a uniform a sampler may deliver), still gives a diffuse
/// direction. Remapped onto the diffuse lobe's share, `(u − p) / (1 − p)` rounds up to exactly 1
/// for many specular probabilities `p` (0.0325, 0.044, …), and a cosine-weighted direction drawn at
/// 1 lies in the horizon, where the pdf is 0: the remapped value must stay below 1.
#[test]
fn plastic_keeps_the_largest_uniform_below_one_in_its_diffuse_lobe() {
    let u = Vec2::new(1.0f32.next_down(), 0.5);
    for k in 1..=200 {
        let plastic = Plastic::new(Vec3::ONE, Vec3::splat(k as f32 / 400.0), 0.3);
        let s = plastic.sample(Vec3::Z, u).unwrap_or_else(|| panic!("p {}: no sample", plastic.specular_probability()));
        assert!(
            s.flags.contains(BsdfFlags::DIFFUSE) && s.wi.z > 0.0 && s.pdf > 0.0,
            "p {}: {s:?}",
            plastic.specular_probability()
        );
    }
}

/// Every sample carries exactly `eval` and `pdf` of its direction, with flags that say what it is;
/// opaque lobes give nothing for `wo` below the surface, and nothing there evaluates.
#[test]
fn samples_carry_eval_and_pdf_of_their_direction() {
    let mut rng = TestRng(31);
    for (name, bsdf) in glossy_lobes() {
        for _ in 0..20_000 {
            let wo = rng.direction();
            let u = Vec2::new(rng.f32(), rng.f32());
            let Some(s) = bsdf.sample(wo, u) else {
                continue;
            };
            assert!(wo.z > 0.0, "{name}: a sample for wo {wo} below the surface");
            assert!(s.wi.z > 0.0 && (s.wi.length() - 1.0).abs() < 1e-5, "{name}: wi {}", s.wi);
            assert_eq!(s.f, bsdf.eval(wo, s.wi), "{name}: f of wo {wo}, wi {}", s.wi);
            assert_eq!(s.pdf, bsdf.pdf(wo, s.wi), "{name}: pdf of wo {wo}, wi {}", s.wi);
            assert!(s.pdf > 0.0 && s.pdf.is_finite() && s.f.is_finite());
            assert!(s.flags.contains(BsdfFlags::REFLECTION) && !s.flags.contains(BsdfFlags::SPECULAR));
            assert!(s.flags.contains(BsdfFlags::DIFFUSE) || s.flags.contains(BsdfFlags::GLOSSY));
        }
        for _ in 0..2000 {
            let (a, b) = (rng.direction(), rng.direction());
            if a.z <= 0.0 || b.z <= 0.0 {
                assert_eq!((bsdf.eval(a, b), bsdf.pdf(a, b)), (Vec3::ZERO, 0.0), "{name}: {a} {b}");
            }
        }
    }
}

/// A direction in the surface's plane (`z = ±0`) is not above it, and every opaque lobe gives it
/// nothing: as `wo`, where `sample` has no direction for it, and as `wi`, where
/// `Bsdf::lambertian_eval` promises `eval` is 0 (light sampling evaluates a diffuse surface's light
/// points without calling `eval`). Random directions never lie exactly in the plane, so the other
/// tests cannot see a lobe that counts `z = 0` as above.
#[test]
fn directions_in_the_surface_plane_get_nothing() {
    let mut rng = TestRng(141);
    for (name, bsdf) in glossy_lobes() {
        for _ in 0..100 {
            let (a, b) = (rng.direction(), rng.direction());
            let above = Vec3::new(a.x, a.y, a.z.abs().max(0.1)).normalize();
            let flat = Vec3::new(b.x, b.y, 0.0).normalize();
            for flat in [flat, Vec3::new(flat.x, flat.y, -0.0)] {
                assert_eq!((bsdf.eval(flat, above), bsdf.pdf(flat, above)), (Vec3::ZERO, 0.0), "{name}: wo {flat}");
                assert_eq!((bsdf.eval(above, flat), bsdf.pdf(above, flat)), (Vec3::ZERO, 0.0), "{name}: wi {flat}");
                assert_eq!(bsdf.sample(flat, Vec2::new(rng.f32(), rng.f32())), None, "{name}: wo {flat}");
            }
        }
    }
}

/// `lambertian_eval(wo)` is the value `eval(wo, wi)` has for every `wi` above the surface: the
/// `shadows` and `direct` integrators light a diffuse surface's light points with it and never
/// call `eval`, so a wrong or missing value there goes unseen by every test of `eval`.
#[test]
fn lambertian_eval_is_the_value_of_every_direction_above() {
    let mut rng = TestRng(151);
    let lambert = Lambert { reflectance: Vec3::new(0.7, 0.5, 0.3) };
    for _ in 0..1000 {
        let (a, b) = (rng.direction(), rng.direction());
        let (wo, wi) = (Vec3::new(a.x, a.y, a.z.abs()), Vec3::new(b.x, b.y, b.z.abs()));
        assert_eq!(lambert.lambertian_eval(wo), Some(lambert.eval(wo, wi)), "wo {wo}, wi {wi}");
    }
}

/// `pdf` integrates to at most 1 over the sphere: less where reflected directions fall below the
/// horizon, which `sample` then rejects. In closed form at normal incidence: visible normals are
/// then GGX's normals weighted by `cos θm`, of which the fraction with `tan θm ≤ 1` (reflections
/// that stay above the surface) is `1 / (1 + α²)`; Lambert's integrates to 1.
#[test]
fn pdfs_integrate_to_at_most_one() {
    for (name, bsdf) in glossy_lobes() {
        for (view, wo) in viewing_directions() {
            let total = integrate_sphere(mirrored(wo), |wi| bsdf.pdf(wo, wi) as f64, 1024);
            println!("{name}, wo {view}: ∫ pdf = {total:.5}");
            assert!(total <= 1.0 + 2e-3, "{name}, wo {view}: ∫ pdf = {total}");
            let kept = |alpha: f32| 1.0 / (1.0 + (alpha as f64).powi(2));
            let expected = match bsdf {
                MaterialBsdf::Lambert(_) => Some(1.0),
                MaterialBsdf::Conductor(c) if view == "normal" => Some(kept(c.distribution.alpha())),
                MaterialBsdf::Plastic(p) if view == "normal" => {
                    let specular = p.specular_probability() as f64;
                    Some(specular * kept(p.distribution().alpha()) + (1.0 - specular))
                }
                _ => None,
            };
            if let Some(expected) = expected {
                assert!((total - expected).abs() < 3e-3, "{name}, wo {view}: ∫ pdf = {total}, expected {expected}");
            }
        }
    }
}

/// Reflection lobes are reciprocal, to the last bit: `f(a, b) = f(b, a)`.
#[test]
fn reflection_lobes_are_reciprocal() {
    let mut rng = TestRng(41);
    for (name, bsdf) in glossy_lobes() {
        for _ in 0..20_000 {
            let (a, b) = (rng.direction(), rng.direction());
            let (a, b) = (Vec3::new(a.x, a.y, a.z.abs()), Vec3::new(b.x, b.y, b.z.abs()));
            assert_eq!(bsdf.eval(a, b), bsdf.eval(b, a), "{name}: {a} {b}");
        }
    }
}

/// At a view so grazing (`cos θo = 1e-25`) that `tan²θo` overflows in `f32`, Smith's `Λ(ωo)` is
/// infinite and every GGX reflection's pdf, `G1(ωo) D / (4 cos θo)`, is 0. A sample must have a
/// positive pdf (its path weight is `f cos / pdf`), so the lobes made of that reflection alone,
/// the conductor and a plastic without a base colour, return none of these directions.
#[test]
fn ggx_samples_at_a_view_grazing_past_f32_have_positive_pdf() {
    let wo = Vec3::new(1.0, 0.0, 1e-25);
    for alpha in ROUGHNESSES {
        assert_eq!(Ggx::new(alpha).lambda(wo), f32::INFINITY);
        let lobes = [
            ("conductor", MaterialBsdf::Conductor(Conductor::new(Vec3::ONE, alpha))),
            ("plastic, black base", MaterialBsdf::Plastic(Plastic::new(Vec3::ZERO, Vec3::ONE, alpha))),
        ];
        for (name, bsdf) in lobes {
            for i in 0..32 {
                for j in 0..32 {
                    let u = Vec2::new((i as f32 + 0.5) / 32.0, (j as f32 + 0.5) / 32.0);
                    if let Some(s) = bsdf.sample(wo, u) {
                        assert!(s.pdf > 0.0 && s.pdf.is_finite(), "{name}, α {alpha}, u {u}: pdf {}", s.pdf);
                    }
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// White furnace

/// The directional albedo `∫ f cos θi dωi` with white colours: 1 for Lambert, at most 1 for the
/// conductor (F0 = 1) and for plastics of every `ks` (with `kd = 1`), for viewing directions from
/// the normal to near the horizon. The same integral estimated with the lobe's own samples
/// (`f cos / pdf`) agrees, which checks the sample weights.
#[test]
fn white_furnace_creates_no_energy() {
    let mut lobes: Vec<(String, MaterialBsdf)> =
        vec![("lambert".into(), MaterialBsdf::Lambert(Lambert { reflectance: Vec3::ONE }))];
    for alpha in ROUGHNESSES {
        lobes.push((format!("conductor α {alpha}"), MaterialBsdf::Conductor(Conductor::new(Vec3::ONE, alpha))));
        for ks in [0.04, 0.5, 1.0] {
            lobes.push((
                format!("plastic ks {ks} α {alpha}"),
                MaterialBsdf::Plastic(Plastic::new(Vec3::ONE, Vec3::splat(ks), alpha)),
            ));
        }
    }
    let mut rng = TestRng(51);
    for (name, bsdf) in lobes {
        for theta_deg in [0.0f64, 30.0, 60.0, 80.0, 89.0] {
            let t = theta_deg.to_radians();
            let wo = DVec3::new(t.sin() * 0.8, t.sin() * 0.6, t.cos()).as_vec3();
            let albedo = integrate_sphere(mirrored(wo), |wi| (bsdf.eval(wo, wi) * wi.z.max(0.0)).x as f64, 1024);
            let n = 100_000;
            let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let weight = bsdf.sample(wo, Vec2::new(rng.f32(), rng.f32())).map_or(0.0, |s| {
                    assert!(s.f.x == s.f.y && s.f.y == s.f.z, "white in, white out");
                    (s.f.x * s.wi.z / s.pdf) as f64
                });
                sum += weight;
                sum_sq += weight * weight;
            }
            let mean = sum / n as f64;
            let error = ((sum_sq / n as f64 - mean * mean) / n as f64).sqrt();
            println!("{name}, θo {theta_deg}°: albedo {albedo:.5} (sampled {mean:.5} ± {error:.5})");
            assert!(albedo <= 1.0 + 3e-3, "{name}, θo {theta_deg}°: albedo {albedo}");
            assert!(
                (mean - albedo).abs() <= 4.0 * error + 3e-3,
                "{name}, θo {theta_deg}°: {mean} ± {error} vs {albedo}"
            );
            if name == "lambert" {
                assert!((albedo - 1.0).abs() < 3e-3, "Lambert's albedo is 1, got {albedo}");
            }
            if name.starts_with("plastic ks 1") && theta_deg < 80.0 {
                // A white coat over a base scaled to nothing: the conductor's single-scattering
                // albedo, never the sum of both lobes.
                assert!(albedo < 1.0 + 3e-3);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Delta lobes

/// Mirror: one direction, weight `F(cos θo)` (white for F0 = 1), nothing from `eval` or `pdf`.
#[test]
fn mirror_reflects_into_the_mirror_direction() {
    let mut rng = TestRng(61);
    let mirror = Mirror::new(Vec3::new(1.0, 0.5, 0.2));
    for _ in 0..10_000 {
        let wo = rng.direction();
        let u = Vec2::new(rng.f32(), rng.f32());
        let Some(s) = mirror.sample(wo, u) else {
            assert!(wo.z <= 0.0, "no sample for {wo}");
            continue;
        };
        assert_eq!(s.wi, mirrored(wo));
        assert_eq!(s.pdf, 1.0);
        assert!(s.flags.contains(BsdfFlags::SPECULAR | BsdfFlags::REFLECTION));
        let weight = s.f * s.wi.z / s.pdf;
        let expected = fresnel_schlick(mirror.f0, wo.z);
        assert!((weight - expected).abs().max_element() < 1e-5 * expected.max_element().max(1.0));
        assert!(weight.max_element() <= 1.0 + 1e-5);
        assert_eq!((mirror.eval(wo, s.wi), mirror.pdf(wo, s.wi)), (Vec3::ZERO, 0.0));
    }
}

/// An interface of index 1 is no interface: every ray goes straight on with weight 1.
#[test]
fn dielectric_of_index_one_is_invisible() {
    let mut rng = TestRng(71);
    let glass = Dielectric::new(1.0, Vec3::ONE);
    for _ in 0..10_000 {
        let wo = rng.direction();
        let s = glass.sample(wo, Vec2::new(rng.f32(), rng.f32())).expect("always a sample");
        assert_eq!(s.wi, -wo);
        assert!(s.flags.contains(BsdfFlags::SPECULAR | BsdfFlags::TRANSMISSION));
        let weight = s.f * s.wi.z.abs() / s.pdf;
        assert!((weight - Vec3::ONE).abs().max_element() < 1e-6, "weight {weight}");
    }
}

/// Energy: the reflection probability is the Fresnel `R` of the side `wo` is on, reflection has
/// weight 1, refraction `1/η²` in radiance (η the relative index across), so that in energy
/// `R + T = 1` for every index and side; refracted directions obey Snell's law, and the frequency
/// of reflections matches `R`.
#[test]
fn dielectric_splits_energy_by_fresnel() {
    let mut rng = TestRng(81);
    for eta in [1.33f32, DEFAULT_IOR, 2.4, 0.8] {
        let glass = Dielectric::new(eta, Vec3::ONE);
        for _ in 0..2000 {
            let wo = rng.direction();
            let relative = if wo.z > 0.0 { eta } else { 1.0 / eta };
            let r = fresnel_dielectric(wo.z.abs(), relative);
            // A u below R reflects, with weight 1.
            let s = glass.sample(wo, Vec2::new(0.5 * r, 0.5)).expect("a reflection");
            assert!(s.flags.contains(BsdfFlags::REFLECTION | BsdfFlags::SPECULAR), "wo {wo}: {s:?}");
            assert_eq!(s.wi, mirrored(wo));
            assert!((s.pdf - r).abs() < 1e-6, "pdf {} vs R {r}", s.pdf);
            let reflected = s.f.x * s.wi.z.abs() / s.pdf;
            assert!((reflected - 1.0).abs() < 1e-5, "reflection weight {reflected}");
            let mut energy = (r * reflected) as f64;
            if r < 1.0 {
                // A u above R refracts, with weight 1/η² in radiance, i.e. 1 in energy.
                let s = glass.sample(wo, Vec2::new(r + 0.5 * (1.0 - r), 0.5)).expect("a refraction");
                assert!(s.flags.contains(BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR), "wo {wo}: {s:?}");
                assert!(s.wi.z * wo.z < 0.0 && (s.wi.length() - 1.0).abs() < 1e-5, "crosses: {}", s.wi);
                assert!((s.pdf - (1.0 - r)).abs() < 1e-6);
                let transmitted = s.f.x * s.wi.z.abs() / s.pdf;
                assert!((transmitted * relative * relative - 1.0).abs() < 1e-4, "refraction weight {transmitted}");
                // Snell: sin θo = η sin θi, in the plane of incidence, on the other side.
                let (sin_o, sin_i) = (wo.truncate().length(), s.wi.truncate().length());
                assert!((sin_o - relative * sin_i).abs() < 1e-5, "Snell: {sin_o} vs {relative} × {sin_i}");
                assert!(s.wi.truncate().dot(wo.truncate()) <= 0.0);
                energy += ((1.0 - r) * transmitted * relative * relative) as f64;
            }
            assert!((energy - 1.0).abs() < 1e-5, "η {eta}, wo {wo}: R + T = {energy}");
            assert_eq!((glass.eval(wo, -wo), glass.pdf(wo, -wo)), (Vec3::ZERO, 0.0));
        }
        // The frequency of reflections, from outside at 50° (within the critical angle of η 0.8).
        let wo = Vec3::new(50f32.to_radians().sin(), 0.0, 50f32.to_radians().cos());
        let r = fresnel_dielectric(wo.z, eta) as f64;
        let n = 200_000u64;
        let reflected = (0..n).filter(|_| glass.sample(wo, Vec2::new(rng.f32(), 0.5)).unwrap().wi.z > 0.0).count();
        let p = lumiere::sampling::chi2::chi2_discrete(&[r, 1.0 - r], &[reflected as u64, n - reflected as u64]);
        assert_passes(&format!("dielectric η {eta}: reflection frequency"), p);
    }
}

/// Inside glass beyond the critical angle, everything is reflected back inside, with weight 1.
#[test]
fn total_internal_reflection_inside_at_grazing_angles() {
    let glass = Dielectric::new(1.5, Vec3::new(0.9, 0.8, 0.7));
    let critical_cos = (1.0f32 - 1.0 / (1.5 * 1.5)).sqrt();
    for cos in [0.01f32, 0.2, 0.5, critical_cos - 1e-3] {
        let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, -cos);
        assert_eq!(fresnel_dielectric(-cos, 1.5), 1.0);
        for k in 0..=100 {
            let s = glass.sample(wo, Vec2::new(k as f32 / 100.0, 0.3)).expect("reflects");
            assert!(s.flags.contains(BsdfFlags::REFLECTION | BsdfFlags::SPECULAR), "cos {cos}: {s:?}");
            assert_eq!(s.wi, mirrored(wo));
            assert!(s.wi.z < 0.0, "stays inside");
            assert!((s.f * cos / s.pdf - Vec3::ONE).abs().max_element() < 1e-5, "weight 1, untinted");
        }
    }
    // Just inside the critical angle some light leaves, tinted by Tf.
    let cos = critical_cos + 0.05;
    let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, -cos);
    let s = glass.sample(wo, Vec2::new(0.999, 0.3)).unwrap();
    assert!(s.flags.contains(BsdfFlags::TRANSMISSION) && s.wi.z > 0.0);
    let weight = s.f * s.wi.z / s.pdf;
    assert!((weight - glass.tf / (1.0 / 1.5f32).powi(2)).abs().max_element() < 1e-4, "weight {weight}");
}

/// A `u.x` of exactly 1 (outside the `[0, 1)` the samplers deliver, but what a number remapped
/// onto `[0, 1]` can round to) still never buys a refraction that Fresnel forbids: at a view so
/// grazing that `R` is 1 in `f32` and `T` 0, the glass reflects with pdf 1 instead of refracting
/// with pdf 0 (a sample's pdf is always positive). Only the `T > 0` guard decides this case.
#[test]
fn a_dielectric_never_refracts_where_fresnel_transmits_nothing() {
    let glass = Dielectric::new(DEFAULT_IOR, Vec3::ONE);
    let wo = Vec3::new(1.0, 0.0, 1e-9);
    assert_eq!(fresnel_dielectric(wo.z, DEFAULT_IOR), 1.0);
    let s = glass.sample(wo, Vec2::new(1.0, 0.5)).expect("a reflection");
    assert!(s.flags.contains(BsdfFlags::REFLECTION | BsdfFlags::SPECULAR), "{s:?}");
    assert_eq!((s.wi, s.pdf), (mirrored(wo), 1.0));
}

/// No sample for a `wo` in the surface's plane or not finite, and none carrying an infinite value
/// where `R / cos θo` overflows `f32` (a view so grazing that Fresnel's `R` rounds to 1): a
/// specular lobe must never hand the integrator a non-finite weight.
#[test]
fn dielectric_declines_degenerate_and_overflowing_views() {
    let us = [Vec2::new(0.0, 0.5), Vec2::new(0.5, 0.5), Vec2::new(0.999, 0.5)];
    for eta in [1.0f32, DEFAULT_IOR, 0.8] {
        let glass = Dielectric::new(eta, Vec3::ONE);
        let degenerate = [
            Vec3::X,
            Vec3::new(-0.6, 0.8, 0.0),
            Vec3::new(0.6, 0.8, -0.0),
            Vec3::new(f32::NAN, 0.0, 0.5),
            Vec3::new(0.0, f32::INFINITY, -0.5),
            Vec3::new(0.6, 0.0, f32::NAN),
        ];
        for wo in degenerate {
            for u in us {
                assert!(glass.sample(wo, u).is_none(), "η {eta}, wo {wo}: {:?}", glass.sample(wo, u));
            }
        }
        // cos θo = ±1e-40: 1 / 1e-40 is beyond f32::MAX (and R is 1 in f32 for an interface:
        // no light gets in, or total internal reflection).
        for wo in [Vec3::new(1.0, 0.0, 1e-40), Vec3::new(0.0, -1.0, -1e-40)] {
            for u in us {
                let s = glass.sample(wo, u);
                assert!(s.is_none_or(|s| s.f.is_finite() && s.pdf > 0.0), "η {eta}, wo {wo}: {s:?}");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Fresnel

#[test]
fn fresnel_matches_known_values() {
    for eta in [1.33f32, 1.5, 2.4] {
        let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        assert!((fresnel_dielectric(1.0, eta) - f0).abs() < 1e-6, "normal incidence, η {eta}");
        assert!((fresnel_dielectric(-1.0, eta) - f0).abs() < 1e-6, "from inside, η {eta}");
        assert_eq!(dielectric_f0(eta), f0);
        // Brewster's angle: the p-polarised reflectance vanishes, the s one does not.
        let brewster_cos = (1.0 / (1.0 + (eta as f64).powi(2)).sqrt()) as f32;
        let (rs, rp) = fresnel_dielectric_polarised(brewster_cos, eta);
        assert!(rp < 1e-7 && rs > 0.01, "Brewster, η {eta}: rs {rs}, rp {rp}");
        // Grazing incidence reflects everything.
        assert!(fresnel_dielectric(1e-6, eta) > 0.999);
        // Stokes: the same R across the interface both ways, at angles related by Snell's law.
        for cos_i in [0.1f32, 0.4, 0.7, 0.95] {
            let cos_t = refracted_cos(cos_i, eta).unwrap();
            let (outside, inside) = (fresnel_dielectric(cos_i, eta), fresnel_dielectric(-cos_t, eta));
            assert!((outside - inside).abs() < 1e-5, "η {eta}, cos {cos_i}: {outside} vs {inside}");
        }
        // Total internal reflection from inside beyond the critical angle only.
        let critical = (1.0 - 1.0 / (eta * eta)).sqrt();
        assert_eq!(fresnel_dielectric(-(critical - 1e-3), eta), 1.0);
        assert!(fresnel_dielectric(-(critical + 1e-2), eta) < 1.0);
    }
    // Index 1: no reflection at all except exactly at grazing.
    assert!(fresnel_dielectric(0.5, 1.0) < 1e-12);
    // Schlick: F0 at normal incidence, white at grazing.
    let f0 = Vec3::new(0.9, 0.6, 0.3);
    assert!((fresnel_schlick(f0, 1.0) - f0).abs().max_element() < 1e-7);
    assert!((fresnel_schlick(f0, 0.0) - Vec3::ONE).abs().max_element() < 1e-7);
}

/// Refraction and Fresnel put the critical angle at the same place, `sin²θt ≥ 1`: where
/// `fresnel_dielectric` reports total reflection, `refracted_cos` has no refracted direction. At
/// an index-1 interface a grazing ray has `sin²θt = 1` exactly.
#[test]
fn refraction_ends_where_fresnel_reflects_everything() {
    assert_eq!(fresnel_dielectric_polarised(0.0, 1.0), (1.0, 1.0));
    assert_eq!(refracted_cos(0.0, 1.0), None);
    // Just off grazing, a (nearly grazing) refracted direction exists and Fresnel lets light in.
    let cos_t = refracted_cos(1e-3, 1.0).expect("refracts");
    assert!((cos_t - 1e-3).abs() < 1e-4, "cos θt {cos_t}");
    assert!(fresnel_dielectric(1e-3, 1.0) < 1.0);
}

// ---------------------------------------------------------------------------------------------
// Material → kind

fn material(name: &str, edit: impl FnOnce(&mut Material)) -> Material {
    let mut m = Material::default_grey(name);
    edit(&mut m);
    m
}

#[test]
fn materials_map_to_the_lobes_their_statements_ask_for() {
    // The staircase's glass: Kd 0, Ks 1, Ni 1.5, d 0, Tf 1, illum 7.
    let glass = material("Glass", |m| {
        (m.kd, m.ks, m.ni, m.dissolve, m.tf, m.illum) = (Vec3::ZERO, Vec3::ONE, 1.5, 0.0, Vec3::ONE, 7);
    });
    assert_eq!(glass.kind(), MaterialKind::Dielectric { eta: 1.5, tf: Vec3::ONE });
    assert_eq!(glass.bsdf(glass.kd), MaterialBsdf::Dielectric(Dielectric::new(1.5, Vec3::ONE)));

    // Brass: Kd = Ks = F0, Ns 198, Pm 1, Pr 0.316228 → GGX α 0.1 with the base colour as F0.
    let brass_kd = Vec3::new(0.525128, 0.392649, 0.31059);
    let brass = material("Brass", |m| {
        (m.kd, m.ks, m.ns, m.metallic, m.roughness) = (brass_kd, brass_kd, 198.0, Some(1.0), Some(0.316228));
    });
    let MaterialKind::Conductor { alpha } = brass.kind() else { panic!("brass: {:?}", brass.kind()) };
    assert!((alpha - 0.1).abs() < 1e-5);
    let MaterialBsdf::Conductor(c) = brass.bsdf(brass.kd) else { panic!("brass: {:?}", brass.bsdf(brass.kd)) };
    assert_eq!(c.f0, brass_kd);
    // A texture's value as base colour replaces Kd.
    let MaterialBsdf::Conductor(c) = brass.bsdf(Vec3::splat(0.5)) else { panic!() };
    assert_eq!(c.f0, Vec3::splat(0.5));

    // The staircase's smooth metals (Pr 0) are mirrors of their base colour.
    let steel = material("StainlessSteel", |m| {
        (m.kd, m.ns, m.metallic, m.roughness) = (Vec3::splat(0.53), 1000.0, Some(1.0), Some(0.0))
    });
    assert_eq!(steel.bsdf(steel.kd), MaterialBsdf::Mirror(Mirror::new(Vec3::splat(0.53))));
    assert_eq!(steel.kind().name(), "mirror");

    // An illum 3 mirror with a black base: a mirror of Ks.
    let mirror = material("mirror", |m| (m.kd, m.ks, m.illum) = (Vec3::ZERO, Vec3::splat(0.9), 3));
    assert_eq!(mirror.kind(), MaterialKind::Mirror { f0: Vec3::splat(0.9) });
    assert!(mirror.bsdf(mirror.kd).is_delta());

    // Ks 0.5 Ns 50 with highlights on: plastic, α from the Blinn–Phong exponent.
    let plastic = material("plastic", |m| (m.kd, m.ks, m.ns, m.illum) = (Vec3::splat(0.4), Vec3::splat(0.5), 50.0, 2));
    assert_eq!(plastic.kind(), MaterialKind::Plastic { ks: Vec3::splat(0.5), alpha: (2.0f32 / 52.0).sqrt() });
    let MaterialBsdf::Plastic(p) = plastic.bsdf(plastic.kd) else { panic!() };
    assert_eq!(p.diffuse(), Vec3::splat(0.4 * 0.5));

    // Plain Kd: Lambert of Kd, bit for bit.
    let grey = Material::default_grey("grey");
    assert_eq!(grey.kind(), MaterialKind::Lambert);
    assert_eq!(grey.bsdf(grey.kd), MaterialBsdf::Lambert(Lambert { reflectance: grey.kd }));
}

/// The rules' order and edges, one statement at a time.
#[test]
fn material_mapping_edges() {
    let kind = |edit: fn(&mut Material)| material("m", edit).kind();
    // Highlights off (illum 0/1, also a material without illum), or Ks black: Lambert.
    assert_eq!(kind(|m| (m.ks, m.ns) = (Vec3::splat(0.5), 50.0)), MaterialKind::Lambert);
    assert_eq!(kind(|m| (m.ks, m.illum) = (Vec3::splat(0.5), 0)), MaterialKind::Lambert);
    assert_eq!(kind(|m| (m.ks, m.illum) = (Vec3::ZERO, 2)), MaterialKind::Lambert);
    // Smooth specular with a base colour: the smoothest plastic, not a mirror that drops Kd.
    assert_eq!(
        kind(|m| (m.ks, m.ns, m.illum) = (Vec3::splat(0.5), 1000.0, 2)),
        MaterialKind::Plastic { ks: Vec3::splat(0.5), alpha: MIN_ALPHA }
    );
    assert_eq!(
        kind(|m| (m.kd, m.ks, m.ns, m.illum) = (Vec3::ZERO, Vec3::splat(0.5), 1000.0, 2)),
        MaterialKind::Mirror { f0: Vec3::splat(0.5) }
    );
    // Glass: transmissive illum models; or d < 1 with an explicit Ni; index 1.5 when absent.
    assert_eq!(kind(|m| m.illum = 4), MaterialKind::Dielectric { eta: DEFAULT_IOR, tf: Vec3::ONE });
    assert_eq!(kind(|m| (m.illum, m.ni) = (6, 1.33)), MaterialKind::Dielectric { eta: 1.33, tf: Vec3::ONE });
    assert_eq!(kind(|m| (m.illum, m.ni) = (9, 50.0)), MaterialKind::Dielectric { eta: DEFAULT_IOR, tf: Vec3::ONE });
    assert_eq!(kind(|m| (m.dissolve, m.ni) = (0.5, 1.33)), MaterialKind::Dielectric { eta: 1.33, tf: Vec3::ONE });
    assert_eq!(kind(|m| m.dissolve = 0.5), MaterialKind::Lambert, "d alone is a cutout, not glass");
    assert_eq!(
        kind(|m| (m.illum, m.tf) = (7, Vec3::new(0.5, 2.0, -1.0))),
        MaterialKind::Dielectric { eta: DEFAULT_IOR, tf: Vec3::new(0.5, 1.0, 0.0) }
    );
    // McGuire's walls carry Ni 1.5 with d 1 and illum 2, Ks 0: diffuse.
    assert_eq!(kind(|m| (m.ni, m.illum) = (1.5, 2)), MaterialKind::Lambert);
    // PBR: a threshold on Pm; Pr alone is a non-metal with a 4% coat; α = Pr², or from Ns.
    assert_eq!(kind(|m| (m.metallic, m.roughness) = (Some(0.7), Some(0.5))), MaterialKind::Conductor { alpha: 0.25 });
    assert_eq!(
        kind(|m| (m.metallic, m.roughness) = (Some(0.3), Some(0.5))),
        MaterialKind::Plastic { ks: Vec3::splat(0.04), alpha: 0.25 }
    );
    assert_eq!(kind(|m| m.roughness = Some(0.5)), MaterialKind::Plastic { ks: Vec3::splat(0.04), alpha: 0.25 });
    assert_eq!(
        kind(|m| (m.metallic, m.ns) = (Some(1.0), 98.0)),
        MaterialKind::Conductor { alpha: alpha_from_ns(98.0) }
    );
    assert_eq!(kind(|m| (m.metallic, m.illum) = (Some(1.0), 7)), MaterialKind::Conductor { alpha: 1.0 });
    // Ns → α: Walter et al.'s Beckmann–Phong correspondence.
    assert_eq!(alpha_from_ns(0.0), 1.0);
    assert!((alpha_from_ns(198.0) - 0.1).abs() < 1e-6);
    assert_eq!(alpha_from_ns(f32::NAN), 1.0);
}

/// A NaN `Pr` counts as absent (the MTL loader passes finite numbers only, but `Material` is
/// public): `α` comes from `Ns` by `α = √(2 / (Ns + 2))`, as for a PBR material without `Pr`,
/// rather than a NaN roughness for the lobe to guess at.
#[test]
fn a_nan_roughness_takes_alpha_from_ns() {
    let alpha = (2.0f32 / (98.0 + 2.0)).sqrt();
    let kind = |metallic: Option<f32>| {
        material("m", |m| (m.metallic, m.roughness, m.ns) = (metallic, Some(f32::NAN), 98.0)).kind()
    };
    assert_eq!(kind(Some(1.0)), MaterialKind::Conductor { alpha });
    assert_eq!(kind(None), MaterialKind::Plastic { ks: Vec3::splat(0.04), alpha });
}

/// The built-in gKit box (Ks 0.5 everywhere, no illum) and McGuire's (illum 2, Ks 0) are
/// Lambertian throughout: the lab's images keep their bytes.
#[test]
fn the_cornell_boxes_are_lambertian() {
    let builtin = Scene::builtin().unwrap();
    let mcguire = Scene::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../lumiere-cli/tests/corpus/seeds/CornellBox-Original.obj"),
    )
    .unwrap();
    for scene in [&builtin, &mcguire] {
        assert_eq!(scene.materials.len(), 8);
        for m in &scene.materials {
            assert_eq!(m.kind(), MaterialKind::Lambert, "{}: {m:?}", m.name);
            assert_eq!(m.bsdf(m.kd), MaterialBsdf::Lambert(Lambert { reflectance: m.kd }));
        }
    }
    assert!(builtin.materials.iter().all(|m| m.ks == Vec3::splat(0.5)), "the gKit box does carry Ks 0.5");
}

/// The staircase's materials, as the loader fills them today, map without surprises: its glass
/// is glass, and its metals are metals wherever the loader gives `Pm`.
#[test]
fn the_staircase_materials_map_as_documented() {
    let Some(mtl) = crate::common::shared_scene("staircase/staircase.mtl") else { return };
    let dir = crate::common::TempDir::new("bsdfs-staircase");
    std::fs::copy(&mtl, dir.path("staircase.mtl")).unwrap();
    let text = std::fs::read_to_string(&mtl).unwrap();
    let names: Vec<&str> = text.lines().filter_map(|l| l.strip_prefix("newmtl ")).map(str::trim).collect();
    let mut obj = String::from("mtllib staircase.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for name in &names {
        obj += &format!("usemtl {name}\nf 1 2 3\n");
    }
    let scene = Scene::load(&dir.write("probe.obj", obj)).unwrap();
    for m in &scene.materials {
        let kind = m.kind();
        println!("{}: {}", m.name, kind.name());
        match m.name.as_str() {
            "Glass" => assert_eq!(kind, MaterialKind::Dielectric { eta: 1.5, tf: Vec3::ONE }),
            "Brass" | "BrushedAluminium" if m.metallic.is_some() => {
                assert!(matches!(kind, MaterialKind::Conductor { alpha } if (alpha - 0.1).abs() < 1e-4))
            }
            "Gold" | "Copper" | "StainlessSteel" if m.metallic.is_some() => assert_eq!(kind.name(), "mirror"),
            _ => assert!(matches!(kind, MaterialKind::Lambert | MaterialKind::Plastic { .. }), "{}: {kind:?}", m.name),
        }
    }
}

/// The enum forwards to the lobe it holds, and says which lobes are delta or transmissive.
#[test]
fn material_bsdf_dispatches_to_its_lobe() {
    let mut rng = TestRng(91);
    let conductor = Conductor::new(Vec3::new(0.9, 0.6, 0.3), 0.3);
    let plastic = Plastic::new(Vec3::splat(0.5), Vec3::splat(0.1), 0.2);
    for _ in 0..1000 {
        let (wo, wi) = (rng.direction(), rng.direction());
        let u = Vec2::new(rng.f32(), rng.f32());
        let (a, b) = (MaterialBsdf::Conductor(conductor), MaterialBsdf::Plastic(plastic));
        assert_eq!(a.eval(wo, wi), conductor.eval(wo, wi));
        assert_eq!(a.sample(wo, u), conductor.sample(wo, u));
        assert_eq!(b.pdf(wo, wi), plastic.pdf(wo, wi));
        assert_eq!(b.albedo(), plastic.albedo());
    }
    let glass = MaterialBsdf::Dielectric(Dielectric::new(1.5, Vec3::ONE));
    assert!(glass.is_delta() && glass.transmits());
    assert!(MaterialBsdf::Mirror(Mirror::new(Vec3::ONE)).is_delta());
    assert!(!MaterialBsdf::Conductor(conductor).is_delta() && !MaterialBsdf::Plastic(plastic).transmits());
    // Albedos stay within [0, 1] (an albedo buffer holds colours).
    for bsdf in [glass, MaterialBsdf::Plastic(Plastic::new(Vec3::ONE, Vec3::ONE, 0.1))] {
        assert!(bsdf.albedo().max_element() <= 1.0 + 1e-6, "{bsdf:?}");
    }
    assert!((Dielectric::new(1.5, Vec3::ONE).albedo() - Vec3::ONE).abs().max_element() < 1e-6);
}

/// A sanity check of the reflect helper and of `reflection()`'s symmetric half-vector cosine.
#[test]
fn microfacet_reflection_terms_are_consistent() {
    let mut rng = TestRng(101);
    let ggx = Ggx::new(0.3);
    for _ in 0..10_000 {
        let (wo, m) = (rng.direction(), rng.direction());
        let wi = reflect(wo, m);
        assert!((wi.length() - 1.0).abs() < 1e-5 && (wi.dot(m) - wo.dot(m)).abs() < 1e-5);
        if let Some(r) = ggx.reflection(wo, wi) {
            let h = (wo + wi).normalize();
            assert!((r.cos_h - wo.dot(h)).abs() < 1e-5);
            let pdf = ggx.visible_normal_pdf(wo, h) / (4.0 * wo.dot(h));
            assert!((r.pdf - pdf).abs() <= 1e-4 * pdf.max(1e-3), "{} vs {pdf}", r.pdf);
        }
    }
}

/// `albedo` (what a denoiser's albedo buffer gets) is the colour each lobe documents: Lambert's
/// reflectance, a metal's or a mirror's `F0`, the plastic's scaled base plus its coat, and glass's
/// `R0 + (1 − R0) tf`. Nothing else looks at these values, so only a test of them can catch one.
#[test]
fn albedos_are_the_documented_colours() {
    let colour = Vec3::new(0.9, 0.6, 0.3);
    assert_eq!(Lambert { reflectance: colour }.albedo(), colour);
    assert_eq!(Conductor::new(colour, 0.3).albedo(), colour);
    assert_eq!(Mirror::new(colour).albedo(), colour);
    let plastic = Plastic::new(colour, Vec3::new(0.2, 0.1, 0.05), 0.3);
    assert!((plastic.diffuse() - colour * 0.8).abs().max_element() < 1e-6, "{}", plastic.diffuse());
    assert_eq!(plastic.albedo(), plastic.diffuse() + plastic.specular());
    // η 1.5: R0 = (0.5 / 2.5)² = 0.04.
    let glass = Dielectric::new(1.5, colour);
    let expected = Vec3::splat(0.04) + colour * 0.96;
    assert!((glass.albedo() - expected).abs().max_element() < 1e-6, "{} vs {expected}", glass.albedo());
}

/// A conductor becomes a perfect mirror only when its roughness lies *below* the smallest GGX
/// keeps, `MIN_ALPHA`, as `MaterialKind::Conductor` documents; at `MIN_ALPHA` itself GGX still
/// holds it, and its lobe and its name say conductor.
#[test]
fn a_conductor_at_the_smallest_ggx_roughness_is_no_mirror() {
    let colour = Vec3::new(0.9, 0.6, 0.3);
    let at = MaterialKind::Conductor { alpha: MIN_ALPHA };
    assert_eq!(at.bsdf(colour), MaterialBsdf::Conductor(Conductor::new(colour, MIN_ALPHA)));
    assert_eq!(at.name(), "conductor");
    let below = MaterialKind::Conductor { alpha: MIN_ALPHA.next_down() };
    assert_eq!(below.bsdf(colour), MaterialBsdf::Mirror(Mirror::new(colour)));
    assert_eq!(below.name(), "mirror");
}
