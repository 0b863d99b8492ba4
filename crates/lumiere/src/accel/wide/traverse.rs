//! Closest-hit and occlusion queries on the wide BVH: one `W`-lane box test per node, one `W`-lane
//! watertight triangle test per leaf block (`triangles.rs`), iterative with a fixed stack, children
//! in the node's near-to-far order for the ray's octant; a tree of one node over a few blocks (the
//! Cornell box) is tested block by block, without the walk. Generic over the lane kernel `L`; each
//! entry point is monomorphised per kernel.

use std::mem::MaybeUninit;

use super::WideBvh;
use super::leaf::{self, LEAF_BIT};
use super::node::{TriangleBlock, WideNode};
use super::triangles::{TriangleRay, intersect_block};
use crate::accel::bvh2::MAX_DEPTH;
use crate::accel::simd::{LaneMask, Lanes, lanes_of};
use crate::accel::slab::{BOX_EXPANSION, PRUNE_SLACK, safe_reciprocal};
use crate::accel::{Hit, TraversalStats, VisitOrder};
use crate::math::Ray;

/// The traversal stack, left uninitialised: zeroing it (2.3 KB per ray at `W = 4`) was measured to
/// cost more than the whole traversal of a small scene. A wide level pushes at most `W` children
/// and pops the first to visit right after, so `(W - 1) * MAX_DEPTH + W` entries would do (writes
/// included: [`Stack::push_if`] writes the entry it drops too); stable Rust cannot size an array by
/// an expression of a const parameter, so the stack holds one row of `W` entries per level. An
/// entry is a node reference with its entry distance, with the lanes that entered it
/// (`shared_origin.rs`), or alone (the batches' walk of a region, `batch.rs`).
pub(in crate::accel) struct Stack<const W: usize, T: Copy = (u32, f32)> {
    entries: [[MaybeUninit<T>; W]; MAX_DEPTH + 1],
    len: usize,
}

impl<const W: usize, T: Copy> Stack<W, T> {
    #[inline(always)]
    pub(in crate::accel) fn new() -> Self {
        Stack { entries: [[MaybeUninit::uninit(); W]; MAX_DEPTH + 1], len: 0 }
    }

    #[inline(always)]
    pub(in crate::accel) fn push(&mut self, entry: T) {
        // The build bounds the depth by MAX_DEPTH and each level pushes at most W - 1 entries.
        self.entries.as_flattened_mut()[self.len] = MaybeUninit::new(entry);
        self.len += 1;
    }

    /// Pushes `entry` if `keep`, without a branch: the entry is written either way, and kept by
    /// the length. Room for it: a level pushes at most `W` entries and pops one, so the length
    /// stays below `(W - 1) * MAX_DEPTH + W`.
    #[inline(always)]
    pub(super) fn push_if(&mut self, entry: T, keep: bool) {
        self.entries.as_flattened_mut()[self.len] = MaybeUninit::new(entry);
        self.len += usize::from(keep);
    }

    #[inline(always)]
    pub(in crate::accel) fn pop(&mut self) -> Option<T> {
        self.len = self.len.checked_sub(1)?;
        // SAFETY: entries below `len` were written by `push` before `len` grew past them.
        Some(unsafe { self.entries.as_flattened()[self.len].assume_init() })
    }
}

/// The box row (min x, y, z, then max x, y, z) of the plane a ray with direction component `d` on
/// `axis` enters first: the max plane when its reciprocal (`safe_reciprocal`, which keeps the
/// sign) is negative, -0.0 included (`d >= 0.0` would take the min plane with a reciprocal of
/// -1e30, and a ray from inside that slab would miss every box around it).
#[inline(always)]
pub(super) fn near_row(d: f32, axis: usize) -> usize {
    if d.is_sign_negative() { axis + 3 } else { axis }
}

/// The ray, splatted for the box tests.
pub(super) struct BoxRay<L> {
    /// Per axis, the bounds row that holds the entry (near) plane: min when the direction is positive.
    near_row: [usize; 3],
    /// The direction's octant, bit `a` set where it is negative on axis `a` (as `near_row`).
    octant: usize,
    origin: [L; 3],
    inv_dir: [L; 3],
}

impl<L> BoxRay<L> {
    #[inline(always)]
    pub(super) fn new<const W: usize>(ray: &Ray) -> Self
    where
        L: Lanes<W>,
    {
        let d = ray.dir.to_array();
        let o = ray.origin.to_array();
        let near_row = [0, 1, 2].map(|a| near_row(d[a], a));
        BoxRay {
            octant: (0..3).fold(0, |octant, a| octant | usize::from(near_row[a] > 2) << a),
            near_row,
            origin: o.map(L::splat),
            inv_dir: d.map(|v| L::splat(safe_reciprocal(v))),
        }
    }

    /// Entry distances of the `W` children and the mask (bit per child) of those the ray enters
    /// before `tmax`. NaN boxes (empty slots) always fail: NaN is kept as the second operand of
    /// every min/max, and comparisons with NaN are false.
    #[inline(always)]
    fn enter<const W: usize>(&self, node: &WideNode<W>, tmax: L) -> (u32, [f32; W])
    where
        L: Lanes<W>,
    {
        let mut near = L::splat(0.0);
        let mut far = tmax;
        for axis in 0..3 {
            let near_plane = L::load(&node.bounds[self.near_row[axis]]);
            let far_plane = L::load(&node.bounds[(self.near_row[axis] + 3) % 6]);
            near = near.max((near_plane - self.origin[axis]) * self.inv_dir[axis]);
            far = far.min((far_plane - self.origin[axis]) * self.inv_dir[axis] * L::splat(BOX_EXPANSION));
        }
        (near.le(far).bits(), near.to_array())
    }
}

// The entry points stay out of line, one copy per kernel and crate: a generic function may otherwise
// be inlined at each call site, which would change the code the renders and benchmarks were
// measured with. Each enters its kernel's instruction set through `Lanes::dispatch`, with the
// traversal in an `#[inline(always)]` closure: only code inlined into the `#[target_feature]`
// function gets the kernel's instructions (anywhere else its intrinsics become calls).
impl<const W: usize, L: Lanes<W>> WideBvh<W, L> {
    /// The closest hit with `t` in `(0, ray.tmax]`, ties to the lower triangle id; identical to
    /// [`crate::accel::Bvh::intersect`].
    #[inline(never)]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        L::dispatch(
            #[inline(always)]
            || self.intersect_impl::<false>(ray, &mut TraversalStats::default(), |_, _, _| true),
        )
    }

    /// As [`WideBvh::intersect`], ignoring the hits `keep(triangle, u, v)` refuses (surfaces cut
    /// out there): the closest hit that `keep` accepts.
    #[inline(never)]
    pub fn intersect_filtered(&self, ray: &Ray, keep: &dyn Fn(u32, f32, f32) -> bool) -> Option<Hit> {
        L::dispatch(
            #[inline(always)]
            || self.intersect_impl::<false>(ray, &mut TraversalStats::default(), keep),
        )
    }

    /// As [`WideBvh::intersect`], counting nodes and blocks visited into `stats`.
    #[inline(never)]
    pub fn intersect_counted(&self, ray: &Ray, stats: &mut TraversalStats) -> Option<Hit> {
        L::dispatch(
            #[inline(always)]
            || self.intersect_impl::<true>(ray, stats, |_, _, _| true),
        )
    }

    /// True if anything lies on the ray with `t` in `(0, ray.tmax]`.
    #[inline(never)]
    pub fn occluded(&self, ray: &Ray) -> bool {
        L::dispatch(
            #[inline(always)]
            || self.occluded_impl::<false>(ray, &mut TraversalStats::default(), |_, _, _| true),
        )
    }

    /// As [`WideBvh::occluded`], counting only the hits `keep(triangle, u, v)` accepts.
    #[inline(never)]
    pub fn occluded_filtered(&self, ray: &Ray, keep: &dyn Fn(u32, f32, f32) -> bool) -> bool {
        L::dispatch(
            #[inline(always)]
            || self.occluded_impl::<false>(ray, &mut TraversalStats::default(), keep),
        )
    }

    /// As [`WideBvh::occluded`], counting nodes and blocks visited into `stats`.
    #[inline(never)]
    pub fn occluded_counted(&self, ray: &Ray, stats: &mut TraversalStats) -> bool {
        L::dispatch(
            #[inline(always)]
            || self.occluded_impl::<true>(ray, stats, |_, _, _| true),
        )
    }

    #[inline(always)]
    fn intersect_impl<const COUNT: bool>(
        &self,
        ray: &Ray,
        stats: &mut TraversalStats,
        keep: impl Fn(u32, f32, f32) -> bool,
    ) -> Option<Hit> {
        let tri_ray = TriangleRay::<L>::new::<W>(ray);
        let mut best: Option<Hit> = None;
        let mut tmax = ray.tmax;
        if let Some(blocks) = self.flat_blocks() {
            for block in blocks {
                if COUNT {
                    stats.blocks += 1;
                }
                closest_in_block(&tri_ray, block, &mut best, &mut tmax, &keep);
            }
            return best;
        }
        let box_ray = BoxRay::<L>::new::<W>(ray);
        let mut stack = Stack::<W>::new();
        let mut current = (0u32, 0f32);
        loop {
            let (reference, near) = current;
            if near <= tmax * PRUNE_SLACK {
                if reference & LEAF_BIT != 0 {
                    for block in &self.blocks[leaf::blocks::<W>(reference)] {
                        if COUNT {
                            stats.blocks += 1;
                        }
                        closest_in_block(&tri_ray, block, &mut best, &mut tmax, &keep);
                    }
                } else {
                    if COUNT {
                        stats.nodes += 1;
                    }
                    let node = &self.nodes[reference as usize];
                    let (mask, nears) = box_ray.enter(node, L::splat(tmax * PRUNE_SLACK));
                    if let Some(next) =
                        push_in_order(node, mask, &nears, box_ray.octant, VisitOrder::NearestFirst, &mut stack)
                    {
                        current = next;
                        continue;
                    }
                }
            }
            match stack.pop() {
                Some(next) => current = next,
                None => return best,
            }
        }
    }

    #[inline(always)]
    fn occluded_impl<const COUNT: bool>(
        &self,
        ray: &Ray,
        stats: &mut TraversalStats,
        keep: impl Fn(u32, f32, f32) -> bool,
    ) -> bool {
        let tri_ray = TriangleRay::<L>::new::<W>(ray);
        if let Some(blocks) = self.flat_blocks() {
            return blocks.iter().any(|block| {
                if COUNT {
                    stats.blocks += 1;
                }
                let hits = intersect_block(&tri_ray, block, ray.tmax);
                lanes_of(hits.mask).any(|lane| keep(block.ids[lane], hits.u[lane], hits.v[lane]))
            });
        }
        let box_ray = BoxRay::<L>::new::<W>(ray);
        self.occluded_below::<COUNT>(0, &box_ray, &tri_ray, ray.tmax, VisitOrder::NearestFirst, stats, keep)
    }

    /// The blocks of a tree small enough to test every one of them, in order: one node (its
    /// children all leaves) over at most [`FLAT_BLOCKS`] blocks. There the walk culls too little to
    /// pay for its box test, the ordering of the children and the stack: single rays on the
    /// Cornell box's 32 triangles (four blocks of eight) took 15-21% less time tested against all
    /// four blocks (`lumiere bench-bvh --scenes cornell`: primary, shadow and diffuse rays).
    #[inline(always)]
    fn flat_blocks(&self) -> Option<&[TriangleBlock<W>]> {
        (self.nodes.len() == 1 && self.blocks.len() <= FLAT_BLOCKS).then_some(&self.blocks[..])
    }

    /// Whether the ray (`box_ray`, `tri_ray`, `tmax`) is blocked by a triangle under the node or
    /// leaf `start` (0: the root) that `keep` accepts, visiting the children it enters nearest or
    /// farthest first (`order`) by the node's stored order for the ray's octant (the answer is
    /// the same either way).
    #[inline(always)]
    #[expect(clippy::too_many_arguments, reason = "the ray in its three forms and four settings of the walk")]
    pub(super) fn occluded_below<const COUNT: bool>(
        &self,
        start: u32,
        box_ray: &BoxRay<L>,
        tri_ray: &TriangleRay<L>,
        tmax: f32,
        order: VisitOrder,
        stats: &mut TraversalStats,
        keep: impl Fn(u32, f32, f32) -> bool,
    ) -> bool {
        let tmax_lanes = L::splat(tmax * PRUNE_SLACK);
        let mut stack = Stack::<W>::new();
        let mut current = (start, 0f32);
        loop {
            let (reference, _) = current;
            if reference & LEAF_BIT != 0 {
                for block in &self.blocks[leaf::blocks::<W>(reference)] {
                    if COUNT {
                        stats.blocks += 1;
                    }
                    // Written out, not through a helper taking `&keep`: with one, the soft shadows'
                    // light-point loop, in the function this walk is inlined into
                    // (`shared_origin.rs`), compiled otherwise and the render took 2.5x as long.
                    let hits = intersect_block(tri_ray, block, tmax);
                    if lanes_of(hits.mask).any(|lane| keep(block.ids[lane], hits.u[lane], hits.v[lane])) {
                        return true;
                    }
                }
            } else {
                if COUNT {
                    stats.nodes += 1;
                }
                let node = &self.nodes[reference as usize];
                let (mask, nears) = box_ray.enter(node, tmax_lanes);
                if let Some(next) = push_in_order(node, mask, &nears, box_ray.octant, order, &mut stack) {
                    current = next;
                    continue;
                }
            }
            match stack.pop() {
                Some(next) => current = next,
                None => return false,
            }
        }
    }
}

/// The most blocks a one-node tree may have for single rays to test them all without its box
/// test ([`WideBvh::flat_blocks`]); the measured Cornell box has four.
const FLAT_BLOCKS: usize = 4;

/// Updates `best` (and `tmax`, its distance) with the hits in `block` that `keep` accepts: the
/// closest, ties to the lower triangle id, so that the order blocks are tested in never matters.
#[inline(always)]
fn closest_in_block<const W: usize, L: Lanes<W>>(
    tri_ray: &TriangleRay<L>,
    block: &TriangleBlock<W>,
    best: &mut Option<Hit>,
    tmax: &mut f32,
    keep: &impl Fn(u32, f32, f32) -> bool,
) {
    let hits = intersect_block(tri_ray, block, *tmax);
    for lane in lanes_of(hits.mask) {
        let (t, id, u, v) = (hits.t[lane], block.ids[lane], hits.u[lane], hits.v[lane]);
        if best.is_none_or(|b| Hit::precedes(t, id, b.t, b.triangle)) && keep(id, u, v) {
            *best = Some(Hit { t, triangle: id, u, v });
            *tmax = t;
        }
    }
}

/// Pushes the entered children (`mask`) in the node's order for the ray's octant, the first to
/// visit last (the nearest, or the farthest for [`VisitOrder::FarthestFirst`]), and returns that
/// one (taken back off the stack): no sort of the entry distances, and no branch per child. On the
/// staircase (`lumiere bench-bvh`, four alternating pairs against the children sorted by their
/// entry distances), its diffuse closest hits took 0-16% less time and its shadow rays 6-11% less,
/// with as many nodes and blocks visited; its path tracing 3-5% less.
#[inline(always)]
fn push_in_order<const W: usize>(
    node: &WideNode<W>,
    mask: u32,
    nears: &[f32; W],
    octant: usize,
    visit: VisitOrder,
    stack: &mut Stack<W>,
) -> Option<(u32, f32)> {
    if mask == 0 {
        return None;
    }
    if mask & (mask - 1) == 0 {
        let first = mask.trailing_zeros() as usize;
        return Some((node.children[first], nears[first]));
    }
    let order = node.near_to_far(octant);
    for i in 0..W {
        // The first visited is pushed last.
        let k = if visit == VisitOrder::NearestFirst { W - 1 - i } else { i };
        let slot = (order >> (4 * k)) as usize & 0xF;
        stack.push_if((node.children[slot], nears[slot]), mask & (1 << slot) != 0);
    }
    stack.pop()
}
