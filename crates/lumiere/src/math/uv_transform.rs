//! The placement of a texture on a surface: an axis-aligned scale and offset of texture
//! coordinates.

use glam::Vec2;

/// Where a texture lies on a surface: the `-s` (scale) and `-o` (offset) options of an MTL texture
/// statement, applied to the texture coordinates before the lookup, `uv · scale + offset` (as
/// Blender's importer maps them); `-s 4 4 1` repeats a tile four times across the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub scale: Vec2,
    pub offset: Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        UvTransform { scale: Vec2::ONE, offset: Vec2::ZERO }
    }
}

impl UvTransform {
    /// The coordinates to look the texture up at, for the surface's `uv`. A multiply then an add,
    /// never fused, so that every ISA gets the same bits.
    #[inline]
    pub fn apply(self, uv: Vec2) -> Vec2 {
        uv * self.scale + self.offset
    }

    pub fn is_identity(self) -> bool {
        self == UvTransform::default()
    }

    /// The placement where it moves the texture, `None` where it leaves it where it is (most
    /// maps): lookups then skip the multiply and add.
    pub fn moving(self) -> Option<UvTransform> {
        Some(self).filter(|p| !p.is_identity())
    }
}
