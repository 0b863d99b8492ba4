//! What `lumiere.distributed` needs from the library: a worker renders a range of passes and ships
//! each pass's raw samples; the driver adds them to a film strictly in pass order (the additions
//! the progressive loop makes, so the bytes match a local render) and saves checkpoints in the
//! CLI's format, which `lumiere render --resume` accepts too.

use std::path::PathBuf;
use std::time::Duration;

use lumiere::render::RenderStats;
use lumiere::render::checkpoint::Checkpoint;
use lumiere::render::film::{Film, PassSamples};
use lumiere::render::fingerprint::{Fingerprints, Mismatch};
use lumiere::render::render_pass_range;
use pyo3::prelude::*;
use pyo3::types::PyByteArray;

use crate::camera::PyCamera;
use crate::errors::{OrPyErr, invalid, unsigned};
use crate::files;
use crate::options::PyOptions;
use crate::pixels::{from_bytes, to_bytearray};
use crate::pools;
use crate::scene::PyScene;
use crate::watch;

/// One rendered pass: its sample index, its values (float32 RGB per pixel) and its rays.
type Pass<'py> = (u32, Bound<'py, PyByteArray>, u64);

/// Renders passes `first .. first + count` on `threads` threads with the GIL released.
#[pyfunction]
#[pyo3(signature = (scene, camera, options, first, count, threads, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn render_passes<'py>(
    py: Python<'py>,
    scene: &PyScene,
    camera: &PyCamera,
    options: &PyOptions,
    first: &Bound<'py, PyAny>,
    count: &Bound<'py, PyAny>,
    threads: &Bound<'py, PyAny>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Vec<Pass<'py>>> {
    let max = u64::from(u32::MAX);
    let (first, count) = (unsigned(first, "first", max)? as u32, unsigned(count, "count", max)? as u32);
    let threads = unsigned(threads, "threads", max)? as usize;
    // Owned by the render's thread (see `watch::run`).
    let (world, camera, options) = (scene.world.clone(), camera.camera.clone(), options.options.clone());
    let pool = pools::for_render(py, threads)?;
    let total = u64::from(camera.width) * u64::from(camera.height) * u64::from(count);
    // Leaves no warnings: any stack level does.
    let passes = watch::run(py, Some(total), progress.as_ref(), 1, move |watch| {
        let (world, camera, options) = (&*world, &camera, &options);
        pool.install(|| render_pass_range(world, camera, options, first, count, &|n| watch.count(n), &watch.cancel))
    })?;
    // Each pass is dropped once copied, so that the task's peak is its passes once, not twice.
    passes.into_iter().map(|p| Ok((p.sample, to_bytearray(py, &p.values)?, p.rays))).collect()
}

/// A film that passes are added to in order, with the render's totals.
#[pyclass(module = "lumiere._lumiere", name = "NativeFilm")]
pub struct PyFilm {
    film: Film,
    stats: RenderStats,
}

#[pymethods]
impl PyFilm {
    #[new]
    fn new(width: &Bound<'_, PyAny>, height: &Bound<'_, PyAny>) -> PyResult<Self> {
        let max = u64::from(u32::MAX);
        let (width, height) = (unsigned(width, "width", max)? as u32, unsigned(height, "height", max)? as u32);
        Ok(PyFilm { film: Film::new(width, height).or_py()?, stats: RenderStats::default() })
    }

    /// Adds pass `sample`, which must be the next one.
    fn add_pass(&mut self, py: Python<'_>, sample: u32, values: &[u8], rays: u64) -> PyResult<()> {
        let values = from_bytes(values, self.film.pixel_count(), &format!("pass {sample}"))?;
        let pass = PassSamples { sample, width: self.film.width, height: self.film.height, values, rays };
        pools::install(py, || self.film.add_pass(&pass))?.or_py()?;
        // A count this large is nonsense, but it must not wrap around to a small one.
        self.stats.rays = self.stats.rays.saturating_add(rays);
        Ok(())
    }

    /// Camera samples per pixel so far (the next pass to add).
    #[getter]
    fn samples(&self) -> u32 {
        self.film.samples
    }

    #[getter]
    fn rays(&self) -> u64 {
        self.stats.rays
    }

    #[getter]
    fn discarded(&self) -> u64 {
        self.film.discarded
    }

    /// Rendering seconds (summed over the sessions of a resumed render); the driver sets it.
    #[getter]
    fn get_seconds(&self) -> f64 {
        self.stats.elapsed.as_secs_f64()
    }

    #[setter]
    fn set_seconds(&mut self, seconds: f64) -> PyResult<()> {
        self.stats.elapsed = Duration::try_from_secs_f64(seconds)
            .map_err(|_| invalid(format!("seconds must be at least 0 and below 2^64, got {seconds}")))?;
        Ok(())
    }

    fn relative_error(&self) -> Option<f64> {
        self.film.relative_error()
    }

    /// The current estimate as float32 RGB bytes, row 0 at the top.
    fn image<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyByteArray>> {
        to_bytearray(py, &pools::install(py, || self.film.image())?.pixels)
    }

    /// Saves the film as a checkpoint of the render of `scene`, `camera` and `options`: the
    /// CLI's format, so `lumiere render --resume` continues it.
    fn save_checkpoint(
        &self,
        py: Python<'_>,
        path: PathBuf,
        scene: &PyScene,
        camera: &PyCamera,
        options: &PyOptions,
    ) -> PyResult<()> {
        // The options describe the camera's size: a film of another size would make a checkpoint
        // that no render can resume.
        let (film, camera_size) = (&self.film, (camera.camera.width, camera.camera.height));
        if (film.width, film.height) != camera_size {
            return Err(invalid(format!(
                "the film is {}x{}, but the camera's image is {}x{}: a checkpoint holds the film of the camera it names",
                film.width, film.height, camera_size.0, camera_size.1
            )));
        }
        let fingerprints = Fingerprints::new(scene.fingerprint, &options.options, &camera.camera);
        let checkpoint = fingerprints.checkpoint(self.film.clone(), self.stats);
        let pool = pools::for_background(py)?;
        py.detach(|| {
            files::tidy_beside(&path);
            pool.install(|| checkpoint.save(&path))
        })
        .or_py()
    }

    /// The film of a checkpoint, refused (naming what differs) unless it was rendered from the
    /// same scene and options.
    #[staticmethod]
    fn load_checkpoint(
        py: Python<'_>,
        path: PathBuf,
        scene: &PyScene,
        camera: &PyCamera,
        options: &PyOptions,
    ) -> PyResult<Self> {
        // A file as large as its film, read without the GIL (a static method borrows nothing).
        let pool = pools::for_background(py)?;
        let checkpoint = py.detach(|| pool.install(|| Checkpoint::load(&path))).or_py()?;
        let fingerprints = Fingerprints::new(scene.fingerprint, &options.options, &camera.camera);
        let why = match fingerprints.mismatch(&checkpoint) {
            None => return Ok(PyFilm { film: checkpoint.film, stats: checkpoint.stats }),
            Some(Mismatch::Scene) => {
                "the checkpoint was rendered from a different scene (geometry, materials, textures or emission)"
                    .to_string()
            }
            Some(Mismatch::Options(differing)) => {
                format!("the checkpoint was rendered with other options: {}; only spp may change", differing.join(", "))
            }
            Some(Mismatch::FilmSize { film, image }) => {
                format!(
                    "the checkpoint's film is {}x{}, but the camera's image is {}x{}",
                    film.0, film.1, image.0, image.1
                )
            }
        };
        Err(invalid(format!("{}: cannot resume: {why}", path.display())))
    }
}
