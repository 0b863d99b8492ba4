//! Discrete distributions: choosing one of `n` items (lights, by power) in proportion to a weight.

/// The outcome of sampling a discrete distribution: the chosen `index` and the probability `pmf`
/// with which it is chosen (a probability mass, not a density).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiscreteSample {
    pub index: usize,
    pub pmf: f32,
}

/// The largest `f32` below 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// One bin of the alias table: keep the bin's own item with probability `threshold`, otherwise
/// take `alias`.
#[derive(Clone, Copy, Debug)]
struct Bin {
    threshold: f32,
    alias: u32,
}

/// Walker's alias method, built with Vose's O(n) algorithm ("A linear algorithm for generating
/// random numbers with a given distribution", IEEE TSE 1991).
///
/// Sampling is O(1) from a single uniform number: its integer part (after scaling by `n`) picks a
/// bin, its fraction decides between the bin's item and its alias. Items of weight 0 get threshold
/// 0 and are never anyone's alias, so they are never returned.
///
/// The fraction left after picking a bin has `24 − log₂ n` bits of an `f32` sample, so tables of
/// more than about 2¹⁶ items quantise their probabilities; lights in our scenes are far fewer.
#[derive(Clone, Debug)]
pub struct AliasTable {
    bins: Vec<Bin>,
    pmf: Vec<f32>,
}

impl AliasTable {
    /// The table for probabilities proportional to `weights` (`f32` or `f64`).
    ///
    /// `None` when there is nothing to sample: no weights, all weights zero, or any weight negative
    /// or not finite. The build works in `f64` so that rounding cannot leave a zero-weight item
    /// with a non-zero threshold.
    pub fn new<W: Copy + Into<f64>>(weights: &[W]) -> Option<AliasTable> {
        let weights: Vec<f64> = weights.iter().map(|&w| w.into()).collect();
        if weights.iter().any(|w| !w.is_finite() || *w < 0.0) {
            return None;
        }
        let sum: f64 = weights.iter().sum();
        if !(sum > 0.0 && sum.is_finite()) || u32::try_from(weights.len()).is_err() {
            return None;
        }
        let pmf = weights.iter().map(|w| (w / sum) as f32).collect();
        Some(AliasTable { bins: vose(&weights, sum), pmf })
    }

    /// Picks an item from one uniform `u ∈ [0, 1)` in O(1).
    ///
    /// `u` = 1 (or above) is clamped into the last bin rather than read out of range.
    #[inline]
    pub fn sample(&self, u: f32) -> DiscreteSample {
        // Inlined, the unused remapped number (pure arithmetic) compiles away.
        self.sample_remapped(u).0
    }

    /// [`AliasTable::sample`] and the part of `u` the choice did not use, rescaled to a fresh
    /// uniform number in `[0, 1)`: within a bin, the values of `u` that pick one item form an
    /// interval, mapped linearly onto `[0, 1)`. Reusing it lets one stratified 2D point both choose
    /// an item and place a point on it (pbrt-v4's `SampleDiscrete` with `uRemapped`, Mitsuba's
    /// `sample_reuse`), where a number of its own for the choice would leave the two stratified
    /// apart only. The rescaled number keeps about `24 − log₂ n` bits of an `f32` sample's.
    #[inline]
    pub fn sample_remapped(&self, u: f32) -> (DiscreteSample, f32) {
        let n = self.bins.len();
        // `u` = 1 or above is read as the largest number below 1: the top of the last bin, where a
        // bin that keeps its own item always would otherwise remap it to 0 / 0. f64: `u · n` is
        // exact and stays below n for every f32 u < 1. Not `clamp`, which keeps a NaN: it reads as 0.
        #[allow(clippy::manual_clamp)]
        let scaled = f64::from(u.max(0.0).min(ONE_MINUS_EPSILON)) * n as f64;
        let bin = scaled as usize;
        let fraction = scaled - bin as f64;
        let Bin { threshold, alias } = self.bins[bin];
        let t = f64::from(threshold);
        let (index, remapped) = if (fraction as f32) < threshold {
            (bin, fraction / t)
        } else {
            (alias as usize, (fraction - t) / (1.0 - t))
        };
        // Rounding of the f32 test can put `fraction` a hair on the other side of `t`.
        (DiscreteSample { index, pmf: self.pmf[index] }, (remapped as f32).clamp(0.0, ONE_MINUS_EPSILON))
    }

    /// The probability of choosing `index` (its weight over the sum of weights).
    #[inline]
    pub fn pmf(&self, index: usize) -> f32 {
        self.pmf[index]
    }

    /// The number of items, zero-weight ones included.
    #[inline]
    pub fn len(&self) -> usize {
        self.bins.len()
    }

    /// Always false: a table without items cannot be built.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.bins.is_empty()
    }
}

/// Vose's construction: bins of the items with less than average weight are topped up by one item
/// with more, which then counts as under or over average itself, until every bin holds exactly
/// the average.
fn vose(weights: &[f64], sum: f64) -> Vec<Bin> {
    let n = weights.len();
    // Weight in units of the average, so every bin holds exactly 1.
    let mut scaled: Vec<f64> = weights.iter().map(|w| w * n as f64 / sum).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    let mut bins = vec![Bin { threshold: 1.0, alias: 0 }; n];
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        bins[s] = Bin { threshold: scaled[s] as f32, alias: l as u32 };
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What is left holds 1 up to rounding: the items keep their own bins. A zero-weight item cannot
    // be among them, since the leftovers' total equals their count within ~n·2⁻⁵² and each is < 1.
    for i in small.into_iter().chain(large) {
        bins[i] = Bin { threshold: 1.0, alias: i as u32 };
    }
    bins
}
