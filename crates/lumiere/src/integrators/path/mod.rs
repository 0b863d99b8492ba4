//! Unidirectional path tracing with next-event estimation and multiple importance sampling.
//!
//! Each vertex of a path adds light in two ways that cover the same paths: a point sampled on a
//! light (next-event estimation) and the light a BSDF-sampled ray happens to hit. Both are weighted
//! with the power heuristic (Veach 1997), so that each contributes where its density is the better
//! one: light sampling for small, bright lights and rough surfaces, BSDF sampling for large lights
//! and glossy lobes. Delta lobes (mirrors, smooth glass) cannot be light-sampled: the light their
//! rays hit counts in full. Russian roulette ends paths whose throughput has become small, and
//! divides the survivors by their survival probability, so the estimate stays unbiased.
//!
//! Depth counts as in Mitsuba 3: `max_depth` 1 shows the emitters the camera sees, 2 adds direct
//! light, 8 allows up to seven bounces; 0 sets no limit (Russian roulette alone ends paths).

mod diffuse;

use glam::{Vec2, Vec3};

use self::diffuse::DiffuseVertices;
use super::{CameraPacket, Integrator, PACKET, SampleContext};
use crate::accel::simd::lanes_of;
use crate::accel::{Hit, Isa};
use crate::geometry::surface::SurfacePoint;
use crate::lights::LightSelection;
use crate::materials::{Bsdf, BsdfFlags, MaterialBsdf};
use crate::math::rows::{row, set_row};
use crate::math::{Frame, Ray};
use crate::sampler::{LaneStreams, SampleStream};
use crate::sampling::mis::power_heuristic;
use crate::world::World;

/// Path tracing with next-event estimation and MIS (`--mode path`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Path {
    /// The longest path, in segments from the camera (Mitsuba's `max_depth`); 0 for no limit.
    pub max_depth: u32,
    /// Russian roulette starts after this many segments (Mitsuba's `rr_depth`, 5 by default).
    pub rr_depth: u32,
    pub strategy: PathStrategy,
}

impl Default for Path {
    fn default() -> Self {
        Path { max_depth: 8, rr_depth: 5, strategy: PathStrategy::Mis }
    }
}

/// Which techniques find the light: both with MIS weights (the renderer's), or one of them alone
/// (for tests: all three converge to the same image, with different noise).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PathStrategy {
    #[default]
    Mis,
    /// Next-event estimation alone: emitters hit by BSDF rays count only through delta lobes.
    LightsOnly,
    /// BSDF sampling alone: light counts only where a ray hits it.
    BsdfOnly,
}

impl Path {
    /// The weight of light found by a BSDF ray of density `bsdf_pdf` that light sampling would have
    /// drawn with density `light_pdf`.
    #[inline]
    fn hit_weight(&self, bsdf_pdf: f32, light_pdf: f32) -> f32 {
        match self.strategy {
            PathStrategy::Mis => power_heuristic(bsdf_pdf, light_pdf),
            PathStrategy::LightsOnly => 0.0,
            PathStrategy::BsdfOnly => 1.0,
        }
    }

    /// The weight of light found by next-event estimation against BSDF sampling, divided by the
    /// light sample's density `light_pdf` (positive).
    #[inline]
    fn light_weight_over_pdf(&self, light_pdf: f32, bsdf_pdf: f32) -> f32 {
        match self.strategy {
            PathStrategy::Mis => mis_light_weight_over_pdf(light_pdf, bsdf_pdf),
            PathStrategy::LightsOnly => 1.0 / light_pdf,
            PathStrategy::BsdfOnly => 0.0,
        }
    }
}

/// The power heuristic's weight of a light sample of density `light_pdf` (positive) against BSDF
/// sampling's `bsdf_pdf`, over `light_pdf`: `l / (l² + b²)`, one division where weight and density
/// apart take two.
#[inline(always)]
fn mis_light_weight_over_pdf(light_pdf: f32, bsdf_pdf: f32) -> f32 {
    let w = light_pdf / (light_pdf * light_pdf + bsdf_pdf * bsdf_pdf);
    // `l² + b²` is infinite for an infinite `l` and 0 for a tiny one (the squares overflow or
    // underflow): the ratio form holds there.
    if w.is_finite() { w } else { power_heuristic(light_pdf, bsdf_pdf) / light_pdf }
}

/// How lights are chosen for next-event estimation: by power, with the triangle → light map
/// giving the same probability back when a BSDF ray hits an emitter.
const SELECTION: LightSelection = LightSelection::Power;

/// The scattering at one path vertex, in the shading frame.
struct Vertex<'a, B> {
    surface: &'a SurfacePoint,
    bsdf: B,
    frame: Frame,
    wo: Vec3,
}

impl<B: Bsdf> Vertex<'_, B> {
    /// `f · |cos θi|` for the world direction `wi`, or zero where the shading frame and the
    /// geometry disagree on the side `wi` lies on (a shading normal must not let light leak through
    /// the surface, nor let a reflection come from behind it).
    #[inline]
    fn f_cos(&self, wi: Vec3) -> (Vec3, Vec3) {
        let local = self.frame.to_local(wi);
        if !self.sides_agree(wi, local) {
            return (Vec3::ZERO, local);
        }
        (self.bsdf.eval(self.wo, local) * local.z.abs(), local)
    }

    /// Whether `wi` is a reflection (same side as the viewer) in the geometry exactly when it is one
    /// in the shading frame. `ng` faces the viewer, so the geometric test is `ng · wi > 0`.
    #[inline]
    fn sides_agree(&self, wi: Vec3, local: Vec3) -> bool {
        (self.surface.ng.dot(wi) > 0.0) == (local.z * self.wo.z > 0.0)
    }
}

/// One path in flight: where it goes next and what it has gathered.
struct PathState {
    ray: Ray,
    throughput: Vec3,
    radiance: Vec3,
    /// The previous vertex's BSDF density for `ray` (infinite for a delta lobe or the camera), for
    /// the MIS weight of the light `ray` hits.
    previous_pdf: f32,
    /// Segments traced so far.
    depth: u32,
}

/// The random numbers of one path vertex. Each vertex takes three dimensions, whether it uses them
/// or not, so that a bounce's numbers do not depend on the vertices before it.
struct VertexNumbers {
    /// Chooses the light and the point on it (next-event estimation).
    light: Vec2,
    /// Chooses the scattered direction.
    scatter: Vec2,
    /// Decides Russian roulette.
    survival: f32,
}

/// A light sample a vertex found unblocked by its BSDF: what it adds if the segment is clear.
struct ShadowTest {
    segment: Ray,
    contribution: Vec3,
}

impl Path {
    /// The paths of up to `N` camera samples (bit `i` of `live` for lane `i`), traced in lockstep,
    /// bounce by bounce: every live path's next closest hit, then every path's surface point, then
    /// every path's scattering, then every shadow segment. Each path does exactly the operations,
    /// in the order, it would do alone (light found at a vertex is added before the next vertex's),
    /// so its radiance has the same bits however many travel together. From AVX2 up, the diffuse
    /// vertices of a bounce are scattered together (`diffuse.rs`, with the bits of [`Path::scatter`]):
    /// the box's vertices were a quarter of its time, one at a time.
    ///
    /// Together, the records a path's shading reads are asked for a phase before they are used
    /// (`World::prefetch_hit` after its hit, `World::prefetch_bsdf` after its surface point), and
    /// come from memory while the other paths are worked on. On a large textured scene those
    /// misses, at the end of a chain of dependent ones, were a fifth of the render: the staircase
    /// takes 11% less time (the 1.1M-triangle bunny 21% less), and the Cornell box, whose records
    /// stay cached, the same.
    fn trace<'a, const N: usize>(
        &self,
        world: &World,
        camera_rays: &[Ray; N],
        streams: &[SampleStream<'a>; N],
        mut live: u32,
        rays: &mut u64,
    ) -> [Vec3; N] {
        let mut streams = LaneStreams::new(streams);
        let mut paths: [PathState; N] = std::array::from_fn(|lane| PathState {
            // Unit directions from here on (BSDF samples are unit vectors): `wo` needs no
            // normalisation, and a hit's `t` is its distance, which the light pdf of an emitter
            // hit uses.
            ray: Ray::new(camera_rays[lane].origin, camera_rays[lane].dir.normalize()),
            throughput: Vec3::ONE,
            radiance: Vec3::ZERO,
            previous_pdf: f32::INFINITY,
            depth: 0,
        });
        let mut shadows: [Option<ShadowTest>; N] = std::array::from_fn(|_| None);
        let mut surfaces = [SurfacePoint::default(); N];
        let diffuse_together = world.isa() >= Isa::Avx2;
        while live != 0 {
            *rays += u64::from(live.count_ones());
            // A plain loop: closures passed to `array::from_fn` may be left out of line.
            let mut hits: [Option<Hit>; N] = [None; N];
            for lane in lanes_of(live) {
                hits[lane] = world.intersect(&paths[lane].ray);
                if let Some(hit) = &hits[lane] {
                    world.prefetch_hit(hit);
                }
            }
            for lane in lanes_of(live) {
                match hits[lane] {
                    Some(hit) if self.arrive(world, &mut paths[lane], &hit) => {}
                    _ => {
                        live &= !(1 << lane);
                        hits[lane] = None;
                    }
                }
            }
            // The surface points of the paths that go on, together (`World::surface_rows`): their
            // corners' loads issue one after the other instead of each heading its own lane's
            // chain of square roots and divisions. The staircase took 6% less time, the Cornell
            // box the same.
            let mut rays_in = [paths[0].ray; N];
            for (ray, path) in rays_in.iter_mut().zip(&paths) {
                *ray = path.ray;
            }
            let rows = world.surface_rows(&rays_in, &hits);
            for lane in lanes_of(live) {
                let Some(hit) = hits[lane] else { continue };
                surfaces[lane] = rows.point(lane, hit.triangle, world.material_of(hit.triangle));
                world.prefetch_bsdf(&surfaces[lane]);
            }
            // The vertices' numbers, for all lanes at once, dead ones included: the hashes vectorise.
            let (light, scatter, survival) = world.simd_256(
                #[inline(always)]
                || (streams.next_2d(), streams.next_2d(), streams.next_1d()),
            );
            // Diffuse vertices are scattered together (`diffuse.rs`), the others one by one, as are
            // all under the estimators kept for tests (the lane loop has the renderer's weight)
            // and on ISAs narrower than AVX2, where the loop's four lanes measured slower (the
            // Cornell box +6% with SSE2).
            let mut diffuse = DiffuseVertices::<N>::default();
            let mut diffuse_lanes = 0u32;
            for lane in lanes_of(live) {
                let numbers = VertexNumbers { light: light[lane], scatter: scatter[lane], survival: survival[lane] };
                let bsdf = world.bsdf(&surfaces[lane]);
                if let (MaterialBsdf::Lambert(lambert), PathStrategy::Mis, true) =
                    (bsdf, self.strategy, diffuse_together)
                {
                    self.gather_diffuse(
                        world,
                        &paths[lane],
                        &surfaces[lane],
                        lambert.reflectance,
                        &numbers,
                        lane,
                        &mut diffuse,
                    );
                    diffuse_lanes |= 1 << lane;
                    continue;
                }
                let (continues, shadow) = self.scatter(world, &mut paths[lane], &surfaces[lane], bsdf, &numbers);
                if !continues {
                    live &= !(1 << lane);
                }
                shadows[lane] = shadow;
            }
            if diffuse_lanes != 0 {
                live &= !scatter_diffuse(world, &diffuse, diffuse_lanes, &mut paths, &mut shadows);
            }
            for (path, shadow) in paths.iter_mut().zip(&mut shadows) {
                if let Some(test) = shadow.take() {
                    *rays += 1;
                    if !world.occluded(&test.segment) {
                        path.radiance += test.contribution;
                    }
                }
            }
        }
        paths.map(|path| path.radiance)
    }

    /// `path`'s ray meeting `hit`: adds the emission found there. False if the path ends here.
    #[inline(always)]
    fn arrive(&self, world: &World, path: &mut PathState, hit: &Hit) -> bool {
        let lights = world.lights();
        let ray = path.ray;
        // Emission: the light this ray found, weighted against having sampled it as a light.
        if let Some(light) = lights.light_of(hit.triangle) {
            let emitted = lights.lights()[light as usize].radiance_towards(-ray.dir);
            if emitted != Vec3::ZERO {
                let weight = if path.previous_pdf.is_finite() {
                    self.hit_weight(path.previous_pdf, lights.pdf_li(SELECTION, light, ray.dir, hit.t))
                } else {
                    1.0
                };
                path.radiance += path.throughput * emitted * weight;
            }
        }
        path.depth += 1;
        self.max_depth == 0 || path.depth < self.max_depth
    }

    /// The vertex at `surface`, where `path` arrived: draws the light sample (returned for its
    /// shadow test) and the next direction. False if the path ends here.
    ///
    /// Out of line: inlined into `trace`'s loop, the Cornell box took 4% longer (its BSDF sampling
    /// and sampler calls were laid out worse).
    #[inline(never)]
    fn scatter(
        &self,
        world: &World,
        path: &mut PathState,
        surface: &SurfacePoint,
        bsdf: MaterialBsdf,
        numbers: &VertexNumbers,
    ) -> (bool, Option<ShadowTest>) {
        let lights = world.lights();
        let ray = path.ray;
        // Opaque lobes scatter on the viewer's side, where `ns` is turned; a transmissive one
        // needs its own orientation (`wo.z < 0` means inside), so its frame keeps the normal's.
        let normal = if bsdf.transmits() && !surface.front_face { -surface.ns } else { surface.ns };
        let frame = Frame::from_normal(normal);
        let wo = frame.to_local(-ray.dir);
        let vertex = Vertex { surface, bsdf, frame, wo };
        // Next-event estimation: one point on a light chosen by power (not through a delta lobe,
        // which no light point can hit), both from one 2D point so that they stratify together.
        let sample = match self.strategy {
            PathStrategy::BsdfOnly => None,
            _ if bsdf.is_delta() => None,
            _ => lights.sample_li_reusing(SELECTION, surface.p, numbers.light),
        };
        let mut shadow = None;
        if let Some(sample) = sample {
            let (f_cos, local) = vertex.f_cos(sample.wi);
            if f_cos != Vec3::ZERO {
                let weight = self.light_weight_over_pdf(sample.pdf, vertex.bsdf.pdf(wo, local));
                shadow = Some(ShadowTest {
                    segment: surface.spawn_segment(sample.target),
                    contribution: path.throughput * f_cos * sample.li * weight,
                });
            }
        }

        // BSDF sampling: where the path goes next.
        let Some(scattered) = vertex.bsdf.sample(wo, numbers.scatter) else { return (false, shadow) };
        let wi = frame.to_world(scattered.wi);
        if !vertex.sides_agree(wi, scattered.wi) {
            return (false, shadow);
        }
        path.throughput *= scattered.f * (scattered.wi.z.abs() / scattered.pdf);
        // A weight gone infinite or NaN (a pdf underflowing to 0) could only spoil the pixel's
        // sample, which the film would then discard: end the path with what it has found.
        if !path.throughput.is_finite() {
            return (false, shadow);
        }
        let specular = scattered.flags.contains(BsdfFlags::SPECULAR);
        path.previous_pdf = if specular { f32::INFINITY } else { scattered.pdf };
        path.ray = surface.spawn_ray(wi);

        // Russian roulette, after `rr_depth` segments: survive with probability q, weigh by 1/q.
        if path.depth >= self.rr_depth {
            let q = path.throughput.max_element().min(0.95);
            if numbers.survival >= q {
                return (false, shadow);
            }
            path.throughput /= q;
        }
        (true, shadow)
    }

    /// Fills lane `lane` of `diffuse` with the vertex at `surface` of `path`, Lambertian of
    /// `reflectance`: what [`Path::scatter`] would read, and the light it would choose.
    #[expect(clippy::too_many_arguments, reason = "the vertex in its parts, and where it goes")]
    #[inline(always)]
    fn gather_diffuse<const N: usize>(
        &self,
        world: &World,
        path: &PathState,
        surface: &SurfacePoint,
        reflectance: Vec3,
        numbers: &VertexNumbers,
        lane: usize,
        diffuse: &mut DiffuseVertices<N>,
    ) {
        let rows = [
            (&mut diffuse.p, surface.p),
            (&mut diffuse.ng, surface.ng),
            (&mut diffuse.ns, surface.ns),
            (&mut diffuse.dir, path.ray.dir),
            (&mut diffuse.throughput, path.throughput),
            (&mut diffuse.reflectance, reflectance),
        ];
        for (rows, v) in rows {
            set_row(rows, lane, v);
        }
        // `LightSet::sample_li_reusing`'s choice (none in a scene without lights).
        let lights = world.lights();
        if let Some((index, pmf, remapped)) = lights.choose_remapped(SELECTION, numbers.light.x) {
            diffuse.light.choose(lane, &lights.lights()[index as usize], pmf);
            diffuse.light_point[lane] = Vec2::new(remapped, numbers.light.y);
        }
        diffuse.scatter_point[lane] = numbers.scatter;
        diffuse.survival[lane] = numbers.survival;
        diffuse.roulette |= u32::from(path.depth >= self.rr_depth) << lane;
    }
}

/// Scatters the diffuse vertices of `lanes` filled in `diffuse` together, and sets their paths
/// and shadow tests as [`Path::scatter`] would; returns the lanes whose paths end.
fn scatter_diffuse<const N: usize>(
    world: &World,
    diffuse: &DiffuseVertices<N>,
    lanes: u32,
    paths: &mut [PathState; N],
    shadows: &mut [Option<ShadowTest>; N],
) -> u32 {
    let out = world.simd_256(
        #[inline(always)]
        || diffuse.scatter(mis_light_weight_over_pdf),
    );
    for lane in lanes_of(lanes & out.shadowed) {
        shadows[lane] = Some(ShadowTest { segment: out.segment(lane), contribution: row(&out.contribution, lane) });
    }
    for lane in lanes_of(lanes & out.continues) {
        let path = &mut paths[lane];
        path.throughput = row(&out.throughput, lane);
        path.previous_pdf = out.pdf[lane];
        path.ray = out.ray(lane);
    }
    lanes & !out.continues
}

impl Integrator for Path {
    fn radiance(&self, world: &World, camera_ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        let [radiance] = self.trace(world, &[*camera_ray], &[ctx.stream], 1, &mut ctx.rays);
        radiance
    }

    fn radiance_packet<'a>(
        &self,
        world: &World,
        camera: &CameraPacket<'a>,
        ctx: &mut SampleContext<'a>,
    ) -> [Vec3; PACKET] {
        self.trace(world, &camera.rays, &camera.streams, camera.live, &mut ctx.rays)
    }
}

#[cfg(test)]
mod tests {
    use super::mis_light_weight_over_pdf;

    /// The power heuristic's weight of the light sample over its density, `l / (l² + b²)`, in
    /// `f64`, whose squares neither overflow nor underflow for any finite `f32` density.
    fn weight_over_pdf(l: f32, b: f32) -> f64 {
        let (l, b) = (f64::from(l), f64::from(b));
        l / (l * l + b * b)
    }

    /// The one-division form `l / (l² + b²)` breaks where the `f32` squares do: both densities so
    /// small that the sum underflows to 0, or an infinite light density (∞ / ∞). There the function
    /// falls back on the power heuristic over `l`, which must give the same value: `l / (l² + b²)`
    /// for tiny densities, and 0 for an infinite one (the weight 1 spread over an infinite density).
    #[test]
    fn mis_light_weight_over_pdf_holds_where_the_squares_underflow_or_overflow() {
        for (l, b) in [(1e-30f32, 1e-30f32), (1e-30, 0.0), (2e-25, 5e-25), (1e-23, 1e-24)] {
            assert_eq!(l * l + b * b, 0.0, "the squares of {l} and {b} underflow in f32");
            let (got, want) = (f64::from(mis_light_weight_over_pdf(l, b)), weight_over_pdf(l, b));
            assert!((got - want).abs() <= 1e-5 * want, "l {l}, b {b}: {got}, expected {want}");
        }
        for b in [0.0, 1.0, 1e30] {
            assert_eq!(mis_light_weight_over_pdf(f32::INFINITY, b), 0.0, "l ∞, b {b}");
        }
    }
}
