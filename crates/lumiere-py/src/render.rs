//! `render`: a whole render on a pool of `threads`, with the GIL released (see `watch.rs`), and the
//! AOVs asked for; returns the image and AOVs as float32 bytes and the render's statistics.

use lumiere::render::aov::render_aovs;
use lumiere::render::film::Film;
use lumiere::render::forecast::{NoiseForecast, shown_number};
use lumiere::render::unlit::{Unlit, is_black, unlit, why_black};
use lumiere::render::{Hooks, RenderStats, StopReason, render_progressive};
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyDict};

use crate::camera::PyCamera;
use crate::options::PyOptions;
use crate::pixels::to_bytearray;
use crate::pools;
use crate::scene::PyScene;
use crate::watch::{self, Watch};

type Rendered<'py> = (Bound<'py, PyByteArray>, Vec<Bound<'py, PyByteArray>>, Bound<'py, PyDict>);

#[pyfunction]
#[pyo3(signature = (scene, camera, options, threads, aovs, progress=None, stacklevel=1))]
#[expect(clippy::too_many_arguments, reason = "Python's arguments, one each")]
pub fn render<'py>(
    py: Python<'py>,
    scene: &PyScene,
    camera: &PyCamera,
    options: &PyOptions,
    threads: usize,
    aovs: Vec<String>,
    progress: Option<Bound<'py, PyAny>>,
    stacklevel: i32,
) -> PyResult<Rendered<'py>> {
    let aovs = crate::aovs::parse(&aovs)?;
    // Owned by the render's thread (see `watch::run`).
    let (world, camera, options) = (scene.world.clone(), camera.camera.clone(), options.options.clone());
    // Before rendering: a huge image's AOVs aborted the interpreter once rendered.
    crate::aovs::check_fit(camera.width, camera.height, aovs.len())?;
    let pool = pools::for_render(py, threads)?;
    let threads = pool.current_num_threads();
    let pixels = u64::from(camera.width) * u64::from(camera.height);
    let total = (options.spp != u32::MAX).then(|| pixels * u64::from(options.spp));
    let work = move |watch: &Watch| {
        let (world, camera, options) = (&*world, &camera, &options);
        pool.install(|| {
            let film = Film::new(camera.width, camera.height)?;
            let warn = |message: String| watch.warnings.lock().unwrap_or_else(|e| e.into_inner()).push(message);
            if let Some(reason) = unlit(world, &options.technique) {
                warn(unlit_message(&reason, options.technique.name()));
            }
            let count = |n| watch.count(n);
            let spp = (options.spp != u32::MAX).then_some(options.spp);
            let mut forecast = NoiseForecast::new(options.noise_target, spp, options.time_budget, film.samples);
            let mut pass_done = |film: &Film, _: &RenderStats| {
                if let Some(report) = forecast.as_mut().and_then(|forecast| forecast.after_pass(film)) {
                    let message = format!(
                        "noise={}: {} (time= or spp= bound it)",
                        shown_number(report.target),
                        report.describe()
                    );
                    warn(message);
                }
                Ok(())
            };
            let hooks = Hooks { progress: &count, pass_done: &mut pass_done, cancel: &watch.cancel };
            let output = render_progressive(world, camera, options, film, RenderStats::default(), hooks)?;
            // As the CLI: a budget spent before the first pass completed leaves no image (a black
            // one came back, as if rendered). Interrupted, `watch::run` raises KeyboardInterrupt.
            if output.film.samples == 0 && !matches!(output.stop, StopReason::Completed | StopReason::Interrupted) {
                return Err(lumiere::Error::invalid(format!(
                    "{} before the first pass completed, so there is no image: one pass takes longer than time=; give more time or fewer samples",
                    output.stop.describe()
                )));
            }
            if is_black(&output) {
                warn(format!("the image is black: {} (mode='hits')", why_black(&options.technique)));
            }
            // Empty when cancelled: `watch::run` then raises, and nothing is returned.
            let buffers = if aovs.is_empty() {
                Vec::new()
            } else {
                render_aovs(world, camera, options, &aovs, &watch.cancel).unwrap_or_default()
            };
            Ok((output, buffers))
        })
    };
    let (output, buffers) = watch::run(py, total, progress.as_ref(), stacklevel, work)?;
    let image = to_bytearray(py, &output.image.pixels)?;
    let buffers = buffers.iter().map(|b| to_bytearray(py, b)).collect::<PyResult<Vec<_>>>()?;
    let stats = PyDict::new(py);
    stats.set_item("samples", output.film.samples)?;
    stats.set_item("rays", output.stats.rays)?;
    stats.set_item("seconds", output.stats.elapsed.as_secs_f64())?;
    stats.set_item("mrays_per_second", output.stats.mrays_per_second())?;
    stats.set_item("stop", output.stop.describe())?;
    stats.set_item("discarded", output.film.discarded)?;
    stats.set_item("threads", threads)?;
    stats.set_item("relative_error", output.film.relative_error())?;
    Ok((image, buffers, stats))
}

/// Why `mode` renders black for want of lights, in the package's words (the CLI says it with its
/// flags).
fn unlit_message(reason: &Unlit, mode: &str) -> String {
    match reason {
        Unlit::EmittersCannotEmit { materials } => format!(
            "no triangle of the emitting material{} {} can emit (none uses it, or only triangles of zero area or of an area too large for f32), so mode={mode:?} renders black",
            if materials.len() == 1 { "" } else { "s" },
            materials.join(", ")
        ),
        Unlit::NoEmitter { materials, more } => format!(
            "the scene has no emitters (no material with ke > 0), so mode={mode:?} renders black; make one emit with load(..., emission={{name: (r, g, b)}}) or a material's ke (materials: {}{}), or try mode='ao'",
            materials.join(", "),
            if *more > 0 { format!(" and {more} more") } else { String::new() }
        ),
    }
}
