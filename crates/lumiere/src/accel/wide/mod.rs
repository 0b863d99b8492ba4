//! The wide BVH used for rendering: the binary SAH tree collapsed so that each node holds up to `W`
//! children, whose boxes are tested together in one SIMD pass, and leaves stored as blocks of `W`
//! triangles in SoA layout, tested together too.
//!
//! The layout (nodes, blocks, collapse, leaf references) is generic in the width `W`; the traversal
//! is generic over the lane kernel `L` (see `simd/`). [`crate::accel::Accel`] instantiates `W = 4`
//! with the SSE kernel (the x86-64 baseline) or the portable one, and `W = 8` with the AVX2 kernel
//! (on both AVX ISAs: see `Accel`).

mod collapse;
mod collapse_plan;
mod leaf;
mod node;
mod packet;
mod shared_origin;
mod traverse;
mod triangles;

use std::marker::PhantomData;

use glam::Vec3;

pub(super) use leaf::{LEAF_BIT, blocks as leaf_blocks};
pub use node::{TriangleBlock, WideNode};
pub use packet::{PacketKey, RayPacket};
pub(super) use traverse::Stack;

use super::bvh2::{BuildPreset, Bvh};

/// A `W`-wide BVH traversed with the lanes `L` (a [`crate::accel::simd::Lanes<W>`] kernel).
#[derive(Clone, Debug)]
pub struct WideBvh<const W: usize, L> {
    pub(super) nodes: Vec<WideNode<W>>,
    pub(super) blocks: Vec<TriangleBlock<W>>,
    triangle_count: usize,
    /// Whether every corner lies within [`SPAN_CULL_EXTENT`] of the origin on every axis: where
    /// packets may cull whole blocks by the span of their rays (`packet.rs`, `PacketSpan`).
    moderate_extent: bool,
    /// The kernel is part of the type, so that the accel a world chose fixes its traversal code.
    /// (`fn() -> L`: the BVH owns no `L`, and stays `Send` and `Sync` whatever `L` is.)
    kernel: PhantomData<fn() -> L>,
}

impl<const W: usize, L> WideBvh<W, L> {
    /// Children per node and triangles per block.
    pub const WIDTH: usize = W;

    /// Builds the binary SAH tree for blocks of `W` triangles and collapses it.
    pub fn build(positions: &[Vec3], indices: &[[u32; 3]], preset: BuildPreset) -> Self
    where
        L: crate::accel::simd::Lanes<W>,
    {
        Self::from_binary(&Bvh::build_for_width::<W>(positions, indices, preset))
    }

    pub fn nodes(&self) -> &[WideNode<W>] {
        &self.nodes
    }

    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Bytes held by the nodes and the triangle blocks.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * size_of::<WideNode<W>>() + self.blocks.len() * size_of::<TriangleBlock<W>>()
    }
}

/// The largest coordinate, of a corner or of a packet's origin, for which packets cull blocks by
/// the span of their rays: below it, no product of two sheared corner coordinates overflows f32
/// (each is at most `2 * 2 * SPAN_CULL_EXTENT`, and 1.6e37 < f32::MAX), which the cull's proof
/// needs.
pub(super) const SPAN_CULL_EXTENT: f32 = 1e18;

/// Fixed pseudo-random numbers in `[0, 1)` for the unit tests (xorshift64, 24 bits a number).
#[cfg(test)]
pub(in crate::accel) fn unit_floats(seed: u64) -> impl FnMut() -> f32 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    }
}
