//! Render options from Python keywords, mapped to the library's `RenderOptions` as the CLI maps its
//! flags (same defaults, same names for modes and samplers), with the CLI's warnings for options
//! that do nothing in the chosen mode.

use std::time::Duration;

use lumiere::integrators::{AmbientOcclusion, Direct, Hits, LightSampling, Materials, Path, Shadows, Technique};
use lumiere::render::RenderOptions;
use lumiere::render::fingerprint::options_description;
use lumiere::sampler::SamplerKind;
use pyo3::prelude::*;

use crate::camera::PyCamera;
use crate::errors::invalid;

/// `samples` when it is not given (the CLI's `--samples` default).
const DEFAULT_SAMPLES: u32 = 16;

#[pyclass(module = "lumiere._lumiere", name = "NativeOptions", frozen)]
pub struct PyOptions {
    pub options: RenderOptions,
    /// One message per option given that this mode ignores.
    #[pyo3(get)]
    pub ignored: Vec<String>,
}

/// `value` as a count from 1 to `max`.
fn positive_count(value: i64, what: &str, max: u32) -> PyResult<u32> {
    u32::try_from(value)
        .ok()
        .filter(|&v| (1..=max).contains(&v))
        .ok_or_else(|| invalid(format!("{what} must be between 1 and {max}, got {value}")))
}

#[pymethods]
impl PyOptions {
    /// `spp` None renders until `time` or `noise` stops it (one of them is then required).
    #[new]
    #[pyo3(signature = (mode, spp, seed, sampler, samples=None, light_sampling=None, ao_distance=None, max_depth=None, time=None, noise=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        mode: &str,
        spp: Option<i64>,
        seed: u64,
        sampler: Option<&str>,
        samples: Option<i64>,
        light_sampling: Option<&str>,
        ao_distance: Option<f32>,
        max_depth: Option<u32>,
        time: Option<f64>,
        noise: Option<f64>,
    ) -> PyResult<Self> {
        let samples_value =
            samples.map(|s| positive_count(s, "samples", u32::MAX)).transpose()?.unwrap_or(DEFAULT_SAMPLES);
        let technique = match mode {
            "hits" => Technique::Hits(Hits),
            "materials" => Technique::Materials(Materials),
            "shadows" => Technique::Shadows(Shadows),
            "direct" => Technique::Direct(Direct {
                samples: samples_value,
                light_sampling: match light_sampling.unwrap_or("per-light") {
                    "per-light" => LightSampling::PerLight,
                    "power" => LightSampling::Power,
                    other => {
                        return Err(invalid(format!("unknown light_sampling {other:?}: choose per-light or power")));
                    }
                },
            }),
            "ao" => Technique::AmbientOcclusion(AmbientOcclusion {
                samples: samples_value,
                distance: ao_distance.unwrap_or(f32::INFINITY),
            }),
            "path" => {
                let defaults = Path::default();
                Technique::Path(Path { max_depth: max_depth.unwrap_or(defaults.max_depth), ..defaults })
            }
            other => {
                return Err(invalid(format!(
                    "unknown mode {other:?}: choose among path, hits, materials, shadows, direct, ao"
                )));
            }
        };
        let sampler = match sampler {
            Some("independent") => SamplerKind::Independent,
            Some("sobol") => SamplerKind::Sobol,
            Some(other) => return Err(invalid(format!("unknown sampler {other:?}: choose independent or sobol"))),
            // The CLI's defaults: Sobol for path tracing, the independent numbers for the lab's modes.
            None if mode == "path" => SamplerKind::Sobol,
            None => SamplerKind::Independent,
        };
        let seconds = |value: Option<f64>, what: &str| -> PyResult<Option<Duration>> {
            value
                // As `--time`: any positive number of seconds, however small, short of what a
                // `Duration` holds (about 585 billion years), which the CLI calls too long too.
                .map(|s| match Duration::try_from_secs_f64(s) {
                    Ok(d) if s > 0.0 => Ok(d),
                    Err(_) if s > 0.0 => Err(invalid(format!("{what}={s} seconds is too long a duration"))),
                    _ => Err(invalid(format!("{what} must be a positive number of seconds"))),
                })
                .transpose()
        };
        let time_budget = seconds(time, "time")?;
        let budget = time.is_some() || noise.is_some();
        let spp = match spp {
            // `u32::MAX` stands for "until a budget stops the render" (`spp=None`).
            Some(spp) => positive_count(spp, "spp", u32::MAX - 1)?,
            None if budget => u32::MAX,
            None => return Err(invalid("spp=None needs a budget: give time= or noise=")),
        };
        let options = RenderOptions { technique, spp, seed, sampler, time_budget, noise_target: noise };
        let mut ignored = Vec::new();
        let mut check = |given: bool, name: &str, applies: bool, which: &str| {
            if given && !applies {
                ignored.push(format!("{name} has no effect in mode {mode:?} ({which})"));
            }
        };
        check(samples.is_some(), "samples", matches!(mode, "direct" | "ao"), "direct and ao only");
        check(light_sampling.is_some(), "light_sampling", mode == "direct", "direct only");
        check(ao_distance.is_some(), "ao_distance", mode == "ao", "ao only");
        check(max_depth.is_some(), "max_depth", mode == "path", "path only");
        options.technique.validate().map_err(crate::errors::to_py)?;
        if options.noise_target.is_some_and(|n| !(n.is_finite() && n > 0.0)) {
            return Err(invalid("noise must be a positive finite number"));
        }
        Ok(PyOptions { options, ignored })
    }

    #[getter]
    fn spp(&self) -> u32 {
        self.options.spp
    }

    /// Everything that decides a sample's value, as the checkpoint stores it.
    fn describe(&self, camera: &PyCamera) -> String {
        options_description(&self.options, &camera.camera)
    }

    fn __repr__(&self) -> String {
        format!("{:?}", self.options)
    }
}
