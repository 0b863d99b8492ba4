use glam::Vec3;

use super::{Integrator, SampleContext};
use crate::accel::Region;
use crate::math::{Frame, Ray};
use crate::sampling::warp::sample_cosine_hemisphere;
use crate::world::World;

/// Ambient occlusion: the fraction of `samples` cosine-weighted directions about the normal (on the
/// viewer's side) that reach the sky, or that travel at least `distance` without a hit.
///
/// With directions drawn with pdf `cos(theta)/pi`, the estimator of `(1/pi) * integral of V cos(theta)`
/// is `(1/N) sum V`: every weight is exactly 1 (GI compendium eq. 35).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusion {
    pub samples: u32,
    /// Rays stop here; `f32::INFINITY` for the lab's "visibility of the sky".
    pub distance: f32,
}

impl Integrator for AmbientOcclusion {
    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        let Some(hit) = world.intersect(ray) else { return Vec3::ZERO };
        let surface = world.surface(ray, &hit);
        let frame = Frame::from_normal(surface.ng);
        let directions = ctx.stream.next_points(self.samples);
        // All probes leave from one origin into the half-space above the surface: trace them as a batch.
        let origin = surface.offset_origin(surface.ng);
        let mut batch = std::mem::take(&mut ctx.batch);
        world.prepare_batch(&mut batch, origin, &Region::hemisphere(origin, surface.ng), self.samples);
        let mut visible = 0u32;
        for k in 0..self.samples {
            if ctx.must_stop(k) {
                break;
            }
            let dir = frame.to_world(sample_cosine_hemisphere(directions.get_2d(k)));
            let probe = Ray { origin, dir, tmax: self.distance };
            visible += u32::from(!world.occluded_in_batch(&batch, &probe));
        }
        ctx.batch = batch;
        ctx.rays += u64::from(self.samples);
        Vec3::splat(visible as f32 / self.samples as f32)
    }
}
