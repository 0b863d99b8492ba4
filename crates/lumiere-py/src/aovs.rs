//! The AOVs of a render computed apart from it: `lumiere.distributed` renders the image on a
//! cluster and its AOVs (a pass of first hits, cheap beside the image) on the driver, with the
//! bytes `lumiere.render` gives them.

use lumiere::render::aov::{Aov, render_aovs};
use lumiere::render::film::check_memory;
use pyo3::prelude::*;
use pyo3::types::PyByteArray;

use crate::camera::PyCamera;
use crate::errors::OrPyErr;
use crate::options::PyOptions;
use crate::pixels::to_bytearray;
use crate::pools;
use crate::scene::PyScene;
use crate::watch;

/// The AOVs named, or the library's refusal of a name.
pub fn parse(names: &[String]) -> PyResult<Vec<Aov>> {
    names.iter().map(|name| Aov::parse(name)).collect::<lumiere::Result<Vec<_>>>().or_py()
}

/// Refuses `count` AOVs of a `width x height` image that would not fit in memory beside its film,
/// as the CLI refuses them: each AOV's buffer and its bytes for numpy, and the image's bytes.
pub fn check_fit(width: u32, height: u32, count: usize) -> PyResult<()> {
    if count == 0 {
        return Ok(());
    }
    check_memory(width, height, count as u64 * 24 + 12, " with its AOVs").or_py()
}

/// Refuses, before a long render, AOV names the library does not know, or AOVs that would not
/// fit in memory.
#[pyfunction]
pub fn check_aovs(width: u32, height: u32, names: Vec<String>) -> PyResult<()> {
    check_fit(width, height, parse(&names)?.len())
}

/// The AOVs named, of the render `options` describe, as float32 RGB bytes (row 0 at the top), on
/// a pool of `threads`, with the GIL released; Ctrl-C gives them up.
#[pyfunction]
pub fn aovs<'py>(
    py: Python<'py>,
    scene: &PyScene,
    camera: &PyCamera,
    options: &PyOptions,
    threads: usize,
    names: Vec<String>,
) -> PyResult<Vec<Bound<'py, PyByteArray>>> {
    let aovs = parse(&names)?;
    check_fit(camera.camera.width, camera.camera.height, aovs.len())?;
    let (world, camera, options) = (scene.world.clone(), camera.camera.clone(), options.options.clone());
    let pool = pools::for_render(py, threads)?;
    // Empty when cancelled: `watch::run` then raises KeyboardInterrupt.
    let work = move |watch: &watch::Watch| {
        Ok(pool.install(|| render_aovs(&world, &camera, &options, &aovs, &watch.cancel).unwrap_or_default()))
    };
    let buffers = watch::run(py, None, None, 1, work)?;
    buffers.iter().map(|buffer| to_bytearray(py, buffer)).collect()
}
