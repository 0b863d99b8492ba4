//! Ray cones: how wide a path's rays are where they hit, so that textures are read at the level of
//! detail of that footprint (Amanatides 1984; Akenine-Möller et al., "Texture Level of Detail
//! Strategies for Real-Time Ray Tracing", 2019).
//!
//! A cone starts at the camera's pinhole with the angle one camera sample stands for, and widens
//! linearly along each segment. At a specular vertex its angle is kept (flat triangles: no
//! curvature); at a vertex sampled from a lobe of density `p` it becomes at least the angle of a
//! cone whose solid angle is `1 / (p · n)`: the share of the lobe one of `n` samples stands for,
//! the "path differential" of a sampled direction (Suykens and Willems 2001).
//!
//! `n` is [`FOOTPRINT_SAMPLES`] for jittered camera samples and 1 for pixel centres, whatever the
//! number of samples per pixel: a render resumed with more samples must give the bytes of one
//! rendered with them from the start, so no footprint may depend on the count. With jittered
//! samples the image therefore converges to the textures filtered over a sixty-fourth of a pixel
//! (as pbrt-v4's differentials, scaled by at least 1/8) and, at bounces, over a sixty-fourth of
//! the lobe: a blur of the indirect light's texture that no eye can see, which makes the bounces'
//! lookups read a few kilobytes of texture instead of missing the cache.

/// Samples assumed to share a pixel, and a lobe, when the camera samples are jittered.
pub const FOOTPRINT_SAMPLES: f32 = 64.0;

/// The width of a path's cone and its angle (both 0: every texture at full resolution).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayCone {
    /// Width at the last vertex, in scene units.
    pub width: f32,
    /// Full angle, in radians, with which the width grows along the ray.
    spread: f32,
    /// `1 / sqrt(n)`: the angle's scale for `n` samples sharing a footprint.
    share: f32,
}

impl RayCone {
    /// The cone of a camera ray, whose pixel subtends `pixel_angle` radians: one of
    /// [`FOOTPRINT_SAMPLES`] samples of it when `jittered`, the whole pixel otherwise.
    pub fn camera(pixel_angle: f32, jittered: bool) -> RayCone {
        let share = if jittered { FOOTPRINT_SAMPLES.sqrt().recip() } else { 1.0 };
        RayCone { width: 0.0, spread: pixel_angle * share, share }
    }

    /// The width at distance `t` from the last vertex along the ray leaving it.
    #[inline]
    pub fn width_at(&self, t: f32) -> f32 {
        self.width + self.spread * t
    }

    /// Moves the last vertex to distance `t` along the ray: its width there.
    #[inline]
    pub fn advance(&mut self, t: f32) -> f32 {
        self.width = self.width_at(t);
        self.width
    }

    /// Widens the angle for a direction sampled with solid-angle density `pdf` (not for delta
    /// lobes, whose directions keep the cone): at least that of a cone of solid angle
    /// `1 / (pdf · n)`, `2 sqrt(1 / (π pdf n))` in the small-angle limit.
    #[inline]
    pub fn scatter(&mut self, pdf: f32) {
        let angle = 2.0 * self.share * (std::f32::consts::FRAC_1_PI / pdf).sqrt();
        // An infinite density gives 0 and keeps the angle; `max` also keeps it for a NaN.
        self.spread = self.spread.max(angle);
    }
}
