//! A scene with its acceleration structure: what integrators trace against.

use glam::Vec3;

use crate::accel::{BuildPreset, Bvh4, Hit, Isa};
use crate::math::Ray;
use crate::scene::Scene;
use crate::scene::mesh::NO_INDEX;

pub struct World {
    pub scene: Scene,
    /// The 4-wide BVH; the binary tree it was collapsed from is dropped to save memory.
    pub bvh: Bvh4,
    /// The instruction set, detected once here; the accel above was chosen from it.
    pub isa: Isa,
}

/// What an integrator needs to know about a hit point.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// Position, interpolated from the vertices (more accurate than `origin + t * dir`).
    pub p: Vec3,
    /// Unit geometric normal, turned towards the side the ray came from.
    pub ng: Vec3,
    /// Unit shading normal (interpolated vertex normals when the file has them, else `ng`), on `ng`'s side.
    pub ns: Vec3,
    pub triangle: u32,
}

impl World {
    pub fn new(scene: Scene, preset: BuildPreset) -> World {
        let isa = Isa::detect();
        // The one place the accel is chosen by ISA. The 4-wide SSE kernel is the only one so far, and
        // SSE is the x86-64 baseline (the portable kernel stands in elsewhere), so every ISA gets it.
        let bvh = match isa {
            Isa::Portable | Isa::Sse2 | Isa::Avx2 | Isa::Avx512 => {
                Bvh4::build(&scene.mesh.positions, &scene.mesh.indices, preset)
            }
        };
        World { scene, bvh, isa }
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.bvh.intersect(ray)
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.bvh.occluded(ray)
    }

    pub fn surface(&self, ray: &Ray, hit: &Hit) -> SurfacePoint {
        let mesh = &self.scene.mesh;
        let id = hit.triangle as usize;
        let [p0, p1, p2] = mesh.vertices(id);
        let w = 1.0 - hit.u - hit.v;
        let p = w * p0 + hit.u * p1 + hit.v * p2;
        let geometric = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let ng = if geometric.dot(ray.dir) > 0.0 { -geometric } else { geometric };
        let ns = self.interpolated_normal(id, w, hit.u, hit.v).map_or(ng, |n| if n.dot(ng) < 0.0 { -n } else { n });
        SurfacePoint { p, ng, ns, triangle: hit.triangle }
    }

    fn interpolated_normal(&self, id: usize, w: f32, u: f32, v: f32) -> Option<Vec3> {
        let mesh = &self.scene.mesh;
        let [a, b, c] = *mesh.normal_indices.get(id)?;
        if a == NO_INDEX || b == NO_INDEX || c == NO_INDEX {
            return None;
        }
        let n = w * mesh.normals[a as usize] + u * mesh.normals[b as usize] + v * mesh.normals[c as usize];
        n.try_normalize()
    }
}
