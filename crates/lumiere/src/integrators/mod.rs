//! Integrators: one file per technique, each computing the radiance arriving along a camera ray.
//! A technique's options are the fields of its integrator; [`Technique`] lists them all.

mod ao;
mod direct;
mod hits;
mod materials;
mod path;
mod shadows;

use glam::Vec3;

use crate::accel::OriginBatch;
use crate::accel::simd::lanes_of;
use crate::error::{Error, Result};
use crate::geometry::surface::SurfacePoint;
use crate::math::{Frame, Ray};
use crate::sampler::SampleStream;
use crate::world::World;

pub use ao::AmbientOcclusion;
pub use direct::{Direct, LightSampling};
pub use hits::Hits;
pub use materials::Materials;
pub use path::{Path, PathStrategy};
pub use shadows::Shadows;

/// What a render computes per pixel, with the options of that technique.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Technique {
    /// 1 where the camera ray hits a triangle, 0 elsewhere (lab figure 1).
    Hits(Hits),
    /// The colour of the hit surface (lab figure 2).
    Materials(Materials),
    /// Direct light from each light triangle's centroid, one shadow ray each (lab figure 3).
    Shadows(Shadows),
    /// Direct light integrated over the area lights with N samples (lab figures 4-6).
    Direct(Direct),
    /// Ambient occlusion with N cosine-weighted directions (lab figures 7-9).
    AmbientOcclusion(AmbientOcclusion),
    /// Global illumination: path tracing with next-event estimation and MIS.
    Path(Path),
}

impl Technique {
    /// The lab's soft shadows: `samples` points on every light triangle.
    pub fn direct(samples: u32) -> Technique {
        Technique::Direct(Direct { samples, light_sampling: LightSampling::PerLight })
    }

    /// The lab's ambient occlusion: `samples` directions, visibility of the sky.
    pub fn ambient_occlusion(samples: u32) -> Technique {
        Technique::AmbientOcclusion(AmbientOcclusion { samples, distance: f32::INFINITY })
    }

    /// The name of the technique on the command line (`--mode`).
    pub fn name(&self) -> &'static str {
        match self {
            Technique::Hits(_) => "hits",
            Technique::Materials(_) => "materials",
            Technique::Shadows(_) => "shadows",
            Technique::Direct(_) => "direct",
            Technique::AmbientOcclusion(_) => "ao",
            Technique::Path(_) => "path",
        }
    }

    /// Refuses options no render could use.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Technique::Direct(Direct { samples: 0, .. })
            | Technique::AmbientOcclusion(AmbientOcclusion { samples: 0, .. }) => {
                Err(Error::invalid("the samples per point (samples) must be at least 1"))
            }
            Technique::AmbientOcclusion(AmbientOcclusion { distance, .. }) if distance.is_nan() || distance <= 0.0 => {
                Err(Error::invalid(format!("the ambient occlusion distance must be positive, got {distance}")))
            }
            _ => Ok(()),
        }
    }
}

/// Per-sample state handed to an integrator: its random numbers, reusable scratch space, and a count
/// of the rays it traces (visibility queries included).
pub struct SampleContext<'a> {
    /// This camera sample's random numbers; the pixel position has taken the first dimension.
    pub stream: SampleStream<'a>,
    /// Reused buffer for shared-origin ray batches (one per thread, never shared).
    pub batch: OriginBatch,
    pub rays: u64,
    /// True once the render must stop (Ctrl-C, time budget). Integrators whose pixels can take
    /// long (thousands of samples or lights) poll it every [`STOP_POLL`] samples or lights
    /// ([`SampleContext::must_stop`]) and return early;
    /// the pass is then abandoned, so the value they return is never used.
    pub stop: &'a (dyn Fn() -> bool + Sync),
}

/// Samples between two polls of [`SampleContext::stop`]: rare enough to cost nothing, often
/// enough to stop within milliseconds.
pub const STOP_POLL: u32 = 1024;

impl SampleContext<'_> {
    /// Whether the render must stop, polled at sample (or light) `k` of a long loop (every
    /// `STOP_POLL`).
    #[inline]
    pub fn must_stop(&self, k: u32) -> bool {
        k % STOP_POLL == STOP_POLL - 1 && (self.stop)()
    }
}

/// Rays from one origin drawn and tested together (ambient occlusion's probes, direct light's
/// shadow rays): [`WIDE_GROUP`] (two AVX-512 registers of f32) while a batch has that many left,
/// then [`NARROW_GROUP`] (one). Twice the rays per broadcast triangle or walked node, and two
/// independent chains of arithmetic: against sixteen at a time (1 thread), ambient occlusion at
/// N = 256 on the Cornell box (four batches of 64) 13% faster, the 1.1M-triangle bunny's (walked)
/// 8%; sixteen probes per point in groups of 32, half of them idle, were 32% slower.
pub const WIDE_GROUP: usize = 32;
pub const NARROW_GROUP: usize = 16;

/// Pixels shaded together: a block of 4x4, whose camera rays are traced as a packet.
pub const PACKET: usize = 16;

/// The camera samples of up to [`PACKET`] pixels: lane `i` has a ray and its sample's random numbers
/// if bit `i` of `live` is set (the other lanes repeat a live one and are never shaded).
pub struct CameraPacket<'a> {
    pub rays: [Ray; PACKET],
    pub streams: [SampleStream<'a>; PACKET],
    pub live: u32,
}

impl CameraPacket<'_> {
    /// The live lanes, in order.
    pub fn lanes(&self) -> impl Iterator<Item = usize> + use<> {
        lanes_of(self.live)
    }
}

/// Radiance along a camera ray. Implemented by plain structs and used through generics, so the
/// per-ray path has no dynamic dispatch.
pub trait Integrator: Sync {
    /// Whether [`Integrator::radiance_packet`] traces the packet's rays together, in the ISA's
    /// full vector width ([`World::simd`]); the pass then computes the camera rays in that width
    /// too. Integrators that trace one ray at a time keep them in the baseline width: computing them
    /// in 512-bit registers made the path tracer, which runs no 512-bit code of its own, 6-7% slower
    /// (a change of clock licence or of register state; this machine could not tell which).
    const PACKETS: bool = false;

    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3;

    /// The radiance of every live lane of `camera` (zero elsewhere): exactly what
    /// [`Integrator::radiance`] returns for each, with each lane's stream. One by one unless the
    /// integrator traces the packet's rays together.
    fn radiance_packet<'a>(
        &self,
        world: &World,
        camera: &CameraPacket<'a>,
        ctx: &mut SampleContext<'a>,
    ) -> [Vec3; PACKET] {
        let mut radiance = [Vec3::ZERO; PACKET];
        for lane in camera.lanes() {
            ctx.stream = camera.streams[lane];
            radiance[lane] = self.radiance(world, &camera.rays[lane], ctx);
        }
        radiance
    }
}

/// An integrator whose radiance is a function of the camera ray's closest hit: it gets
/// [`Integrator`] from this, with the hits of a packet's camera rays found together
/// ([`World::intersect_packet`]) and their surface points computed together ([`World::surfaces`]).
pub trait ShadesClosestHit: Sync {
    /// The radiance along the camera ray `ray`, whose closest hit has the surface point `surface`
    /// (`None` for a miss; the ray is counted).
    fn shade(&self, world: &World, ray: &Ray, surface: Option<&SurfacePoint>, ctx: &mut SampleContext) -> Vec3;
}

impl<T: ShadesClosestHit> Integrator for T {
    const PACKETS: bool = true;

    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        let surface = world.intersect(ray).map(|hit| world.surface(ray, &hit));
        self.shade(world, ray, surface.as_ref(), ctx)
    }

    fn radiance_packet<'a>(
        &self,
        world: &World,
        camera: &CameraPacket<'a>,
        ctx: &mut SampleContext<'a>,
    ) -> [Vec3; PACKET] {
        let hits = world.intersect_packet(&camera.rays, camera.live);
        let surfaces = world.surfaces(&camera.rays, &hits);
        let mut radiance = [Vec3::ZERO; PACKET];
        for lane in camera.lanes() {
            ctx.stream = camera.streams[lane];
            ctx.rays += 1;
            radiance[lane] = self.shade(world, &camera.rays[lane], hits[lane].map(|_| &surfaces[lane]), ctx);
        }
        radiance
    }
}

/// The shading frame at a surface (`z` = the shading normal) and the direction towards the viewer
/// (who looks along `view`) in it, for BSDF evaluation.
#[inline]
fn shading_frame(ns: Vec3, view: Vec3) -> (Frame, Vec3) {
    let frame = Frame::from_normal(ns);
    let wo = frame.to_local(-view.normalize());
    (frame, wo)
}
