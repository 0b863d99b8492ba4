//! Tangent-space normal maps (glTF's `normalTexture`), decoded once, and the shading normal they
//! give at a hit: the map's direction in the frame of the triangle's texture axes and the
//! interpolated shading normal.
//!
//! The tangent frame is the triangle's own: `∂p/∂u` and `∂p/∂v` from its corners' positions and
//! texture coordinates, made orthonormal around the shading normal. glTF asks for MikkTSpace
//! tangents where a file gives none; per-triangle derivatives agree with them on flat and gently
//! curved surfaces, and a file's `TANGENT` attribute is not read (docs/MATERIALS.md).

use glam::{Vec2, Vec3};

use crate::materials::Material;
use crate::math::UvTransform;
use crate::textures::{EmbeddedImages, TextureId, TextureSet, TextureUse};

/// Each material's normal map, where it has one that decoded, and the textures.
#[derive(Clone, Debug, Default)]
pub(super) struct NormalMaps {
    of_material: Vec<Option<Placed>>,
    textures: TextureSet,
}

/// A material's normal map with its placement and strength.
#[derive(Clone, Copy, Debug)]
struct Placed {
    texture: TextureId,
    /// `None` where the placement leaves the texture where it is.
    placement: Option<UvTransform>,
    scale: f32,
}

/// The corners of a hit's triangle, which give its texture axes.
pub(super) struct Corners {
    pub(super) positions: [Vec3; 3],
    pub(super) texcoords: [Vec2; 3],
}

impl NormalMaps {
    /// Decodes the normal maps of `materials` (or takes the images `embedded` in the scene file),
    /// each file once; a map that cannot be used costs one warning and leaves its surface the
    /// interpolated normals.
    pub(super) fn for_materials(materials: &[Material], embedded: &EmbeddedImages) -> (NormalMaps, Vec<String>) {
        let paths = materials.iter().map(|m| m.normal_map.as_ref().map(|map| map.path.as_path()));
        let (ids, textures, warnings) = TextureSet::for_use(TextureUse::Normals, paths, embedded);
        let of_material = materials
            .iter()
            .zip(ids)
            .map(|(material, id)| {
                let map = material.normal_map.as_ref()?;
                let placement = Some(map.transform).filter(|p| !p.is_identity());
                Some(Placed { texture: id?, placement, scale: map.scale })
            })
            .collect();
        (NormalMaps { of_material, textures }, warnings)
    }

    /// Whether no material has a normal map (most scenes): hits keep their normals untouched.
    #[inline]
    pub(super) fn is_empty(&self) -> bool {
        self.textures.is_empty()
    }

    /// The stable hash of the file material `material`'s normal map was decoded from, `None`
    /// where it has none or its file could not be used.
    pub(super) fn contents(&self, material: usize) -> Option<u64> {
        let map = self.of_material.get(material).copied().flatten()?;
        Some(self.textures.contents_hash(map.texture))
    }

    /// The bytes all texels take in memory.
    pub(super) fn memory_bytes(&self) -> usize {
        self.textures.memory_bytes()
    }

    /// Whether material `material` has a normal map.
    #[inline]
    pub(super) fn maps(&self, material: u32) -> bool {
        self.of_material.get(material as usize).is_some_and(Option::is_some)
    }

    /// The shading normal at texture coordinates `uv` of a hit on a triangle of material
    /// `material` with `corners`, whose interpolated shading normal is `ns` and geometric normal
    /// `ng` (both on the side the ray arrived from). `ns` itself where the material has no map,
    /// where the triangle's texture axes are degenerate, or where the mapped normal would face away
    /// from `ng` (light would leak through the surface).
    #[inline]
    pub(super) fn shading_normal(&self, material: u32, corners: &Corners, uv: Vec2, ns: Vec3, ng: Vec3) -> Vec3 {
        let Some(Some(map)) = self.of_material.get(material as usize) else { return ns };
        let Some((tangent, bitangent)) = texture_axes(corners) else { return ns };
        let Some(t) = (tangent - ns * ns.dot(tangent)).try_normalize() else { return ns };
        let b = ns.cross(t);
        // On a triangle whose texture is mirrored (or seen from behind), `∂p/∂v` lies on the other
        // side of the tangent.
        let b = if b.dot(bitangent) < 0.0 { -b } else { b };
        let uv = map.placement.map_or(uv, |p| p.apply(uv));
        let c = self.textures.get(map.texture).sample_stored(uv) * 2.0 - Vec3::ONE;
        let mapped = (t * (c.x * map.scale) + b * (c.y * map.scale) + ns * c.z).try_normalize();
        mapped.filter(|n| n.dot(ng) > 0.0).unwrap_or(ns)
    }
}

/// `∂p/∂u` and `∂p/∂v` on the triangle of `corners`; `None` where its texture coordinates do not
/// span a triangle.
#[inline]
fn texture_axes(corners: &Corners) -> Option<(Vec3, Vec3)> {
    let [p0, p1, p2] = corners.positions;
    let [t0, t1, t2] = corners.texcoords;
    let (dp1, dp2, d1, d2) = (p1 - p0, p2 - p0, t1 - t0, t2 - t0);
    let det = d1.x * d2.y - d1.y * d2.x;
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let axes = ((dp1 * d2.y - dp2 * d1.y) / det, (dp2 * d1.x - dp1 * d2.x) / det);
    (axes.0.is_finite() && axes.1.is_finite()).then_some(axes)
}
