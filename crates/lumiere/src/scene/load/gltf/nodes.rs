//! The meshes a glTF scene draws and where, and the cameras it places: its node tree walked from
//! the scene's roots, each node's transform composed with its parents' (in double precision), one
//! instance per node with a mesh, one placed camera per node with a camera. A node reached twice
//! (two parents, or its own ancestor) is refused: the format requires a tree, and a graph could
//! make a few bytes expand without end.

use crate::error::{Error, Result, quote, shown_path};
use crate::scene::load::warnings::Warnings;
use glam::DMat4;
use gltf::Document;
use std::path::Path;

/// One mesh drawn by one node.
pub(super) struct Instance {
    pub(super) node: usize,
    pub(super) mesh: usize,
    /// From the mesh's coordinates to the scene's.
    pub(super) transform: DMat4,
}

/// One camera placed by one node.
pub(super) struct PlacedCamera {
    pub(super) node: usize,
    pub(super) camera: usize,
    /// From the camera's coordinates to the scene's.
    pub(super) transform: DMat4,
}

/// What the walk of the node tree found, each list in the walk's order.
pub(super) struct Walked {
    pub(super) instances: Vec<Instance>,
    pub(super) cameras: Vec<PlacedCamera>,
}

/// Every mesh the file's scene draws and every camera it places, in the order of a depth-first
/// walk from its roots (a node before its children, children in the order the file lists them,
/// roots in the scene's order). The scene is the file's `scene`, else its first; a file without
/// scenes draws every node that is no node's child, in the file's order.
pub(super) fn walk(document: &Document, file: &Path, warnings: &mut Warnings) -> Result<Walked> {
    let scene = document.default_scene().or_else(|| document.scenes().next());
    let roots: Vec<usize> = match &scene {
        Some(scene) => scene.nodes().map(|node| node.index()).collect(),
        None => {
            let mut is_child = vec![false; document.nodes().len()];
            for child in document.nodes().flat_map(|node| node.children()) {
                is_child[child.index()] = true;
            }
            (0..is_child.len()).filter(|&i| !is_child[i]).collect()
        }
    };
    if let Some(scene) = &scene
        && document.scenes().len() > 1
    {
        let named = scene.name().map(|name| format!(" ({})", quote(name))).unwrap_or_default();
        let count = document.scenes().len();
        warnings.push(file, "scenes not drawn", || {
            format!("{}: the file has {count} scenes; drawing scene {}{named}", shown_path(file), scene.index())
        });
    }
    let nodes: Vec<gltf::Node> = document.nodes().collect();
    let mut reached = vec![false; nodes.len()];
    let mut stack: Vec<(usize, DMat4)> = roots.iter().rev().map(|&root| (root, DMat4::IDENTITY)).collect();
    let (mut instances, mut cameras) = (Vec::new(), Vec::new());
    while let Some((index, parent)) = stack.pop() {
        if std::mem::replace(&mut reached[index], true) {
            return Err(Error::invalid(format!(
                "{}: node {index} is reached twice from the scene's roots; glTF nodes must form a tree (no node \
                 with two parents, none its own ancestor)",
                shown_path(file)
            )));
        }
        let node = &nodes[index];
        let matrix = node.transform().matrix().map(|column| column.map(f64::from));
        let transform = parent * DMat4::from_cols_array_2d(&matrix);
        if !transform.is_finite() {
            return Err(Error::invalid(format!("{}: node {index}: its transform is not finite", shown_path(file))));
        }
        if let Some(mesh) = node.mesh() {
            instances.push(Instance { node: index, mesh: mesh.index(), transform });
        }
        if let Some(camera) = node.camera() {
            cameras.push(PlacedCamera { node: index, camera: camera.index(), transform });
        }
        stack.extend(node.children().map(|child| (child.index(), transform)).collect::<Vec<_>>().into_iter().rev());
    }
    Ok(Walked { instances, cameras })
}
