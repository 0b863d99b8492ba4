//! Binned SAH build (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", 2007).
//!
//! Each node bins triangle centroids along all three axes, sweeps the bins for the split of least
//! surface-area cost, and becomes a leaf when no split beats intersecting its triangles directly.
//! Large subtrees are built in parallel with rayon, then written once into one array, so siblings
//! stay adjacent and the layout is the same whatever the thread count.
//!
//! Triangles travel as 32-byte references holding their box and id (Embree's `PrimRef`), which the
//! partition moves: every pass reads memory in order, where an array of ids into a box array cost a
//! cache miss per triangle in the top levels. The partition also gathers both sides' bounds, so a
//! node never makes a pass of its own to find them.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::{Vec3, Vec3A};
use rayon::prelude::*;

use super::{Bvh, Node};
use crate::geometry::triangle::is_degenerate;
use crate::math::Aabb;

/// Leaves never hold more triangles than this (the traversal's leaf loop is sized by it).
pub const MAX_LEAF_SIZE: usize = 16;
/// Below this depth splits follow the SAH; deeper, the build halves by object count, so the
/// depth, and the traversal stack, stay bounded whatever the input.
const SAH_DEPTH_LIMIT: usize = 40;
/// Depth bound: SAH levels plus the halvings needed for 2^32 triangles.
pub const MAX_DEPTH: usize = SAH_DEPTH_LIMIT + 32;
/// Subtrees with fewer triangles are built on the current thread.
const PARALLEL_THRESHOLD: usize = 4096;

/// Named trade-offs between build time and trace speed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuildPreset {
    /// 8 bins: the quickest build, a slightly worse tree.
    Fast,
    /// 16 bins.
    #[default]
    Default,
    /// 64 bins.
    HighQuality,
}

impl BuildPreset {
    pub const ALL: [BuildPreset; 3] = [BuildPreset::Fast, BuildPreset::Default, BuildPreset::HighQuality];

    fn bins(self) -> usize {
        match self {
            BuildPreset::Fast => 8,
            BuildPreset::Default => 16,
            BuildPreset::HighQuality => 64,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            BuildPreset::Fast => "fast",
            BuildPreset::Default => "default",
            BuildPreset::HighQuality => "high",
        }
    }
}

/// Relative cost of visiting a node versus testing one block of triangles.
const TRAVERSAL_COST: f64 = 1.0;
const INTERSECTION_COST: f64 = 1.0;

/// The wide layouts test leaves `block_width` triangles at a time (see `wide/`), so a leaf of 1 to
/// `block_width` triangles costs one block test: counting blocks instead of triangles fills the
/// leaves' SIMD lanes. The build passes its const width, so the division is a shift for 4 or 8.
#[inline(always)]
pub(super) fn leaf_cost(count: usize, block_width: usize) -> f64 {
    count.div_ceil(block_width) as f64
}

/// Nodes with more triangles than this bin them in parallel chunks (the top levels, where
/// `rayon::join` has not yet split the work).
const PARALLEL_BINNING_THRESHOLD: usize = 1 << 16;
const BINNING_CHUNK: usize = 1 << 14;

/// A box in 16-byte lanes, so that growing it is one SSE min and one max.
#[derive(Clone, Copy, Debug)]
struct Box3A {
    min: Vec3A,
    max: Vec3A,
}

impl Box3A {
    const EMPTY: Box3A = Box3A { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

    #[inline(always)]
    fn union(self, o: Box3A) -> Box3A {
        Box3A { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    #[inline(always)]
    fn grow(self, p: Vec3A) -> Box3A {
        Box3A { min: self.min.min(p), max: self.max.max(p) }
    }

    fn to_aabb(self) -> Aabb {
        Aabb { min: self.min.into(), max: self.max.into() }
    }

    #[inline(always)]
    fn centroid(self) -> Vec3A {
        0.5 * (self.min + self.max)
    }
}

/// The id that marks a zero-area triangle before it is dropped (ids are below `u32::MAX`).
const DEGENERATE: u32 = u32::MAX;

/// A triangle as the build moves it: its box and its id, 32 bytes.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct PrimRef {
    min: [f32; 3],
    id: u32,
    max: [f32; 3],
}

impl PrimRef {
    #[inline(always)]
    fn bounds(&self) -> Box3A {
        Box3A { min: Vec3A::from_array(self.min), max: Vec3A::from_array(self.max) }
    }
}

/// Bounds of the triangles of a node and of their centroids, gathered in one pass.
#[derive(Clone, Copy)]
struct NodeBounds {
    bounds: Box3A,
    centroids: Box3A,
}

impl NodeBounds {
    const EMPTY: NodeBounds = NodeBounds { bounds: Box3A::EMPTY, centroids: Box3A::EMPTY };

    fn merge(self, o: NodeBounds) -> NodeBounds {
        NodeBounds { bounds: self.bounds.union(o.bounds), centroids: self.centroids.union(o.centroids) }
    }

    #[inline(always)]
    fn grow(self, b: Box3A) -> NodeBounds {
        NodeBounds { bounds: self.bounds.union(b), centroids: self.centroids.grow(b.centroid()) }
    }

    /// The bounds of `refs`, in parallel chunks when there are many.
    fn of(refs: &[PrimRef]) -> NodeBounds {
        let gather = |refs: &[PrimRef]| refs.iter().fold(NodeBounds::EMPTY, |acc, r| acc.grow(r.bounds()));
        if refs.len() > PARALLEL_BINNING_THRESHOLD {
            refs.par_chunks(BINNING_CHUNK).map(gather).reduce(|| NodeBounds::EMPTY, NodeBounds::merge)
        } else {
            gather(refs)
        }
    }
}

/// What every node of one build shares. `W` is the block width the SAH counts leaves in: a const,
/// not a field, so that `leaf_cost` divides by a constant in the split sweep.
struct Context<const W: usize> {
    bins: usize,
}

/// Builds the tree; with `copy_vertices` false the leaf-order corner copy is left out (for a tree
/// that is collapsed right away, see [`Bvh::build_tree_for_width`]).
pub fn build<const W: usize>(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    preset: BuildPreset,
    copy_vertices: bool,
) -> Bvh {
    let corners = |t: &[u32; 3]| t.map(|i| positions[i as usize]);
    // Zero-area triangles have no surface and are never hit (see `is_degenerate`).
    // Written in place by an indexed parallel map, then compacted if any is degenerate (a
    // serial pass): a parallel filter collects into pieces and copies them again (a tenth of the
    // bunny-1m build).
    let degenerate = AtomicBool::new(false);
    let mut refs: Vec<PrimRef> = indices
        .par_iter()
        .enumerate()
        .map(|(id, t)| {
            let [p0, p1, p2] = corners(t);
            let id = if is_degenerate(p0, p1, p2) {
                degenerate.store(true, Ordering::Relaxed);
                DEGENERATE
            } else {
                id as u32
            };
            let [a, b, c] = [p0, p1, p2].map(Vec3A::from);
            let (min, max) = (a.min(b).min(c), a.max(b).max(c));
            PrimRef { min: min.to_array(), id, max: max.to_array() }
        })
        .collect();
    if degenerate.into_inner() {
        refs.retain(|r| r.id != DEGENERATE);
    }
    let ctx = Context::<W> { bins: preset.bins() };

    let nodes = if refs.is_empty() {
        vec![Node::new(Aabb::EMPTY, 0, 0)]
    } else {
        let bounds = NodeBounds::of(&refs);
        build_subtree(&ctx, &mut refs, bounds, 0, 0).into_nodes()
    };
    let triangle_ids: Vec<u32> = refs.par_iter().map(|r| r.id).collect();
    let vertices = if copy_vertices {
        triangle_ids.par_iter().map(|&id| corners(&indices[id as usize])).collect()
    } else {
        Vec::new()
    };
    Bvh { nodes, vertices, triangle_ids, input_triangles: indices.len(), block_width: W }
}

/// A subtree as the parallel build returns it: built on one thread into an array of its own
/// (root at 0), or a node whose two subtrees were built in parallel. [`Subtree::place`] then
/// writes every node once into the tree's array; stitching the arrays together level by level
/// copied each node once per parallel level (eight on the 1.1M-triangle bunny), into fresh pages.
enum Subtree {
    Local(Vec<Node>),
    Split { bounds: Aabb, left: Box<Subtree>, right: Box<Subtree>, size: usize },
}

impl Subtree {
    /// Nodes in the subtree, its root included.
    fn size(&self) -> usize {
        match self {
            Subtree::Local(nodes) => nodes.len(),
            Subtree::Split { size, .. } => *size,
        }
    }

    /// Writes the root into `root` and the other nodes into `rest`, which starts at index
    /// `rest_start` of the tree's array. The layout is the one [`build_into`] gives a subtree
    /// built on one thread: a node's two children side by side, the left one's descendants next,
    /// then the right one's.
    fn place(self, root: &mut Node, rest: &mut [Node], rest_start: usize) {
        debug_assert_eq!(rest.len() + 1, self.size());
        match self {
            Subtree::Local(nodes) => {
                // Local index j > 0 moves to `rest_start + j - 1`; local 0 is `root`.
                let relink = |node: Node| {
                    if node.is_leaf() {
                        return node;
                    }
                    Node { first: (rest_start + node.first as usize - 1) as u32, ..node }
                };
                *root = relink(nodes[0]);
                for (slot, &node) in rest.iter_mut().zip(&nodes[1..]) {
                    *slot = relink(node);
                }
            }
            Subtree::Split { bounds, left, right, .. } => {
                *root = Node::new(bounds, rest_start as u32, 0);
                let (roots, descendants) = rest.split_at_mut(2);
                let (left_root, right_root) = roots.split_at_mut(1);
                let left_size = left.size();
                let (left_rest, right_rest) = descendants.split_at_mut(left_size - 1);
                let (left_start, right_start) = (rest_start + 2, rest_start + 1 + left_size);
                rayon::join(
                    || left.place(&mut left_root[0], left_rest, left_start),
                    || right.place(&mut right_root[0], right_rest, right_start),
                );
            }
        }
    }

    /// The tree's node array, root at 0.
    fn into_nodes(self) -> Vec<Node> {
        let mut nodes = vec![Node::default(); self.size()];
        let (root, rest) = nodes.split_at_mut(1);
        self.place(&mut root[0], rest, 1);
        nodes
    }
}

/// Builds the subtree over `refs` (whose bounds are `bounds`, and whose first element is triangle
/// slot `offset` in leaf order): large ones split in parallel, the rest on this thread.
fn build_subtree<const W: usize>(
    ctx: &Context<W>,
    refs: &mut [PrimRef],
    bounds: NodeBounds,
    offset: usize,
    depth: usize,
) -> Subtree {
    if refs.len() >= PARALLEL_THRESHOLD
        && let Some((mid, left_bounds, right_bounds)) =
            choose_split(ctx, refs, &bounds.bounds.to_aabb(), &bounds.centroids.to_aabb(), depth)
    {
        let (left, right) = refs.split_at_mut(mid);
        let (left, right) = rayon::join(
            || build_subtree(ctx, left, left_bounds, offset, depth + 1),
            || build_subtree(ctx, right, right_bounds, offset + mid, depth + 1),
        );
        let size = 1 + left.size() + right.size();
        return Subtree::Split { bounds: bounds.bounds.to_aabb(), left: Box::new(left), right: Box::new(right), size };
    }
    let mut nodes = Vec::with_capacity(refs.len());
    nodes.push(Node::default());
    build_into(ctx, refs, bounds, offset, depth, 0, &mut nodes);
    Subtree::Local(nodes)
}

/// Fills node `index` of `nodes` for the triangles `refs`, appending its descendants (on this
/// thread).
fn build_into<const W: usize>(
    ctx: &Context<W>,
    refs: &mut [PrimRef],
    node_bounds: NodeBounds,
    offset: usize,
    depth: usize,
    index: usize,
    nodes: &mut Vec<Node>,
) {
    let bounds = node_bounds.bounds.to_aabb();
    let Some((mid, left_bounds, right_bounds)) =
        choose_split(ctx, refs, &bounds, &node_bounds.centroids.to_aabb(), depth)
    else {
        nodes[index] = Node::new(bounds, offset as u32, refs.len() as u32);
        return;
    };
    let (left, right) = refs.split_at_mut(mid);
    let first_child = nodes.len();
    nodes[index] = Node::new(bounds, first_child as u32, 0);
    nodes.push(Node::default());
    nodes.push(Node::default());
    build_into(ctx, left, left_bounds, offset, depth + 1, first_child, nodes);
    build_into(ctx, right, right_bounds, offset + mid, depth + 1, first_child + 1, nodes);
}

/// Decides whether to split `refs`; if so, partitions it in place and returns the size of the left
/// part and the bounds of both parts.
fn choose_split<const W: usize>(
    ctx: &Context<W>,
    refs: &mut [PrimRef],
    bounds: &Aabb,
    centroid_bounds: &Aabb,
    depth: usize,
) -> Option<(usize, NodeBounds, NodeBounds)> {
    let count = refs.len();
    if count <= 1 {
        return None;
    }
    let extent = centroid_bounds.extent();
    let binnable = extent.max_element() > 0.0 && extent.is_finite();
    if depth >= SAH_DEPTH_LIMIT || !binnable {
        // Degenerate input (all centroids equal, or overflowing extents) or too deep for the SAH to be
        // trusted: a leaf if small enough, else an object-median halving, which always terminates.
        return median_split(refs, if binnable { extent.max_position() } else { 0 });
    }

    let Some(split) = best_binned_split(ctx, refs, centroid_bounds) else {
        return median_split(refs, extent.max_position());
    };
    let as_leaf = INTERSECTION_COST * leaf_cost(count, W);
    let split_cost = TRAVERSAL_COST + INTERSECTION_COST * split.cost / bounds.half_area();
    if count <= MAX_LEAF_SIZE && as_leaf <= split_cost {
        return None;
    }
    let (axis, min, scale) = (split.axis, centroid_bounds.min[split.axis], split.scale);
    // A centroid is in a bin below `split.bin` exactly when its position in bins, `x >= 0`, is
    // below it: `floor(x) < k` iff `x < k` for a whole `k` (the clamp to the last bin cannot
    // matter, `k` being at most that bin). Compared as floats: the conversion costs more.
    let boundary = split.bin as f32;
    Some(partition(refs, |b| (b.centroid()[axis] - min) * scale < boundary))
}

/// Halves `refs` by centroid along `axis`, or makes a leaf if it is small enough.
fn median_split(refs: &mut [PrimRef], axis: usize) -> Option<(usize, NodeBounds, NodeBounds)> {
    if refs.len() <= MAX_LEAF_SIZE {
        return None;
    }
    let mid = refs.len() / 2;
    let key = |r: &PrimRef| r.bounds().centroid()[axis];
    refs.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
    let (left, right) = refs.split_at(mid);
    Some((mid, NodeBounds::of(left), NodeBounds::of(right)))
}

struct Split {
    axis: usize,
    /// Triangles in bins `< bin` go left.
    bin: usize,
    /// `area_left * leaf_cost(count_left) + area_right * leaf_cost(count_right)` (half areas).
    cost: f64,
    scale: f32,
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Box3A,
    count: u32,
}

impl Bin {
    const EMPTY: Bin = Bin { bounds: Box3A::EMPTY, count: 0 };

    fn merge(self, o: Bin) -> Bin {
        Bin { bounds: self.bounds.union(o.bounds), count: self.count + o.count }
    }

    /// Half area times leaf cost, `Aabb::half_area`'s arithmetic (f32 extent, f64 products, so
    /// that huge coordinates cannot overflow) without its conversions: the sweep runs it 90
    /// times a node at 16 bins.
    #[inline(always)]
    fn cost<const W: usize>(self) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        let e = (self.bounds.max - self.bounds.min).as_dvec3();
        (e.x * e.y + e.y * e.z + e.z * e.x) * leaf_cost(self.count as usize, W)
    }
}

/// One row of `B` bins per axis. `B` is a compile-time constant so that each preset initialises only
/// the bins it uses (a 64-bin grid is 9 KB, and there is one per node).
type BinGrid<const B: usize> = [[Bin; B]; 3];

/// Bins the centroids of `refs` along the three axes at once.
fn bin_triangles<const B: usize>(refs: &[PrimRef], min: Vec3A, scale: Vec3A) -> BinGrid<B> {
    let last = Vec3A::splat((B - 1) as f32);
    let mut grid = [[Bin::EMPTY; B]; 3];
    for r in refs {
        let b = r.bounds();
        let index = bin_indices((b.centroid() - min) * scale, last);
        for axis in 0..3 {
            let bin = &mut grid[axis][index[axis]];
            bin.bounds = bin.bounds.union(b);
            bin.count += 1;
        }
    }
    grid
}

/// The bin of a centroid on each axis, from its position in bins (`(c - min) * scale`, never
/// negative or NaN here: centroids lie within the node's centroid bounds), clamped to `last`. One
/// truncating conversion for the three axes where SSE2 has it, rather than three saturating ones.
#[inline(always)]
fn bin_indices(position: Vec3A, last: Vec3A) -> [usize; 3] {
    let clamped = position.min(last);
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128, __m128i, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of x86-64. Values in [0, last] convert exactly to their integer part.
        let truncated: __m128i = unsafe { _mm_cvttps_epi32(__m128::from(clamped)) };
        // SAFETY: `__m128i` and `[i32; 4]` have the same size, and every bit pattern is valid.
        let [x, y, z, _] = unsafe { std::mem::transmute::<__m128i, [i32; 4]>(truncated) };
        [x as usize, y as usize, z as usize]
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        clamped.to_array().map(|v| v as usize)
    }
}

fn merge_grids<const B: usize>(mut a: BinGrid<B>, b: BinGrid<B>) -> BinGrid<B> {
    for (row_a, row_b) in a.iter_mut().zip(b.iter()) {
        for (x, y) in row_a.iter_mut().zip(row_b.iter()) {
            *x = x.merge(*y);
        }
    }
    a
}

/// The cheapest bin boundary over the three axes, or None if every candidate puts all triangles
/// on one side (possible only for degenerate centroid layouts).
fn best_binned_split<const W: usize>(ctx: &Context<W>, refs: &[PrimRef], centroid_bounds: &Aabb) -> Option<Split> {
    match ctx.bins {
        8 => best_binned_split_with::<W, 8>(refs, centroid_bounds),
        16 => best_binned_split_with::<W, 16>(refs, centroid_bounds),
        _ => best_binned_split_with::<W, 64>(refs, centroid_bounds),
    }
}

fn best_binned_split_with<const W: usize, const B: usize>(refs: &[PrimRef], centroid_bounds: &Aabb) -> Option<Split> {
    let bins = B;
    let extent = centroid_bounds.extent();
    let scale = Vec3::select(extent.cmpgt(Vec3::ZERO), bins as f32 / extent, Vec3::ZERO);
    let (min, scale_a) = (Vec3A::from(centroid_bounds.min), Vec3A::from(scale));
    let grid = if refs.len() > PARALLEL_BINNING_THRESHOLD {
        refs.par_chunks(BINNING_CHUNK)
            .map(|chunk| bin_triangles::<B>(chunk, min, scale_a))
            .reduce(|| [[Bin::EMPTY; B]; 3], merge_grids)
    } else {
        bin_triangles::<B>(refs, min, scale_a)
    };

    let mut best: Option<Split> = None;
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let row = &grid[axis];
        // right_cost[k] = area * cost of bins k.. (suffix), filled right to left.
        let mut right_cost = [0.0f64; B];
        let mut acc = Bin::EMPTY;
        for k in (1..bins).rev() {
            acc = acc.merge(row[k]);
            right_cost[k] = acc.cost::<W>();
        }
        let mut left = Bin::EMPTY;
        for k in 1..bins {
            left = left.merge(row[k - 1]);
            if left.count == 0 || left.count as usize == refs.len() {
                continue;
            }
            let cost = left.cost::<W>() + right_cost[k];
            if best.as_ref().is_none_or(|b| cost < b.cost) {
                best = Some(Split { axis, bin: k, cost, scale: scale[axis] });
            }
        }
    }
    best
}

/// In-place partition, elements whose box `goes_left` first (Lomuto's swaps: the order, hence the
/// tree, is this build's own), gathering both sides' bounds on the way. Returns the left count and
/// the bounds of the left and right parts.
fn partition(refs: &mut [PrimRef], goes_left: impl Fn(Box3A) -> bool) -> (usize, NodeBounds, NodeBounds) {
    let (mut left, mut right) = (NodeBounds::EMPTY, NodeBounds::EMPTY);
    let mut first_right = 0;
    for i in 0..refs.len() {
        let b = refs[i].bounds();
        if goes_left(b) {
            left = left.grow(b);
            refs.swap(i, first_right);
            first_right += 1;
        } else {
            right = right.grow(b);
        }
    }
    (first_right, left, right)
}
