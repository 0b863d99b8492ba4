//! From the binary tree to the wide one: each wide node takes up to `W` binary descendants as its
//! children, those that the collapse plan (`collapse_plan.rs`) found cheapest for the SAH.
//!
//! The leaves' triangle blocks are laid out in the binary tree's leaf order (spatially coherent)
//! and filled in parallel before the nodes are collapsed: gathering every triangle's corners is
//! most of the work, and the nodes then only refer to their leaves' blocks.

use std::marker::PhantomData;
use std::mem::MaybeUninit;

use glam::Vec3;
use rayon::prelude::*;

use super::collapse_plan::CollapsePlan;
use super::node::{TriangleBlock, WideNode};
use super::{WideBvh, leaf};
use crate::accel::bvh2::{Bvh, Node};
use crate::accel::simd::Lanes;

impl<const W: usize, L: Lanes<W>> WideBvh<W, L> {
    /// Collapses a binary BVH. Any binary tree will do; one built for blocks of `W` triangles
    /// (`Bvh::build_for_width::<W>`) has the leaves this layout packs best.
    pub fn from_binary(bvh: &Bvh) -> Self {
        Self::from_tree(bvh, |slot| bvh.vertices[slot])
    }

    /// Collapses the tree of `bvh`, reading the corners of the triangle in leaf-order slot `i`
    /// from `corners(i)` (so that the tree need not hold a copy of them).
    pub(in crate::accel) fn from_tree(bvh: &Bvh, corners: impl Fn(usize) -> [Vec3; 3] + Sync) -> Self {
        // The byte budgets of this width, checked at compile time.
        let () = WideNode::<W>::BYTE_BUDGET;
        let () = TriangleBlock::<W>::BYTE_BUDGET;
        // A BVH is the only way into a kernel's code (`Lanes::dispatch`): never build one for a
        // kernel this CPU cannot run.
        assert!(L::supported(), "this CPU cannot run the kernel of a {W}-wide BVH");

        let root = &bvh.nodes()[0];
        let lone_leaf = root.is_leaf() || bvh.triangle_count() == 0;
        // The plan reads only the binary nodes: it is worked out while the blocks are filled.
        let ((blocks, first_block_of_leaf), plan) =
            rayon::join(|| leaf_blocks::<W>(bvh, &corners), || (!lone_leaf).then(|| CollapsePlan::<W>::new(bvh)));
        // Each wide node takes at least one binary interior node: room for all, reserved, not touched.
        let interior = bvh.nodes().len() - first_block_of_leaf.iter().filter(|&&b| b != NOT_A_LEAF).count();
        let mut wide = WideBvh {
            nodes: Vec::with_capacity(interior.max(1)),
            blocks,
            triangle_count: bvh.triangle_count(),
            moderate_extent: {
                let bounds = root.bounds();
                (bounds.min.abs().max(bounds.max.abs())).max_element() < super::SPAN_CULL_EXTENT
            },
            kernel: PhantomData,
        };
        if let Some(plan) = plan {
            wide.collapse(bvh, &plan, &first_block_of_leaf, 0);
        } else {
            // A lone leaf (or nothing) still needs a wide root node to hang from.
            wide.nodes.push(WideNode::empty());
            if bvh.triangle_count() > 0 {
                let leaf = leaf::encode::<W>(0, wide.blocks.len());
                set_child(&mut wide.nodes[0], 0, leaf, root);
            }
        }
        // Once every child is set, in parallel: node by node inside the serial collapse, the
        // orders made the bunny-1m build 8% longer at 2 threads.
        wide.nodes.par_iter_mut().for_each(WideNode::order_children);
        wide
    }

    /// Writes the wide node for binary interior node `index` (and its subtree); returns its index.
    fn collapse(&mut self, bvh: &Bvh, plan: &CollapsePlan<W>, first_block_of_leaf: &[u32], index: usize) -> u32 {
        let nodes = bvh.nodes();
        let mut children = [0usize; W];
        let count = plan.children_of(nodes, index, &mut children);
        let wide_index = self.nodes.len();
        self.nodes.push(WideNode::empty());
        for (slot, &child) in children[..count].iter().enumerate() {
            let binary = &nodes[child];
            let reference = if binary.is_leaf() {
                let first_block = first_block_of_leaf[child] as usize;
                leaf::encode::<W>(first_block, (binary.count as usize).div_ceil(W))
            } else {
                self.collapse(bvh, plan, first_block_of_leaf, child)
            };
            set_child(&mut self.nodes[wide_index], slot, reference, binary);
        }
        wide_index as u32
    }
}

/// `leaf_blocks`'s entry for an interior node.
const NOT_A_LEAF: u32 = u32::MAX;

/// The triangle blocks of every leaf of `bvh`, leaf after leaf in slot order, and the first block
/// of each leaf by binary node index (`NOT_A_LEAF` for the others).
fn leaf_blocks<const W: usize>(
    bvh: &Bvh,
    corners: &(impl Fn(usize) -> [Vec3; 3] + Sync),
) -> (Vec<TriangleBlock<W>>, Vec<u32>) {
    let nodes = bvh.nodes();
    let mut first_block_of_leaf = vec![NOT_A_LEAF; nodes.len()];
    // Leaves in slot order: a depth-first walk, left child first, meets them as the build numbered them.
    let mut leaves = Vec::new();
    let mut block_count = 0;
    let mut stack = vec![0usize];
    while let Some(index) = stack.pop() {
        let node = &nodes[index];
        if node.is_leaf() {
            first_block_of_leaf[index] = block_count as u32;
            block_count += (node.count as usize).div_ceil(W);
            leaves.push((node.first as usize, node.count as usize));
        } else if bvh.triangle_count() > 0 {
            stack.push(node.first as usize + 1);
            stack.push(node.first as usize);
        }
    }
    let mut blocks = Vec::with_capacity(block_count);
    // Each leaf's piece of the uninitialised array, filled in parallel (first touches included).
    let mut pieces = Vec::with_capacity(leaves.len());
    let mut rest = &mut blocks.spare_capacity_mut()[..block_count];
    for &(first, count) in &leaves {
        let (piece, tail) = rest.split_at_mut(count.div_ceil(W));
        pieces.push((piece, first, count));
        rest = tail;
    }
    pieces.into_par_iter().for_each(|(piece, first, count)| fill_leaf(bvh, corners, piece, first, count));
    // SAFETY: the pieces cover the first `block_count` entries, and `fill_leaf` wrote each of them.
    unsafe { blocks.set_len(block_count) };
    (blocks, first_block_of_leaf)
}

/// Writes the blocks of the leaf holding triangle slots `first .. first + count`; a last block
/// not full repeats the leaf's last triangle.
fn fill_leaf<const W: usize>(
    bvh: &Bvh,
    corners: &impl Fn(usize) -> [Vec3; 3],
    piece: &mut [MaybeUninit<TriangleBlock<W>>],
    first: usize,
    count: usize,
) {
    for (block_slot, start) in piece.iter_mut().zip((first..first + count).step_by(W)) {
        let mut block = TriangleBlock { vertices: [[[0.0; W]; 3]; 3], ids: [0; W] };
        for lane in 0..W {
            let slot = (start + lane).min(first + count - 1);
            for (corner, p) in corners(slot).iter().enumerate() {
                for axis in 0..3 {
                    block.vertices[corner][axis][lane] = p[axis];
                }
            }
            block.ids[lane] = bvh.triangle_id(slot);
        }
        block_slot.write(block);
    }
}

fn set_child<const W: usize>(node: &mut WideNode<W>, slot: usize, reference: u32, binary: &Node) {
    for axis in 0..3 {
        node.bounds[axis][slot] = binary.min[axis];
        node.bounds[axis + 3][slot] = binary.max[axis];
    }
    node.children[slot] = reference;
}
