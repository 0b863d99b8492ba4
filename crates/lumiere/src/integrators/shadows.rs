use glam::Vec3;

use super::{CameraPacket, Integrator, PACKET, SampleContext, shading_frame};
use crate::accel::Hit;
use crate::accel::simd::lanes_of;
use crate::geometry::surface::SurfacePoint;
use crate::lights::AreaLight;
use crate::materials::{Bsdf, MaterialBsdf};
use crate::math::{Frame, Ray};
use crate::world::World;

/// The lab's hard shadows: every light triangle acts as a point light at its centroid carrying the
/// triangle's area, `L = sum Ke * f * cos(theta) * cos(theta_light) * area / d^2 * V`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shadows;

impl Integrator for Shadows {
    const PACKETS: bool = true;

    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        let receiver = match Receiver::new(world, ray, world.intersect(ray)) {
            Ok(receiver) => receiver,
            Err(radiance) => return radiance,
        };
        let mut sum = Vec3::ZERO;
        for light in world.lights().lights() {
            if let Some((segment, contribution)) = receiver.unshadowed(light, &LightPoint::of(light)) {
                ctx.rays += 1;
                if !world.occluded(&segment) {
                    sum += contribution;
                }
            }
        }
        sum
    }

    /// The camera rays of the block as a packet, then for each light the block's shadow rays
    /// towards its centroid as a packet: they share an end point, so they are as coherent as the
    /// camera rays. Each lane adds its lights in the same order as `radiance`: the same bits.
    fn radiance_packet<'a>(
        &self,
        world: &World,
        camera: &CameraPacket<'a>,
        ctx: &mut SampleContext<'a>,
    ) -> [Vec3; PACKET] {
        let hits = world.intersect_packet(&camera.rays, camera.live);
        ctx.rays += u64::from(camera.live.count_ones());
        let mut radiance = [Vec3::ZERO; PACKET];
        let mut receivers: [Option<Receiver>; PACKET] = [None; PACKET];
        for lane in camera.lanes() {
            match Receiver::new(world, &camera.rays[lane], hits[lane]) {
                Ok(receiver) => receivers[lane] = Some(receiver),
                Err(value) => radiance[lane] = value,
            }
        }
        let mut segments = camera.rays;
        let mut contributions = [Vec3::ZERO; PACKET];
        for light in world.lights().lights() {
            let point = LightPoint::of(light);
            let mut traced = 0u32;
            for (lane, receiver) in receivers.iter().enumerate() {
                if let Some((segment, contribution)) = receiver.as_ref().and_then(|r| r.unshadowed(light, &point)) {
                    (segments[lane], contributions[lane]) = (segment, contribution);
                    traced |= 1 << lane;
                }
            }
            if traced == 0 {
                continue;
            }
            ctx.rays += u64::from(traced.count_ones());
            let lit = traced & !world.occluded_packet(&segments, traced);
            for lane in lanes_of(lit) {
                radiance[lane] += contributions[lane];
            }
        }
        radiance
    }
}

/// Where a light triangle acts as a point light: its centroid, and the point on its shadow-target
/// triangle the shadow segments end at. The same for every receiver: computed once per light.
struct LightPoint {
    centroid: Vec3,
    target: Vec3,
}

impl LightPoint {
    #[inline]
    fn of(light: &AreaLight) -> LightPoint {
        LightPoint { centroid: light.centroid(), target: light.shadow_target(Vec3::splat(1.0 / 3.0)) }
    }
}

/// A surface point seen by a camera ray, ready to be lit.
#[derive(Clone, Copy)]
struct Receiver {
    surface: SurfacePoint,
    bsdf: MaterialBsdf,
    /// The BSDF's value wherever it is not zero, for a diffuse surface (`Bsdf::lambertian_eval`):
    /// no evaluation per light then.
    lambertian: Option<Vec3>,
    frame: Frame,
    wo: Vec3,
}

impl Receiver {
    /// The receiver at the camera ray's closest hit, or the pixel's final value: black for a
    /// miss, the emission of a light seen from the side it faces (from behind it is a surface).
    #[inline]
    fn new(world: &World, ray: &Ray, hit: Option<Hit>) -> Result<Receiver, Vec3> {
        let Some(hit) = hit else { return Err(Vec3::ZERO) };
        let emitted = world.emitted(hit.triangle, ray);
        if emitted != Vec3::ZERO {
            return Err(emitted);
        }
        let surface = world.surface(ray, &hit);
        let bsdf = world.bsdf(&surface);
        let (frame, wo) = shading_frame(surface.ns, ray);
        Ok(Receiver { surface, bsdf, lambertian: bsdf.lambertian_eval(wo), frame, wo })
    }

    /// The shadow ray towards `light`'s centroid and the light it brings if nothing blocks it, or
    /// `None` when the light cannot reach the surface (no ray is traced then).
    #[inline]
    fn unshadowed(&self, light: &AreaLight, point: &LightPoint) -> Option<(Ray, Vec3)> {
        let surface = &self.surface;
        let to_light = point.centroid - surface.p;
        let d2 = to_light.length_squared();
        let wi = to_light / d2.sqrt();
        let cos_surface = surface.ns.dot(wi);
        let cos_light = light.normal.dot(-wi);
        if cos_surface <= 0.0 || cos_light <= 0.0 || surface.ng.dot(wi) <= 0.0 {
            return None;
        }
        // A diffuse BSDF is its constant wherever `wi` is above `ns` (`cos_surface > 0` here).
        let f = self.lambertian.unwrap_or_else(|| self.bsdf.eval(self.wo, self.frame.to_local(wi)));
        // The segment ends on the light's shadow-target triangle, just in front of the light.
        Some((surface.spawn_segment(point.target), f * light.emission * (cos_surface * cos_light * light.area / d2)))
    }
}
