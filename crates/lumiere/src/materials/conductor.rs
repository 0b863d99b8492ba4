//! Metals: a rough GGX conductor, and its smooth limit, a perfect mirror.
//!
//! Both take their colour as the reflectance at normal incidence `F0` (the MTL PBR extension's
//! base colour `Kd` with `Pm 1`) and brighten it towards white at grazing angles with Schlick's
//! Fresnel approximation (see [`super::fresnel`] for why not the complex index).

use glam::{Vec2, Vec3};

use super::fresnel::fresnel_schlick;
use super::microfacet::{Ggx, MIN_ALPHA, reflect};
use super::{Bsdf, BsdfFlags, BsdfSample};

/// A rough metal: `f = F(ωo·h) D(h) G2(ωo, ωi) / (4 cos θo cos θi)` with GGX `D`, the
/// height-correlated Smith `G2` and Schlick's `F` from `f0`; sampled through the visible normals.
///
/// One-sided: nothing is reflected unless `wo` and `wi` both lie above the surface (`z > 0`).
/// Energy: with `f0 = 1` the directional albedo is `∫ G2/G1 D_ωo`, at most 1. Single scattering
/// loses the light that would bounce again between microfacets, which grows fast with roughness:
/// at normal incidence the albedo is 0.997 for `α = 0.05`, 0.88 for 0.3 and 0.43 for 0.8 (of the
/// visible normals at `α = 0.8`, 39% already reflect below the horizon), as in pbrt and Mitsuba
/// without multiple-scattering compensation (Kulla & Conty 2017), which we do not have yet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Reflectance at normal incidence, per channel, in `[0, 1]`.
    pub f0: Vec3,
    pub distribution: Ggx,
}

impl Conductor {
    /// A conductor of colour `f0` (clamped to `[0, 1]`) and GGX roughness `alpha` (clamped as
    /// [`Ggx::new`] says). Materials whose `alpha` is below [`MIN_ALPHA`] use [`Mirror`] instead.
    #[inline]
    pub fn new(f0: Vec3, alpha: f32) -> Conductor {
        Conductor { f0: f0.clamp(Vec3::ZERO, Vec3::ONE), distribution: Ggx::new(alpha) }
    }

    /// `f` and the pdf at `(wo, wi)`: the one computation behind `eval`, `pdf` and `sample`.
    #[inline]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
        let r = self.distribution.reflection(wo, wi)?;
        Some((fresnel_schlick(self.f0, r.cos_h) * r.value, r.pdf))
    }
}

impl Bsdf for Conductor {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.eval_pdf(wo, wi).map_or(Vec3::ZERO, |(f, _)| f)
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let m = self.distribution.sample_visible_normal(wo, u);
        let wi = reflect(wo, m);
        let (f, pdf) = self.eval_pdf(wo, wi)?;
        (pdf > 0.0 && pdf.is_finite()).then_some(BsdfSample {
            f,
            wi,
            pdf,
            flags: BsdfFlags::REFLECTION | BsdfFlags::GLOSSY,
        })
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(wo, wi).map_or(0.0, |(_, pdf)| pdf)
    }

    /// `F0`, the colour at normal incidence.
    #[inline]
    fn albedo(&self) -> Vec3 {
        self.f0
    }
}

/// A perfect mirror, the `α → 0` limit of [`Conductor`]: all light leaves in the mirror direction
/// `(−wo.x, −wo.y, wo.z)` with Schlick's reflectance `F(cos θo)` from `f0`.
///
/// A delta lobe (pbrt's convention): `eval` and `pdf` are 0 for every pair of directions (the
/// chance of naming the mirror direction is nil); `sample` returns `pdf = 1` (the discrete
/// probability of its only lobe) and `f = F / cos θi`, so that the path weight `f cos θi / pdf`
/// is `F`. Flags `SPECULAR | REFLECTION`. One-sided, like the conductor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// Reflectance at normal incidence, per channel, in `[0, 1]`.
    pub f0: Vec3,
}

impl Mirror {
    /// A mirror of colour `f0`, clamped to `[0, 1]`.
    #[inline]
    pub fn new(f0: Vec3) -> Mirror {
        Mirror { f0: f0.clamp(Vec3::ZERO, Vec3::ONE) }
    }
}

impl Bsdf for Mirror {
    #[inline]
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    #[inline]
    fn sample(&self, wo: Vec3, _u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let f = fresnel_schlick(self.f0, wo.z) / wo.z;
        f.is_finite().then_some(BsdfSample {
            f,
            wi: Vec3::new(-wo.x, -wo.y, wo.z),
            pdf: 1.0,
            flags: BsdfFlags::REFLECTION | BsdfFlags::SPECULAR,
        })
    }

    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    #[inline]
    fn albedo(&self) -> Vec3 {
        self.f0
    }
}

/// Whether a roughness is too small for a GGX lobe and means a perfect mirror.
#[inline]
pub(crate) fn is_smooth(alpha: f32) -> bool {
    alpha < MIN_ALPHA
}
