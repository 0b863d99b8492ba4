//! Progressive rendering: passes of one camera sample per pixel over the whole image, each pass
//! split into tiles scheduled with rayon. A pixel's samples depend only on the pixel, the sample
//! index and the options, never on the thread that ran them, and passes are accumulated in order,
//! so images are identical for any thread count and for any stopping point.

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
mod options;
pub mod range;

pub use options::RenderOptions;
pub use range::render_pass_range;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::time::{Duration, Instant};

use glam::Vec3;
use rayon::prelude::*;

use crate::accel::OriginBatch;
use crate::error::{Error, Result};
use crate::integrators::{Integrator, SampleContext};
use crate::math::Ray;
use crate::sampler::{SampleStream, Sampler};
use crate::scene::camera::Camera;
use crate::world::World;
use film::{Film, Image};

/// Tiles are small enough to balance two cores and to notice an interruption within milliseconds,
/// and large enough that scheduling costs nothing.
const TILE_SIZE: u32 = 16;

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
    let tiles = tiles(camera.width, camera.height);
    let pixel_centre = options.samples_pixel_centres();
    let expired = AtomicBool::new(false);
    // Checked between passes, before every pixel and inside costly pixels, so that a render of
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
            if film.samples >= options.spp {
                break (StopReason::Completed, Ok(()));
            }
            if let Some(reason) = stop_now() {
                break (reason, Ok(()));
            }
            let pass = Pass { sampler: &sampler, sample: film.samples, pixel_centre };
            let Some(tile_values) = render_pass(integrator, world, camera, &pass, &tiles, hooks.progress, &stop_now)
            else {
                // The pass in flight is abandoned: the film keeps whole passes only.
                break (stop_now().unwrap_or(StopReason::Interrupted), Ok(()));
            };
            for (tile, (values, rays)) in tiles.iter().zip(tile_values) {
                film.add_tile(tile.x0, tile.y0, tile.x1 - tile.x0, &values);
                stats.rays += rays;
            }
            film.samples += 1;
            stats.elapsed = before + start.elapsed();
            if let Err(e) = (hooks.pass_done)(&film, &stats) {
                break (StopReason::Interrupted, Err(e));
            }
            if let (Some(target), Some(error)) = (options.noise_target, film.relative_error())
                && error <= target
            {
                break (StopReason::NoiseTarget, Ok(()));
            }
        };
        drop(render_done);
        outcome
    });
    result?;
    stats.elapsed = before + start.elapsed();
    Ok(RenderOutput { image: film.image(), film, stats, stop })
}

/// What every pixel of one pass shares.
struct Pass<'a> {
    sampler: &'a Sampler,
    /// The camera sample index of this pass.
    sample: u32,
    /// Sample pixel centres (the lab's single ray) rather than jittered positions.
    pixel_centre: bool,
}

/// The camera ray of sample `sample` of pixel `(x, y)`, and that sample's random numbers with the
/// pixel position already drawn from their first dimension (drawn even for pixel centres, so that
/// the integrator's dimensions do not depend on it). The one place a sample's position is decided:
/// the render and its AOVs go through it, so they line up.
pub(crate) fn camera_sample<'a>(
    camera: &Camera,
    sampler: &'a Sampler,
    (x, y): (u32, u32),
    sample: u32,
    pixel_centre: bool,
) -> (Ray, SampleStream<'a>) {
    let mut stream = SampleStream::new(sampler, y * camera.width + x, sample);
    let jitter = stream.next_points(1);
    let offset = if pixel_centre { glam::Vec2::splat(0.5) } else { jitter.get_2d(0) };
    (camera.ray(x as f32 + offset.x, y as f32 + offset.y), stream)
}

/// One sample per pixel: per tile, its values row by row and its rays; `None` as soon as
/// `stop_now` says so (checked before every pixel, and by integrators inside costly pixels).
fn render_pass<I: Integrator>(
    integrator: &I,
    world: &World,
    camera: &Camera,
    pass: &Pass,
    tiles: &[Tile],
    progress: &(dyn Fn(u64) + Sync),
    stop_now: &(dyn Fn() -> Option<StopReason> + Sync),
) -> Option<Vec<(Vec<Vec3>, u64)>> {
    tiles
        .par_iter()
        .map(|tile| {
            let stream = SampleStream::new(pass.sampler, 0, pass.sample);
            let stop = || stop_now().is_some();
            let mut ctx = SampleContext { stream, batch: OriginBatch::default(), rays: 0, stop: &stop };
            let mut values = Vec::with_capacity(((tile.x1 - tile.x0) * (tile.y1 - tile.y0)) as usize);
            for y in tile.y0..tile.y1 {
                for x in tile.x0..tile.x1 {
                    if stop_now().is_some() {
                        return None;
                    }
                    let (ray, stream) = camera_sample(camera, pass.sampler, (x, y), pass.sample, pass.pixel_centre);
                    ctx.stream = stream;
                    values.push(integrator.radiance(world, &ray, &mut ctx));
                }
            }
            progress(values.len() as u64);
            Some((values, ctx.rays))
        })
        .collect()
}

#[derive(Clone, Copy)]
struct Tile {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

fn tiles(width: u32, height: u32) -> Vec<Tile> {
    let mut out = Vec::new();
    for y0 in (0..height).step_by(TILE_SIZE as usize) {
        for x0 in (0..width).step_by(TILE_SIZE as usize) {
            out.push(Tile { x0, y0, x1: (x0 + TILE_SIZE).min(width), y1: (y0 + TILE_SIZE).min(height) });
        }
    }
    out
}
