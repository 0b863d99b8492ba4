//! The view a glTF scene gives itself: the first perspective camera its node tree places, in the
//! order of the walk (`nodes.rs`: depth first from the scene's roots, a node before its children).
//! A camera looks down its node's −Z axis with its +Y axis up (glTF 2.0 §3.10.1), its `yfov` the
//! vertical field of view. Its `aspectRatio`, `znear` and `zfar` are not read: the image's size
//! decides the horizontal field of view, and a pinhole has no clipping planes.
//!
//! lumiere has no orthographic projection: such a camera is passed over with a warning, as is one
//! whose numbers make no view; the next camera of the walk may then be the view.

use super::nodes::PlacedCamera;
use crate::error::{quote, shown_path};
use crate::scene::camera::{Camera, View};
use crate::scene::load::warnings::Warnings;
use glam::{DMat4, DVec3};
use gltf::Document;
use gltf::json::camera::Type;
use gltf::json::validation::Checked;
use std::f64::consts::PI;
use std::path::Path;

/// The view of the first camera in `placed` (the walk's order) that makes one; warns about the
/// cameras passed over, those placed after it and those no node of the scene places.
pub(super) fn view(document: &Document, placed: &[PlacedCamera], file: &Path, warnings: &mut Warnings) -> Option<View> {
    warn_unplaced(document, placed, file, warnings);
    let mut walk = placed.iter();
    let view = walk.by_ref().find_map(|camera| match camera_view(document, camera) {
        Ok(view) => Some(view),
        Err(why) => {
            warnings.push(file, "cameras not read", || {
                format!("{}: {}: {why}", shown_path(file), described(document, camera))
            });
            None
        }
    })?;
    let unused = walk.count();
    if unused > 0 {
        warnings.push(file, "cameras not used", || {
            format!("{}: {} placed after the one viewed from not used", shown_path(file), cameras(unused))
        });
    }
    Some(view)
}

/// The view `placed` gives, or why it gives none.
fn camera_view(document: &Document, placed: &PlacedCamera) -> Result<View, String> {
    let json = &document.as_json().cameras[placed.camera];
    // Read from the JSON: the crate's `projection()` unwraps a projection that validation lets be
    // missing (`"type": "perspective"` beside an `orthographic` object alone).
    let yfov = match (json.type_, &json.perspective) {
        (Checked::Valid(Type::Perspective), Some(perspective)) => perspective.yfov,
        (Checked::Valid(Type::Orthographic), _) => {
            return Err("orthographic camera not read (lumiere has no orthographic projection)".into());
        }
        _ => return Err("not read: its type is perspective but it has no perspective projection".into()),
    };
    let name = json.name.clone().or_else(|| document.nodes().nth(placed.node)?.name().map(String::from));
    looking(placed.transform, yfov, name).map_err(|why| format!("not read as the view: {why}"))
}

/// The view of a camera placed by `transform` with vertical field of view `yfov` radians.
fn looking(transform: DMat4, yfov: f32, name: Option<String>) -> Result<View, String> {
    if !(yfov > 0.0 && f64::from(yfov) < PI) {
        return Err(format!("its yfov {yfov} is not in (0, π) radians"));
    }
    let yfov = f64::from(yfov);
    let eye = transform.transform_point3(DVec3::ZERO);
    // Only the axes' directions make the view: a scaled node (a scene exported in centimetres)
    // looks the same way.
    let axis = |local: DVec3, name: &str| {
        transform
            .transform_vector3(local)
            .try_normalize()
            .ok_or_else(|| format!("its transform collapses its {name} axis"))
    };
    let (forward, up) = (axis(DVec3::NEG_Z, "-Z")?, axis(DVec3::Y, "+Y")?);
    // A target as far along the axis as the eye is from the origin keeps the direction
    // `target - eye` as precise in single precision as the eye itself; one unit away, an eye at
    // 1000 would turn the view by up to a thousandth of a radian.
    let target = eye + forward * eye.abs().max_element().max(1.0);
    let view = View {
        eye: eye.as_vec3(),
        target: target.as_vec3(),
        up: up.as_vec3(),
        fov_degrees: yfov.to_degrees() as f32,
        name,
    };
    // What else makes no picture (an eye beyond single precision, +Y along −Z) is what the
    // camera refuses, with its reason.
    Camera::look_at(view.eye, view.target, view.up, view.fov_degrees, 1, 1).map_err(|error| error.to_string())?;
    Ok(view)
}

/// Warns about the cameras the file defines that no node of its scene places.
fn warn_unplaced(document: &Document, placed: &[PlacedCamera], file: &Path, warnings: &mut Warnings) {
    let mut is_placed = vec![false; document.cameras().len()];
    for camera in placed {
        is_placed[camera.camera] = true;
    }
    let unplaced = is_placed.iter().filter(|&&placed| !placed).count();
    if unplaced > 0 {
        warnings.push(file, "cameras not used", || {
            format!("{}: {} that no node of the scene places not read", shown_path(file), cameras(unplaced))
        });
    }
}

/// `camera 2 ("Main") of node 5`, as warnings name a placed camera.
fn described(document: &Document, placed: &PlacedCamera) -> String {
    let name = document.as_json().cameras[placed.camera].name.as_deref();
    let name = name.map(|name| format!(" ({})", quote(name))).unwrap_or_default();
    format!("camera {}{name} of node {}", placed.camera, placed.node)
}

fn cameras(count: usize) -> String {
    if count == 1 { "1 camera".into() } else { format!("{count} cameras") }
}
