use std::io::IsTerminal;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

use lumiere::accel::BuildPreset;
use lumiere::image_io::{PngEncoding, check_output_path, check_writable, write_atomically, write_image};
use lumiere::integrators::LightSampling;
use lumiere::render::{RenderOptions, render};
use lumiere::sampler::SamplerKind;
use lumiere::scene::camera::{Camera, Orbiter};
use lumiere::scene::{Scene, builtin};
use lumiere::world::World;
use lumiere::{Error, Result};

use super::args::{LightSamplingArg, RenderArgs, SamplerArg};

pub fn run(args: &RenderArgs) -> Result<()> {
    // Refuse a bad output path before spending minutes on a render.
    check_output_path(&args.output)?;
    if let Some(stats) = &args.stats_json {
        check_writable(stats)?;
    }
    let pool = super::pool(args.threads)?;
    let threads = pool.current_num_threads();
    pool.install(|| render_in_pool(args, threads))
}

fn render_in_pool(args: &RenderArgs, threads: usize) -> Result<()> {
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

    let build_start = Instant::now();
    let world = World::new(scene, BuildPreset::Default);
    let build_ms = build_start.elapsed().as_secs_f64() * 1e3;

    let options = RenderOptions {
        mode: args.mode.into(),
        samples: args.samples,
        spp: args.spp,
        seed: args.seed,
        sampler: match args.sampler {
            SamplerArg::Independent => SamplerKind::Independent,
            SamplerArg::Sobol => SamplerKind::Sobol,
        },
        light_sampling: match args.light_sampling {
            LightSamplingArg::PerLight => LightSampling::PerLight,
            LightSamplingArg::Power => LightSampling::Power,
        },
        ao_distance: args.ao_distance.unwrap_or(f32::INFINITY),
    };
    let bar = progress_bar(u64::from(camera.width) * u64::from(camera.height));
    let output = render(&world, &camera, &options, &|pixels| bar.inc(pixels))?;
    bar.finish_and_clear();

    let png = if args.png_linear { PngEncoding::GkitLinear } else { PngEncoding::Srgb };
    write_image(&args.output, output.image.width, output.image.height, &output.image.pixels, png)?;
    let render_ms = output.elapsed.as_secs_f64() * 1e3;
    eprintln!(
        "lumiere: {} {}x{} in {:.1} ms ({} threads): {} rays, {:.1} Mrays/s -> {}",
        options.mode.name(),
        camera.width,
        camera.height,
        render_ms,
        threads,
        output.rays,
        output.mrays_per_second(),
        args.output.display()
    );

    if let Some(path) = &args.stats_json {
        let stats = serde_json::json!({
            "scene": world.scene.name,
            "mode": options.mode.name(),
            "width": camera.width,
            "height": camera.height,
            "samples": options.samples,
            "spp": options.spp,
            "sampler": format!("{:?}", options.sampler).to_lowercase(),
            "seed": options.seed,
            "threads": threads,
            "triangles": world.scene.mesh.triangle_count(),
            "lights": world.scene.lights.len(),
            "bvh_nodes": world.bvh.nodes().len(),
            "load_ms": load_ms,
            "build_ms": build_ms,
            "render_ms": render_ms,
            "rays": output.rays,
            "mrays_per_s": output.mrays_per_second(),
        });
        let text = serde_json::to_string_pretty(&stats).map_err(|e| Error::invalid(format!("stats: {e}")))?;
        write_atomically(path, format!("{text}\n").as_bytes())?;
    }
    Ok(())
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
    if bounds.is_empty() {
        return Err(Error::invalid(format!("{}: no vertices to frame; give --eye and --target", scene.name)));
    }
    let radius = 0.5 * bounds.extent().length();
    let distance = radius / (0.5 * args.fov.to_radians()).sin();
    let target = bounds.center();
    Camera::look_at(target + glam::Vec3::Z * distance.max(1e-6), target, args.up, args.fov, width, height)
}

fn progress_bar(total: u64) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    if let Ok(style) = ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {percent}% ETA {eta}") {
        bar.set_style(style);
    }
    bar
}
