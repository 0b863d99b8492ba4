//! Accumulation of camera samples: per-pixel sums and second moments, filled in passes of one
//! sample per pixel, so that an image exists after the first pass and a render stopped after S
//! samples holds exactly the bits of one asked for S samples.

use glam::Vec3;

use crate::error::{Error, Result};

/// Bytes a pixel costs while rendering: the film (3 sums and a second moment in f64), the tile's
/// pass buffer and the final image.
pub const BYTES_PER_PIXEL: u64 = 4 * 8 + 4 * 8 + 3 * 4;

/// Linear RGB pixels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Sum of sample radiance per pixel.
    pub(crate) sum: Vec<[f64; 3]>,
    /// Sum of squared sample luminance per pixel (for the noise estimate).
    pub(crate) sum_sq: Vec<f64>,
    /// Camera samples accumulated in every pixel.
    pub samples: u32,
    /// Samples that were NaN, infinite or negative and counted as 0 instead (should be 0).
    pub discarded: u64,
}

/// The camera samples of one pass, as rendered: one value per pixel, row 0 at the top, before the
/// film replaces invalid values (NaN, infinite, negative) by 0. Twelve bytes a pixel: the least a
/// pass can be shipped as and still be added exactly (see [`Film::add_pass`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PassSamples {
    /// The camera sample index of the pass (0 for the first).
    pub sample: u32,
    pub width: u32,
    pub height: u32,
    pub values: Vec<Vec3>,
    /// Rays traced for this pass (camera rays and visibility queries).
    pub rays: u64,
}

/// Rec. 709 luminance, the quantity whose noise the budgets measure.
#[inline]
pub fn luminance(c: Vec3) -> f64 {
    (0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z) as f64
}

impl Film {
    /// An empty film, refused (before allocating) if its buffers would not fit in memory.
    pub fn new(width: u32, height: u32) -> Result<Film> {
        if width == 0 || height == 0 {
            return Err(Error::invalid(format!("image size {width}x{height} has no pixels")));
        }
        check_memory(width, height)?;
        let pixels = width as usize * height as usize;
        Ok(Film { width, height, sum: vec![[0.0; 3]; pixels], sum_sq: vec![0.0; pixels], samples: 0, discarded: 0 })
    }

    pub fn pixel_count(&self) -> usize {
        self.sum.len()
    }

    /// The current estimate: the mean of every pixel's samples (black before the first pass).
    pub fn image(&self) -> Image {
        let scale = if self.samples == 0 { 0.0 } else { 1.0 / self.samples as f64 };
        let pixels =
            self.sum.iter().map(|s| Vec3::new((s[0] * scale) as f32, (s[1] * scale) as f32, (s[2] * scale) as f32));
        Image { width: self.width, height: self.height, pixels: pixels.collect() }
    }

    /// Estimated relative standard error of the image: the root mean square over pixels of the
    /// standard error of each pixel's mean luminance, divided by the mean luminance. `None` until
    /// two samples exist; 0 for a black image.
    pub fn relative_error(&self) -> Option<f64> {
        let n = self.samples as f64;
        if self.samples < 2 {
            return None;
        }
        let (mut variance_sum, mut mean_sum) = (0.0, 0.0);
        for (s, &sq) in self.sum.iter().zip(&self.sum_sq) {
            let mean = (0.2126 * s[0] + 0.7152 * s[1] + 0.0722 * s[2]) / n;
            // Variance of the mean from the sample second moment, clamped against rounding below 0.
            variance_sum += ((sq / n - mean * mean) / (n - 1.0)).max(0.0);
            mean_sum += mean;
        }
        let pixels = self.pixel_count() as f64;
        let mean = mean_sum / pixels;
        Some(if mean > 0.0 { (variance_sum / pixels).sqrt() / mean } else { 0.0 })
    }

    /// Adds the samples of pass `pass.sample`, which must be the next one (`self.samples`): the
    /// same additions, in the same order per pixel, as the progressive loop makes, so a film built
    /// from passes rendered apart (other threads, processes or machines) holds the same bits as one
    /// rendered in one go. Summing per-range films instead would not: floating-point addition is
    /// not associative, so `(s + a) + b` and `s + (a + b)` may differ in the last bit.
    pub fn add_pass(&mut self, pass: &PassSamples) -> Result<()> {
        if (pass.width, pass.height) != (self.width, self.height) || pass.values.len() != self.pixel_count() {
            return Err(Error::invalid(format!(
                "pass {} is {}x{} with {} values but the film is {}x{}",
                pass.sample,
                pass.width,
                pass.height,
                pass.values.len(),
                self.width,
                self.height
            )));
        }
        if pass.sample != self.samples {
            return Err(Error::invalid(format!(
                "pass {} cannot be added to a film of {} samples: passes are added in order",
                pass.sample, self.samples
            )));
        }
        self.add_tile(0, 0, self.width, &pass.values);
        self.samples += 1;
        Ok(())
    }

    /// Adds one sample per pixel, given row by row for the rectangle starting at `(x0, y0)`.
    pub(crate) fn add_tile(&mut self, x0: u32, y0: u32, width: u32, values: &[Vec3]) {
        for (i, value) in values.iter().enumerate() {
            let (x, y) = (x0 + i as u32 % width, y0 + i as u32 / width);
            let p = y as usize * self.width as usize + x as usize;
            let valid = value.is_finite() && value.min_element() >= 0.0;
            let v = if valid { *value } else { Vec3::ZERO };
            self.discarded += u64::from(!valid);
            let s = &mut self.sum[p];
            s[0] += v.x as f64;
            s[1] += v.y as f64;
            s[2] += v.z as f64;
            let y = luminance(v);
            self.sum_sq[p] += y * y;
        }
    }
}

/// Refuses sizes whose buffers cannot fit, naming the memory they need.
fn check_memory(width: u32, height: u32) -> Result<()> {
    // In u128: width * height * bytes overflows u64 for the largest u32 sizes.
    let needed = width as u128 * height as u128 * BYTES_PER_PIXEL as u128;
    let available = crate::util::read::available_memory().unwrap_or(64 << 30);
    if needed > available as u128 {
        return Err(Error::invalid(format!(
            "image size {width}x{height} needs {:.1} GiB of memory to render; {:.1} GiB is available",
            needed as f64 / (1u64 << 30) as f64,
            available as f64 / (1u64 << 30) as f64
        )));
    }
    Ok(())
}
