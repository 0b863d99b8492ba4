use glam::{Vec2, Vec3};

use super::{CameraPacket, Integrator, PACKET, SampleContext, shading_frame};
use crate::accel::simd::{all_lanes, lanes_of};
use crate::accel::{Hit, OriginBatch};
use crate::geometry::surface::{SurfacePoint, offset_origin};
use crate::geometry::surface_lanes::SurfaceRows;
use crate::lights::AreaLight;
use crate::materials::{Bsdf, Lambert, MaterialBsdf};
use crate::math::rows::{row, set_row};
use crate::math::{Frame, Ray, offset_ray_origin};
use crate::world::World;

/// The lab's hard shadows: every light triangle acts as a point light at its centroid carrying the
/// triangle's area, `L = sum Ke * f * cos(theta) * cos(theta_light) * area / d^2 * V`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shadows;

impl Integrator for Shadows {
    const PACKETS: bool = true;

    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        let receiver = match Receiver::lit_hit(world, ray, world.intersect(ray)) {
            Ok(hit) => Receiver::new(world, ray, world.surface(ray, &hit)),
            Err(radiance) => return radiance,
        };
        let mut sum = Vec3::ZERO;
        for (index, light) in world.lights().lights().iter().enumerate() {
            // Thousands of lights make a long pixel (the staircase's bulbs: 6,430).
            if ctx.must_stop(index as u32) {
                break;
            }
            let point = LightPoint::of(world, index, light);
            if let Some((segment, contribution)) = receiver.unshadowed(light, &point) {
                ctx.rays += 1;
                if !point.occluded(world, &segment) {
                    sum += contribution;
                }
            }
        }
        sum
    }

    /// The camera rays of the block as a packet, then for each light the block's shadow rays
    /// towards its centroid together: read backwards, as rays from that point, against the
    /// light's batch of candidates ([`World::hard_shadow_batch`]), or else as a packet (they share
    /// an end point, so they are as coherent as the camera rays). Each lane adds its lights in the
    /// same order as `radiance`, and asks the same test: the same bits.
    ///
    /// Diffuse receivers (all of the lab's) are lit together, their surface points kept in rows
    /// ([`DiffuseLanes`]); any other is lit one at a time by its [`Receiver`].
    fn radiance_packet<'a>(
        &self,
        world: &World,
        camera: &CameraPacket<'a>,
        ctx: &mut SampleContext<'a>,
    ) -> [Vec3; PACKET] {
        let hits = world.intersect_packet(&camera.rays, camera.live);
        let rows = world.surface_rows(&camera.rays, &hits);
        ctx.rays += u64::from(camera.live.count_ones());
        let mut radiance = [Vec3::ZERO; PACKET];
        let mut diffuse = DiffuseLanes::default();
        let mut others: [Option<Receiver>; PACKET] = [None; PACKET];
        for lane in camera.lanes() {
            let ray = &camera.rays[lane];
            let hit = match Receiver::lit_hit(world, ray, hits[lane]) {
                Ok(hit) => hit,
                Err(value) => {
                    radiance[lane] = value;
                    continue;
                }
            };
            let material = world.material_of(hit.triangle);
            let uv = Vec2::new(rows.uv[0][lane], rows.uv[1][lane]);
            match world.lambert_reflectance(material, uv) {
                Some(reflectance) => diffuse.add(lane, reflectance),
                None => others[lane] = Some(Receiver::new(world, ray, rows.point(lane, hit.triangle, material))),
            }
        }
        if diffuse.live != 0 {
            world.simd(
                #[inline(always)]
                || diffuse.receive(&rows, &camera.rays),
            );
        }
        let mut segments = camera.rays;
        let mut contributions = [Vec3::ZERO; PACKET];
        for (index, light) in world.lights().lights().iter().enumerate() {
            if ctx.must_stop(index as u32) {
                break;
            }
            let point = LightPoint::of(world, index, light);
            // In the ISA's width: the lane loop's square roots and divisions, 16 at a time.
            let mut traced = world.simd(
                #[inline(always)]
                || diffuse.unshadowed(light, &point, &mut segments, &mut contributions),
            );
            for (lane, receiver) in others.iter().enumerate() {
                if let Some((segment, contribution)) = receiver.as_ref().and_then(|r| r.unshadowed(light, &point)) {
                    (segments[lane], contributions[lane]) = (segment, contribution);
                    traced |= 1 << lane;
                }
            }
            if traced == 0 {
                continue;
            }
            ctx.rays += u64::from(traced.count_ones());
            let lit = traced & !point.occluded_lanes(world, &segments, traced);
            for lane in lanes_of(lit) {
                radiance[lane] += contributions[lane];
            }
        }
        radiance
    }
}

/// The diffuse receivers of a packet, SoA: what lighting them needs, and nothing else. Filled in
/// two steps: each lane's reflectance ([`DiffuseLanes::add`]), then the rest straight from the
/// packet's surface rows ([`DiffuseLanes::receive`]). Filled a whole [`Receiver`] at a time, the
/// points went from rows to structs and back, and each lane's BSDF was copied through the stack
/// in pieces wider than it was written in: hard shadows took 10% longer.
#[derive(Default)]
struct DiffuseLanes {
    /// Bit `i` set if lane `i` holds a diffuse receiver.
    live: u32,
    p: [[f32; PACKET]; 3],
    ns: [[f32; PACKET]; 3],
    ng: [[f32; PACKET]; 3],
    /// The reflectance, then (once received) the BSDF's constant value.
    f: [[f32; PACKET]; 3],
    /// The surface point moved off the surface to the side of `ng`, where every shadow ray of a
    /// diffuse receiver leaves (`unshadowed` wants `wi` above `ng`): computed once, not per light.
    origin: [[f32; PACKET]; 3],
}

impl DiffuseLanes {
    /// Makes lane `lane` a diffuse receiver of reflectance `reflectance` (its [`Lambert`] BSDF's).
    fn add(&mut self, lane: usize, reflectance: Vec3) {
        self.live |= 1 << lane;
        set_row(&mut self.f, lane, reflectance);
    }

    /// Takes the receivers' points from `rows`, the surface rows of the camera rays `rays`, and
    /// works out each lane's BSDF constant and shadow-ray origin with the operations of
    /// [`Receiver::new`] and [`SurfacePoint::offset_origin`] (the same bits), for every lane:
    /// those that are not receivers compute values no one reads. Run it in the ISA's width.
    #[inline(always)]
    fn receive(&mut self, rows: &SurfaceRows<PACKET>, rays: &[Ray; PACKET]) {
        (self.p, self.ns, self.ng) = (rows.p, rows.ns, rows.ng);
        let mut view = [[0.0f32; PACKET]; 3];
        for (lane, ray) in rays.iter().enumerate() {
            set_row(&mut view, lane, ray.dir);
        }
        for lane in 0..PACKET {
            let (p, ng) = (row(&rows.p, lane), row(&rows.ng, lane));
            let (_, wo) = shading_frame(row(&rows.ns, lane), row(&view, lane));
            let lambert = Lambert { reflectance: row(&self.f, lane) };
            set_row(&mut self.f, lane, lambert.lambertian_eval(wo).unwrap_or(Vec3::ZERO));
            set_row(&mut self.origin, lane, offset_origin(p, ng, ng));
        }
    }

    /// [`Receiver::unshadowed`] for every diffuse lane: writes the shadow segments and
    /// contributions of the lanes the light can reach into `segments` and `contributions`, and
    /// returns those lanes. Each lane does `unshadowed`'s operations in its order (glam's `dot`
    /// and `length_squared` sum x, y, then z), so the bits are its.
    #[inline(always)]
    fn unshadowed(
        &self,
        light: &AreaLight,
        point: &LightPoint,
        segments: &mut [Ray; PACKET],
        contributions: &mut [Vec3; PACKET],
    ) -> u32 {
        if self.live == 0 {
            return 0;
        }
        let (c, n) = (point.centroid.to_array(), light.normal.to_array());
        let (target, emission) = (point.target.to_array(), light.emission.to_array());
        let mut weight = [0.0f32; PACKET];
        let mut reaches = [false; PACKET];
        let mut above_ng = [false; PACKET];
        for lane in 0..PACKET {
            // Arrays written out, not `.map(..)`, whose call is not always inlined (see
            // `direct.rs`): the loop must stay whole to be vectorised.
            let v = [c[0] - self.p[0][lane], c[1] - self.p[1][lane], c[2] - self.p[2][lane]];
            let d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            let length = d2.sqrt();
            let wi = [v[0] / length, v[1] / length, v[2] / length];
            let dot = |rows: &[[f32; PACKET]; 3]| rows[0][lane] * wi[0] + rows[1][lane] * wi[1] + rows[2][lane] * wi[2];
            let cos_surface = dot(&self.ns);
            let cos_light = n[0] * -wi[0] + n[1] * -wi[1] + n[2] * -wi[2];
            reaches[lane] = !(cos_surface <= 0.0 || cos_light <= 0.0 || dot(&self.ng) <= 0.0);
            weight[lane] = cos_surface * cos_light * light.area / d2;
            // `spawn_segment`'s side: the target above `ng` (almost always, once `wi` is).
            let to_target = [target[0] - self.p[0][lane], target[1] - self.p[1][lane], target[2] - self.p[2][lane]];
            above_ng[lane] =
                self.ng[0][lane] * to_target[0] + self.ng[1][lane] * to_target[1] + self.ng[2][lane] * to_target[2]
                    >= 0.0;
        }
        let mut traced = 0;
        for lane in lanes_of(self.live) {
            if !reaches[lane] {
                continue;
            }
            traced |= 1 << lane;
            let f = Vec3::new(self.f[0][lane], self.f[1][lane], self.f[2][lane]);
            contributions[lane] = f * Vec3::from_array(emission) * weight[lane];
            let p = Vec3::new(self.p[0][lane], self.p[1][lane], self.p[2][lane]);
            let ng = Vec3::new(self.ng[0][lane], self.ng[1][lane], self.ng[2][lane]);
            let origin = if above_ng[lane] {
                Vec3::new(self.origin[0][lane], self.origin[1][lane], self.origin[2][lane])
            } else {
                offset_ray_origin(p, -ng)
            };
            segments[lane] = Ray::segment(origin, point.target);
        }
        traced
    }
}

/// Where a light triangle acts as a point light: its centroid, and the point on its shadow-target
/// triangle the shadow segments end at, with what tests them. The same for every receiver:
/// computed once per light.
struct LightPoint<'w> {
    centroid: Vec3,
    target: Vec3,
    /// The light's normal: the side of `target` the segments' batch covers.
    normal: Vec3,
    /// The triangles that may block a segment ending at `target`, if gathered.
    batch: Option<&'w OriginBatch>,
}

impl<'w> LightPoint<'w> {
    #[inline]
    fn of(world: &'w World, index: usize, light: &AreaLight) -> LightPoint<'w> {
        LightPoint {
            centroid: light.centroid(),
            target: light.hard_shadow_target(),
            normal: light.normal,
            batch: world.hard_shadow_batch(index),
        }
    }

    /// The direction of the segment from `origin` to the target read backwards, from the target,
    /// if it leaves into the half-space the batch covers: the origin lies in front of the target
    /// (a receiver the light reaches almost always does; one just in front of the light's plane
    /// may not).
    #[inline(always)]
    fn reversed(&self, origin: Vec3) -> Option<Vec3> {
        let dir = origin - self.target;
        (self.normal.dot(dir) > 0.0).then_some(dir)
    }

    /// Whether something blocks `segment`, a segment towards the target: the batch's test of the
    /// segment read backwards, or else the BVH's.
    #[inline]
    fn occluded(&self, world: &World, segment: &Ray) -> bool {
        if let Some(batch) = self.batch
            && let Some(dir) = self.reversed(segment.origin)
        {
            return world.occluded_in_batch(batch, &Ray { origin: self.target, dir, tmax: 1.0 });
        }
        world.occluded(segment)
    }

    /// [`LightPoint::occluded`] for the lanes `traced` of `segments`, bit `i` set if segment `i`
    /// is blocked: those the batch takes tested together, ray-major (with the operations of the
    /// batch's ray-by-ray test, so the same answers), the others as a packet.
    #[inline]
    fn occluded_lanes(&self, world: &World, segments: &[Ray; PACKET], traced: u32) -> u32 {
        let (mut reversed, mut blocked) = (0u32, 0u32);
        if let Some(batch) = self.batch {
            let mut dirs = [[0.0f32; PACKET]; 3];
            for lane in lanes_of(traced) {
                if let Some(dir) = self.reversed(segments[lane].origin) {
                    set_row(&mut dirs, lane, dir);
                    reversed |= 1 << lane;
                }
            }
            if reversed != 0 {
                // The other lanes repeat a reversed one, so that the test can stop once all are
                // blocked.
                let first = reversed.trailing_zeros() as usize;
                for lane in lanes_of(!reversed & const { all_lanes(PACKET) }) {
                    for row in &mut dirs {
                        row[lane] = row[first];
                    }
                }
                blocked = reversed
                    & world.simd(
                        #[inline(always)]
                        || world.occluded_lanes_in_batch(batch, &dirs, 1.0, reversed),
                    );
            }
        }
        let rest = traced & !reversed;
        if rest != 0 {
            blocked |= rest & world.occluded_packet(segments, rest);
        }
        blocked
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
    /// The camera ray's closest hit if lights reach the pixel there, or else the pixel's final
    /// value: black for a miss, the emission of a light seen from the side it faces (from behind
    /// it is a surface).
    #[inline]
    fn lit_hit(world: &World, ray: &Ray, hit: Option<Hit>) -> Result<Hit, Vec3> {
        let Some(hit) = hit else { return Err(Vec3::ZERO) };
        let emitted = world.emitted(hit.triangle, ray);
        if emitted != Vec3::ZERO {
            return Err(emitted);
        }
        Ok(hit)
    }

    /// The receiver at `surface`, the surface point of a hit that [`Receiver::lit_hit`] let
    /// through.
    #[inline]
    fn new(world: &World, ray: &Ray, surface: SurfacePoint) -> Receiver {
        let bsdf = world.bsdf(&surface);
        let (frame, wo) = shading_frame(surface.ns, ray.dir);
        Receiver { surface, bsdf, lambertian: bsdf.lambertian_eval(wo), frame, wo }
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
