//! `lumiere bench-sampler`: image error of each sampler against a converged reference, at the
//! lab's sample counts, on the built-in scene's soft-shadow and ambient-occlusion images.

use lumiere::Result;
use lumiere::integrators::Technique;
use lumiere::render::film::Image;
use lumiere::render::{RenderOptions, render};
use lumiere::sampler::SamplerKind;
use lumiere::scene::camera::Camera;
use lumiere::scene::{Scene, builtin};
use lumiere::world::World;

use super::args::BenchSamplerArgs;
use super::output;

pub fn run(args: &BenchSamplerArgs) -> Result<()> {
    let (width, height) = args.size;
    // Refused before the table starts: the reference image is kept beside each render.
    lumiere::render::film::check_memory(width, height, 12, " beside its reference image")?;
    let world = World::new(Scene::builtin()?, Default::default());
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter()?, width, height);
    let render_image = |technique: fn(u32) -> Technique, samples, sampler, seed| -> Result<Image> {
        let options = RenderOptions { sampler, seed, ..RenderOptions::new(technique(samples)) };
        Ok(render(&world, &camera, &options, &|_| {})?.image)
    };
    output::print(format_args!(
        "| image ({width}x{height}) | N | independent RMSE | Sobol RMSE | Sobol / independent | (reference: Sobol, N={}, seed 1000) |",
        args.reference_samples
    ))?;
    output::print(format_args!("|---|---|---|---|---|---|"))?;
    for (label, mode) in
        [("soft shadows", Technique::direct as fn(u32) -> Technique), ("AO", Technique::ambient_occlusion)]
    {
        let reference = render_image(mode, args.reference_samples, SamplerKind::Sobol, 1000)?;
        for n in [16, 64, 256] {
            // Averaged over a few seeds so one lucky seed does not decide the comparison.
            let error = |sampler| -> Result<f64> {
                let mut sum = 0.0;
                for seed in 0..args.seeds {
                    sum += rmse(&render_image(mode, n, sampler, seed)?, &reference);
                }
                Ok(sum / args.seeds as f64)
            };
            let (independent, sobol) = (error(SamplerKind::Independent)?, error(SamplerKind::Sobol)?);
            output::print(format_args!(
                "| {label} | {n} | {independent:.5} | {sobol:.5} | {:.2} | |",
                sobol / independent
            ))?;
        }
    }
    Ok(())
}

/// Root mean square difference over all pixels and channels.
fn rmse(image: &Image, reference: &Image) -> f64 {
    let sum: f64 = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, b)| (*a - *b).to_array().iter().map(|d| (*d as f64).powi(2)).sum::<f64>())
        .sum();
    (sum / (3 * image.pixels.len()) as f64).sqrt()
}
