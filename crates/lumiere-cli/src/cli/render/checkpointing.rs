//! Where a render starts (a fresh film, or a checkpoint of the same scene and options) and how its
//! state is saved.

use lumiere::error::shown_path;
use std::path::Path;

use lumiere::render::RenderOptions;
use lumiere::render::RenderStats;
use lumiere::render::checkpoint::{Checkpoint, differing_options};
use lumiere::render::film::Film;
use lumiere::render::fingerprint::{options_description, scene_fingerprint};
use lumiere::scene::Scene;
use lumiere::scene::camera::Camera;
use lumiere::util::hash::hash_bytes;
use lumiere::{Error, Result};

/// What a checkpoint must match to be resumed: the scene, and the options that decide sample
/// values (seed included), kept as readable text so that a refusal can name what differs.
#[derive(Clone, Debug)]
pub struct Fingerprints {
    scene: u64,
    options: String,
    seed: u64,
}

impl Fingerprints {
    pub fn new(scene: &Scene, options: &RenderOptions, camera: &Camera) -> Fingerprints {
        Fingerprints {
            scene: scene_fingerprint(scene),
            options: options_description(options, camera),
            seed: options.seed,
        }
    }

    /// The film and totals to start from: those of the checkpoint `resume`, or fresh ones.
    pub fn start(&self, resume: Option<&Path>, camera: &Camera) -> Result<(Film, RenderStats)> {
        match resume {
            Some(path) => self.resume(path, camera),
            None => Ok((Film::new(camera.width, camera.height)?, RenderStats::default())),
        }
    }

    /// Loads a checkpoint and refuses it unless it was made from the same scene and options.
    fn resume(&self, path: &Path, camera: &Camera) -> Result<(Film, RenderStats)> {
        let checkpoint = Checkpoint::load(path)?;
        if checkpoint.scene_fingerprint != self.scene {
            return Err(Error::invalid(format!(
                "{}: cannot resume: the checkpoint was rendered from a different scene (geometry, materials or --emission)",
                shown_path(path)
            )));
        }
        if checkpoint.options_fingerprint != hash_bytes(self.options.as_bytes()) || checkpoint.seed != self.seed {
            let differing = differing_options(&checkpoint.options, &self.options);
            return Err(Error::invalid(format!(
                "{}: cannot resume: the checkpoint was rendered with other options: {}; only --spp, the budgets, --threads and the outputs may change",
                shown_path(path),
                differing.join(", ")
            )));
        }
        // Its options name the camera's size, but its film is written apart (a checkpoint saved
        // from Python's film API can hold a film of another size): refused here, with the file.
        let film = &checkpoint.film;
        if (film.width, film.height) != (camera.width, camera.height) {
            return Err(Error::invalid(format!(
                "{}: cannot resume: the checkpoint's film is {}x{}, but the image is {}x{}",
                shown_path(path),
                film.width,
                film.height,
                camera.width,
                camera.height
            )));
        }
        Ok((checkpoint.film, checkpoint.stats))
    }

    pub fn save(&self, path: &Path, film: &Film, stats: &RenderStats) -> Result<()> {
        let checkpoint = Checkpoint {
            scene_fingerprint: self.scene,
            options_fingerprint: hash_bytes(self.options.as_bytes()),
            seed: self.seed,
            options: self.options.clone(),
            film: film.clone(),
            stats: *stats,
        };
        checkpoint.save(path)
    }
}
