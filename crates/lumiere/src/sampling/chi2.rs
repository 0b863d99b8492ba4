//! The one chi-square goodness-of-fit harness for every warp, discrete distribution and sampler.
//!
//! A sampler is correct when the histogram of its samples matches its claimed density. The test
//! bins samples on a grid over a 2D parameter square `[0, 1]²`, integrates the density over each
//! cell for the expected counts, pools cells expecting fewer than 5 samples (where the chi-square
//! approximation breaks down), and turns Pearson's statistic into a p-value. It fails at once when
//! a sample is NaN, leaves the square, or lands where the density is 0 — errors no amount of
//! statistics should be allowed to average away. The idea follows Mitsuba's `chi2.py` and pbrt's
//! BSDF tests; the code is ours.
//!
//! Callers map their domain onto the square and transform the density with the Jacobian. For a
//! direction `ω` on the sphere, for example, `(x, y) = ((1 − cos θ)/2, φ/2π)` has `dω = 4π dx dy`,
//! so the density on the square is `4π · pdf(ω)` for a solid-angle pdf.

use glam::Vec2;

/// Tests pass when the p-value is at least this: a correct sampler fails 1% of fixed seeds.
pub const SIGNIFICANCE: f64 = 0.01;

/// Cells expecting fewer samples than this are pooled into one (Cochran's rule of thumb).
const MIN_EXPECTED: f64 = 5.0;

/// How many of the worst cells a failure report lists.
const REPORT_CELLS: usize = 8;

/// A 2D chi-square test on a `cells_x × cells_y` grid over the parameter square `[0, 1]²`.
#[derive(Clone, Copy, Debug)]
pub struct Chi2Test {
    pub cells_x: usize,
    pub cells_y: usize,
    /// The p-value below which the test fails; [`SIGNIFICANCE`] unless a test wants to prove a
    /// stronger rejection.
    pub significance: f64,
    /// Simpson sub-intervals per cell and axis (even) when integrating the density.
    pub integration_steps: usize,
}

impl Chi2Test {
    /// A test on a `cells_x × cells_y` grid at the default [`SIGNIFICANCE`].
    pub fn new(cells_x: usize, cells_y: usize) -> Chi2Test {
        Chi2Test { cells_x, cells_y, significance: SIGNIFICANCE, integration_steps: 8 }
    }

    /// Tests a warp: `sample` gets `n` uniform points from a SplitMix64 stream seeded with `seed`
    /// and returns its result as a point of the parameter square (`None` when it produces no
    /// sample, which then counts in no cell). `density` is the claimed density of those points
    /// with respect to area on the square.
    ///
    /// `Ok(p_value)` when `p ≥ significance`, otherwise `Err` with a report of the worst cells.
    pub fn run_warp(
        &self,
        n: u64,
        seed: u64,
        mut sample: impl FnMut(Vec2) -> Option<Vec2>,
        density: impl Fn(Vec2) -> f64,
    ) -> Result<f64, String> {
        let mut rng = SplitMix64(seed);
        self.run_points((0..n).map(|_| sample(rng.next_vec2())), density)
    }

    /// Tests a ready stream of points of the parameter square (for samplers, which make their own
    /// numbers); `None` items count as samples that produced nothing.
    pub fn run_points(
        &self,
        points: impl IntoIterator<Item = Option<Vec2>>,
        density: impl Fn(Vec2) -> f64,
    ) -> Result<f64, String> {
        assert!(self.cells_x > 0 && self.cells_y > 0, "the grid needs cells");
        let mut observed = vec![0u64; self.cells_x * self.cells_y];
        let mut n = 0u64;
        for point in points {
            n += 1;
            let Some(p) = point else { continue };
            check_sample(p, &density)?;
            observed[self.cell_of(p)] += 1;
        }
        let expected = self.integrate_cells(&density);
        let cells = (0..observed.len())
            .map(|i| Cell {
                label: format!("cell ({}, {})", i % self.cells_x, i / self.cells_x),
                observed: observed[i],
                expected: expected[i] * n as f64,
            })
            .collect();
        evaluate(cells, n, self.significance)
    }

    /// The index of the cell containing `p`; points on the far edges belong to the last cells.
    fn cell_of(&self, p: Vec2) -> usize {
        let x = ((p.x as f64 * self.cells_x as f64) as usize).min(self.cells_x - 1);
        let y = ((p.y as f64 * self.cells_y as f64) as usize).min(self.cells_y - 1);
        y * self.cells_x + x
    }

    /// The integral of `density` over every cell, by composite Simpson's rule on a shared grid.
    fn integrate_cells(&self, density: &impl Fn(Vec2) -> f64) -> Vec<f64> {
        let steps = self.integration_steps.max(2).next_multiple_of(2);
        let (nx, ny) = (self.cells_x * steps, self.cells_y * steps);
        let values: Vec<f64> = (0..=ny)
            .flat_map(|j| (0..=nx).map(move |i| (i, j)))
            .map(|(i, j)| density(Vec2::new((i as f64 / nx as f64) as f32, (j as f64 / ny as f64) as f32)))
            .collect();
        let h = 1.0 / (nx as f64 * ny as f64);
        let mut cells = vec![0.0; self.cells_x * self.cells_y];
        for (c, integral) in cells.iter_mut().enumerate() {
            let (x0, y0) = ((c % self.cells_x) * steps, (c / self.cells_x) * steps);
            let mut sum = 0.0;
            for j in 0..=steps {
                for i in 0..=steps {
                    sum += simpson_weight(i, steps) * simpson_weight(j, steps) * values[(y0 + j) * (nx + 1) + x0 + i];
                }
            }
            *integral = sum * h / 9.0;
        }
        cells
    }
}

/// Integrates `density` over the unit square by composite Simpson's rule with `steps` (even)
/// sub-intervals per axis; tests use it to check that a pdf integrates to 1 over its domain.
pub fn integrate_unit_square(density: impl Fn(Vec2) -> f64, steps: usize) -> f64 {
    let test = Chi2Test { cells_x: 1, cells_y: 1, significance: SIGNIFICANCE, integration_steps: steps };
    test.integrate_cells(&density)[0]
}

/// Tests counts of a discrete distribution (an alias table, say) against its probabilities `pmf`.
///
/// Fails at once when an item of probability 0 was drawn or a probability is negative or NaN. `Ok(p_value)` when `p ≥`
/// [`SIGNIFICANCE`], otherwise `Err` with a report of the worst items.
pub fn chi2_discrete(pmf: &[f64], counts: &[u64]) -> Result<f64, String> {
    assert_eq!(pmf.len(), counts.len(), "one count per item");
    let n: u64 = counts.iter().sum();
    let cells = (0..pmf.len())
        .map(|i| Cell { label: format!("item {i}"), observed: counts[i], expected: pmf[i] * n as f64 })
        .collect();
    evaluate(cells, n, SIGNIFICANCE)
}

/// Fails for samples that should not exist: NaN, outside the square, or where the density is 0.
fn check_sample(p: Vec2, density: &impl Fn(Vec2) -> f64) -> Result<(), String> {
    if !p.is_finite() {
        return Err(format!("sample {p} is not finite"));
    }
    if p.min_element() < 0.0 || p.max_element() > 1.0 {
        return Err(format!("sample {p} lies outside the parameter square [0, 1]²"));
    }
    let d = density(p);
    if d.is_nan() || d <= 0.0 {
        return Err(format!("sample {p} lies where the density is {d}"));
    }
    Ok(())
}

/// A histogram bin: how many samples it got and how many it should get.
struct Cell {
    label: String,
    observed: u64,
    expected: f64,
}

/// Pools sparse cells, computes Pearson's statistic and its p-value, and judges it.
fn evaluate(cells: Vec<Cell>, n: u64, significance: f64) -> Result<f64, String> {
    if let Some(c) = cells.iter().find(|c| !c.expected.is_finite() || c.expected < 0.0) {
        return Err(format!("{}: the expected count is {}; the density must be finite and ≥ 0", c.label, c.expected));
    }
    if let Some(c) = cells.iter().find(|c| c.observed > 0 && c.expected == 0.0) {
        return Err(format!("{} got {} samples where the density integrates to 0", c.label, c.observed));
    }
    let total_expected: f64 = cells.iter().map(|c| c.expected).sum();
    let cells = pool_sparse(cells);
    if cells.len() < 2 {
        return Err(format!("{n} samples fill fewer than 2 cells of 5 expected; use more samples"));
    }
    let contribution = |c: &Cell| (c.observed as f64 - c.expected).powi(2) / c.expected;
    let statistic: f64 = cells.iter().map(contribution).sum();
    let dof = cells.len() - 1;
    let p = chi2_survival(statistic, dof as f64);
    if p >= significance {
        return Ok(p);
    }
    let mut worst: Vec<&Cell> = cells.iter().collect();
    worst.sort_by(|a, b| contribution(b).total_cmp(&contribution(a)));
    let mut report = format!(
        "chi-square test failed: p = {p:.3e} < {significance} (χ² = {statistic:.1}, {dof} degrees of freedom, \
         {n} samples, density integrates to {:.6}); worst cells:",
        total_expected / n as f64
    );
    for c in worst.iter().take(REPORT_CELLS) {
        report += &format!("\n  {}: observed {}, expected {:.1}", c.label, c.observed, c.expected);
    }
    Err(report)
}

/// Merges every cell expecting fewer than [`MIN_EXPECTED`] samples into one, adding the next
/// sparsest cells while the pool itself is still that sparse. Empty cells (expected 0) vanish.
fn pool_sparse(mut cells: Vec<Cell>) -> Vec<Cell> {
    cells.retain(|c| c.expected > 0.0);
    cells.sort_by(|a, b| a.expected.total_cmp(&b.expected));
    let mut pool = Cell { label: String::from("pooled sparse cells"), observed: 0, expected: 0.0 };
    let mut pooled = 0;
    for c in &cells {
        if c.expected >= MIN_EXPECTED && (pooled == 0 || pool.expected >= MIN_EXPECTED) {
            break;
        }
        pool.observed += c.observed;
        pool.expected += c.expected;
        pooled += 1;
    }
    let mut kept = cells.split_off(pooled);
    if pooled > 0 {
        pool.label = format!("{pooled} pooled sparse cells");
        kept.push(pool);
    }
    kept
}

/// Simpson's weight (before the common factor h/3) of node `i` of `steps` sub-intervals.
fn simpson_weight(i: usize, steps: usize) -> f64 {
    if i == 0 || i == steps {
        1.0
    } else if i % 2 == 1 {
        4.0
    } else {
        2.0
    }
}

/// `P(X ≥ x)` for `X` chi-square distributed with `dof` degrees of freedom: `Q(dof/2, x/2)`.
pub fn chi2_survival(x: f64, dof: f64) -> f64 {
    if x <= 0.0 { 1.0 } else { regularized_gamma_q(0.5 * dof, 0.5 * x) }
}

/// The regularized upper incomplete gamma function `Q(a, x) = Γ(a, x) / Γ(a)` for `a > 0`,
/// `x ≥ 0`: by its power series below `x = a + 1`, where that converges fast, and by its
/// continued fraction above (Numerical Recipes §6.2 describes both).
fn regularized_gamma_q(a: f64, x: f64) -> f64 {
    if x < a + 1.0 { 1.0 - gamma_p_series(a, x) } else { gamma_q_continued_fraction(a, x) }
}

/// `P(a, x) = e^{−x} x^a / Γ(a) · Σₖ xᵏ / (a (a+1) ⋯ (a+k))`.
fn gamma_p_series(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let (mut term, mut sum, mut denominator) = (1.0 / a, 1.0 / a, a);
    for _ in 0..1000 {
        denominator += 1.0;
        term *= x / denominator;
        sum += term;
        if term.abs() < sum.abs() * 1e-15 {
            break;
        }
    }
    sum * (a * x.ln() - x - ln_gamma(a)).exp()
}

/// `Q(a, x)` from the continued fraction `e^{−x} x^a / Γ(a) · 1/(x+1−a− 1·(1−a)/(x+3−a− ⋯))`,
/// evaluated with the modified Lentz method.
fn gamma_q_continued_fraction(a: f64, x: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / TINY;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..1000 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        d = if d.abs() < TINY { TINY } else { d };
        c = b + an / c;
        c = if c.abs() < TINY { TINY } else { c };
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h * (a * x.ln() - x - ln_gamma(a)).exp()
}

/// `ln Γ(x)` for `x > 0`: the Lanczos approximation (g = 7, 9 terms), accurate to ~1e-15, with
/// the reflection `Γ(x) Γ(1−x) = π / sin(πx)` below 1/2.
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const COEFFICIENTS: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + G + 0.5;
    let series = COEFFICIENTS[1..].iter().enumerate().fold(COEFFICIENTS[0], |s, (k, c)| s + c / (x + k as f64 + 1.0));
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + series.ln()
}

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny seeded generator, so that every test run draws
/// the same uniform points.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Two uniforms in `[0, 1)` with 24 random bits each, like the renderer's samplers.
    fn next_vec2(&mut self) -> Vec2 {
        let bits = self.next_u64();
        let unit = |b: u64| (b & 0xFF_FFFF) as f32 * (1.0 / 16_777_216.0);
        Vec2::new(unit(bits >> 40), unit(bits >> 16))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For even degrees of freedom `2k` the survival function has the closed form
    /// `e^{−x/2} Σ_{i<k} (x/2)ⁱ / i!`; the cases straddle `x = a + 1`, where the two methods meet.
    #[test]
    fn survival_function_matches_closed_form() {
        for (x, dof) in [(0.5, 2), (2.0, 2), (3.0, 10), (18.307, 10), (80.0, 100), (124.342, 100), (1057.7, 1000)] {
            let half: f64 = 0.5 * x;
            let (mut term, mut sum) = (1.0f64, 0.0f64);
            for i in 0..dof / 2 {
                sum += term;
                term *= half / (i + 1) as f64;
            }
            let want = sum * (-half).exp();
            let got = chi2_survival(x, dof as f64);
            assert!((got - want).abs() <= 1e-10 * want.max(1e-300), "Q({x}, {dof}) = {got}, want {want}");
        }
        // The 5% critical value of one degree of freedom, from any table.
        assert!((chi2_survival(3.841_458_820_694_124, 1.0) - 0.05).abs() < 1e-12);
    }

    #[test]
    fn ln_gamma_matches_factorials() {
        let mut factorial = 1.0f64;
        for n in 1..30 {
            assert!((ln_gamma(n as f64) - factorial.ln()).abs() < 1e-12, "ln Γ({n})");
            factorial *= n as f64;
        }
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
    }
}
