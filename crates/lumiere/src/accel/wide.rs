//! The 4-wide BVH used for rendering: the binary SAH tree collapsed so that each node holds up to
//! four children, whose boxes are tested together in one SSE pass, and leaves stored as blocks of
//! four triangles in SoA layout, tested together too.
//!
//! Why four and not eight: SSE is part of the x86-64 baseline, so the binary runs on every x86-64
//! CPU with no runtime dispatch; eight lanes would need AVX2 and a second code path.

use super::Bvh;

/// Child reference with this bit set: a leaf, `(first_block << 3) | (block_count - 1)`.
pub(super) const LEAF_BIT: u32 = 1 << 31;
/// Unused child slot; its box is NaN so no ray ever enters it.
pub(super) const EMPTY_CHILD: u32 = u32::MAX;

/// Up to four children: their boxes as SoA rows (min x, y, z then max x, y, z; one lane per child)
/// and their references. 128 bytes, two cache lines, aligned to them.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct Node4 {
    pub bounds: [[f32; 4]; 6],
    pub children: [u32; 4],
    _pad: [u32; 4],
}

const _: () = assert!(size_of::<Node4>() == 128);

/// Four triangles, corner-major SoA: `vertices[corner][axis][lane]`. A leaf whose triangle count is
/// not a multiple of four repeats its last triangle: a duplicate gives the same `t` and id, so it
/// never changes an answer, and the hot loop needs no lane mask.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct TriangleBlock {
    pub vertices: [[[f32; 4]; 3]; 3],
    pub ids: [u32; 4],
}

const _: () = assert!(size_of::<TriangleBlock>() == 160);

#[derive(Clone, Debug)]
pub struct Bvh4 {
    pub(super) nodes: Vec<Node4>,
    pub(super) blocks: Vec<TriangleBlock>,
    triangle_count: usize,
}

impl Bvh4 {
    /// Collapses a binary BVH: each wide node takes its binary node's children and keeps opening
    /// the largest interior child (by surface area, the one most rays enter) until it has four.
    pub fn from_binary(bvh: &Bvh) -> Bvh4 {
        let mut wide = Bvh4 { nodes: Vec::new(), blocks: Vec::new(), triangle_count: bvh.triangle_count() };
        let root = &bvh.nodes[0];
        if root.is_leaf() || bvh.triangle_count() == 0 {
            // A lone leaf (or nothing) still needs a wide root node to hang from.
            wide.nodes.push(empty_node());
            if bvh.triangle_count() > 0 {
                let leaf = wide.push_leaf(bvh, root.first as usize, root.count as usize);
                set_child(&mut wide.nodes[0], 0, leaf, root);
            }
        } else {
            wide.collapse(bvh, 0);
        }
        wide
    }

    pub fn nodes(&self) -> &[Node4] {
        &self.nodes
    }

    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Bytes held by the nodes and the triangle blocks.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * size_of::<Node4>() + self.blocks.len() * size_of::<TriangleBlock>()
    }

    /// Writes the wide node for binary interior node `index` (and its subtree); returns its index.
    fn collapse(&mut self, bvh: &Bvh, index: usize) -> u32 {
        let node = &bvh.nodes[index];
        let mut children = vec![node.first as usize, node.first as usize + 1];
        while children.len() < 4 {
            let widest =
                children.iter().enumerate().filter(|&(_, &c)| !bvh.nodes[c].is_leaf()).max_by(|a, b| {
                    bvh.nodes[*a.1].bounds().half_area().total_cmp(&bvh.nodes[*b.1].bounds().half_area())
                });
            let Some((slot, &open)) = widest else { break };
            let first = bvh.nodes[open].first as usize;
            children[slot] = first;
            children.push(first + 1);
        }
        let wide_index = self.nodes.len();
        self.nodes.push(empty_node());
        for (slot, &child) in children.iter().enumerate() {
            let binary = &bvh.nodes[child];
            let reference = if binary.is_leaf() {
                self.push_leaf(bvh, binary.first as usize, binary.count as usize)
            } else {
                self.collapse(bvh, child)
            };
            set_child(&mut self.nodes[wide_index], slot, reference, binary);
        }
        wide_index as u32
    }

    /// Appends the blocks of a leaf holding triangle slots `first .. first + count`; returns its reference.
    fn push_leaf(&mut self, bvh: &Bvh, first: usize, count: usize) -> u32 {
        let first_block = self.blocks.len();
        for start in (first..first + count).step_by(4) {
            let mut block = TriangleBlock { vertices: [[[0.0; 4]; 3]; 3], ids: [0; 4] };
            for lane in 0..4 {
                let slot = (start + lane).min(first + count - 1);
                for (corner, p) in bvh.vertices[slot].iter().enumerate() {
                    for axis in 0..3 {
                        block.vertices[corner][axis][lane] = p[axis];
                    }
                }
                block.ids[lane] = bvh.triangle_ids[slot];
            }
            self.blocks.push(block);
        }
        let block_count = self.blocks.len() - first_block;
        debug_assert!((1..=8).contains(&block_count) && first_block < 1 << 28);
        LEAF_BIT | (first_block as u32) << 3 | (block_count as u32 - 1)
    }
}

fn empty_node() -> Node4 {
    Node4 { bounds: [[f32::NAN; 4]; 6], children: [EMPTY_CHILD; 4], _pad: [0; 4] }
}

fn set_child(node: &mut Node4, slot: usize, reference: u32, binary: &super::Node) {
    for axis in 0..3 {
        node.bounds[axis][slot] = binary.min[axis];
        node.bounds[axis + 3][slot] = binary.max[axis];
    }
    node.children[slot] = reference;
}

/// Decodes a leaf reference into its block range.
#[inline(always)]
pub(super) fn leaf_blocks(reference: u32) -> std::ops::Range<usize> {
    let first = ((reference & !LEAF_BIT) >> 3) as usize;
    first..first + (reference & 7) as usize + 1
}
