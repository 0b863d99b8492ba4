//! Bounding volume hierarchies over triangles. The BVH knows triangles only as three positions and
//! an id; materials and lights live elsewhere.
//!
//! - `bvh2/`: the binary binned-SAH build every layout starts from, and the scalar reference
//!   traversal the fast paths are checked against.
//! - `wide/`: the `W`-wide layout rendered with (nodes of `W` boxes, blocks of `W` triangles),
//!   collapsed from the binary tree, traversed with a SIMD lane kernel.
//! - `simd/`: the lane trait, its kernels, and [`Isa::detect`].
//! - `batch.rs`: shared-origin ray batches (shadow rays to one light triangle, AO hemispheres).
//! - `dispatch.rs`: [`Accel`], the wide BVH of the [`Isa`] a render runs with.

mod batch;
mod bvh2;
mod dispatch;
pub mod simd;
mod slab;
mod visit_order;
mod wide;

pub use batch::{OriginBatch, Region};
pub use bvh2::{BuildPreset, Bvh, Node};
pub use dispatch::Accel;
pub use simd::Isa;
pub use visit_order::VisitOrder;
pub use wide::{TriangleBlock, WideBvh, WideNode};

/// The 4-wide layout with the SSE kernel (the x86-64 baseline; the portable kernel elsewhere):
/// [`Accel`]'s choice for [`Isa::Sse2`].
pub type Bvh4 = WideBvh<4, simd::F32x4>;

/// The closest intersection along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// The triangle's id in the scene (file order).
    pub triangle: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
}

impl Hit {
    /// Whether a hit at `t` on `triangle` wins over one at `best_t` on `best_triangle`: the
    /// closer, ties to the lower id. Every traversal keeps hits by this one rule, so that the
    /// order triangles are tested in never changes the answer.
    #[inline(always)]
    pub fn precedes(t: f32, triangle: u32, best_t: f32, best_triangle: u32) -> bool {
        t < best_t || (t == best_t && triangle < best_triangle)
    }
}

/// Work done by counted queries, for the benchmarks: interior nodes whose children were box-tested
/// and triangle blocks tested.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    pub nodes: u64,
    pub blocks: u64,
}
