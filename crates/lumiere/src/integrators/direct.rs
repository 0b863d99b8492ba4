use std::f32::consts::FRAC_1_PI;

use glam::Vec3;

use super::{Integrator, SampleContext, dims};
use crate::accel::Region;
use crate::lights::AreaLight;
use crate::math::{Ray, offset_ray_origin};
use crate::sampling::distrib::AliasTable;
use crate::sampling::warp::sample_uniform_triangle;
use crate::world::{SurfacePoint, World};

/// How the direct-light estimator spends its samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LightSampling {
    /// N points on every light triangle, as the lab counts (N * lights shadow rays a pixel).
    #[default]
    PerLight,
    /// N points in total, each on a light chosen in proportion to its power (alias table, O(1)).
    Power,
}

/// Direct lighting from area lights with Lambertian receivers (lab figures 4-6):
/// `Lr = (1/N) sum Le * Kd/pi * V * cos(theta) cos(theta_s) / d^2 / pdf(s)`, with `s` uniform on
/// a light triangle (GI compendium eq. 18, area pdf `1/A`), or on a light picked by power (area pdf
/// `pmf / A`). Where the camera sees a light directly, its emission.
pub struct Direct {
    pub samples: u32,
    pub light_sampling: LightSampling,
    /// Built from the lights' power for `LightSampling::Power`; `None` when there are no lights.
    power: Option<AliasTable>,
}

impl Direct {
    pub fn new(world: &World, samples: u32, light_sampling: LightSampling) -> Direct {
        let power = match light_sampling {
            LightSampling::Power => {
                let weights: Vec<f32> = world.scene.lights.iter().map(|l| l.power().element_sum()).collect();
                AliasTable::new(&weights)
            }
            LightSampling::PerLight => None,
        };
        Direct { samples, light_sampling, power }
    }
}

/// The unoccluded contribution of the light point `y` (sampled on the light's shadow-target
/// triangle, a few ulps in front of it) to `surface`, divided by the area pdf, and the shadow
/// segment that decides its visibility; `None` when a cosine is not positive.
///
/// `cos(theta) cos(theta_s) / d^2` is evaluated as `(n . v)(-n_s . v) / (v . v)^2` with the
/// unnormalised `v = y - p`: no square root and one division per sample.
#[inline(always)]
fn light_sample(surface: &SurfacePoint, origin: Vec3, light: &AreaLight, y: Vec3) -> Option<(Vec3, Ray)> {
    let v = y - surface.p;
    let cos_surface = surface.ns.dot(v);
    let cos_light = -light.normal.dot(v);
    if cos_surface <= 0.0 || cos_light <= 0.0 || surface.ng.dot(v) <= 0.0 {
        return None;
    }
    let d2 = v.length_squared();
    Some((light.emission * (cos_surface * cos_light / (d2 * d2)), Ray::segment(origin, y)))
}

/// False when no point of the light can contribute: the light lies wholly below the surface's
/// tangent plane, or the surface lies behind the light. Saves preparing a batch for nothing.
fn faces_each_other(surface: &SurfacePoint, light: &AreaLight) -> bool {
    let above = light.vertices.iter().any(|&v| surface.ng.dot(v - surface.p) > 0.0);
    let in_front = light.normal.dot(surface.p - light.vertices[0]) > 0.0;
    above && in_front
}

#[inline(always)]
fn point_on(light: &AreaLight, u: glam::Vec2) -> Vec3 {
    light.shadow_target(sample_uniform_triangle(u))
}

impl Integrator for Direct {
    fn radiance(&self, world: &World, ray: &Ray, ctx: &mut SampleContext) -> Vec3 {
        ctx.rays += 1;
        let Some(hit) = world.intersect(ray) else { return Vec3::ZERO };
        let material = world.scene.material(hit.triangle);
        if material.is_emissive() {
            return material.ke;
        }
        let surface = world.surface(ray, &hit);
        let origin = offset_ray_origin(surface.p, surface.ng);
        let n = self.samples;
        let mut sum = Vec3::ZERO;
        match self.light_sampling {
            LightSampling::PerLight => {
                // The N shadow rays towards one light triangle share their origin and stay in the shaft
                // from it to the triangle: trace them as a batch.
                let mut batch = std::mem::take(&mut ctx.batch);
                for (index, light) in world.scene.lights.iter().enumerate() {
                    if !faces_each_other(&surface, light) {
                        continue;
                    }
                    let Some(shaft) = Region::shaft(origin, light.shadow_targets) else { continue };
                    batch.prepare(&world.bvh, origin, &shaft);
                    let dimension = dims::LIGHT_POINT + index as u32;
                    let mut light_sum = Vec3::ZERO;
                    for k in 0..n {
                        let y = point_on(light, ctx.point_2d(dimension, k, n));
                        let Some((contribution, shadow)) = light_sample(&surface, origin, light, y) else { continue };
                        ctx.rays += 1;
                        if !batch.occluded(&world.bvh, &shadow) {
                            light_sum += contribution;
                        }
                    }
                    sum += light_sum * light.area;
                }
                ctx.batch = batch;
            }
            LightSampling::Power => {
                let Some(table) = &self.power else { return Vec3::ZERO };
                for k in 0..n {
                    let choice = table.sample(ctx.point_1d(dims::LIGHT_CHOICE, k, n));
                    let light = &world.scene.lights[choice.index];
                    let y = point_on(light, ctx.point_2d(dims::LIGHT_POINT, k, n));
                    let Some((contribution, shadow)) = light_sample(&surface, origin, light, y) else { continue };
                    ctx.rays += 1;
                    if !world.occluded(&shadow) {
                        sum += contribution * (light.area / choice.pmf);
                    }
                }
            }
        }
        sum * material.kd * (FRAC_1_PI / n as f32)
    }
}
