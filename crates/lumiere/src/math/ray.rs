use glam::Vec3;

/// A ray `origin + t * dir` for `t` in `[0, tmax]`.
///
/// `dir` need not be unit length: shadow rays use `dir = target - origin` with `tmax = 1`, so the
/// segment ends exactly at the target with no division or epsilon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tmax: f32,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Ray { origin, dir, tmax: f32::INFINITY }
    }

    /// The segment from `from` to `to`: `t = 1` is `to`.
    pub fn segment(from: Vec3, to: Vec3) -> Self {
        Ray { origin: from, dir: to - from, tmax: 1.0 }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}
