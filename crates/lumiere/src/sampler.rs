//! Deterministic random numbers for rendering: pure functions of (pixel, sample index, dimension,
//! seed), so no state is shared between threads and a render is bit-identical for any thread count
//! or tile order, and any pixel can be replayed alone.
//!
//! The integrator numbers the random quantities of one path sample (`dimension` 0 for the lens or
//! pixel position, 1 for the first bounce, ...). [`Sampler::get_1d`] and [`Sampler::get_2d`] share
//! that numbering: a 1D dimension is the first coordinate of the 2D pair of the same number.

use glam::Vec2;

use crate::util::hash::mix64;

/// Which sequence a [`Sampler`] draws from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum SamplerKind {
    /// Independent uniform numbers from an integer hash: unbiased, no structure, error ~ 1/√n.
    #[default]
    Independent,
    /// Owen-scrambled Sobol points: every power-of-two prefix of a pixel's samples is stratified,
    /// which converges faster on smooth integrands and is never worse than independent sampling.
    Sobol,
}

/// A source of uniform numbers in `[0, 1)` addressed by (pixel, sample index, dimension).
///
/// `pixel` is `y · width + x`, `index` the sample's number within its pixel, `dimension` the
/// integrator's number for the random quantity. Values have 24 random bits, so they are exact
/// multiples of 2⁻²⁴ and never 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sampler {
    pub kind: SamplerKind,
    /// The hash of the seed that every number of this sampler starts from, computed once here
    /// rather than once per number.
    key: u64,
}

impl Sampler {
    /// A sampler of `kind` whose whole stream is fixed by `seed`.
    pub fn new(kind: SamplerKind, seed: u64) -> Sampler {
        let salt = match kind {
            SamplerKind::Independent => 0x5EED_1DE9_E4DE_4E47,
            SamplerKind::Sobol => 0x50B0_15C4_A3B1_ED00,
        };
        Sampler { kind, key: mix64(seed ^ salt) }
    }

    /// One uniform number in `[0, 1)`.
    #[inline]
    pub fn get_1d(&self, pixel: u32, index: u32, dimension: u32) -> f32 {
        match self.kind {
            SamplerKind::Independent => unit_f32((self.independent_bits(pixel, index, dimension) >> 32) as u32),
            SamplerKind::Sobol => {
                let seeds = SobolSeeds::new(self.key, pixel, dimension);
                let i = shuffle(index, seeds.shuffle);
                unit_f32(scrambled_digits(i, seeds.x))
            }
        }
    }

    /// A uniform point in `[0, 1)²`; its `x` equals `get_1d` of the same arguments.
    #[inline]
    pub fn get_2d(&self, pixel: u32, index: u32, dimension: u32) -> Vec2 {
        match self.kind {
            SamplerKind::Independent => {
                let bits = self.independent_bits(pixel, index, dimension);
                Vec2::new(unit_f32((bits >> 32) as u32), unit_f32((bits << 24 >> 32) as u32))
            }
            SamplerKind::Sobol => {
                let seeds = SobolSeeds::new(self.key, pixel, dimension);
                let i = shuffle(index, seeds.shuffle);
                let x = scrambled_digits(i, seeds.x);
                let y = scrambled_digits(sobol_second_digits(i), seeds.y);
                Vec2::new(unit_f32(x), unit_f32(y))
            }
        }
    }

    /// 64 hashed bits for one (pixel, index, dimension); two 24-bit numbers come from the top 48.
    /// The index is mixed into the key of its (pixel, dimension), so a set of points in one
    /// dimension (a pixel's N light points or directions) costs one finaliser per point, its key
    /// hashed once (see [`PointSet::get_2d_lanes`]): the 64-bit multiplies of a second finaliser
    /// were a tenth of a soft-shadow render at N = 256.
    #[inline]
    fn independent_bits(&self, pixel: u32, index: u32, dimension: u32) -> u64 {
        independent_bits_in(self.independent_key(pixel, dimension), index)
    }

    /// The key of the independent numbers of one (pixel, dimension): a random 64-bit value. Two
    /// (pixel, dimension) pairs feed the finaliser a common input only if their keys agree in the
    /// top 32 bits, which the index never reaches (a chance of 2⁻³² per pair).
    #[inline]
    fn independent_key(&self, pixel: u32, dimension: u32) -> u64 {
        mix64(self.key ^ (u64::from(pixel) << 32 | u64::from(dimension)))
    }
}

/// The random numbers of one camera sample, drawn dimension after dimension: each call to
/// [`SampleStream::next_points`] (or `next_1d`/`next_2d`) takes the next dimension, so a path draws
/// as many as it needs (pixel position first, then whatever each bounce asks for) and stays a pure
/// function of (pixel, sample, seed): the same numbers for any thread count or tile order.
#[derive(Clone, Copy, Debug)]
pub struct SampleStream<'a> {
    sampler: &'a Sampler,
    pixel: u32,
    sample: u32,
    dimension: u32,
}

impl<'a> SampleStream<'a> {
    /// The stream of camera sample `sample` (0-based) of pixel `pixel` (`y · width + x`).
    pub fn new(sampler: &'a Sampler, pixel: u32, sample: u32) -> Self {
        SampleStream { sampler, pixel, sample, dimension: 0 }
    }

    /// The next dimension as a set of `n` points for this camera sample, e.g. the N shadow rays of
    /// one light. Consecutive camera samples own consecutive blocks of `n` indices, so a stratified
    /// sampler stratifies across all the camera samples of a pixel, not just within one.
    #[inline]
    pub fn next_points(&mut self, n: u32) -> PointSet<'a> {
        let dimension = self.dimension;
        self.dimension += 1;
        PointSet { sampler: self.sampler, pixel: self.pixel, dimension, first: self.sample.wrapping_mul(n) }
    }

    /// One number from the next dimension.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        self.next_points(1).get_1d(0)
    }

    /// One 2D point from the next dimension.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        self.next_points(1).get_2d(0)
    }
}

/// The streams of `N` camera samples of one sampler that draw in lockstep, dimension after
/// dimension (the paths of a block, traced together): the numbers of their [`SampleStream`]s,
/// computed for all lanes at once in loops the compiler can vectorise. Drawn one lane at a time,
/// a path vertex's hashes were 8% of a path-traced Cornell box.
#[derive(Clone, Copy, Debug)]
pub struct LaneStreams<'a, const N: usize> {
    sampler: &'a Sampler,
    pixel: [u32; N],
    sample: [u32; N],
    dimension: u32,
}

impl<'a, const N: usize> LaneStreams<'a, N> {
    /// The lanes of `streams`, which must share their sampler and their next dimension.
    ///
    /// # Panics
    /// If they do not.
    pub fn new(streams: &[SampleStream<'a>; N]) -> Self {
        let first = &streams[0];
        assert!(
            streams.iter().all(|s| std::ptr::eq(s.sampler, first.sampler) && s.dimension == first.dimension),
            "streams drawn in lockstep share a sampler and a dimension"
        );
        LaneStreams {
            sampler: first.sampler,
            pixel: streams.map(|s| s.pixel),
            sample: streams.map(|s| s.sample),
            dimension: first.dimension,
        }
    }

    /// [`SampleStream::next_2d`] of every lane.
    #[inline(always)]
    pub fn next_2d(&mut self) -> [Vec2; N] {
        let (dimension, sampler) = (self.dimension, self.sampler);
        self.dimension += 1;
        // The first point of a one-point set has the sample's own index.
        let (mut x, mut y) = ([0u32; N], [0u32; N]);
        match sampler.kind {
            SamplerKind::Independent => {
                for lane in 0..N {
                    let bits = sampler.independent_bits(self.pixel[lane], self.sample[lane], dimension);
                    (x[lane], y[lane]) = ((bits >> 32) as u32, (bits << 24 >> 32) as u32);
                }
            }
            SamplerKind::Sobol => {
                for lane in 0..N {
                    let seeds = SobolSeeds::new(sampler.key, self.pixel[lane], dimension);
                    let i = shuffle(self.sample[lane], seeds.shuffle);
                    x[lane] = scrambled_digits(i, seeds.x);
                    y[lane] = scrambled_digits(sobol_second_digits(i), seeds.y);
                }
            }
        }
        std::array::from_fn(|lane| Vec2::new(unit_f32(x[lane]), unit_f32(y[lane])))
    }

    /// [`SampleStream::next_1d`] of every lane: the first coordinates of `next_2d`, without the
    /// second's hashes.
    #[inline(always)]
    pub fn next_1d(&mut self) -> [f32; N] {
        let (dimension, sampler) = (self.dimension, self.sampler);
        self.dimension += 1;
        let mut x = [0u32; N];
        match sampler.kind {
            SamplerKind::Independent => {
                for (lane, x) in x.iter_mut().enumerate() {
                    *x = (sampler.independent_bits(self.pixel[lane], self.sample[lane], dimension) >> 32) as u32;
                }
            }
            SamplerKind::Sobol => {
                for (lane, x) in x.iter_mut().enumerate() {
                    let seeds = SobolSeeds::new(sampler.key, self.pixel[lane], dimension);
                    *x = scrambled_digits(shuffle(self.sample[lane], seeds.shuffle), seeds.x);
                }
            }
        }
        x.map(unit_f32)
    }
}

/// `n` points of one dimension of one camera sample (see [`SampleStream::next_points`]); nothing is
/// computed until a point is asked for.
#[derive(Clone, Copy, Debug)]
pub struct PointSet<'a> {
    sampler: &'a Sampler,
    pixel: u32,
    dimension: u32,
    first: u32,
}

impl PointSet<'_> {
    /// Point `k` of the set, in `[0, 1)`.
    #[inline]
    pub fn get_1d(&self, k: u32) -> f32 {
        self.sampler.get_1d(self.pixel, self.first.wrapping_add(k), self.dimension)
    }

    /// Point `k` of the set, in `[0, 1)²`.
    #[inline]
    pub fn get_2d(&self, k: u32) -> Vec2 {
        self.sampler.get_2d(self.pixel, self.first.wrapping_add(k), self.dimension)
    }

    /// Points `first .. first + N` of the set: exactly the numbers of [`PointSet::get_2d`], with
    /// the sampler's kind and Sobol's per-dimension seeds decided once instead of per point, in
    /// loops the compiler can vectorise (for the ray-major batches, which draw 32 or 16 points at
    /// once: `WIDE_GROUP`, `NARROW_GROUP`).
    #[inline(always)]
    pub fn get_2d_lanes<const N: usize>(&self, first: u32) -> [Vec2; N] {
        let [xs, ys] = self.get_2d_rows::<N>(first);
        let mut points = [Vec2::ZERO; N];
        for (lane, point) in points.iter_mut().enumerate() {
            *point = Vec2::new(xs[lane], ys[lane]);
        }
        points
    }

    /// [`PointSet::get_2d_lanes`] as two rows, the points' first coordinates and their second:
    /// for lane loops that change one coordinate, which stay scalar on interleaved `Vec2`s.
    #[inline(always)]
    pub fn get_2d_rows<const N: usize>(&self, first: u32) -> [[f32; N]; 2] {
        let sampler = self.sampler;
        let base = self.first.wrapping_add(first);
        let (mut xs, mut ys) = ([0.0; N], [0.0; N]);
        match sampler.kind {
            SamplerKind::Independent => {
                let key = sampler.independent_key(self.pixel, self.dimension);
                for lane in 0..N {
                    let bits = independent_bits_in(key, base.wrapping_add(lane as u32));
                    (xs[lane], ys[lane]) = (unit_f32((bits >> 32) as u32), unit_f32((bits << 24 >> 32) as u32));
                }
            }
            SamplerKind::Sobol => {
                let seeds = SobolSeeds::new(sampler.key, self.pixel, self.dimension);
                for lane in 0..N {
                    let i = shuffle(base.wrapping_add(lane as u32), seeds.shuffle);
                    xs[lane] = unit_f32(scrambled_digits(i, seeds.x));
                    ys[lane] = unit_f32(scrambled_digits(sobol_second_digits(i), seeds.y));
                }
            }
        }
        [xs, ys]
    }
}

/// The three scrambling seeds of one (seed, pixel, dimension): one shuffles the sample order, one
/// scrambles each axis. Different pixels and dimensions thus get independent randomisations of
/// the same (0, 2)-sequence, which decorrelates them.
struct SobolSeeds {
    shuffle: u32,
    x: u32,
    y: u32,
}

impl SobolSeeds {
    #[inline]
    fn new(key: u64, pixel: u32, dimension: u32) -> SobolSeeds {
        let h = mix64(key ^ (u64::from(pixel) << 32 | u64::from(dimension)));
        SobolSeeds { shuffle: h as u32, x: (h >> 32) as u32, y: mix64(h) as u32 }
    }
}

/// The bits of sample `index` under the key of its (pixel, dimension).
#[inline]
fn independent_bits_in(key: u64, index: u32) -> u64 {
    mix64(key ^ u64::from(index))
}

/// The top 24 bits of `bits` as a float in `[0, 1)`; 24 bits are all an `f32` below 1 can hold
/// uniformly, and dropping the rest keeps the result away from rounding up to 1.
#[inline]
fn unit_f32(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The sample index, Owen-scrambled as if it were a number `0.b₀b₁b₂…` (Burley 2020, §4): the
/// first 2ᵏ shuffled indices are a permutation of one aligned block of 2ᵏ Sobol indices, and every
/// such block of a (0, 2)-sequence is a (0, k, 2)-net, so stratification survives the shuffle
/// while each pixel visits the points in its own order.
#[inline]
fn shuffle(index: u32, seed: u32) -> u32 {
    owen_scramble(index, seed)
}

/// Both Sobol dimensions are kept as their *digit vectors*: bit `d` of the word holds the `d`-th
/// binary digit after the point (the first dimension's digits are the index's bits: van der
/// Corput). Owen scrambling works on that reversed form anyway (see [`owen_scramble`]), so a
/// point costs one bit reversal at the end instead of three.
///
/// Scrambles the digit vector `digits` with `seed` and returns the point as a 0.32 fixed-point
/// number: `owen_scramble(digits.reverse_bits(), seed)`, without reversing twice.
#[inline]
fn scrambled_digits(digits: u32, seed: u32) -> u32 {
    laine_karras(digits, seed).reverse_bits()
}

/// The digit vector of the second Sobol dimension for `index`. Its generator matrix is Pascal's
/// triangle mod 2 (primitive polynomial `x + 1`, `m₁ = 1`): digit `d` is the XOR of the index bits
/// `k` with `C(k, d)` odd, and by Lucas's theorem `C(k, d)` is odd exactly when the bits of `d` are
/// a subset of those of `k`. So the digits are the superset XOR-transform of the index bits over
/// the five bits of a position: five shift-and-mask steps (Yates's fast zeta transform) instead of
/// one XOR per set bit of the shuffled index (~16 of them). With the other shortcuts here, that took
/// the sampler's share of a Sobol path-tracing profile from 18% to 10%.
#[inline]
fn sobol_second_digits(index: u32) -> u32 {
    let mut v = index;
    v ^= (v >> 1) & 0x5555_5555;
    v ^= (v >> 2) & 0x3333_3333;
    v ^= (v >> 4) & 0x0F0F_0F0F;
    v ^= (v >> 8) & 0x00FF_00FF;
    v ^= v >> 16;
    v
}

/// Nested uniform (Owen) scrambling of a 0.32 fixed-point number, by a hash.
///
/// Burley 2020, "Practical Hash-based Owen Scrambling" (JCGT 9(4)), after Laine and Karras 2011:
/// with the bits reversed, a hash in which each bit is flipped by a function of the seed and the
/// *less* significant bits only — adding the seed, xor-ing in multiples by even constants — flips
/// each digit of the number by a random function of the digits before it, which is exactly an Owen
/// scramble. The constants are those the paper found to randomise well.
#[inline]
fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// The hash of [`owen_scramble`] on the bit-reversed number: each bit flipped by a function of
/// the seed and the less significant bits.
#[inline]
fn laine_karras(mut v: u32, seed: u32) -> u32 {
    v = v.wrapping_add(seed);
    v ^= v.wrapping_mul(0x6C50_B47C);
    v ^= v.wrapping_mul(0xB82F_1E52);
    v ^= v.wrapping_mul(0xC7AF_E638);
    v ^ v.wrapping_mul(0x8D22_F6E6)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lane version hands out exactly the points of the one-at-a-time version, for both kinds,
    /// any start and any set (the ray-major batches rely on it for their bytes).
    #[test]
    fn points_in_lanes_are_the_points_one_at_a_time() {
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            let sampler = Sampler::new(kind, 42);
            for (pixel, sample, dimension) in [(0, 0, 0), (7, 3, 5), (123_456, 1_000, 17), (u32::MAX, u32::MAX, 2)] {
                let mut stream = SampleStream::new(&sampler, pixel, sample);
                for _ in 0..dimension {
                    stream.next_points(1);
                }
                let set = stream.next_points(40);
                for first in [0, 16, 33] {
                    let lanes: [Vec2; 16] = set.get_2d_lanes(first);
                    for (lane, point) in lanes.iter().enumerate() {
                        let one = set.get_2d(first + lane as u32);
                        assert_eq!(point.to_array().map(f32::to_bits), one.to_array().map(f32::to_bits), "{kind:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn lanes_in_lockstep_draw_the_numbers_of_their_streams() {
        for kind in [SamplerKind::Independent, SamplerKind::Sobol] {
            let sampler = Sampler::new(kind, 7);
            let mut streams: [SampleStream; 16] = std::array::from_fn(|lane| {
                let lane = lane as u32;
                SampleStream::new(&sampler, lane.wrapping_mul(2_654_435_761), lane * lane + u32::MAX / 3 * (lane % 2))
            });
            for stream in &mut streams {
                stream.next_2d();
            }
            let mut lanes = LaneStreams::new(&streams);
            for _ in 0..5 {
                let (points, numbers) = (lanes.next_2d(), lanes.next_1d());
                for (lane, stream) in streams.iter_mut().enumerate() {
                    let bits = |v: Vec2| v.to_array().map(f32::to_bits);
                    assert_eq!(bits(points[lane]), bits(stream.next_2d()), "{kind:?} lane {lane}");
                    assert_eq!(numbers[lane].to_bits(), stream.next_1d().to_bits(), "{kind:?} lane {lane}");
                }
            }
        }
    }

    #[test]
    #[should_panic(expected = "share a sampler and a dimension")]
    fn lanes_in_lockstep_must_be_at_one_dimension() {
        let sampler = Sampler::new(SamplerKind::Sobol, 7);
        let mut streams = [SampleStream::new(&sampler, 0, 0); 2];
        streams[1].next_1d();
        LaneStreams::new(&streams);
    }

    /// The second dimension as Sobol defines it: the XOR of the direction numbers `vₖ = mₖ / 2ᵏ` of
    /// the index's set bits, with `mₖ = 2mₖ₋₁ ⊕ mₖ₋₁` (Pascal's triangle mod 2), in 0.32 fixed point.
    fn sobol_second_by_direction_numbers(index: u32) -> u32 {
        let mut m: u64 = 1;
        let mut x = 0;
        for k in 0..32 {
            if index >> k & 1 == 1 {
                x ^= (m << (31 - k)) as u32;
            }
            m ^= m << 1;
        }
        x
    }

    #[test]
    fn second_sobol_dimension_is_pascal_mod_2() {
        let first: Vec<f64> =
            (0..8).map(|i| f64::from(sobol_second_digits(i).reverse_bits()) / 2f64.powi(32)).collect();
        assert_eq!(first, [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875]);
        let mut index = 0u32;
        for k in 0..200_000u32 {
            assert_eq!(
                sobol_second_digits(index).reverse_bits(),
                sobol_second_by_direction_numbers(index),
                "{index:#x}"
            );
            index = index.wrapping_mul(0x9E37_79B9).wrapping_add(k);
        }
        for index in [u32::MAX, 1 << 31, 0x8000_0001] {
            assert_eq!(sobol_second_digits(index).reverse_bits(), sobol_second_by_direction_numbers(index));
        }
    }

    /// The shortcut of [`scrambled_digits`] is the Owen scramble of the point.
    #[test]
    fn scrambled_digits_is_owen_scramble_of_the_point() {
        for (k, seed) in (0..10_000u32).zip((0u32..).map(|s| s.wrapping_mul(0x2545_F491))) {
            let digits = k.wrapping_mul(0x9E37_79B9);
            assert_eq!(scrambled_digits(digits, seed), owen_scramble(digits.reverse_bits(), seed));
        }
    }

    /// An Owen scramble permutes every aligned block of 2ᵏ values among itself, for every k.
    #[test]
    fn owen_scramble_keeps_prefixes_together() {
        for seed in [0, 1, 0xDEAD_BEEF, u32::MAX] {
            for k in 1..=8 {
                let mut hit = vec![false; 1 << k];
                for i in 0u32..1 << k {
                    let cell = (owen_scramble(i << (32 - k), seed) >> (32 - k)) as usize;
                    assert!(!hit[cell], "seed {seed:#x}, k {k}: two values in one cell");
                    hit[cell] = true;
                }
            }
        }
    }
}
