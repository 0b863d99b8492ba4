use glam::Vec3;

use super::{Integrator, SampleContext};
use crate::materials::Bsdf;
use crate::math::Ray;
use crate::world::World;

/// The colour (albedo) of the first surface hit, its texture included.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Materials;

impl Integrator for Materials {
    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        world.intersect(ray).map_or(Vec3::ZERO, |hit| world.bsdf(&world.surface(ray, &hit)).albedo())
    }
}
