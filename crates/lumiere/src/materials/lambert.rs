use std::f32::consts::FRAC_1_PI;

use glam::{Vec2, Vec3};

use super::{Bsdf, BsdfFlags, BsdfSample};
use crate::sampling::warp::{cosine_hemisphere_pdf, sample_cosine_hemisphere};

/// Ideal diffuse reflection: `f = reflectance / π` on the side of the normal, sampled with the
/// cosine-weighted hemisphere (pdf `cos θ / π`, so `f cos θ / pdf = reflectance` exactly).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert {
    pub reflectance: Vec3,
}

impl Bsdf for Lambert {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z > 0.0 && wi.z > 0.0 { self.reflectance * FRAC_1_PI } else { Vec3::ZERO }
    }

    #[inline]
    fn lambertian_eval(&self, wo: Vec3) -> Option<Vec3> {
        Some(self.eval(wo, Vec3::Z))
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = sample_cosine_hemisphere(u);
        let pdf = cosine_hemisphere_pdf(wi.z);
        (pdf > 0.0).then(|| BsdfSample {
            f: self.reflectance * FRAC_1_PI,
            wi,
            pdf,
            flags: BsdfFlags::REFLECTION | BsdfFlags::DIFFUSE,
        })
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 && wi.z > 0.0 { cosine_hemisphere_pdf(wi.z) } else { 0.0 }
    }

    #[inline]
    fn albedo(&self) -> Vec3 {
        self.reflectance
    }
}
