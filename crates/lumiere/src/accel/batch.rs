//! Shared-origin ray batches: many visibility rays leaving one point (the N shadow rays towards one
//! light triangle, the N ambient-occlusion rays of a hemisphere).
//!
//! Once per origin, the BVH is walked with a convex region instead of a ray (the shaft from the
//! origin to the light triangle or quad, or the half-space above the surface) to gather the few triangles
//! that can block any ray of the batch. For each of them the Plücker edge vectors
//! `(vi - o) x (vj - o)` are precomputed; a ray `o + t d` then crosses the triangle iff the three
//! `d . edge` share a sign, and the distance needs one more dot product: four dot products per
//! ray and triangle, and no traversal at all. `occluded` tests one ray against four triangles per
//! SSE operation; `occluded_lanes` (what the integrators use) tests each triangle against up to 32
//! rays at once, ray-major, with the same operations, so both give the same answers.
//!
//! A half-space can also be split into four quarters of azimuth, gathered in the same walk, each
//! with the triangles that may block its own rays (about half of the whole's): ambient occlusion
//! with many rays per point traces them quarter by quarter (`OriginBatch::select_part`).
//!
//! The walk is generic in the BVH's width and kernel; the candidates go four to a Plücker block
//! whatever that width: four kept side by side in a leaf block as they lie, the others repacked.
//!
//! Watertight like the Woop test: the two triangles sharing an edge compute its vector from the
//! same two corner vectors in swapped order, so one is exactly the negation of the other and a ray
//! through the edge is accepted by at least one of them. When gathering will not pay (too few
//! rays per origin, a hemisphere in a large scene) or the region holds too many triangles, the
//! batch falls back to ordinary traversal for each ray.

use glam::{Vec3, Vec4};

use super::simd::{F32x4, LaneMask, Lanes, all_lanes, min_ps};
use super::wide::{LEAF_BIT, Stack, TriangleBlock, WideBvh, leaf_blocks};
use crate::math::{Frame, Ray};

/// Beyond this many candidate blocks (of four triangles), per-ray traversal is cheaper.
const MAX_CANDIDATE_BLOCKS: usize = 24;

/// Fewer rays than this per origin do not pay for gathering their candidates: measured on the
/// Cornell box (`--mode direct` and `--mode ao` at N = 1 to 6, two threads, gathering against
/// traversal alternately, since quad shafts and whole groups made gathering cheaper), a shaft
/// towards a light triangle (or its quad) pays from 2 rays (19% faster there, 30% at 3; 1: 2%
/// slower), a hemisphere, which keeps more triangles, from 4 (12% faster; 6: 30%; 2: 24% slower).
const MIN_SHAFT_RAYS: u32 = 2;
const MIN_HEMISPHERE_RAYS: u32 = 4;

/// Scenes with more triangles than this never batch a hemisphere: an unbounded half-space above a
/// surface holds a sizeable part of any such scene, far more than `MAX_CANDIDATE_BLOCKS` blocks, and
/// finding that out cost walking dozens of nodes and blocks per origin before giving up (22% of an
/// ambient-occlusion render of the 1.1M-triangle bunny). The choice depends on the scene alone, so
/// the bytes stay the same whatever the thread count.
const MAX_HEMISPHERE_SCENE_TRIANGLES: usize = 16 * 4 * MAX_CANDIDATE_BLOCKS;

/// Four candidate triangles, SoA: the three Plücker edge vectors and the plane (normal, and the
/// normal's dot product with the first corner relative to the origin), the normal turned away from
/// the origin and the edges turned with it.
///
/// Why the edges turn too: with corners `a`, `b`, `c` relative to the origin, the edge vectors are
/// `b × c`, `c × a`, `a × b`, and a direction `d = αa + βb + γc` gives the edge functions
/// `α det`, `β det`, `γ det`, `det = a · (b × c)`, whose sign is the plane offset's. Turned by that
/// sign, none is below zero exactly for the directions that pass through the triangle ahead of the
/// origin; all `<= 0` is the opposite cone, behind it. A ray that never ends needs nothing else: no
/// plane test (a fifth of the operations per ray and triangle). A segment adds the plane's reach,
/// which the cone behind never passes. All three 0 at once would take a direction perpendicular
/// to three independent vectors, so the test does not look for it: leaving out the largest of the
/// three and its comparison made ambient occlusion at N = 256 faster, with the same image bytes.
#[derive(Clone, Copy, Debug)]
struct PluckerBlock {
    edges: [[[f32; 4]; 3]; 3],
    normal: [[f32; 4]; 3],
    plane_offset: [f32; 4],
}

/// A convex region of space, `n . x + d >= 0` for every plane, that contains every ray of a batch.
#[derive(Clone, Copy, Debug)]
pub struct Region {
    planes: [Vec4; MAX_PLANES],
    /// A box or triangle is kept only if it reaches above `keep_above[i]` on plane `i`. Planes
    /// through the origin of the rays get a small negative margin (the few-ulp offsets of ray ends
    /// and the rounding of the plane equations); planes the rays cannot reach (the light's, which
    /// the segments end in front of; the surface's, which the rays leave) get 0, so that what lies
    /// on them (the light itself, a coplanar ceiling, the floor under a point) is left out.
    keep_above: [f32; MAX_PLANES],
    count: usize,
    /// Set for a hemisphere split into quarters, each gathered apart (`OriginBatch::select_part`).
    quarters: Option<Quarters>,
}

/// The planes through the origin that split a hemisphere into quarters of azimuth, and how far
/// beyond them a triangle is still kept in a quarter (see [`Region::hemisphere_in_quarters`]).
#[derive(Clone, Copy, Debug)]
struct Quarters {
    x: Vec4,
    y: Vec4,
    margin: f32,
}

/// The parts of a region split into quarters.
const QUARTERS: usize = 4;

/// A shaft towards a quad: four sides, the quad's plane and the surface the rays leave.
const MAX_PLANES: usize = 6;

// The constructors and their helpers are `#[inline]`: the integrators call them once per receiver
// and light (soft shadows) or receiver (ambient occlusion) from another codegen unit, where, out of
// line, each returned its `Region` through memory and the planes' square roots and divisions
// waited on calls. Soft shadows N = 16 took 10% longer (BENCHMARKS.md, sixth session of 2026-12-05).
impl Region {
    /// The tetrahedron spanned by `origin` and the triangle `corners` (the shaft of all segments
    /// from the origin to points of the triangle).
    #[inline]
    pub fn shaft(origin: Vec3, corners: [Vec3; 3]) -> Option<Region> {
        let centroid = (origin + corners[0] + corners[1] + corners[2]) * 0.25;
        let faces = [
            [origin, corners[0], corners[1]],
            [origin, corners[1], corners[2]],
            [origin, corners[2], corners[0]],
            [corners[0], corners[1], corners[2]],
        ];
        let mut planes = [Vec4::ZERO; MAX_PLANES];
        for (plane, [a, b, c]) in planes.iter_mut().zip(faces) {
            *plane = plane_facing(a, b, c, centroid)?;
        }
        let margin = -tolerance(origin, &corners);
        // The segments end on the triangle `corners` (the light's shadow targets): nothing on or
        // beyond its plane can block them.
        Some(Region { planes, keep_above: [margin, margin, margin, 0.0, 0.0, 0.0], count: 4, quarters: None })
    }

    /// The pyramid spanned by `origin` and the convex quad `corners` (in order around it), cut by
    /// `plane` (`n . x + w`, positive at the origin), on or behind which every segment from the
    /// origin into the quad ends; `None` if the origin is not in front of it.
    #[inline]
    pub fn shaft_to_quad(origin: Vec3, corners: [Vec3; 4], plane: Vec4) -> Option<Region> {
        // In front of the plane (a NaN distance is not).
        if plane.truncate().dot(origin) + plane.w <= 0.0 || plane.is_nan() || origin.is_nan() {
            return None;
        }
        let centroid = (origin + corners[0] + corners[1] + corners[2] + corners[3]) * 0.2;
        let mut planes = [plane; MAX_PLANES];
        for (k, side) in planes.iter_mut().take(4).enumerate() {
            *side = plane_facing(origin, corners[k], corners[(k + 1) % 4], centroid)?;
        }
        let margin = -tolerance(origin, &corners);
        Some(Region { planes, keep_above: [margin, margin, margin, margin, 0.0, 0.0], count: 5, quarters: None })
    }

    /// The half-space above the plane through `origin` with normal `normal`: rays leaving `origin`
    /// on that side never reach anything on or below the plane.
    #[inline]
    pub fn hemisphere(origin: Vec3, normal: Vec3) -> Region {
        let n = normal.normalize();
        let mut planes = [Vec4::ZERO; MAX_PLANES];
        planes[0] = n.extend(-n.dot(origin));
        Region { planes, keep_above: [0.0; MAX_PLANES], count: 1, quarters: None }
    }

    /// [`Region::hemisphere`] about `frame.z`, split into four quarters of azimuth, gathered
    /// apart in one walk: quarter `q` holds the directions between `q` and `q + 1` quarter turns
    /// from `frame.x` towards `frame.y`, and the triangles that may block them.
    ///
    /// `reach` bounds how far from `origin` anything can be (the scene's size): a direction that
    /// strays out of its quarter by rounding (its sine or cosine a few ulps below zero at a side)
    /// still finds every triangle that can block it within that distance, as a quarter keeps what
    /// lies a few thousand ulps of `reach` beyond its sides.
    #[inline]
    pub fn hemisphere_in_quarters(origin: Vec3, frame: &Frame, reach: f32) -> Region {
        let through_origin = |n: Vec3| n.extend(-n.dot(origin));
        let quarters = Quarters {
            x: through_origin(frame.x),
            y: through_origin(frame.y),
            margin: tolerance_within(origin, reach),
        };
        Region { quarters: Some(quarters), ..Region::hemisphere(origin, frame.z) }
    }

    /// The region cut by the plane through `origin` with normal `normal` (the surface the rays
    /// leave, all of them above it): what lies wholly on or below it is left out, which in a
    /// shaft is mostly the receiver's own triangles, kept by its sides' margins where they meet at
    /// the origin (a shaft to the Cornell box's light held them alone seven times in ten).
    #[inline]
    pub fn above(mut self, origin: Vec3, normal: Vec3) -> Region {
        debug_assert!(self.count < MAX_PLANES, "a region has at most {MAX_PLANES} planes");
        let n = normal.normalize();
        self.planes[self.count] = n.extend(-n.dot(origin));
        self.keep_above[self.count] = 0.0;
        self.count += 1;
        self
    }

    /// Whether the region is a whole half-space (a hemisphere of directions, split into quarters
    /// or not), rather than a shaft: it has no end, so in a large scene it holds far too much.
    fn is_half_space(&self) -> bool {
        self.count == 1
    }

    /// Mask of the block's `W` triangles that do not lie wholly at or below `keep_above` of a plane.
    #[inline(always)]
    fn keeps_triangles<const W: usize, L: Lanes<W>>(&self, vertices: &[[[f32; W]; 3]; 3]) -> u32 {
        let mut kept = const { all_lanes(W) };
        for (plane, &keep_above) in self.planes[..self.count].iter().zip(&self.keep_above) {
            let highest = plane_distance::<W, L>(plane, &vertices[0])
                .max(plane_distance(plane, &vertices[1]))
                .max(plane_distance(plane, &vertices[2]));
            kept &= highest.gt(L::splat(keep_above)).bits();
        }
        kept
    }

    /// Masks of the block's `W` triangles that may reach into each quarter (all of them when the
    /// region is not split): a triangle is left out of a quarter that lies wholly beyond one of
    /// its sides, more than the margin away.
    #[inline(always)]
    fn quarter_masks<const W: usize, L: Lanes<W>>(&self, vertices: &[[[f32; W]; 3]; 3]) -> [u32; QUARTERS] {
        let Some(quarters) = &self.quarters else { return [all_lanes(W); QUARTERS] };
        let (low_x, high_x) = distance_range::<W, L>(&quarters.x, vertices);
        let (low_y, high_y) = distance_range::<W, L>(&quarters.y, vertices);
        let (margin, beyond) = (L::splat(quarters.margin), L::splat(-quarters.margin));
        let (pos_x, neg_x) = (high_x.gt(beyond).bits(), margin.gt(low_x).bits());
        let (pos_y, neg_y) = (high_y.gt(beyond).bits(), margin.gt(low_y).bits());
        [pos_x & pos_y, neg_x & pos_y, neg_x & neg_y, pos_x & neg_y]
    }

    /// Mask of the node's `W` child boxes that reach above `keep_above` on every plane.
    #[inline(always)]
    fn contains_box<const W: usize, L: Lanes<W>>(&self, node_bounds: &[[f32; W]; 6]) -> u32 {
        let mut inside = const { all_lanes(W) };
        for (plane, &keep_above) in self.planes[..self.count].iter().zip(&self.keep_above) {
            // The corner of each box farthest along the plane normal.
            let far = |axis: usize| {
                let row = if plane[axis] >= 0.0 { axis + 3 } else { axis };
                L::load(&node_bounds[row]) * L::splat(plane[axis])
            };
            let distance = far(0) + far(1) + far(2) + L::splat(plane.w);
            inside &= distance.gt(L::splat(keep_above)).bits();
        }
        inside
    }
}

/// The plane through `a`, `b`, `c`, its unit normal turned towards `inside`; `None` if degenerate.
#[inline]
fn plane_facing(a: Vec3, b: Vec3, c: Vec3, inside: Vec3) -> Option<Vec4> {
    let n = (b - a).cross(c - a).try_normalize()?;
    let n = if n.dot(inside - a) < 0.0 { -n } else { n };
    Some(n.extend(-n.dot(a)))
}

/// Signed distances (times the normal's length) of `W` points, SoA, above `plane`. A function
/// rather than a closure, so that it is inlined into the kernel's `#[target_feature]` code.
#[inline(always)]
fn plane_distance<const W: usize, L: Lanes<W>>(plane: &Vec4, points: &[[f32; W]; 3]) -> L {
    L::load(&points[0]) * L::splat(plane.x)
        + L::load(&points[1]) * L::splat(plane.y)
        + L::load(&points[2]) * L::splat(plane.z)
        + L::splat(plane.w)
}

/// The lowest and highest signed distances (as [`plane_distance`]) of the corners of `W`
/// triangles, SoA. A function, not a closure, for the same reason.
#[inline(always)]
fn distance_range<const W: usize, L: Lanes<W>>(plane: &Vec4, vertices: &[[[f32; W]; 3]; 3]) -> (L, L) {
    let (d0, d1, d2) = (
        plane_distance::<W, L>(plane, &vertices[0]),
        plane_distance::<W, L>(plane, &vertices[1]),
        plane_distance::<W, L>(plane, &vertices[2]),
    );
    (d0.min(d1).min(d2), d0.max(d1).max(d2))
}

/// A few thousand ulps of the coordinates of a shaft from `origin` to `corners`: far above
/// rounding, far below any geometry.
#[inline]
fn tolerance(origin: Vec3, corners: &[Vec3]) -> f32 {
    tolerance_within(origin, corners.iter().map(|c| (*c - origin).length()).fold(0.0f32, f32::max))
}

/// A few thousand ulps of the coordinates of a region reaching `size` from `origin`.
#[inline]
fn tolerance_within(origin: Vec3, size: f32) -> f32 {
    4096.0 * f32::EPSILON * (origin.abs().max_element() + size)
}

/// Candidate triangles for rays from one origin, or a note to traverse the BVH per ray. Keep one
/// per thread and `prepare` it for each origin: its buffer is reused.
#[derive(Clone, Debug, Default)]
pub struct OriginBatch {
    origin: Vec3,
    /// The candidates of each part of the region, four triangles to a block: one part, or the
    /// four quarters of a hemisphere split into quarters.
    parts: [Vec<PluckerBlock>; QUARTERS],
    /// The part the rays tested next lie in ([`OriginBatch::select_part`]).
    part: usize,
    traverse: bool,
}

impl OriginBatch {
    /// Gathers the triangles of `bvh` that may block `rays` rays from `origin` within `region`, or
    /// decides up front that per-ray traversal will be cheaper (too few rays, too large a region).
    /// Out of line, one copy per BVH type and crate (see the note in `wide/traverse.rs`).
    #[inline(never)]
    pub fn prepare<const W: usize, L: Lanes<W>>(
        &mut self,
        bvh: &WideBvh<W, L>,
        origin: Vec3,
        region: &Region,
        rays: u32,
    ) {
        self.origin = origin;
        self.parts.iter_mut().for_each(Vec::clear);
        self.part = 0;
        self.traverse = if region.is_half_space() {
            rays < MIN_HEMISPHERE_RAYS || bvh.triangle_count() > MAX_HEMISPHERE_SCENE_TRIANGLES
        } else {
            rays < MIN_SHAFT_RAYS
        };
        if self.traverse || bvh.triangle_count() == 0 {
            return;
        }
        if region.quarters.is_some() {
            L::dispatch(
                #[inline(always)]
                || self.gather::<W, L, QUARTERS>(bvh, region),
            );
        } else {
            L::dispatch(
                #[inline(always)]
                || self.gather::<W, L, 1>(bvh, region),
            );
        }
    }

    /// Makes the rays tested next those of quarter `part` of a region split into quarters (0, the
    /// default, for any other region). The rays must lie in it.
    ///
    /// # Panics
    /// If `part` is not below 4.
    pub fn select_part(&mut self, part: usize) {
        assert!(part < QUARTERS, "a region has at most {QUARTERS} parts, not {}", part + 1);
        self.part = part;
    }

    /// The candidates of the selected part.
    #[inline(always)]
    fn blocks(&self) -> &[PluckerBlock] {
        &self.parts[self.part]
    }

    /// Gathers the candidates of the region's `P` parts (1, or its quarters) in one walk.
    #[inline(always)]
    fn gather<const W: usize, L: Lanes<W>, const P: usize>(&mut self, bvh: &WideBvh<W, L>, region: &Region) {
        // Triangles kept but not yet packed into a block of four, per part. (`prepare` gathers
        // only in a BVH with triangles, so it has a first block.)
        let mut pending: [_; P] = std::array::from_fn(|_| pending::Pending::new(&bvh.blocks[0]));
        // Depth-first walk of the region, on the traversal's uninitialised stack: zeroing one for
        // every origin was a fifth of a soft-shadow render's instructions (callgrind).
        let mut stack = Stack::<W, u32>::new();
        stack.push(0);
        while let Some(reference) = stack.pop() {
            if reference & LEAF_BIT != 0 {
                for block in &bvh.blocks[leaf_blocks::<W>(reference)] {
                    let kept = region.keeps_triangles::<W, L>(&block.vertices);
                    let in_part = region.quarter_masks::<W, L>(&block.vertices);
                    for (part, pending) in pending.iter_mut().enumerate() {
                        if !self.keep_in_part(part, block, kept & in_part[part], pending) {
                            self.traverse = true;
                            self.parts.iter_mut().for_each(Vec::clear);
                            return;
                        }
                    }
                }
                continue;
            }
            let node = &bvh.nodes[reference as usize];
            let mut mask = region.contains_box::<W, L>(&node.bounds);
            while mask != 0 {
                let slot = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                stack.push(node.children[slot]);
            }
        }
        for (part, pending) in pending.iter_mut().enumerate() {
            if !pending.is_empty() {
                self.push_block(part, pending);
            }
        }
    }

    /// Adds the triangles `kept` of `block` to part `part`'s candidates; false if they overflow
    /// `MAX_CANDIDATE_BLOCKS` blocks.
    #[inline(always)]
    fn keep_in_part<'a, const W: usize>(
        &mut self,
        part: usize,
        block: &'a TriangleBlock<W>,
        mut kept: u32,
        pending: &mut pending::Pending<'a, W>,
    ) -> bool {
        // Four kept triangles side by side (padding repeats included: a duplicate never changes
        // an any-hit answer) are already four-lane rows: no repacking.
        for group in 0..W / 4 {
            let lanes = 0xF << (4 * group);
            if kept & lanes == lanes {
                if self.parts[part].len() == MAX_CANDIDATE_BLOCKS {
                    return false;
                }
                self.push_corners(part, pending::group_corners(block, group));
                kept &= !lanes;
            }
        }
        while kept != 0 {
            let lane = kept.trailing_zeros() as usize;
            kept &= kept - 1;
            // Padding lanes repeat the block's last triangle: skip the repeats.
            if block.is_padding(lane) {
                continue;
            }
            if pending.len() == 4 {
                self.push_block(part, pending);
            }
            if self.parts[part].len() == MAX_CANDIDATE_BLOCKS {
                return false;
            }
            pending.push(block, lane);
        }
        true
    }

    /// Appends to part `part` the Plücker block of the `pending` triangles (emptying it), written
    /// in place: a block built on the stack and pushed was a `memcpy` call per block (8% of
    /// ambient occlusion at N = 16).
    #[inline(always)]
    fn push_block<const W: usize>(&mut self, part: usize, pending: &mut pending::Pending<W>) {
        self.push_corners(part, pending.corners());
        pending.clear();
    }

    /// Appends to part `part` the Plücker block of four triangles' corners (`[corner][axis]`, a
    /// lane each).
    #[inline(always)]
    fn push_corners(&mut self, part: usize, corners: [[F32x4; 3]; 3]) {
        let blocks = &mut self.parts[part];
        if blocks.len() == blocks.capacity() {
            blocks.reserve(MAX_CANDIDATE_BLOCKS);
        }
        let len = blocks.len();
        // SAFETY: there is room for one more block (reserved above); `write_plucker_block` writes
        // every field of the slot before the length covers it.
        unsafe {
            write_plucker_block(blocks.as_mut_ptr().add(len), self.origin, corners);
            blocks.set_len(len + 1);
        }
    }

    /// The origin the batch was prepared for.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// Whether rays of this batch are traced one by one through the BVH (no candidates gathered).
    pub fn traverses(&self) -> bool {
        self.traverse
    }

    /// Candidate blocks gathered, and whether rays fall back to traversal (for tests and tuning).
    pub fn candidate_blocks(&self) -> Option<usize> {
        (!self.traverse).then_some(self.blocks().len())
    }

    /// True if the ray (which must leave from the prepared origin, inside the region) is blocked
    /// with `t` in `(0, ray.tmax]`.
    #[inline]
    pub fn occluded<const W: usize, L: Lanes<W>>(&self, bvh: &WideBvh<W, L>, ray: &Ray) -> bool {
        debug_assert_eq!(ray.origin, self.origin);
        if self.traverse {
            return bvh.occluded(ray);
        }
        let d = ray.dir.to_array().map(F32x4::splat);
        let zero = F32x4::splat(0.0);
        let tmax = F32x4::splat(ray.tmax);
        let bounded = ray.tmax != f32::INFINITY;
        self.blocks().iter().any(|block| {
            let dot =
                |v: &[[f32; 4]; 3]| d[0] * F32x4::load(&v[0]) + d[1] * F32x4::load(&v[1]) + d[2] * F32x4::load(&v[2]);
            let (s0, s1, s2) = (dot(&block.edges[0]), dot(&block.edges[1]), dot(&block.edges[2]));
            // Through the triangle, ahead (see `PluckerBlock`): no edge function below zero.
            let through = zero.le(s0.min(s1).min(s2)).bits();
            if !bounded || through == 0 {
                return through != 0;
            }
            // t = plane_offset / (d . n), accepted in (0, tmax] without dividing. The normal faces
            // away from the origin (`plane_offset` > 0, or NaN), so within reach implies ahead:
            // `0 < plane_offset <= tmax (d . n)` with `tmax > 0` holds only where `d . n > 0`.
            let within = F32x4::load(&block.plane_offset).le(tmax * dot(&block.normal));
            through & within.bits() != 0
        })
    }
}

impl OriginBatch {
    /// [`OriginBatch::occluded`] for `N <= 32` rays at once (directions SoA, one `tmax`), ray-major:
    /// each candidate triangle is tested against every ray with the same operations, in the same
    /// order, as the ray-by-ray test, so the answers are the same bits. Written as loops over the
    /// rays, which the compiler vectorises in the ISA the caller runs in (`Accel::simd`). Bit `i` of
    /// the result is set if ray `i` is blocked. The batch must have gathered candidates.
    #[inline(always)]
    pub fn occluded_lanes<const N: usize>(&self, dirs: &[[f32; N]; 3], tmax: f32) -> u32 {
        // Ambient occlusion's rays never end: the edge functions' signs alone say whether a ray
        // passes through a triangle ahead (see `PluckerBlock`), and the plane is not tested.
        if tmax == f32::INFINITY {
            self.occluded_lanes_within::<N, false>(dirs, tmax)
        } else {
            self.occluded_lanes_within::<N, true>(dirs, tmax)
        }
    }

    #[inline(always)]
    fn occluded_lanes_within<const N: usize, const BOUNDED: bool>(&self, dirs: &[[f32; N]; 3], tmax: f32) -> u32 {
        const { assert!(N <= 32, "a lane mask is a u32") };
        debug_assert!(!self.traverse);
        // A word per lane, not a `bool`: with bytes, the compiler stored every triangle's mask,
        // packed, and read it back for the check below (AO N = 256 took 5% longer).
        let mut blocked = [0u32; N];
        for block in self.blocks() {
            for triangle in 0..4 {
                let vector = |v: &[[f32; 4]; 3]| [v[0][triangle], v[1][triangle], v[2][triangle]];
                let [e0, e1, e2] = [vector(&block.edges[0]), vector(&block.edges[1]), vector(&block.edges[2])];
                let normal = vector(&block.normal);
                let numerator = block.plane_offset[triangle];
                for ray in 0..N {
                    let d = [dirs[0][ray], dirs[1][ray], dirs[2][ray]];
                    let dot = |v: [f32; 3]| d[0] * v[0] + d[1] * v[1] + d[2] * v[2];
                    let (s0, s1, s2) = (dot(e0), dot(e1), dot(e2));
                    let through = min_ps(min_ps(s0, s1), s2) >= 0.0;
                    blocked[ray] |= u32::from(if BOUNDED {
                        // And the plane within reach (which implies ahead: see `occluded`).
                        through & (numerator <= tmax * dot(normal))
                    } else {
                        through
                    });
                }
            }
            // In a closed room every ray is often blocked after the first blocks. (Sorting the
            // blocks by solid angle first, to stop sooner, cost more than it saved at every N.)
            if blocked.iter().fold(true, |all, &b| all & (b != 0)) {
                break;
            }
        }
        blocked.iter().enumerate().fold(0, |mask, (i, &b)| mask | b << i)
    }
}

/// Writes to `block` the edge vectors and planes of four triangles (`corners[corner][axis]`, a
/// lane each; lanes past the gathered triangles repeat the last one: a duplicate never changes an
/// any-hit answer) relative to `origin`, computed four lanes at a time.
///
/// # Safety
/// `block` must be valid for writes.
#[inline(always)]
unsafe fn write_plucker_block(block: *mut PluckerBlock, origin: Vec3, corners: [[F32x4; 3]; 3]) {
    let o = origin.to_array();
    let rel = |c: usize| -> [F32x4; 3] { [0, 1, 2].map(|a| corners[c][a] - F32x4::splat(o[a])) };
    let (a, b, c) = (rel(0), rel(1), rel(2));
    let cross = |u: &[F32x4; 3], v: &[F32x4; 3]| {
        [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    };
    let sub = |u: &[F32x4; 3], v: &[F32x4; 3]| [u[0] - v[0], u[1] - v[1], u[2] - v[2]];
    let dot = |u: &[F32x4; 3], v: &[F32x4; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let edges = [cross(&b, &c), cross(&c, &a), cross(&a, &b)];
    let normal = cross(&sub(&b, &a), &sub(&c, &a));
    // SAFETY: the caller's; each field is written through the raw pointer, not read.
    unsafe {
        // Turned to face away from the origin (`plane_offset` positive), so that the tests need
        // not compare signs, and the edges with it (exact: a product by +-1): `side` is +-1, or
        // NaN where the origin lies in the plane (0 / 0), which makes every comparison false: no
        // ray from there crosses the triangle.
        let offset = dot(&a, &normal);
        let side = offset / offset.abs();
        for (k, edge) in edges.iter().enumerate() {
            for (axis, lanes) in edge.iter().enumerate() {
                (*block).edges[k][axis] = (*lanes * side).to_array();
            }
        }
        for (axis, lanes) in normal.iter().enumerate() {
            (*block).normal[axis] = (*lanes * side).to_array();
        }
        (*block).plane_offset = (offset * side).to_array();
    }
}

/// Up to four gathered triangles, as the blocks and lanes they are found in. Their corners are
/// read into vectors only when the four are packed: written lane by lane into an SoA buffer and
/// then loaded as vectors, each load waited for four stores it could not be forwarded from (an
/// eighth of ambient occlusion at N = 16).
mod pending {
    use crate::accel::simd::{F32x4, Lanes};
    use crate::accel::wide::TriangleBlock;

    pub struct Pending<'a, const W: usize> {
        triangles: [(&'a TriangleBlock<W>, usize); 4],
        len: usize,
    }

    /// The corners of triangles `4 * group .. 4 * group + 4` of `block`, `[corner][axis]`.
    #[inline(always)]
    pub fn group_corners<const W: usize>(block: &TriangleBlock<W>, group: usize) -> [[F32x4; 3]; 3] {
        std::array::from_fn(|corner| {
            std::array::from_fn(|axis| {
                let row = &block.vertices[corner][axis][4 * group..4 * group + 4];
                F32x4::load(row.try_into().expect("a group is four lanes"))
            })
        })
    }

    impl<'a, const W: usize> Pending<'a, W> {
        /// Empty; `first` only fills the unused slots.
        pub fn new(first: &'a TriangleBlock<W>) -> Self {
            Pending { triangles: [(first, 0); 4], len: 0 }
        }
        /// Appends triangle `lane` of `block`.
        pub fn push(&mut self, block: &'a TriangleBlock<W>, lane: usize) {
            self.triangles[self.len] = (block, lane);
            self.len += 1;
        }
        pub fn len(&self) -> usize {
            self.len
        }
        pub fn is_empty(&self) -> bool {
            self.len == 0
        }
        pub fn clear(&mut self) {
            self.len = 0;
        }
        /// The corners of the triangles, `[corner][axis]` with one lane per triangle; the unused
        /// lanes repeat the last triangle.
        #[inline(always)]
        pub fn corners(&self) -> [[F32x4; 3]; 3] {
            let slot = |lane: usize| self.triangles[lane.min(self.len - 1)];
            let [t0, t1, t2, t3] = [0, 1, 2, 3].map(slot);
            std::array::from_fn(|corner| {
                std::array::from_fn(|axis| {
                    let value = |(block, lane): (&TriangleBlock<W>, usize)| block.vertices[corner][axis][lane];
                    F32x4::load(&[value(t0), value(t1), value(t2), value(t3)])
                })
            })
        }
    }
}
