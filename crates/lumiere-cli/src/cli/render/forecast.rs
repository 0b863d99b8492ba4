//! A noise target that the render will take hours to reach, said once, early, in the CLI's terms
//! (the library's [`NoiseForecast`] projects it).

use lumiere::render::film::Film;
use lumiere::render::forecast::{NoiseForecast, shown_number};

use crate::cli::args::RenderArgs;
use crate::cli::output;

/// The forecast of a render with `--noise`, starting now from `film_samples` samples (those of a
/// checkpoint resumed); `--spp` stops it when given (without it, the default stops nothing in
/// practice).
pub fn noise_forecast(args: &RenderArgs, film_samples: u32) -> Option<NoiseForecast> {
    NoiseForecast::new(args.noise, args.spp, args.time, film_samples)
}

/// Called after each pass: warns once if the target is out of reach.
pub fn after_pass(forecast: &mut NoiseForecast, film: &Film) {
    if let Some(report) = forecast.after_pass(film) {
        output::warn(format!(
            "--noise {}: {} (Ctrl-C writes the image so far; --time or --spp bound it)",
            shown_number(report.target),
            report.describe()
        ));
    }
}
