//! Binned SAH build (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", 2007).
//!
//! Each node bins triangle centroids along all three axes, sweeps the bins for the split of least
//! surface-area cost, and becomes a leaf when no split beats intersecting its triangles directly.
//! Large subtrees are built in parallel with rayon and stitched into one array, so siblings stay
//! adjacent and the layout is the same whatever the thread count.

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
}

/// What every node of one build shares. `W` is the block width the SAH counts leaves in: a const,
/// not a field, so that `leaf_cost` divides by a constant in the split sweep.
struct Context<'a, const W: usize> {
    bounds: &'a [Box3A],
    centroids: &'a [Vec3A],
    bins: usize,
}

impl<const W: usize> Context<'_, W> {
    fn node_bounds(&self, order: &[u32]) -> NodeBounds {
        let gather = |ids: &[u32]| {
            ids.iter().fold(NodeBounds::EMPTY, |acc, &i| NodeBounds {
                bounds: acc.bounds.union(self.bounds[i as usize]),
                centroids: acc.centroids.grow(self.centroids[i as usize]),
            })
        };
        if order.len() > PARALLEL_BINNING_THRESHOLD {
            order.par_chunks(BINNING_CHUNK).map(gather).reduce(|| NodeBounds::EMPTY, NodeBounds::merge)
        } else {
            gather(order)
        }
    }
}

pub fn build<const W: usize>(positions: &[Vec3], indices: &[[u32; 3]], preset: BuildPreset) -> Bvh {
    let corners = |t: &[u32; 3]| t.map(|i| positions[i as usize]);
    let bounds: Vec<Box3A> = indices
        .par_iter()
        .map(|t| {
            let [a, b, c] = corners(t).map(Vec3A::from);
            Box3A { min: a.min(b).min(c), max: a.max(b).max(c) }
        })
        .collect();
    let centroids: Vec<Vec3A> = bounds.par_iter().map(|b| 0.5 * (b.min + b.max)).collect();
    // Zero-area triangles have no surface and are never hit (see `is_degenerate`).
    let mut order: Vec<u32> = (0..indices.len() as u32)
        .filter(|&i| {
            let [p0, p1, p2] = corners(&indices[i as usize]);
            !is_degenerate(p0, p1, p2)
        })
        .collect();
    let ctx = Context::<W> { bounds: &bounds, centroids: &centroids, bins: preset.bins() };

    let nodes =
        if order.is_empty() { vec![Node::new(Aabb::EMPTY, 0, 0)] } else { build_subtree(&ctx, &mut order, 0, 0) };
    let vertices = order.iter().map(|&id| corners(&indices[id as usize])).collect();
    Bvh { nodes, vertices, triangle_ids: order, input_triangles: indices.len(), block_width: W }
}

/// Builds the subtree over `order` (whose first element is triangle slot `offset` in leaf order)
/// into a node array whose root is at index 0.
fn build_subtree<const W: usize>(ctx: &Context<W>, order: &mut [u32], offset: usize, depth: usize) -> Vec<Node> {
    let mut nodes = Vec::with_capacity(order.len());
    nodes.push(Node::default());
    build_into(ctx, order, offset, depth, 0, &mut nodes);
    nodes
}

/// Fills node `index` of `nodes` for the triangles `order`, appending its descendants.
fn build_into<const W: usize>(
    ctx: &Context<W>,
    order: &mut [u32],
    offset: usize,
    depth: usize,
    index: usize,
    nodes: &mut Vec<Node>,
) {
    let node_bounds = ctx.node_bounds(order);
    let bounds = node_bounds.bounds.to_aabb();
    let Some(mid) = choose_split(ctx, order, &bounds, &node_bounds.centroids.to_aabb(), depth) else {
        nodes[index] = Node::new(bounds, offset as u32, order.len() as u32);
        return;
    };
    let (left, right) = order.split_at_mut(mid);
    let first_child = nodes.len();
    nodes[index] = Node::new(bounds, first_child as u32, 0);

    if left.len() + right.len() >= PARALLEL_THRESHOLD {
        let (left_nodes, right_nodes) = rayon::join(
            || build_subtree(ctx, left, offset, depth + 1),
            || build_subtree(ctx, right, offset + mid, depth + 1),
        );
        stitch(nodes, first_child, left_nodes, right_nodes);
    } else {
        nodes.push(Node::default());
        nodes.push(Node::default());
        build_into(ctx, left, offset, depth + 1, first_child, nodes);
        build_into(ctx, right, offset + mid, depth + 1, first_child + 1, nodes);
    }
}

/// Appends two independently built subtrees so that their roots land at `first_child` and
/// `first_child + 1` (adjacent siblings), renumbering their interior child links.
fn stitch(nodes: &mut Vec<Node>, first_child: usize, left: Vec<Node>, right: Vec<Node>) {
    debug_assert_eq!(nodes.len(), first_child);
    let left_rest = first_child + 2;
    let right_rest = left_rest + left.len() - 1;
    // Local index j > 0 of a subtree moves to its block; local 0 is the root placed beside its sibling.
    let relink = |node: Node, root: usize, rest: usize| -> Node {
        if node.is_leaf() {
            return node;
        }
        let j = node.first as usize;
        let first = if j == 0 { root } else { rest + j - 1 };
        Node { first: first as u32, ..node }
    };
    nodes.push(relink(left[0], first_child, left_rest));
    nodes.push(relink(right[0], first_child + 1, right_rest));
    nodes.extend(left[1..].iter().map(|&n| relink(n, first_child, left_rest)));
    nodes.extend(right[1..].iter().map(|&n| relink(n, first_child + 1, right_rest)));
}

/// Decides whether to split `order`; if so, partitions it in place and returns the size of the left part.
fn choose_split<const W: usize>(
    ctx: &Context<W>,
    order: &mut [u32],
    bounds: &Aabb,
    centroid_bounds: &Aabb,
    depth: usize,
) -> Option<usize> {
    let count = order.len();
    if count <= 1 {
        return None;
    }
    let extent = centroid_bounds.extent();
    let binnable = extent.max_element() > 0.0 && extent.is_finite();
    if depth >= SAH_DEPTH_LIMIT || !binnable {
        // Degenerate input (all centroids equal, or overflowing extents) or too deep for the SAH to be
        // trusted: a leaf if small enough, else an object-median halving, which always terminates.
        return median_split(ctx, order, if binnable { extent.max_position() } else { 0 });
    }

    let Some(split) = best_binned_split(ctx, order, centroid_bounds) else {
        return median_split(ctx, order, extent.max_position());
    };
    let as_leaf = INTERSECTION_COST * leaf_cost(count, W);
    let split_cost = TRAVERSAL_COST + INTERSECTION_COST * split.cost / bounds.half_area();
    if count <= MAX_LEAF_SIZE && as_leaf <= split_cost {
        return None;
    }
    let (axis, min, scale) = (split.axis, centroid_bounds.min[split.axis], split.scale);
    let bins = ctx.bins;
    let mid = partition(order, |&i| bin_index(ctx.centroids[i as usize][axis], min, scale, bins) < split.bin);
    Some(mid)
}

/// Halves `order` by centroid along `axis`, or makes a leaf if it is small enough.
fn median_split<const W: usize>(ctx: &Context<W>, order: &mut [u32], axis: usize) -> Option<usize> {
    if order.len() <= MAX_LEAF_SIZE {
        return None;
    }
    let mid = order.len() / 2;
    let key = |i: &u32| ctx.centroids[*i as usize][axis];
    order.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
    Some(mid)
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
}

/// One row of `B` bins per axis. `B` is a compile-time constant so that each preset initialises only
/// the bins it uses (a 64-bin grid is 9 KB, and there is one per node).
type BinGrid<const B: usize> = [[Bin; B]; 3];

/// Bins the centroids of `order` along the three axes at once.
fn bin_triangles<const W: usize, const B: usize>(
    ctx: &Context<W>,
    order: &[u32],
    min: Vec3A,
    scale: Vec3A,
) -> BinGrid<B> {
    let last = Vec3A::splat((B - 1) as f32);
    let mut grid = [[Bin::EMPTY; B]; 3];
    for &i in order {
        let b = ctx.bounds[i as usize];
        // Float min before the integer conversion keeps the index in range (NaN never occurs here).
        let index = ((ctx.centroids[i as usize] - min) * scale).min(last).to_array();
        for axis in 0..3 {
            let bin = &mut grid[axis][index[axis] as usize];
            bin.bounds = bin.bounds.union(b);
            bin.count += 1;
        }
    }
    grid
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
fn best_binned_split<const W: usize>(ctx: &Context<W>, order: &[u32], centroid_bounds: &Aabb) -> Option<Split> {
    match ctx.bins {
        8 => best_binned_split_with::<W, 8>(ctx, order, centroid_bounds),
        16 => best_binned_split_with::<W, 16>(ctx, order, centroid_bounds),
        _ => best_binned_split_with::<W, 64>(ctx, order, centroid_bounds),
    }
}

fn best_binned_split_with<const W: usize, const B: usize>(
    ctx: &Context<W>,
    order: &[u32],
    centroid_bounds: &Aabb,
) -> Option<Split> {
    let bins = B;
    let extent = centroid_bounds.extent();
    let scale = Vec3::select(extent.cmpgt(Vec3::ZERO), bins as f32 / extent, Vec3::ZERO);
    let (min, scale_a) = (Vec3A::from(centroid_bounds.min), Vec3A::from(scale));
    let grid = if order.len() > PARALLEL_BINNING_THRESHOLD {
        order
            .par_chunks(BINNING_CHUNK)
            .map(|chunk| bin_triangles::<W, B>(ctx, chunk, min, scale_a))
            .reduce(|| [[Bin::EMPTY; B]; 3], merge_grids)
    } else {
        bin_triangles::<W, B>(ctx, order, min, scale_a)
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
            right_cost[k] = acc.bounds.to_aabb().half_area() * leaf_cost(acc.count as usize, W);
        }
        let mut left = Bin::EMPTY;
        for k in 1..bins {
            left = left.merge(row[k - 1]);
            if left.count == 0 || left.count as usize == order.len() {
                continue;
            }
            let cost = left.bounds.to_aabb().half_area() * leaf_cost(left.count as usize, W) + right_cost[k];
            if best.as_ref().is_none_or(|b| cost < b.cost) {
                best = Some(Split { axis, bin: k, cost, scale: scale[axis] });
            }
        }
    }
    best
}

#[inline]
fn bin_index(c: f32, min: f32, scale: f32, bins: usize) -> usize {
    (((c - min) * scale) as usize).min(bins - 1)
}

/// Stable-enough in-place partition: elements satisfying `pred` first; returns their count.
fn partition(order: &mut [u32], pred: impl Fn(&u32) -> bool) -> usize {
    let mut first_false = 0;
    for i in 0..order.len() {
        if pred(&order[i]) {
            order.swap(i, first_false);
            first_false += 1;
        }
    }
    first_false
}
