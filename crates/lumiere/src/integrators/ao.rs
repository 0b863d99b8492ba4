use std::ops::Range;

use glam::{Vec2, Vec3};

use super::{NARROW_GROUP, SampleContext, ShadesClosestHit, WIDE_GROUP};
use crate::accel::{OriginBatch, Region};
use crate::geometry::surface::SurfacePoint;
use crate::math::{Frame, Ray};
use crate::sampler::PointSet;
use crate::sampling::warp::sample_cosine_hemisphere;
use crate::world::World;

/// Ambient occlusion: the fraction of `samples` cosine-weighted directions about the normal (on the
/// viewer's side) that reach the sky, or that travel at least `distance` without a hit.
///
/// With directions drawn with pdf `cos(theta)/pi`, the estimator of `(1/pi) * integral of V cos(theta)`
/// is `(1/N) sum V`: every weight is exactly 1 (GI compendium eq. 35). When `samples` is a multiple
/// of four, the directions are stratified in azimuth: each quarter turn about the normal gets a
/// quarter of them (the estimator stays unbiased, with less variance), and from
/// `MIN_QUARTER_BATCH` directions on, each quarter is traced as a batch of its own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmbientOcclusion {
    pub samples: u32,
    /// Rays stop here; `f32::INFINITY` for the lab's "visibility of the sky".
    pub distance: f32,
}

/// From this many probes per point, each quarter of the hemisphere has candidates of its own,
/// gathered together in one walk: a quarter of the Cornell box's hemispheres holds 3.2 blocks of
/// four triangles on average against 7.4 for the whole, so each probe is tested against less than
/// half as many triangles. Fewer probes do not pay for the quarters' partly filled groups of
/// `NARROW_GROUP`. Measured on the Cornell box (1024x768, 2 threads, alternating, medians of 5),
/// quarters from 16 probes on against from 256 on: 128 probes 488 -> 438 ms, 64: 292 -> 298, 16:
/// 139 -> 306; with groups of 32, quarters from 64 probes on were slower again (653 -> 673 ms).
const MIN_QUARTER_BATCH: u32 = 128;

impl ShadesClosestHit for AmbientOcclusion {
    fn shade(&self, world: &World, _: &Ray, surface: Option<&SurfacePoint>, ctx: &mut SampleContext) -> Vec3 {
        let Some(surface) = surface else { return Vec3::ZERO };
        let frame = Frame::from_normal(surface.ng);
        let directions = Directions { points: ctx.stream.next_points(self.samples), quarters: self.quarters() };
        // All probes leave from one origin into the half-space above the surface: trace them as a
        // batch, or as four, one per quarter of the half-space, gathered together.
        let origin = surface.offset_origin(surface.ng);
        let mut batch = std::mem::take(&mut ctx.batch);
        let mut visible = 0;
        if let Some(starts) = directions.quarters.filter(|_| self.samples >= MIN_QUARTER_BATCH) {
            let region = Region::hemisphere_in_quarters(origin, &frame, world.diameter());
            world.prepare_batch(&mut batch, origin, &region, self.samples);
            for quarter in 0..4 {
                batch.select_part(quarter);
                let probes = starts[quarter]..starts[quarter + 1];
                visible += world.simd(
                    #[inline(always)]
                    || self.count_visible(world, &batch, &frame, &directions, probes, ctx),
                );
            }
        } else {
            world.prepare_batch(&mut batch, origin, &Region::hemisphere(origin, surface.ng), self.samples);
            visible = world.simd(
                #[inline(always)]
                || self.count_visible(world, &batch, &frame, &directions, 0..self.samples, ctx),
            );
        }
        ctx.batch = batch;
        ctx.rays += u64::from(self.samples);
        Vec3::splat(visible as f32 / self.samples as f32)
    }
}

impl AmbientOcclusion {
    /// Where the quarters of the probes start (probes `starts[q]..starts[q + 1]` lie in quarter
    /// `q`, `starts[4]` being `samples`), when `samples` is a multiple of four.
    fn quarters(&self) -> Option<[u32; 5]> {
        let quarter = self.samples / 4;
        self.samples.is_multiple_of(4).then(|| [0, quarter, 2 * quarter, 3 * quarter, self.samples])
    }

    /// How many of the probes `probes` reach the sky, [`WIDE_GROUP`] or [`NARROW_GROUP`] at a
    /// time.
    #[inline(always)]
    fn count_visible(
        &self,
        world: &World,
        batch: &OriginBatch,
        frame: &Frame,
        directions: &Directions<'_>,
        probes: Range<u32>,
        ctx: &SampleContext,
    ) -> u32 {
        let mut visible = 0;
        let mut first = probes.start;
        while first < probes.end {
            // Polled about as often as one probe at a time polled it (every `STOP_POLL` probes):
            // a quarter's probes start anywhere, so `first` is rounded down to a multiple of
            // `WIDE_GROUP`, and each `WIDE_GROUP` probes hold one group that polls.
            if ctx.must_stop(first / WIDE_GROUP as u32 * WIDE_GROUP as u32 + WIDE_GROUP as u32 - 1) {
                break;
            }
            let left = probes.end - first;
            if left >= WIDE_GROUP as u32 {
                visible += self.count_visible_in_group::<WIDE_GROUP>(world, batch, frame, directions, first, left);
                first += WIDE_GROUP as u32;
            } else {
                visible += self.count_visible_in_group::<NARROW_GROUP>(world, batch, frame, directions, first, left);
                first += NARROW_GROUP as u32;
            }
        }
        visible
    }

    /// How many of the `left.min(N)` probes from `first` on reach the sky: their directions are
    /// computed in loops over the lanes (vectorised in the world's ISA; each lane does the scalar
    /// operations, so the bits do not depend on `N`), then tested together against the batch.
    #[inline(always)]
    fn count_visible_in_group<const N: usize>(
        &self,
        world: &World,
        batch: &OriginBatch,
        frame: &Frame,
        directions: &Directions<'_>,
        first: u32,
        left: u32,
    ) -> u32 {
        let [xs, azimuths] = directions.points_from::<N>(first);
        let mut dirs = [[0.0; N]; 3];
        for lane in 0..N {
            let dir = frame.to_world(sample_cosine_hemisphere(Vec2::new(xs[lane], azimuths[lane])));
            [dirs[0][lane], dirs[1][lane], dirs[2][lane]] = dir.to_array();
        }
        let live = u32::MAX >> (32 - left.min(N as u32));
        let blocked = world.occluded_lanes_in_batch(batch, &dirs, self.distance, live);
        (live & !blocked).count_ones()
    }
}

/// The random points of a pixel's probes, and where each quarter of them starts when the probes
/// are stratified in azimuth.
struct Directions<'a> {
    points: PointSet<'a>,
    quarters: Option<[u32; 5]>,
}

impl Directions<'_> {
    /// The points of probes `first..first + N` as rows (see [`PointSet::get_2d_rows`]), each
    /// with its azimuth number moved into its quarter turn when the probes are stratified: probe
    /// `i` of quarter `q` turns by `(q + u) / 4` of a turn instead of `u`. The same points
    /// whatever range they are drawn for.
    #[inline(always)]
    fn points_from<const N: usize>(&self, first: u32) -> [[f32; N]; 2] {
        let [xs, mut azimuths] = self.points.get_2d_rows::<N>(first);
        if let Some(starts) = self.quarters {
            for (lane, azimuth) in azimuths.iter_mut().enumerate() {
                let probe = first.wrapping_add(lane as u32);
                let quarter =
                    u32::from(probe >= starts[1]) + u32::from(probe >= starts[2]) + u32::from(probe >= starts[3]);
                *azimuth = (quarter as f32 + *azimuth) * 0.25;
            }
        }
        [xs, azimuths]
    }
}
