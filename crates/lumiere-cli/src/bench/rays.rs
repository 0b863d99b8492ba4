//! Reproducible ray sets for measuring traversal: camera rays, shadow rays from their hits, and
//! cosine-distributed diffuse rays from their hits.

use glam::Vec3;
use rayon::prelude::*;

use lumiere::math::{Frame, Ray, offset_ray_origin};
use lumiere::sampler::{Sampler, SamplerKind};
use lumiere::sampling::warp::{sample_cosine_hemisphere, sample_uniform_triangle};
use lumiere::scene::camera::Camera;
use lumiere::world::World;

/// Which query a ray set is traced with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Query {
    Closest,
    Occluded,
}

impl Query {
    pub fn name(self) -> &'static str {
        match self {
            Query::Closest => "closest",
            Query::Occluded => "occluded",
        }
    }
}

#[derive(Clone, Debug)]
pub struct RaySet {
    /// `primary`, `shadow` or `diffuse`.
    pub kind: &'static str,
    pub query: Query,
    pub rays: Vec<Ray>,
}

/// The benchmark's ray sets, in this order: primary (closest), shadow (occluded), diffuse
/// (occluded), diffuse (closest). Shadow rays go to a uniform point of a light triangle chosen by
/// index (ending just in front of it, as the renderer's do), or, in scenes without lights, to a point above the scene.
pub fn make_ray_sets(world: &World, camera: &Camera, seed: u64) -> Vec<RaySet> {
    let sampler = Sampler::new(SamplerKind::Independent, seed);
    let (width, height) = (camera.width, camera.height);
    let primary: Vec<Ray> =
        (0..width * height).map(|p| camera.ray((p % width) as f32 + 0.5, (p / width) as f32 + 0.5)).collect();
    let bounds = world.scene().bounds();
    let fixed_light = bounds.center() + Vec3::Y * bounds.extent().length();
    let lights = world.lights().lights();

    // For every primary hit: a shadow ray and a diffuse ray leaving from the offset hit point.
    let secondary: Vec<(Ray, Ray)> = primary
        .par_iter()
        .enumerate()
        .filter_map(|(pixel, ray)| {
            let hit = world.intersect(ray)?;
            let surface = world.surface(ray, &hit);
            let origin = offset_ray_origin(surface.p, surface.ng);
            let pixel = pixel as u32;
            let target = if lights.is_empty() {
                fixed_light
            } else {
                let light = &lights[(sampler.get_1d(pixel, 0, 0) * lights.len() as f32) as usize % lights.len()];
                let b = sample_uniform_triangle(sampler.get_2d(pixel, 0, 1));
                // As the renderer does: end on the light's shadow-target triangle, just in front of it.
                light.shadow_target(b)
            };
            let shadow = Ray::segment(origin, target);
            let local = sample_cosine_hemisphere(sampler.get_2d(pixel, 0, 2));
            let diffuse = Ray::new(origin, Frame::from_normal(surface.ng).to_world(local));
            Some((shadow, diffuse))
        })
        .collect();
    let (shadow, diffuse): (Vec<Ray>, Vec<Ray>) = secondary.into_iter().unzip();
    vec![
        RaySet { kind: "primary", query: Query::Closest, rays: primary },
        RaySet { kind: "shadow", query: Query::Occluded, rays: shadow },
        RaySet { kind: "diffuse", query: Query::Occluded, rays: diffuse.clone() },
        RaySet { kind: "diffuse", query: Query::Closest, rays: diffuse },
    ]
}
