//! Fresnel reflectance: the fraction of light a smooth interface reflects.
//!
//! * Dielectrics (glass, water, the coat of a plastic): the exact Fresnel equations for
//!   unpolarised light, with total internal reflection. `eta` is always the *relative* index
//!   `η_t / η_i` across the interface, seen from the side the normal points to.
//! * Conductors (metals): Schlick's approximation `F0 + (1 − F0)(1 − cos θ)⁵` from the reflectance
//!   at normal incidence `F0`. Scene files give a metal's colour (the MTL PBR extension's base
//!   colour `Kd`, glTF's `baseColor`), not its complex index `n + ik` per wavelength, and that colour
//!   *is* `F0`; Schlick's curve then adds the whitening at grazing angles every real metal shows.
//!   This is what mainstream real-time and production "metallic" models do (Burley 2012, glTF).

use glam::Vec3;

/// Fresnel reflectance of a smooth dielectric interface for unpolarised light: the mean of the
/// s- and p-polarised reflectances of [`fresnel_dielectric_polarised`].
///
/// `cos_i` is the cosine between the incident direction and the normal; `eta = η_t / η_i` is the
/// relative index seen from the side the normal points to. A negative `cos_i` means light arrives
/// from the other side, where the interface has index `1 / eta`. Returns 1 under total internal
/// reflection. `eta` must be positive and finite.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (rs, rp) = fresnel_dielectric_polarised(cos_i, eta);
    0.5 * (rs + rp)
}

/// The reflectances `(R_s, R_p)` (squared amplitude ratios, in `[0, 1]`) of light polarised
/// perpendicular (s) and parallel (p) to the plane of incidence, from the Fresnel equations
/// (Born & Wolf §1.5; pbrt-v4 §9.3 derives them the same way):
///
/// `r_s = (cos θi − η cos θt) / (cos θi + η cos θt)`, `r_p = (η cos θi − cos θt) / (η cos θi + cos θt)`,
/// with Snell's law `sin θt = sin θi / η`. `R_p` vanishes at Brewster's angle `tan θi = η`.
/// Both are 1 under total internal reflection (`sin θt ≥ 1`). Conventions as in
/// [`fresnel_dielectric`].
#[inline]
pub fn fresnel_dielectric_polarised(cos_i: f32, eta: f32) -> (f32, f32) {
    let (cos_i, eta) = if cos_i < 0.0 { (-cos_i, 1.0 / eta) } else { (cos_i, eta) };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return (1.0, 1.0);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (rs * rs, rp * rp)
}

/// The cosine of the refracted direction's angle with the normal, `cos θt = √(1 − sin²θi / η²)`,
/// for `cos_i ∈ [0, 1]` and relative index `eta`; `None` under total internal reflection.
#[inline]
pub fn refracted_cos(cos_i: f32, eta: f32) -> Option<f32> {
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    (sin2_t < 1.0).then(|| (1.0 - sin2_t).sqrt())
}

/// Schlick's approximation of a conductor's reflectance, `F0 + (1 − F0)(1 − cos θ)⁵`, per channel
/// (Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering"). `cos` is clamped to
/// `[0, 1]`; `f0` is the reflectance at normal incidence (a metal's base colour).
#[inline]
pub fn fresnel_schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = 1.0 - cos.clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (Vec3::ONE - f0) * (m2 * m2 * m)
}

/// The reflectance at normal incidence of a dielectric of relative index `eta`: `((η − 1)/(η + 1))²`.
#[inline]
pub fn dielectric_f0(eta: f32) -> f32 {
    let r = (eta - 1.0) / (eta + 1.0);
    r * r
}
