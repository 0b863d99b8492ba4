use glam::Vec3;

/// A right-handed orthonormal basis: `x × y = z`.
///
/// Shading works in the local frame of a surface, where the normal is `+z`: warps such as
/// [`crate::sampling::warp::sample_cosine_hemisphere`] return directions there and `cos θ` is just
/// the `z` coordinate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub x: Vec3,
    pub y: Vec3,
    pub z: Vec3,
}

impl Frame {
    /// The frame with `z = n` for a unit normal `n`.
    ///
    /// Duff et al. 2017, "Building an Orthonormal Basis, Revisited" (JCGT 6(1)): the branchless
    /// form with `copysign`, which stays orthonormal for every unit normal, including `(0, 0, -1)`
    /// where Frisvad's original construction divides by zero. The tangents vary continuously except
    /// across the plane `z = 0`, which is irrelevant for sampling.
    #[inline]
    pub fn from_normal(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let x = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let y = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { x, y, z: n }
    }

    /// Coordinates of the world vector `v` in this frame.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    /// The world vector whose coordinates in this frame are `v`.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}
