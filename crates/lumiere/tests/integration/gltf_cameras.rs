//! glTF cameras: the first perspective camera the node tree places is the scene's view (its node's
//! origin, −Z and +Y, its `yfov`), whatever the scale; orthographic cameras, cameras whose numbers
//! make no view and cameras left over are named in warnings; other formats have no view.

use crate::common::TempDir;
use crate::gltf_loading::{Builder, no_files};
use glam::Vec3;
use lumiere::scene::Scene;
use lumiere::scene::camera::View;
use lumiere::scene::load::gltf::parse_gltf;
use std::path::Path;

/// A quarter turn about +Y: the camera's −Z (its line of sight) turned to −X.
const LOOK_ALONG_NEG_X: &str = r#""rotation": [0, 0.70710678, 0, 0.70710678]"#;
const PERSPECTIVE: &str = r#"{"type": "perspective", "name": "Main", "perspective": {"yfov": 0.8, "znear": 0.1}}"#;
const ORTHOGRAPHIC: &str =
    r#"{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}"#;

/// A triangle (node 0) and `cameras`, placed by `nodes` (which follow node 0: the first is node 1),
/// the scene's roots `roots`.
fn gltf(cameras: &[&str], nodes: &[&str], roots: &str) -> Vec<u8> {
    let mut builder = Builder::default();
    let positions = builder.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], "VEC3");
    let indices = builder.indices(&[0, 1, 2]);
    let nodes = [r#"{"mesh": 0}"#].iter().chain(nodes).copied().collect::<Vec<_>>().join(", ");
    builder.gltf(&format!(
        r#""meshes": [{{"primitives": [{{"attributes": {{"POSITION": {positions}}}, "indices": {indices}}}]}}],
           "cameras": [{}], "nodes": [{nodes}], "scenes": [{{"nodes": [{roots}]}}], "scene": 0"#,
        cameras.join(", ")
    ))
}

fn load(cameras: &[&str], nodes: &[&str], roots: &str) -> Scene {
    parse_gltf(&gltf(cameras, nodes, roots), Path::new("test.gltf"), &no_files)
        .unwrap_or_else(|error| panic!("unexpected error: {error}"))
}

fn assert_close(actual: Vec3, expected: Vec3, what: &str) {
    assert!(actual.abs_diff_eq(expected, 1e-5), "{what}: expected {expected}, got {actual}");
}

/// The view's eye, line of sight, up and field of view checked to 1e-5.
fn assert_view(view: &View, eye: Vec3, forward: Vec3, up: Vec3, fov_degrees: f32) {
    assert_close(view.eye, eye, "eye");
    assert_close((view.target - view.eye).normalize(), forward, "line of sight");
    assert_close(view.up, up, "up");
    assert!((view.fov_degrees - fov_degrees).abs() < 1e-5, "fov: expected {fov_degrees}, got {}", view.fov_degrees);
}

fn the_view(scene: &Scene) -> &View {
    scene.view.as_ref().unwrap_or_else(|| panic!("no view; warnings: {:?}", scene.warnings))
}

/// The warnings that contain `text`.
fn warnings_with<'s>(scene: &'s Scene, text: &str) -> Vec<&'s str> {
    scene.warnings.iter().map(String::as_str).filter(|w| w.contains(text)).collect()
}

#[test]
fn a_camera_node_gives_the_view_its_translation_and_rotation_place() {
    let node = format!(r#"{{"camera": 0, "translation": [1, 2, 3], {LOOK_ALONG_NEG_X}}}"#);
    let scene = load(&[PERSPECTIVE], &[&node], "0, 1");
    let view = the_view(&scene);
    assert_view(view, Vec3::new(1.0, 2.0, 3.0), Vec3::NEG_X, Vec3::Y, 0.8f32.to_degrees());
    assert_eq!(view.name.as_deref(), Some("Main"));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // The camera it makes looks where the view does: the ray through the picture's centre.
    let camera = lumiere::scene::camera::Camera::look_at(view.eye, view.target, view.up, view.fov_degrees, 64, 48)
        .expect("a usable view");
    assert_close(camera.ray(32.0, 24.0).dir, Vec3::NEG_X, "central ray");
}

#[test]
fn a_camera_node_given_as_a_matrix_is_read_as_its_trs_twin() {
    // Columns: x -> -z, y -> y, z -> x (the quarter turn above), then the translation.
    let matrix = r#"{"camera": 0, "matrix": [0, 0, -1, 0,  0, 1, 0, 0,  1, 0, 0, 0,  1, 2, 3, 1]}"#;
    let view = load(&[PERSPECTIVE], &[matrix], "0, 1").view.expect("a view");
    assert_view(&view, Vec3::new(1.0, 2.0, 3.0), Vec3::NEG_X, Vec3::Y, 0.8f32.to_degrees());
}

#[test]
fn a_scaled_parent_or_camera_node_changes_neither_the_directions_nor_the_view() {
    let plain = format!(r#"{{"camera": 0, "translation": [1, 2, 3], {LOOK_ALONG_NEG_X}}}"#);
    let expected = the_view(&load(&[PERSPECTIVE], &[&plain], "0, 1")).clone();
    let scaled_parents = [
        format!(r#"{{"children": [2], "translation": [1, 2, 3], {LOOK_ALONG_NEG_X}, "scale": [3, 3, 3]}}"#),
        // Applied before the rotation: a non-uniform scale stretches the axes without turning them.
        format!(r#"{{"children": [2], "translation": [1, 2, 3], {LOOK_ALONG_NEG_X}, "scale": [0.01, 7, 0.5]}}"#),
    ];
    for parent in &scaled_parents {
        let scene = load(&[PERSPECTIVE], &[parent, r#"{"camera": 0}"#], "0, 1");
        let view = the_view(&scene);
        assert!((view.up.length() - 1.0).abs() < 1e-6, "{parent}: up {} is not unit", view.up);
        assert_view(view, expected.eye, Vec3::NEG_X, Vec3::Y, expected.fov_degrees);
        assert_close(view.target, expected.target, "target");
    }
    let scaled_camera =
        format!(r#"{{"camera": 0, "translation": [1, 2, 3], {LOOK_ALONG_NEG_X}, "scale": [100, 100, 100]}}"#);
    let scene = load(&[PERSPECTIVE], &[&scaled_camera], "0, 1");
    assert_view(the_view(&scene), expected.eye, Vec3::NEG_X, Vec3::Y, expected.fov_degrees);
}

#[test]
fn a_camera_far_from_the_origin_keeps_its_line_of_sight_in_single_precision() {
    // Turned 30° about +Y, it looks along (−1/2, 0, −√3/2), no axis: a target one unit away from
    // an eye thousands of units out would be rounded off its line of sight in single precision.
    let node = r#"{"camera": 0, "translation": [3000, -2000, 1000], "rotation": [0, 0.25881905, 0, 0.96592583]}"#;
    let scene = load(&[PERSPECTIVE], &[node], "0, 1");
    let forward = Vec3::new(-0.5, 0.0, -(3f32.sqrt()) / 2.0);
    assert_view(the_view(&scene), Vec3::new(3000.0, -2000.0, 1000.0), forward, Vec3::Y, 0.8f32.to_degrees());
}

#[test]
fn the_first_perspective_camera_of_the_walk_is_the_view_and_the_others_are_counted() {
    let far = r#"{"type": "perspective", "name": "Far", "perspective": {"yfov": 0.5, "znear": 0.1}}"#;
    // The walk goes 0, 3, 1, 2 (roots in the scene's order, a node before its children): node 3's
    // camera comes first, though node 2 comes first in the file.
    let nodes = [
        r#"{"children": [2]}"#,
        r#"{"camera": 0, "translation": [0, 0, 5]}"#,
        r#"{"camera": 1, "translation": [0, 0, 9]}"#,
    ];
    let scene = load(&[PERSPECTIVE, far], &nodes, "0, 3, 1");
    let view = the_view(&scene);
    assert_view(view, Vec3::new(0.0, 0.0, 9.0), Vec3::NEG_Z, Vec3::Y, 0.5f32.to_degrees());
    assert_eq!(view.name.as_deref(), Some("Far"));
    assert_eq!(scene.warnings, ["test.gltf: 1 camera placed after the one viewed from not used"]);

    // A camera placed by two nodes counts twice: each is a view that is not used.
    let nodes = [r#"{"camera": 0}"#, r#"{"camera": 0}"#, r#"{"camera": 0, "translation": [0, 0, 5]}"#];
    let scene = load(&[PERSPECTIVE], &nodes, "0, 1, 2, 3");
    assert_view(the_view(&scene), Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 0.8f32.to_degrees());
    assert_eq!(scene.warnings, ["test.gltf: 2 cameras placed after the one viewed from not used"]);
}

#[test]
fn a_camera_no_node_of_the_scene_places_is_not_a_view() {
    // Node 1 places the camera but is not in the scene; node 0 places none.
    let scene = load(&[PERSPECTIVE, ORTHOGRAPHIC], &[r#"{"camera": 0}"#], "0");
    assert_eq!(scene.view, None);
    assert_eq!(scene.warnings, ["test.gltf: 2 cameras that no node of the scene places not read"]);
}

#[test]
fn an_orthographic_camera_is_passed_over_with_a_warning() {
    let nodes = [r#"{"camera": 0, "translation": [0, 0, 5]}"#, r#"{"camera": 1, "translation": [0, 0, 7]}"#];
    let scene = load(&[ORTHOGRAPHIC, PERSPECTIVE], &nodes, "0, 1, 2");
    assert_view(the_view(&scene), Vec3::new(0.0, 0.0, 7.0), Vec3::NEG_Z, Vec3::Y, 0.8f32.to_degrees());
    assert_eq!(
        scene.warnings,
        ["test.gltf: camera 0 of node 1: orthographic camera not read (lumiere has no orthographic projection)"]
    );

    let alone = load(&[ORTHOGRAPHIC], &[r#"{"camera": 0}"#], "0, 1");
    assert_eq!(alone.view, None);
    assert_eq!(warnings_with(&alone, "orthographic camera not read").len(), 1, "{:?}", alone.warnings);
}

#[test]
fn a_camera_whose_numbers_make_no_view_is_passed_over_with_a_warning() {
    let yfov = |yfov: &str| format!(r#"{{"type": "perspective", "perspective": {{"yfov": {yfov}, "znear": 0.1}}}}"#);
    let (zero, past_pi, infinite) = (yfov("0"), yfov("3.2"), yfov("1e39"));
    let cases: [(&str, &str, &str); 6] = [
        (&zero, r#"{"camera": 0}"#, "its yfov 0 is not in (0, π) radians"),
        (&past_pi, r#"{"camera": 0}"#, "its yfov 3.2 is not in (0, π) radians"),
        // Beyond single precision, the JSON's number is read as infinite.
        (&infinite, r#"{"camera": 0}"#, "its yfov inf is not in (0, π) radians"),
        (PERSPECTIVE, r#"{"camera": 0, "scale": [1, 1, 0]}"#, "its transform collapses its -Z axis"),
        (PERSPECTIVE, r#"{"camera": 0, "scale": [0, 0, 0]}"#, "its transform collapses its -Z axis"),
        // Finite in the double precision of the walk, beyond the single precision of a camera: the
        // node lies under a parent that moves it as far again.
        (PERSPECTIVE, r#"{"camera": 0, "translation": [3e38, 0, 0]}"#, "camera: the eye"),
    ];
    for (camera, node, reason) in cases {
        let parent = r#"{"children": [2], "translation": [3e38, 0, 0]}"#;
        let nodes = if reason.starts_with("camera:") { vec![parent, node] } else { vec![node] };
        let scene = load(&[camera], &nodes, "0, 1");
        assert_eq!(scene.view, None, "{node}: {reason}");
        let expected = format!("not read as the view: {reason}");
        assert_eq!(warnings_with(&scene, &expected).len(), 1, "{reason}: {:?}", scene.warnings);
        assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    }
}

#[test]
fn a_camera_whose_type_names_a_projection_it_lacks_is_passed_over_without_a_panic() {
    let mismatched = r#"{"type": "perspective", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}"#;
    let nodes = [r#"{"camera": 0}"#, r#"{"camera": 1, "translation": [0, 0, 5]}"#];
    let scene = load(&[mismatched, PERSPECTIVE], &nodes, "0, 1, 2");
    assert_view(the_view(&scene), Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z, Vec3::Y, 0.8f32.to_degrees());
    assert_eq!(
        scene.warnings,
        ["test.gltf: camera 0 of node 1: not read: its type is perspective but it has no perspective projection"]
    );
}

#[test]
fn scenes_without_cameras_have_no_view() {
    let scene = load(&[], &[], "0");
    assert_eq!(scene.view, None);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);

    let dir = TempDir::new("gltf-cameras-obj");
    let obj = dir.write("triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let ply = dir.write(
        "triangle.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
    );
    for path in [obj, ply] {
        assert_eq!(Scene::load(&path).expect("a valid scene").view, None, "{}", path.display());
    }
    assert_eq!(Scene::builtin().expect("the built-in scene").view, None);
}
