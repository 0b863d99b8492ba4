//! Files the Python half reads or writes itself, under the rules the CLI follows: an input is read
//! as a regular file only, never past its size (`util::read`: a FIFO would block and `/dev/zero`
//! never end), and no output may be an input, another output or a file the scene reads
//! (`util::overwrite`, the CLI's very checks and messages, with the names Python gives the files);
//! and, as the CLI does before it writes, the temporary files of killed writers are cleared away.

use std::path::{Path, PathBuf};

use lumiere::Error;
use lumiere::util::overwrite::{Named, check_outputs as check, check_scene_files};
use lumiere::util::read::read_regular_file;
use lumiere::util::write::remove_stale_temporaries;
use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::errors::OrPyErr;
use crate::scene::PyScene;

/// The bytes of the input file at `path` (an orbiter camera), read as `lumiere.load` reads scenes.
#[pyfunction]
pub fn read_input<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyBytes>> {
    let bytes = py.detach(|| read_regular_file(&path).map_err(|e| Error::io(&path, e))).or_py()?;
    Ok(PyBytes::new(py, &bytes))
}

/// Removes the temporary files that killed writers left beside `path` (see
/// [`remove_stale_temporaries`]), as the CLI does before it writes there: call it before a write.
pub fn tidy_beside(path: &Path) {
    remove_stale_temporaries(path.parent().unwrap_or(Path::new("")));
}

/// Refuses, before a render, `outputs` that are one file, that would overwrite one of `inputs`,
/// or (given the loaded `scene`) one of the files it read: each a (name, path) pair, the name
/// being the argument or flag that gave the path.
#[pyfunction]
#[pyo3(signature = (outputs, inputs, scene=None))]
pub fn check_outputs(
    outputs: Vec<(String, PathBuf)>,
    inputs: Vec<(String, PathBuf)>,
    scene: Option<&PyScene>,
) -> PyResult<()> {
    check(&named(&outputs), &named(&inputs), None).or_py()?;
    if let Some(scene) = scene {
        let scene = scene.world.scene();
        check_scene_files(outputs.iter().map(|(_, path)| path.as_path()), scene.files_read()).or_py()?;
    }
    Ok(())
}

fn named(files: &[(String, PathBuf)]) -> Vec<Named<'_>> {
    files.iter().map(|(name, path)| Named { name, path }).collect()
}
