//! Integrators: one file per technique, all computing the radiance arriving along a camera ray.

mod hits;
mod materials;
mod shadows;

use glam::Vec3;

use crate::math::Ray;
use crate::world::World;

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
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Hits => "hits",
            Mode::Materials => "materials",
            Mode::Shadows => "shadows",
        }
    }
}

/// Per-sample state handed to an integrator; counts the rays it traces.
#[derive(Debug, Default)]
pub struct SampleContext {
    pub rays: u64,
}

/// Radiance along a camera ray. Implemented by plain structs and used through generics, so the
/// per-ray path has no dynamic dispatch.
pub trait Integrator: Sync {
    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3;
}
