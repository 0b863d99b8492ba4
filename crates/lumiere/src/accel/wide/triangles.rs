//! The `W`-wide watertight triangle test of one leaf block.
//!
//! It performs exactly the operations of the scalar `intersect_triangle`, in the same order, so it
//! returns the same bits; lanes that need the scalar test's f64 fallbacks are handed to it. The wide
//! and the binary BVH therefore give identical answers, which the tests demand.

use super::node::TriangleBlock;
use crate::accel::simd::{LaneMask, Lanes, all_lanes, lanes_of};
use crate::geometry::triangle::{CANCELLATION_ERROR, WatertightRay, intersect_triangle};
use crate::math::Ray;

/// The ray, splatted for the `W`-wide watertight test (same shear as `WatertightRay`).
pub(super) struct TriangleRay<L> {
    scalar: WatertightRay,
    k: [usize; 3],
    origin: [L; 3],
    shear: [L; 3],
}

impl<L> TriangleRay<L> {
    #[inline(always)]
    pub(super) fn new<const W: usize>(ray: &Ray) -> Self
    where
        L: Lanes<W>,
    {
        Self::splat(WatertightRay::new(ray))
    }

    /// The ray of `scalar`, splatted.
    #[inline(always)]
    pub(super) fn splat<const W: usize>(scalar: WatertightRay) -> Self
    where
        L: Lanes<W>,
    {
        let (k, shear) = scalar.permutation_and_shear();
        TriangleRay { scalar, k, origin: scalar.origin.to_array().map(L::splat), shear: shear.map(L::splat) }
    }
}

/// Hits of one block: bit `i` of `mask` for lane `i`, with its `t` and barycentrics.
pub(super) struct BlockHits<const W: usize> {
    pub mask: u32,
    pub t: [f32; W],
    pub u: [f32; W],
    pub v: [f32; W],
}

#[inline(always)]
pub(super) fn intersect_block<const W: usize, L: Lanes<W>>(
    ray: &TriangleRay<L>,
    block: &TriangleBlock<W>,
    tmax: f32,
) -> BlockHits<W> {
    let all = const { all_lanes(W) };
    let [kx, ky, kz] = ray.k;
    let [sx, sy, sz] = ray.shear;
    // Corner positions relative to the origin, permuted so that the ray runs along +z.
    let rel = |corner: usize, axis: usize| L::load(&block.vertices[corner][axis]) - ray.origin[axis];
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
    let zero = L::splat(0.0);
    let negative = u.lt(zero) | v.lt(zero) | w.lt(zero);
    let positive = u.gt(zero) | v.gt(zero) | w.gt(zero);
    let inside = !(negative.bits() & positive.bits()) & all;
    let zero_edge = (u.eq(zero) | v.eq(zero) | w.eq(zero)).bits();
    // Most blocks a ray reaches have no lane inside all three edges: skip the distance entirely.
    if inside | zero_edge == 0 {
        return BlockHits { mask: 0, t: [0.0; W], u: [0.0; W], v: [0.0; W] };
    }
    let det = u + v + w;
    let (az, bz, cz) = (sz * a_kz, sz * b_kz, sz * c_kz);
    let t_scaled = u * az + v * bz + w * cz;
    // Lanes the scalar test redoes in f64: an edge function exactly 0, overflow, or cancellation
    // (the same `cancels` condition, evaluated with the same operations).
    let overflow = !(det.is_finite() & t_scaled.is_finite()).bits() & all;
    let error = (u1.abs() + u2.abs()) * az.abs() + (v1.abs() + v2.abs()) * bz.abs() + (w1.abs() + w2.abs()) * cz.abs();
    let cancel = (error * L::splat(CANCELLATION_ERROR)).gt(t_scaled.abs()).bits();
    let needs_scalar = zero_edge | (inside & (overflow | cancel));

    let inv_det = L::splat(1.0) / det;
    let t = t_scaled * inv_det;
    let accepted = (det.ne(zero) & (t_scaled * det).gt(zero) & t.le(L::splat(tmax))).bits();
    let mut hits = BlockHits {
        mask: inside & accepted & !needs_scalar,
        t: t.to_array(),
        u: (v * inv_det).to_array(),
        v: (w * inv_det).to_array(),
    };
    if needs_scalar != 0 {
        resolve_scalar_lanes(&ray.scalar, block, tmax, needs_scalar, &mut hits);
    }
    hits
}

#[cold]
fn resolve_scalar_lanes<const W: usize>(
    ray: &WatertightRay,
    block: &TriangleBlock<W>,
    tmax: f32,
    lanes: u32,
    hits: &mut BlockHits<W>,
) {
    for lane in lanes_of(lanes) {
        let corner = |c: usize| glam::Vec3::from_array([0, 1, 2].map(|a| block.vertices[c][a][lane]));
        if let Some(h) = intersect_triangle(ray, tmax, corner(0), corner(1), corner(2)) {
            hits.mask |= 1 << lane;
            (hits.t[lane], hits.u[lane], hits.v[lane]) = (h.t, h.u, h.v);
        }
    }
}
