//! From the binary tree to the wide one: each wide node takes its binary node's children and keeps
//! opening the largest interior child (by surface area, the one most rays enter) until it has `W`.

use std::marker::PhantomData;

use glam::Vec3;

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
    pub(in crate::accel) fn from_tree(bvh: &Bvh, corners: impl Fn(usize) -> [Vec3; 3]) -> Self {
        // The byte budgets of this width, checked at compile time.
        let () = WideNode::<W>::BYTE_BUDGET;
        let () = TriangleBlock::<W>::BYTE_BUDGET;
        // A BVH is the only way into a kernel's code (`Lanes::dispatch`): never build one for a
        // kernel this CPU cannot run.
        assert!(L::supported(), "this CPU cannot run the kernel of a {W}-wide BVH");

        // Every leaf's blocks, counted up front: growing the block array by doubling copied it
        // and touched fresh memory over and over (a sixth of the bunny-1m build).
        let block_count = bvh.nodes().iter().filter(|n| n.is_leaf()).map(|n| (n.count as usize).div_ceil(W)).sum();
        let mut wide = WideBvh {
            nodes: Vec::new(),
            blocks: Vec::with_capacity(block_count),
            triangle_count: bvh.triangle_count(),
            kernel: PhantomData,
        };
        let root = &bvh.nodes()[0];
        if root.is_leaf() || bvh.triangle_count() == 0 {
            // A lone leaf (or nothing) still needs a wide root node to hang from.
            wide.nodes.push(WideNode::empty());
            if bvh.triangle_count() > 0 {
                let leaf = wide.push_leaf(bvh, &corners, root.first as usize, root.count as usize);
                set_child(&mut wide.nodes[0], 0, leaf, root);
            }
        } else {
            wide.collapse(bvh, &corners, 0);
        }
        wide
    }

    /// Writes the wide node for binary interior node `index` (and its subtree); returns its index.
    fn collapse(&mut self, bvh: &Bvh, corners: &impl Fn(usize) -> [Vec3; 3], index: usize) -> u32 {
        let nodes = bvh.nodes();
        let node = &nodes[index];
        let mut children = vec![node.first as usize, node.first as usize + 1];
        while children.len() < W {
            let widest = children
                .iter()
                .enumerate()
                .filter(|&(_, &c)| !nodes[c].is_leaf())
                .max_by(|a, b| nodes[*a.1].bounds().half_area().total_cmp(&nodes[*b.1].bounds().half_area()));
            let Some((slot, &open)) = widest else { break };
            let first = nodes[open].first as usize;
            children[slot] = first;
            children.push(first + 1);
        }
        let wide_index = self.nodes.len();
        self.nodes.push(WideNode::empty());
        for (slot, &child) in children.iter().enumerate() {
            let binary = &nodes[child];
            let reference = if binary.is_leaf() {
                self.push_leaf(bvh, corners, binary.first as usize, binary.count as usize)
            } else {
                self.collapse(bvh, corners, child)
            };
            set_child(&mut self.nodes[wide_index], slot, reference, binary);
        }
        wide_index as u32
    }

    /// Appends the blocks of a leaf holding triangle slots `first .. first + count`; returns its reference.
    fn push_leaf(&mut self, bvh: &Bvh, corners: &impl Fn(usize) -> [Vec3; 3], first: usize, count: usize) -> u32 {
        let first_block = self.blocks.len();
        for start in (first..first + count).step_by(W) {
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
            self.blocks.push(block);
        }
        leaf::encode::<W>(first_block, self.blocks.len() - first_block)
    }
}

fn set_child<const W: usize>(node: &mut WideNode<W>, slot: usize, reference: u32, binary: &Node) {
    for axis in 0..3 {
        node.bounds[axis][slot] = binary.min[axis];
        node.bounds[axis + 3][slot] = binary.max[axis];
    }
    node.children[slot] = reference;
}
