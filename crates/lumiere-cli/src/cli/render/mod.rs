//! `lumiere render`: arguments → options → scene → world → passes → image file and statistics.

mod camera;
mod checkpointing;
mod forecast;
mod oidn;
mod options;
mod paths;
mod report;
mod signals;

use std::sync::atomic::AtomicBool;
use std::time::Instant;

use glam::Vec3;
use lumiere::Result;
use lumiere::accel::BuildPreset;
use lumiere::error::{Error, shown_name, shown_path};
use lumiere::image_io::{
    ExrLayer, NOISY_LAYER, PngEncoding, PngStyle, RGB_CHANNELS, Tonemap, write_exr_with_layers, write_image,
};
use lumiere::render::aov::{Aov, render_aovs};
use lumiere::render::film::Film;
use lumiere::render::fingerprint::{Fingerprints, scene_fingerprint};
use lumiere::render::{Hooks, RenderOptions, RenderOutput, RenderStats, StopReason, render_progressive};
use lumiere::scene::Scene;
use lumiere::scene::camera::Camera;
use lumiere::util::write::write_atomically;
use lumiere::world::World;

use super::args::{ModeArg, RenderArgs, STDOUT_ARG, TonemapArg};
use super::output;
use report::Timings;

/// Exit code of a render stopped by SIGINT, SIGTERM or SIGHUP (its image of completed samples is written).
pub const EXIT_INTERRUPTED: u8 = 3;

/// Renders; returns the process exit code (0, or `EXIT_INTERRUPTED`).
pub fn run(args: &RenderArgs) -> Result<u8> {
    signals::install();
    // Refuse bad or clashing paths before spending minutes on a render.
    paths::check(args)?;
    // Likewise a denoiser that is not there.
    let denoiser = if args.denoise { Some(oidn::Oidn::load()?) } else { None };
    let pool = lumiere::util::threads::pool(args.threads)?;
    let threads = pool.current_num_threads();
    pool.install(|| render(args, threads, denoiser.as_ref()))
}

fn render(args: &RenderArgs, threads: usize, denoiser: Option<&oidn::Oidn>) -> Result<u8> {
    for ignored in options::ignored_flags(args) {
        output::warn(ignored);
    }
    let isa = super::isa::choose(args.isa)?;
    let load_start = Instant::now();
    let scene = load_scene(args)?;
    let load_ms = load_start.elapsed().as_secs_f64() * 1e3;
    paths::check_against_sources(args, &scene)?;
    let camera = camera::from_args(args, &scene)?;
    let options = options::from_args(args);
    check_memory_for_outputs(args, &camera)?;

    let build_start = Instant::now();
    let world = World::with_isa(scene, BuildPreset::Default, isa);
    for warning in world.warnings() {
        output::warn(warning);
    }
    let timings = Timings { load_ms, build_ms: build_start.elapsed().as_secs_f64() * 1e3 };

    // After the build: the scene's fingerprint holds its decoded textures' bytes.
    let fingerprints = Fingerprints::new(scene_fingerprint(&world), &options, &camera);
    let (film, stats) = checkpointing::start(&fingerprints, args.resume.as_deref(), &camera)?;
    if let Some(resume) = args.resume.as_deref().filter(|_| film.samples > options.spp) {
        // Samples cannot be taken back out of a film: say that the image will have them all.
        output::warn(format_args!(
            "{} already holds {} spp, more than --spp {}: nothing is added, and the image keeps all {}",
            shown_path(resume),
            film.samples,
            options.spp,
            film.samples
        ));
    }

    report::warn_if_unlit(&world, &options);
    signals::rendering_starts();
    let output = render_passes(args, &world, &camera, &options, &fingerprints, film, stats)?;
    if output.film.samples == 0 {
        return nothing_rendered(args, &output);
    }
    report::warn_if_black(&output, &options.technique);
    write_output(args, &world, &camera, &options, &output, denoiser)?;
    // Its error (a full disk) comes after the image, the summary and the statistics are out.
    let checkpoint =
        args.checkpoint.as_ref().map(|path| fingerprints.checkpoint(output.film.clone(), output.stats).save(path));
    report::summary(&options, &camera, &output, threads, &args.output);
    if let Some(path) = &args.stats_json {
        let json = report::stats_json(&world, &options, &camera, &output, threads, &timings)?;
        if path.as_os_str() == STDOUT_ARG {
            output::write_stdout(json.as_bytes())?;
        } else {
            write_atomically(path, json.as_bytes())?;
        }
    }
    checkpoint.transpose()?;
    Ok(if output.stop == StopReason::Interrupted { EXIT_INTERRUPTED } else { 0 })
}

/// A render stopped before its first pass completed writes nothing: its image would be black and
/// would replace whatever the output file held (and a checkpoint of no samples is worth nothing).
/// Interrupted, it exits as interrupted; out of time, it is an error, since the image asked for
/// was not made.
fn nothing_rendered(args: &RenderArgs, output: &RenderOutput) -> Result<u8> {
    let path = shown_path(&args.output);
    if output.stop == StopReason::Interrupted {
        output::warn(format_args!(
            "interrupted before the first pass completed: nothing was written ({path} is left as it was)"
        ));
        return Ok(EXIT_INTERRUPTED);
    }
    Err(Error::invalid(format!(
        "{path}: {} before the first pass completed, so nothing was written: one pass takes longer than --time; give more time or fewer --samples",
        output.stop.describe()
    )))
}

/// The scene file or the built-in scene, with `--emission` applied and load warnings shown.
fn load_scene(args: &RenderArgs) -> Result<Scene> {
    // Two values for one material, refused before loading: which one was meant?
    let names: Vec<&String> = args.emission.iter().map(|(name, _)| name).collect();
    if let Some(name) = first_repeat(&names) {
        return Err(Error::invalid(format!("--emission {} is given twice", shown_name(name))));
    }
    let mut scene = match &args.scene {
        Some(path) => Scene::load(path)?,
        None => Scene::builtin()?,
    };
    for (name, ke) in &args.emission {
        scene.set_emission(name, *ke)?;
    }
    for warning in &scene.warnings {
        output::warn(format_args!("{warning}"));
    }
    scene.check_has_faces()?;
    Ok(scene)
}

/// The first item given a second time (an option that names one thing twice).
fn first_repeat<T: PartialEq>(items: &[T]) -> Option<&T> {
    items.iter().enumerate().find(|(i, item)| items[..*i].contains(item)).map(|(_, item)| item)
}

/// Runs the progressive passes with a progress bar, previews and checkpoints between passes, and
/// the signal handler's cancel flag.
fn render_passes(
    args: &RenderArgs,
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    fingerprints: &Fingerprints,
    film: Film,
    stats: RenderStats,
) -> Result<RenderOutput> {
    let pixels = u64::from(camera.width) * u64::from(camera.height);
    let bar = report::progress_bar(pixels * u64::from(options.spp), pixels * u64::from(film.samples));
    let mut last_preview = Instant::now();
    let mut last_checkpoint = Instant::now();
    let (mut preview_failed, mut checkpoint_failed) = (false, false);
    let mut forecast = forecast::noise_forecast(args, film.samples);
    let mut pass_done = |film: &Film, stats: &RenderStats| -> Result<()> {
        if let Some(forecast) = &mut forecast {
            forecast::after_pass(forecast, film);
        }
        if let Some(every) = args.preview_every
            && last_preview.elapsed().as_secs_f64() >= every
        {
            // As a checkpoint's: a preview that cannot be written (a full disk for a moment) costs
            // a warning, not the render; the final image's write reports its own error.
            let image = film.image();
            if let Err(e) = write_image(&args.output, image.width, image.height, &image.pixels, png_style(args))
                && !std::mem::replace(&mut preview_failed, true)
            {
                output::warn(format_args!(
                    "{e}: the preview was not written after pass {}; the render goes on, and any image already there is left as it was",
                    film.samples
                ));
            }
            last_preview = Instant::now();
        }
        if let Some(path) = &args.checkpoint
            && last_checkpoint.elapsed().as_secs_f64() >= args.checkpoint_every.unwrap_or(0.0)
        {
            // A checkpoint that cannot be written (a full disk) must not cost the render: the
            // passes go on to the image, the checkpoint written last stays as it was, and the
            // final checkpoint's error, after the image, makes the exit code.
            if let Err(e) = fingerprints.checkpoint(film.clone(), *stats).save(path)
                && !std::mem::replace(&mut checkpoint_failed, true)
            {
                output::warn(format_args!(
                    "{e}: the checkpoint was not updated after pass {}; the render goes on, and any checkpoint already there is left as it was",
                    film.samples
                ));
            }
            last_checkpoint = Instant::now();
        }
        Ok(())
    };
    let hooks = Hooks { progress: &|n| bar.inc(n), pass_done: &mut pass_done, cancel: &signals::CANCEL };
    let output = render_progressive(world, camera, options, film, stats, hooks);
    bar.finish_and_clear();
    output
}

/// Refuses, before rendering, a render whose film and outputs together cannot fit in memory: the
/// film is checked alone when it is made, but AOVs, a denoised image and a checkpoint's encoding
/// need buffers as large, allocated only once the passes are done (a 4000x3000 render with three
/// AOVs under a 1.5 GB limit rendered, then aborted).
fn check_memory_for_outputs(args: &RenderArgs, camera: &Camera) -> Result<()> {
    // Bytes a pixel costs: an AOV's buffer, its channels copied for the EXR writer and encoded
    // (12 each); with any layer, the image's own copy and encoding; the denoised image; a
    // checkpoint's encoding of the film's four f64 values.
    let mut layers = args.aov.len() as u64;
    if args.denoise {
        layers += [Aov::Albedo, Aov::Normal].iter().filter(|aov| !args.aov.contains(aov)).count() as u64;
    }
    let mut extra = layers * 36;
    let mut extras = Vec::new();
    if layers > 0 {
        extra += 24;
        extras.push("AOVs");
    }
    if args.denoise {
        extra += 12;
        extras.push("denoised image");
    }
    if args.checkpoint.is_some() {
        extra += 32;
        extras.push("checkpoint");
    }
    if extras.is_empty() {
        return Ok(());
    }
    lumiere::render::film::check_memory(camera.width, camera.height, extra, &format!(" with its {}", extras.join(", ")))
}

/// The image (denoised with `--denoise`), with its AOVs as extra EXR channels when asked for, and
/// the noisy image as the `noisy` layer of a denoised EXR.
fn write_output(
    args: &RenderArgs,
    world: &World,
    camera: &Camera,
    options: &RenderOptions,
    output: &RenderOutput,
    denoiser: Option<&oidn::Oidn>,
) -> Result<()> {
    let image = &output.image;
    let mut wanted = args.aov.clone();
    if denoiser.is_some() {
        for aov in [Aov::Albedo, Aov::Normal] {
            if !wanted.contains(&aov) {
                wanted.push(aov);
            }
        }
    }
    // Not cancelled by a second Ctrl-C: the image written after an interrupted render needs them.
    let never = AtomicBool::new(false);
    let buffers = if wanted.is_empty() {
        Vec::new()
    } else {
        render_aovs(world, camera, options, &wanted, &never).unwrap_or_default()
    };
    let buffer = |aov: Aov| -> &[Vec3] {
        let index = wanted.iter().position(|w| *w == aov).expect("the AOV was asked for");
        &buffers[index]
    };
    let denoised = match denoiser {
        Some(oidn) => {
            let start = Instant::now();
            let pixels =
                oidn.denoise(image.width, image.height, &image.pixels, buffer(Aov::Albedo), buffer(Aov::Normal))?;
            output::note(format_args!("denoised in {:.1} ms", start.elapsed().as_secs_f64() * 1e3));
            Some(pixels)
        }
        None => None,
    };
    let pixels = denoised.as_deref().unwrap_or(&image.pixels);
    let mut layers: Vec<ExrLayer> = args
        .aov
        .iter()
        .map(|&aov| ExrLayer { name: aov.name(), channels: aov.exr_channels(), pixels: buffer(aov) })
        .collect();
    let exr = args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if denoised.is_some() && exr {
        layers.push(ExrLayer { name: NOISY_LAYER, channels: RGB_CHANNELS, pixels: &image.pixels });
    }
    if layers.is_empty() {
        return write_image(&args.output, image.width, image.height, pixels, png_style(args));
    }
    write_exr_with_layers(&args.output, image.width, image.height, pixels, &layers)
}

fn png_style(args: &RenderArgs) -> PngStyle {
    // gKit's PNGs are clamped: --png-linear, which writes as gKit does, clamps unless told otherwise.
    let filmic = args.mode == ModeArg::Path && !args.png_linear;
    PngStyle {
        encoding: if args.png_linear { PngEncoding::GkitLinear } else { PngEncoding::Srgb },
        exposure: args.exposure.unwrap_or(0.0),
        tonemap: match args.tonemap {
            Some(TonemapArg::Aces) => Tonemap::Aces,
            Some(TonemapArg::Clamp) => Tonemap::Clamp,
            None if filmic => Tonemap::Aces,
            None => Tonemap::Clamp,
        },
    }
}
