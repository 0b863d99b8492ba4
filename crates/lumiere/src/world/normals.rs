//! Normal and bump maps (glTF's `normalTexture`, MTL `norm`, `bump` and `map_Bump`), decoded
//! once, and the shading normal they give at a hit: a normal map's direction in the frame of the
//! triangle's texture axes and the interpolated shading normal, or the normal of the surface a
//! height map displaces along it.
//!
//! The tangent frame is the triangle's own: `∂p/∂u` and `∂p/∂v` from its corners' positions and
//! texture coordinates, made orthonormal around the shading normal. glTF asks for MikkTSpace
//! tangents where a file gives none; per-triangle derivatives agree with them on flat and gently
//! curved surfaces, and a file's `TANGENT` attribute is not read (docs/MATERIALS.md).
//!
//! The relief belongs to the surface's front, the side its winding faces: seen from behind, a
//! surface shows the opposite of the normal its front shows, as a thin sheet pressed into that
//! relief would (and as glTF's reference viewer flips the whole frame on back faces).

use glam::{Vec2, Vec3};

use crate::materials::{Material, Relief};
use crate::math::UvTransform;
use crate::textures::{Channel, EmbeddedImages, Texture, TextureId, TextureSet, TextureUse};

/// Each material's normal map, where it has one that decoded, and the textures.
#[derive(Clone, Debug, Default)]
pub(super) struct NormalMaps {
    of_material: Vec<Option<Placed>>,
    textures: TextureSet,
}

/// A material's normal map with its placement, strength and what its texels hold.
#[derive(Clone, Copy, Debug)]
struct Placed {
    texture: TextureId,
    /// `None` where the placement leaves the texture where it is.
    placement: Option<UvTransform>,
    scale: f32,
    /// Directions, or heights in a channel: a bump map with a normal map's colours reads as
    /// directions ([`has_normal_map_colours`]).
    relief: Relief,
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
        // Each texture's colours are looked at once, however many materials share it as a bump map.
        let mut normal_coloured: Vec<Option<bool>> = vec![None; textures.len()];
        let of_material = materials
            .iter()
            .zip(ids)
            .map(|(material, id)| {
                let map = material.normal_map.as_ref()?;
                let texture = id?;
                let placement = map.transform.moving();
                let relief = match map.relief {
                    Relief::Heights { .. } => {
                        let coloured = normal_coloured[texture.index()]
                            .get_or_insert_with(|| has_normal_map_colours(textures.get(texture)));
                        if *coloured { Relief::Directions } else { map.relief }
                    }
                    Relief::Directions => Relief::Directions,
                };
                Some(Placed { texture, placement, scale: map.scale, relief })
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
        let Some(axes) = texture_axes(corners) else { return ns };
        // The relief is the front's (the module's comment): worked out there, turned back after.
        let [p0, p1, p2] = corners.positions;
        let behind = (p1 - p0).cross(p2 - p0).dot(ng) < 0.0;
        let front = if behind { -ns } else { ns };
        let texture = self.textures.get(map.texture);
        let placed = map.placement.map_or(uv, |p| p.apply(uv));
        let mapped = match map.relief {
            Relief::Directions => directions(texture, placed, axes, front, map.scale),
            Relief::Heights { channel } => {
                let stretch = map.placement.map_or(Vec2::ONE, |p| p.scale);
                displaced(texture, channel, placed, stretch, axes, front, map.scale)
            }
        };
        let mapped = mapped.map(|n| if behind { -n } else { n });
        mapped.filter(|n| n.dot(ng) > 0.0).unwrap_or(ns)
    }
}

/// The normal a normal map gives at its coordinates `uv` on a surface of texture axes `axes` and
/// shading normal `ns` (the front's): the texel's direction in the frame of the axes made
/// orthonormal around `ns`, its tangential part `scale` times as strong.
#[inline]
fn directions(texture: &Texture, uv: Vec2, (tangent, bitangent): (Vec3, Vec3), ns: Vec3, scale: f32) -> Option<Vec3> {
    let t = (tangent - ns * ns.dot(tangent)).try_normalize()?;
    let b = ns.cross(t);
    // On a triangle whose texture is mirrored, `∂p/∂v` lies on the other side of the tangent.
    let b = if b.dot(bitangent) < 0.0 { -b } else { b };
    let c = texture.sample_stored(uv) * 2.0 - Vec3::ONE;
    (t * (c.x * scale) + b * (c.y * scale) + ns * c.z).try_normalize()
}

/// The normal a height map gives at its coordinates `uv` (placed from the surface's by a scale of
/// `stretch`) on a surface of texture axes `axes` and shading normal `ns` (the front's): the
/// normal of the surface moved along `ns` by `scale` times the height, `p + ns · scale · h(u, v)`,
/// whose axes are `∂p/∂u + ns · scale · ∂h/∂u` and likewise in `v` (pbrt's bump mapping, with
/// the change of `ns` along the surface left out, as renderers do). The slopes are central
/// differences across one texel of the filtered heights.
#[inline]
fn displaced(
    texture: &Texture,
    channel: Channel,
    uv: Vec2,
    stretch: Vec2,
    (dpdu, dpdv): (Vec3, Vec3),
    ns: Vec3,
    scale: f32,
) -> Option<Vec3> {
    let step = Vec2::new(1.0 / texture.width() as f32, 1.0 / texture.height() as f32);
    let height = |offset: Vec2| texture.sample_channel(uv + offset, channel);
    let (du, dv) = (Vec2::new(0.5 * step.x, 0.0), Vec2::new(0.0, 0.5 * step.y));
    // Slopes in the texture's coordinates, then in the surface's through the placement's scale.
    let slope_u = (height(du) - height(-du)) / step.x * stretch.x;
    let slope_v = (height(dv) - height(-dv)) / step.y * stretch.y;
    let along_u = dpdu - ns * ns.dot(dpdu) + ns * (scale * slope_u);
    let along_v = dpdv - ns * ns.dot(dpdv) + ns * (scale * slope_v);
    let n = along_u.cross(along_v).try_normalize()?;
    // The axes' cross product faces `ns` unless the texture is mirrored on the triangle.
    Some(if n.dot(ns) < 0.0 { -n } else { n })
}

/// Whether a bump map's image holds a normal map's colours rather than heights: a height map is
/// grey, while a normal map's blue (its `z`, `2b − 1`, towards the surface's normal) stands well
/// above its red and green (the tilts, around one half) and never far below one half. Blender's
/// OBJ exporter writes its normal maps as `map_Bump`, and Blender's importer reads them back as
/// normal maps; a grey image is never taken for one.
fn has_normal_map_colours(texture: &Texture) -> bool {
    let (mut count, mut blue_above_tilts, mut below_half) = (0.0f64, 0.0f64, 0usize);
    for c in texture.stored_texels() {
        count += 1.0;
        blue_above_tilts += f64::from(c.z - 0.5 * (c.x + c.y));
        below_half += usize::from(c.z < 0.45);
    }
    count > 0.0 && blue_above_tilts / count >= 0.25 && below_half as f64 <= 0.01 * count
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
