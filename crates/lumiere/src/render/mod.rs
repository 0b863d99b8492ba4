//! Progressive rendering: passes of one camera sample per pixel over the whole image (`pass.rs`),
//! each added to the film when it is complete. A pixel's samples depend only on the pixel, the
//! sample index and the options, never on the thread that ran them, and passes are accumulated in
//! order, so images are identical for any thread count and for any stopping point.

/// Runs `$body` with `$integrator` bound to the integrator of `$technique`: one monomorphised render
/// loop per technique, no dynamic dispatch per sample.
macro_rules! with_integrator {
    ($technique:expr, $integrator:ident => $body:expr) => {
        match $technique {
            $crate::integrators::Technique::Hits($integrator) => $body,
            $crate::integrators::Technique::Materials($integrator) => $body,
            $crate::integrators::Technique::Shadows($integrator) => $body,
            $crate::integrators::Technique::Direct($integrator) => $body,
            $crate::integrators::Technique::AmbientOcclusion($integrator) => $body,
            $crate::integrators::Technique::Path($integrator) => $body,
        }
    };
}

pub mod aov;
pub mod checkpoint;
pub mod film;
pub mod fingerprint;
pub mod forecast;
mod options;
mod pass;
pub mod range;
pub mod unlit;

pub use options::RenderOptions;
pub use range::render_pass_range;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::{Duration, Instant};

use crate::error::{Error, Result};
use crate::integrators::Integrator;
use crate::sampler::Sampler;
use crate::scene::camera::Camera;
use crate::world::World;
use film::{Film, Image};
pub(crate) use pass::film_position;
use pass::{Pass, pass_buffer, render_pass};

/// Why a render stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// Every pixel has the requested samples.
    Completed,
    TimeBudget,
    NoiseTarget,
    /// Cancelled (Ctrl-C); the pass in flight was abandoned.
    Interrupted,
}

impl StopReason {
    pub fn describe(self) -> &'static str {
        match self {
            StopReason::Completed => "all samples done",
            StopReason::TimeBudget => "time budget reached",
            StopReason::NoiseTarget => "noise target reached",
            StopReason::Interrupted => "interrupted",
        }
    }
}

/// Totals of a render, carried across checkpoints.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Every ray traced: camera rays and visibility queries.
    pub rays: u64,
    /// Rendering time, summed over the sessions of a resumed render.
    pub elapsed: Duration,
}

impl RenderStats {
    pub fn mrays_per_second(&self) -> f64 {
        self.rays as f64 / self.elapsed.as_secs_f64().max(1e-9) / 1e6
    }
}

#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub image: Image,
    pub film: Film,
    pub stats: RenderStats,
    pub stop: StopReason,
}

/// What the caller can watch and steer during a progressive render.
pub struct Hooks<'a> {
    /// Called after each tile with the number of pixel samples it added.
    pub progress: &'a (dyn Fn(u64) + Sync),
    /// Called after each completed pass (previews, checkpoints); an error stops the render.
    pub pass_done: &'a mut dyn FnMut(&Film, &RenderStats) -> Result<()>,
    /// Set from another thread (a signal handler) to stop; the pass in flight is abandoned.
    pub cancel: &'a AtomicBool,
}

/// Renders `options.spp` samples per pixel on the current rayon pool, without hooks.
pub fn render(
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderOutput> {
    let film = Film::new(camera.width, camera.height)?;
    let cancel = AtomicBool::new(false);
    let hooks = Hooks { progress, pass_done: &mut |_, _| Ok(()), cancel: &cancel };
    render_progressive(world, camera, options, film, RenderStats::default(), hooks)
}

/// Continues `film` (new, or resumed from a checkpoint with its `stats`) pass by pass until it has
/// `options.spp` samples, a budget is reached or `hooks.cancel` is set.
pub fn render_progressive(
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    film: Film,
    stats: RenderStats,
    hooks: Hooks,
) -> Result<RenderOutput> {
    options.validate(camera)?;
    if (film.width, film.height) != (camera.width, camera.height) {
        return Err(Error::invalid(format!(
            "film is {}x{} but the camera is {}x{}",
            film.width, film.height, camera.width, camera.height
        )));
    }
    with_integrator!(&options.technique, integrator => run_passes(integrator, world, camera, options, film, stats, hooks))
}

fn run_passes<I: Integrator>(
    integrator: &I,
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    mut film: Film,
    mut stats: RenderStats,
    hooks: Hooks,
) -> Result<RenderOutput> {
    let start = Instant::now();
    let before = stats.elapsed;
    let sampler = Sampler::new(options.sampler, options.seed);
    let pixel_centre = options.samples_pixel_centres();
    // The buffer passes render into, allocated when a pass needs one: the first pass's becomes the
    // film (no copy), and every later pass reuses a second one.
    let mut buffer = Vec::new();
    let expired = AtomicBool::new(false);
    // Checked between passes, before every 4x4 block of pixels and inside costly pixels, so that a render of
    // thousands of samples or lights per pixel neither outlives its budget nor ignores Ctrl-C. Two
    // atomic loads: reading the clock per pixel would cost more than a hard-shadow pixel.
    let stop_now = || {
        if hooks.cancel.load(Ordering::Relaxed) {
            Some(StopReason::Interrupted)
        } else if expired.load(Ordering::Relaxed) {
            Some(StopReason::TimeBudget)
        } else {
            None
        }
    };
    let (stop, result) = std::thread::scope(|scope| {
        // The budget's watchdog: it sets `expired` at the deadline, or leaves when the render ends
        // first (its channel closes).
        let (render_done, watchdog) = mpsc::channel::<()>();
        if let Some(budget) = options.time_budget {
            let expired = &expired;
            scope.spawn(move || {
                if watchdog.recv_timeout(budget) == Err(RecvTimeoutError::Timeout) {
                    expired.store(true, Ordering::Relaxed);
                }
            });
        }
        let outcome = loop {
            // Asked before each pass, the first too: a resumed film may already meet the target
            // (a run killed after its last pass's checkpoint was saved, but before it stopped),
            // and must stop where the run that was not killed stopped. Only with a target: the
            // estimate is a serial sweep over the film.
            if let Some(target) = options.noise_target
                && film.relative_error().is_some_and(|error| error <= target)
            {
                break (StopReason::NoiseTarget, Ok(()));
            }
            if film.samples >= options.spp {
                break (StopReason::Completed, Ok(()));
            }
            if let Some(reason) = stop_now() {
                break (reason, Ok(()));
            }
            let pass = Pass { sampler: &sampler, sample: film.samples, pixel_centre };
            if buffer.is_empty() {
                match pass_buffer(camera.width, camera.height) {
                    Ok(fresh) => buffer = fresh,
                    Err(e) => break (StopReason::Interrupted, Err(e)),
                }
            }
            let Some(rays) = render_pass(integrator, world, camera, &pass, &mut buffer, hooks.progress, &stop_now)
            else {
                // The pass in flight is abandoned: the film keeps whole passes only.
                break (stop_now().unwrap_or(StopReason::Interrupted), Ok(()));
            };
            if let Err(e) = film.add_rendered(&mut buffer) {
                break (StopReason::Interrupted, Err(e));
            }
            // Saturating: a checkpoint's count may already be near the top (the checksum does not
            // stop a forged one), and a total is no reason to wrap or panic.
            stats.rays = stats.rays.saturating_add(rays);
            stats.elapsed = before + start.elapsed();
            if let Err(e) = (hooks.pass_done)(&film, &stats) {
                break (StopReason::Interrupted, Err(e));
            }
        };
        drop(render_done);
        outcome
    });
    result?;
    stats.elapsed = before + start.elapsed();
    Ok(RenderOutput { image: film.image(), film, stats, stop })
}
