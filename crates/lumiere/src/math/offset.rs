use glam::Vec3;

/// Moves a surface point `p` off its surface, to the side `n` points to, by an amount that scales
/// with the magnitude of `p`'s coordinates (a few ULPs), so that a ray leaving from the result does
/// not hit the surface it starts on, at any scene scale.
///
/// Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing Gems
/// ch. 6: the offset is applied to the integer representation of each coordinate, except near the
/// origin where float spacing is tiny and a small absolute offset is used instead.
#[inline(always)]
pub fn offset_ray_origin(p: Vec3, n: Vec3) -> Vec3 {
    const ORIGIN: f32 = 1.0 / 32.0;
    const FLOAT_SCALE: f32 = 1.0 / 65536.0;
    const INT_SCALE: f32 = 256.0;
    let offset_axis = |p: f32, n: f32| -> f32 {
        if p.abs() < ORIGIN {
            return p + FLOAT_SCALE * n;
        }
        let of_i = saturating_i32(INT_SCALE * n);
        let bits = p.to_bits() as i32;
        // Moving away from zero adds to the bit pattern, towards zero subtracts, whatever the sign of p.
        let moved = if p < 0.0 { bits.wrapping_sub(of_i) } else { bits.wrapping_add(of_i) };
        f32::from_bits(moved as u32)
    };
    Vec3::new(offset_axis(p.x, n.x), offset_axis(p.y, n.y), offset_axis(p.z, n.z))
}

/// `x as i32` (Rust's saturating conversion: NaN to 0, beyond the range to its nearest end) in
/// operations a lane loop vectorises. The compiler keeps `as` scalar, and every loop calling
/// `offset_ray_origin` over lanes (the path tracer's diffuse vertices) took its lanes out of the
/// vectors and back, seven instructions a lane and axis. Here the value is clamped (NaN to the low
/// end, by `max_ps`'s rule) into what truncation takes exactly, truncated, and the two cases the
/// clamp got wrong are put back.
#[inline(always)]
fn saturating_i32(x: f32) -> i32 {
    const LOW: f32 = -2_147_483_648.0; // -2^31, exactly i32::MIN
    const HIGH: f32 = 2_147_483_520.0; // the largest f32 below 2^31
    let clamped = if x > LOW { x } else { LOW };
    let clamped = if clamped < HIGH { clamped } else { HIGH };
    // SAFETY: `clamped` is finite and within [i32::MIN, 2^31), so its truncation is an i32.
    let truncated = unsafe { clamped.to_int_unchecked::<i32>() };
    let truncated = if x >= -LOW { i32::MAX } else { truncated };
    if x.is_nan() { 0 } else { truncated }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same answer as `as` for the values around every edge of the conversion and for a
    /// spread of bit patterns over the whole f32 range (NaNs, infinities and subnormals included).
    #[test]
    fn saturating_i32_is_rusts_conversion() {
        let edges = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            0.999_999_9,
            -0.999_999_9,
            1.0,
            -1.0,
            255.9,
            -255.9,
            256.0,
            -256.0,
            2_147_483_520.0,
            2_147_483_648.0,
            -2_147_483_648.0,
            -2_147_483_904.0,
            3e9,
            -3e9,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
            f32::MIN_POSITIVE,
            1e-45,
        ];
        for x in edges {
            assert_eq!(saturating_i32(x), x as i32, "{x:e}");
        }
        // Every 9,973rd bit pattern (a prime stride: every exponent, both signs, varied mantissas).
        for bits in (0..=u32::MAX).step_by(9_973) {
            let x = f32::from_bits(bits);
            assert_eq!(saturating_i32(x), x as i32, "{bits:#010x}");
        }
    }
}
