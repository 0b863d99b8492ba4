//! Where a render starts (a fresh film, or a checkpoint of the same scene and options) and how its
//! state is saved.

use std::path::Path;

use lumiere::render::RenderOptions;
use lumiere::render::RenderStats;
use lumiere::render::checkpoint::Checkpoint;
use lumiere::render::film::Film;
use lumiere::render::fingerprint::{options_fingerprint, scene_fingerprint};
use lumiere::scene::Scene;
use lumiere::scene::camera::Camera;
use lumiere::{Error, Result};

/// What a checkpoint must match to be resumed: the scene, the options that decide sample values,
/// and the seed.
#[derive(Clone, Copy, Debug)]
pub struct Fingerprints {
    scene: u64,
    options: u64,
    seed: u64,
}

impl Fingerprints {
    pub fn new(scene: &Scene, options: &RenderOptions, camera: &Camera) -> Fingerprints {
        Fingerprints {
            scene: scene_fingerprint(scene),
            options: options_fingerprint(options, camera),
            seed: options.seed,
        }
    }

    /// The film and totals to start from: those of the checkpoint `resume`, or fresh ones.
    pub fn start(&self, resume: Option<&Path>, camera: &Camera) -> Result<(Film, RenderStats)> {
        match resume {
            Some(path) => self.resume(path),
            None => Ok((Film::new(camera.width, camera.height)?, RenderStats::default())),
        }
    }

    /// Loads a checkpoint and refuses it unless it was made from the same scene and options.
    fn resume(&self, path: &Path) -> Result<(Film, RenderStats)> {
        let checkpoint = Checkpoint::load(path)?;
        if checkpoint.scene_fingerprint != self.scene {
            return Err(Error::invalid(format!(
                "{}: cannot resume: the checkpoint was rendered from a different scene (geometry, materials or --emission)",
                path.display()
            )));
        }
        if checkpoint.options_fingerprint != self.options || checkpoint.seed != self.seed {
            return Err(Error::invalid(format!(
                "{}: cannot resume: the checkpoint was rendered with different options (mode, --samples, --seed, --sampler, --light-sampling, --ao-distance, camera or --size); only --spp and the budgets may change",
                path.display()
            )));
        }
        Ok((checkpoint.film, checkpoint.stats))
    }

    pub fn save(&self, path: &Path, film: &Film, stats: &RenderStats) -> Result<()> {
        let checkpoint = Checkpoint {
            scene_fingerprint: self.scene,
            options_fingerprint: self.options,
            seed: self.seed,
            film: film.clone(),
            stats: *stats,
        };
        checkpoint.save(path)
    }
}
