//! Unidirectional path tracing with next-event estimation and multiple importance sampling.
//!
//! Each vertex of a path adds light in two ways that cover the same paths: a point sampled on a
//! light (next-event estimation) and the light a BSDF-sampled ray happens to hit. Both are weighted
//! with the power heuristic (Veach 1997), so that each contributes where its density is the better
//! one: light sampling for small, bright lights and rough surfaces, BSDF sampling for large lights
//! and glossy lobes. Delta lobes (mirrors, smooth glass) cannot be light-sampled: the light their
//! rays hit counts in full. Russian roulette ends paths whose throughput has become small, and
//! divides the survivors by their survival probability, so the estimate stays unbiased.
//!
//! Depth counts as in Mitsuba 3: `max_depth` 1 shows the emitters the camera sees, 2 adds direct
//! light, 8 allows up to seven bounces; 0 sets no limit (Russian roulette alone ends paths).

use glam::Vec3;

use super::{Integrator, SampleContext};
use crate::geometry::surface::SurfacePoint;
use crate::lights::LightSelection;
use crate::materials::{Bsdf, BsdfFlags};
use crate::math::{Frame, Ray};
use crate::sampling::mis::power_heuristic;
use crate::world::World;

/// Path tracing with next-event estimation and MIS (`--mode path`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Path {
    /// The longest path, in segments from the camera (Mitsuba's `max_depth`); 0 for no limit.
    pub max_depth: u32,
    /// Russian roulette starts after this many segments (Mitsuba's `rr_depth`, 5 by default).
    pub rr_depth: u32,
    pub strategy: PathStrategy,
}

impl Default for Path {
    fn default() -> Self {
        Path { max_depth: 8, rr_depth: 5, strategy: PathStrategy::Mis }
    }
}

/// Which techniques find the light: both with MIS weights (the renderer's), or one of them alone
/// (for tests: all three converge to the same image, with different noise).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum PathStrategy {
    #[default]
    Mis,
    /// Next-event estimation alone: emitters hit by BSDF rays count only through delta lobes.
    LightsOnly,
    /// BSDF sampling alone: light counts only where a ray hits it.
    BsdfOnly,
}

impl Path {
    /// The weight of light found by a BSDF ray of density `bsdf_pdf` that light sampling would have
    /// drawn with density `light_pdf`.
    #[inline]
    fn hit_weight(&self, bsdf_pdf: f32, light_pdf: f32) -> f32 {
        match self.strategy {
            PathStrategy::Mis => power_heuristic(bsdf_pdf, light_pdf),
            PathStrategy::LightsOnly => 0.0,
            PathStrategy::BsdfOnly => 1.0,
        }
    }

    /// The weight of light found by next-event estimation against BSDF sampling, divided by the
    /// light sample's density `light_pdf` (positive): the power heuristic over the density is
    /// `l / (l² + b²)`, one division where weight and density apart take two.
    #[inline]
    fn light_weight_over_pdf(&self, light_pdf: f32, bsdf_pdf: f32) -> f32 {
        match self.strategy {
            PathStrategy::Mis => {
                let w = light_pdf / (light_pdf * light_pdf + bsdf_pdf * bsdf_pdf);
                // `l² + b²` is infinite for an infinite `l` and 0 for a tiny one (the squares
                // overflow or underflow): the ratio form holds there.
                if w.is_finite() { w } else { power_heuristic(light_pdf, bsdf_pdf) / light_pdf }
            }
            PathStrategy::LightsOnly => 1.0 / light_pdf,
            PathStrategy::BsdfOnly => 0.0,
        }
    }
}

/// How lights are chosen for next-event estimation: by power, with the triangle → light map
/// giving the same probability back when a BSDF ray hits an emitter.
const SELECTION: LightSelection = LightSelection::Power;

/// The scattering at one path vertex, in the shading frame.
struct Vertex<'a, B> {
    surface: &'a SurfacePoint,
    bsdf: B,
    frame: Frame,
    wo: Vec3,
}

impl<B: Bsdf> Vertex<'_, B> {
    /// `f · |cos θi|` for the world direction `wi`, or zero where the shading frame and the
    /// geometry disagree on the side `wi` lies on (a shading normal must not let light leak through
    /// the surface, nor let a reflection come from behind it).
    #[inline]
    fn f_cos(&self, wi: Vec3) -> (Vec3, Vec3) {
        let local = self.frame.to_local(wi);
        if !self.sides_agree(wi, local) {
            return (Vec3::ZERO, local);
        }
        (self.bsdf.eval(self.wo, local) * local.z.abs(), local)
    }

    /// Whether `wi` is a reflection (same side as the viewer) in the geometry exactly when it is one
    /// in the shading frame. `ng` faces the viewer, so the geometric test is `ng · wi > 0`.
    #[inline]
    fn sides_agree(&self, wi: Vec3, local: Vec3) -> bool {
        (self.surface.ng.dot(wi) > 0.0) == (local.z * self.wo.z > 0.0)
    }
}

impl Integrator for Path {
    fn radiance(&self, world: &World, camera_ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        let lights = world.lights();
        let mut radiance = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        // Unit directions from here on (BSDF samples are unit vectors): `wo` needs no
        // normalisation, and a hit's `t` is its distance, which the light pdf of an emitter hit uses.
        let mut ray = Ray::new(camera_ray.origin, camera_ray.dir.normalize());
        // The previous vertex's BSDF density for the ray that left it (infinite for a delta lobe
        // or the camera), for the MIS weight of the light that ray hits.
        let mut previous_pdf = f32::INFINITY;
        let mut depth = 0u32;
        loop {
            ctx.rays += 1;
            let Some(hit) = world.intersect(&ray) else { break };

            // Emission: the light this ray found, weighted against having sampled it as a light.
            if let Some(light) = lights.light_of(hit.triangle) {
                let emitted = lights.lights()[light as usize].radiance_towards(-ray.dir);
                if emitted != Vec3::ZERO {
                    let weight = if previous_pdf.is_finite() {
                        self.hit_weight(previous_pdf, lights.pdf_li(SELECTION, light, ray.dir, hit.t))
                    } else {
                        1.0
                    };
                    radiance += throughput * emitted * weight;
                }
            }
            depth += 1;
            if self.max_depth != 0 && depth >= self.max_depth {
                break;
            }

            let surface = world.surface(&ray, &hit);
            let bsdf = world.bsdf(&surface);
            // Opaque lobes scatter on the viewer's side, where `ns` is turned; a transmissive one
            // needs its own orientation (`wo.z < 0` means inside), so its frame keeps the normal's.
            let normal = if bsdf.transmits() && !surface.front_face { -surface.ns } else { surface.ns };
            let frame = Frame::from_normal(normal);
            let wo = frame.to_local(-ray.dir);
            let vertex = Vertex { surface: &surface, bsdf, frame, wo };
            // Each vertex takes three dimensions, whether it uses them or not, so that a bounce's
            // numbers do not depend on the vertices before it; a dimension not used is not computed.
            let (light_point, scatter_point, survival) =
                (ctx.stream.next_points(1), ctx.stream.next_points(1), ctx.stream.next_points(1));

            // Next-event estimation: one point on a light chosen by power (not through a delta lobe,
            // which no light point can hit), both from one 2D point so that they stratify together.
            let sample = match self.strategy {
                PathStrategy::BsdfOnly => None,
                _ if bsdf.is_delta() => None,
                _ => lights.sample_li_reusing(SELECTION, surface.p, light_point.get_2d(0)),
            };
            if let Some(sample) = sample {
                let (f_cos, local) = vertex.f_cos(sample.wi);
                if f_cos != Vec3::ZERO {
                    ctx.rays += 1;
                    if !world.occluded(&surface.spawn_segment(sample.target)) {
                        let weight = self.light_weight_over_pdf(sample.pdf, vertex.bsdf.pdf(wo, local));
                        radiance += throughput * f_cos * sample.li * weight;
                    }
                }
            }

            // BSDF sampling: where the path goes next.
            let Some(scattered) = vertex.bsdf.sample(wo, scatter_point.get_2d(0)) else { break };
            let wi = frame.to_world(scattered.wi);
            if !vertex.sides_agree(wi, scattered.wi) {
                break;
            }
            throughput *= scattered.f * (scattered.wi.z.abs() / scattered.pdf);
            let specular = scattered.flags.contains(BsdfFlags::SPECULAR);
            previous_pdf = if specular { f32::INFINITY } else { scattered.pdf };
            ray = surface.spawn_ray(wi);

            // Russian roulette, after `rr_depth` segments: survive with probability q, weigh by 1/q.
            if depth >= self.rr_depth {
                let q = throughput.max_element().min(0.95);
                if q.is_nan() || survival.get_1d(0) >= q {
                    break;
                }
                throughput /= q;
            }
        }
        radiance
    }
}
