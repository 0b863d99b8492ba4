//! One pass: one camera sample per pixel, shaded straight into a buffer of the image's size, row
//! by row. Pixels are shaded tile by tile on rayon (tiles keep rays coherent, balance the cores and
//! notice a stop within milliseconds), and every tile is handed its own pieces of the buffer's
//! rows: disjoint borrows, so workers write each value where it belongs, with no lock, no buffer
//! per tile and no copy afterwards.

use glam::Vec2;
use rayon::prelude::*;

use super::StopReason;
use super::film::out_of_memory;
use crate::accel::OriginBatch;
use crate::error::Result;
use crate::integrators::{CameraPacket, Integrator, PACKET, SampleContext};
use crate::sampler::{SampleStream, Sampler};
use crate::scene::camera::Camera;
use crate::util::memory::{ask_for_huge_pages, try_zeroed_vec};
use crate::world::World;

/// Tiles are small enough to balance two cores and to notice an interruption within milliseconds,
/// and large enough that scheduling costs nothing.
const TILE_SIZE: usize = 16;

/// Pixels are shaded in square blocks of this side, [`PACKET`] to a block.
const BLOCK: usize = 4;
const _: () = assert!(BLOCK * BLOCK == PACKET && TILE_SIZE.is_multiple_of(BLOCK));

/// What every pixel of one pass shares.
pub(super) struct Pass<'a> {
    pub sampler: &'a Sampler,
    /// The camera sample index of this pass.
    pub sample: u32,
    /// Sample pixel centres (the lab's single ray) rather than jittered positions.
    pub pixel_centre: bool,
}

/// A buffer for one pass of a `width` x `height` image. Arrays rather than `Vec3`: a `vec!` of
/// zero arrays is allocated zeroed (calloc), its pages first touched by the workers that write
/// them, in parallel, where `vec![Vec3::ZERO; n]` fills every pixel on one thread first (4 ms at
/// 1024x768).
pub(super) fn pass_buffer(width: u32, height: u32) -> Result<Vec<[f32; 3]>> {
    let len = width as usize * height as usize;
    let buffer = try_zeroed_vec(len).ok_or_else(|| out_of_memory(width, height, len * 12, "a pass's buffer"))?;
    // Its 2,300 4 KB pages, zeroed at their first touch, were a sixth of a hard-shadow render.
    ask_for_huge_pages(buffer.as_ptr(), buffer.len());
    Ok(buffer)
}

/// The film position of sample `sample` of pixel `(x, y)` (its camera ray is `Camera::ray` there,
/// or `Camera::rays` for many), and that sample's random numbers with the position already drawn
/// from their first dimension (drawn even for pixel centres, so that the integrator's dimensions do
/// not depend on it). The one place a sample's position is decided: the render and its AOVs go
/// through it, so they line up.
pub(crate) fn film_position<'a>(
    camera: &Camera,
    sampler: &'a Sampler,
    (x, y): (u32, u32),
    sample: u32,
    pixel_centre: bool,
) -> (Vec2, SampleStream<'a>) {
    let mut stream = SampleStream::new(sampler, y * camera.width + x, sample);
    let jitter = stream.next_points(1);
    let offset = if pixel_centre { Vec2::splat(0.5) } else { jitter.get_2d(0) };
    (Vec2::new(x as f32 + offset.x, y as f32 + offset.y), stream)
}

/// Shades one sample per pixel into `buffer` (one value per pixel, row by row, as the integrator
/// returned it) and returns the rays traced; `None` as soon as `stop_now` says so (checked before
/// every block of pixels, and by integrators inside costly pixels), the buffer then holding part of a pass.
pub(super) fn render_pass<I: Integrator>(
    integrator: &I,
    world: &World,
    camera: &Camera,
    pass: &Pass,
    buffer: &mut [[f32; 3]],
    progress: &(dyn Fn(u64) + Sync),
    stop_now: &(dyn Fn() -> Option<StopReason> + Sync),
) -> Option<u64> {
    let width = camera.width as usize;
    debug_assert_eq!(buffer.len(), width * camera.height as usize);
    let shade = |tile: Tile| shade_tile(integrator, world, camera, pass, tile, progress, stop_now);
    buffer
        .par_chunks_mut(width * TILE_SIZE)
        .enumerate()
        .map(|(band, rows)| {
            // Each row of the band cut at the tile edges, the pieces regrouped tile by tile.
            let height = rows.len() / width;
            let mut cut: Vec<_> = rows.chunks_mut(width).map(|row| row.chunks_mut(TILE_SIZE)).collect();
            let columns = width.div_ceil(TILE_SIZE);
            let mut pieces = Vec::with_capacity(columns * height);
            for _ in 0..columns {
                pieces.extend(cut.iter_mut().filter_map(Iterator::next));
            }
            pieces
                .par_chunks_mut(height)
                .enumerate()
                .map(|(column, rows)| shade(Tile { x0: column * TILE_SIZE, y0: band * TILE_SIZE, rows }))
                .try_reduce(|| 0, |a, b| Some(a + b))
        })
        .try_reduce(|| 0, |a, b| Some(a + b))
}

/// A tile of the image: its top left pixel and its rows, each a piece of a row of the pass buffer.
struct Tile<'a, 'b> {
    x0: usize,
    y0: usize,
    rows: &'a mut [&'b mut [[f32; 3]]],
}

/// Shades the pixels of `tile` block by block (4x4 pixels, [`PACKET`] lanes, traced together where
/// the integrator can); the rays traced, or `None` if `stop_now` stopped it (checked before every
/// block and after the last).
fn shade_tile<I: Integrator>(
    integrator: &I,
    world: &World,
    camera: &Camera,
    pass: &Pass,
    tile: Tile,
    progress: &(dyn Fn(u64) + Sync),
    stop_now: &(dyn Fn() -> Option<StopReason> + Sync),
) -> Option<u64> {
    let stream = SampleStream::new(pass.sampler, 0, pass.sample);
    let stop = || stop_now().is_some();
    let mut ctx = SampleContext { stream, batch: OriginBatch::default(), rays: 0, stop: &stop };
    let mut pixels = 0;
    for by in (0..tile.rows.len()).step_by(BLOCK) {
        for bx in (0..tile.rows[by].len()).step_by(BLOCK) {
            if stop_now().is_some() {
                return None;
            }
            // Lane `dy * BLOCK + dx` is pixel (bx + dx, by + dy) of the tile, if the tile has it.
            let pixel = |lane: usize| (bx + lane % BLOCK, by + lane / BLOCK);
            let inside = |(x, y): (usize, usize)| y < tile.rows.len() && x < tile.rows[y].len();
            let live = (0..PACKET).fold(0u32, |m, lane| m | u32::from(inside(pixel(lane))) << lane);
            // A plain loop: built by `array::from_fn`, the samples were left to a call per lane
            // whenever the codegen units fell otherwise (`--mode hits` 20% slower).
            let (mut xs, mut ys, mut streams) = ([0.0; PACKET], [0.0; PACKET], [stream; PACKET]);
            for lane in 0..PACKET {
                // Dead lanes repeat the block's first pixel (always inside the tile).
                let (x, y) = if live & (1 << lane) != 0 { pixel(lane) } else { (bx, by) };
                let image_pixel = ((tile.x0 + x) as u32, (tile.y0 + y) as u32);
                let (position, stream) =
                    film_position(camera, pass.sampler, image_pixel, pass.sample, pass.pixel_centre);
                (xs[lane], ys[lane], streams[lane]) = (position.x, position.y, stream);
            }
            let rays = if I::PACKETS {
                world.simd(
                    #[inline(always)]
                    || camera.rays(&xs, &ys),
                )
            } else {
                camera.rays(&xs, &ys)
            };
            let packet = CameraPacket { rays, streams, live };
            let radiance = integrator.radiance_packet(world, &packet, &mut ctx);
            for lane in packet.lanes() {
                let (x, y) = pixel(lane);
                tile.rows[y][x] = radiance[lane].to_array();
            }
            pixels += u64::from(live.count_ones());
        }
    }
    // An integrator that saw the stop inside the tile's last block returned early, leaving part of
    // its pixels' samples out: the tile is not whole. The flags never clear, so a stop unseen here
    // was not seen inside the blocks either.
    if stop_now().is_some() {
        return None;
    }
    progress(pixels);
    Some(ctx.rays)
}
