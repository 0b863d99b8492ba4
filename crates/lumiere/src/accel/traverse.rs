//! Closest-hit and occlusion queries: iterative, fixed stack, near child first.

use glam::Vec3;

use super::build::MAX_DEPTH;
use super::{Bvh, Node};
use crate::geometry::triangle::{WatertightRay, intersect_triangle};
use crate::math::Ray;

/// The closest intersection along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// The triangle's id in the scene (file order).
    pub triangle: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex.
    pub v: f32,
}

/// Slab test expansion that makes the f32 box test conservative: `1 + 2 * gamma(3)` (Ize, "Robust BVH
/// Ray Traversal", JCGT 2013), so a ray that hits a triangle never misses that triangle's box.
pub(super) const BOX_EXPANSION: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Slack on the "is this box closer than the best hit?" test. A box entry distance and a triangle's
/// `t` are rounded differently; without slack, a box whose triangle lies at exactly the best `t`
/// (a ray through a shared edge or vertex) could be pruned, and the lower-id tie-break would then
/// depend on the visiting order. About 32 ulps: it costs nothing measurable.
pub(super) const PRUNE_SLACK: f32 = 1.0 + 1.0 / (1 << 18) as f32;

/// `1 / d`, but a huge finite value instead of infinity for a zero direction component, so that
/// `(plane - origin) * inv_dir` is 0, not NaN, for an origin lying on a slab plane.
#[inline]
pub(super) fn safe_reciprocal(d: f32) -> f32 {
    if d.abs() < 1e-30 { 1e30f32.copysign(d) } else { 1.0 / d }
}

/// Ray constants for the box tests.
struct BoxRay {
    origin: Vec3,
    inv_dir: Vec3,
}

impl BoxRay {
    fn new(ray: &Ray) -> Self {
        BoxRay { origin: ray.origin, inv_dir: ray.dir.map(safe_reciprocal) }
    }

    /// Entry distance into `node`'s box if the ray meets it within `[0, tmax]`.
    #[inline(always)]
    fn enter(&self, node: &Node, tmax: f32) -> Option<f32> {
        let t0 = (Vec3::from_array(node.min) - self.origin) * self.inv_dir;
        let t1 = (Vec3::from_array(node.max) - self.origin) * self.inv_dir;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element() * BOX_EXPANSION;
        (near <= far && near <= tmax * PRUNE_SLACK).then_some(near)
    }
}

impl Bvh {
    /// The closest hit with `t` in `(0, ray.tmax]`. Of hits at exactly the same `t` (a ray through a
    /// shared edge), the lower triangle id wins, so the answer does not depend on the tree's shape.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if self.triangle_ids.is_empty() {
            return None;
        }
        let box_ray = BoxRay::new(ray);
        let tri_ray = WatertightRay::new(ray);
        let mut best: Option<Hit> = None;
        let mut tmax = ray.tmax;
        let mut stack = [0u32; MAX_DEPTH + 1];
        let mut sp = 0;
        let mut index = 0usize;
        box_ray.enter(&self.nodes[0], tmax)?;
        loop {
            let node = &self.nodes[index];
            if node.is_leaf() {
                for slot in node.first as usize..(node.first + node.count) as usize {
                    let [p0, p1, p2] = self.vertices[slot];
                    if let Some(h) = intersect_triangle(&tri_ray, tmax, p0, p1, p2) {
                        let id = self.triangle_ids[slot];
                        if best.is_none_or(|b| h.t < b.t || (h.t == b.t && id < b.triangle)) {
                            best = Some(Hit { t: h.t, triangle: id, u: h.u, v: h.v });
                            tmax = h.t;
                        }
                    }
                }
            } else {
                let first = node.first as usize;
                let near = box_ray.enter(&self.nodes[first], tmax);
                let far = box_ray.enter(&self.nodes[first + 1], tmax);
                match (near, far) {
                    (Some(a), Some(b)) => {
                        let (closer, farther) = if a <= b { (first, first + 1) } else { (first + 1, first) };
                        stack[sp] = farther as u32;
                        sp += 1;
                        index = closer;
                        continue;
                    }
                    (Some(_), None) => {
                        index = first;
                        continue;
                    }
                    (None, Some(_)) => {
                        index = first + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                return best;
            }
            sp -= 1;
            index = stack[sp] as usize;
        }
    }

    /// True if anything lies on the ray with `t` in `(0, ray.tmax]`; stops at the first hit found.
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.triangle_ids.is_empty() {
            return false;
        }
        let box_ray = BoxRay::new(ray);
        let tri_ray = WatertightRay::new(ray);
        let tmax = ray.tmax;
        let mut stack = [0u32; MAX_DEPTH + 1];
        let mut sp = 0;
        let mut index = 0usize;
        if box_ray.enter(&self.nodes[0], tmax).is_none() {
            return false;
        }
        loop {
            let node = &self.nodes[index];
            if node.is_leaf() {
                for slot in node.first as usize..(node.first + node.count) as usize {
                    let [p0, p1, p2] = self.vertices[slot];
                    if intersect_triangle(&tri_ray, tmax, p0, p1, p2).is_some() {
                        return true;
                    }
                }
            } else {
                let first = node.first as usize;
                let near = box_ray.enter(&self.nodes[first], tmax);
                let far = box_ray.enter(&self.nodes[first + 1], tmax);
                match (near, far) {
                    (Some(_), Some(_)) => {
                        stack[sp] = (first + 1) as u32;
                        sp += 1;
                        index = first;
                        continue;
                    }
                    (Some(_), None) => {
                        index = first;
                        continue;
                    }
                    (None, Some(_)) => {
                        index = first + 1;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            index = stack[sp] as usize;
        }
    }
}
