//! Integrators: one file per technique, all computing the radiance arriving along a camera ray.

mod ao;
mod direct;
mod hits;
mod materials;
mod shadows;

use glam::{Vec2, Vec3};

use crate::accel::OriginBatch;
use crate::math::Ray;
use crate::sampler::Sampler;
use crate::world::World;

pub use ao::AmbientOcclusion;
pub use direct::{Direct, LightSampling};
pub use hits::Hits;
pub use materials::Materials;
pub use shadows::Shadows;

/// What a render computes per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mode {
    /// 1 where the camera ray hits a triangle, 0 elsewhere (lab figure 1).
    Hits,
    /// Diffuse colour Kd of the hit triangle (lab figure 2).
    Materials,
    /// Direct light from each light triangle's centroid, one shadow ray each (lab figure 3).
    Shadows,
    /// Direct light integrated over the area lights with N samples (lab figures 4-6).
    Direct,
    /// Ambient occlusion with N cosine-weighted directions (lab figures 7-9).
    AmbientOcclusion,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Hits => "hits",
            Mode::Materials => "materials",
            Mode::Shadows => "shadows",
            Mode::Direct => "direct",
            Mode::AmbientOcclusion => "ao",
        }
    }
}

/// Sample dimensions, numbered once here so that no two uses of the sampler collide.
pub mod dims {
    /// Position inside the pixel (anti-aliasing jitter).
    pub const PIXEL: u32 = 0;
    /// Which light, for power-proportional light selection.
    pub const LIGHT_CHOICE: u32 = 1;
    /// Hemisphere direction, for ambient occlusion.
    pub const HEMISPHERE: u32 = 2;
    /// Point on a light; per-light sampling uses `LIGHT_POINT + light index`.
    pub const LIGHT_POINT: u32 = 3;
}

/// Per-sample state handed to an integrator: where the sample is, its random numbers, and a count
/// of the rays it traces (visibility queries included).
#[derive(Debug)]
pub struct SampleContext<'a> {
    pub sampler: &'a Sampler,
    /// Reused buffer for shared-origin ray batches (one per thread, never shared).
    pub batch: OriginBatch,
    /// `y * width + x`.
    pub pixel: u32,
    /// Index of this camera sample within its pixel (0 .. spp).
    pub sample: u32,
    pub rays: u64,
}

impl<'a> SampleContext<'a> {
    pub fn new(sampler: &'a Sampler) -> Self {
        SampleContext { sampler, batch: OriginBatch::default(), pixel: 0, sample: 0, rays: 0 }
    }

    /// The `k`-th of `n` 2D points of `dimension` for this camera sample. Consecutive camera samples
    /// own consecutive blocks of `n` indices, so a stratified sampler stratifies across all of them.
    #[inline]
    pub fn point_2d(&self, dimension: u32, k: u32, n: u32) -> Vec2 {
        self.sampler.get_2d(self.pixel, self.sample * n + k, dimension)
    }

    #[inline]
    pub fn point_1d(&self, dimension: u32, k: u32, n: u32) -> f32 {
        self.sampler.get_1d(self.pixel, self.sample * n + k, dimension)
    }
}

/// Radiance along a camera ray. Implemented by plain structs and used through generics, so the
/// per-ray path has no dynamic dispatch.
pub trait Integrator: Sync {
    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3;
}
