//! Materials and their BSDFs. A [`Material`] is what a scene file says about a surface; its
//! [`Bsdf`] is how light scatters there, evaluated and sampled in the local shading frame, where
//! the shading normal is `+z` (so `cos θ` is a `z` coordinate).
//!
//! Conventions (pbrt's): `wo` points towards the viewer, `wi` towards the light, both unit vectors
//! leaving the surface. `eval` returns `f(wo, wi)` without the cosine; integrators multiply by
//! `|cos θi|` themselves.

mod lambert;
mod material;

use glam::{Vec2, Vec3};

pub use lambert::Lambert;
pub use material::Material;

/// What kind of scattering a sample took; integrators use it to skip light sampling where it
/// cannot help (specular lobes) and to count bounces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BsdfFlags(u8);

impl BsdfFlags {
    pub const REFLECTION: BsdfFlags = BsdfFlags(1);
    pub const TRANSMISSION: BsdfFlags = BsdfFlags(2);
    pub const DIFFUSE: BsdfFlags = BsdfFlags(4);
    pub const GLOSSY: BsdfFlags = BsdfFlags(8);
    pub const SPECULAR: BsdfFlags = BsdfFlags(16);

    #[inline]
    pub fn contains(self, other: BsdfFlags) -> bool {
        self.0 & other.0 == other.0
    }
}

impl std::ops::BitOr for BsdfFlags {
    type Output = BsdfFlags;
    fn bitor(self, other: BsdfFlags) -> BsdfFlags {
        BsdfFlags(self.0 | other.0)
    }
}

/// A direction drawn from a BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// `f(wo, wi)`, without the cosine.
    pub f: Vec3,
    /// The sampled direction, in the local shading frame.
    pub wi: Vec3,
    /// Probability density of `wi` per unit solid angle; always positive (samples with a zero pdf
    /// are not returned).
    pub pdf: f32,
    pub flags: BsdfFlags,
}

/// Scattering at a surface point, in the local shading frame. Implemented by plain structs and used
/// through generics or enums: no dynamic dispatch per ray.
pub trait Bsdf {
    /// `f(wo, wi)`: reflected radiance per unit irradiance, without the cosine.
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3;
    /// Draws `wi` for a given `wo` from the uniform point `u`; `None` where nothing scatters
    /// (a grazing or below-surface `wo`, or a zero pdf).
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample>;
    /// The solid-angle density with which `sample` returns `wi` for this `wo`.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;
    /// The surface's colour: the fraction of light it reflects at normal incidence, per channel.
    /// What the `materials` mode shows and what a denoiser's albedo buffer holds.
    fn albedo(&self) -> Vec3;
}
