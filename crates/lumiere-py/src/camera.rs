//! Cameras: a look-at pinhole, a gKit orbiter (given as the file's text, so that a pickled camera
//! needs no file on the machine that renders it), the built-in scene's orbiter, and the view that
//! frames a scene when no camera is given (the CLI's, from the library).

use std::path::PathBuf;

use glam::Vec3;
use lumiere::scene::builtin;
use lumiere::scene::camera::{self, Camera, Orbiter};
use pyo3::prelude::*;

use crate::errors::{OrPyErr, invalid};
use crate::scene::PyScene;

#[pyclass(module = "lumiere._lumiere", name = "NativeCamera", frozen)]
pub struct PyCamera {
    pub camera: Camera,
}

fn check_size(width: u32, height: u32) -> PyResult<()> {
    if width == 0 || height == 0 {
        return Err(invalid(format!("image size {width}x{height} has no pixels")));
    }
    Ok(())
}

#[pymethods]
impl PyCamera {
    /// A pinhole at `eye` looking at `target`, vertical field of view `fov` degrees.
    #[staticmethod]
    fn look_at(eye: [f32; 3], target: [f32; 3], up: [f32; 3], fov: f32, width: u32, height: u32) -> PyResult<Self> {
        check_size(width, height)?;
        let camera =
            Camera::look_at(Vec3::from(eye), Vec3::from(target), Vec3::from(up), fov, width, height).or_py()?;
        Ok(PyCamera { camera })
    }

    /// gKit's orbiter camera from the text of an orbiter file (`path` names it in errors).
    #[staticmethod]
    fn orbiter(text: &[u8], path: PathBuf, width: u32, height: u32) -> PyResult<Self> {
        check_size(width, height)?;
        let orbiter = Orbiter::parse(text, &path).or_py()?;
        Ok(PyCamera { camera: Camera::from_orbiter(&orbiter, width, height) })
    }

    /// The built-in scene's camera: gKit's 2022 orbiter for the Cornell box.
    #[staticmethod]
    fn builtin(width: u32, height: u32) -> PyResult<Self> {
        check_size(width, height)?;
        Ok(PyCamera { camera: Camera::from_orbiter(&builtin::cornell_orbiter().or_py()?, width, height) })
    }

    /// The eye and target of the view from +z that frames `scene` with field of view `fov`.
    #[staticmethod]
    fn framing(scene: &PyScene, fov: f32) -> PyResult<([f32; 3], [f32; 3])> {
        let scene = scene.world.scene();
        let (eye, target) = camera::framing(&scene.bounds(), fov)
            .map_err(|why| invalid(format!("{}: {why}; give a camera (lumiere.Camera.look_at)", scene.name)))?;
        Ok((eye.to_array(), target.to_array()))
    }

    #[getter]
    fn width(&self) -> u32 {
        self.camera.width
    }

    #[getter]
    fn height(&self) -> u32 {
        self.camera.height
    }

    fn __repr__(&self) -> String {
        format!("{:?}", self.camera)
    }
}
