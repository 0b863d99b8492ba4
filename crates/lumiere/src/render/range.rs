//! Rendering a range of passes on its own, so that a render can be split across processes or
//! machines (Python's `lumiere.distributed`) and still end with the bytes of a single-process one.
//!
//! A pass's values depend only on the pixel, the sample index and the options, so pass `k` renders
//! the same anywhere. What is not free is the sum: floating-point addition is not associative, so
//! per-range films summed together differ in the last bits from a film that added pass after pass.
//! Ranges therefore return each pass's raw samples ([`PassSamples`], 12 bytes a pixel), and the
//! caller adds them with [`Film::add_pass`] in pass order: the very additions the progressive loop
//! makes. `tests/integration/range.rs` checks the bytes.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

use glam::Vec3;

use super::film::PassSamples;
use super::pass::{Pass, pass_buffer, render_pass};
use super::{RenderOptions, StopReason};
use crate::error::{Error, Result};
use crate::integrators::Integrator;
use crate::sampler::Sampler;
use crate::scene::camera::Camera;
use crate::world::World;

/// Renders passes `first .. first + count` of the render `options` describes (same seed, sampler,
/// technique and pixel positions; `options.spp` is the whole render's, which decides pixel centres
/// versus jitter) on the current rayon pool. The budgets in `options` do not apply: a range is a
/// fixed amount of work, and stopping is its caller's decision.
///
/// `progress` is called after each tile with the samples it added. When `cancel` is set the pass in
/// flight is abandoned and the passes completed so far are returned, so the result may hold fewer
/// than `count` passes; it never holds a partial one.
///
/// [`Film::add_pass`]: super::film::Film::add_pass
pub fn render_pass_range(
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    first: u32,
    count: u32,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> Result<Vec<PassSamples>> {
    options.validate(camera)?;
    match first.checked_add(count) {
        Some(end) if end <= options.spp => {}
        _ => {
            return Err(Error::invalid(format!(
                "passes {first}..{} are outside a render of {} samples per pixel",
                u64::from(first) + u64::from(count),
                options.spp
            )));
        }
    }
    with_integrator!(&options.technique, integrator => {
        run_range(integrator, world, camera, options, first..first + count, progress, cancel)
    })
}

fn run_range<I: Integrator>(
    integrator: &I,
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    samples: Range<u32>,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> Result<Vec<PassSamples>> {
    let sampler = Sampler::new(options.sampler, options.seed);
    let pixel_centre = options.samples_pixel_centres();
    let stop_now = || cancel.load(Ordering::Relaxed).then_some(StopReason::Interrupted);
    // Grown pass by pass: a range of billions of passes (most of which a cancel will cut short)
    // must not ask for their records up front.
    let mut passes = Vec::new();
    for sample in samples {
        let pass = Pass { sampler: &sampler, sample, pixel_centre };
        let mut values = pass_buffer(camera.width, camera.height)?;
        let Some(rays) = render_pass(integrator, world, camera, &pass, &mut values, progress, &stop_now) else {
            break;
        };
        // In place: arrays and `Vec3` have the same size and alignment, so the buffer is reused.
        let values = values.into_iter().map(Vec3::from).collect();
        passes.push(PassSamples { sample, width: camera.width, height: camera.height, values, rays });
    }
    Ok(passes)
}
