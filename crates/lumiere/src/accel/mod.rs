//! Bounding volume hierarchy over triangles: binned-SAH build, flat 32-byte nodes, closest-hit and
//! occlusion queries. The BVH knows triangles only as three positions and an id; materials and
//! lights live elsewhere.

mod batch;
mod build;
mod node;
mod simd;
mod traverse;
mod validate;
mod wide;
mod wide_traverse;

pub use batch::{OriginBatch, Region};
pub use build::BuildPreset;
pub use node::Node;
pub use traverse::Hit;
pub use wide::{Bvh4, Node4, TriangleBlock};

/// Work done by counted queries, for the benchmarks: interior nodes whose children were box-tested
/// and triangle blocks (of four) tested.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    pub nodes: u64,
    pub blocks: u64,
}

use glam::Vec3;

use crate::math::Aabb;

/// A BVH with its triangles copied into leaf order, so that a leaf's triangles are contiguous in
/// memory and the hot loop reads no index buffer.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// `vertices[i]` are the corners of the `i`-th triangle in leaf order.
    vertices: Vec<[Vec3; 3]>,
    /// `triangle_ids[i]` is the scene's id of the `i`-th triangle in leaf order.
    triangle_ids: Vec<u32>,
    /// Triangles given to the build, degenerate ones included.
    input_triangles: usize,
}

impl Bvh {
    /// Builds over the triangles `indices` of `positions`; triangle ids in hits are positions in
    /// `indices`. Zero-area triangles are left out: they are never hit.
    pub fn build(positions: &[Vec3], indices: &[[u32; 3]], preset: BuildPreset) -> Bvh {
        let bvh = build::build(positions, indices, preset);
        debug_assert_eq!(bvh.validate(), Ok(()));
        bvh
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// Triangles in the tree (the input less its zero-area triangles).
    pub fn triangle_count(&self) -> usize {
        self.triangle_ids.len()
    }

    pub fn bounds(&self) -> Aabb {
        self.nodes[0].bounds()
    }

    /// Surface area heuristic cost of the tree with unit traversal and block costs: the expected
    /// number of node visits plus 4-triangle block tests for a random ray hitting the root box.
    pub fn sah_cost(&self) -> f64 {
        let root_area = self.nodes[0].bounds().half_area();
        if root_area <= 0.0 {
            return 0.0;
        }
        let total: f64 = self
            .nodes
            .iter()
            .map(|n| {
                let weight = if n.is_leaf() { build::leaf_cost(n.count as usize) } else { 1.0 };
                weight * n.bounds().half_area()
            })
            .sum();
        total / root_area
    }

    /// Bytes held by the nodes, the leaf-ordered triangles and their ids.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * size_of::<Node>()
            + self.vertices.len() * size_of::<[Vec3; 3]>()
            + self.triangle_ids.len() * size_of::<u32>()
    }

    /// Checks the structural invariants; see `validate.rs`.
    pub fn validate(&self) -> Result<(), String> {
        validate::validate(self)
    }
}
