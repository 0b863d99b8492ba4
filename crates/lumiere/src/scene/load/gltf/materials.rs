//! glTF materials as lumiere's [`Material`]: the metallic-roughness model onto the MTL PBR
//! extension's mapping (a metal from `metallic ≥ 0.5`, otherwise a plastic with a 4% layer;
//! GGX `α = roughness²`), `KHR_materials_transmission` onto smooth glass of `KHR_materials_ior`'s
//! index, emission from `emissiveFactor` (times `KHR_materials_emissive_strength`), and the base
//! colour texture with its placement, the metallic-roughness texture as maps of the two, the
//! normal texture, and `alphaMode` `MASK` and `BLEND` as cutouts by the base colour's alpha.
//! What is not honoured is named in one warning per material.
//! docs/MATERIALS.md has the table.

use crate::error::{shown_name, shown_path};
use crate::materials::{CoverageTest, Cut, Material, NormalMap, ParameterMap, Relief};
use crate::math::UvTransform;
use crate::scene::load::warnings::Warnings;
use crate::textures::Channel;
use glam::{Vec2, Vec3};
use std::path::{Path, PathBuf};

/// The name of the material of primitives that name none: glTF's default material (white, fully
/// metallic and rough), named as an OBJ face without `usemtl` names its material.
pub const DEFAULT_NAME: &str = "default";

/// Transmission from which a material is drawn as glass: lumiere's dielectric transmits all or
/// nothing, so a weight is rounded to the nearer.
const GLASS_FROM_TRANSMISSION: f32 = 0.5;

/// Finds the file a glTF image is in (or names its embedded bytes); the error is a reason.
pub(super) type ImagePath<'r> = &'r mut dyn FnMut(&gltf::Image) -> Result<PathBuf, String>;

/// A glTF material as lumiere draws it, the texture coordinate set (`TEXCOORD_n`) its textures
/// read, and whether its surface is there at all.
pub(super) struct Converted {
    pub(super) material: Material,
    pub(super) texcoord_set: u32,
    /// False where `alphaMode MASK` cuts the whole surface out: its primitives are not drawn.
    pub(super) drawn: bool,
}

/// glTF's default material, of primitives that name none: white, metallic and rough.
pub(super) fn default_material() -> Converted {
    let mut material = Material::default_grey(DEFAULT_NAME);
    (material.kd, material.metallic, material.roughness) = (Vec3::ONE, Some(1.0), Some(1.0));
    Converted { material, texcoord_set: 0, drawn: true }
}

/// Converts `source`, warning (about `file`) about what is not honoured; `index` names an unnamed
/// material (`material3`).
pub(super) fn convert(
    source: &gltf::Material,
    file: &Path,
    image_path: ImagePath,
    warnings: &mut Warnings,
) -> Converted {
    let name = match (source.name(), source.index()) {
        (Some(name), _) => name.to_string(),
        (None, index) => format!("material{}", index.unwrap_or_default()),
    };
    let mut material = Material::default_grey(&name);
    let mut not_read: Vec<String> = Vec::new();
    let pbr = source.pbr_metallic_roughness();
    let [r, g, b, alpha] = pbr.base_color_factor();
    material.kd = Vec3::new(r, g, b);
    material.metallic = Some(pbr.metallic_factor());
    material.roughness = Some(pbr.roughness_factor());
    let mut texcoord_set = 0;
    if let Some(info) = pbr.base_color_texture() {
        match texture_of(&info, image_path, &mut not_read) {
            Ok((path, transform, set)) => {
                // The texture's colour times the factor, as glTF says (`kd`, the factor alone, is
                // what the material shows where the texture cannot be used).
                material.map_kd_factor = material.kd;
                material.map_kd = Some(path);
                material.map_kd_transform = transform;
                texcoord_set = set;
            }
            Err(reason) => {
                let not_read = TextureNotRead { kind: "base colour textures not read", texture: "baseColorTexture" };
                not_read.warn(warnings, file, &name, &reason, "baseColorFactor is used instead")
            }
        }
    }
    let glass = source.transmission().filter(|t| t.transmission_factor() >= GLASS_FROM_TRANSMISSION);
    if let Some(transmission) = glass {
        // Glass: the PBR fields would make it a metal or a plastic (see `Material::kind`).
        (material.metallic, material.roughness) = (None, None);
        material.illum = 7;
        // An index past f32's range (`"ior": 3.5e38`) reads as infinite: the default is used.
        material.ni = source.ior().filter(|ior| ior.is_finite()).unwrap_or(crate::materials::DEFAULT_IOR);
        material.tf = material.kd;
        if transmission.transmission_texture().is_some() {
            not_read.push("transmissionTexture".to_string());
        }
        if pbr.roughness_factor() > 0.0 {
            not_read.push("roughness under transmission (the glass is smooth)".to_string());
        }
        if pbr.metallic_roughness_texture().is_some() {
            not_read.push("metallicRoughnessTexture under transmission (the glass is smooth)".to_string());
        }
    } else {
        if source.ior().is_some_and(|ior| ior != crate::materials::DEFAULT_IOR) {
            not_read.push("KHR_materials_ior without transmission (the specular layer reflects 4%)".to_string());
        }
        if let Some(info) = pbr.metallic_roughness_texture() {
            let base_set = material.map_kd.is_some().then_some(texcoord_set);
            match metallic_roughness_maps(&mut material, &info, base_set, image_path, &mut not_read) {
                Ok(set) => texcoord_set = set,
                Err(reason) => {
                    let texture = "metallicRoughnessTexture";
                    let not_read = TextureNotRead { kind: "metallic-roughness textures not read", texture };
                    not_read.warn(warnings, file, &name, &reason, "metallicFactor and roughnessFactor are used instead")
                }
            }
        }
    }
    if let Some(normal) = source.normal_texture() {
        let set_so_far = (material.map_kd.is_some() || material.map_pm.is_some()).then_some(texcoord_set);
        match normal_map(&mut material, &normal, set_so_far, image_path, &mut not_read) {
            Ok(set) => texcoord_set = set,
            Err(reason) => {
                let not_read = TextureNotRead { kind: "normal textures not read", texture: "normalTexture" };
                not_read.warn(warnings, file, &name, &reason, "the surface keeps its interpolated normals")
            }
        }
    }
    let strength = source.emissive_strength().unwrap_or(1.0);
    material.ke = Vec3::from(source.emissive_factor()) * strength;
    if source.emissive_texture().is_some() && material.is_emissive() {
        // A texture that paints a screen or a lamp's bulb on a surface: emitting its factor over
        // the whole surface would light the scene with what is mostly dark.
        material.ke = Vec3::ZERO;
        not_read
            .push("emissiveTexture (the material does not emit; --emission NAME=R,G,B makes it a light)".to_string());
    }
    let mut drawn = true;
    match source.alpha_mode() {
        gltf::material::AlphaMode::Opaque => {}
        gltf::material::AlphaMode::Mask => {
            let cutoff = source.alpha_cutoff().unwrap_or(DEFAULT_ALPHA_CUTOFF);
            drawn = cut_by_alpha(&mut material, alpha, Cut::Below(cutoff));
            if !drawn {
                warn_cut_whole(
                    warnings,
                    file,
                    &name,
                    &format!("MASK cuts it out (baseColorFactor alpha {alpha} below alphaCutoff {cutoff})"),
                );
            }
        }
        // A light is whole (see `Material::cutout_mask`).
        gltf::material::AlphaMode::Blend if material.is_emissive() => {
            not_read.push("alphaMode BLEND on an emitter (drawn opaque: a light is whole)".to_string());
        }
        gltf::material::AlphaMode::Blend => {
            drawn = cut_by_alpha(&mut material, alpha, Cut::Hashed);
            if !drawn {
                warn_cut_whole(warnings, file, &name, "BLEND covers none of it (baseColorFactor alpha 0)");
            }
        }
    }
    for (present, what) in [(source.occlusion_texture().is_some(), "occlusionTexture")] {
        if present {
            not_read.push(what.to_string());
        }
    }
    if !not_read.is_empty() {
        let list = not_read.join(", ");
        warnings.push(file, "material properties not read", || {
            format!("{}: material {}: not read: {list}", shown_path(file), shown_name(&name))
        });
    }
    Converted { material, texcoord_set, drawn }
}

/// A texture of a material that could not be read: the kind of warning (capped per kind) and the
/// texture's glTF name.
struct TextureNotRead {
    kind: &'static str,
    texture: &'static str,
}

impl TextureNotRead {
    /// Warns (about `file`) that material `name`'s texture was not read, for `reason`, and what
    /// is used `instead`.
    fn warn(&self, warnings: &mut Warnings, file: &Path, name: &str, reason: &str, instead: &str) {
        warnings.push(file, self.kind, || {
            format!(
                "{}: material {}: {} not read: {reason}; {instead}",
                shown_path(file),
                shown_name(name),
                self.texture
            )
        })
    }
}

/// glTF's `alphaCutoff` where a `MASK` material gives none.
const DEFAULT_ALPHA_CUTOFF: f32 = 0.5;

/// glTF's `alphaMode` `MASK` or `BLEND` onto a cutout by the base colour's alpha, its texture's
/// (read from the same texels as the colour) times its factor's `alpha`, cut as `cut` says.
/// Without a texture the factor's alpha covers the whole surface alike: returns whether it covers
/// any of it.
fn cut_by_alpha(material: &mut Material, alpha: f32, cut: Cut) -> bool {
    material.map_d_test = CoverageTest { alpha_only: true, scale: alpha, cut };
    if let Some(texture) = &material.map_kd {
        material.map_d = Some(texture.clone());
        material.map_d_transform = material.map_kd_transform;
        return true;
    }
    match cut {
        Cut::Below(cutoff) => alpha >= cutoff,
        Cut::Hashed => alpha > 0.0,
    }
}

/// Warns that `name`'s primitives are not drawn, its alpha mode covering none of its surface
/// (`why`).
fn warn_cut_whole(warnings: &mut Warnings, file: &Path, name: &str, why: &str) {
    warnings.push(file, "materials cut out whole", || {
        format!(
            "{}: material {}: alphaMode {why}, without a texture: its primitives are not drawn",
            shown_path(file),
            shown_name(name)
        )
    });
}

/// glTF's `metallicRoughnessTexture` onto `material`'s metallic and roughness maps: its blue
/// channel times `metallicFactor`, its green times `roughnessFactor` (data, not colours). Returns
/// the coordinate set the material's textures read ([`shared_set`], after the base colour's
/// `base_set`).
fn metallic_roughness_maps(
    material: &mut Material,
    info: &gltf::texture::Info,
    base_set: Option<u32>,
    image_path: ImagePath,
    not_read: &mut Vec<String>,
) -> Result<u32, String> {
    let (path, transform, set) = texture_of(info, image_path, not_read)?;
    let map = |channel, factor: Option<f32>| ParameterMap {
        path: path.clone(),
        transform,
        channel,
        scale: factor.unwrap_or(1.0),
    };
    material.map_pm = Some(map(Channel::Blue, material.metallic));
    material.map_pr = Some(map(Channel::Green, material.roughness));
    Ok(shared_set("metallicRoughnessTexture", set, base_set, not_read))
}

/// The coordinate set a material's textures read, where its texture `texture` names `set`: the
/// set of its textures read before (`set_so_far`) where it has some, since a material's textures
/// share one set here; a set that differs goes onto `not_read`.
fn shared_set(texture: &str, set: u32, set_so_far: Option<u32>, not_read: &mut Vec<String>) -> u32 {
    match set_so_far {
        Some(so_far) if so_far != set => {
            not_read.push(format!("{texture}'s TEXCOORD_{set} (it reads TEXCOORD_{so_far}, as the other textures do)"));
            so_far
        }
        _ => set,
    }
}

/// A texture's file, placement and coordinate set; what is not honoured of it goes onto
/// `not_read`.
fn texture_of(
    info: &gltf::texture::Info,
    image_path: ImagePath,
    not_read: &mut Vec<String>,
) -> Result<(PathBuf, UvTransform, u32), String> {
    let path = texture_file(&info.texture(), image_path, not_read)?;
    let mut set = info.tex_coord();
    let mut transform = UvTransform::default();
    if let Some(placement) = info.texture_transform() {
        set = placement.tex_coord().unwrap_or(set);
        if placement.rotation() != 0.0 {
            not_read.push("KHR_texture_transform's rotation".to_string());
        }
        let placed = flipped(Vec2::from(placement.scale()), Vec2::from(placement.offset()));
        if placed.scale.is_finite() && placed.offset.is_finite() {
            transform = placed;
        } else {
            not_read.push("KHR_texture_transform with numbers that are not finite".to_string());
        }
    }
    Ok((path, transform, set))
}

/// The file of `texture`'s image (or the name of its embedded bytes); a sampler that does not
/// repeat goes onto `not_read`.
fn texture_file(texture: &gltf::Texture, image_path: ImagePath, not_read: &mut Vec<String>) -> Result<PathBuf, String> {
    let sampler = texture.sampler();
    if sampler.wrap_s() != gltf::texture::WrappingMode::Repeat
        || sampler.wrap_t() != gltf::texture::WrappingMode::Repeat
    {
        not_read.push("the sampler's wrapping (textures repeat)".to_string());
    }
    image_path(&texture.source())
}

/// glTF's `normalTexture` onto `material`'s normal map, with its `scale` (a `KHR_texture_transform`
/// on it is not seen: the `gltf` crate reads that extension on other textures only). Returns the
/// coordinate set the material's textures read ([`shared_set`], after `set_so_far`).
fn normal_map(
    material: &mut Material,
    normal: &gltf::material::NormalTexture,
    set_so_far: Option<u32>,
    image_path: ImagePath,
    not_read: &mut Vec<String>,
) -> Result<u32, String> {
    let path = texture_file(&normal.texture(), image_path, not_read)?;
    material.normal_map =
        Some(NormalMap { path, transform: UvTransform::default(), scale: normal.scale(), relief: Relief::Directions });
    Ok(shared_set("normalTexture", normal.tex_coord(), set_so_far, not_read))
}

/// A placement `uv · scale + offset` in glTF's coordinates (`v` down from the image's top) as one in
/// lumiere's, where `v` runs up from the bottom as in OBJ (the loader reads `v` as `1 − v`).
fn flipped(scale: Vec2, offset: Vec2) -> UvTransform {
    UvTransform { scale, offset: Vec2::new(offset.x, 1.0 - offset.y - scale.y) }
}
