//! What a render is asked to do: the technique with its own options, and what every technique
//! shares (samples per pixel, seed, sampler, budgets).

use std::time::Duration;

use crate::error::{Error, Result};
use crate::integrators::Technique;
use crate::sampler::SamplerKind;
use crate::scene::camera::Camera;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub technique: Technique,
    /// Camera samples per pixel to reach; 1 is the lab's single ray through the pixel centre,
    /// more are jittered inside the pixel.
    pub spp: u32,
    pub seed: u64,
    pub sampler: SamplerKind,
    /// Stop once this run has rendered this long (a resumed render gets the whole budget again),
    /// abandoning the pass in flight: the film keeps completed passes only.
    pub time_budget: Option<Duration>,
    /// Stop once the image's estimated relative standard error is below this.
    pub noise_target: Option<f64>,
}

impl RenderOptions {
    /// The options of a lab image: one camera ray per pixel centre, independent samples, no budget.
    pub fn new(technique: Technique) -> Self {
        RenderOptions {
            technique,
            spp: 1,
            seed: 0,
            sampler: SamplerKind::Independent,
            time_budget: None,
            noise_target: None,
        }
    }

    /// Whether camera samples go through pixel centres (the lab's single ray, `spp == 1`) rather
    /// than jittered positions. A render is one or the other from its first sample on: a render
    /// of one sample per pixel cannot be continued with more (its checkpoint is refused), and a
    /// render of several stopped after one pass holds a jittered sample, not the centre.
    pub fn samples_pixel_centres(&self) -> bool {
        self.spp == 1
    }

    pub(super) fn validate(&self, camera: &Camera) -> Result<()> {
        if camera.width == 0 || camera.height == 0 {
            return Err(Error::invalid(format!("image size {}x{} has no pixels", camera.width, camera.height)));
        }
        // Pixels are numbered in 32 bits for the sampler: past that, two pixels would share
        // their random numbers (no machine today holds such a film, but the check is free).
        if u64::from(camera.width) * u64::from(camera.height) > u64::from(u32::MAX) {
            return Err(Error::invalid(format!(
                "image size {}x{} has more than 4,294,967,295 pixels, the most a render numbers",
                camera.width, camera.height
            )));
        }
        self.technique.validate()?;
        if self.spp == 0 {
            return Err(Error::invalid("the samples per pixel (spp) must be at least 1"));
        }
        if self.noise_target.is_some_and(|n| n.is_nan() || n <= 0.0) {
            return Err(Error::invalid("the noise target must be positive"));
        }
        Ok(())
    }
}
