use glam::Vec3;

/// Axis-aligned box; the empty box has `min = +inf`, `max = -inf` so that growing it is branch free.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    pub fn from_points(points: &[Vec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.grow(p))
    }

    #[inline]
    pub fn grow(self, p: Vec3) -> Self {
        Aabb { min: self.min.min(p), max: self.max.max(p) }
    }

    #[inline]
    pub fn union(self, o: Aabb) -> Self {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    #[inline]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    #[inline]
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Half the surface area (all SAH costs are ratios, so the factor 2 is dropped); 0 when empty.
    /// In f64 so that scenes with huge coordinates do not overflow their costs.
    #[inline]
    pub fn half_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent().as_dvec3();
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// True if `inner` lies inside `self` (inclusive), used by the BVH validator.
    pub fn contains(&self, inner: &Aabb) -> bool {
        inner.is_empty() || (self.min.cmple(inner.min).all() && inner.max.cmple(self.max).all())
    }

    /// True if the two boxes share a point (inclusive), used by the BVH validator.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }
}
