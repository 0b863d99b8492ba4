//! Progressive rendering: passes of one camera sample per pixel over the whole image, each pass
//! split into tiles scheduled with rayon. A pixel's samples depend only on the pixel, the sample
//! index and the options, never on the thread that ran them, and passes are accumulated in order,
//! so images are identical for any thread count and for any stopping point.

pub mod checkpoint;
pub mod film;
pub mod fingerprint;

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use glam::Vec3;
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::integrators::{
    AmbientOcclusion, Direct, Hits, Integrator, LightSampling, Materials, Mode, SampleContext, Shadows, dims,
};
use crate::sampler::{Sampler, SamplerKind};
use crate::scene::camera::Camera;
use crate::world::World;
use film::{Film, Image};

/// Tiles are small enough to balance two cores and to notice an interruption within milliseconds,
/// and large enough that scheduling costs nothing.
const TILE_SIZE: u32 = 16;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub mode: Mode,
    /// Samples per light (or in total, with power light sampling) or per hemisphere.
    pub samples: u32,
    /// Camera samples per pixel to reach; 1 is the lab's single ray through the pixel centre,
    /// more are jittered inside the pixel.
    pub spp: u32,
    pub seed: u64,
    pub sampler: SamplerKind,
    pub light_sampling: LightSampling,
    /// Ambient occlusion rays stop at this distance (infinite: visibility of the sky).
    pub ao_distance: f32,
    /// Stop after the pass that crosses this much rendering time.
    pub time_budget: Option<Duration>,
    /// Stop once the image's estimated relative standard error is below this.
    pub noise_target: Option<f64>,
}

impl RenderOptions {
    /// The options of a lab image: one camera ray per pixel centre, independent samples, no budget.
    pub fn new(mode: Mode, samples: u32) -> Self {
        RenderOptions {
            mode,
            samples,
            spp: 1,
            seed: 0,
            sampler: SamplerKind::Independent,
            light_sampling: LightSampling::PerLight,
            ao_distance: f32::INFINITY,
            time_budget: None,
            noise_target: None,
        }
    }

    fn validate(&self, camera: &Camera) -> Result<()> {
        if camera.width == 0 || camera.height == 0 {
            return Err(Error::invalid(format!("image size {}x{} has no pixels", camera.width, camera.height)));
        }
        if self.samples == 0 {
            return Err(Error::invalid("--samples must be at least 1"));
        }
        if self.spp == 0 {
            return Err(Error::invalid("--spp must be at least 1"));
        }
        if self.ao_distance.is_nan() || self.ao_distance <= 0.0 {
            return Err(Error::invalid(format!("--ao-distance must be positive, got {}", self.ao_distance)));
        }
        if self.noise_target.is_some_and(|n| n.is_nan() || n <= 0.0) {
            return Err(Error::invalid("--noise must be positive"));
        }
        Ok(())
    }
}

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
    let n = options.samples;
    match options.mode {
        Mode::Hits => run_passes(&Hits, world, camera, options, film, stats, hooks),
        Mode::Materials => run_passes(&Materials, world, camera, options, film, stats, hooks),
        Mode::Shadows => run_passes(&Shadows, world, camera, options, film, stats, hooks),
        Mode::Direct => {
            run_passes(&Direct::new(world, n, options.light_sampling), world, camera, options, film, stats, hooks)
        }
        Mode::AmbientOcclusion => {
            let ao = AmbientOcclusion { samples: n, distance: options.ao_distance };
            run_passes(&ao, world, camera, options, film, stats, hooks)
        }
    }
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
    let stop = loop {
        if film.samples >= options.spp {
            break StopReason::Completed;
        }
        let Some(pass) = render_pass(integrator, world, camera, &sampler, &tiles, film.samples, options.spp, &hooks)
        else {
            break StopReason::Interrupted;
        };
        for (tile, (values, rays)) in tiles.iter().zip(pass) {
            film.add_tile(tile.x0, tile.y0, tile.x1 - tile.x0, &values);
            stats.rays += rays;
        }
        film.samples += 1;
        stats.elapsed = before + start.elapsed();
        (hooks.pass_done)(&film, &stats)?;
        if film.samples >= options.spp {
            break StopReason::Completed;
        }
        if options.time_budget.is_some_and(|budget| start.elapsed() >= budget) {
            break StopReason::TimeBudget;
        }
        if let (Some(target), Some(error)) = (options.noise_target, film.relative_error())
            && error <= target
        {
            break StopReason::NoiseTarget;
        }
        if hooks.cancel.load(Ordering::Relaxed) {
            break StopReason::Interrupted;
        }
    };
    stats.elapsed = before + start.elapsed();
    Ok(RenderOutput { image: film.image(), film, stats, stop })
}

/// One sample per pixel (sample index `sample`): per tile, its values row by row and its rays;
/// `None` if cancelled before the pass completed.
#[expect(clippy::too_many_arguments, reason = "the pass's whole context, passed once per pass")]
fn render_pass<I: Integrator>(
    integrator: &I,
    world: &World,
    camera: &Camera,
    sampler: &Sampler,
    tiles: &[Tile],
    sample: u32,
    spp: u32,
    hooks: &Hooks,
) -> Option<Vec<(Vec<Vec3>, u64)>> {
    tiles
        .par_iter()
        .map(|tile| {
            if hooks.cancel.load(Ordering::Relaxed) {
                return None;
            }
            let mut ctx = SampleContext::new(sampler);
            ctx.sample = sample;
            let mut values = Vec::with_capacity(((tile.x1 - tile.x0) * (tile.y1 - tile.y0)) as usize);
            for y in tile.y0..tile.y1 {
                for x in tile.x0..tile.x1 {
                    ctx.pixel = y * camera.width + x;
                    // One sample: the pixel centre, as the lab did; more: jittered in the pixel.
                    let offset = if spp == 1 { glam::Vec2::splat(0.5) } else { ctx.point_2d(dims::PIXEL, 0, 1) };
                    let ray = camera.ray(x as f32 + offset.x, y as f32 + offset.y);
                    values.push(integrator.radiance(world, &ray, &mut ctx));
                }
            }
            (hooks.progress)(values.len() as u64);
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
