//! Where a render starts: a fresh film, or a checkpoint of the same scene and options.

use lumiere::error::shown_path;
use std::path::Path;

use lumiere::render::RenderStats;
use lumiere::render::checkpoint::Checkpoint;
use lumiere::render::film::Film;
use lumiere::render::fingerprint::{Fingerprints, Mismatch};
use lumiere::scene::camera::Camera;
use lumiere::{Error, Result};

/// Where a render starts, from `fingerprints` (see [`Fingerprints`]): the film and totals of the
/// checkpoint `resume`, refused unless it was made from the same scene and options, or fresh ones.
pub fn start(fingerprints: &Fingerprints, resume: Option<&Path>, camera: &Camera) -> Result<(Film, RenderStats)> {
    let Some(path) = resume else {
        return Ok((Film::new(camera.width, camera.height)?, RenderStats::default()));
    };
    let checkpoint = Checkpoint::load(path)?;
    let why = match fingerprints.mismatch(&checkpoint) {
        None => return Ok((checkpoint.film, checkpoint.stats)),
        Some(Mismatch::Scene) => {
            "the checkpoint was rendered from a different scene (geometry, materials, textures or --emission)"
                .to_string()
        }
        Some(Mismatch::Options(differing)) => format!(
            "the checkpoint was rendered with other options: {}; only --spp, the budgets, --threads and the outputs may change",
            differing.join(", ")
        ),
        Some(Mismatch::FilmSize { film, image }) => {
            format!("the checkpoint's film is {}x{}, but the image is {}x{}", film.0, film.1, image.0, image.1)
        }
    };
    Err(Error::invalid(format!("{}: cannot resume: {why}", shown_path(path))))
}
