//! The textures that paint a material's PBR parameters (MTL's `map_Pm` and `map_Pr`, glTF's
//! `metallicRoughnessTexture`), decoded once, and the kind of scattering they give at a hit:
//! [`MaterialKind::pbr`] of the metallic weight and roughness read there, as
//! [`Material::kind`] maps the constants.

use glam::Vec2;

use crate::materials::{Material, MaterialKind, ParameterMap, pbr_alpha};
use crate::math::UvTransform;
use crate::textures::{Channel, EmbeddedImages, TextureId, TextureSet, TextureUse};

/// Each material's painted parameters, where it has any, and the textures they read.
#[derive(Clone, Debug, Default)]
pub(super) struct ParameterTextures {
    /// `None` for the materials no texture paints (most): their kind is the constant one.
    of_material: Vec<Option<Painted>>,
    textures: TextureSet,
}

/// A material's metallic weight and GGX roughness at a hit.
#[derive(Clone, Copy, Debug)]
struct Painted {
    metallic: Parameter,
    /// Read as a perceptual roughness and squared; a constant is already `α`.
    alpha: Parameter,
}

/// One parameter at a hit: the material's constant, or a texture's value there.
#[derive(Clone, Copy, Debug)]
enum Parameter {
    Constant(f32),
    Painted {
        texture: TextureId,
        /// `None` where the placement leaves the texture where it is (most maps).
        placement: Option<UvTransform>,
        channel: Channel,
        scale: f32,
    },
}

impl Parameter {
    /// The parameter painted by `map` where its texture decoded (`id`), otherwise `constant`.
    fn new(map: Option<&ParameterMap>, id: Option<TextureId>, constant: f32) -> Parameter {
        match (map, id) {
            (Some(map), Some(texture)) => Parameter::Painted {
                texture,
                placement: map.transform.moving(),
                channel: map.channel,
                scale: map.scale,
            },
            _ => Parameter::Constant(constant),
        }
    }

    fn is_painted(&self) -> bool {
        matches!(self, Parameter::Painted { .. })
    }

    /// The value at `uv`: the constant, or `to_value` of the texture's scaled value there.
    #[inline]
    fn at(&self, textures: &TextureSet, uv: Vec2, to_value: impl FnOnce(f32) -> f32) -> f32 {
        match *self {
            Parameter::Constant(value) => value,
            Parameter::Painted { texture, placement, channel, scale } => {
                let uv = placement.map_or(uv, |p| p.apply(uv));
                to_value(scale * textures.get(texture).sample_channel(uv, channel))
            }
        }
    }
}

impl ParameterTextures {
    /// Decodes the parameter maps of `materials` (or takes the images `embedded` in the scene
    /// file), each file once, with the warnings of [`TextureSet::for_use`]: a map that
    /// cannot be used leaves its material the constant.
    pub(super) fn for_materials(materials: &[Material], embedded: &EmbeddedImages) -> (ParameterTextures, Vec<String>) {
        let paths =
            materials.iter().flat_map(|m| [&m.map_pm, &m.map_pr]).map(|map| map.as_ref().map(|map| map.path.as_path()));
        let (ids, textures, warnings) = TextureSet::for_use(TextureUse::Parameters, paths, embedded);
        let of_material = materials
            .iter()
            .zip(ids.chunks_exact(2))
            .map(|(material, ids)| {
                let metallic = Parameter::new(material.map_pm.as_ref(), ids[0], material.metallic.unwrap_or(0.0));
                let alpha = Parameter::new(material.map_pr.as_ref(), ids[1], material.pbr_alpha());
                (metallic.is_painted() || alpha.is_painted()).then_some(Painted { metallic, alpha })
            })
            .collect();
        (ParameterTextures { of_material, textures }, warnings)
    }

    /// The kind of scattering of material `material` at texture coordinates `uv`, if textures
    /// paint its parameters; `None` where its kind is [`Material::kind`] everywhere.
    #[inline]
    pub(super) fn kind_at(&self, material: usize, uv: Vec2) -> Option<MaterialKind> {
        let painted = self.of_material.get(material)?.as_ref()?;
        let metallic = painted.metallic.at(&self.textures, uv, |metallic| metallic);
        let alpha = painted.alpha.at(&self.textures, uv, pbr_alpha);
        Some(MaterialKind::pbr(metallic, alpha))
    }

    /// The stable hashes of the files material `material`'s metallic and roughness maps were
    /// decoded from, `None` where it has none or its file could not be used.
    pub(super) fn contents(&self, material: usize) -> [Option<u64>; 2] {
        let painted = self.of_material.get(material).copied().flatten();
        let content = |parameter: Option<Parameter>| match parameter? {
            Parameter::Painted { texture, .. } => Some(self.textures.contents_hash(texture)),
            Parameter::Constant(_) => None,
        };
        [content(painted.map(|p| p.metallic)), content(painted.map(|p| p.alpha))]
    }

    /// The bytes all texels take in memory.
    pub(super) fn memory_bytes(&self) -> usize {
        self.textures.memory_bytes()
    }
}
