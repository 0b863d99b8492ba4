//! Spatial splits (Stich, Friedrich and Dietrich, "Spatial Splits in Bounding Volume Hierarchies",
//! 2009): a node may cut its triangles by a plane instead of sorting them whole to one side, so a
//! large triangle is referenced from both children, each with the box of its own piece.
//!
//! Architectural scenes need them: a wall or a floor spans most of the scene, and an object split
//! must put its whole box on one side, where it overlaps everything beside it. The build tries a
//! spatial split only where the best object split's children overlap by more than a small share of
//! the scene's area, and only within a budget of extra references that each node hands its children
//! in proportion, so the tree stays the same whatever the thread count.

use glam::{DVec3, Vec3, Vec3A};

use rayon::prelude::*;

use super::build::{BINNING_CHUNK, Bin, Box3A, Context, NodeBounds, PARALLEL_BINNING_THRESHOLD, PrimRef};

/// Spatial splits are tried where the object split's children overlap by more than this share of
/// the root's area (the paper's alpha; its 1e-5 built a staircase tree of the same SAH cost, 27.0,
/// taking 40% longer)...
pub(super) const OVERLAP_SHARE: f64 = 1e-3;

/// ...and by more than this share of the node's extent along the split's axis: without it the
/// bunny-1m's build took twice as long (427-450 ms at 2 threads); with it the bunny's tree is within
/// ten nodes of the uncut one.
pub(super) const OVERLAP_THICKNESS: f32 = 0.05;

/// Extra references the whole build may add, as a share of the triangles.
pub(super) const REFERENCE_BUDGET: f64 = 0.5;

/// A node tries spatial splits only while its budget is at least this share (1/8) of its
/// references; a node whose trial lost hands its children half its budget. Together they stop the
/// trials where cuts keep losing, and cost the staircase none of its cuts' gain (SAH cost 27.0).
pub(super) const LEAST_BUDGET_SHARE: usize = 8;

/// The cheapest plane of the spatial bins, and what the sweep found on each side.
pub(super) struct SpatialSplit {
    axis: usize,
    position: f32,
    /// `area * leaf_cost` of both sides, as in the object splits' sweep.
    pub(super) cost: f64,
    /// References the split adds at most (straddling triangles counted on both sides).
    pub(super) extra_references: usize,
    left: Bin,
    right: Bin,
}

/// One spatial bin: the union of the triangles' pieces inside it, and how many references start
/// (have their lowest piece) and end in it.
#[derive(Clone, Copy)]
struct SpatialBin {
    bounds: Box3A,
    entries: u32,
    exits: u32,
}

impl SpatialBin {
    const EMPTY: SpatialBin = SpatialBin { bounds: Box3A::EMPTY, entries: 0, exits: 0 };

    fn merge(self, o: SpatialBin) -> SpatialBin {
        SpatialBin {
            bounds: self.bounds.union(o.bounds),
            entries: self.entries + o.entries,
            exits: self.exits + o.exits,
        }
    }
}

/// Bounds of the part of triangle `corners` with `lo <= p[axis] <= hi`, or None if that part is
/// empty. Conservative in f32: edge crossings are found in f64 and rounded outwards with a margin
/// above f64's rounding error, so a box never misses a sliver of its piece (a ray through it would
/// then miss the triangle).
pub(super) fn clip_triangle(corners: [Vec3; 3], axis: usize, lo: f32, hi: f32) -> Option<Box3A> {
    let p = corners.map(|c| c.as_dvec3());
    let (lo, hi) = (f64::from(lo), f64::from(hi));
    let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for i in 0..3 {
        let (a, b) = (p[i], p[(i + 1) % 3]);
        if lo <= a[axis] && a[axis] <= hi {
            (min, max) = (min.min(a), max.max(a));
        }
        for plane in [lo, hi] {
            if (a[axis] < plane && plane < b[axis]) || (b[axis] < plane && plane < a[axis]) {
                let mut q = a + (b - a) * ((plane - a[axis]) / (b[axis] - a[axis]));
                q[axis] = plane;
                // Each coordinate is within a few f64 ulps of the operands' magnitude.
                let margin = DVec3::splat(a.abs().max(b.abs()).max_element() * f64::EPSILON * 8.0);
                (min, max) = (min.min(q - margin), max.max(q + margin));
            }
        }
    }
    if min.cmpgt(max).any() {
        return None;
    }
    // Within the slab and the triangle's own (exact) box, which the margins may overstep.
    let mut bounds = Box3A { min: round_down(min), max: round_up(max) };
    bounds.min[axis] = bounds.min[axis].max(lo as f32);
    bounds.max[axis] = bounds.max[axis].min(hi as f32);
    let [a, b, c] = corners.map(Vec3A::from);
    Some(Box3A { min: bounds.min.max(a.min(b).min(c)), max: bounds.max.min(a.max(b).max(c)) })
}

fn round_down(v: DVec3) -> Vec3A {
    Vec3A::from_array(v.to_array().map(|x| {
        let f = x as f32;
        if f64::from(f) > x { f.next_down() } else { f }
    }))
}

fn round_up(v: DVec3) -> Vec3A {
    Vec3A::from_array(v.to_array().map(|x| {
        let f = x as f32;
        if f64::from(f) < x { f.next_up() } else { f }
    }))
}

/// A triangle's corners sorted along one axis, for the sections of the spatial bins' planes. In
/// f32, and a reference that is already a piece gets its end bins' pieces from the sections and
/// corners inside them only: the bins estimate the costs; the partition clips conservatively.
struct Slices {
    corners: [Vec3A; 3],
    axis: usize,
}

impl Slices {
    fn new(corners: [Vec3; 3], axis: usize) -> Slices {
        let mut corners = corners.map(Vec3A::from);
        corners.sort_unstable_by(|a, b| a[axis].total_cmp(&b[axis]));
        Slices { corners, axis }
    }

    /// The box of the segment where the plane at `c` (strictly between the lowest and the highest
    /// corner) cuts the triangle: on the long edge, and on the edge below or above the middle corner.
    fn section(&self, c: f32) -> Box3A {
        let [a, m, b] = self.corners;
        let at = |p: Vec3A, q: Vec3A| {
            let span = q[self.axis] - p[self.axis];
            let t = if span > 0.0 { ((c - p[self.axis]) / span).clamp(0.0, 1.0) } else { 0.0 };
            p + (q - p) * t
        };
        let (x, y) = (at(a, b), if c < m[self.axis] { at(a, m) } else { at(m, b) });
        Box3A { min: x.min(y), max: x.max(y) }
    }

    /// The box of the corners with `lo <= p[axis] < hi` (`<= hi` if `inclusive`), or empty.
    fn corners_within(&self, lo: f32, hi: f32, inclusive: bool) -> Box3A {
        self.corners
            .iter()
            .filter(|p| lo <= p[self.axis] && (p[self.axis] < hi || inclusive))
            .fold(Box3A::EMPTY, |b, &p| b.grow(p))
    }
}

/// The piece of `r`'s triangle in `lo ..= hi` along `axis`, within `r`'s own box (which may
/// already be a piece).
fn piece(corners: [Vec3; 3], r: &PrimRef, axis: usize, lo: f32, hi: f32) -> Option<Box3A> {
    clip_triangle(corners, axis, lo, hi)?.intersection(r.bounds())
}

/// The spatial bins of one axis: `B` slabs of `width` from `min`.
struct Grid {
    axis: usize,
    min: f32,
    width: f32,
}

impl Grid {
    fn plane(&self, k: usize) -> f32 {
        self.min + k as f32 * self.width
    }

    fn bin_of(&self, x: f32, bins: usize) -> usize {
        (((x - self.min) / self.width) as usize).min(bins - 1)
    }

    /// Each reference's pieces in the bins it spans, and where it enters and leaves.
    fn bin<const W: usize, const B: usize>(&self, ctx: &Context<W>, refs: &[PrimRef]) -> [SpatialBin; B] {
        let axis = self.axis;
        let mut bins = [SpatialBin::EMPTY; B];
        for r in refs {
            let own = r.bounds();
            let (first, last) = (self.bin_of(own.min[axis], B), self.bin_of(own.max[axis], B));
            bins[first].entries += 1;
            bins[last].exits += 1;
            if first == last {
                bins[first].bounds = bins[first].bounds.union(own);
                continue;
            }
            let slices = Slices::new(ctx.corners(r.id), axis);
            // Each bin's piece: the sections at its two planes and the corners between them.
            let mut lower = Box3A::EMPTY;
            for (k, bin) in bins.iter_mut().enumerate().take(last + 1).skip(first) {
                let (lo, hi) = (self.plane(k), self.plane(k + 1));
                let upper = if k == last { Box3A::EMPTY } else { slices.section(hi) };
                let corners = slices.corners_within(if k == first { f32::NEG_INFINITY } else { lo }, hi, k == last);
                if let Some(p) = lower.union(upper).union(corners).intersection(own) {
                    bin.bounds = bin.bounds.union(p);
                }
                lower = upper;
            }
        }
        bins
    }
}

/// The cheapest spatial split of `refs` (whose box is `bounds`) over `B` bins an axis, if any plane
/// leaves references on both sides.
pub(super) fn best_spatial_split<const W: usize, const B: usize>(
    ctx: &Context<W>,
    refs: &[PrimRef],
    bounds: Box3A,
) -> Option<SpatialSplit> {
    let extent = bounds.max - bounds.min;
    let mut best: Option<SpatialSplit> = None;
    for axis in 0..3 {
        if extent[axis] <= 0.0 || !extent[axis].is_finite() {
            continue;
        }
        let grid = Grid { axis, min: bounds.min[axis], width: extent[axis] / B as f32 };
        let bins = if refs.len() > PARALLEL_BINNING_THRESHOLD {
            refs.par_chunks(BINNING_CHUNK)
                .map(|chunk| grid.bin::<W, B>(ctx, chunk))
                .reduce(|| [SpatialBin::EMPTY; B], |a, b| std::array::from_fn(|k| a[k].merge(b[k])))
        } else {
            grid.bin::<W, B>(ctx, refs)
        };
        let mut right = [SpatialBin::EMPTY; B];
        let mut acc = SpatialBin::EMPTY;
        for k in (1..B).rev() {
            acc = acc.merge(bins[k]);
            right[k] = acc;
        }
        let mut left = SpatialBin::EMPTY;
        for k in 1..B {
            left = left.merge(bins[k - 1]);
            let position = grid.plane(k);
            // Both children must shrink along the axis, or the recursion would not end.
            if left.entries == 0 || right[k].exits == 0 || !(grid.min < position && position < bounds.max[axis]) {
                continue;
            }
            let (l, r) = (
                Bin { bounds: left.bounds, count: left.entries },
                Bin { bounds: right[k].bounds, count: right[k].exits },
            );
            let cost = l.cost::<W>() + r.cost::<W>();
            if best.as_ref().is_none_or(|b| cost < b.cost) {
                let extra_references = (l.count + r.count) as usize - refs.len();
                best = Some(SpatialSplit { axis, position, cost, extra_references, left: l, right: r });
            }
        }
    }
    best
}

/// The references of each side of `split`, with their bounds. A straddling triangle goes to both
/// sides, each copy boxed to its own piece, unless keeping it whole on one side costs less by the
/// SAH (the paper's reference unsplitting). None if a side would be left empty.
pub(super) fn partition<const W: usize>(
    ctx: &Context<W>,
    refs: &[PrimRef],
    split: &SpatialSplit,
) -> Option<(Vec<PrimRef>, NodeBounds, Vec<PrimRef>, NodeBounds)> {
    let (axis, position) = (split.axis, split.position);
    let (mut left, mut right) = (Vec::with_capacity(refs.len()), Vec::with_capacity(refs.len()));
    let mut straddling = Vec::new();
    for r in refs {
        let own = r.bounds();
        if own.max[axis] <= position {
            left.push(*r);
        } else if own.min[axis] >= position {
            right.push(*r);
        } else {
            straddling.push(*r);
        }
    }
    // The sweep's sides, as if every straddling reference were split.
    let (mut l, mut r) = (split.left, split.right);
    for s in straddling {
        let corners = ctx.corners(s.id);
        let pieces =
            (piece(corners, &s, axis, f32::NEG_INFINITY, position), piece(corners, &s, axis, position, f32::INFINITY));
        let whole = s.bounds();
        match pieces {
            (Some(lp), Some(rp)) => {
                let both = l.cost::<W>() + r.cost::<W>();
                let all_left = Bin { bounds: l.bounds.union(whole), count: l.count }.cost::<W>()
                    + Bin { count: r.count.saturating_sub(1), ..r }.cost::<W>();
                let all_right = Bin { count: l.count.saturating_sub(1), ..l }.cost::<W>()
                    + Bin { bounds: r.bounds.union(whole), count: r.count }.cost::<W>();
                if all_left < both && all_left <= all_right {
                    left.push(s);
                    (l.bounds, r.count) = (l.bounds.union(whole), r.count.saturating_sub(1));
                } else if all_right < both {
                    right.push(s);
                    (r.bounds, l.count) = (r.bounds.union(whole), l.count.saturating_sub(1));
                } else {
                    left.push(s.with_bounds(lp));
                    right.push(s.with_bounds(rp));
                }
            }
            (Some(lp), None) => left.push(s.with_bounds(lp)),
            (None, Some(rp)) => right.push(s.with_bounds(rp)),
            // Not met (the pieces are conservative), but never drop a triangle.
            (None, None) => left.push(s),
        }
    }
    if left.is_empty() || right.is_empty() {
        return None;
    }
    let (left_bounds, right_bounds) = (NodeBounds::of(&left), NodeBounds::of(&right));
    Some((left, left_bounds, right, right_bounds))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The piece's box holds, in f64, every corner in the slab and every point where an edge
    /// crosses one of its planes (the piece's own corners), so rounding never shaves a sliver off;
    /// it lies within the slab and the triangle's box; and it is None exactly when no such point
    /// exists.
    #[test]
    fn clipped_boxes_hold_the_exact_piece() {
        let mut unit = crate::accel::wide::unit_floats(7);
        let mut next = || unit() * 20.0 - 10.0;
        for case in 0..20_000 {
            let corners = [0; 3].map(|_| Vec3::new(next(), next(), next()));
            let axis = case % 3;
            let (a, b) = (next(), next());
            let (lo, hi) = (a.min(b), a.max(b));
            let mut piece_corners = Vec::new();
            for i in 0..3 {
                let (p, q) = (corners[i].as_dvec3(), corners[(i + 1) % 3].as_dvec3());
                if f64::from(lo) <= p[axis] && p[axis] <= f64::from(hi) {
                    piece_corners.push(p);
                }
                for plane in [f64::from(lo), f64::from(hi)] {
                    if (p[axis] - plane) * (q[axis] - plane) < 0.0 {
                        let mut x = p + (q - p) * ((plane - p[axis]) / (q[axis] - p[axis]));
                        x[axis] = plane;
                        piece_corners.push(x);
                    }
                }
            }
            let clipped = clip_triangle(corners, axis, lo, hi);
            assert_eq!(clipped.is_some(), !piece_corners.is_empty(), "case {case}");
            let Some(bounds) = clipped else { continue };
            let (min, max) = (bounds.min.as_dvec3(), bounds.max.as_dvec3());
            for x in piece_corners {
                assert!(min.cmple(x).all() && x.cmple(max).all(), "case {case}: {x} outside {bounds:?}");
            }
            let whole = corners.iter().fold(Box3A::EMPTY, |b, &p| b.grow(p.into()));
            assert!(whole.min.cmple(bounds.min).all() && bounds.max.cmple(whole.max).all(), "case {case}");
            assert!(lo <= bounds.min[axis] && bounds.max[axis] <= hi, "case {case}");
        }
    }
}
