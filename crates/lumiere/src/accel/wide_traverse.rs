//! Closest-hit and occlusion queries on the 4-wide BVH: one SSE box test per node, one 4-wide
//! watertight triangle test per leaf block, iterative with a fixed stack, nearest child first.
//!
//! The triangle test performs exactly the operations of the scalar `intersect_triangle`, in the same
//! order, so it returns the same bits; lanes that need the scalar test's f64 fallbacks are handed
//! to it. The wide and the binary BVH therefore give identical answers, which the tests demand.

use std::mem::MaybeUninit;

use super::build::MAX_DEPTH;
use super::simd::F32x4;
use super::traverse::{BOX_EXPANSION, PRUNE_SLACK, safe_reciprocal};
use super::wide::{Bvh4, LEAF_BIT, Node4, TriangleBlock, leaf_blocks};
use super::{Hit, TraversalStats};
use crate::geometry::triangle::{CANCELLATION_ERROR, WatertightRay, intersect_triangle};
use crate::math::Ray;

/// Each wide level pushes at most three siblings.
const STACK_SIZE: usize = 3 * MAX_DEPTH + 1;

/// The traversal stack, left uninitialised: zeroing 1.7 KB per ray cost more than the whole
/// traversal of a small scene (measured: 14 -> see BENCHMARKS.md).
struct Stack {
    entries: [MaybeUninit<(u32, f32)>; STACK_SIZE],
    len: usize,
}

impl Stack {
    #[inline(always)]
    fn new() -> Self {
        Stack { entries: [const { MaybeUninit::uninit() }; STACK_SIZE], len: 0 }
    }

    #[inline(always)]
    fn push(&mut self, entry: (u32, f32)) {
        // The build bounds the depth by MAX_DEPTH and each level pushes at most three entries.
        self.entries[self.len] = MaybeUninit::new(entry);
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<(u32, f32)> {
        self.len = self.len.checked_sub(1)?;
        // SAFETY: entries below `len` were written by `push` before `len` grew past them.
        Some(unsafe { self.entries[self.len].assume_init() })
    }
}

/// The ray, splatted for the box tests.
struct BoxRay4 {
    /// Per axis, the bounds row that holds the entry (near) plane: min when the direction is positive.
    near_row: [usize; 3],
    origin: [F32x4; 3],
    inv_dir: [F32x4; 3],
}

impl BoxRay4 {
    fn new(ray: &Ray) -> Self {
        let d = ray.dir.to_array();
        let o = ray.origin.to_array();
        BoxRay4 {
            near_row: [0, 1, 2].map(|a| if d[a] >= 0.0 { a } else { a + 3 }),
            origin: o.map(F32x4::splat),
            inv_dir: d.map(|v| F32x4::splat(safe_reciprocal(v))),
        }
    }

    /// Entry distances of the four children and the mask (bit per child) of those the ray enters
    /// before `tmax`. NaN boxes (empty slots) always fail: NaN is kept as the second operand of
    /// every min/max, and comparisons with NaN are false.
    #[inline(always)]
    fn enter(&self, node: &Node4, tmax: F32x4) -> (u32, [f32; 4]) {
        let mut near = F32x4::splat(0.0);
        let mut far = tmax;
        for axis in 0..3 {
            let near_plane = F32x4::load(&node.bounds[self.near_row[axis]]);
            let far_plane = F32x4::load(&node.bounds[(self.near_row[axis] + 3) % 6]);
            near = near.max((near_plane - self.origin[axis]) * self.inv_dir[axis]);
            far = far.min((far_plane - self.origin[axis]) * self.inv_dir[axis] * F32x4::splat(BOX_EXPANSION));
        }
        (near.le(far).bits(), near.to_array())
    }
}

/// The ray, splatted for the 4-wide watertight test (same shear as `WatertightRay`).
struct TriangleRay4 {
    scalar: WatertightRay,
    k: [usize; 3],
    origin: [F32x4; 3],
    shear: [F32x4; 3],
}

impl TriangleRay4 {
    fn new(ray: &Ray) -> Self {
        let scalar = WatertightRay::new(ray);
        let (k, shear) = scalar.permutation_and_shear();
        TriangleRay4 { scalar, k, origin: ray.origin.to_array().map(F32x4::splat), shear: shear.map(F32x4::splat) }
    }
}

/// Hits of one block: bit `i` of `mask` for lane `i`, with its `t` and barycentrics.
struct BlockHits {
    mask: u32,
    t: [f32; 4],
    u: [f32; 4],
    v: [f32; 4],
}

#[inline(always)]
fn intersect_block(ray: &TriangleRay4, block: &TriangleBlock, tmax: f32) -> BlockHits {
    let [kx, ky, kz] = ray.k;
    let [sx, sy, sz] = ray.shear;
    // Corner positions relative to the origin, permuted so that the ray runs along +z.
    let rel = |corner: usize, axis: usize| F32x4::load(&block.vertices[corner][axis]) - ray.origin[axis];
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
    let zero = F32x4::splat(0.0);
    let negative = u.lt(zero) | v.lt(zero) | w.lt(zero);
    let positive = u.gt(zero) | v.gt(zero) | w.gt(zero);
    let inside = !(negative.bits() & positive.bits()) & 0xF;
    let zero_edge = (u.eq(zero) | v.eq(zero) | w.eq(zero)).bits();
    // Most blocks a ray reaches have no lane inside all three edges: skip the distance entirely.
    if inside | zero_edge == 0 {
        return BlockHits { mask: 0, t: [0.0; 4], u: [0.0; 4], v: [0.0; 4] };
    }
    let det = u + v + w;
    let (az, bz, cz) = (sz * a_kz, sz * b_kz, sz * c_kz);
    let t_scaled = u * az + v * bz + w * cz;
    // Lanes the scalar test redoes in f64: an edge function exactly 0, overflow, or cancellation
    // (the same `cancels` condition, evaluated with the same operations).
    let overflow = !(det.is_finite() & t_scaled.is_finite()).bits() & 0xF;
    let error = (u1.abs() + u2.abs()) * az.abs() + (v1.abs() + v2.abs()) * bz.abs() + (w1.abs() + w2.abs()) * cz.abs();
    let cancel = (error * F32x4::splat(CANCELLATION_ERROR)).gt(t_scaled.abs()).bits();
    let needs_scalar = zero_edge | (inside & (overflow | cancel));

    let inv_det = F32x4::splat(1.0) / det;
    let t = t_scaled * inv_det;
    let accepted = (det.ne(zero) & (t_scaled * det).gt(zero) & t.le(F32x4::splat(tmax))).bits();
    let mut hits = BlockHits {
        mask: inside & accepted & !needs_scalar,
        t: t.to_array(),
        u: (v * inv_det).to_array(),
        v: (w * inv_det).to_array(),
    };
    if needs_scalar != 0 {
        resolve_scalar_lanes(ray, block, tmax, needs_scalar, &mut hits);
    }
    hits
}

#[cold]
fn resolve_scalar_lanes(ray: &TriangleRay4, block: &TriangleBlock, tmax: f32, lanes: u32, hits: &mut BlockHits) {
    for lane in (0..4).filter(|l| lanes & (1 << l) != 0) {
        let corner = |c: usize| glam::Vec3::from_array([0, 1, 2].map(|a| block.vertices[c][a][lane]));
        if let Some(h) = intersect_triangle(&ray.scalar, tmax, corner(0), corner(1), corner(2)) {
            hits.mask |= 1 << lane;
            (hits.t[lane], hits.u[lane], hits.v[lane]) = (h.t, h.u, h.v);
        }
    }
}

impl Bvh4 {
    /// The closest hit with `t` in `(0, ray.tmax]`, ties to the lower triangle id; identical to
    /// [`super::Bvh::intersect`].
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_impl::<false>(ray, &mut TraversalStats::default())
    }

    /// As [`Bvh4::intersect`], counting nodes and blocks visited into `stats`.
    pub fn intersect_counted(&self, ray: &Ray, stats: &mut TraversalStats) -> Option<Hit> {
        self.intersect_impl::<true>(ray, stats)
    }

    /// True if anything lies on the ray with `t` in `(0, ray.tmax]`.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_impl::<false>(ray, &mut TraversalStats::default())
    }

    /// As [`Bvh4::occluded`], counting nodes and blocks visited into `stats`.
    pub fn occluded_counted(&self, ray: &Ray, stats: &mut TraversalStats) -> bool {
        self.occluded_impl::<true>(ray, stats)
    }

    #[inline(always)]
    fn intersect_impl<const COUNT: bool>(&self, ray: &Ray, stats: &mut TraversalStats) -> Option<Hit> {
        let box_ray = BoxRay4::new(ray);
        let tri_ray = TriangleRay4::new(ray);
        let mut best: Option<Hit> = None;
        let mut tmax = ray.tmax;
        let mut stack = Stack::new();
        let mut current = (0u32, 0f32);
        loop {
            let (reference, near) = current;
            if near <= tmax * PRUNE_SLACK {
                if reference & LEAF_BIT != 0 {
                    for block in &self.blocks[leaf_blocks(reference)] {
                        if COUNT {
                            stats.blocks += 1;
                        }
                        let hits = intersect_block(&tri_ray, block, tmax);
                        let mut mask = hits.mask;
                        while mask != 0 {
                            let lane = mask.trailing_zeros() as usize;
                            mask &= mask - 1;
                            let (t, id) = (hits.t[lane], block.ids[lane]);
                            if best.is_none_or(|b| t < b.t || (t == b.t && id < b.triangle)) {
                                best = Some(Hit { t, triangle: id, u: hits.u[lane], v: hits.v[lane] });
                                tmax = t;
                            }
                        }
                    }
                } else {
                    if COUNT {
                        stats.nodes += 1;
                    }
                    let node = &self.nodes[reference as usize];
                    let (mask, nears) = box_ray.enter(node, F32x4::splat(tmax * PRUNE_SLACK));
                    if let Some(next) = push_children(node, mask, &nears, &mut stack) {
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
    fn occluded_impl<const COUNT: bool>(&self, ray: &Ray, stats: &mut TraversalStats) -> bool {
        let box_ray = BoxRay4::new(ray);
        let tri_ray = TriangleRay4::new(ray);
        let tmax = ray.tmax;
        let tmax4 = F32x4::splat(tmax * PRUNE_SLACK);
        let mut stack = Stack::new();
        let mut current = (0u32, 0f32);
        loop {
            let (reference, _) = current;
            if reference & LEAF_BIT != 0 {
                for block in &self.blocks[leaf_blocks(reference)] {
                    if COUNT {
                        stats.blocks += 1;
                    }
                    if intersect_block(&tri_ray, block, tmax).mask != 0 {
                        return true;
                    }
                }
            } else {
                if COUNT {
                    stats.nodes += 1;
                }
                let node = &self.nodes[reference as usize];
                let (mask, nears) = box_ray.enter(node, tmax4);
                if let Some(next) = push_children(node, mask, &nears, &mut stack) {
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

/// Pushes the entered children but the nearest, farthest first, and returns the nearest to visit next.
#[inline(always)]
fn push_children(node: &Node4, mask: u32, nears: &[f32; 4], stack: &mut Stack) -> Option<(u32, f32)> {
    if mask == 0 {
        return None;
    }
    let first = mask.trailing_zeros() as usize;
    if mask & (mask - 1) == 0 {
        return Some((node.children[first], nears[first]));
    }
    // Two to four children: sort them by entry distance, nearest last (insertion sort on <= 4 items).
    let mut entries = [(0u32, 0f32); 4];
    let mut count = 0;
    let mut bits = mask;
    while bits != 0 {
        let lane = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        let entry = (node.children[lane], nears[lane]);
        let mut i = count;
        while i > 0 && entries[i - 1].1 < entry.1 {
            entries[i] = entries[i - 1];
            i -= 1;
        }
        entries[i] = entry;
        count += 1;
    }
    for &entry in &entries[..count - 1] {
        stack.push(entry);
    }
    Some(entries[count - 1])
}
