use glam::{Vec2, Vec3};

use super::{SampleContext, ShadesClosestHit};
use crate::accel::Hit;
use crate::accel::{OriginBatch, Region};
use crate::math::{Frame, Ray};
use crate::sampler::PointSet;
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

/// Probes drawn and tested together: one AVX-512 register of f32 (two AVX2 ones).
const LANES: usize = 16;

impl ShadesClosestHit for AmbientOcclusion {
    fn shade(&self, world: &World, ray: &Ray, hit: Option<Hit>, ctx: &mut SampleContext) -> Vec3 {
        let Some(hit) = hit else { return Vec3::ZERO };
        let surface = world.surface(ray, &hit);
        let frame = Frame::from_normal(surface.ng);
        let directions = ctx.stream.next_points(self.samples);
        // All probes leave from one origin into the half-space above the surface: trace them as a batch.
        let origin = surface.offset_origin(surface.ng);
        let mut batch = std::mem::take(&mut ctx.batch);
        world.prepare_batch(&mut batch, origin, &Region::hemisphere(origin, surface.ng), self.samples);
        let visible = world.simd(
            #[inline(always)]
            || self.count_visible(world, &batch, &frame, &directions, ctx),
        );
        ctx.batch = batch;
        ctx.rays += u64::from(self.samples);
        Vec3::splat(visible as f32 / self.samples as f32)
    }
}

impl AmbientOcclusion {
    /// How many of the probes reach the sky, `LANES` at a time: their directions are computed in
    /// loops over the lanes (vectorised in the world's ISA; each lane does the scalar operations,
    /// so the bits do not depend on it), then tested together against the batch.
    #[inline(always)]
    fn count_visible(
        &self,
        world: &World,
        batch: &OriginBatch,
        frame: &Frame,
        directions: &PointSet,
        ctx: &SampleContext,
    ) -> u32 {
        let mut visible = 0;
        for first in (0..self.samples).step_by(LANES) {
            // Polled as often as one probe at a time polled it (every `STOP_POLL` probes).
            if ctx.must_stop(first + LANES as u32 - 1) {
                break;
            }
            // The random numbers first, then the warp, each in its own vectorisable loop.
            let points: [Vec2; LANES] = directions.get_2d_lanes(first);
            let mut dirs = [[0.0; LANES]; 3];
            for lane in 0..LANES {
                let dir = frame.to_world(sample_cosine_hemisphere(points[lane]));
                [dirs[0][lane], dirs[1][lane], dirs[2][lane]] = dir.to_array();
            }
            let live = u32::MAX >> (32 - (self.samples - first).min(LANES as u32));
            let blocked = world.occluded_lanes_in_batch(batch, &dirs, self.distance, live);
            visible += (live & !blocked).count_ones();
        }
        visible
    }
}
