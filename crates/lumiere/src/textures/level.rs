//! One image of a texture's mip chain (`mip.rs`): its texels, and where a texture coordinate falls
//! among them (the four texels of a bilinear lookup, with repeat wrapping).

use glam::{Vec2, Vec3};

use super::linear_to_srgb;

/// The colour of every texel: the 8-bit sRGB codes of most files, decoded through the table at
/// each lookup (the same `f32` values, in a third of the memory: path tracing reads texels at
/// random, and their cache misses were most of a textured scene's shading), or linear `f32` (16-bit
/// files, [`Texture::from_linear`]).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Texels {
    /// RGB codes and a padding byte, so that a texel is one aligned 4-byte load.
    Srgb8 {
        codes: Vec<[u8; 4]>,
        table: &'static [f32; 256],
    },
    Linear(Vec<Vec3>),
}

impl Texels {
    #[inline]
    pub(super) fn get(&self, i: usize) -> Vec3 {
        match self {
            Texels::Srgb8 { codes, table } => {
                let [r, g, b, _] = codes[i];
                Vec3::new(table[r as usize], table[g as usize], table[b as usize])
            }
            Texels::Linear(rgb) => rgb[i],
        }
    }

    /// Texel `i` read as a scalar (a coverage mask without an alpha channel): the luminance of the
    /// values the file stores, without sRGB decoding (a mask is not a colour). 8-bit codes are
    /// kept, over 255; 16-bit texels were decoded when loaded, and the encoding curve gives their
    /// file values back (to within rounding), so that a mask reads the same at either depth.
    #[inline]
    pub(super) fn scalar(&self, i: usize) -> f32 {
        let stored = match self {
            Texels::Srgb8 { codes, .. } => {
                let [r, g, b, _] = codes[i];
                Vec3::new(r.into(), g.into(), b.into()) / 255.0
            }
            Texels::Linear(rgb) => rgb[i].to_array().map(linear_to_srgb).into(),
        };
        stored.dot(Vec3::new(0.2126, 0.7152, 0.0722))
    }

    pub(super) fn memory_bytes(&self) -> usize {
        match self {
            Texels::Srgb8 { codes, .. } => codes.len() * 4,
            Texels::Linear(rgb) => rgb.len() * std::mem::size_of::<Vec3>(),
        }
    }
}

/// An image: `width × height` texels, row-major from the top row (as stored in the file).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Level {
    pub width: u32,
    pub height: u32,
    pub rgb: Texels,
}

impl Level {
    /// The bilinearly filtered colour at `uv` (OBJ convention: `v = 0` is the bottom row), with
    /// repeat wrapping.
    #[inline]
    pub(super) fn bilinear(&self, uv: Vec2) -> Vec3 {
        let [(i00, w00), (i10, w10), (i01, w01), (i11, w11)] = self.footprint(uv);
        let rgb = &self.rgb;
        rgb.get(i00) * w00 + rgb.get(i10) * w10 + rgb.get(i01) * w01 + rgb.get(i11) * w11
    }

    /// The four texels around `uv` and their bilinear weights (which sum to 1).
    #[inline]
    pub(super) fn footprint(&self, uv: Vec2) -> [(usize, f32); 4] {
        // Continuous texel coordinates, with texel centres at integers; rows from the top.
        let x = wrap_unit(uv.x) * self.width as f32 - 0.5;
        let y = (1.0 - wrap_unit(uv.y)) * self.height as f32 - 0.5;
        let (x0, y0) = (floor(x), floor(y));
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        [
            (self.index(x0, y0), (1.0 - fx) * (1.0 - fy)),
            (self.index(x0 + 1, y0), fx * (1.0 - fy)),
            (self.index(x0, y0 + 1), (1.0 - fx) * fy),
            (self.index(x0 + 1, y0 + 1), fx * fy),
        ]
    }

    /// The storage index of texel `(x, y)`, wrapped into the image.
    #[inline]
    pub(super) fn index(&self, x: i64, y: i64) -> usize {
        wrap_texel(y, self.height) * self.width as usize + wrap_texel(x, self.width)
    }
}

/// `i.rem_euclid(n)`. The footprint's texels lie in `-1 ..= n` (the coordinates come wrapped into
/// `[0, 1]`), which two comparisons wrap: the integer division was a quarter of the staircase's
/// render, eight of them per lookup.
#[inline]
fn wrap_texel(i: i64, n: u32) -> usize {
    let n = i64::from(n);
    let wrapped = if i < 0 {
        i + n
    } else if i >= n {
        i - n
    } else {
        i
    };
    if (0..n).contains(&wrapped) { wrapped as usize } else { i.rem_euclid(n) as usize }
}

/// `t.floor()` for a finite `t`, without the libm call it compiles to on x86-64's baseline (SSE2
/// has no rounding instruction): truncate, and step down for negative non-integers. Values of
/// magnitude `2^23` and above are integers already. The result's sign of zero may differ from
/// `floor`'s (`-0.0` gives `0.0`), which no use here can see.
#[inline]
fn floor(t: f32) -> f32 {
    if t.abs() >= 8_388_608.0 {
        return t;
    }
    let truncated = t as i32 as f32;
    if truncated > t { truncated - 1.0 } else { truncated }
}

/// `t` wrapped into `[0, 1]` (repeat); 0 for NaN and infinities. The result can be exactly 1 for
/// tiny negative `t` (`1 − 1e-9` rounds up), which the index wrapping handles.
#[inline]
fn wrap_unit(t: f32) -> f32 {
    if t.is_finite() { t - floor(t) } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::{floor, wrap_texel};

    #[test]
    fn floor_is_f32_floor() {
        let mut values = vec![0.0f32, -0.0, 0.5, -0.5, 1.0, -1.0, 2.999_999_8, -2.999_999_8, 1e-30, -1e-30];
        values.extend([8_388_607.5f32, -8_388_607.5, 8_388_608.0, -8_388_609.0, 1e30, -1e30, f32::MAX, f32::MIN]);
        values.extend((0..10_000).map(|i| (i as f32 - 5000.0) * 0.37));
        for t in values {
            assert_eq!(floor(t), t.floor(), "{t}");
        }
    }

    #[test]
    fn wrap_texel_is_rem_euclid() {
        for n in [1u32, 2, 3, 7, 1024] {
            for i in -3 * i64::from(n) - 2..3 * i64::from(n) + 2 {
                assert_eq!(wrap_texel(i, n), i.rem_euclid(i64::from(n)) as usize, "{i} mod {n}");
            }
        }
    }
}
