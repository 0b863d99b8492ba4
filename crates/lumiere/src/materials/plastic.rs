//! A glossy plastic: a diffuse base under a GGX specular layer.

use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::microfacet::{Ggx, reflect};
use super::{Bsdf, BsdfFlags, BsdfSample};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

/// The largest `f32` below 1, where remapped uniforms are kept.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Diffuse `kd` plus a GGX specular layer of reflectance `ks` (the MTL `Kd`/`Ks`/`Ns` model):
///
/// `f = ks D G2 / (4 cos θo cos θi) + (1 − max(ks)) kd / π`.
///
/// **Energy.** The specular term is a microfacet mirror surface scaled by `ks`, so it reflects at
/// most `ks` of the incoming light in every channel; the diffuse term reflects at most
/// `(1 − max ks) kd ≤ 1 − max ks`. Their sum is at most 1 per channel for every `wo`: the material
/// never creates energy, whatever `kd` and `ks` a file gives (both are clamped to `[0, 1]`). Unlike
/// a Fresnel-weighted coat, `ks` is the specular reflectance at every angle, as in the Phong model
/// the MTL statements come from; it is reciprocal, and the bound needs no fitted tables.
///
/// **Sampling.** One of the two lobes is chosen with a probability proportional to its albedo
/// estimate (the mean of `ks`, the mean of the scaled `kd`), the specular one through the GGX
/// visible normals, the diffuse one cosine-weighted. `pdf` is the mixture of both lobes' pdfs,
/// and every sample carries the full `f` and mixture pdf, so `f cos / pdf` is an unbiased weight
/// and MIS sees one density.
///
/// One-sided: nothing is reflected unless `wo` and `wi` both lie above the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// The diffuse lobe's reflectance, already scaled by `1 − max(ks)`.
    diffuse: Vec3,
    /// The specular layer's reflectance.
    ks: Vec3,
    distribution: Ggx,
    /// The probability of sampling the specular lobe.
    specular_probability: f32,
}

impl Plastic {
    /// The plastic of diffuse colour `kd` and specular colour `ks` (each clamped to `[0, 1]`) with
    /// GGX roughness `alpha` (clamped as [`Ggx::new`] says).
    #[inline]
    pub fn new(kd: Vec3, ks: Vec3, alpha: f32) -> Plastic {
        let ks = ks.clamp(Vec3::ZERO, Vec3::ONE);
        let diffuse = kd.clamp(Vec3::ZERO, Vec3::ONE) * (1.0 - ks.max_element());
        let (specular_weight, diffuse_weight) = (mean(ks), mean(diffuse));
        let total = specular_weight + diffuse_weight;
        let specular_probability = if total > 0.0 { specular_weight / total } else { 0.0 };
        Plastic { diffuse, ks, distribution: Ggx::new(alpha), specular_probability }
    }

    /// The diffuse reflectance after the energy scaling, `(1 − max ks) kd`.
    #[inline]
    pub fn diffuse(&self) -> Vec3 {
        self.diffuse
    }

    /// The specular reflectance `ks`.
    #[inline]
    pub fn specular(&self) -> Vec3 {
        self.ks
    }

    /// The GGX distribution of the specular layer.
    #[inline]
    pub fn distribution(&self) -> Ggx {
        self.distribution
    }

    /// The probability with which `sample` picks the specular lobe.
    #[inline]
    pub fn specular_probability(&self) -> f32 {
        self.specular_probability
    }

    /// `f` and the mixture pdf at `(wo, wi)`: the one computation behind `eval`, `pdf` and `sample`.
    #[inline]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
        let r = self.distribution.reflection(wo, wi)?;
        let p = self.specular_probability;
        let f = self.ks * r.value + self.diffuse * FRAC_1_PI;
        let pdf = p * r.pdf + (1.0 - p) * cosine_hemisphere_pdf(wi.z);
        Some((f, pdf))
    }
}

impl Bsdf for Plastic {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.eval_pdf(wo, wi).map_or(Vec3::ZERO, |(f, _)| f)
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        let p = self.specular_probability;
        if wo.z <= 0.0 || (p == 0.0 && self.diffuse == Vec3::ZERO) {
            return None;
        }
        let (wi, flags) = if u.x < p || p >= 1.0 {
            let u = Vec2::new((u.x / p).min(ONE_MINUS_EPSILON), u.y);
            (reflect(wo, self.distribution.sample_visible_normal(wo, u)), BsdfFlags::GLOSSY)
        } else {
            let u = Vec2::new(((u.x - p) / (1.0 - p)).clamp(0.0, ONE_MINUS_EPSILON), u.y);
            (sample_cosine_hemisphere(u), BsdfFlags::DIFFUSE)
        };
        let (f, pdf) = self.eval_pdf(wo, wi)?;
        (pdf > 0.0 && pdf.is_finite()).then_some(BsdfSample { f, wi, pdf, flags: BsdfFlags::REFLECTION | flags })
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(wo, wi).map_or(0.0, |(_, pdf)| pdf)
    }

    /// The reflectance at normal incidence, roughly: the scaled diffuse colour plus `ks`.
    #[inline]
    fn albedo(&self) -> Vec3 {
        self.diffuse + self.ks
    }
}

#[inline]
fn mean(v: Vec3) -> f32 {
    (v.x + v.y + v.z) / 3.0
}
