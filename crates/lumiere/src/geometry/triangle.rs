//! Watertight ray/triangle intersection (Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2013).
//!
//! The ray is sheared so that it becomes the +z axis; each edge then gets a 2D edge function whose
//! sign is computed the same way for both triangles sharing the edge, so a ray can never slip
//! between them. Edge functions that evaluate to exactly 0 in f32 are recomputed in f64, as the
//! paper recommends, so hits on shared edges and vertices are classified consistently.

use glam::Vec3;

use crate::math::Ray;

/// Per-ray constants of the watertight test: the axis permutation and the shear.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub origin: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl WatertightRay {
    /// Without branches: for incoherent rays (a path's bounces) the dominant axis and its sign are
    /// coin flips, and predicting them wrong cost more than the selects.
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir.to_array();
        let kz = dominant_axis(ray.dir);
        let (next, after) = ([1, 2, 0][kz], [2, 0, 1][kz]);
        // Keep the winding: if the dominant direction is negative, swap x and y.
        let negative = d[kz] < 0.0;
        let kx = if negative { after } else { next };
        let ky = if negative { next } else { after };
        WatertightRay { origin: ray.origin, kx, ky, kz, sx: d[kx] / d[kz], sy: d[ky] / d[kz], sz: 1.0 / d[kz] }
    }
}

/// The axis of the largest component of `d` in magnitude (the first of equals), which the
/// watertight test turns into its z axis. Computed without branches (see [`WatertightRay::new`]).
#[inline(always)]
pub fn dominant_axis(d: Vec3) -> usize {
    let abs = d.abs();
    let x_wins = (abs.x >= abs.y) & (abs.x >= abs.z);
    let y_beats_z = abs.y >= abs.z;
    usize::from(!x_wins) * (2 - usize::from(y_beats_z))
}

impl WatertightRay {
    /// The axis permutation `[kx, ky, kz]` and shear `[sx, sy, sz]`, for SIMD variants of the test.
    pub fn permutation_and_shear(&self) -> ([usize; 3], [f32; 3]) {
        ([self.kx, self.ky, self.kz], [self.sx, self.sy, self.sz])
    }
}

/// Where a ray met a triangle: `t` along the ray, and the barycentric weights `u` of the second and
/// `v` of the third vertex (the first has `1 - u - v`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// Intersects the triangle `(p0, p1, p2)` for `t` in the open-closed range `(0, tmax]`; both faces count.
///
/// The returned `t` is the one compared with `tmax`, so a BVH that shrinks `tmax` as it finds hits
/// selects the same closest triangle as a brute-force loop, whatever the visiting order.
#[inline(always)]
pub fn intersect_triangle(ray: &WatertightRay, tmax: f32, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<TriangleHit> {
    let (kx, ky, kz) = (ray.kx, ray.ky, ray.kz);
    let a = p0 - ray.origin;
    let b = p1 - ray.origin;
    let c = p2 - ray.origin;
    let ax = a[kx] - ray.sx * a[kz];
    let ay = a[ky] - ray.sy * a[kz];
    let bx = b[kx] - ray.sx * b[kz];
    let by = b[ky] - ray.sy * b[kz];
    let cx = c[kx] - ray.sx * c[kz];
    let cy = c[ky] - ray.sy * c[kz];

    let (u1, u2, v1, v2, w1, w2) = (cx * by, cy * bx, ax * cy, ay * cx, bx * ay, by * ax);
    let mut u = u1 - u2;
    let mut v = v1 - v2;
    let mut w = w1 - w2;
    // Rounding of each edge function is of the order of its products' magnitudes.
    let magnitudes = [u1.abs() + u2.abs(), v1.abs() + v2.abs(), w1.abs() + w2.abs()];
    if u == 0.0 || v == 0.0 || w == 0.0 {
        u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
        v = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
        w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    let (az, bz, cz) = (ray.sz * a[kz], ray.sz * b[kz], ray.sz * c[kz]);
    let t_scaled = u * az + v * bz + w * cz;
    if !(det.is_finite() && t_scaled.is_finite()) {
        // Products of coordinates beyond ~1e18 overflow f32 (or NaN from inf - inf).
        return intersect_triangle_f64(ray, tmax, p0, p1, p2);
    }
    if cancels(magnitudes, [az, bz, cz], t_scaled) {
        // The f32 edge tests above already decided, watertightly, that the ray crosses the triangle;
        // only the distance is recomputed. Re-deciding the edges in f64 (with a differently rounded
        // shear) could reject a ray on a shared edge from both triangles.
        return distance_f64(ray, tmax, p0, p1, p2);
    }
    if det == 0.0 || t_scaled * det <= 0.0 {
        return None;
    }
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    (t <= tmax).then_some(TriangleHit { t, u: v * inv_det, v: w * inv_det })
}

/// True when the rounding error of the f32 distance may be as large as the distance itself.
///
/// `t` is a mean of the vertex depths weighted by the edge functions, whose rounding error is of the
/// order of `EPSILON x` their products' magnitudes. That error, carried by depths far larger than
/// `t`, can turn a clean hit into `t <= 0` (seen on a 1 x 20000 wall hit at distance 2, whose edge
/// functions were small differences of products near 4e7). Such cases go to f64. For ordinary
/// triangles, including the one a secondary ray leaves from, the bound is far below `|t|`.
#[inline(always)]
pub fn cancels(magnitudes: [f32; 3], depths: [f32; 3], t_scaled: f32) -> bool {
    let error = magnitudes[0] * depths[0].abs() + magnitudes[1] * depths[1].abs() + magnitudes[2] * depths[2].abs();
    error * CANCELLATION_ERROR > t_scaled.abs()
}

/// Rounding error per unit of magnitude, with a wide margin: 64 ulps.
pub const CANCELLATION_ERROR: f32 = 64.0 * f32::EPSILON;

/// Sheared corner coordinates and edge functions in f64: `(u, v, w)` and the depths `(az, bz, cz)`.
#[cold]
fn edge_functions_f64(ray: &WatertightRay, p0: Vec3, p1: Vec3, p2: Vec3) -> ([f64; 3], [f64; 3]) {
    let (kx, ky, kz) = (ray.kx, ray.ky, ray.kz);
    let o = ray.origin.as_dvec3();
    let (sx, sy, sz) = (ray.sx as f64, ray.sy as f64, ray.sz as f64);
    let [a, b, c] = [p0, p1, p2].map(|p| p.as_dvec3() - o);
    let shear = |p: glam::DVec3| (p[kx] - sx * p[kz], p[ky] - sy * p[kz], sz * p[kz]);
    let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (shear(a), shear(b), shear(c));
    ([cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax], [az, bz, cz])
}

/// The whole test in f64, for inputs whose f32 products overflow. Rare, so it favours clarity.
#[cold]
fn intersect_triangle_f64(ray: &WatertightRay, tmax: f32, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<TriangleHit> {
    let ([u, v, w], _) = edge_functions_f64(ray, p0, p1, p2);
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    distance_f64(ray, tmax, p0, p1, p2)
}

/// Distance and barycentrics in f64 for a ray already known to cross the triangle's edges.
#[cold]
fn distance_f64(ray: &WatertightRay, tmax: f32, p0: Vec3, p1: Vec3, p2: Vec3) -> Option<TriangleHit> {
    let ([u, v, w], [az, bz, cz]) = edge_functions_f64(ray, p0, p1, p2);
    let det = u + v + w;
    let t = (u * az + v * bz + w * cz) / det;
    // `t > 0.0` is false for NaN too, which rejects it.
    let positive = t > 0.0;
    if det == 0.0 || !positive || t as f32 > tmax {
        return None;
    }
    Some(TriangleHit { t: t as f32, u: (v / det) as f32, v: (w / det) as f32 })
}

/// True if the triangle has exactly zero area in f32 (repeated or collinear corners). Such a
/// triangle has no surface: a ray along its line would get a meaningless `t` from rounding noise,
/// so acceleration structures leave it out and no query ever reports it.
#[inline]
pub fn is_degenerate(p0: Vec3, p1: Vec3, p2: Vec3) -> bool {
    (p1 - p0).cross(p2 - p0) == Vec3::ZERO
}

/// Area of the triangle.
#[inline]
pub fn triangle_area(p0: Vec3, p1: Vec3, p2: Vec3) -> f32 {
    0.5 * (p1 - p0).cross(p2 - p0).length()
}

/// Unnormalised geometric normal, following the winding `p0 -> p1 -> p2` (right-handed).
#[inline]
pub fn triangle_normal(p0: Vec3, p1: Vec3, p2: Vec3) -> Vec3 {
    (p1 - p0).cross(p2 - p0)
}
