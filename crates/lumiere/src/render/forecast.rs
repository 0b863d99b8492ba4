//! Whether a render's noise target is within reach. Without a look ahead, a render whose target is
//! set too low runs on in silence: a progress bar's total is unlimited then, and scripts and
//! notebooks show none. After each pass, at a few looks, the samples and time the target needs are
//! projected from the run's rate and error; a target more than an hour away, that no sample count
//! or time budget stops the render before, is reported once. The CLI and the Python module word
//! the report in their own terms (flags, keyword arguments).

use std::time::{Duration, Instant};

use super::film::Film;

/// When the forecast looks, in seconds of rendering: the first look waits for an error estimate
/// over enough passes, the later ones catch a render whose rate or error changed.
const LOOKS: [f64; 4] = [2.0, 10.0, 60.0, 600.0];

/// Renders projected to reach their noise target sooner than this are not reported.
const REPORT_AFTER: Duration = Duration::from_secs(3600);

/// Fewer passes than this in the run give too rough an error (and rate) to project from.
const MIN_PASSES: u32 = 4;

/// A noise target out of reach: where the render stands and what the target needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutOfReach {
    /// The noise target.
    pub target: f64,
    /// The image's estimated relative error now.
    pub error: f64,
    /// Samples per pixel done.
    pub samples: u32,
    /// Samples per pixel the target needs (the error falls as one over their square root).
    pub needed_samples: f64,
    /// Seconds to the target at this run's rate.
    pub seconds_to_target: f64,
}

impl OutOfReach {
    /// The report, less how the caller names the target and how a render is bounded (a flag, a
    /// keyword): "the relative error is 0.0078 after 7625 spp; at this rate the target needs about
    /// 4.63e17 spp, 3.85e6 years more; the render goes on until then".
    pub fn describe(&self) -> String {
        format!(
            "the relative error is {:.4} after {} spp; at this rate the target needs {}; the render goes on until then",
            self.error,
            self.samples,
            self.need()
        )
    }

    /// What the target needs, in words, or, for a target so low that the count overflows, that it
    /// is beyond counting.
    fn need(&self) -> String {
        if self.needed_samples.is_finite() && self.seconds_to_target.is_finite() {
            format!("about {:.2e} spp, {} more", self.needed_samples, shown_duration(self.seconds_to_target))
        } else {
            "more spp than a 64-bit float counts, forever in practice".to_string()
        }
    }
}

pub struct NoiseForecast {
    target: f64,
    /// The sample count that stops the render, if one does.
    spp: Option<u32>,
    time_budget: Option<Duration>,
    start: Instant,
    start_samples: u32,
    looks_done: usize,
}

impl NoiseForecast {
    /// A forecast for a render with noise target `target`, stopped also at `spp` samples per pixel
    /// and after `time_budget` if given, starting now from `film_samples` samples (those of a
    /// checkpoint resumed). `None` without a target.
    pub fn new(
        target: Option<f64>,
        spp: Option<u32>,
        time_budget: Option<Duration>,
        film_samples: u32,
    ) -> Option<NoiseForecast> {
        Some(NoiseForecast {
            target: target?,
            spp,
            time_budget,
            start: Instant::now(),
            start_samples: film_samples,
            looks_done: 0,
        })
    }

    /// Called after each pass: at each look, the target if it is out of reach (more than an hour
    /// away at this run's rate, and neither the sample count nor the time budget stops the render
    /// before it); once, then never again.
    pub fn after_pass(&mut self, film: &Film) -> Option<OutOfReach> {
        let elapsed = self.start.elapsed();
        let due = LOOKS.iter().take_while(|&&at| elapsed.as_secs_f64() >= at).count();
        if due <= self.looks_done {
            return None;
        }
        self.looks_done = due;
        let out_of_reach = self.out_of_reach(film, elapsed)?;
        self.looks_done = LOOKS.len();
        Some(out_of_reach)
    }

    fn out_of_reach(&self, film: &Film, elapsed: Duration) -> Option<OutOfReach> {
        let done = film.samples.saturating_sub(self.start_samples);
        let error = film.relative_error()?;
        if done < MIN_PASSES || !error.is_finite() || error <= self.target {
            return None;
        }
        let needed_samples = f64::from(film.samples) * (error / self.target).powi(2);
        let seconds_per_sample = elapsed.as_secs_f64() / f64::from(done);
        let seconds_to_target = (needed_samples - f64::from(film.samples)) * seconds_per_sample;
        let to_spp = self.spp.map(|spp| f64::from(spp.saturating_sub(film.samples)) * seconds_per_sample);
        let to_budget = self.time_budget.map(|budget| budget.saturating_sub(elapsed).as_secs_f64());
        let stopped_sooner = [to_spp, to_budget].into_iter().flatten().any(|other| other < seconds_to_target);
        if stopped_sooner || seconds_to_target < REPORT_AFTER.as_secs_f64() {
            return None;
        }
        Some(OutOfReach { target: self.target, error, samples: film.samples, needed_samples, seconds_to_target })
    }
}

/// `x` as a person would write it: with an exponent when small or large (`1e-9`, not
/// `0.000000001`), as given when it has a short decimal form (`0.01`).
pub fn shown_number(x: f64) -> String {
    if x != 0.0 && !(1e-4..1e6).contains(&x.abs()) { format!("{x:e}") } else { format!("{x}") }
}

/// `seconds` in the largest unit that keeps it above 1, roughly: hours, days or years.
fn shown_duration(seconds: f64) -> String {
    const DAY: f64 = 86_400.0;
    match seconds {
        s if s >= 365.0 * DAY => format!("{:.2e} years", s / (365.25 * DAY)),
        s if s >= 2.0 * DAY => format!("{:.0} days", s / DAY),
        s => format!("{:.1} hours", s / 3600.0),
    }
}

#[cfg(test)]
mod tests {
    use super::{OutOfReach, shown_duration, shown_number};

    #[test]
    fn numbers_read_as_written() {
        assert_eq!(shown_number(1e-9), "1e-9");
        assert_eq!(shown_number(1e-300), "1e-300");
        assert_eq!(shown_number(0.01), "0.01");
        assert_eq!(shown_number(0.0005), "0.0005");
        assert_eq!(shown_number(2.5e7), "2.5e7");
    }

    #[test]
    fn a_need_beyond_counting_says_so() {
        let report = |needed_samples, seconds_to_target| OutOfReach {
            target: 1e-9,
            error: 0.01,
            samples: 8,
            needed_samples,
            seconds_to_target,
        };
        assert_eq!(
            report(4.63e17, 1.2e14).describe(),
            "the relative error is 0.0100 after 8 spp; at this rate the target needs about 4.63e17 spp, 3.80e6 years more; the render goes on until then"
        );
        assert_eq!(
            report(f64::INFINITY, f64::INFINITY).describe(),
            "the relative error is 0.0100 after 8 spp; at this rate the target needs more spp than a 64-bit float counts, forever in practice; the render goes on until then"
        );
    }

    #[test]
    fn durations_read_in_hours_days_or_years() {
        assert_eq!(shown_duration(5400.0), "1.5 hours");
        assert_eq!(shown_duration(3.0 * 86_400.0), "3 days");
        assert_eq!(shown_duration(2.0e9 * 86_400.0), "5.48e6 years");
    }
}
