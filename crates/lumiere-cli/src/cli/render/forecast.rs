//! A noise target that the render will take hours to reach, said once, early: without it a
//! render with `--noise` set too low runs on in silence (there is no progress bar when stderr is
//! not a terminal, and the bar's total is unlimited anyway).

use std::time::{Duration, Instant};

use lumiere::render::film::Film;

use crate::cli::args::RenderArgs;
use crate::cli::output;

/// When the forecast looks, in seconds of rendering: the first look waits for an error estimate
/// over enough passes, the later ones catch a render whose rate or error changed.
const LOOKS: [f64; 4] = [2.0, 10.0, 60.0, 600.0];

/// Renders projected to reach their noise target sooner than this are not warned about.
const WARN_AFTER: Duration = Duration::from_secs(3600);

/// Fewer passes than this in the run give too rough an error (and rate) to project from.
const MIN_PASSES: u32 = 4;

pub struct NoiseForecast {
    target: f64,
    /// `--spp` when given (the default without it, unlimited, stops nothing in practice).
    spp: Option<u32>,
    time_budget: Option<Duration>,
    start: Instant,
    start_samples: u32,
    looks_done: usize,
}

impl NoiseForecast {
    /// A forecast for a render with a noise target starting now from `film_samples` samples
    /// (those of a checkpoint resumed).
    pub fn new(args: &RenderArgs, film_samples: u32) -> Option<NoiseForecast> {
        Some(NoiseForecast {
            target: args.noise?,
            spp: args.spp,
            time_budget: args.time,
            start: Instant::now(),
            start_samples: film_samples,
            looks_done: 0,
        })
    }

    /// Called after each pass: at each look, warns (once) if the target is more than
    /// [`WARN_AFTER`] away at this run's rate and neither `--spp` nor `--time` stops the render
    /// before it.
    pub fn after_pass(&mut self, film: &Film) {
        let elapsed = self.start.elapsed();
        let due = LOOKS.iter().take_while(|&&at| elapsed.as_secs_f64() >= at).count();
        if due <= self.looks_done {
            return;
        }
        self.looks_done = due;
        if let Some(message) = self.warning(film, elapsed) {
            output::warn(message);
            self.looks_done = LOOKS.len();
        }
    }

    fn warning(&self, film: &Film, elapsed: Duration) -> Option<String> {
        let done = film.samples.saturating_sub(self.start_samples);
        let error = film.relative_error()?;
        if done < MIN_PASSES || !error.is_finite() || error <= self.target {
            return None;
        }
        // The relative standard error falls as one over the square root of the samples.
        let needed = f64::from(film.samples) * (error / self.target).powi(2);
        let seconds_per_sample = elapsed.as_secs_f64() / f64::from(done);
        let to_target = (needed - f64::from(film.samples)) * seconds_per_sample;
        let to_spp = self.spp.map(|spp| f64::from(spp.saturating_sub(film.samples)) * seconds_per_sample);
        let to_budget = self.time_budget.map(|budget| budget.saturating_sub(elapsed).as_secs_f64());
        let stopped_sooner = [to_spp, to_budget].into_iter().flatten().any(|other| other < to_target);
        if stopped_sooner || to_target < WARN_AFTER.as_secs_f64() {
            return None;
        }
        Some(format!(
            "--noise {}: the relative error is {error:.4} after {} spp; at this rate the target needs about {needed:.2e} spp, {} more; the render goes on until then (Ctrl-C writes the image so far; --time or --spp bound it)",
            self.target,
            film.samples,
            shown_duration(to_target)
        ))
    }
}

/// `seconds` in the largest unit that keeps it above 1, roughly.
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
    use super::shown_duration;

    #[test]
    fn durations_read_in_hours_days_or_years() {
        assert_eq!(shown_duration(5400.0), "1.5 hours");
        assert_eq!(shown_duration(3.0 * 86_400.0), "3 days");
        assert_eq!(shown_duration(2.0e9 * 86_400.0), "5.48e6 years");
    }
}
