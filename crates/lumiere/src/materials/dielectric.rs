//! A smooth dielectric interface (glass, water): specular reflection and refraction, weighted by
//! the exact Fresnel reflectance.

use glam::{Vec2, Vec3};

use super::fresnel::{dielectric_f0, fresnel_dielectric, refracted_cos};
use super::{Bsdf, BsdfFlags, BsdfSample};

/// A smooth interface between the outside (where the normal points, index 1) and a medium of
/// index `eta` inside, with a transmission filter `tf` applied at every refraction.
///
/// Two delta lobes, chosen with the Fresnel reflectance `R(cos θo)` as probability (pbrt's
/// convention for specular lobes):
/// * reflection: `wi = (−wo.x, −wo.y, wo.z)`, `pdf = R`, `f = R / |cos θi|`: path weight 1;
///   flags `SPECULAR | REFLECTION`;
/// * refraction by Snell's law: `pdf = T = 1 − R`, `f = T tf / (η² |cos θi|)`: path weight
///   `tf / η²`, where `η` is the relative index, that of the side `wi` lies on over that of the
///   side of `wo` (`eta` for `wo` outside, `1 / eta` inside); flags `SPECULAR | TRANSMISSION`.
///
/// The `1/η²` is the radiance scaling at a refractive boundary (radiance is power per solid
/// angle, and solid angles contract by `η²` entering the denser medium; Veach 1997 §5.2, pbrt-v4
/// §9.5.2): energy is conserved, `R + T = 1`, while a ray that enters and leaves the glass gets
/// `η²` and `1/η²`, i.e. weight 1. This is the convention for *radiance* paths traced from the
/// camera; a light tracer would need the adjoint (no scaling).
///
/// `wo` may lie on either side: below the surface (`wo.z < 0`, a ray travelling inside the glass)
/// the interface is seen with index `1 / eta`, and total internal reflection happens beyond the
/// critical angle. `eval` and `pdf` are 0 for every pair of directions. An index of exactly 1 is
/// invisible: everything passes straight through (`wi = −wo`) with weight `tf`.
///
/// `tf` is a surface filter, not volume absorption: a ray through a pane is filtered twice.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// Index of refraction of the inside over the outside; positive and finite.
    pub eta: f32,
    /// Transmission filter per channel, in `[0, 1]`; 1 for clear glass.
    pub tf: Vec3,
}

impl Dielectric {
    /// A dielectric of index `eta` (positive and finite; the material mapping makes sure) and
    /// transmission filter `tf` (clamped to `[0, 1]`).
    #[inline]
    pub fn new(eta: f32, tf: Vec3) -> Dielectric {
        debug_assert!(eta > 0.0 && eta.is_finite(), "index of refraction {eta}");
        Dielectric { eta, tf: tf.clamp(Vec3::ZERO, Vec3::ONE) }
    }
}

impl Bsdf for Dielectric {
    #[inline]
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        let cos_o = wo.z.abs();
        if cos_o == 0.0 || !wo.is_finite() {
            return None;
        }
        let transmission = BsdfFlags::TRANSMISSION | BsdfFlags::SPECULAR;
        if self.eta == 1.0 {
            // No interface at all: Fresnel's R is 0 and Snell's law the identity. Written out so
            // that rounding cannot scatter a stray reflection or bend the ray.
            // At a view within ~3e-39 of grazing, 1 / cos θo overflows: no sample, as below.
            let (wi, f) = (-wo, self.tf / cos_o);
            return f.is_finite().then_some(BsdfSample { f, wi, pdf: 1.0, flags: transmission });
        }
        // The relative index across the interface as light crossing it towards wo sees it.
        let eta = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let r = fresnel_dielectric(cos_o, eta);
        let t = 1.0 - r;
        let cos_t = refracted_cos(cos_o, eta);
        match cos_t {
            Some(cos_t) if u.x >= r && t > 0.0 => {
                // Snell: the tangential part scales by 1/η and flips, the normal part crosses.
                let wi = Vec3::new(-wo.x / eta, -wo.y / eta, -cos_t.copysign(wo.z));
                let f = self.tf * (t / (eta * eta * cos_t));
                f.is_finite().then_some(BsdfSample { f, wi, pdf: t, flags: transmission })
            }
            _ => {
                // Reflection, chosen with probability R; certain under total internal reflection.
                let r = if cos_t.is_none() { 1.0 } else { r };
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                let f = Vec3::splat(r / cos_o);
                (r > 0.0 && f.is_finite()).then_some(BsdfSample {
                    f,
                    wi,
                    pdf: r,
                    flags: BsdfFlags::REFLECTION | BsdfFlags::SPECULAR,
                })
            }
        }
    }

    #[inline]
    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    /// The fraction of light scattered, reflected or transmitted, at normal incidence from
    /// outside: `R0 + (1 − R0) tf`, white for clear glass (what a denoiser's albedo buffer expects
    /// of a clear specular surface).
    #[inline]
    fn albedo(&self) -> Vec3 {
        let r0 = dielectric_f0(self.eta);
        Vec3::splat(r0) + self.tf * (1.0 - r0)
    }
}
