//! The binary BVH: the binned-SAH build (with spatial splits) every layout starts from, flat
//! 32-byte nodes, a scalar closest-hit and occlusion traversal (the reference the wide kernels must
//! match bit for bit), and the structural validator.

mod build;
mod node;
mod spatial_split;
mod traverse;
mod validate;

pub use build::BuildPreset;
pub(super) use build::{MAX_DEPTH, MAX_LEAF_SIZE};
pub use node::Node;

use glam::Vec3;

use super::Bvh4;

/// A BVH with its triangles copied into leaf order, so that a leaf's triangles are contiguous in
/// memory and the hot loop reads no index buffer.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// `vertices[i]` are the corners of the `i`-th triangle in leaf order.
    pub(super) vertices: Vec<[Vec3; 3]>,
    /// `triangle_ids[i]` is the scene's id of the triangle in leaf-order slot `i`. A triangle cut
    /// by spatial splits fills a slot in each leaf that holds a piece of it.
    pub(super) triangle_ids: Vec<u32>,
    /// Distinct triangles in the tree.
    triangles: usize,
    /// Triangles given to the build, degenerate ones included.
    input_triangles: usize,
    /// Triangles per block of the wide layout the SAH was computed for (see `build::leaf_cost`).
    block_width: usize,
}

impl Bvh {
    /// Builds over the triangles `indices` of `positions` for the 4-wide layout, [`Bvh4`] (SSE2
    /// and the portable kernel): the SAH counts leaves in its blocks of four triangles. Triangle ids in hits are positions in
    /// `indices`. Zero-area triangles are left out: they are never hit.
    pub fn build(positions: &[Vec3], indices: &[[u32; 3]], preset: BuildPreset) -> Bvh {
        Self::build_for_width::<{ Bvh4::WIDTH }>(positions, indices, preset)
    }

    /// As [`Bvh::build`], for a wide layout with blocks of `W` triangles: a leaf of 1 to `W`
    /// triangles costs one block test, so the SAH fills the blocks' lanes.
    pub fn build_for_width<const W: usize>(positions: &[Vec3], indices: &[[u32; 3]], preset: BuildPreset) -> Bvh {
        let bvh = build::build::<W>(positions, indices, preset, true);
        debug_assert_eq!(bvh.validate(), Ok(()));
        bvh
    }

    /// The tree of [`Bvh::build_for_width`] without its copy of the corners, only to be collapsed
    /// into a wide layout right away (which gathers the corners itself): its own traversal and
    /// validator need them. Copying 36 bytes per triangle was a tenth of the bunny-1m build.
    pub(in crate::accel) fn build_tree_for_width<const W: usize>(
        positions: &[Vec3],
        indices: &[[u32; 3]],
        preset: BuildPreset,
    ) -> Bvh {
        build::build::<W>(positions, indices, preset, false)
    }

    /// The scene's id of the triangle in leaf-order slot `slot`.
    pub(in crate::accel) fn triangle_id(&self, slot: usize) -> u32 {
        self.triangle_ids[slot]
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// Triangles in the tree (the input less its zero-area triangles).
    pub fn triangle_count(&self) -> usize {
        self.triangles
    }

    /// Leaf slots: the triangles, plus the extra references spatial splits added.
    pub fn slot_count(&self) -> usize {
        self.triangle_ids.len()
    }

    /// Surface area heuristic cost of the tree with unit traversal and block costs: the expected
    /// number of node visits plus block tests (blocks of the width the tree was built for) for a
    /// random ray hitting the root box.
    pub fn sah_cost(&self) -> f64 {
        let root_area = self.nodes[0].bounds().half_area();
        if root_area <= 0.0 {
            return 0.0;
        }
        let total: f64 = self
            .nodes
            .iter()
            .map(|n| {
                let weight = if n.is_leaf() { build::leaf_cost(n.count as usize, self.block_width) } else { 1.0 };
                weight * n.bounds().half_area()
            })
            .sum();
        total / root_area
    }

    /// Checks the structural invariants; see `validate.rs`.
    pub fn validate(&self) -> Result<(), String> {
        validate::validate(self)
    }
}
