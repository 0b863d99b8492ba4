//! Tiles of pixels scheduled with rayon; each pixel's value depends only on the pixel and the
//! options, never on which thread ran it, so images are identical for any thread count.

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

/// Tiles are small enough to balance two cores on a 1024x768 image and large enough that
/// scheduling costs nothing.
const TILE_SIZE: u32 = 16;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    pub mode: Mode,
    /// Samples per light (or in total, with power light sampling) or per hemisphere.
    pub samples: u32,
    /// Camera samples per pixel; 1 is the lab's single ray through the pixel centre, more are
    /// jittered inside the pixel.
    pub spp: u32,
    pub seed: u64,
    pub sampler: SamplerKind,
    pub light_sampling: LightSampling,
    /// Ambient occlusion rays stop at this distance (infinite: visibility of the sky).
    pub ao_distance: f32,
}

impl RenderOptions {
    /// The options of a lab image: one camera ray per pixel centre, independent samples.
    pub fn new(mode: Mode, samples: u32) -> Self {
        RenderOptions {
            mode,
            samples,
            spp: 1,
            seed: 0,
            sampler: SamplerKind::Independent,
            light_sampling: LightSampling::PerLight,
            ao_distance: f32::INFINITY,
        }
    }
}

/// Linear RGB pixels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub image: Image,
    /// Every ray traced: camera rays and shadow rays.
    pub rays: u64,
    pub elapsed: Duration,
}

impl RenderOutput {
    pub fn mrays_per_second(&self) -> f64 {
        self.rays as f64 / self.elapsed.as_secs_f64().max(1e-9) / 1e6
    }
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

/// Renders on the current rayon pool; `progress(pixels_done)` is called after each tile.
pub fn render(
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<RenderOutput> {
    if camera.width == 0 || camera.height == 0 {
        return Err(Error::invalid(format!("image size {}x{} has no pixels", camera.width, camera.height)));
    }
    if options.samples == 0 {
        return Err(Error::invalid("--samples must be at least 1"));
    }
    if options.spp == 0 {
        return Err(Error::invalid("--spp must be at least 1"));
    }
    if options.ao_distance.is_nan() || options.ao_distance <= 0.0 {
        return Err(Error::invalid(format!("--ao-distance must be positive, got {}", options.ao_distance)));
    }
    let n = options.samples;
    Ok(match options.mode {
        Mode::Hits => render_with(&Hits, world, camera, options, progress),
        Mode::Materials => render_with(&Materials, world, camera, options, progress),
        Mode::Shadows => render_with(&Shadows, world, camera, options, progress),
        Mode::Direct => render_with(&Direct::new(world, n, options.light_sampling), world, camera, options, progress),
        Mode::AmbientOcclusion => {
            let ao = AmbientOcclusion { samples: n, distance: options.ao_distance };
            render_with(&ao, world, camera, options, progress)
        }
    })
}

/// The estimate of pixel `(x, y)`: the mean over its camera samples.
#[inline]
fn render_pixel<I: Integrator>(
    integrator: &I,
    world: &World,
    camera: &Camera,
    spp: u32,
    (x, y): (u32, u32),
    ctx: &mut SampleContext,
) -> Vec3 {
    ctx.pixel = y * camera.width + x;
    let mut sum = Vec3::ZERO;
    for sample in 0..spp {
        ctx.sample = sample;
        let offset = if spp == 1 { glam::Vec2::splat(0.5) } else { ctx.point_2d(dims::PIXEL, 0, 1) };
        let ray = camera.ray(x as f32 + offset.x, y as f32 + offset.y);
        sum += integrator.radiance(world, &ray, ctx);
    }
    sum / spp as f32
}

fn render_with<I: Integrator>(
    integrator: &I,
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    progress: &(dyn Fn(u64) + Sync),
) -> RenderOutput {
    let start = Instant::now();
    let sampler = Sampler::new(options.sampler, options.seed);
    let tiles = tiles(camera.width, camera.height);
    let rendered: Vec<(Vec<Vec3>, u64)> = tiles
        .par_iter()
        .map(|tile| {
            let mut ctx = SampleContext::new(&sampler);
            let mut pixels = Vec::with_capacity(((tile.x1 - tile.x0) * (tile.y1 - tile.y0)) as usize);
            for y in tile.y0..tile.y1 {
                for x in tile.x0..tile.x1 {
                    pixels.push(render_pixel(integrator, world, camera, options.spp, (x, y), &mut ctx));
                }
            }
            progress(pixels.len() as u64);
            (pixels, ctx.rays)
        })
        .collect();

    let (width, height) = (camera.width, camera.height);
    let mut image = Image { width, height, pixels: vec![Vec3::ZERO; width as usize * height as usize] };
    let mut rays = 0;
    for (tile, (pixels, tile_rays)) in tiles.iter().zip(rendered) {
        rays += tile_rays;
        let tile_width = (tile.x1 - tile.x0) as usize;
        for (row, chunk) in pixels.chunks_exact(tile_width).enumerate() {
            let start = (tile.y0 as usize + row) * width as usize + tile.x0 as usize;
            image.pixels[start..start + tile_width].copy_from_slice(chunk);
        }
    }
    RenderOutput { image, rays, elapsed: start.elapsed() }
}
