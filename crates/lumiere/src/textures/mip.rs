//! Mip-maps: each texture's chain of images halved down to one texel (Williams 1983), so that a
//! ray whose footprint covers many texels reads an image where one texel stands for them.
//!
//! A path tracer's bounces read textures at random: at full resolution each lookup is a cache miss,
//! and a footprint wider than a texel aliases. Read at the footprint's level, a bounce off a wall
//! reads an image of a few kilobytes.
//!
//! * **Halving.** Texel `(x, y)` of level `l + 1` is the mean, in linear RGB, of texels `2x, 2x + 1`
//!   by `2y, 2y + 1` of level `l`, wrapped (repeat, as the lookups wrap); a level is
//!   `⌈w/2⌉ × ⌈h/2⌉`, so an odd size's last column also averages the first. 8-bit images keep
//!   8-bit sRGB codes at every level: the code whose linear value is nearest the mean (in 16-bit
//!   fixed point, see `Encoding`).
//! * **Level.** A footprint `n` texels of level 0 across is read from level `⌊log₂ n⌋` (the last
//!   level beyond the chain), bilinearly: pbrt-v4's `bilinear` filter. Its `trilinear` filter,
//!   which blends that level with the next, was measured here to cost two cache misses for one at
//!   the camera's vertices, where a footprint of an eighth of a pixel falls between levels 0 and 1.

use glam::Vec3;
use rayon::prelude::*;

use super::level::{Level, Texels};

/// The halvings of `image`, down to a level of one texel (none for a single texel).
pub(super) fn halvings(image: &Level) -> Vec<Level> {
    let mut levels = Vec::new();
    loop {
        let last = levels.last().unwrap_or(image);
        if last.width == 1 && last.height == 1 {
            return levels;
        }
        let half = halve(last);
        levels.push(half);
    }
}

/// The next level of `level`: each texel the mean of a 2×2 block (see the module's comment).
fn halve(level: &Level) -> Level {
    let (width, height) = (level.width.div_ceil(2), level.height.div_ceil(2));
    let row_length = level.width as usize;
    // The storage indices of the 2×2 block under texel `(x, y)` of the half: column or row
    // `2i + 1` wraps to 0 past the last of an odd size.
    let second = |i: usize, n: u32| if 2 * i + 1 < n as usize { 2 * i + 1 } else { 0 };
    let block = |x: usize, y: usize| {
        let (x0, x1) = (2 * x, second(x, level.width));
        let (y0, y1) = (2 * y * row_length, second(y, level.height) * row_length);
        [y0 + x0, y0 + x1, y1 + x0, y1 + x1]
    };
    let rgb = match &level.rgb {
        Texels::Srgb8 { codes, table } => {
            let encoding = Encoding::of(table);
            Texels::Srgb8 {
                codes: by_rows(width, height, |x, y| {
                    let mut sums = [0u32; 3];
                    for i in block(x, y) {
                        for (sum, &code) in sums.iter_mut().zip(&codes[i][..3]) {
                            *sum += u32::from(encoding.linear[code as usize]);
                        }
                    }
                    let [r, g, b] = sums.map(|sum| encoding.code[((sum + 2) >> 2) as usize]);
                    [r, g, b, 0]
                }),
                table,
            }
        }
        Texels::Linear(rgb) => {
            Texels::Linear(by_rows(width, height, |x, y| block(x, y).iter().map(|&i| rgb[i]).sum::<Vec3>() * 0.25))
        }
    };
    Level { width, height, rgb }
}

/// A `width × height` image whose texel `(x, y)` is `texel(x, y)`, its rows computed in parallel.
fn by_rows<T: Copy + Default + Send>(width: u32, height: u32, texel: impl Fn(usize, usize) -> T + Sync) -> Vec<T> {
    let mut image = vec![T::default(); width as usize * height as usize];
    image.par_chunks_mut(width as usize).enumerate().for_each(|(y, row)| {
        for (x, value) in row.iter_mut().enumerate() {
            *value = texel(x, y);
        }
    });
    image
}

/// 8-bit codes to linear values in 16-bit fixed point and back, so that a mean of codes is a sum
/// and a shift, and its code one table lookup: a texture's mip chain is about a third as many
/// texels as its image, each the mean of four. Fixed point at 2⁻¹⁶ holds the closest two codes'
/// values (codes 0 and 1 of sRGB, 3e-4 apart) twenty steps apart.
struct Encoding {
    /// The linear value of each code, times 65535, rounded.
    linear: [u16; 256],
    /// For each fixed-point value, the code whose `linear` value is nearest (the lower of two).
    code: Vec<u8>,
}

impl Encoding {
    fn of(table: &[f32; 256]) -> Encoding {
        let linear = table.map(|value| (value.clamp(0.0, 1.0) * 65535.0).round() as u16);
        let mut code = Vec::with_capacity(1 << 16);
        let mut nearest = 0usize;
        for value in 0..=u16::MAX {
            // `linear` increases, so the nearest code never moves down as `value` grows.
            while nearest < 255 && linear[nearest + 1].abs_diff(value) < linear[nearest].abs_diff(value) {
                nearest += 1;
            }
            code.push(nearest as u8);
        }
        Encoding { linear, code }
    }
}

/// The level a footprint of `texels_squared` texels² of level 0 is read from: `⌊log₂ n⌋` for
/// `n = √texels_squared` texels across, which is the exponent of `texels_squared` halved (its
/// mantissa adds less than ½ to `log₂ n`); 0 below one texel (and for NaN), `u32::MAX` for an
/// infinite footprint. Integer arithmetic only: the same level on every machine.
#[inline]
pub(super) fn level_of_footprint(texels_squared: f32) -> u32 {
    if texels_squared.is_nan() || texels_squared < 1.0 {
        0
    } else if texels_squared == f32::INFINITY {
        u32::MAX
    } else {
        ((texels_squared.to_bits() >> 23) - 127) >> 1
    }
}

#[cfg(test)]
mod tests {
    use super::{Encoding, level_of_footprint};

    #[test]
    fn level_of_footprint_is_the_floor_of_log2_of_the_width() {
        for texels in [1.0f32, 1.5, 1.999, 2.0, 3.0, 4.0, 7.9, 8.0, 1000.0, 4096.0, 1e9, 3e38] {
            let squared = texels * texels;
            if squared.is_finite() {
                assert_eq!(level_of_footprint(squared), texels.log2().floor() as u32, "{texels}");
            }
        }
        assert_eq!(level_of_footprint(0.99), 0);
        assert_eq!(level_of_footprint(0.0), 0);
        assert_eq!(level_of_footprint(-5.0), 0);
        assert_eq!(level_of_footprint(f32::NAN), 0);
        assert_eq!(level_of_footprint(f32::INFINITY), u32::MAX);
        assert_eq!(level_of_footprint(f32::MAX), 63);
    }

    #[test]
    fn the_encoding_gives_each_code_back_and_the_nearest_code_of_a_mean() {
        let table = super::super::srgb_table();
        let encoding = Encoding::of(table);
        for code in 0..=255u8 {
            assert_eq!(encoding.code[encoding.linear[code as usize] as usize], code);
        }
        // Every fixed-point value gets the code a search of the whole table finds.
        for value in 0..=u16::MAX {
            let nearest = (0..256).min_by_key(|&c: &usize| (encoding.linear[c].abs_diff(value), c)).unwrap();
            assert_eq!(encoding.code[value as usize] as usize, nearest, "{value}");
        }
        // Black and white average to the code nearest a linear half: 188 (0.5029).
        let half = (u32::from(encoding.linear[0]) + u32::from(encoding.linear[255]) + 1) >> 1;
        assert_eq!(encoding.code[half as usize], 188);
    }
}
