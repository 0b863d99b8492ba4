//! Materials and their BSDFs. A [`Material`] is what a scene file says about a surface; its
//! [`Bsdf`] is how light scatters there, evaluated and sampled in the local shading frame, where
//! the shading normal is `+z` (so `cos θ` is a `z` coordinate).
//!
//! Conventions (pbrt's): `wo` points towards the viewer, `wi` towards the light, both unit vectors
//! leaving the surface. `eval` returns `f(wo, wi)` without the cosine; integrators multiply by
//! `|cos θi|` themselves.
//!
//! The lobes, each in its own file: [`Lambert`] (diffuse), [`Plastic`] (diffuse under a GGX
//! specular layer), [`Conductor`] (rough metal) and [`Mirror`] (its smooth limit), [`Dielectric`]
//! (smooth glass); [`microfacet`] holds the GGX distribution and [`fresnel`] the Fresnel terms.
//! [`MaterialBsdf`] is the one type integrators get from [`Material::bsdf`]: an enum over the
//! lobes, dispatched by `match`. docs/MATERIALS.md tells which scene-file statements map to which
//! lobe.

mod conductor;
mod dielectric;
pub mod fresnel;
mod lambert;
mod material;
pub mod microfacet;
mod plastic;

use glam::{Vec2, Vec3};

pub use conductor::{Conductor, Mirror};
pub use dielectric::Dielectric;
pub use lambert::Lambert;
pub use material::{
    CoverageTest, Cut, DEFAULT_IOR, Material, MaterialKind, NormalMap, ParameterMap, Relief, SMOOTH_NS, alpha_from_ns,
    pbr_alpha,
};
pub use plastic::Plastic;

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

/// A direction drawn from a BSDF. In every case `f |cos θi| / pdf` is the sample's path weight.
///
/// For a **specular** (delta) sample, flagged [`BsdfFlags::SPECULAR`], `pdf` is not a density but
/// the discrete probability with which that lobe was chosen (1 for a mirror, the Fresnel
/// reflectance or transmittance for glass), and `f` carries the delta lobe's weight divided by
/// `|cos θi|` (pbrt's convention). Such a direction cannot be reached by light sampling and
/// `Bsdf::pdf` returns 0 for it: integrators give it no MIS weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// `f(wo, wi)`, without the cosine.
    pub f: Vec3,
    /// The sampled direction, in the local shading frame.
    pub wi: Vec3,
    /// Probability density of `wi` per unit solid angle (a discrete probability for specular
    /// samples, see above); always positive and finite (samples with a zero pdf are not returned).
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
    /// For a purely diffuse lobe, the `f` that `eval(wo, wi)` returns for every `wi` with
    /// `wi.z > 0` (and it returns 0 for the others): lets light sampling evaluate many `wi` at
    /// once. `None` for lobes that depend on `wi`.
    fn lambertian_eval(&self, _wo: Vec3) -> Option<Vec3> {
        None
    }
}

/// The BSDF of any material, as [`Material::bsdf`] builds it: one variant per lobe, dispatched by
/// `match` (no `dyn`, no allocation), so integrators hold it by value for each hit.
///
/// Sidedness: every lobe but [`Dielectric`] is one-sided and scatters only for `wo.z > 0`;
/// integrators that want two-sided opaque surfaces (most OBJ scenes need them) flip the shading
/// frame towards `wo` for those ([`MaterialBsdf::transmits`] is false), and must *not* flip it
/// for a dielectric, whose `wo.z < 0` means "inside the glass".
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialBsdf {
    Lambert(Lambert),
    Plastic(Plastic),
    Conductor(Conductor),
    Mirror(Mirror),
    Dielectric(Dielectric),
}

impl MaterialBsdf {
    /// True when every lobe is a delta lobe (mirror, smooth glass): `eval` and `pdf` are 0
    /// everywhere, so light sampling (next-event estimation) cannot contribute and can be skipped.
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(self, MaterialBsdf::Mirror(_) | MaterialBsdf::Dielectric(_))
    }

    /// True when light can pass through the surface (samples with `wi.z` on the other side of
    /// `wo.z`): only the dielectric. Such a surface needs the shading frame unflipped.
    #[inline]
    pub fn transmits(&self) -> bool {
        matches!(self, MaterialBsdf::Dielectric(_))
    }
}

/// Forwards a `Bsdf` method to the lobe inside.
macro_rules! dispatch {
    ($self:expr, $lobe:ident => $call:expr) => {
        match $self {
            MaterialBsdf::Lambert($lobe) => $call,
            MaterialBsdf::Plastic($lobe) => $call,
            MaterialBsdf::Conductor($lobe) => $call,
            MaterialBsdf::Mirror($lobe) => $call,
            MaterialBsdf::Dielectric($lobe) => $call,
        }
    };
}

impl Bsdf for MaterialBsdf {
    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        dispatch!(self, lobe => lobe.eval(wo, wi))
    }

    #[inline]
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        dispatch!(self, lobe => lobe.sample(wo, u))
    }

    #[inline]
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        dispatch!(self, lobe => lobe.pdf(wo, wi))
    }

    #[inline]
    fn albedo(&self) -> Vec3 {
        dispatch!(self, lobe => lobe.albedo())
    }

    #[inline]
    fn lambertian_eval(&self, wo: Vec3) -> Option<Vec3> {
        dispatch!(self, lobe => lobe.lambertian_eval(wo))
    }
}
