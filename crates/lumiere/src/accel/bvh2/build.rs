//! Binned SAH build (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", 2007).
//!
//! Each node bins triangle centroids along all three axes, sweeps the bins for the split of least
//! surface-area cost, and becomes a leaf when no split beats intersecting its triangles directly.
//! Where that split's children overlap much, the node also tries cutting its triangles by a plane
//! (`spatial_split.rs`), and takes whichever costs less.
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

use super::spatial_split::{self, SpatialSplit};
use super::{Bvh, Node};
use crate::geometry::triangle::is_degenerate;
use crate::math::Aabb;

/// Leaves never hold more triangles than this (the wide leaf references' count bits are sized by it).
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
    /// 8 bins and no spatial splits: the quickest build, a slightly worse tree.
    Fast,
    /// 16 bins, spatial splits.
    #[default]
    Default,
    /// 64 bins, spatial splits.
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

    /// Extra references spatial splits may add, as a share of the triangles: none for the
    /// quickest build.
    fn reference_budget(self) -> f64 {
        match self {
            BuildPreset::Fast => 0.0,
            BuildPreset::Default | BuildPreset::HighQuality => spatial_split::REFERENCE_BUDGET,
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
pub(super) const PARALLEL_BINNING_THRESHOLD: usize = 1 << 16;
pub(super) const BINNING_CHUNK: usize = 1 << 14;

/// A box in 16-byte lanes, so that growing it is one SSE min and one max.
#[derive(Clone, Copy, Debug)]
pub(super) struct Box3A {
    pub(super) min: Vec3A,
    pub(super) max: Vec3A,
}

impl Box3A {
    pub(super) const EMPTY: Box3A = Box3A { min: Vec3A::INFINITY, max: Vec3A::NEG_INFINITY };

    #[inline(always)]
    pub(super) fn union(self, o: Box3A) -> Box3A {
        Box3A { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    #[inline(always)]
    pub(super) fn grow(self, p: Vec3A) -> Box3A {
        Box3A { min: self.min.min(p), max: self.max.max(p) }
    }

    fn to_aabb(self) -> Aabb {
        Aabb { min: self.min.into(), max: self.max.into() }
    }

    /// `Aabb::half_area`'s arithmetic (f32 extent, f64 products, so that huge coordinates cannot
    /// overflow) without its conversions.
    #[inline(always)]
    fn half_area(self) -> f64 {
        let e = (self.max - self.min).as_dvec3();
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// The box both boxes hold, or None.
    pub(super) fn intersection(self, o: Box3A) -> Option<Box3A> {
        let b = Box3A { min: self.min.max(o.min), max: self.max.min(o.max) };
        (!b.min.cmpgt(b.max).any()).then_some(b)
    }

    #[inline(always)]
    fn centroid(self) -> Vec3A {
        0.5 * (self.min + self.max)
    }
}

/// The id that marks a zero-area triangle before it is dropped (ids are below `u32::MAX`).
const DEGENERATE: u32 = u32::MAX;

/// A triangle as the build moves it: its box and its id, 32 bytes.
/// With spatial splits (`spatial_split.rs`) a reference may hold the box of a piece of its
/// triangle, and a triangle may have several references.
#[derive(Clone, Copy)]
#[repr(C, align(16))]
pub(super) struct PrimRef {
    min: [f32; 3],
    pub(super) id: u32,
    max: [f32; 3],
}

impl PrimRef {
    #[inline(always)]
    pub(super) fn bounds(&self) -> Box3A {
        Box3A { min: Vec3A::from_array(self.min), max: Vec3A::from_array(self.max) }
    }

    /// This reference for a piece of its triangle boxed by `bounds`.
    pub(super) fn with_bounds(self, bounds: Box3A) -> PrimRef {
        PrimRef { min: bounds.min.to_array(), max: bounds.max.to_array(), ..self }
    }
}

/// Bounds of the triangles of a node and of their centroids, gathered in one pass.
#[derive(Clone, Copy)]
pub(super) struct NodeBounds {
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
    pub(super) fn of(refs: &[PrimRef]) -> NodeBounds {
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
pub(super) struct Context<'a, const W: usize> {
    bins: usize,
    positions: &'a [Vec3],
    indices: &'a [[u32; 3]],
    /// Spatial splits are tried where the object split's children overlap by more than this.
    spatial_overlap: f64,
}

impl<const W: usize> Context<'_, W> {
    pub(super) fn corners(&self, id: u32) -> [Vec3; 3] {
        self.indices[id as usize].map(|i| self.positions[i as usize])
    }

    /// Whether a node of box `node` whose best object split along `axis` leaves its children
    /// sharing the box `overlap` should try a spatial split (`spatial_split.rs`): where the overlap
    /// is large by area and thick along the axis. A fine mesh's object splits overlap in a thin
    /// slab of small straddling triangles, which cutting cannot much improve.
    fn worth_a_spatial_split(&self, overlap: Box3A, node: Box3A, axis: usize) -> bool {
        overlap.half_area() > self.spatial_overlap
            && overlap.max[axis] - overlap.min[axis]
                > spatial_split::OVERLAP_THICKNESS * (node.max[axis] - node.min[axis])
    }
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
    let triangles = refs.len();

    let (nodes, triangle_ids) = if refs.is_empty() {
        (vec![Node::new(Aabb::EMPTY, 0, 0)], Vec::new())
    } else {
        let bounds = NodeBounds::of(&refs);
        let ctx = Context::<W> {
            bins: preset.bins(),
            positions,
            indices,
            spatial_overlap: spatial_split::OVERLAP_SHARE * bounds.bounds.half_area(),
        };
        let spare = (triangles as f64 * preset.reference_budget()) as usize;
        build_subtree(&ctx, &mut refs, bounds, spare, 0).into_tree()
    };
    let vertices = if copy_vertices {
        triangle_ids.par_iter().map(|&id| corners(&indices[id as usize])).collect()
    } else {
        Vec::new()
    };
    Bvh { nodes, vertices, triangle_ids, triangles, input_triangles: indices.len(), block_width: W }
}

/// A subtree as the parallel build returns it: built on one thread into arrays of its own (root
/// at 0, leaves numbering their triangle slots from 0), or a node whose two subtrees were built
/// in parallel. [`Subtree::place`] then writes every node and slot once into the tree's arrays;
/// stitching the arrays together level by level copied each node once per parallel level (eight
/// on the 1.1M-triangle bunny), into fresh pages.
enum Subtree {
    Local(LocalTree),
    Split { bounds: Aabb, left: Box<Subtree>, right: Box<Subtree>, size: usize, slots: usize },
}

impl Subtree {
    /// Nodes in the subtree, its root included.
    fn size(&self) -> usize {
        match self {
            Subtree::Local(tree) => tree.nodes.len(),
            Subtree::Split { size, .. } => *size,
        }
    }

    /// Triangle slots of its leaves (references: a triangle split by a spatial split has several).
    fn slots(&self) -> usize {
        match self {
            Subtree::Local(tree) => tree.triangle_ids.len(),
            Subtree::Split { slots, .. } => *slots,
        }
    }

    /// Writes the root into `root` and the other nodes into `rest`, which starts at index
    /// `rest_start` of the tree's array, and the leaves' triangle ids into `ids`, which starts at
    /// slot `slot_start`. The layout is the one [`build_into`] gives a subtree built on one
    /// thread: a node's two children side by side, the left one's descendants next, then the
    /// right one's; the left one's slots before the right one's.
    fn place(self, root: &mut Node, rest: &mut [Node], rest_start: usize, ids: &mut [u32], slot_start: usize) {
        debug_assert_eq!((rest.len() + 1, ids.len()), (self.size(), self.slots()));
        match self {
            Subtree::Local(LocalTree { nodes, triangle_ids }) => {
                // Local index j > 0 moves to `rest_start + j - 1`; local 0 is `root`.
                let relink = |node: Node| {
                    let first = if node.is_leaf() {
                        slot_start + node.first as usize
                    } else {
                        rest_start + node.first as usize - 1
                    };
                    Node { first: first as u32, ..node }
                };
                *root = relink(nodes[0]);
                for (slot, &node) in rest.iter_mut().zip(&nodes[1..]) {
                    *slot = relink(node);
                }
                ids.copy_from_slice(&triangle_ids);
            }
            Subtree::Split { bounds, left, right, .. } => {
                *root = Node::new(bounds, rest_start as u32, 0);
                let (roots, descendants) = rest.split_at_mut(2);
                let (left_root, right_root) = roots.split_at_mut(1);
                let (left_size, left_slots) = (left.size(), left.slots());
                let (left_rest, right_rest) = descendants.split_at_mut(left_size - 1);
                let (left_start, right_start) = (rest_start + 2, rest_start + 1 + left_size);
                let (left_ids, right_ids) = ids.split_at_mut(left_slots);
                rayon::join(
                    || left.place(&mut left_root[0], left_rest, left_start, left_ids, slot_start),
                    || right.place(&mut right_root[0], right_rest, right_start, right_ids, slot_start + left_slots),
                );
            }
        }
    }

    /// The tree's node array, root at 0, and its triangle ids in slot order.
    fn into_tree(self) -> (Vec<Node>, Vec<u32>) {
        let mut nodes = vec![Node::default(); self.size()];
        let mut ids = vec![0; self.slots()];
        let (root, rest) = nodes.split_at_mut(1);
        self.place(&mut root[0], rest, 1, &mut ids, 0);
        (nodes, ids)
    }
}

/// How a node's references are divided between its children.
enum Partition {
    /// The first `mid` references, moved in place, go left. `spatial_lost`: a spatial split was
    /// tried and cost more.
    Object { mid: usize, left: NodeBounds, right: NodeBounds, spatial_lost: bool },
    /// Spatial splits copy straddling references, so the children get arrays of their own.
    Spatial { left_refs: Vec<PrimRef>, left: NodeBounds, right_refs: Vec<PrimRef>, right: NodeBounds },
}

impl Partition {
    /// The children's references, bounds and shares of `spare`, the extra references the node
    /// may still add: what a spatial split added is taken out (half of it dropped after a spatial
    /// split lost), the rest divided by size.
    fn children<'r>(
        &'r mut self,
        refs: &'r mut [PrimRef],
        spare: usize,
    ) -> [(&'r mut [PrimRef], NodeBounds, usize); 2] {
        let parent = refs.len();
        let mut spare = spare;
        let (left_refs, left, right_refs, right) = match self {
            Partition::Object { mid, left, right, spatial_lost } => {
                // Where cutting did not pay it seldom pays below: a soup of 200,000 large random
                // triangles built in 679 ms trying at every node, 151 ms with the budget halved.
                if *spatial_lost {
                    spare /= 2;
                }
                let (l, r) = refs.split_at_mut(*mid);
                (l, *left, r, *right)
            }
            Partition::Spatial { left_refs, left, right_refs, right } => {
                (&mut left_refs[..], *left, &mut right_refs[..], *right)
            }
        };
        let total = left_refs.len() + right_refs.len();
        let spare = spare.saturating_sub(total - parent);
        let left_spare = (spare as u128 * left_refs.len() as u128 / total as u128) as usize;
        [(left_refs, left, left_spare), (right_refs, right, spare - left_spare)]
    }
}

/// Builds the subtree over `refs` (whose bounds are `bounds`, and which may add `spare` references
/// by spatial splits): large ones split in parallel, the rest on this thread.
fn build_subtree<const W: usize>(
    ctx: &Context<W>,
    refs: &mut [PrimRef],
    bounds: NodeBounds,
    spare: usize,
    depth: usize,
) -> Subtree {
    if refs.len() >= PARALLEL_THRESHOLD
        && let Some(mut partition) = choose_split(ctx, refs, &bounds, spare, depth)
    {
        let node_bounds = bounds.bounds.to_aabb();
        let [(left, left_bounds, left_spare), (right, right_bounds, right_spare)] = partition.children(refs, spare);
        let (left, right) = rayon::join(
            || build_subtree(ctx, left, left_bounds, left_spare, depth + 1),
            || build_subtree(ctx, right, right_bounds, right_spare, depth + 1),
        );
        let (size, slots) = (1 + left.size() + right.size(), left.slots() + right.slots());
        return Subtree::Split { bounds: node_bounds, left: Box::new(left), right: Box::new(right), size, slots };
    }
    let mut tree = LocalTree { nodes: Vec::with_capacity(refs.len()), triangle_ids: Vec::with_capacity(refs.len()) };
    tree.nodes.push(Node::default());
    build_into(ctx, refs, bounds, spare, depth, 0, &mut tree);
    Subtree::Local(tree)
}

/// A subtree built on one thread: its nodes, root at 0, and its leaves' triangle ids, whose
/// positions are the slots its leaves number from 0.
struct LocalTree {
    nodes: Vec<Node>,
    triangle_ids: Vec<u32>,
}

/// Fills node `index` of `tree` for the triangles `refs`, appending its descendants (on this
/// thread) and its leaves' triangle ids.
fn build_into<const W: usize>(
    ctx: &Context<W>,
    refs: &mut [PrimRef],
    node_bounds: NodeBounds,
    spare: usize,
    depth: usize,
    index: usize,
    tree: &mut LocalTree,
) {
    let bounds = node_bounds.bounds.to_aabb();
    let Some(mut partition) = choose_split(ctx, refs, &node_bounds, spare, depth) else {
        tree.nodes[index] = Node::new(bounds, tree.triangle_ids.len() as u32, refs.len() as u32);
        tree.triangle_ids.extend(refs.iter().map(|r| r.id));
        return;
    };
    let first_child = tree.nodes.len();
    tree.nodes[index] = Node::new(bounds, first_child as u32, 0);
    tree.nodes.push(Node::default());
    tree.nodes.push(Node::default());
    for (child, (refs, bounds, spare)) in partition.children(refs, spare).into_iter().enumerate() {
        build_into(ctx, refs, bounds, spare, depth + 1, first_child + child, tree);
    }
}

/// Decides whether to split `refs`, and how.
fn choose_split<const W: usize>(
    ctx: &Context<W>,
    refs: &mut [PrimRef],
    node: &NodeBounds,
    spare: usize,
    depth: usize,
) -> Option<Partition> {
    let count = refs.len();
    if count <= 1 {
        return None;
    }
    let (bounds, centroid_bounds) = (node.bounds.to_aabb(), node.centroids.to_aabb());
    let extent = centroid_bounds.extent();
    let binnable = extent.max_element() > 0.0 && extent.is_finite();
    if depth >= SAH_DEPTH_LIMIT || !binnable {
        // Degenerate input (all centroids equal, or overflowing extents) or too deep for the SAH to be
        // trusted: a leaf if small enough, else an object-median halving, which always terminates.
        return median_split(refs, if binnable { extent.max_position() } else { 0 });
    }

    let Some(split) = best_binned_split(ctx, refs, &centroid_bounds) else {
        return median_split(refs, extent.max_position());
    };
    // Where the object split's children overlap much, cutting the triangles may do better.
    let tried = spare >= count.div_ceil(spatial_split::LEAST_BUDGET_SHARE)
        && split.overlap.is_some_and(|o| ctx.worth_a_spatial_split(o, node.bounds, split.axis));
    let spatial = tried
        .then(|| best_spatial_split(ctx, refs, node.bounds))
        .flatten()
        .filter(|s| s.cost < split.cost && s.extra_references <= spare);
    let spatial_lost = tried && spatial.is_none();
    let best_cost = spatial.as_ref().map_or(split.cost, |s| s.cost);
    let as_leaf = INTERSECTION_COST * leaf_cost(count, W);
    let split_cost = TRAVERSAL_COST + INTERSECTION_COST * best_cost / bounds.half_area();
    if count <= MAX_LEAF_SIZE && as_leaf <= split_cost {
        return None;
    }
    if let Some((left_refs, left, right_refs, right)) = spatial.and_then(|s| spatial_split::partition(ctx, refs, &s)) {
        return Some(Partition::Spatial { left_refs, left, right_refs, right });
    }
    let (axis, min, scale) = (split.axis, centroid_bounds.min[split.axis], split.scale);
    // A centroid is in a bin below `split.bin` exactly when its position in bins, `x >= 0`, is
    // below it: `floor(x) < k` iff `x < k` for a whole `k` (the clamp to the last bin cannot
    // matter, `k` being at most that bin). Compared as floats: the conversion costs more.
    let boundary = split.bin as f32;
    let (mid, left, right) = partition(refs, |b| (b.centroid()[axis] - min) * scale < boundary);
    Some(Partition::Object { mid, left, right, spatial_lost })
}

/// The spatial split of `refs` over the preset's bins.
fn best_spatial_split<const W: usize>(ctx: &Context<W>, refs: &[PrimRef], bounds: Box3A) -> Option<SpatialSplit> {
    match ctx.bins {
        8 => spatial_split::best_spatial_split::<W, 8>(ctx, refs, bounds),
        16 => spatial_split::best_spatial_split::<W, 16>(ctx, refs, bounds),
        _ => spatial_split::best_spatial_split::<W, 64>(ctx, refs, bounds),
    }
}

/// Halves `refs` by centroid along `axis`, or makes a leaf if it is small enough.
fn median_split(refs: &mut [PrimRef], axis: usize) -> Option<Partition> {
    if refs.len() <= MAX_LEAF_SIZE {
        return None;
    }
    let mid = refs.len() / 2;
    let key = |r: &PrimRef| r.bounds().centroid()[axis];
    refs.select_nth_unstable_by(mid, |a, b| key(a).total_cmp(&key(b)));
    let (left, right) = refs.split_at(mid);
    Some(Partition::Object { mid, left: NodeBounds::of(left), right: NodeBounds::of(right), spatial_lost: false })
}

struct Split {
    axis: usize,
    /// Triangles in bins `< bin` go left.
    bin: usize,
    /// `area_left * leaf_cost(count_left) + area_right * leaf_cost(count_right)` (half areas).
    cost: f64,
    scale: f32,
    /// The box the two sides' boxes share, if any (spatial splits are tried where it is large).
    overlap: Option<Box3A>,
}

#[derive(Clone, Copy)]
pub(super) struct Bin {
    pub(super) bounds: Box3A,
    pub(super) count: u32,
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
    pub(super) fn cost<const W: usize>(self) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        self.bounds.half_area() * leaf_cost(self.count as usize, W)
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
        // right[k] = bins k.. (suffix) and their area * cost, filled right to left.
        let mut right = [(Bin::EMPTY, 0.0f64); B];
        let mut acc = Bin::EMPTY;
        for k in (1..bins).rev() {
            acc = acc.merge(row[k]);
            right[k] = (acc, acc.cost::<W>());
        }
        let mut left = Bin::EMPTY;
        for k in 1..bins {
            left = left.merge(row[k - 1]);
            if left.count == 0 || left.count as usize == refs.len() {
                continue;
            }
            let cost = left.cost::<W>() + right[k].1;
            if best.as_ref().is_none_or(|b| cost < b.cost) {
                let overlap = left.bounds.intersection(right[k].0.bounds);
                best = Some(Split { axis, bin: k, cost, scale: scale[axis], overlap });
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
