//! One emissive triangle as an area light.

use glam::Vec3;

use crate::geometry::triangle::{triangle_area, triangle_normal};
use crate::math::offset_ray_origin;
use crate::scene::Scene;

/// One emissive triangle. It emits `emission` (radiance) from the side its unit `normal` points to
/// (the winding `p0 -> p1 -> p2`), as gKit's and McGuire's boxes orient their lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaLight {
    pub triangle: u32,
    pub vertices: [Vec3; 3],
    /// The vertices moved a few ulps off the light's surface, to the emitting side (see
    /// `offset_ray_origin`). Shadow rays end on this triangle: every point of it lies in front of the
    /// light (a convex combination of points in front is in front), so a ray neither stops short of
    /// the light nor reports the light itself as its occluder, with no per-ray offset.
    pub shadow_targets: [Vec3; 3],
    pub normal: Vec3,
    pub area: f32,
    pub emission: Vec3,
}

impl AreaLight {
    pub fn centroid(&self) -> Vec3 {
        (self.vertices[0] + self.vertices[1] + self.vertices[2]) / 3.0
    }

    /// The point with barycentrics `b` on the shadow-target triangle (just in front of the light).
    #[inline]
    pub fn shadow_target(&self, b: Vec3) -> Vec3 {
        let [p0, p1, p2] = self.shadow_targets;
        b.x * p0 + b.y * p1 + b.z * p2
    }

    /// Where the lab's hard shadows end their segments: the centroid of the shadow-target triangle.
    #[inline]
    pub fn hard_shadow_target(&self) -> Vec3 {
        self.shadow_target(Vec3::splat(1.0 / 3.0))
    }

    /// Radiance leaving the light towards direction `w` (pointing away from the light): its
    /// emission on the side its winding faces, nothing behind.
    #[inline]
    pub fn radiance_towards(&self, w: Vec3) -> Vec3 {
        if self.normal.dot(w) > 0.0 { self.emission } else { Vec3::ZERO }
    }

    /// Radiant flux of a Lambertian emitter: `pi * L * A` per channel.
    pub fn power(&self) -> Vec3 {
        std::f32::consts::PI * self.area * self.emission
    }

    /// The light's weight in the power-proportional choice: its flux summed over the channels,
    /// the `f32` sum exactly, or, where that overflows (a huge but finite `Ke`), the same sum in
    /// `f64`, so that one bright light cannot leave the whole scene without a choice.
    pub fn power_weight(&self) -> f64 {
        let sum = self.power().element_sum();
        if sum.is_finite() {
            return f64::from(sum);
        }
        let [r, g, b] = self.emission.to_array().map(f64::from);
        std::f64::consts::PI * f64::from(self.area) * (r + g + b)
    }
}

/// Every emissive triangle of a scene, in triangle id order. Zero-area triangles are skipped: they
/// emit nothing and have no normal.
pub(super) fn collect_lights(scene: &Scene) -> Vec<AreaLight> {
    let mesh = &scene.mesh;
    (0..mesh.triangle_count())
        .filter_map(|id| {
            let emission = scene.material(id as u32).ke;
            if emission.max_element() <= 0.0 {
                return None;
            }
            let vertices = mesh.vertices(id);
            let [p0, p1, p2] = vertices;
            let area = triangle_area(p0, p1, p2);
            let normal = triangle_normal(p0, p1, p2).try_normalize()?;
            let shadow_targets = vertices.map(|v| offset_ray_origin(v, normal));
            // An area that overflows (corners near f32's limits) could not be sampled.
            (area > 0.0 && area.is_finite()).then_some(AreaLight {
                triangle: id as u32,
                vertices,
                shadow_targets,
                normal,
                area,
                emission,
            })
        })
        .collect()
}
