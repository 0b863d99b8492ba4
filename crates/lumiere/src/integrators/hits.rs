use glam::Vec3;

use super::{Integrator, SampleContext};
use crate::math::Ray;
use crate::world::World;

/// White where the camera ray hits something, black elsewhere.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hits;

impl Integrator for Hits {
    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        if world.occluded(ray) { Vec3::ONE } else { Vec3::ZERO }
    }
}
