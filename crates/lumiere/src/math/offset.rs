use glam::Vec3;

/// Moves a surface point `p` off its surface, to the side `n` points to, by an amount that scales
/// with the magnitude of `p`'s coordinates (a few ULPs), so that a ray leaving from the result does
/// not hit the surface it starts on, at any scene scale.
///
/// Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems
/// ch. 6: the offset is applied to the integer representation of each coordinate, except near the
/// origin where float spacing is tiny and a small absolute offset is used instead.
#[inline]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let offset_axis = |p: f32, n: f32| -> f32 {
        if p.abs() < ORIGIN {
            return p + FLOAT_SCALE * n;
        }
        let of_i = (INT_SCALE * n) as i32;
        let bits = p.to_bits() as i32;
        // Moving away from zero adds to the bit pattern, towards zero subtracts, whatever the sign of p.
        let moved = if p < 0.0 { bits.wrapping_sub(of_i) } else { bits.wrapping_add(of_i) };
        f32::from_bits(moved as u32)
    };
    Vec3::new(offset_axis(p.x, n.x), offset_axis(p.y, n.y), offset_axis(p.z, n.z))
}
