use glam::Vec3;

use super::{Integrator, SampleContext, shading_frame};
use crate::materials::Bsdf;
use crate::math::Ray;
use crate::world::World;

/// The lab's hard shadows: every light triangle acts as a point light at its centroid carrying the
/// triangle's area, `L = sum Ke * f * cos(theta) * cos(theta_light) * area / d^2 * V`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shadows;

impl Integrator for Shadows {
    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        let Some(hit) = world.intersect(ray) else { return Vec3::ZERO };
        // A light seen from the side it faces shows its emission; from behind it is a surface.
        let emitted = world.emitted(hit.triangle, ray);
        if emitted != Vec3::ZERO {
            return emitted;
        }
        let surface = world.surface(ray, &hit);
        let bsdf = world.bsdf(&surface);
        let (frame, wo) = shading_frame(surface.ns, ray);
        let mut sum = Vec3::ZERO;
        for light in world.lights().lights() {
            let to_light = light.centroid() - surface.p;
            let d2 = to_light.length_squared();
            let wi = to_light / d2.sqrt();
            let cos_surface = surface.ns.dot(wi);
            let cos_light = light.normal.dot(-wi);
            if cos_surface <= 0.0 || cos_light <= 0.0 || surface.ng.dot(wi) <= 0.0 {
                continue;
            }
            // The segment ends on the light's shadow-target triangle, just in front of the light.
            let target = light.shadow_target(Vec3::splat(1.0 / 3.0));
            ctx.rays += 1;
            if world.occluded(&surface.spawn_segment(target)) {
                continue;
            }
            let f = bsdf.eval(wo, frame.to_local(wi));
            sum += f * light.emission * (cos_surface * cos_light * light.area / d2);
        }
        sum
    }
}
