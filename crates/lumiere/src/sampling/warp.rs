//! Warps from the unit square to triangles, hemispheres and spheres.
//!
//! Every warp is a pure function of its uniform sample `u ∈ [0, 1]²` and comes as a triple:
//! `sample_*`, `*_pdf` and `invert_*_sample`. Without an RNG inside, they can be driven by
//! independent or quasi-random numbers alike, checked on grids, and round-tripped in tests. Each pdf
//! names its measure; directions are in the local frame of [`crate::math::Frame`] (`z` = normal).
//!
//! All sample functions accept `u` on the closed square, including exact 0 and 1, without NaN.

use std::f32::consts::{FRAC_1_PI, TAU};

use glam::{Vec2, Vec3};

/// Uniform point on a triangle as barycentric coordinates `(b0, b1, b2)`, weights of vertices 0, 1, 2.
///
/// Global Illumination Compendium (Dutré), eq. 18: `b0 = 1 − √u₁`, `b1 = u₂·√u₁`. `b2` is taken as
/// `1 − b0 − b1` so that the three always sum to one.
#[inline]
pub fn sample_uniform_triangle(u: Vec2) -> Vec3 {
    let s = u.x.sqrt();
    let b0 = 1.0 - s;
    let b1 = u.y * s;
    Vec3::new(b0, b1, 1.0 - b0 - b1)
}

/// Density of [`sample_uniform_triangle`] with respect to **area** on a triangle of area `area`.
///
/// Lights convert it to solid angle with `distance² / cos θ` at the one place that needs it.
#[inline]
pub fn uniform_triangle_pdf(area: f32) -> f32 {
    1.0 / area
}

/// The `u` that [`sample_uniform_triangle`] maps to the barycentrics `b`.
///
/// `√u₁ = 1 − b0` is computed as `b1 + b2`, which keeps its precision near vertex 0.
#[inline]
pub fn invert_uniform_triangle_sample(b: Vec3) -> Vec2 {
    let s = b.y + b.z;
    let v = if s > 0.0 { (b.y / s).min(1.0) } else { 0.0 };
    Vec2::new((s * s).min(1.0), v)
}

/// Cosine-weighted direction on the hemisphere around `+z`.
///
/// Global Illumination Compendium, eq. 35 (Malley's method: uniform on the disk, projected up):
/// `sin θ = √u₁`, `φ = 2π·u₂`, so `cos²θ = 1 − u₁` is uniform as the density `cos θ / π` requires.
/// This orientation (rather than `cos θ = √u₁`) keeps samplers' `u₁ ∈ [0, 1)` off the horizon,
/// where the pdf is 0: the lowest direction it can produce has `cos θ = √(2⁻²⁴) > 0`.
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let sin_theta = u.x.sqrt();
    let cos_theta = (1.0 - u.x).max(0.0).sqrt();
    direction(sin_theta, cos_theta, TAU * u.y)
}

/// Density of [`sample_cosine_hemisphere`] with respect to **solid angle**: `max(cos θ, 0) / π`.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// The `u` that [`sample_cosine_hemisphere`] maps to the unit direction `w` (`w.z ≥ 0`).
#[inline]
pub fn invert_cosine_hemisphere_sample(w: Vec3) -> Vec2 {
    Vec2::new((w.x * w.x + w.y * w.y).min(1.0), azimuth_fraction(w))
}

/// Uniform direction on the hemisphere around `+z`: `cos θ = 1 − u₁`, `φ = 2π·u₂`
/// (Archimedes: height on the sphere is uniform in area). `u₁ < 1` never reaches the horizon.
#[inline]
pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let cos_theta = 1.0 - u.x;
    // √(1 − cos²θ) written as √(u₁(2 − u₁)) keeps its precision near the pole.
    let sin_theta = (u.x * (2.0 - u.x)).max(0.0).sqrt();
    direction(sin_theta, cos_theta, TAU * u.y)
}

/// Density of [`sample_uniform_hemisphere`] with respect to **solid angle**: `1 / 2π` on the
/// closed upper hemisphere (`cos θ ≥ 0`), 0 below.
#[inline]
pub fn uniform_hemisphere_pdf(cos_theta: f32) -> f32 {
    if cos_theta >= 0.0 { 0.5 * FRAC_1_PI } else { 0.0 }
}

/// The `u` that [`sample_uniform_hemisphere`] maps to the unit direction `w` (`w.z ≥ 0`).
#[inline]
pub fn invert_uniform_hemisphere_sample(w: Vec3) -> Vec2 {
    Vec2::new((1.0 - w.z).clamp(0.0, 1.0), azimuth_fraction(w))
}

/// Uniform direction on the unit sphere: `cos θ = 1 − 2u₁`, `φ = 2π·u₂`.
#[inline]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let cos_theta = 1.0 - 2.0 * u.x;
    // √(1 − cos²θ) = 2√(u₁(1 − u₁)): exact at both poles.
    let sin_theta = 2.0 * (u.x * (1.0 - u.x)).max(0.0).sqrt();
    direction(sin_theta, cos_theta, TAU * u.y)
}

/// Density of [`sample_uniform_sphere`] with respect to **solid angle**: `1 / 4π` everywhere.
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// The `u` that [`sample_uniform_sphere`] maps to the unit direction `w`.
#[inline]
pub fn invert_uniform_sphere_sample(w: Vec3) -> Vec2 {
    Vec2::new((0.5 * (1.0 - w.z)).clamp(0.0, 1.0), azimuth_fraction(w))
}

/// The unit vector with polar angle given by its sine and cosine and azimuth `phi`.
#[inline]
fn direction(sin_theta: f32, cos_theta: f32, phi: f32) -> Vec3 {
    let (sin_phi, cos_phi) = sin_cos_turns(phi / TAU);
    Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta)
}

/// `sin` and `cos` of `2π·turns` for `turns >= 0`, within 3e-8 of the exact values.
///
/// libm's `sincosf` took a fifth of ambient-occlusion render time. The angle is reduced to a
/// quarter turn around the nearest multiple of 90° (|a| ≤ π/4), where Taylor series to `a⁹`/`a⁸`
/// are accurate to 2e-9/3e-8, and the quadrant rotates the result back.
#[inline]
pub fn sin_cos_turns(turns: f32) -> (f32, f32) {
    // Nearest quarter turn; truncating rounds for `turns >= 0` after adding 0.5, without a libm
    // call (SSE2 has no rounding instruction; `f32::round` showed up in profiles).
    let quadrant = truncate(turns * 4.0 + 0.5);
    let a = (turns - quadrant * 0.25) * TAU;
    let a2 = a * a;
    let sin = a * (1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362_880.0)))));
    let cos = 1.0 + a2 * (-0.5 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40_320.0))));
    // Rotate back by the quadrant q: (sin, cos), (cos, -sin), (-sin, -cos), (-cos, sin) for q = 0..3,
    // written as selects rather than a match, so that loops over many angles vectorise (a match
    // compiled to a jump table on a random quadrant).
    let q = truncate_to_i32(quadrant);
    let (a, b) = if q & 1 == 0 { (sin, cos) } else { (cos, sin) };
    (if q & 2 == 0 { a } else { -a }, if (q + 1) & 2 == 0 { b } else { -b })
}

/// `x as i32`, for the values [`sin_cos_turns`] converts, without the saturation `as` adds: Rust's
/// saturating conversion (NaN to 0, out of range to the limits) does not vectorise, and compiled to
/// a scalar conversion and two conditional moves per lane (12% of ambient occlusion at N = 256).
/// The input is first clamped into `i32`'s range, so the unchecked conversion is always defined:
/// for every finite `x` whose truncation fits in an `f32` below 2³¹ in magnitude it is `x as i32`,
/// bit for bit; a NaN gives the lower bound where `as` gives 0 (either way the angle is NaN).
#[inline(always)]
fn truncate_to_i32(x: f32) -> i32 {
    // `f32::max` and `min` return the other operand for a NaN, where `clamp` would keep the NaN.
    #[allow(clippy::manual_clamp)]
    let x = x.max(-2_147_483_520.0).min(2_147_483_520.0);
    // SAFETY: `x` is finite and its truncation lies within `i32`'s range (both bounds are `f32`
    // values inside it).
    unsafe { x.to_int_unchecked::<i32>() }
}

/// `x as i32 as f32` (see [`truncate_to_i32`]).
#[inline(always)]
fn truncate(x: f32) -> f32 {
    truncate_to_i32(x) as f32
}

/// `φ / 2π ∈ [0, 1)` for the azimuth `φ` of `w` around `+z`; 0 on the axis, where `φ` is arbitrary.
#[inline]
fn azimuth_fraction(w: Vec3) -> f32 {
    let f = w.y.atan2(w.x) / TAU;
    let f = if f < 0.0 { f + 1.0 } else { f };
    // `f + 1` rounds to exactly 1 for tiny negative angles; the sample for that is u₂ = 0 anyway.
    if f >= 1.0 { 0.0 } else { f }
}

#[cfg(test)]
mod tests {
    use super::truncate_to_i32;

    /// The unchecked conversion agrees with `as` wherever `sin_cos_turns` can land (and far
    /// beyond), and stays defined, clamped, outside `i32`'s range.
    #[test]
    fn truncation_is_as_i32_within_range() {
        let small = (-200_000..200_000).map(|i| i as f32 * 0.000_37);
        let large = (0..230).flat_map(|k| {
            let x = 1.1f32.powi(k);
            [x, -x]
        });
        let edges =
            [0.0f32, -0.0, 0.499_999_97, 0.5, 4.499_999_5, 1.0 - f32::EPSILON, 2_147_483_520.0, -2_147_483_520.0];
        for x in small.chain(large).chain(edges) {
            if x.abs() <= 2_147_483_520.0 {
                assert_eq!(truncate_to_i32(x), x as i32, "{x}");
            } else {
                assert_eq!(truncate_to_i32(x), if x > 0.0 { 2_147_483_520 } else { -2_147_483_520 }, "{x}");
            }
        }
        assert_eq!(truncate_to_i32(f32::INFINITY), 2_147_483_520);
        assert_eq!(truncate_to_i32(f32::NEG_INFINITY), -2_147_483_520);
        assert_eq!(truncate_to_i32(f32::NAN), -2_147_483_520);
    }
}
