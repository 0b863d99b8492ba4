//! Triangle soup with optional per-corner attributes, in the order the scene file gave the faces.

use glam::{Vec2, Vec3};

/// Marks a triangle corner that has no normal or texture coordinate in the file.
pub const NO_INDEX: u32 = u32::MAX;

/// All triangles of a scene. Triangle `i` has corners `indices[i]` (into `positions`), material
/// `material_ids[i]`, and, when the file gave them, `normal_indices[i]` / `texcoord_indices[i]`.
///
/// Triangle ids follow gKit: faces in file order, polygons split as fans `(a,b,c), (a,c,d), ...`.
#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
    pub material_ids: Vec<u32>,
    pub normals: Vec<Vec3>,
    /// Empty when no face has normals; otherwise one entry per triangle, `NO_INDEX` per missing corner.
    pub normal_indices: Vec<[u32; 3]>,
    pub texcoords: Vec<Vec2>,
    /// Empty when no face has texture coordinates; otherwise one entry per triangle.
    pub texcoord_indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// The bytes of the arrays shading reads (positions, corners, materials, normals, texture
    /// coordinates).
    pub fn memory_bytes(&self) -> usize {
        fn bytes<T>(values: &[T]) -> usize {
            std::mem::size_of_val(values)
        }
        bytes(&self.positions)
            + bytes(&self.indices)
            + bytes(&self.material_ids)
            + bytes(&self.normals)
            + bytes(&self.normal_indices)
            + bytes(&self.texcoords)
            + bytes(&self.texcoord_indices)
    }

    /// The three corner positions of triangle `id`.
    #[inline]
    pub fn vertices(&self, id: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[id];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }

    /// The three corner normals of triangle `id`, if the file gave all of them.
    #[inline(always)]
    pub fn corner_normals(&self, id: usize) -> Option<[Vec3; 3]> {
        corners(&self.normals, self.normal_indices.get(id)?)
    }

    /// The three corner texture coordinates of triangle `id`, if the file gave all of them.
    #[inline(always)]
    pub fn corner_texcoords(&self, id: usize) -> Option<[Vec2; 3]> {
        corners(&self.texcoords, self.texcoord_indices.get(id)?)
    }
}

/// The values of `indices`, unless one is [`NO_INDEX`].
#[inline(always)]
fn corners<T: Copy>(values: &[T], &[a, b, c]: &[u32; 3]) -> Option<[T; 3]> {
    if a == NO_INDEX || b == NO_INDEX || c == NO_INDEX {
        return None;
    }
    Some([values[a as usize], values[b as usize], values[c as usize]])
}
