//! A technique's options as the statistics JSON holds them (`render --stats-json`, `bench
//! --json`): an object keyed by the options' names as the flags and the Python keywords spell them
//! (`max_depth` for `--max-depth`), so that a script reads `stats["technique"]["max_depth"]`
//! rather than parsing Rust's Debug text.

use lumiere::integrators::{AmbientOcclusion, Direct, LightSampling, Path, PathStrategy, Technique};
use serde_json::{Value, json};

/// The options of `technique` (an empty object for the modes that have none).
pub fn technique_json(technique: &Technique) -> Value {
    match *technique {
        Technique::Hits(_) | Technique::Materials(_) | Technique::Shadows(_) => json!({}),
        Technique::Direct(Direct { samples, light_sampling }) => json!({
            "samples": samples,
            "light_sampling": match light_sampling {
                LightSampling::PerLight => "per-light",
                LightSampling::Power => "power",
            },
        }),
        // No distance (the lab's visibility of the sky) is null: JSON has no infinity.
        Technique::AmbientOcclusion(AmbientOcclusion { samples, distance }) => json!({
            "samples": samples,
            "ao_distance": distance.is_finite().then_some(distance),
        }),
        Technique::Path(Path { max_depth, rr_depth, strategy }) => json!({
            "max_depth": max_depth,
            "rr_depth": rr_depth,
            "strategy": match strategy {
                PathStrategy::Mis => "mis",
                PathStrategy::LightsOnly => "lights-only",
                PathStrategy::BsdfOnly => "bsdf-only",
            },
        }),
    }
}
