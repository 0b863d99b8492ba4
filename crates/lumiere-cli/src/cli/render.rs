use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

use lumiere::accel::BuildPreset;
use lumiere::image_io::{PngEncoding, check_output_path, write_image};
use lumiere::integrators::{AmbientOcclusion, Direct, Hits, LightSampling, Materials, Shadows, Technique};
use lumiere::render::checkpoint::Checkpoint;
use lumiere::render::film::Film;
use lumiere::render::fingerprint::{options_fingerprint, scene_fingerprint};
use lumiere::render::{Hooks, RenderOptions, RenderStats, StopReason, render_progressive};
use lumiere::sampler::SamplerKind;
use lumiere::scene::camera::{Camera, Orbiter};
use lumiere::scene::{Scene, builtin};
use lumiere::util::fs::{check_writable, write_atomically};
use lumiere::world::World;
use lumiere::{Error, Result};

use super::args::{LightSamplingArg, ModeArg, RenderArgs, SamplerArg};

/// Exit code of a render stopped by SIGINT or SIGTERM (its image of completed samples is written).
pub const EXIT_INTERRUPTED: u8 = 3;

/// Set by the first SIGINT/SIGTERM; the render finishes cleanly. A second signal exits at once
/// (every file is written atomically, so nothing half-written is left either way).
static CANCEL: AtomicBool = AtomicBool::new(false);

/// Renders; returns the process exit code (0, or `EXIT_INTERRUPTED`).
pub fn run(args: &RenderArgs) -> Result<u8> {
    // Refuse bad output paths before spending minutes on a render.
    check_output_path(&args.output)?;
    for path in [&args.stats_json, &args.checkpoint].into_iter().flatten() {
        check_writable(path)?;
    }
    let pool = super::pool(args.threads)?;
    let threads = pool.current_num_threads();
    pool.install(|| render_in_pool(args, threads))
}

fn render_in_pool(args: &RenderArgs, threads: usize) -> Result<u8> {
    let load_start = Instant::now();
    let mut scene = match &args.scene {
        Some(path) => Scene::load(path)?,
        None => Scene::builtin()?,
    };
    for (name, ke) in &args.emission {
        scene.set_emission(name, *ke)?;
    }
    let load_ms = load_start.elapsed().as_secs_f64() * 1e3;
    for warning in &scene.warnings {
        eprintln!("lumiere: warning: {warning}");
    }
    let camera = make_camera(args, &scene)?;
    let options = render_options(args);
    let fingerprints = (scene_fingerprint(&scene), options_fingerprint(&options, &camera));
    let (film, stats) = match &args.resume {
        Some(path) => resume(path, fingerprints, options.seed)?,
        None => (Film::new(camera.width, camera.height)?, RenderStats::default()),
    };

    let build_start = Instant::now();
    let world = World::new(scene, BuildPreset::Default);
    let build_ms = build_start.elapsed().as_secs_f64() * 1e3;

    let pixels = u64::from(camera.width) * u64::from(camera.height);
    let bar = progress_bar(pixels * u64::from(options.spp), pixels * u64::from(film.samples));
    let png = if args.png_linear { PngEncoding::GkitLinear } else { PngEncoding::Srgb };
    if let Err(e) = ctrlc::set_handler(|| {
        if CANCEL.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    }) {
        eprintln!("lumiere: warning: cannot catch Ctrl-C ({e}); an interruption will lose the render");
    }
    let mut last_preview = Instant::now();
    let mut last_checkpoint = Instant::now();
    let mut pass_done = |film: &Film, stats: &RenderStats| -> Result<()> {
        if let Some(every) = args.preview_every
            && last_preview.elapsed().as_secs_f64() >= every
        {
            let image = film.image();
            write_image(&args.output, image.width, image.height, &image.pixels, png)?;
            last_preview = Instant::now();
        }
        if let Some(path) = &args.checkpoint
            && last_checkpoint.elapsed().as_secs_f64() >= args.checkpoint_every
        {
            save_checkpoint(path, fingerprints, options.seed, film, stats)?;
            last_checkpoint = Instant::now();
        }
        Ok(())
    };
    let hooks = Hooks { progress: &|n| bar.inc(n), pass_done: &mut pass_done, cancel: &CANCEL };
    let output = render_progressive(&world, &camera, &options, film, stats, hooks)?;
    bar.finish_and_clear();

    write_image(&args.output, output.image.width, output.image.height, &output.image.pixels, png)?;
    if let Some(path) = &args.checkpoint {
        save_checkpoint(path, fingerprints, options.seed, &output.film, &output.stats)?;
    }
    let render_ms = output.stats.elapsed.as_secs_f64() * 1e3;
    let noise = output.film.relative_error().map_or(String::new(), |e| format!(", relative error {e:.4}"));
    eprintln!(
        "lumiere: {} {}x{}: {} after {} of {} spp{noise}; {:.1} ms ({threads} threads), {} rays, {:.1} Mrays/s -> {}",
        options.technique.name(),
        camera.width,
        camera.height,
        output.stop.describe(),
        output.film.samples,
        options.spp,
        render_ms,
        output.stats.rays,
        output.stats.mrays_per_second(),
        args.output.display()
    );
    if output.film.discarded > 0 {
        eprintln!("lumiere: warning: {} non-finite or negative samples were discarded", output.film.discarded);
    }

    if let Some(path) = &args.stats_json {
        let stats = serde_json::json!({
            "scene": world.scene().name,
            "mode": options.technique.name(),
            "width": camera.width,
            "height": camera.height,
            "samples": args.samples,
            "spp": output.film.samples,
            "spp_requested": options.spp,
            "sampler": format!("{:?}", options.sampler).to_lowercase(),
            "seed": options.seed,
            "threads": threads,
            "triangles": world.scene().mesh.triangle_count(),
            "lights": world.lights().lights().len(),
            "bvh_nodes": world.bvh().nodes().len(),
            "load_ms": load_ms,
            "build_ms": build_ms,
            "render_ms": render_ms,
            "rays": output.stats.rays,
            "mrays_per_s": output.stats.mrays_per_second(),
            "stop": output.stop.describe(),
            "relative_error": output.film.relative_error(),
            "discarded_samples": output.film.discarded,
        });
        let text = serde_json::to_string_pretty(&stats).map_err(|e| Error::invalid(format!("stats: {e}")))?;
        write_atomically(path, format!("{text}\n").as_bytes())?;
    }
    Ok(if output.stop == StopReason::Interrupted { EXIT_INTERRUPTED } else { 0 })
}

fn render_options(args: &RenderArgs) -> RenderOptions {
    let samples = args.samples;
    let technique = match args.mode {
        ModeArg::Hits => Technique::Hits(Hits),
        ModeArg::Materials => Technique::Materials(Materials),
        ModeArg::Shadows => Technique::Shadows(Shadows),
        ModeArg::Direct => Technique::Direct(Direct {
            samples,
            light_sampling: match args.light_sampling {
                LightSamplingArg::PerLight => LightSampling::PerLight,
                LightSamplingArg::Power => LightSampling::Power,
            },
        }),
        ModeArg::Ao => Technique::AmbientOcclusion(AmbientOcclusion {
            samples,
            distance: args.ao_distance.unwrap_or(f32::INFINITY),
        }),
    };
    RenderOptions {
        technique,
        spp: args.spp,
        seed: args.seed,
        sampler: match args.sampler {
            SamplerArg::Independent => SamplerKind::Independent,
            SamplerArg::Sobol => SamplerKind::Sobol,
        },
        time_budget: args.time,
        noise_target: args.noise,
    }
}

/// Loads a checkpoint and refuses it unless it was made from the same scene and options.
fn resume(path: &std::path::Path, (scene, options): (u64, u64), seed: u64) -> Result<(Film, RenderStats)> {
    let checkpoint = Checkpoint::load(path)?;
    if checkpoint.scene_fingerprint != scene {
        return Err(Error::invalid(format!(
            "{}: cannot resume: the checkpoint was rendered from a different scene (geometry, materials or --emission)",
            path.display()
        )));
    }
    if checkpoint.options_fingerprint != options || checkpoint.seed != seed {
        return Err(Error::invalid(format!(
            "{}: cannot resume: the checkpoint was rendered with different options (mode, --samples, --seed, --sampler, --light-sampling, --ao-distance, camera or --size); only --spp and the budgets may change",
            path.display()
        )));
    }
    Ok((checkpoint.film, checkpoint.stats))
}

fn save_checkpoint(
    path: &std::path::Path,
    (scene, options): (u64, u64),
    seed: u64,
    film: &Film,
    stats: &RenderStats,
) -> Result<()> {
    let checkpoint =
        Checkpoint { scene_fingerprint: scene, options_fingerprint: options, seed, film: film.clone(), stats: *stats };
    checkpoint.save(path)
}

/// The camera the user asked for: an orbiter file, a look-at, the built-in scene's orbiter, or a
/// view that frames the whole scene.
fn make_camera(args: &RenderArgs, scene: &Scene) -> Result<Camera> {
    let (width, height) = args.size;
    if let Some(path) = &args.orbiter {
        return Ok(Camera::from_orbiter(&Orbiter::load(path)?, width, height));
    }
    if let (Some(eye), Some(target)) = (args.eye, args.target) {
        return Camera::look_at(eye, target, args.up, args.fov, width, height);
    }
    if args.scene.is_none() {
        return Ok(Camera::from_orbiter(&builtin::cornell_orbiter()?, width, height));
    }
    let bounds = scene.bounds();
    let cannot_frame = |why: &str| Error::invalid(format!("{}: {why}; give --eye and --target", scene.name));
    if bounds.is_empty() {
        return Err(cannot_frame("no vertices to frame"));
    }
    let radius = 0.5 * bounds.extent().length();
    let distance = radius / (0.5 * args.fov.to_radians()).sin();
    let target = bounds.center();
    let eye = target + glam::Vec3::Z * distance.max(1e-6);
    if !(eye.is_finite() && target.is_finite()) || eye == target {
        return Err(cannot_frame("its bounds are too large (or too far from the origin) to frame automatically"));
    }
    Camera::look_at(eye, target, args.up, args.fov, width, height)
}

fn progress_bar(total: u64, done: u64) -> ProgressBar {
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
