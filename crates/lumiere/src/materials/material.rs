//! The format-neutral description of a surface, as scene loaders fill it (from MTL statements
//! today), and the one mapping from it to a kind of BSDF ([`Material::kind`]). Integrators never
//! read the statements directly: they ask the material for its [`MaterialBsdf`].
//!
//! docs/MATERIALS.md lists, with reasons, which statements are honoured and which are not.

use glam::Vec3;

use super::conductor::is_smooth;
use super::microfacet::MIN_ALPHA;
use super::{Conductor, Dielectric, Lambert, MaterialBsdf, Mirror, Plastic};
use crate::error::shown_name;
use crate::math::UvTransform;
use crate::textures::Channel;
use std::path::{Path, PathBuf};

/// The index of refraction of a transmissive material whose file gives none usable (ordinary
/// glass). `Ni 1` counts as none: it is both our default and what exporters write when no index
/// was set, and a glass of index 1 would be invisible.
pub const DEFAULT_IOR: f32 = 1.5;

/// The Phong exponent from which a specular layer counts as smooth: 1000, the top of the MTL
/// format's range (`Ns` 0–1000), which exporters write for "perfectly smooth".
pub const SMOOTH_NS: f32 = 1000.0;

/// The specular reflectance of a non-metal in the PBR extension (`Pm < 0.5`): 4%, the normal
/// reflectance of an interface of index 1.5, as in glTF and Blender's Principled BSDF.
const PBR_DIELECTRIC_SPECULAR: f32 = 0.04;

/// The range of `Ni` the MTL format allows; values outside it (and `Ni 1`) use [`DEFAULT_IOR`].
const IOR_RANGE: std::ops::RangeInclusive<f32> = 0.001..=10.0;

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Diffuse reflectance (MTL `Kd`); also the base colour of metals (`Pm`), i.e. their `F0`.
    pub kd: Vec3,
    /// Specular reflectance (MTL `Ks`): the specular layer of a plastic, or a mirror's colour.
    pub ks: Vec3,
    /// Phong exponent (MTL `Ns`, 0–1000): the specular layer's sharpness, mapped to GGX roughness
    /// by [`alpha_from_ns`].
    pub ns: f32,
    /// Emitted radiance; a non-zero value makes every triangle with this material a light.
    pub ke: Vec3,
    /// Diffuse texture, resolved relative to the MTL file; where it decodes, its value at the hit
    /// replaces `kd` as the base colour.
    pub map_kd: Option<PathBuf>,
    /// Where `map_kd` lies on the surface (its `-s` and `-o` options).
    pub map_kd_transform: UvTransform,
    /// What `map_kd`'s colour is multiplied by: glTF's `baseColorFactor`; white for MTL, whose
    /// `map_Kd` replaces `Kd`, as mainstream OBJ readers do.
    pub map_kd_factor: Vec3,
    /// Coverage texture (MTL `map_d`), resolved relative to the MTL file: where its coverage fails
    /// `map_d_test` (below one half, for MTL) the surface is cut out (rays pass through it), as
    /// leaves and fences are drawn.
    pub map_d: Option<PathBuf>,
    /// Where `map_d` lies on the surface (its `-s` and `-o` options).
    pub map_d_transform: UvTransform,
    /// How `map_d`'s coverage is read and where it cuts: MTL's rule, or glTF's `alphaMode` `MASK`
    /// or `BLEND`, whose factor's alpha cuts even without a texture.
    pub map_d_test: CoverageTest,
    /// Index of refraction (MTL `Ni`) of a transmissive material.
    pub ni: f32,
    /// Opacity (`d`, or `1 − Tr`), 1 = opaque. Below 1 together with an explicit `Ni`, the surface
    /// is glass; otherwise it is not honoured (no alpha blending: cutouts come from `map_d`).
    pub dissolve: f32,
    /// MTL illumination model: 0–1 switch the specular layer off, 2 on, 3/5/8 make it a mirror,
    /// 4/6/7/9 make the surface glass (see [`Material::kind`]).
    pub illum: u32,
    /// Transmission filter (MTL `Tf`): the colour glass passes, per refraction; default white.
    pub tf: Vec3,
    /// Metallic weight (MTL PBR extension `Pm`, 0–1); `None` when the file does not say.
    /// Its presence, or that of `roughness`, selects the PBR mapping.
    pub metallic: Option<f32>,
    /// Perceptual roughness (MTL PBR extension `Pr`, 0–1); GGX `α = Pr²`. `None` when the file
    /// does not say.
    pub roughness: Option<f32>,
    /// Metallic weight painted by a texture (MTL `map_Pm`, glTF's `metallicRoughnessTexture`'s
    /// blue channel): where it decodes, its value at the hit replaces `metallic`.
    pub map_pm: Option<ParameterMap>,
    /// Perceptual roughness painted by a texture (MTL `map_Pr`, glTF's
    /// `metallicRoughnessTexture`'s green channel): where it decodes, its value at the hit
    /// replaces `roughness`.
    pub map_pr: Option<ParameterMap>,
    /// A texture that bends the shading normal: a tangent-space normal map (glTF's
    /// `normalTexture`, MTL `norm`) or a height map (MTL `bump`, `map_Bump`).
    pub normal_map: Option<NormalMap>,
}

/// A texture that bends the shading normal, as its [`Relief`] says, `scale` times as strongly as
/// drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap {
    /// The name of an image the scene file embeds, or a file's path.
    pub path: PathBuf,
    /// Where the texture lies on the surface.
    pub transform: UvTransform,
    /// How strongly the map bends the normal (1 as drawn): glTF's `normalTexture.scale`, MTL's
    /// `-bm` (the bump multiplier).
    pub scale: f32,
    pub relief: Relief,
}

/// How a [`NormalMap`]'s texels describe the relief of its surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Relief {
    /// Directions: each texel's stored values `c` (data, not a colour), as `2c − 1`, are a
    /// direction in the frame of the surface's texture axes (`x` along increasing `u`, `y` along
    /// increasing `v`, glTF's and OpenGL's convention) and its shading normal (`z`), its `x` and
    /// `y` multiplied by the map's scale (glTF's `normalTexture`, MTL `norm`).
    Directions,
    /// Heights: `channel` of the stored values is the surface's displacement along its normal,
    /// in scene units times the map's scale, whose slopes tilt the normal (MTL `bump` and
    /// `map_Bump`, pbrt's and Mitsuba's bump mapping). An image with the colours of a normal map
    /// is read as [`Relief::Directions`] instead: Blender's exporter writes its normal maps as
    /// `map_Bump` (`world/normals.rs` says how it is told apart).
    Heights { channel: Channel },
}

/// A material parameter painted by a texture: one channel of the values its file stores (data,
/// not a colour: no sRGB decoding), bilinearly filtered, times `scale`.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterMap {
    /// Resolved relative to the MTL file, or the name of an image the scene file embeds.
    pub path: PathBuf,
    /// Where the texture lies on the surface (`-s`, `-o`, or glTF's `KHR_texture_transform`).
    pub transform: UvTransform,
    pub channel: Channel,
    /// What the texture's value is multiplied by: glTF's `metallicFactor` or `roughnessFactor`;
    /// 1 for MTL, whose map replaces the value, as `map_Kd` replaces `Kd`.
    pub scale: f32,
}

/// Where a coverage texture keeps its surface: the coverage (the texture's bilinearly filtered
/// alpha, or unless `alpha_only` the grey level of a file without alpha; 1 without a texture)
/// times `scale`, tested as `cut` says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoverageTest {
    /// Whether only the alpha channel counts, a file without one being opaque (glTF, where the
    /// texture is the base colour's); otherwise a file without alpha is read as a grey mask, as
    /// renderers read MTL's `map_d`.
    pub alpha_only: bool,
    /// What the coverage is multiplied by: glTF's `baseColorFactor` alpha; 1 for MTL.
    pub scale: f32,
    /// Where the scaled coverage cuts.
    pub cut: Cut,
}

/// How a coverage cuts a surface out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cut {
    /// Where the coverage is below this threshold: one half for MTL, `alphaCutoff` for glTF's
    /// `MASK`.
    Below(f32),
    /// With a probability of one minus the coverage, decided at each point by a hash of the point
    /// (hashed alpha testing, as pbrt-v4 reads an alpha below 1): a partly covering surface
    /// (glTF's `BLEND`) lets that share of the rays that meet it through, and the same ray always
    /// the same way.
    Hashed,
}

impl CoverageTest {
    /// MTL's `map_d`: alpha, or grey levels without it, cut below one half.
    pub const MTL: CoverageTest = CoverageTest { alpha_only: false, scale: 1.0, cut: Cut::Below(0.5) };

    /// Whether a surface of coverage `coverage` is there; `hash` gives the point's number in
    /// [0, 1) that a [`Cut::Hashed`] compares the coverage with.
    #[inline]
    pub fn keeps(&self, coverage: f32, hash: impl FnOnce() -> f32) -> bool {
        let coverage = coverage * self.scale;
        match self.cut {
            Cut::Below(threshold) => coverage >= threshold,
            Cut::Hashed => coverage > hash(),
        }
    }

    /// Whether full coverage keeps the surface everywhere: then only a texture's alpha can cut it.
    pub fn keeps_full_coverage(&self) -> bool {
        match self.cut {
            Cut::Below(threshold) => self.scale >= threshold,
            Cut::Hashed => self.scale >= 1.0,
        }
    }
}

/// The kind of scattering a [`Material`] stands for, with its parameters resolved from the file's
/// statements; the base colour (`kd` or a texture's value at the hit) is supplied when the BSDF is
/// built, by [`MaterialKind::bsdf`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialKind {
    /// Diffuse reflection of the base colour.
    Lambert,
    /// The base colour, diffuse, under a GGX specular layer of reflectance `ks` and roughness `alpha`.
    Plastic { ks: Vec3, alpha: f32 },
    /// A metal whose reflectance at normal incidence is the base colour, with GGX roughness
    /// `alpha`; a perfect [`Mirror`] of the base colour when `alpha` is below [`MIN_ALPHA`].
    Conductor { alpha: f32 },
    /// A perfect mirror of reflectance `f0` at normal incidence (from `Ks`); ignores the base colour.
    Mirror { f0: Vec3 },
    /// Smooth glass of index `eta` with transmission filter `tf`; ignores the base colour.
    Dielectric { eta: f32, tf: Vec3 },
}

impl MaterialKind {
    /// The PBR extension's kind: a metal ([`MaterialKind::Conductor`], base colour = `F0`) of GGX
    /// roughness `alpha` when `metallic ≥ 0.5`, otherwise a plastic with a 4% specular layer (the
    /// PBR dielectric). A threshold, not a blend: scanned materials are metal or not, and values
    /// in between come from filtered metallic maps at the borders of metal parts (a NaN is not
    /// metal).
    #[inline]
    pub fn pbr(metallic: f32, alpha: f32) -> MaterialKind {
        if metallic >= 0.5 {
            MaterialKind::Conductor { alpha }
        } else {
            MaterialKind::Plastic { ks: Vec3::splat(PBR_DIELECTRIC_SPECULAR), alpha }
        }
    }

    /// The BSDF of this kind with `base_colour` (the material's `kd`, or its texture's value at the
    /// hit) as diffuse colour or metal `F0`.
    #[inline]
    pub fn bsdf(&self, base_colour: Vec3) -> MaterialBsdf {
        match *self {
            MaterialKind::Lambert => MaterialBsdf::Lambert(Lambert { reflectance: base_colour }),
            MaterialKind::Plastic { ks, alpha } => MaterialBsdf::Plastic(Plastic::new(base_colour, ks, alpha)),
            MaterialKind::Conductor { alpha } if is_smooth(alpha) => MaterialBsdf::Mirror(Mirror::new(base_colour)),
            MaterialKind::Conductor { alpha } => MaterialBsdf::Conductor(Conductor::new(base_colour, alpha)),
            MaterialKind::Mirror { f0 } => MaterialBsdf::Mirror(Mirror::new(f0)),
            MaterialKind::Dielectric { eta, tf } => MaterialBsdf::Dielectric(Dielectric::new(eta, tf)),
        }
    }

    /// A short name for messages and `info`: "lambert", "plastic", "conductor", "mirror", "dielectric".
    pub fn name(&self) -> &'static str {
        match self {
            MaterialKind::Lambert => "lambert",
            MaterialKind::Plastic { .. } => "plastic",
            MaterialKind::Conductor { alpha } if is_smooth(*alpha) => "mirror",
            MaterialKind::Conductor { .. } => "conductor",
            MaterialKind::Mirror { .. } => "mirror",
            MaterialKind::Dielectric { .. } => "dielectric",
        }
    }
}

/// GGX `α` from a perceptual roughness (`Pr`, glTF's `roughness`): its square, the roughness
/// clamped to [0, 1] first; a NaN (a texture's 0 times an infinite factor) gives 1, the roughest.
#[inline]
pub fn pbr_alpha(roughness: f32) -> f32 {
    if roughness.is_nan() { 1.0 } else { roughness.clamp(0.0, 1.0).powi(2) }
}

/// The GGX roughness equivalent to a Blinn–Phong exponent: `α = √(2 / (Ns + 2))`, the
/// Beckmann–Phong correspondence of Walter et al. 2007 (§5.2), used for GGX as is customary (the
/// two distributions nearly agree at small α). `Ns ≤ 0` (or NaN) gives 1, the roughest; `Ns` 1000
/// gives 0.045. The staircase's converter wrote `Ns = 2/α² − 2`, the inverse of this.
#[inline]
pub fn alpha_from_ns(ns: f32) -> f32 {
    if ns.is_nan() || ns <= 0.0 { 1.0 } else { (2.0 / (ns + 2.0)).sqrt() }
}

impl Material {
    /// The grey diffuse material used when a file names no material or its MTL cannot be read;
    /// also what loaders start a `newmtl` from.
    pub fn default_grey(name: &str) -> Self {
        Material {
            name: name.to_string(),
            kd: Vec3::splat(0.8),
            ks: Vec3::ZERO,
            ns: 0.0,
            ke: Vec3::ZERO,
            map_kd: None,
            map_kd_transform: UvTransform::default(),
            map_d: None,
            map_kd_factor: Vec3::ONE,
            map_d_transform: UvTransform::default(),
            map_d_test: CoverageTest::MTL,
            ni: 1.0,
            dissolve: 1.0,
            illum: 1,
            tf: Vec3::ONE,
            metallic: None,
            roughness: None,
            map_pm: None,
            map_pr: None,
            normal_map: None,
        }
    }

    pub fn is_emissive(&self) -> bool {
        self.ke.max_element() > 0.0
    }

    /// Clamps `kd` to [0, 1] where it lies outside: a reflectance above 1 would reflect more light
    /// than arrives (below 0, take some away) in every lobe that reads it (diffuse, a metal's base
    /// colour). Returns what was clamped, for the loader's warning.
    pub fn clamp_kd(&mut self) -> Option<String> {
        // A texture's factor (glTF's `baseColorFactor`, which is also its `kd`) likewise.
        self.map_kd_factor = self.map_kd_factor.clamp(Vec3::ZERO, Vec3::ONE);
        let clamped = self.kd.clamp(Vec3::ZERO, Vec3::ONE);
        if clamped == self.kd {
            return None;
        }
        let Vec3 { x, y, z } = std::mem::replace(&mut self.kd, clamped);
        Some(format!("colour {x} {y} {z} clamped to [0, 1] (a surface reflects at most the light it receives)"))
    }

    /// Whether a texture paints some part of the material (its base colour, cutout, metallic
    /// weight, roughness or relief): its triangles need texture coordinates.
    pub fn reads_texture_coordinates(&self) -> bool {
        self.map_kd.is_some()
            || self.cutout_mask().is_some()
            || self.map_pm.is_some()
            || self.map_pr.is_some()
            || self.normal_map.is_some()
    }

    /// The coverage texture that cuts the surface out: `map_d`, except on an emitter. Lights are
    /// sampled over their whole triangles, so an emitter stays whole for the rays that find it
    /// too: cut out, a BSDF-sampled ray would pass where light sampling adds emission, and the two
    /// strategies would disagree.
    pub fn cutout_mask(&self) -> Option<&Path> {
        self.map_d.as_deref().filter(|_| !self.is_emissive())
    }

    /// The warning for a `map_d` that [`Material::cutout_mask`] leaves out, if there is one.
    pub fn ignored_mask_warning(&self) -> Option<String> {
        (self.map_d.is_some() && self.cutout_mask().is_none())
            .then(|| format!("material {}: map_d is ignored on an emitter; it stays opaque", shown_name(&self.name)))
    }

    /// The one mapping from a material's statements to its kind of scattering, in this order
    /// (the first rule that applies wins; docs/MATERIALS.md has the table and the reasons):
    ///
    /// 1. **PBR extension** (`Pm`, `Pr`, `map_Pm` or `map_Pr` given): [`MaterialKind::pbr`] of
    ///    `Pm` (0 without) and `Pr` (see [`Material::pbr_alpha`]). Where a map paints either,
    ///    the kind at each hit is that of the map's value there ([`MaterialKind::pbr`] again);
    ///    this is the kind without the maps.
    /// 2. **Glass** ([`MaterialKind::Dielectric`]): `illum` 4, 6, 7 or 9 (the transmissive
    ///    illumination models), or `d < 1` with an explicit `Ni` (≠ 1); index `Ni`, or
    ///    [`DEFAULT_IOR`] when absent, 1 or outside the format's range; filter `Tf`.
    /// 3. **No specular layer** ([`MaterialKind::Lambert`]): `illum` 0 or 1 (the models without
    ///    highlights; 1 is also what a material without `illum` gets), or `Ks` black.
    /// 4. **Smooth specular**: `illum` 3, 5 or 8 (reflection on), or `Ns ≥` [`SMOOTH_NS`]: a
    ///    [`MaterialKind::Mirror`] of `Ks` when the base colour is black (`Kd 0`, no texture; a
    ///    material without `Kd` has the grey of [`Material::default_grey`]),
    ///    otherwise a plastic whose layer is as smooth as GGX goes (`α =` [`MIN_ALPHA`]), so that
    ///    a glossy paint keeps its colour.
    /// 5. **Plastic**: `Kd` under a GGX layer of `Ks`, `α =` [`alpha_from_ns`]`(Ns)`.
    pub fn kind(&self) -> MaterialKind {
        if self.is_pbr() {
            return MaterialKind::pbr(self.metallic.unwrap_or(0.0), self.pbr_alpha());
        }
        let explicit_ior = IOR_RANGE.contains(&self.ni) && self.ni != 1.0;
        if matches!(self.illum, 4 | 6 | 7 | 9) || (self.dissolve < 1.0 && explicit_ior) {
            let eta = if explicit_ior { self.ni } else { DEFAULT_IOR };
            return MaterialKind::Dielectric { eta, tf: self.tf.clamp(Vec3::ZERO, Vec3::ONE) };
        }
        let ks = self.ks.clamp(Vec3::ZERO, Vec3::ONE);
        if matches!(self.illum, 0 | 1) || ks.max_element() <= 0.0 {
            return MaterialKind::Lambert;
        }
        if matches!(self.illum, 3 | 5 | 8) || self.ns >= SMOOTH_NS {
            let has_base_colour = self.kd.max_element() > 0.0 || self.map_kd.is_some();
            return if has_base_colour {
                MaterialKind::Plastic { ks, alpha: MIN_ALPHA }
            } else {
                MaterialKind::Mirror { f0: ks }
            };
        }
        MaterialKind::Plastic { ks, alpha: alpha_from_ns(self.ns) }
    }

    /// Whether the PBR extension's rule decides the kind (rule 1 of [`Material::kind`]).
    pub fn is_pbr(&self) -> bool {
        self.metallic.is_some() || self.roughness.is_some() || self.map_pm.is_some() || self.map_pr.is_some()
    }

    /// The GGX roughness of a PBR material without a roughness map: `Pr²`, or from `Ns` without
    /// `Pr` (or with a NaN one).
    pub fn pbr_alpha(&self) -> f32 {
        match self.roughness {
            Some(pr) if !pr.is_nan() => pbr_alpha(pr),
            _ => alpha_from_ns(self.ns),
        }
    }

    /// The scattering function of this material at a point whose base colour is `base_colour`:
    /// `kd`, or the value of the material's texture there (the caller looks it up). For the
    /// all-Lambertian scenes of the lab this is `Lambert { reflectance: base_colour }`, bit for bit
    /// what it always was.
    #[inline]
    pub fn bsdf(&self, base_colour: Vec3) -> MaterialBsdf {
        self.kind().bsdf(base_colour)
    }
}
