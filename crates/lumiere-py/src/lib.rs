//! `lumiere._lumiere`: the native half of the Python package. It only turns Python values into
//! library calls and back; the Python half (`python/lumiere/`) gives it the API a Python user
//! expects (numpy arrays, keyword options, pickling for Ray), so each side does what it does best.

mod aovs;
mod camera;
mod errors;
mod files;
mod film;
mod image;
mod options;
mod pixels;
mod pools;
mod render;
mod scene;
mod watch;

use pyo3::prelude::*;

#[pymodule]
fn _lumiere(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    module.add_class::<scene::PyScene>()?;
    module.add_class::<camera::PyCamera>()?;
    module.add_class::<options::PyOptions>()?;
    module.add_class::<film::PyFilm>()?;
    module.add_function(wrap_pyfunction!(render::render, module)?)?;
    module.add_function(wrap_pyfunction!(aovs::aovs, module)?)?;
    module.add_function(wrap_pyfunction!(aovs::check_aovs, module)?)?;
    module.add_function(wrap_pyfunction!(film::render_passes, module)?)?;
    module.add_function(wrap_pyfunction!(image::write_image, module)?)?;
    module.add_function(wrap_pyfunction!(image::check_image_output, module)?)?;
    module.add_function(wrap_pyfunction!(image::check_checkpoint_output, module)?)?;
    module.add_function(wrap_pyfunction!(files::check_outputs, module)?)?;
    module.add_function(wrap_pyfunction!(files::read_input, module)?)?;
    Ok(())
}
