use glam::Vec3;

use super::{CameraPacket, Integrator, PACKET, SampleContext};
use crate::math::Ray;
use crate::world::World;

/// White where the camera ray hits something, black elsewhere.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hits;

impl Integrator for Hits {
    const PACKETS: bool = true;

    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        if world.occluded(ray) { Vec3::ONE } else { Vec3::ZERO }
    }

    fn radiance_packet<'a>(
        &self,
        world: &World,
        camera: &CameraPacket<'a>,
        ctx: &mut SampleContext<'a>,
    ) -> [Vec3; PACKET] {
        ctx.rays += u64::from(camera.live.count_ones());
        let blocked = world.occluded_packet(&camera.rays, camera.live);
        std::array::from_fn(|lane| if blocked & (1 << lane) != 0 { Vec3::ONE } else { Vec3::ZERO })
    }
}
