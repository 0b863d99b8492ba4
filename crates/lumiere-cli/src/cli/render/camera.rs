//! The camera the user asked for.

use lumiere::scene::camera::{Camera, Orbiter};
use lumiere::scene::{Scene, builtin};
use lumiere::{Error, Result};

use crate::cli::args::RenderArgs;

/// An orbiter file, a look-at, the built-in scene's orbiter, or a view that frames the whole scene.
pub fn from_args(args: &RenderArgs, scene: &Scene) -> Result<Camera> {
    let (width, height) = args.size;
    let fov = args.fov.unwrap_or(super::options::DEFAULT_FOV);
    if let Some(path) = &args.orbiter {
        return Ok(Camera::from_orbiter(&Orbiter::load(path)?, width, height));
    }
    if let (Some(eye), Some(target)) = (args.eye, args.target) {
        return Camera::look_at(eye, target, args.up, fov, width, height);
    }
    if args.scene.is_none() {
        return Ok(Camera::from_orbiter(&builtin::cornell_orbiter()?, width, height));
    }
    let bounds = scene.bounds();
    let cannot_frame = |why: &str| Error::invalid(format!("{}: {why}; give --eye and --target", scene.name));
    if bounds.is_empty() {
        return Err(cannot_frame("no vertices to frame"));
    }
    let radius = 0.5 * bounds.extent().length();
    let distance = radius / (0.5 * fov.to_radians()).sin();
    let target = bounds.center();
    let eye = target + glam::Vec3::Z * distance.max(1e-6);
    if !(eye.is_finite() && target.is_finite()) || eye == target {
        return Err(cannot_frame("its bounds are too large (or too far from the origin) to frame automatically"));
    }
    Camera::look_at(eye, target, args.up, fov, width, height)
}
