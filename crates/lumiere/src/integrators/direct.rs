use glam::{Vec2, Vec3};

use super::{NARROW_GROUP, SampleContext, ShadesClosestHit, WIDE_GROUP, shading_frame};
use crate::accel::simd::lanes_of;
use crate::accel::{OriginBatch, Region};
use crate::geometry::surface::SurfacePoint;
use crate::lights::{AreaLight, LightSample, LightSelection, LightSet};
use crate::materials::Bsdf;
use crate::math::{Frame, Ray};
use crate::sampler::PointSet;
use crate::world::World;

/// How the direct-light estimator spends its samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LightSampling {
    /// N points on every light triangle, as the lab counts (N * lights shadow rays a pixel).
    #[default]
    PerLight,
    /// N points in total, each on a light chosen in proportion to its power.
    Power,
}

/// Direct lighting from area lights (lab figures 4-6): `Lr = (1/N) sum f Le V cos(theta) / pdf(wi)`,
/// with light points drawn uniformly on a light triangle (the solid-angle pdf converts the area pdf
/// `1/A`, GI compendium eq. 18), on every light in turn or on a light picked by power. Where the
/// camera sees a light directly, its emission.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Direct {
    pub samples: u32,
    pub light_sampling: LightSampling,
}

/// The BSDF and geometry of the receiving point, shared by all its light samples.
struct Receiver<'a, B> {
    surface: &'a SurfacePoint,
    bsdf: B,
    frame: Frame,
    wo: Vec3,
}

impl<B: Bsdf> Receiver<'_, B> {
    /// `f Le cos(theta) / pdf` of a light sample, before visibility; `None` when it cannot
    /// contribute (below the surface, or a zero BSDF), so that no shadow ray is traced for it.
    #[inline(always)]
    fn unshadowed(&self, sample: &LightSample) -> Option<Vec3> {
        if !self.faces(sample) {
            return None;
        }
        let cos_surface = self.surface.ns.dot(sample.wi);
        let f = self.bsdf.eval(self.wo, self.frame.to_local(sample.wi));
        (f != Vec3::ZERO).then(|| f * sample.li * (cos_surface / sample.pdf))
    }
}

/// A group of one light's samples: `first..` of the `n`, for a diffuse receiver or another.
struct Group {
    light: u32,
    first: u32,
    n: u32,
    diffuse: bool,
}

impl<B: Bsdf> Receiver<'_, B> {
    /// `sum` plus `f Le V cos(theta) / pdf` of each of the `n` points of `light` drawn from
    /// `points`, [`WIDE_GROUP`] or [`NARROW_GROUP`] at a time: their contributions are computed
    /// lane by lane and their shadow segments tested together against the batch (prepared for the
    /// shaft to the light).
    ///
    /// A diffuse receiver's contributions are `f Le` times a weight `cos(theta) / pdf`: the
    /// visible weights are added up in `NARROW_GROUP` sums (sample `k` into sum
    /// `k % NARROW_GROUP`, in sample order, whatever the groups' widths), the sums then in order,
    /// and `f Le` times that total is added to `sum`: the same additions on every ISA. (Adding
    /// each visible contribution to `sum` in sample order, a chain of dependent scalar additions,
    /// was a tenth of a soft-shadow render.) Other receivers add their visible contributions to
    /// `sum` in sample order.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn add_light(
        &self,
        mut sum: Vec3,
        world: &World,
        light: u32,
        points: &PointSet,
        n: u32,
        batch: &OriginBatch,
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let lights = world.lights();
        let lambertian = self.bsdf.lambertian_eval(self.wo);
        if lambertian == Some(Vec3::ZERO) {
            // A zero BSDF: `unshadowed` refuses every sample, no ray is traced.
            return sum;
        }
        let area_light = &lights.lights()[light as usize];
        let mut weight_sums = [0.0f32; NARROW_GROUP];
        let mut first = 0;
        while first < n {
            // Polled as often as one sample at a time polled it (every `STOP_POLL` samples): each
            // wide group starts at a multiple of `WIDE_GROUP`. (Rounding `first` down to one, as
            // ambient occlusion's probes must, made soft shadows at N = 64 take 3,030 ms instead
            // of 640, 1 thread: the compiler then builds this loop otherwise.)
            if ctx.must_stop(first + WIDE_GROUP as u32 - 1) {
                break;
            }
            let group = Group { light, first, n, diffuse: lambertian.is_some() };
            if n - first >= WIDE_GROUP as u32 {
                sum = self.add_group::<WIDE_GROUP>(sum, world, points, &group, batch, &mut weight_sums, ctx);
                first += WIDE_GROUP as u32;
            } else {
                sum = self.add_group::<NARROW_GROUP>(sum, world, points, &group, batch, &mut weight_sums, ctx);
                first += NARROW_GROUP as u32;
            }
        }
        match lambertian {
            Some(f) => {
                let total = weight_sums.iter().fold(0.0, |total, &weight| total + weight);
                sum + f * area_light.emission * total
            }
            None => sum,
        }
    }

    /// [`Receiver::add_light`]'s samples `group.first..group.first + N` (those below `group.n`):
    /// a diffuse receiver's visible weights added to `weight_sums`, another's visible
    /// contributions to `sum`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn add_group<const N: usize>(
        &self,
        mut sum: Vec3,
        world: &World,
        points: &PointSet,
        group: &Group,
        batch: &OriginBatch,
        weight_sums: &mut [f32; NARROW_GROUP],
        ctx: &mut SampleContext,
    ) -> Vec3 {
        let count = (group.n - group.first).min(N as u32) as usize;
        let points: [Vec2; N] = points.get_2d_lanes(group.first);
        if group.diffuse {
            let area_light = &world.lights().lights()[group.light as usize];
            let (weights, segments, traced) = self.lambertian_lanes(area_light, &points, count, batch.origin());
            let visible = trace(world, batch, &segments, traced, ctx);
            // All ones for a visible lane, else zero: the weights are masked bitwise (an unlit
            // lane's may be infinite or NaN, which a product by 0 would keep). Lane `k` is sample
            // `first + k`, and `first` is a multiple of `NARROW_GROUP`. Summed a row of
            // `NARROW_GROUP` at a time, so that each loop vectorises (indexed by `lane %
            // NARROW_GROUP`, the one loop stayed scalar: 7% of soft shadows N = 64); each sum
            // still adds its lanes in increasing order.
            const { assert!(N.is_multiple_of(NARROW_GROUP), "lanes fill whole rows of sums") };
            for row in 0..N / NARROW_GROUP {
                for (k, sum) in weight_sums.iter_mut().enumerate() {
                    let lane = row * NARROW_GROUP + k;
                    let keep = 0u32.wrapping_sub((visible >> lane) & 1);
                    *sum += f32::from_bits(weights[lane].to_bits() & keep);
                }
            }
        } else {
            let (contributions, segments, traced) =
                self.bsdf_lanes(world.lights(), group.light, &points, count, batch.origin());
            for lane in lanes_of(trace(world, batch, &segments, traced, ctx)) {
                sum += contributions[lane];
            }
        }
        sum
    }
}

impl<B: Bsdf> Receiver<'_, B> {
    /// The contributions (before visibility) and shadow segments of the light points of `light`
    /// drawn from `points` (the first `count` of them), and the lanes that need a shadow ray. Two
    /// loops: the light points (plain arithmetic, vectorised), then the BSDF, a call per lane,
    /// which would keep the points scalar if they shared its loop.
    #[inline(always)]
    fn bsdf_lanes<const N: usize>(
        &self,
        lights: &LightSet,
        light: u32,
        points: &[Vec2; N],
        count: usize,
        origin: Vec3,
    ) -> ([Vec3; N], [[f32; N]; 3], u32) {
        let mut samples = [None; N];
        for (sample, &u) in samples.iter_mut().zip(points) {
            *sample = lights.sample_li_on(light, self.surface.p, u).filter(|s| self.faces(s));
        }
        let mut contributions = [Vec3::ZERO; N];
        let mut segments = [[0.0; N]; 3];
        let mut traced = 0u32;
        for (lane, sample) in samples.iter().enumerate().take(count) {
            let Some(sample) = sample else { continue };
            let Some(contribution) = self.unshadowed(sample) else { continue };
            contributions[lane] = contribution;
            // `Ray::segment(origin, target)`: the direction is the whole segment, tmax 1.
            [segments[0][lane], segments[1][lane], segments[2][lane]] = (sample.target - origin).to_array();
            traced |= 1 << lane;
        }
        (contributions, segments, traced)
    }

    /// [`Receiver::bsdf_lanes`] for a diffuse receiver, whose BSDF is `f` wherever `wi` is above
    /// its shading normal, so that a contribution is `f Le` times a weight `cos(theta) / pdf`:
    /// the weights, shadow segments and traced lanes, in one loop over the lanes, SoA, which the
    /// ISA vectorises whole. Each lane does the operations of `sample_uniform_triangle`,
    /// `shadow_target`, `sample_li_on`, `faces` and `unshadowed` in their order (glam's `dot` and
    /// `length_squared` sum x, y, then z), so its segment and weight have their bits.
    #[inline(always)]
    fn lambertian_lanes<const N: usize>(
        &self,
        light: &AreaLight,
        points: &[Vec2; N],
        count: usize,
        origin: Vec3,
    ) -> ([f32; N], [[f32; N]; 3], u32) {
        let [p0, p1, p2] = light.shadow_targets.map(|t| t.to_array());
        let (p, o) = (self.surface.p.to_array(), origin.to_array());
        let (ns, ng, normal) = (self.surface.ns, self.surface.ng, light.normal);
        let mut weights = [0.0f32; N];
        let mut segments = [[0.0; N]; 3];
        let mut traced = 0u32;
        for (lane, u) in points.iter().enumerate() {
            let s = u.x.sqrt();
            let (b0, b1) = (1.0 - s, u.y * s);
            let b2 = 1.0 - b0 - b1;
            // Arrays written out, not `[0, 1, 2].map(..)`: where that call was not inlined (as
            // the crate's code moved between codegen units), the loop stayed scalar and the
            // soft-shadow rows took five times as long.
            let lerp = |c: usize| b0 * p0[c] + b1 * p1[c] + b2 * p2[c];
            let target = [lerp(0), lerp(1), lerp(2)];
            let v = [target[0] - p[0], target[1] - p[1], target[2] - p[2]];
            let dist2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            let dist = dist2.sqrt();
            let inv_dist = 1.0 / dist;
            let wi = [v[0] * inv_dist, v[1] * inv_dist, v[2] * inv_dist];
            let cos_light_dist = -(normal.x * v[0] + normal.y * v[1] + normal.z * v[2]);
            let sampled = !(cos_light_dist <= 0.0 || dist2 <= 0.0);
            let pdf = dist2 * dist / (cos_light_dist * light.area);
            let cos_surface = ns.x * wi[0] + ns.y * wi[1] + ns.z * wi[2];
            let cos_geometric = ng.x * wi[0] + ng.y * wi[1] + ng.z * wi[2];
            let faces = !(cos_surface <= 0.0 || cos_geometric <= 0.0);
            // `eval` is `f` for `wi.z > 0` in the shading frame, whose z is `ns`: `cos_surface`.
            let lit = sampled & faces & (cos_surface > 0.0) & (lane < count);
            weights[lane] = cos_surface / pdf;
            for c in 0..3 {
                segments[c][lane] = target[c] - o[c];
            }
            traced |= u32::from(lit) << lane;
        }
        (weights, segments, traced)
    }
}

impl<B> Receiver<'_, B> {
    /// Whether the light sample may arrive from above the surface, by both normals (a NaN passes:
    /// its contribution is counted as discarded, as every non-finite sample is).
    #[inline(always)]
    fn faces(&self, sample: &LightSample) -> bool {
        !(self.surface.ns.dot(sample.wi) <= 0.0 || self.surface.ng.dot(sample.wi) <= 0.0)
    }
}

/// Traces the `traced` shadow segments of a group of light points (from the batch's origin, ending
/// at `t = 1`, SoA) against the batch, counting them; the lanes that reach the light.
#[inline(always)]
fn trace<const N: usize>(
    world: &World,
    batch: &OriginBatch,
    segments: &[[f32; N]; 3],
    traced: u32,
    ctx: &mut SampleContext,
) -> u32 {
    ctx.rays += u64::from(traced.count_ones());
    traced & !world.occluded_lanes_in_batch(batch, segments, 1.0, traced)
}

/// False when no point of the light can contribute: the light lies wholly below the surface's
/// tangent plane, or the surface lies behind the light. Saves preparing a batch for nothing.
fn faces_each_other(surface: &SurfacePoint, light: &AreaLight) -> bool {
    let above = light.vertices.iter().any(|&v| surface.ng.dot(v - surface.p) > 0.0);
    let in_front = light.normal.dot(surface.p - light.vertices[0]) > 0.0;
    above && in_front
}

impl ShadesClosestHit for Direct {
    fn shade(&self, world: &World, ray: &Ray, surface: Option<&SurfacePoint>, ctx: &mut SampleContext) -> Vec3 {
        let Some(surface) = surface else { return Vec3::ZERO };
        // A light seen from the side it faces shows its emission; from behind it is a surface.
        let emitted = world.emitted(surface.triangle, ray);
        if emitted != Vec3::ZERO {
            return emitted;
        }
        let (frame, wo) = shading_frame(surface.ns, ray.dir);
        let receiver = Receiver { surface, bsdf: world.bsdf(surface), frame, wo };
        // Every shadow ray leaves above the geometric surface (the others are skipped), so they
        // share one origin.
        let origin = surface.offset_origin(surface.ng);
        let lights = world.lights();
        let n = self.samples;
        let mut sum = Vec3::ZERO;
        match self.light_sampling {
            LightSampling::PerLight => {
                // The N shadow rays towards one light triangle share their origin and stay in the shaft
                // from it to the triangle: trace them as a batch. The two triangles of a quad light
                // share one, the shaft to the quad (a fifth of a soft-shadow render was spent
                // preparing the second).
                let mut batch = std::mem::take(&mut ctx.batch);
                let mut batch_quad = None;
                for (index, light) in lights.lights().iter().enumerate() {
                    // Each light's samples poll too, but only from `STOP_POLL` of them on.
                    if ctx.must_stop(index as u32) {
                        break;
                    }
                    // Taken for every light, lit or not, so that each light keeps its dimension.
                    let points = ctx.stream.next_points(n);
                    if !faces_each_other(surface, light) {
                        continue;
                    }
                    let quad = lights.quad_of(index as u32);
                    if quad.is_none_or(|(q, _)| batch_quad != Some(q)) {
                        // The shaft to the quad, or to the triangle alone where the receiver is not
                        // in front of the quad's plane (or the light has no quad).
                        let quad_shaft = quad.and_then(|(q, quad)| {
                            Region::shaft_to_quad(origin, quad.corners, quad.plane).map(|shaft| (q, shaft))
                        });
                        batch_quad = quad_shaft.map(|(q, _)| q);
                        let shaft = quad_shaft.map(|(_, shaft)| shaft);
                        let shaft = shaft.or_else(|| Region::shaft(origin, light.shadow_targets));
                        // Cut by the surface: every traced segment leaves above it (samples below
                        // `ng` are skipped), so the receiver's own triangles cannot block one.
                        let Some(shaft) = shaft.map(|shaft| shaft.above(origin, surface.ng)) else {
                            continue;
                        };
                        world.prepare_batch(&mut batch, origin, &shaft, n);
                    }
                    let light = index as u32;
                    sum = world.simd(
                        #[inline(always)]
                        || receiver.add_light(sum, world, light, &points, n, &batch, ctx),
                    );
                }
                ctx.batch = batch;
            }
            LightSampling::Power => {
                let (choices, points) = (ctx.stream.next_points(n), ctx.stream.next_points(n));
                for k in 0..n {
                    if ctx.must_stop(k) {
                        break;
                    }
                    let u_light = choices.get_1d(k);
                    let Some(sample) = lights.sample_li(LightSelection::Power, surface.p, u_light, points.get_2d(k))
                    else {
                        continue;
                    };
                    let Some(contribution) = receiver.unshadowed(&sample) else { continue };
                    ctx.rays += 1;
                    if !world.occluded(&Ray::segment(origin, sample.target)) {
                        sum += contribution;
                    }
                }
            }
        }
        sum / n as f32
    }
}
