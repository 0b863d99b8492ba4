//! Accumulation of camera samples: per-pixel sums and second moments, filled in passes of one
//! sample per pixel, so that an image exists after the first pass and a render stopped after S
//! samples holds exactly the bits of one asked for S samples.
//!
//! A film keeps its samples in the smallest form that holds them exactly: nothing before the first
//! pass, the pass's own values after it (a one-pass render, the lab's modes, is the buffer its
//! workers wrote, with no addition and no copy), and f64 sums from the second pass on. Every form
//! reads as the same sums and second moments ([`Film::moments`]), so checkpoints, equality and the
//! image do not depend on which one a film is in.

use glam::Vec3;
use rayon::prelude::*;

use crate::error::{Error, Result, shown_bytes};
use crate::util::memory::try_zeroed_vec;

/// Bytes a pixel costs while rendering: the film (3 sums and a second moment in f64), the buffer a
/// pass renders into and the final image. Adding the second pass holds the first pass's values, the
/// pass buffer and the new sums: the same total.
pub const BYTES_PER_PIXEL: u64 = 4 * 8 + 3 * 4 + 3 * 4;

/// Pixels per parallel job when a pass is added: large enough that scheduling costs nothing, small
/// enough to share a 1024x768 film among many cores.
const CHUNK: usize = 1 << 13;

/// Linear RGB pixels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

#[derive(Clone, Debug)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    accumulated: Accumulated,
    /// Camera samples accumulated in every pixel.
    pub samples: u32,
    /// Samples that were NaN, infinite or negative and counted as 0 instead (should be 0).
    pub discarded: u64,
}

/// A film's samples, in the smallest form that holds them exactly.
#[derive(Clone, Debug)]
enum Accumulated {
    /// No pass yet: the image is black, and nothing is allocated.
    Nothing,
    /// One pass: each pixel's sample as kept ([`kept`]). That is exactly what the sums and second
    /// moments would hold after one addition to zero (`0 + x = x`; the second moment is the
    /// squared luminance), in 12 bytes a pixel instead of 32, and no second moment to compute
    /// unless something asks for it (a checkpoint). Nothing needs one before two samples exist.
    One(Vec<[f32; 3]>),
    /// Sums of sample radiance and of squared sample luminance (for the noise estimate), in f64:
    /// films of two passes or more, and films read from checkpoints (kept as stored, so that they
    /// encode back to the same bytes).
    Sums { sum: Vec<[f64; 3]>, sum_sq: Vec<f64> },
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

/// A sample as the film adds it, and whether it was valid: NaN, infinite or negative values (which
/// would poison or bias every later sum) count as 0. `+ 0.0` turns -0 into +0, the value the old
/// film's `0 + x` stored, so that a one-pass film holds exactly the bits of its sums.
#[inline]
fn kept(value: Vec3) -> (Vec3, bool) {
    let valid = value.is_finite() && value.min_element() >= 0.0;
    (if valid { value + Vec3::ZERO } else { Vec3::ZERO }, valid)
}

/// Two equal films hold the same sums, second moments and counts, whatever form each keeps them in.
impl PartialEq for Film {
    fn eq(&self, other: &Film) -> bool {
        (self.width, self.height, self.samples, self.discarded)
            == (other.width, other.height, other.samples, other.discarded)
            && self.moments().eq(other.moments())
    }
}

impl Film {
    /// An empty film, refused if its buffers would not fit in memory. It allocates nothing: the
    /// first pass's buffer becomes its storage.
    pub fn new(width: u32, height: u32) -> Result<Film> {
        if width == 0 || height == 0 {
            return Err(Error::invalid(format!("image size {width}x{height} has no pixels")));
        }
        check_memory(width, height, 0, "")?;
        Ok(Film { width, height, accumulated: Accumulated::Nothing, samples: 0, discarded: 0 })
    }

    /// A film of `samples` samples given as each pixel's sums and second moment, row by row (a
    /// checkpoint's); refused like [`Film::new`] before anything is read.
    pub(crate) fn from_moments(
        width: u32,
        height: u32,
        samples: u32,
        discarded: u64,
        moments: impl Iterator<Item = ([f64; 3], f64)>,
    ) -> Result<Film> {
        let mut film = Film::new(width, height)?;
        let (sum, sum_sq) = moments.take(film.pixel_count()).unzip();
        film.accumulated = Accumulated::Sums { sum, sum_sq };
        (film.samples, film.discarded) = (samples, discarded);
        Ok(film)
    }

    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Every pixel's radiance sums and luminance second moment, row by row: what a film of f64 sums
    /// added pass after pass holds, whatever form this one keeps them in.
    pub fn moments(&self) -> impl Iterator<Item = ([f64; 3], f64)> + '_ {
        (0..self.pixel_count()).map(|p| match &self.accumulated {
            Accumulated::Nothing => ([0.0; 3], 0.0),
            Accumulated::One(values) => {
                let y = luminance(Vec3::from(values[p]));
                (values[p].map(f64::from), y * y)
            }
            Accumulated::Sums { sum, sum_sq } => (sum[p], sum_sq[p]),
        })
    }

    /// The current estimate: the mean of every pixel's samples (black before the first pass).
    pub fn image(&self) -> Image {
        let pixels = match &self.accumulated {
            Accumulated::Nothing => vec![Vec3::ZERO; self.pixel_count()],
            // The mean of one sample is the sample: `(x as f64 * 1.0) as f32 == x`.
            Accumulated::One(values) => values.par_iter().map(|&v| Vec3::from(v)).collect(),
            Accumulated::Sums { sum, .. } => {
                let scale = if self.samples == 0 { 0.0 } else { 1.0 / self.samples as f64 };
                sum.par_iter().map(|s| Vec3::from(s.map(|c| (c * scale) as f32))).collect()
            }
        };
        Image { width: self.width, height: self.height, pixels }
    }

    /// Estimated relative standard error of the image: the root mean square over pixels of the
    /// standard error of each pixel's mean luminance, divided by the mean luminance. `None` until
    /// two samples exist; 0 for a black image. Summed in pixel order, so that a noise target stops
    /// every render of the same options at the same pass.
    pub fn relative_error(&self) -> Option<f64> {
        let n = self.samples as f64;
        if self.samples < 2 {
            return None;
        }
        let (mut variance_sum, mut mean_sum) = (0.0, 0.0);
        for (s, sq) in self.moments() {
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
        // Into the layout passes render in (one copy: these values come from elsewhere, and the
        // progressive loop's passes need none).
        let mut values: Vec<[f32; 3]> = pass.values.par_iter().map(|v| v.to_array()).collect();
        self.add_rendered(&mut values)
    }

    /// Adds the next pass, given as one sample per pixel, row by row, as rendered. The first pass
    /// is kept as it is: it is taken out of `values`, which is left empty (the caller allocates
    /// another buffer for the next pass). Later ones are added in parallel, each pixel's sums in
    /// pass order, so the bits do not depend on the thread count; `values` is left as it was.
    pub(crate) fn add_rendered(&mut self, values: &mut Vec<[f32; 3]>) -> Result<()> {
        debug_assert_eq!(values.len(), self.pixel_count());
        // Asked before anything is added: a film is whole passes or nothing. Only a forged
        // checkpoint gets here (no render asks for more passes than a u32 counts).
        let Some(samples) = self.samples.checked_add(1) else {
            return Err(Error::invalid(format!(
                "a film of {} samples per pixel cannot take another pass",
                self.samples
            )));
        };
        let discarded = match &mut self.accumulated {
            Accumulated::Nothing => {
                let discarded = values.par_chunks_mut(CHUNK).map(keep_in_place).sum();
                self.accumulated = Accumulated::One(std::mem::take(values));
                discarded
            }
            Accumulated::One(first) => {
                // Zeroed by the allocator (pages first touched below, in parallel), then set to the
                // first pass's sums, `0 + x = x`, before the second pass is added to them.
                let n = first.len();
                let (width, height) = (self.width, self.height);
                let sums = || out_of_memory(width, height, n * 32, "the film's sums");
                let mut sum = try_zeroed_vec(n).ok_or_else(sums)?;
                let mut sum_sq = try_zeroed_vec(n).ok_or_else(sums)?;
                let discarded = add_in_parallel(&mut sum, &mut sum_sq, values, Some(first));
                self.accumulated = Accumulated::Sums { sum, sum_sq };
                discarded
            }
            Accumulated::Sums { sum, sum_sq } => add_in_parallel(sum, sum_sq, values, None),
        };
        self.discarded = self.discarded.saturating_add(discarded);
        self.samples = samples;
        Ok(())
    }
}

/// Replaces each value by the one the film keeps; returns how many were invalid. Most values are
/// kept as they are, and are only read: each of their components is +0 or positive and finite,
/// which as bits is below +∞'s.
fn keep_in_place(values: &mut [[f32; 3]]) -> u64 {
    let mut discarded = 0;
    for value in values {
        if value.iter().any(|c| c.to_bits() >= f32::INFINITY.to_bits()) {
            let (v, valid) = kept(Vec3::from(*value));
            *value = v.to_array();
            discarded += u64::from(!valid);
        }
    }
    discarded
}

/// Adds `values` to the sums and second moments, in chunks of pixels on the rayon pool (each pixel
/// still gets one addition per pass, in pass order); returns how many values were invalid. With
/// `first` (a one-pass film's values, the sums being zero), adds those to each pixel first.
fn add_in_parallel(sum: &mut [[f64; 3]], sum_sq: &mut [f64], values: &[[f32; 3]], first: Option<&[[f32; 3]]>) -> u64 {
    let chunks = sum.par_chunks_mut(CHUNK).zip(sum_sq.par_chunks_mut(CHUNK)).zip(values.par_chunks(CHUNK));
    chunks
        .enumerate()
        .map(|(chunk, ((sum, sum_sq), values))| {
            let mut discarded = 0;
            for (p, ((s, sq), &value)) in sum.iter_mut().zip(sum_sq).zip(values).enumerate() {
                if let Some(first) = first {
                    add_sample(s, sq, first[chunk * CHUNK + p]);
                }
                discarded += u64::from(!add_sample(s, sq, value));
            }
            discarded
        })
        .sum()
}

/// Adds one sample to a pixel's sums as kept ([`kept`]); returns whether it was valid.
#[inline]
fn add_sample(s: &mut [f64; 3], sq: &mut f64, value: [f32; 3]) -> bool {
    let (v, valid) = kept(Vec3::from(value));
    s[0] += v.x as f64;
    s[1] += v.y as f64;
    s[2] += v.z as f64;
    let y = luminance(v);
    *sq += y * y;
    valid
}

/// The error of a render's buffer that the memory left cannot hold (more than the check before
/// rendering foresaw: other processes took memory meanwhile, or the scene's own did not count).
pub(crate) fn out_of_memory(width: u32, height: u32, bytes: usize, what: &str) -> Error {
    Error::invalid(format!(
        "image size {width}x{height}: out of memory for {what} ({}); render a smaller image, or free memory",
        shown_bytes(bytes as u64)
    ))
}

/// Refuses a render of `width` x `height` whose buffers cannot fit in the memory left, naming
/// what it needs: the film's [`BYTES_PER_PIXEL`], and `extra_per_pixel` more for what a front end
/// keeps beside it, which `extras` names for the message (" with its AOVs": their buffers and EXR
/// layers, or a checkpoint's encoding). Asked before rendering, so that a render that could not
/// write its outputs does not run first and then fail to allocate them.
pub fn check_memory(width: u32, height: u32, extra_per_pixel: u64, extras: &str) -> Result<()> {
    // In u128: width * height * bytes overflows u64 for the largest u32 sizes.
    let needed = width as u128 * height as u128 * (BYTES_PER_PIXEL + extra_per_pixel) as u128;
    let available = crate::util::read::available_memory().unwrap_or(64 << 30);
    if needed > available as u128 {
        return Err(Error::invalid(format!(
            "image size {width}x{height}{extras} needs {} of memory to render; {} is available",
            shown_bytes(needed),
            shown_bytes(available)
        )));
    }
    Ok(())
}
