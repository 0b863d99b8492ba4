//! What a render tells the user: a progress bar on a terminal, one closing line, and on request a
//! JSON file of statistics.

use lumiere::error::shown_path;
use std::io::IsTerminal;
use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};

use lumiere::integrators::{AmbientOcclusion, Direct, Technique};
use lumiere::render::unlit::{Unlit, is_black, unlit, why_black};
use lumiere::render::{RenderOptions, RenderOutput};
use lumiere::scene::camera::Camera;
use lumiere::world::World;
use lumiere::{Error, Result};

use crate::cli::output;
use crate::cli::technique_json::technique_json;

/// Milliseconds spent before rendering.
pub struct Timings {
    pub load_ms: f64,
    pub build_ms: f64,
}

/// A bar of pixel samples (`done` of `total`) with an ETA, on stderr when it is a terminal.
pub fn progress_bar(total: u64, done: u64) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    bar.set_position(done);
    if let Ok(style) = ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}") {
        bar.set_style(style);
    }
    bar
}

/// The closing line: what was rendered, why it stopped, time, rays and speed, where it went.
pub fn summary(options: &RenderOptions, camera: &Camera, output: &RenderOutput, threads: usize, path: &Path) {
    let noise = output.film.relative_error().map_or(String::new(), |e| format!(", relative error {e:.4}"));
    // A resumed checkpoint may hold more than --spp asked for (warned about when it was loaded).
    let asked = if options.spp == u32::MAX {
        "unlimited".to_string()
    } else {
        options.spp.max(output.film.samples).to_string()
    };
    let threads = if threads == 1 { "1 thread".to_string() } else { format!("{threads} threads") };
    output::note(format_args!(
        "{} {}x{}: {} after {} of {asked} spp{noise}; {:.1} ms ({threads}), {} rays, {:.1} Mrays/s -> {}",
        options.technique.name(),
        camera.width,
        camera.height,
        output.stop.describe(),
        output.film.samples,
        output.stats.elapsed.as_secs_f64() * 1e3,
        output.stats.rays,
        output.stats.mrays_per_second(),
        shown_path(path)
    ));
    if output.film.discarded > 0 {
        output::warn(format_args!("{} non-finite or negative samples were discarded", output.film.discarded));
    }
}

/// The statistics of a render as JSON text.
pub fn stats_json(
    world: &World,
    options: &RenderOptions,
    camera: &Camera,
    output: &RenderOutput,
    threads: usize,
    timings: &Timings,
) -> Result<String> {
    let stats = serde_json::json!({
        "scene": world.scene().name,
        "mode": options.technique.name(),
        "technique": technique_json(&options.technique),
        "samples": samples_per_camera_sample(&options.technique),
        "width": camera.width,
        "height": camera.height,
        "spp": output.film.samples,
        "spp_requested": options.spp,
        "sampler": format!("{:?}", options.sampler).to_lowercase(),
        "seed": options.seed,
        "threads": threads,
        "triangles": world.scene().mesh.triangle_count(),
        "lights": world.lights().lights().len(),
        "bvh_nodes": world.accel().node_count(),
        "isa": world.isa().name(),
        // The binary's commit (see build.rs): a benchmark's table names what it ran.
        "commit": env!("LUMIERE_COMMIT"),
        "load_ms": timings.load_ms,
        "build_ms": timings.build_ms,
        "render_ms": output.stats.elapsed.as_secs_f64() * 1e3,
        "rays": output.stats.rays,
        "mrays_per_s": output.stats.mrays_per_second(),
        "stop": output.stop.describe(),
        "relative_error": output.film.relative_error(),
        "discarded_samples": output.film.discarded,
    });
    let text = serde_json::to_string_pretty(&stats).map_err(|e| Error::invalid(format!("stats: {e}")))?;
    Ok(format!("{text}\n"))
}

/// `--samples` where the technique has it (null in the JSON otherwise).
fn samples_per_camera_sample(technique: &Technique) -> Option<u32> {
    match technique {
        Technique::Direct(Direct { samples, .. }) | Technique::AmbientOcclusion(AmbientOcclusion { samples, .. }) => {
            Some(*samples)
        }
        _ => None,
    }
}

/// Why an image may come out black, said before rendering: a technique that needs lights in a
/// scene that has none.
pub fn warn_if_unlit(world: &World, options: &RenderOptions) {
    let mode = options.technique.name();
    match unlit(world, &options.technique) {
        None => {}
        Some(Unlit::EmittersCannotEmit { materials }) => output::warn(format_args!(
            "no triangle of the emitting material{} {} can emit (none uses it, or only triangles of zero area or of an area too large for f32), so --mode {mode} renders black",
            if materials.len() == 1 { "" } else { "s" },
            materials.join(", ")
        )),
        Some(Unlit::NoEmitter { materials, more }) => {
            let more = if more > 0 { format!(" and {more} more") } else { String::new() };
            output::warn(format_args!(
                "the scene has no emitters (no material with Ke > 0), so --mode {mode} renders black; make one emit with --emission NAME=r,g,b (materials: {}{more}) or try --mode ao",
                materials.join(", ")
            ));
        }
    }
}

/// Why an image came out black, said after rendering: no camera ray saw anything lit.
pub fn warn_if_black(output: &RenderOutput, technique: &Technique) {
    if is_black(output) {
        output::warn(format_args!("the image is black: {} (--mode hits)", why_black(technique)));
    }
}
