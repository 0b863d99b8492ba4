//! Closest-hit and occlusion queries on the binary BVH: iterative, fixed stack, near child first,
//! one scalar box and one scalar watertight triangle test at a time. The reference every wide
//! kernel is checked against (by the tests and by `lumiere bench-bvh` as it measures).

use glam::Vec3;

use super::build::MAX_DEPTH;
use super::{Bvh, Node};
use crate::accel::Hit;
use crate::accel::slab::{BOX_EXPANSION, PRUNE_SLACK, safe_reciprocal};
use crate::geometry::triangle::{WatertightRay, intersect_triangle};
use crate::math::Ray;

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
                        if best.is_none_or(|b| Hit::precedes(h.t, id, b.t, b.triangle)) {
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
