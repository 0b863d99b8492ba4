//! The point where a ray met a surface, with what shading needs and how rays leave it.

use glam::{Vec2, Vec3};

use crate::math::{Ray, offset_ray_origin};

/// What an integrator knows about a hit point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfacePoint {
    /// Position, interpolated from the vertices (more accurate than `origin + t * dir`).
    pub p: Vec3,
    /// Unit geometric normal, turned towards the side the ray came from. Decides which side a ray
    /// leaves on and whether a direction is on the side the shading normal says (no light leaks
    /// where the two disagree); ambient occlusion's hemisphere is built on it.
    pub ng: Vec3,
    /// Unit shading normal (interpolated vertex normals when the file has them, else `ng`), on
    /// `ng`'s side.
    pub ns: Vec3,
    /// Texture coordinates interpolated from the file's `vt` (zero when it has none).
    pub uv: Vec2,
    pub triangle: u32,
    /// Index of the triangle's material in the scene.
    pub material: u32,
    /// Whether the ray arrived on the side the triangle's winding faces (its front): `ng` and `ns`
    /// are turned towards the ray, so a transmissive material needs this to tell inside from
    /// outside.
    pub front_face: bool,
}

impl SurfacePoint {
    /// A ray from this point in direction `dir`, its origin moved off the surface a few ulps to
    /// the side `dir` leaves on (Wächter and Binder; pbrt's `SpawnRay`): no scene-scale epsilon,
    /// and no self-intersection on either side.
    #[inline]
    pub fn spawn_ray(&self, dir: Vec3) -> Ray {
        Ray::new(self.offset_origin(dir), dir)
    }

    /// The segment from this point (offset to the side of `target`) to `target`, ending exactly at
    /// `t = 1`: a shadow ray. Always inlined, as the offsets below: called from a lane loop (the
    /// path tracer's diffuse vertices) and left out of line, it kept the loop from vectorising.
    #[inline(always)]
    pub fn spawn_segment(&self, target: Vec3) -> Ray {
        Ray::segment(self.offset_origin(target - self.p), target)
    }

    /// The origin for rays leaving towards `dir`: `p` moved off the surface on `dir`'s side.
    #[inline(always)]
    pub fn offset_origin(&self, dir: Vec3) -> Vec3 {
        offset_origin(self.p, self.ng, dir)
    }
}

/// [`SurfacePoint::offset_origin`] of the point `p` with geometric normal `ng`, for callers that
/// keep points in rows rather than as `SurfacePoint`s.
#[inline(always)]
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let side = if ng.dot(dir) >= 0.0 { ng } else { -ng };
    offset_ray_origin(p, side)
}
