//! The GGX (Trowbridge–Reitz) microfacet distribution, isotropic, with the height-correlated Smith
//! masking-shadowing term and sampling of the normals visible from `wo`.
//!
//! * `D(m) = 1 / (π α² (cos²θm + sin²θm / α²)²)` (Trowbridge & Reitz 1975; Walter et al. 2007,
//!   "Microfacet Models for Refraction through Rough Surfaces", eq. 33). Written with
//!   `sin²θm = m.x² + m.y²` rather than `1 − cos²θm`, which keeps its precision at small `α`, where
//!   the lobe lives within a few 1e-3 of the pole.
//! * Smith's `Λ(ω) = (√(1 + α² tan²θ) − 1) / 2` (Walter et al. eq. 34 and 72), `G1 = 1 / (1 + Λ)`.
//! * Masking and shadowing: the **height-correlated** form `G2 = 1 / (1 + Λ(ωo) + Λ(ωi))` (Heitz
//!   2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs", eq. 99), which
//!   is exact for a Smith surface and slightly above the separable `G1(ωo) G1(ωi)`.
//! * Sampling: the distribution of visible normals `D_ωo(m) = G1(ωo) max(0, ωo·m) D(m) / cos θo`
//!   (Heitz 2014, eq. 2), sampled exactly by Heitz 2018, "Sampling the GGX Distribution of Visible
//!   Normals" (JCGT 7(4)): stretch `ωo` to the `α = 1` configuration, where the visible normals are
//!   uniform over the projected hemisphere, sample that projection (a disk whose lower half is
//!   squashed by `cos θo`), lift to the hemisphere and unstretch. Every sample is a normal the
//!   viewer sees, so no sample is wasted on back-facing microfacets, and the weight of a reflection
//!   sample is `F G2 / G1(ωo)`, at most `F`.
//!
//! `α` is clamped to [`MIN_ALPHA`, `MAX_ALPHA`]: below `1e-3` the lobe is narrower than the `f32`
//! direction grid around the pole resolves well, and materials treat it as a perfect mirror
//! instead (see [`super::Mirror`]).

use std::f32::consts::{FRAC_1_PI, TAU};

use glam::{Vec2, Vec3};

use crate::sampling::warp::sin_cos_turns;

/// The smallest roughness a [`Ggx`] keeps; smaller values (including 0) are raised to it.
/// Materials whose roughness is below it use a delta lobe instead (`Conductor` → `Mirror`).
pub const MIN_ALPHA: f32 = 1e-3;

/// The largest roughness a [`Ggx`] keeps. The mappings from scene files (`Pr²`, Blinn–Phong `Ns`)
/// never exceed 1; larger values only make the lobe more retro-reflective and are not needed.
pub const MAX_ALPHA: f32 = 1.0;

/// An isotropic GGX distribution of microfacet normals with roughness `α` (the slope scale; the
/// perceptual roughness of PBR files is `√α`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    alpha: f32,
}

/// What a microfacet reflection lobe needs at a pair of directions: computed once and shared by
/// `eval`, `pdf` and `sample` of the lobes built on it, so that a sample carries exactly the values
/// `eval` and `pdf` give for its direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicrofacetReflection {
    /// `D(h) G2(ωo, ωi) / (4 cos θo cos θi)`: the BRDF of a surface of perfect mirrors (Fresnel 1).
    pub value: f32,
    /// The solid-angle density with which [`Ggx::sample_visible_normal`] followed by a reflection
    /// about the normal gives `ωi`: `D_ωo(h) / (4 |ωo·h|) = G1(ωo) D(h) / (4 cos θo)`.
    pub pdf: f32,
    /// `ωo·h = ωi·h`, computed symmetrically (the mean of both) so that Fresnel terms built on it
    /// are exactly reciprocal.
    pub cos_h: f32,
}

impl Ggx {
    /// The distribution of roughness `alpha`, clamped to [`MIN_ALPHA`, `MAX_ALPHA`]; NaN counts
    /// as the roughest.
    #[inline]
    pub fn new(alpha: f32) -> Ggx {
        let alpha = if alpha.is_nan() { MAX_ALPHA } else { alpha.clamp(MIN_ALPHA, MAX_ALPHA) };
        Ggx { alpha }
    }

    /// The roughness `α` after clamping.
    #[inline]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// The density of microfacet normals `D(m)` per unit solid angle of `m` (a unit vector), with
    /// `∫ D(m) cos θm dωm = 1` over the hemisphere; 0 for `m` at or below the horizon.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let k = m.z * m.z + (m.x * m.x + m.y * m.y) / a2;
        FRAC_1_PI / (a2 * k * k)
    }

    /// Smith's `Λ(ω)` for a unit direction `ω` on either side (its `|cos θ|` is used): `∞` on the
    /// horizon, where every microfacet is masked.
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let z2 = w.z * w.z;
        // α² tan²θ; infinite (or NaN) at and next to the horizon.
        let x = self.alpha * self.alpha * (w.x * w.x + w.y * w.y) / z2;
        if !x.is_finite() {
            return f32::INFINITY;
        }
        // (√(1 + x) − 1) / 2 without the cancellation at small x.
        x / (2.0 * ((1.0 + x).sqrt() + 1.0))
    }

    /// Smith's masking function `G1(ω) = 1 / (1 + Λ(ω))`.
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// The height-correlated masking-shadowing function `G2(ωo, ωi) = 1 / (1 + Λ(ωo) + Λ(ωi))`,
    /// symmetric in its arguments to the last bit.
    #[inline]
    pub fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + (self.lambda(wo) + self.lambda(wi)))
    }

    /// The density of normals visible from `wo` (`wo.z > 0`), per unit solid angle of `m`:
    /// `D_ωo(m) = G1(ωo) max(0, ωo·m) D(m) / cos θo`. It integrates to 1 over the hemisphere and is
    /// the pdf of [`Ggx::sample_visible_normal`]. 0 when `wo` is not above the surface.
    #[inline]
    pub fn visible_normal_pdf(&self, wo: Vec3, m: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * wo.dot(m).max(0.0) * self.d(m) / wo.z
    }

    /// A microfacet normal visible from `wo` (`wo.z > 0`), distributed with density
    /// [`Ggx::visible_normal_pdf`], from the uniform point `u ∈ [0, 1]²` (Heitz 2018).
    ///
    /// `u` is used as polar coordinates on the unit disk (`r = √u₁`, `φ = 2π u₂`), which is what
    /// [`Ggx::invert_visible_normal_sample`] undoes.
    #[inline]
    pub fn sample_visible_normal(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let (vh, t1, t2) = self.stretched_frame(wo);
        // A uniform point on the unit disk, its lower half (p2 < 0) squashed to the projection of
        // the hemisphere seen from vh: p2 ↦ (1 − s)√(1 − p1²) + s p2 with s = (1 + cos θv)/2.
        let r = u.x.max(0.0).sqrt();
        let (sin_phi, cos_phi) = sin_cos_turns(u.y.max(0.0));
        let p1 = r * cos_phi;
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * (r * sin_phi);
        // Lift onto the hemisphere around vh, then undo the stretch (normals scale by 1/α in x, y,
        // so the inverse transpose of the stretch multiplies them by α).
        let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        Vec3::new(self.alpha * nh.x, self.alpha * nh.y, nh.z.max(0.0)).normalize()
    }

    /// The `u` that [`Ggx::sample_visible_normal`] maps to the visible normal `m` for this `wo`.
    #[inline]
    pub fn invert_visible_normal_sample(&self, wo: Vec3, m: Vec3) -> Vec2 {
        let (vh, t1, t2) = self.stretched_frame(wo);
        let nh = Vec3::new(m.x / self.alpha, m.y / self.alpha, m.z).normalize();
        let p1 = nh.dot(t1);
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (nh.dot(t2) - (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt()) / s;
        let phi = (p2.atan2(p1) / TAU).rem_euclid(1.0);
        Vec2::new((p1 * p1 + p2 * p2).min(1.0), if phi >= 1.0 { 0.0 } else { phi })
    }

    /// `wo` stretched to the `α = 1` configuration, and two unit vectors completing a right-handed
    /// frame around it, the first horizontal (Heitz 2018, listing 1).
    #[inline]
    fn stretched_frame(&self, wo: Vec3) -> (Vec3, Vec3, Vec3) {
        let vh = Vec3::new(self.alpha * wo.x, self.alpha * wo.y, wo.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        // A subnormal `len2` (`vh` within 1e-19 of the pole) keeps too few bits for its square root
        // to normalise `t1`; there any horizontal vector is perpendicular to `vh` to `f32` precision.
        let t1 = if len2 >= f32::MIN_POSITIVE { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
        (vh, t1, vh.cross(t1))
    }

    /// The microfacet reflection terms at `(wo, wi)`, or `None` unless both lie above the
    /// surface (a pair whose cosines multiply to 0 in `f32`, at the horizon, counts as not above).
    #[inline]
    pub fn reflection(&self, wo: Vec3, wi: Vec3) -> Option<MicrofacetReflection> {
        let cos_product = wo.z * wi.z;
        if wo.z <= 0.0 || wi.z <= 0.0 || cos_product <= 0.0 {
            return None;
        }
        // Both above the surface: wo + wi has a positive z and is never zero.
        let h = (wo + wi).normalize();
        let d = self.d(h);
        let (lambda_o, lambda_i) = (self.lambda(wo), self.lambda(wi));
        let value = d / ((1.0 + (lambda_o + lambda_i)) * (4.0 * cos_product));
        let pdf = d / ((1.0 + lambda_o) * (4.0 * wo.z));
        let cos_h = 0.5 * (wo.dot(h) + wi.dot(h));
        Some(MicrofacetReflection { value, pdf, cos_h })
    }
}

/// The mirror image of `wo` about the unit normal `m`: `2 (wo·m) m − wo`.
#[inline]
pub fn reflect(wo: Vec3, m: Vec3) -> Vec3 {
    2.0 * wo.dot(m) * m - wo
}
