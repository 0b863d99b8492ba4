use glam::Vec3;

use super::{SampleContext, ShadesClosestHit};
use crate::geometry::surface::SurfacePoint;
use crate::materials::Bsdf;
use crate::math::Ray;
use crate::world::World;

/// The colour (albedo) of the first surface hit, its texture included.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Materials;

impl ShadesClosestHit for Materials {
    fn shade(&self, world: &World, _: &Ray, surface: Option<&SurfacePoint>, _: &mut SampleContext) -> Vec3 {
        surface.map_or(Vec3::ZERO, |surface| world.bsdf(surface).albedo())
    }
}
