use glam::Vec3;

use super::{SampleContext, ShadesClosestHit};
use crate::accel::Hit;
use crate::materials::Bsdf;
use crate::math::Ray;
use crate::world::World;

/// The colour (albedo) of the first surface hit, its texture included.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Materials;

impl ShadesClosestHit for Materials {
    fn shade(&self, world: &World, ray: &Ray, hit: Option<Hit>, _: &mut SampleContext) -> Vec3 {
        hit.map_or(Vec3::ZERO, |hit| world.bsdf(&world.surface(ray, &hit)).albedo())
    }
}
