//! The scene's lights, derived once in `World::new`: every emissive triangle is an area light, and
//! a [`LightSet`] chooses among them and samples points on them for the integrators.
//!
//! Samples carry their pdf per unit solid angle at the receiver, the measure in which BSDF samples
//! are drawn too, so that multiple importance sampling compares like with like. The conversion from
//! the area measure happens here, and in the lane loops that repeat `sample_li_on`'s operations
//! for many samples at once (`integrators/direct.rs`, `integrators/path/diffuse.rs`), which must
//! stay in step with it (their tests compare bits).

mod area;
mod quad;

use std::sync::OnceLock;

use glam::{Vec2, Vec3};

pub use area::AreaLight;
pub use quad::QuadLight;

use crate::sampling::distrib::{AliasTable, ONE_MINUS_EPSILON};
use crate::sampling::warp::sample_uniform_triangle;
use crate::scene::Scene;
use crate::util::memory::prefetch;

/// How a light is chosen for one light sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum LightSelection {
    /// Every light with the same probability.
    #[default]
    Uniform,
    /// In proportion to the light's power (alias table, O(1)); bright lights get more samples.
    Power,
}

/// A point sampled on a light, as seen from a receiving point `p`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Radiance the light emits towards `p` (before visibility).
    pub li: Vec3,
    /// Unit direction from `p` to the light point.
    pub wi: Vec3,
    /// Probability density of this point per unit solid angle at `p`, light choice included.
    pub pdf: f32,
    /// Where a shadow segment from `p` ends: the sampled point moved a few ulps to the emitting side
    /// of the light (see [`AreaLight::shadow_targets`]).
    pub target: Vec3,
    /// Index of the light in [`LightSet::lights`].
    pub light: u32,
}

/// Marks a triangle that is not a light in the triangle → light map.
const NOT_A_LIGHT: u32 = u32::MAX;

#[derive(Clone, Debug)]
pub struct LightSet {
    lights: Vec<AreaLight>,
    /// Triangle id → index in `lights`, or `NOT_A_LIGHT`: when a BSDF-sampled ray hits an emitter,
    /// multiple importance sampling needs the probability that light sampling picks that light.
    light_of_triangle: Vec<u32>,
    /// Power-proportional choice; `None` when there are no lights (or none has power).
    power: Option<AliasTable>,
    /// Pairs of light triangles forming convex quads, found when first asked for: only direct
    /// lighting's per-light shafts use them, and with a million light triangles pairing them took
    /// a second and 160 MB that other modes would pay for nothing.
    quads: OnceLock<quad::Quads>,
}

impl LightSet {
    /// The lights of every emissive triangle of `scene`, in triangle id order.
    pub fn new(scene: &Scene) -> LightSet {
        let lights = area::collect_lights(scene);
        let mut light_of_triangle = vec![NOT_A_LIGHT; scene.mesh.triangle_count()];
        for (index, light) in lights.iter().enumerate() {
            light_of_triangle[light.triangle as usize] = index as u32;
        }
        let weights: Vec<f64> = lights.iter().map(AreaLight::power_weight).collect();
        LightSet { lights, light_of_triangle, power: AliasTable::new(&weights), quads: OnceLock::new() }
    }

    /// The convex quad light `light` forms with another light triangle, and its index, if any.
    /// The first call pairs all the lights (the same pairs whichever thread makes it).
    #[inline]
    pub fn quad_of(&self, light: u32) -> Option<(u32, &QuadLight)> {
        let quad::Quads { quads, quad_of_light } = self.quads.get_or_init(|| quad::pair_lights(&self.lights));
        let index = *quad_of_light.get(light as usize)?;
        (index != quad::NO_QUAD).then(|| (index, &quads[index as usize]))
    }

    pub fn lights(&self) -> &[AreaLight] {
        &self.lights
    }

    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// The light whose surface is triangle `id`, if it is one.
    #[inline]
    pub fn light_of(&self, triangle: u32) -> Option<u32> {
        let index = *self.light_of_triangle.get(triangle as usize)?;
        (index != NOT_A_LIGHT).then_some(index)
    }

    /// Starts loading the entry [`LightSet::light_of`] reads for `triangle`.
    #[inline]
    pub fn prefetch_light_of(&self, triangle: u32) {
        if let Some(entry) = self.light_of_triangle.get(triangle as usize) {
            prefetch(entry);
        }
    }

    /// Chooses a light with `u` in `[0, 1)`: its index and the probability of that choice.
    #[inline]
    pub fn choose(&self, selection: LightSelection, u: f32) -> Option<(u32, f32)> {
        self.choose_remapped(selection, u).map(|(index, pmf, _)| (index, pmf))
    }

    /// [`LightSet::choose`], and the part of `u` the choice left unused, rescaled to a uniform
    /// number in `[0, 1)` (see [`AliasTable::sample_remapped`]).
    #[inline]
    pub fn choose_remapped(&self, selection: LightSelection, u: f32) -> Option<(u32, f32, f32)> {
        let n = self.lights.len();
        match selection {
            LightSelection::Uniform if n > 0 => {
                let scaled = u * n as f32;
                let index = (scaled as usize).min(n - 1);
                let remapped = (scaled - index as f32).clamp(0.0, ONE_MINUS_EPSILON);
                Some((index as u32, 1.0 / n as f32, remapped))
            }
            LightSelection::Uniform => None,
            LightSelection::Power => {
                let (choice, remapped) = self.power.as_ref()?.sample_remapped(u);
                Some((choice.index as u32, choice.pmf, remapped))
            }
        }
    }

    /// The probability that [`LightSet::choose`] picks light `index`.
    #[inline]
    pub fn choice_pmf(&self, selection: LightSelection, index: u32) -> f32 {
        match selection {
            LightSelection::Uniform => 1.0 / self.lights.len() as f32,
            LightSelection::Power => self.power.as_ref().map_or(0.0, |table| table.pmf(index as usize)),
        }
    }

    /// Chooses a light with `u_light` and a point on it with `u_point`, seen from `p`; `None` when
    /// there is no light or the point faces away from `p` (its emission is one-sided).
    #[inline(always)]
    pub fn sample_li(&self, selection: LightSelection, p: Vec3, u_light: f32, u_point: Vec2) -> Option<LightSample> {
        let (index, pmf) = self.choose(selection, u_light)?;
        let mut sample = self.sample_li_on(index, p, u_point)?;
        sample.pdf *= pmf;
        Some(sample)
    }

    /// [`LightSet::sample_li`] from one 2D point: `u.x` chooses the light and, rescaled, places
    /// the point on it with `u.y`. A stratified 2D pattern thus stays stratified over all the
    /// lights together (over the two triangles of a quad light, say), which a separate number for
    /// the choice would not give.
    #[inline(always)]
    pub fn sample_li_reusing(&self, selection: LightSelection, p: Vec3, u: Vec2) -> Option<LightSample> {
        let (index, pmf, remapped) = self.choose_remapped(selection, u.x)?;
        let mut sample = self.sample_li_on(index, p, Vec2::new(remapped, u.y))?;
        sample.pdf *= pmf;
        Some(sample)
    }

    /// A point on light `index` chosen uniformly by area with `u`, seen from `p`; its pdf does not
    /// include any light choice. `None` when it faces away from `p` or lies on `p`.
    #[inline(always)]
    pub fn sample_li_on(&self, index: u32, p: Vec3, u: Vec2) -> Option<LightSample> {
        let light = &self.lights[index as usize];
        // The point on the shadow-target triangle, a few ulps in front of the light: where the
        // shadow segment must end, and, for the geometry terms, the light point itself to within
        // rounding (one barycentric combination per sample instead of two).
        let target = light.shadow_target(sample_uniform_triangle(u));
        let v = target - p;
        let dist2 = v.length_squared();
        // One square root and two independent divisions: this runs once per shadow ray of the lab's
        // soft shadows, where a longer chain of divisions measurably costs (`lumiere bench`).
        let dist = dist2.sqrt();
        let inv_dist = 1.0 / dist;
        let wi = v * inv_dist;
        let cos_light_dist = -light.normal.dot(v);
        if cos_light_dist <= 0.0 || dist2 <= 0.0 {
            return None;
        }
        // Area measure 1/A to solid angle: dA = dω d² / cos θ_light, with cos θ_light = -n·v / d.
        let pdf = dist2 * dist / (cos_light_dist * light.area);
        Some(LightSample { li: light.emission, wi, pdf, target, light: index })
    }

    /// The solid-angle pdf with which [`LightSet::sample_li`] would have produced the point of light
    /// `index` at distance `dist` along the unit direction `wi` from the receiver: what a
    /// BSDF-sampled ray that hits an emitter weighs against (its hit distance is `dist`).
    #[inline]
    pub fn pdf_li(&self, selection: LightSelection, index: u32, wi: Vec3, dist: f32) -> f32 {
        let light = &self.lights[index as usize];
        let cos_light = -light.normal.dot(wi);
        if cos_light <= 0.0 || dist <= 0.0 {
            return 0.0;
        }
        // Area measure 1/A to solid angle, as in `sample_li_on`.
        self.choice_pmf(selection, index) * dist * dist / (cos_light * light.area)
    }
}
