//! The camera the user asked for.

use glam::Vec3;
use lumiere::scene::camera::{self, Camera, Orbiter};
use lumiere::scene::{Scene, builtin};
use lumiere::{Error, Result};

use crate::cli::args::RenderArgs;

/// An orbiter file, a look-at, the built-in scene's orbiter, the scene file's own view (a glTF
/// camera; `--fov` and `--up` replace its own), or a view that frames the whole scene.
pub fn from_args(args: &RenderArgs, scene: &Scene) -> Result<Camera> {
    let (width, height) = args.size;
    let fov = args.fov.unwrap_or(super::options::DEFAULT_FOV);
    if let Some(path) = &args.orbiter {
        return Ok(Camera::from_orbiter(&Orbiter::load(path)?, width, height));
    }
    if let (Some(eye), Some(target)) = (args.eye, args.target) {
        return Camera::look_at(eye, target, up(args), fov, width, height);
    }
    if args.scene.is_none() {
        return Ok(Camera::from_orbiter(&builtin::cornell_orbiter()?, width, height));
    }
    if let Some(view) = &scene.view {
        let (up, fov) = (args.up.unwrap_or(view.up), args.fov.unwrap_or(view.fov_degrees));
        return Camera::look_at(view.eye, view.target, up, fov, width, height);
    }
    let (eye, target) = camera::framing(&scene.bounds(), fov)
        .map_err(|why| Error::invalid(format!("{}: {why}; give --eye and --target", scene.name)))?;
    Camera::look_at(eye, target, up(args), fov, width, height)
}

/// The look-at camera's up direction: `--up`, or +y.
fn up(args: &RenderArgs) -> Vec3 {
    args.up.unwrap_or(Vec3::Y)
}
