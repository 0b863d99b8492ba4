//! Render arguments to library options: the technique with its own options, and the rest.

use lumiere::integrators::{AmbientOcclusion, Direct, Hits, LightSampling, Materials, Shadows, Technique};
use lumiere::render::RenderOptions;
use lumiere::sampler::SamplerKind;

use crate::cli::args::{LightSamplingArg, ModeArg, RenderArgs, SamplerArg};

pub fn from_args(args: &RenderArgs) -> RenderOptions {
    RenderOptions {
        technique: technique(args),
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

fn technique(args: &RenderArgs) -> Technique {
    let samples = args.samples;
    match args.mode {
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
    }
}
