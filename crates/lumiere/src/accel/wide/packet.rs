//! Packets: `N` coherent rays (a 4x4 block of camera rays, their shadow rays towards one light
//! point) walk the wide BVH together, ray-major: each child box and each triangle is loaded once
//! and tested against all `N` rays, in loops over the lanes that the compiler vectorises in the ISA
//! the caller runs in ([`crate::accel::Accel::simd`]).
//!
//! Every lane performs exactly the operations of the single-ray traversal (`traverse.rs`,
//! `triangles.rs`): the same slab test, the same watertight triangle test with the same scalar
//! fallbacks, the same "closest, ties to the lower id" rule, so a packet returns the same hits,
//! bit for bit, as tracing its rays one by one. That needs the rays to share the slab test's entry
//! planes (direction signs) and the triangle test's axis permutation; [`PacketKey`] says which rays
//! do, and callers trace the others alone.

use glam::Vec3;

use super::leaf::{self, LEAF_BIT};
use super::node::{EMPTY_CHILD, TriangleBlock, WideNode};
use super::traverse::Stack;
use super::{SPAN_CULL_EXTENT, WideBvh};
use crate::accel::Hit;
use crate::accel::simd::{F32x4, Lanes, lanes_of, max_ps, min_ps};
use crate::accel::slab::{BOX_EXPANSION, PRUNE_SLACK, safe_reciprocal};
use crate::geometry::triangle::{CANCELLATION_ERROR, WatertightRay, dominant_axis, intersect_triangle};
use crate::math::Ray;

/// What rays must share to travel in one packet: the sign of each direction component (which slab
/// plane is entered first) and the dominant axis (the watertight test's axis permutation follows
/// from both). Three sign bits and the axis, decided with comparisons only.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PacketKey(u8);

impl PacketKey {
    /// The key of a ray whose direction has a NaN or is zero: such a ray is traced alone.
    pub const ALONE: PacketKey = PacketKey(u8::MAX);

    /// The key of `ray`: sign bits as `traverse.rs`'s `near_row` reads them (-0.0 negative). The
    /// dominant component is never zero but for a zero direction, traced alone, so its sign bit
    /// is also `WatertightRay`'s `d[kz] < 0.0`.
    #[inline(always)]
    pub fn of(ray: &Ray) -> PacketKey {
        let d = ray.dir;
        if d.is_nan() || d == Vec3::ZERO {
            return PacketKey::ALONE;
        }
        let kz = dominant_axis(d) as u8;
        let negative = u8::from(d.x.is_sign_negative())
            | u8::from(d.y.is_sign_negative()) << 1
            | u8::from(d.z.is_sign_negative()) << 2;
        PacketKey(negative | kz << 3)
    }

    /// The box row (min x, y, z, then max x, y, z) holding the plane each axis enters first.
    fn near_rows(self) -> [usize; 3] {
        [0, 1, 2].map(|axis| if self.0 & (1 << axis) == 0 { axis } else { axis + 3 })
    }

    /// `WatertightRay`'s `[kx, ky, kz]`: the dominant axis last, x and y swapped if it points down.
    fn permutation(self) -> [usize; 3] {
        let kz = usize::from(self.0 >> 3);
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if self.0 & (1 << kz) != 0 { [ky, kx, kz] } else { [kx, ky, kz] }
    }
}

/// `N` rays sharing a [`PacketKey`], SoA, splatted for the box and triangle tests.
pub struct RayPacket<const N: usize> {
    near_rows: [usize; 3],
    permutation: [usize; 3],
    origin: [[f32; N]; 3],
    dir: [[f32; N]; 3],
    inv_dir: [[f32; N]; 3],
    shear: [[f32; N]; 3],
    tmax: [f32; N],
}

/// What bounds every lane's view of a triangle: per axis, the least and the greatest origin
/// coordinate of any lane, and the least and the greatest of the watertight test's shears `sx`,
/// `sy`. Enough to rule out, a block at a time, the triangles that no lane can hit
/// ([`PacketSpan::outside`]): a camera packet's rays pass through a few pixels, and most of a
/// leaf's triangles lie wholly to one side of all of them.
struct PacketSpan {
    origin: [[f32; 2]; 3],
    shear: [[f32; 2]; 2],
    /// Whether every lane starts at the same point (a pinhole camera's packets): half the work.
    one_origin: bool,
}

impl PacketSpan {
    /// The triangles of `block` (bit per triangle) that no lane of the packet this span bounds
    /// can hit, the packet's axis permutation being `permutation`.
    ///
    /// The watertight test moves each corner into the ray's frame: `x = (p[kx] - o[kx]) - sx *
    /// (p[kz] - o[kz])`, and `y` alike with `ky` and `sy`, each operation rounded. Every rounded
    /// operation is monotone in each operand, so `x` is monotone in `o[kx]`, in `o[kz]` and in
    /// `sx` separately, and its extremes over the span come from its corners: the same operations
    /// on the span's bounds give, bit for bit, a least and a greatest `x` between which every
    /// lane's lies. A triangle whose three corners have `x < 0` for every lane (or `x > 0`, or the
    /// same with `y`) leaves the origin of every lane's 2D frame strictly outside it, for the
    /// rounded coordinates the test works with. The test then cannot report a hit: its edge
    /// functions are differences of rounded products, so each has the exact sign of the
    /// difference (the origin being outside, not all the same) or is 0, and a 0 sends the lane to
    /// the same products in f64, whose signs are exact. That holds while no product overflows,
    /// which [`SPAN_CULL_EXTENT`] ensures (the shears are at most 1 in magnitude: `kz` is the
    /// direction's dominant axis).
    #[inline(always)]
    fn outside<const W: usize>(&self, permutation: [usize; 3], block: &TriangleBlock<W>) -> u32 {
        let [kx, ky, kz] = permutation;
        let [depth_origin_low, depth_origin_high] = self.origin[kz];
        // Per frame axis (x, y), the greatest and the least coordinate of any corner for any lane.
        let mut highest = [[f32::NEG_INFINITY; W]; 2];
        let mut lowest = [[f32::INFINITY; W]; 2];
        for corner in &block.vertices {
            for (axis, k) in [kx, ky].into_iter().enumerate() {
                let [shear_low, shear_high] = self.shear[axis];
                let [origin_low, origin_high] = self.origin[k];
                if self.one_origin {
                    // One depth a corner: its products with the two shears bound all.
                    for t in 0..W {
                        let depth = corner[kz][t] - depth_origin_low;
                        let (low, high) = (shear_low * depth, shear_high * depth);
                        let (least, greatest) = (min_ps(low, high), max_ps(low, high));
                        let relative = corner[k][t] - origin_low;
                        highest[axis][t] = max_ps(highest[axis][t], relative - least);
                        lowest[axis][t] = min_ps(lowest[axis][t], relative - greatest);
                    }
                    continue;
                }
                for t in 0..W {
                    let (depth_low, depth_high) = (corner[kz][t] - depth_origin_high, corner[kz][t] - depth_origin_low);
                    let products = [
                        shear_low * depth_low,
                        shear_low * depth_high,
                        shear_high * depth_low,
                        shear_high * depth_high,
                    ];
                    let least = min_ps(min_ps(products[0], products[1]), min_ps(products[2], products[3]));
                    let greatest = max_ps(max_ps(products[0], products[1]), max_ps(products[2], products[3]));
                    highest[axis][t] = max_ps(highest[axis][t], (corner[k][t] - origin_low) - least);
                    lowest[axis][t] = min_ps(lowest[axis][t], (corner[k][t] - origin_high) - greatest);
                }
            }
        }
        (0..W).fold(0, |mask, t| {
            let out = highest[0][t] < 0.0 || lowest[0][t] > 0.0 || highest[1][t] < 0.0 || lowest[1][t] > 0.0;
            mask | u32::from(out) << t
        })
    }
}

/// A packet's span, worked out when it first reaches a leaf (many camera packets reach none).
enum LazySpan {
    Unknown,
    /// `None` where the packet's origins or the scene's corners are too far out to cull by it.
    Known(Option<PacketSpan>),
}

impl LazySpan {
    /// [`PacketSpan::outside`] for `packet`'s span (none where `moderate_extent` is false: the
    /// scene's corners lie too far out).
    #[inline(always)]
    fn outside<const N: usize, const W: usize>(
        &mut self,
        packet: &RayPacket<N>,
        moderate_extent: bool,
        block: &TriangleBlock<W>,
    ) -> u32 {
        if let LazySpan::Unknown = self {
            *self = LazySpan::Known(if moderate_extent { packet.span() } else { None });
        }
        // A `match`, not `map_or`: a closure may be left out of line, outside the ISA.
        match self {
            LazySpan::Known(Some(span)) => span.outside(packet.permutation, block),
            _ => 0,
        }
    }
}

/// The least and the greatest of `values`, four lanes at a time (a chain of dependent scalar steps
/// otherwise); where only one is used, the other's operations are dropped.
#[inline(always)]
fn range<const N: usize>(values: &[f32; N]) -> [f32; 2] {
    let mut quads = values.chunks_exact(4);
    let (mut low, mut high) = (F32x4::splat(f32::INFINITY), F32x4::splat(f32::NEG_INFINITY));
    for quad in &mut quads {
        let quad = F32x4::load(quad.try_into().expect("four lanes"));
        (low, high) = (low.min(quad), high.max(quad));
    }
    let ([a, b, c, d], [e, f, g, h]) = (low.to_array(), high.to_array());
    let init = [min_ps(min_ps(a, b), min_ps(c, d)), max_ps(max_ps(e, f), max_ps(g, h))];
    quads.remainder().iter().fold(init, |[low, high], &v| [min_ps(low, v), max_ps(high, v)])
}

/// The origin that all of a packet's rays start from, and the range of each axis's reciprocal
/// direction over the lanes: enough to bound every lane's slab test of a box at once.
struct SharedOrigin {
    origin: [f32; 3],
    /// Per axis, the least and the greatest reciprocal of any lane.
    inv_dir: [[f32; 2]; 3],
}

impl<const N: usize> RayPacket<N> {
    /// The packet of `rays`, which must all have the key `key` (lanes a caller leaves out repeat
    /// a ray that does). The reciprocals and shears of `safe_reciprocal` and `WatertightRay`,
    /// computed in loops over the lanes.
    #[inline(always)]
    pub fn new(key: PacketKey, rays: &[Ray; N]) -> Self {
        let mut packet = RayPacket {
            near_rows: key.near_rows(),
            permutation: key.permutation(),
            origin: [[0.0; N]; 3],
            dir: [[0.0; N]; 3],
            inv_dir: [[0.0; N]; 3],
            shear: [[0.0; N]; 3],
            tmax: [0.0; N],
        };
        for (lane, ray) in rays.iter().enumerate() {
            debug_assert_eq!(PacketKey::of(ray), key);
            for axis in 0..3 {
                packet.origin[axis][lane] = ray.origin[axis];
                packet.dir[axis][lane] = ray.dir[axis];
            }
            packet.tmax[lane] = ray.tmax;
        }
        for axis in 0..3 {
            for lane in 0..N {
                packet.inv_dir[axis][lane] = safe_reciprocal(packet.dir[axis][lane]);
            }
        }
        let [kx, ky, kz] = packet.permutation;
        for lane in 0..N {
            let d = [packet.dir[kx][lane], packet.dir[ky][lane], packet.dir[kz][lane]];
            packet.shear[0][lane] = d[0] / d[2];
            packet.shear[1][lane] = d[1] / d[2];
            packet.shear[2][lane] = 1.0 / d[2];
        }
        packet
    }

    /// The packet's shared origin and reciprocal ranges, if every lane starts at the same point (a
    /// pinhole camera's rays do).
    #[inline(always)]
    fn shared_origin(&self) -> Option<SharedOrigin> {
        // Plain loops: closures passed to `array::map` were left out of line, outside the ISA.
        let mut shared = SharedOrigin { origin: [0.0; 3], inv_dir: [[f32::INFINITY, f32::NEG_INFINITY]; 3] };
        for axis in 0..3 {
            let origin = self.origin[axis][0];
            let mut same = true;
            for lane in 0..N {
                same &= self.origin[axis][lane].to_bits() == origin.to_bits();
                let inv_dir = self.inv_dir[axis][lane];
                let [least, greatest] = &mut shared.inv_dir[axis];
                (*least, *greatest) = (least.min(inv_dir), greatest.max(inv_dir));
            }
            if !same {
                return None;
            }
            shared.origin[axis] = origin;
        }
        Some(shared)
    }

    /// The span of the packet's origins and shears, if its origins lie within
    /// [`SPAN_CULL_EXTENT`] (the scene's corners must too: see [`PacketSpan::outside`]).
    #[inline(always)]
    fn span(&self) -> Option<PacketSpan> {
        let origin = [range(&self.origin[0]), range(&self.origin[1]), range(&self.origin[2])];
        let moderate = origin.iter().all(|[low, high]| -SPAN_CULL_EXTENT < *low && *high < SPAN_CULL_EXTENT);
        let one_origin = origin.iter().all(|[low, high]| low == high);
        moderate.then(|| PacketSpan { origin, shear: [range(&self.shear[0]), range(&self.shear[1])], one_origin })
    }

    /// For a packet whose rays share their origin (`shared`, from [`RayPacket::shared_origin`]),
    /// the children of `node` that some lane may enter before its `limit` (bit per child).
    ///
    /// Never leaves out a child that a lane's [`RayPacket::enter`] enters: with one origin, each
    /// plane's distance is the same number `d` for every lane, and a lane's entry `d * inv_dir`,
    /// rounded, moves monotonically with its `inv_dir` (its exit `d * inv_dir * BOX_EXPANSION`
    /// too), so the lanes of the least and the greatest `inv_dir` bound all of them: a child whose
    /// least entry comes after its greatest exit is entered by none. One test for the `W` children
    /// spares the per-lane tests of the many children that a narrow packet misses, deep in the
    /// tree. (Bounding shadow packets, whose origins differ, by the corners of an origin interval
    /// too made them slower: hard shadows +14%.)
    #[inline(always)]
    fn children_entered_by_some<const W: usize>(
        &self,
        shared: &SharedOrigin,
        node: &WideNode<W>,
        limit: &[f32; N],
    ) -> u32 {
        // The closest-hit walk knows this maximum already (`farthest_limit`), but passing it in
        // made Cornell hits 33 -> 41 ms: the fold over the lanes in registers costs less.
        let farthest = limit.iter().fold(f32::NEG_INFINITY, |a, &b| max_ps(a, b));
        let mut near = [0.0f32; W];
        let mut far = [farthest; W];
        for axis in 0..3 {
            let near_row = self.near_rows[axis];
            let (near_planes, far_planes) = (&node.bounds[near_row], &node.bounds[(near_row + 3) % 6]);
            let [least, greatest] = shared.inv_dir[axis];
            let origin = shared.origin[axis];
            for child in 0..W {
                let (to_near, to_far) = (near_planes[child] - origin, far_planes[child] - origin);
                let entry = (to_near * least).min(to_near * greatest);
                let exit = (to_far * least * BOX_EXPANSION).max(to_far * greatest * BOX_EXPANSION);
                near[child] = max_ps(near[child], entry);
                far[child] = min_ps(far[child], exit);
            }
        }
        // Kept unless the entry surely comes after the exit (a NaN, an empty slot's, decides nothing).
        let kept = |child: usize| near[child].partial_cmp(&far[child]) != Some(std::cmp::Ordering::Greater);
        (0..W).fold(0, |mask, child| mask | u32::from(kept(child)) << child)
    }

    /// Lane `lane`'s ray, for the scalar test's f64 fallbacks.
    fn watertight(&self, lane: usize) -> WatertightRay {
        let vector = |v: &[[f32; N]; 3]| glam::Vec3::new(v[0][lane], v[1][lane], v[2][lane]);
        WatertightRay::new(&Ray { origin: vector(&self.origin), dir: vector(&self.dir), tmax: self.tmax[lane] })
    }

    /// Per lane, whether the ray enters child `child` of `node` before `limit` (the single-ray slab
    /// test of `traverse.rs`, one lane per ray), as a mask, and the nearest entry among them.
    #[inline(always)]
    fn enter<const W: usize>(&self, node: &WideNode<W>, child: usize, limit: &[f32; N]) -> (u32, f32) {
        let bounds = std::array::from_fn(|row| node.bounds[row][child]);
        let (near, far) = self.slabs(&bounds, limit);
        let mut mask = 0u32;
        for lane in 0..N {
            mask |= u32::from(near[lane] <= far[lane]) << lane;
        }
        // The least entry of any lane, entering or not: a lower bound of the entering lanes' (all
        // that ordering and pruning boxes need). The running minimum over the entering lanes it
        // replaces compiled to a chain of `N` dependent scalar steps (a seventh of a packet's
        // traversal on the bunny). A NaN lane would make it NaN, which prunes nothing.
        (mask, range(&near)[0])
    }

    /// Whether any lane enters the box of triangle `lane_in_block` of `block` before `limit` (the
    /// slab test is conservative: a ray that hits a triangle enters its box). See [`BoxFirst`].
    #[inline(always)]
    fn may_hit<const W: usize>(&self, block: &TriangleBlock<W>, lane_in_block: usize, limit: &[f32; N]) -> bool {
        let v = |corner: usize, axis: usize| block.vertices[corner][axis][lane_in_block];
        let low = |axis: usize| v(0, axis).min(v(1, axis)).min(v(2, axis));
        let high = |axis: usize| v(0, axis).max(v(1, axis)).max(v(2, axis));
        let bounds = [low(0), low(1), low(2), high(0), high(1), high(2)];
        let (near, far) = self.slabs(&bounds, limit);
        // Any lane, without building the lane mask.
        near.iter().zip(&far).fold(false, |any, (n, f)| any | (n <= f))
    }

    /// Each lane's entry and exit distances of a box given as its rows, the exit clipped to `limit`.
    #[inline(always)]
    fn slabs(&self, bounds: &[f32; 6], limit: &[f32; N]) -> ([f32; N], [f32; N]) {
        let mut near = [0.0f32; N];
        let mut far = *limit;
        for axis in 0..3 {
            let near_plane = bounds[self.near_rows[axis]];
            let far_plane = bounds[(self.near_rows[axis] + 3) % 6];
            let (origin, inv_dir) = (&self.origin[axis], &self.inv_dir[axis]);
            for lane in 0..N {
                near[lane] = max_ps(near[lane], (near_plane - origin[lane]) * inv_dir[lane]);
                far[lane] = min_ps(far[lane], (far_plane - origin[lane]) * inv_dir[lane] * BOX_EXPANSION);
            }
        }
        (near, far)
    }
}

/// The closest hits found so far, one per lane (`t` infinite and id `u32::MAX` for none).
struct Closest<const N: usize> {
    t: [f32; N],
    triangle: [u32; N],
    u: [f32; N],
    v: [f32; N],
}

impl<const N: usize> Closest<N> {
    /// Keeps the hit of lane `lane` if it is closer, or as close with a lower id (the single-ray rule).
    #[inline(always)]
    fn offer(&mut self, lane: usize, t: f32, triangle: u32, u: f32, v: f32) {
        if Hit::precedes(t, triangle, self.t[lane], self.triangle[lane]) {
            (self.t[lane], self.triangle[lane], self.u[lane], self.v[lane]) = (t, triangle, u, v);
        }
    }
}

/// Pushes the children of `node` that some lane of `packet` enters before its `limit` onto the
/// walk's stack (each with the nearest entry of any lane into it), nearest last, so that it is
/// popped first.
#[inline(always)]
fn push_children<const N: usize, const W: usize>(
    stack: &mut Stack<W>,
    packet: &RayPacket<N>,
    shared: Option<&SharedOrigin>,
    node: &WideNode<W>,
    limit: &[f32; N],
) {
    let mut entered = [(0u32, 0f32); W];
    let mut count = 0;
    let candidates = shared.map_or(u32::MAX, |shared| packet.children_entered_by_some(shared, node, limit));
    for child in 0..W {
        if node.children[child] == EMPTY_CHILD || candidates & (1 << child) == 0 {
            debug_assert!(node.children[child] == EMPTY_CHILD || packet.enter(node, child, limit).0 == 0);
            continue;
        }
        let (mask, nearest) = packet.enter(node, child, limit);
        if mask == 0 {
            continue;
        }
        // Insertion sort, farthest first.
        let mut i = count;
        while i > 0 && entered[i - 1].1 < nearest {
            entered[i] = entered[i - 1];
            i -= 1;
        }
        entered[i] = (node.children[child], nearest);
        count += 1;
    }
    for &entry in &entered[..count] {
        stack.push(entry);
    }
}

/// Per lane, the watertight test of triangle `lane_in_block` of `block`: the operations of
/// `intersect_block` (hence of the scalar `intersect_triangle`), one ray per lane; keep the three
/// in step (the tests compare them bit for bit). Returns the
/// lanes hit (with `t`, `u`, `v` filled in) and those the scalar test must decide (f64 fallbacks).
#[inline(always)]
fn test_triangle<const N: usize, const W: usize>(
    packet: &RayPacket<N>,
    block: &TriangleBlock<W>,
    lane_in_block: usize,
    tmax: &[f32; N],
    out: &mut [[f32; N]; 3],
) -> (u32, u32) {
    let [kx, ky, kz] = packet.permutation;
    let vertex = |corner: usize, axis: usize| block.vertices[corner][axis][lane_in_block];
    let (mut hit, mut needs_scalar) = (0u32, 0u32);
    for lane in 0..N {
        let rel = |corner: usize, axis: usize| vertex(corner, axis) - packet.origin[axis][lane];
        let [sx, sy, sz] = [packet.shear[0][lane], packet.shear[1][lane], packet.shear[2][lane]];
        let (a_kz, b_kz, c_kz) = (rel(0, kz), rel(1, kz), rel(2, kz));
        let ax = rel(0, kx) - sx * a_kz;
        let ay = rel(0, ky) - sy * a_kz;
        let bx = rel(1, kx) - sx * b_kz;
        let by = rel(1, ky) - sy * b_kz;
        let cx = rel(2, kx) - sx * c_kz;
        let cy = rel(2, ky) - sy * c_kz;
        let (u1, u2, v1, v2, w1, w2) = (cx * by, cy * bx, ax * cy, ay * cx, bx * ay, by * ax);
        let u = u1 - u2;
        let v = v1 - v2;
        let w = w1 - w2;
        let negative = (u < 0.0) | (v < 0.0) | (w < 0.0);
        let positive = (u > 0.0) | (v > 0.0) | (w > 0.0);
        let inside = !(negative & positive);
        let zero_edge = (u == 0.0) | (v == 0.0) | (w == 0.0);
        let det = u + v + w;
        let (az, bz, cz) = (sz * a_kz, sz * b_kz, sz * c_kz);
        let t_scaled = u * az + v * bz + w * cz;
        let overflow = !(det.is_finite() & t_scaled.is_finite());
        let error =
            (u1.abs() + u2.abs()) * az.abs() + (v1.abs() + v2.abs()) * bz.abs() + (w1.abs() + w2.abs()) * cz.abs();
        let cancel = error * CANCELLATION_ERROR > t_scaled.abs();
        let scalar = zero_edge | (inside & (overflow | cancel));
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        let accepted = (det != 0.0) & (t_scaled * det > 0.0) & (t <= tmax[lane]);
        hit |= u32::from(inside & accepted & !scalar) << lane;
        needs_scalar |= u32::from(scalar) << lane;
        out[0][lane] = t;
        out[1][lane] = v * inv_det;
        out[2][lane] = w * inv_det;
    }
    (hit, needs_scalar)
}

/// The scalar test, with its f64 fallbacks, for the lanes `test_triangle` could not decide.
#[cold]
#[inline(never)]
fn test_triangle_scalar<const N: usize, const W: usize>(
    packet: &RayPacket<N>,
    block: &TriangleBlock<W>,
    lane_in_block: usize,
    tmax: &[f32; N],
    lanes: u32,
) -> [Option<crate::geometry::triangle::TriangleHit>; N] {
    let corner = |c: usize| glam::Vec3::from_array([0, 1, 2].map(|a| block.vertices[c][a][lane_in_block]));
    let mut hits = [None; N];
    for lane in lanes_of(lanes) {
        hits[lane] = intersect_triangle(&packet.watertight(lane), tmax[lane], corner(0), corner(1), corner(2));
    }
    hits
}

/// Whether to test each triangle's box before the triangle itself. A packet tests a leaf's
/// triangles one by one against all its rays, and one that enters a leaf often misses most of
/// them. A box test (conservative: a ray that hits a triangle enters its box) pays where it rules
/// out most triangles: 88% of the boxes of the Cornell box's camera packets do (hits and hard
/// shadows 17% faster, the staircase's camera rays too), 57% on the 1.1M-triangle bunny, where
/// testing every box was 8-14% slower (3% as decided here). Decided per thread from the packets
/// it traced: on while at least two thirds of the boxes were ruled out (between the two), with
/// every 16th packet testing boxes anyway to keep the count current (a thread moves between
/// regions of a scene). It only skips triangles no lane can hit, so the hits never depend on it.
#[derive(Clone, Copy)]
struct BoxFirst {
    packets: u32,
    tested: u32,
    ruled_out: u32,
}

thread_local! {
    static BOX_FIRST: std::cell::Cell<BoxFirst> = const { std::cell::Cell::new(BoxFirst { packets: 0, tested: 0, ruled_out: 0 }) };
}

impl BoxFirst {
    /// Box tests counted before the first decision, and the most kept (older ones are halved).
    const TRIAL: u32 = 64;
    const WINDOW: u32 = 4096;

    /// Whether the next packet tests boxes.
    fn for_next_packet() -> bool {
        let stats = BOX_FIRST.get();
        stats.tested < Self::TRIAL || 3 * stats.ruled_out >= 2 * stats.tested || stats.packets.is_multiple_of(16)
    }

    /// Adds a packet's counts.
    fn record(tested: u32, ruled_out: u32) {
        let mut stats = BOX_FIRST.get();
        stats.packets = stats.packets.wrapping_add(1);
        stats.tested += tested;
        stats.ruled_out += ruled_out;
        if stats.tested > Self::WINDOW {
            (stats.tested, stats.ruled_out) = (stats.tested / 2, stats.ruled_out / 2);
        }
        BOX_FIRST.set(stats);
    }
}

// Inlined into the caller, which runs them in its ISA's `Accel::simd`: unlike the single-ray entry
// points, these own no dispatch of their own.
impl<const W: usize, L> WideBvh<W, L> {
    /// The closest hit of every lane of `packet` (as [`WideBvh::intersect`] would return it).
    #[inline(always)]
    pub fn intersect_packet<const N: usize>(&self, packet: &RayPacket<N>) -> [Option<Hit>; N] {
        let mut closest = Closest { t: [f32::INFINITY; N], triangle: [u32::MAX; N], u: [0.0; N], v: [0.0; N] };
        // Each lane's distance limit: its ray's tmax, then its closest hit.
        let mut tmax = packet.tmax;
        let mut stack = Stack::<W>::new();
        stack.push((0, 0.0));
        let mut farthest_limit = tmax.iter().fold(f32::NEG_INFINITY, |a, &b| max_ps(a, b));
        let mut out = [[0.0f32; N]; 3];
        let use_boxes = BoxFirst::for_next_packet();
        let (mut boxes_tested, mut boxes_ruled_out) = (0u32, 0u32);
        let shared = packet.shared_origin();
        let mut span = LazySpan::Unknown;
        while let Some((reference, nearest)) = stack.pop() {
            // No lane can find anything closer in there (the single-ray pruning, for the packet).
            if nearest > farthest_limit * PRUNE_SLACK {
                continue;
            }
            let limit = tmax.map(|t| t * PRUNE_SLACK);
            if reference & LEAF_BIT == 0 {
                push_children(&mut stack, packet, shared.as_ref(), &self.nodes[reference as usize], &limit);
                continue;
            }
            for block in &self.blocks[leaf::blocks::<W>(reference)] {
                let outside = span.outside(packet, self.moderate_extent, block);
                for lane_in_block in (0..W).filter(|&l| outside & (1 << l) == 0 && !block.is_padding(l)) {
                    if use_boxes {
                        boxes_tested += 1;
                        if !packet.may_hit(block, lane_in_block, &limit) {
                            boxes_ruled_out += 1;
                            continue;
                        }
                    }
                    let id = block.ids[lane_in_block];
                    let (mut hit, scalar) = test_triangle(packet, block, lane_in_block, &tmax, &mut out);
                    if scalar != 0 {
                        let resolved = test_triangle_scalar(packet, block, lane_in_block, &tmax, scalar);
                        for (lane, h) in resolved.iter().enumerate() {
                            if let Some(h) = h {
                                hit |= 1 << lane;
                                (out[0][lane], out[1][lane], out[2][lane]) = (h.t, h.u, h.v);
                            }
                        }
                    }
                    if hit == 0 {
                        continue;
                    }
                    for lane in 0..N {
                        if hit & (1 << lane) != 0 {
                            closest.offer(lane, out[0][lane], id, out[1][lane], out[2][lane]);
                            tmax[lane] = closest.t[lane];
                        }
                    }
                    farthest_limit = tmax.iter().fold(f32::NEG_INFINITY, |a, &b| max_ps(a, b));
                }
            }
        }
        BoxFirst::record(boxes_tested, boxes_ruled_out);
        std::array::from_fn(|lane| {
            (closest.triangle[lane] != u32::MAX).then(|| Hit {
                t: closest.t[lane],
                triangle: closest.triangle[lane],
                u: closest.u[lane],
                v: closest.v[lane],
            })
        })
    }

    /// Which lanes of `packet` are blocked, bit `i` for lane `i` (as [`WideBvh::occluded`] would
    /// answer each); stops as soon as every lane of `wanted` is.
    #[inline(always)]
    pub fn occluded_packet<const N: usize>(&self, packet: &RayPacket<N>, wanted: u32) -> u32 {
        let limit = packet.tmax.map(|t| t * PRUNE_SLACK);
        let mut blocked = 0u32;
        let mut stack = Stack::<W>::new();
        stack.push((0, 0.0));
        let mut out = [[0.0f32; N]; 3];
        let use_boxes = BoxFirst::for_next_packet();
        let (mut boxes_tested, mut boxes_ruled_out) = (0u32, 0u32);
        let mut span = LazySpan::Unknown;
        while let Some((reference, _)) = stack.pop() {
            if reference & LEAF_BIT == 0 {
                // Shadow packets share an end point, not an origin: no node test for them.
                push_children(&mut stack, packet, None, &self.nodes[reference as usize], &limit);
                continue;
            }
            for block in &self.blocks[leaf::blocks::<W>(reference)] {
                let outside = span.outside(packet, self.moderate_extent, block);
                for lane_in_block in (0..W).filter(|&l| outside & (1 << l) == 0 && !block.is_padding(l)) {
                    if use_boxes {
                        boxes_tested += 1;
                        if !packet.may_hit(block, lane_in_block, &limit) {
                            boxes_ruled_out += 1;
                            continue;
                        }
                    }
                    let (hit, scalar) = test_triangle(packet, block, lane_in_block, &packet.tmax, &mut out);
                    blocked |= hit;
                    let undecided = scalar & !blocked;
                    if undecided != 0 {
                        let resolved = test_triangle_scalar(packet, block, lane_in_block, &packet.tmax, undecided);
                        for (lane, h) in resolved.iter().enumerate() {
                            blocked |= u32::from(h.is_some()) << lane;
                        }
                    }
                    if blocked & wanted == wanted {
                        BoxFirst::record(boxes_tested, boxes_ruled_out);
                        return blocked;
                    }
                }
            }
        }
        BoxFirst::record(boxes_tested, boxes_ruled_out);
        blocked
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The node test of a packet whose rays share their origin keeps every child that a lane's own
    /// slab test enters, down to the last bit: boxes flat on an axis (walls), rays aimed exactly
    /// at box corners (where entry and exit meet and only `BOX_EXPANSION` lets the ray in), lanes
    /// a few ulps apart, short and infinite limits.
    #[test]
    fn a_shared_origin_node_test_keeps_every_child_a_lane_enters() {
        let mut next = crate::accel::wide::unit_floats(0x9E37_79B9_7F4A_7C15u64);
        let (mut checked, mut entered) = (0, 0);
        for _ in 0..4000 {
            let mut node = WideNode::<8>::empty();
            for child in 0..8 {
                let centre = [0, 1, 2].map(|_| next() * 2.0 - 1.0);
                let flat = (next() * 4.0) as usize;
                for (axis, centre) in centre.into_iter().enumerate() {
                    let half = if axis == flat { 0.0 } else { next() * 0.5 };
                    node.bounds[axis][child] = centre - half;
                    node.bounds[axis + 3][child] = centre + half;
                }
                node.children[child] = child as u32;
            }
            let origin = Vec3::new(next() * 20.0 - 10.0, next() * 20.0 - 10.0, 8.0 + next() * 4.0);
            // Every lane aimed at one corner of one child, a few ulps apart, or all exactly there.
            let child = (next() * 8.0) as usize;
            let corner: [f32; 3] = [0, 1, 2].map(|axis| node.bounds[axis + 3 * usize::from(next() < 0.5)][child]);
            let ulps = (next() * 3.0) as u32;
            let rays: [Ray; 16] = std::array::from_fn(|lane| {
                let aim = corner.map(|c| f32::from_bits(c.to_bits().wrapping_add(lane as u32 % 2 * ulps)));
                Ray::new(origin, Vec3::from_array(aim) - origin)
            });
            let key = PacketKey::of(&rays[0]);
            if rays.iter().any(|ray| PacketKey::of(ray) != key) {
                continue;
            }
            let packet = RayPacket::new(key, &rays);
            let limit: [f32; 16] =
                std::array::from_fn(|lane| if lane % 4 == 0 { 30.0 * next() } else { f32::INFINITY });
            let shared = packet.shared_origin().expect("one origin");
            let candidates = packet.children_entered_by_some(&shared, &node, &limit);
            for child in 0..8 {
                checked += 1;
                if packet.enter(&node, child, &limit).0 != 0 {
                    entered += 1;
                    assert!(candidates & (1 << child) != 0, "child {child} of {node:?} left out for {rays:?}");
                }
            }
        }
        assert!(checked > 10_000 && entered > 2_000, "{checked} children checked, {entered} entered");
    }

    /// A block's triangles culled by a packet's span are hit by none of its lanes, not even by the
    /// rounding of the watertight test: packets from one origin and from origins a pixel apart
    /// (gKit's camera) or far apart, aimed exactly at triangle corners and between them, against
    /// slivers, tiny and large triangles around the aim.
    #[test]
    fn a_span_culls_only_triangles_no_lane_hits() {
        let mut next = crate::accel::wide::unit_floats(0x2545_F491_4F6C_DD1Du64);
        let (mut culled, mut kept_and_hit, mut culled_near) = (0, 0, 0);
        for round in 0..3000 {
            // Eight triangles around a point, from slivers to large ones.
            let centre = Vec3::new(next() * 4.0 - 2.0, next() * 4.0 - 2.0, next() * 4.0 - 2.0);
            let scale = [1e-4, 1e-2, 1.0][round % 3];
            let mut block = TriangleBlock::<8> { vertices: [[[0.0; 8]; 3]; 3], ids: [0; 8] };
            let mut corners = Vec::new();
            for t in 0..8 {
                // Half of them meet at the centre, as a mesh's triangles meet at a vertex.
                let a = if t % 2 == 0 {
                    centre
                } else {
                    centre + Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * scale
                };
                let b = a + Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * scale;
                // A sliver: the third corner almost on the line through the first two.
                let c = if t % 3 == 0 {
                    a + (b - a) * (next() * 3.0 - 1.0) + Vec3::splat(scale * 1e-6)
                } else {
                    a + Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * scale
                };
                for (corner, p) in [a, b, c].into_iter().enumerate() {
                    for axis in 0..3 {
                        block.vertices[corner][axis][t] = p[axis];
                    }
                }
                block.ids[t] = t as u32;
                corners.extend([a, b, c]);
            }
            // Sixteen rays from one origin, from origins a pixel apart, or from far apart, aimed
            // as a tile of pixels is: around a point (a corner, or between two), half of them
            // exactly at it.
            let eye = centre + Vec3::new(next() - 0.5, next() - 0.5, 3.0 + next());
            let spread = [0.0, 1e-3 * scale, 0.5][(round / 3) % 3];
            let pick = |u: f32| corners[(u * corners.len() as f32) as usize];
            let focus = match (next() * 3.0) as usize {
                0 => centre,
                1 => pick(next()),
                _ => pick(next()).lerp(pick(next()), next()),
            };
            let jitter = scale * [1e-6, 1e-3, 0.1][(round / 9) % 3];
            let rays: [Ray; 16] = std::array::from_fn(|lane| {
                let origin = eye + Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * spread;
                let offset = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * jitter;
                let aim = if lane % 2 == 0 { focus } else { focus + offset };
                Ray::new(origin, aim - origin)
            });
            let key = PacketKey::of(&rays[0]);
            if rays.iter().any(|ray| PacketKey::of(ray) != key) {
                continue;
            }
            let packet = RayPacket::new(key, &rays);
            let outside = packet.span().expect("moderate origins").outside(packet.permutation, &block);
            for t in 0..8 {
                let corner = |c: usize| Vec3::from_array([0, 1, 2].map(|axis| block.vertices[c][axis][t]));
                let hits: Vec<usize> = (0..16)
                    .filter(|&lane| {
                        intersect_triangle(&packet.watertight(lane), f32::INFINITY, corner(0), corner(1), corner(2))
                            .is_some()
                    })
                    .collect();
                if outside & (1 << t) != 0 {
                    assert!(hits.is_empty(), "triangle {t} of {block:?} culled, yet lanes {hits:?} of {rays:?} hit it");
                    culled += 1;
                    // Culled though every even lane is aimed exactly at one of its corners.
                    let near = focus == centre && t % 2 == 0;
                    culled_near += usize::from(near);
                } else if !hits.is_empty() {
                    kept_and_hit += 1;
                }
            }
        }
        assert!(
            culled > 5_000 && kept_and_hit > 2_000 && culled_near > 20,
            "{culled} culled ({culled_near} aimed at a corner), {kept_and_hit} kept and hit"
        );
    }

    /// The key's permutation and the packet's shears are `WatertightRay`'s, for directions along
    /// and between the axes, of either sign, zero components included.
    #[test]
    fn packets_shear_rays_as_the_watertight_test_does() {
        let values = [-2.0f32, -1.0, -0.5, -0.0, 0.0, 0.5, 1.0, 2.0];
        let mut rays = Vec::new();
        for &x in &values {
            for &y in &values {
                for &z in &values {
                    if x != 0.0 || y != 0.0 || z != 0.0 {
                        rays.push(Ray::new(Vec3::new(0.25, -1.0, 3.0), Vec3::new(x, y, z)));
                    }
                }
            }
        }
        for ray in rays {
            let key = PacketKey::of(&ray);
            let (permutation, shear) = WatertightRay::new(&ray).permutation_and_shear();
            assert_eq!(key.permutation(), permutation, "{ray:?}");
            let packet = RayPacket::<4>::new(key, &[ray; 4]);
            let packet_shear = [0, 1, 2].map(|axis| packet.shear[axis][3]);
            assert_eq!(packet_shear.map(f32::to_bits), shear.map(f32::to_bits), "{ray:?}");
        }
    }
}
