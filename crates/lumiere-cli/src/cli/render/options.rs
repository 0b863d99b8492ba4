//! Render arguments to library options: the technique with its own options, and the rest; and the
//! flags that were given but do nothing for this render.

use lumiere::integrators::{AmbientOcclusion, Direct, Hits, LightSampling, Materials, Path, Shadows, Technique};
use lumiere::render::RenderOptions;
use lumiere::sampler::SamplerKind;

use crate::cli::args::{LightSamplingArg, ModeArg, RenderArgs, SamplerArg};

/// `--samples` when it is not given.
const DEFAULT_SAMPLES: u32 = 16;
/// `--spp` of `--mode path` when it is not given: a picture in a few seconds at 1024x768.
const DEFAULT_PATH_SPP: u32 = 8;
/// The look-at camera's field of view when `--fov` is not given (gKit's).
pub const DEFAULT_FOV: f32 = 45.0;

pub fn from_args(args: &RenderArgs) -> RenderOptions {
    // With a budget and no sample count, render until the budget is met.
    let budget = args.time.is_some() || args.noise.is_some();
    // Path tracing needs several jittered samples to show anything but noise; the lab's modes
    // default to its single ray through each pixel centre.
    let default_spp = if args.mode == ModeArg::Path { DEFAULT_PATH_SPP } else { 1 };
    let spp = args.spp.unwrap_or(if budget { u32::MAX } else { default_spp });
    RenderOptions {
        technique: technique(args),
        spp,
        seed: args.seed,
        sampler: match args.sampler {
            Some(SamplerArg::Independent) => SamplerKind::Independent,
            Some(SamplerArg::Sobol) => SamplerKind::Sobol,
            // Path tracing draws a few well-stratified 2D dimensions per bounce, where Sobol's
            // error is about half the independent sampler's at 64 spp (BENCHMARKS.md); the lab's
            // modes keep the independent numbers their images were recorded with.
            None if args.mode == ModeArg::Path => SamplerKind::Sobol,
            None => SamplerKind::Independent,
        },
        time_budget: args.time,
        noise_target: args.noise,
    }
}

fn technique(args: &RenderArgs) -> Technique {
    let samples = args.samples.unwrap_or(DEFAULT_SAMPLES);
    match args.mode {
        ModeArg::Hits => Technique::Hits(Hits),
        ModeArg::Materials => Technique::Materials(Materials),
        ModeArg::Shadows => Technique::Shadows(Shadows),
        ModeArg::Direct => Technique::Direct(Direct {
            samples,
            light_sampling: match args.light_sampling.unwrap_or(LightSamplingArg::PerLight) {
                LightSamplingArg::PerLight => LightSampling::PerLight,
                LightSamplingArg::Power => LightSampling::Power,
            },
        }),
        ModeArg::Ao => Technique::AmbientOcclusion(AmbientOcclusion {
            samples,
            distance: args.ao_distance.unwrap_or(f32::INFINITY),
        }),
        ModeArg::Path => {
            let defaults = Path::default();
            Technique::Path(Path { max_depth: args.max_depth.unwrap_or(defaults.max_depth), ..defaults })
        }
    }
}

/// One warning per flag given that this render ignores.
pub fn ignored_flags(args: &RenderArgs) -> Vec<String> {
    let mode = args.mode;
    let mode_name = format!("{mode:?}").to_lowercase();
    let mut ignored = Vec::new();
    let mut check = |given: bool, flag: &str, applies: bool, which: &str| {
        if given && !applies {
            ignored.push(format!("{flag} has no effect in --mode {mode_name} ({which})"));
        }
    };
    check(args.samples.is_some(), "--samples", matches!(mode, ModeArg::Direct | ModeArg::Ao), "direct and ao only");
    check(args.light_sampling.is_some(), "--light-sampling", mode == ModeArg::Direct, "direct only");
    check(args.ao_distance.is_some(), "--ao-distance", mode == ModeArg::Ao, "ao only");
    check(args.max_depth.is_some(), "--max-depth", mode == ModeArg::Path, "path only");
    // The lab's first three images trace one ray through each pixel's centre: no random number,
    // unless passes are jittered (more than one camera sample, or a budget that runs passes).
    let one_centred_pass = args.spp.is_none_or(|spp| spp == 1) && args.time.is_none() && args.noise.is_none();
    let draws_numbers = !matches!(mode, ModeArg::Hits | ModeArg::Materials | ModeArg::Shadows) || !one_centred_pass;
    check(
        args.sampler.is_some(),
        "--sampler",
        draws_numbers,
        "one ray through each pixel centre draws no random number",
    );
    for (flag, given) in [("--fov", args.fov.is_some()), ("--up", args.up.is_some())] {
        if given && args.orbiter.is_some() {
            ignored.push(format!("{flag} has no effect with --orbiter (gKit's orbiter camera has its own)"));
        } else if given && args.scene.is_none() && args.eye.is_none() {
            ignored
                .push(format!("{flag} has no effect on the built-in scene's orbiter camera; give --eye and --target"));
        }
    }
    let png = args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let png_only = [
        ("--exposure", args.exposure.is_some()),
        ("--tonemap", args.tonemap.is_some()),
        ("--png-linear", args.png_linear),
    ];
    for (flag, given) in png_only {
        if given && !png {
            ignored.push(format!(
                "{flag} has no effect on a {} output (PNG only: EXR and PFM stay linear)",
                extension(args)
            ));
        }
    }
    if args.checkpoint_every.is_some() && args.checkpoint.is_none() {
        ignored.push("--checkpoint-every has no effect without --checkpoint".to_string());
    }
    ignored
}

/// The output's extension, as written (`.exr`), for messages.
fn extension(args: &RenderArgs) -> String {
    args.output.extension().map_or_else(|| "extensionless".to_string(), |e| format!(".{}", e.to_string_lossy()))
}
