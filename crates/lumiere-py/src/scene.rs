//! Scenes: loaded from a file, the built-in Cornell box, or built from arrays; each becomes a
//! `World` (BVH and lights) at once, as the CLI does, so a render starts straight away and `info()`
//! describes what will be rendered.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use glam::{Vec2, Vec3};
use lumiere::accel::BuildPreset;
use lumiere::materials::{Material, Relief};
use lumiere::math::UvTransform;
use lumiere::render::fingerprint::scene_fingerprint;
use lumiere::scene::Scene;
use lumiere::scene::camera::View;
use lumiere::scene::load::memory::{MeshSize, check_arrays_memory};
use lumiere::scene::mesh::TriangleMesh;
use lumiere::world::World;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::OrPyErr;
use crate::{pools, watch};

/// A scene ready to render (its BVH and lights built).
#[pyclass(module = "lumiere._lumiere", name = "NativeScene", frozen)]
pub struct PyScene {
    pub world: Arc<World>,
    /// The built-in scene, whose default camera is gKit's orbiter.
    #[pyo3(get)]
    pub builtin: bool,
    /// The fingerprint checkpoints store: geometry, materials and textures, emission included.
    #[pyo3(get)]
    pub fingerprint: u64,
    #[pyo3(get)]
    pub load_seconds: f64,
    #[pyo3(get)]
    pub build_seconds: f64,
}

/// A material given from Python: name, diffuse colour, emission.
type MaterialSpec = (String, [f32; 3], [f32; 3]);

impl PyScene {
    /// Applies `emission` and builds the world, away from the GIL: Ctrl-C returns at once, and
    /// the build ends in the background ([`watch::abandonable`]).
    fn finish(
        py: Python<'_>,
        scene: impl FnOnce() -> lumiere::Result<Scene> + Send + 'static,
        emission: Vec<(String, [f32; 3])>,
        builtin: bool,
    ) -> PyResult<Self> {
        let start = Instant::now();
        let pool = pools::for_background(py)?;
        let (fingerprint, world, load_seconds, build_seconds) = watch::abandonable(py, "a load", move || {
            pool.install(|| {
                let mut scene = scene()?;
                for (name, ke) in emission {
                    scene.set_emission(&name, Vec3::from(ke))?;
                }
                let load_seconds = start.elapsed().as_secs_f64();
                let build = Instant::now();
                let world = World::new(scene, BuildPreset::Default);
                let build_seconds = build.elapsed().as_secs_f64();
                Ok((scene_fingerprint(&world), world, load_seconds, build_seconds))
            })
        })?
        .or_py()?;
        Ok(PyScene { world: Arc::new(world), builtin, fingerprint, load_seconds, build_seconds })
    }
}

#[pymethods]
impl PyScene {
    /// Loads an OBJ file with its MTL or a PLY file (either also gzipped), or the built-in scene
    /// when `path` is None.
    /// Ctrl-C returns at once, as during the build (the load ends in the background, unused).
    #[staticmethod]
    #[pyo3(signature = (path, emission))]
    fn load(py: Python<'_>, path: Option<PathBuf>, emission: Vec<(String, [f32; 3])>) -> PyResult<Self> {
        let builtin = path.is_none();
        let scene = move || match &path {
            Some(path) => Scene::load(path),
            None => Scene::builtin(),
        };
        PyScene::finish(py, scene, emission, builtin)
    }

    /// A scene from float32 positions (x, y, z per vertex), uint32 corner indices (three per
    /// triangle), uint32 material ids (one per triangle) and the materials they index, all as
    /// native-endian bytes; optional float32 per-vertex normals (same indices as positions).
    #[staticmethod]
    #[pyo3(signature = (name, positions, indices, material_ids, materials, normals=None))]
    fn from_arrays(
        py: Python<'_>,
        name: String,
        positions: &[u8],
        indices: &[u8],
        material_ids: &[u8],
        materials: Vec<MaterialSpec>,
        normals: Option<&[u8]>,
    ) -> PyResult<Self> {
        // Refused before the copies below, which a scene too large for memory would abort in.
        let size = MeshSize {
            positions: positions.len() / 12,
            texcoords: 0,
            normals: normals.map_or(0, |n| n.len() / 12),
            triangles: (indices.len() / 12) as u64,
        };
        let held = [positions, indices, material_ids, normals.unwrap_or_default()].iter().map(|b| b.len() as u64).sum();
        check_arrays_memory(&name, size, held).or_py()?;
        // Copied while the GIL is held (the buffers are Python's), converted away from it.
        let arrays = Arrays {
            name,
            positions: positions.to_vec(),
            indices: indices.to_vec(),
            material_ids: material_ids.to_vec(),
            materials,
            normals: normals.map(<[u8]>::to_vec),
        };
        PyScene::finish(py, move || arrays.into_scene(), Vec::new(), false)
    }

    #[getter]
    fn name(&self) -> String {
        self.world.scene().name.clone()
    }

    /// The loader's warnings, then the world's (textures that could not be read or decoded):
    /// everything the CLI prints before a render.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.world.scene().warnings.iter().chain(self.world.warnings()).cloned().collect()
    }

    /// The view the scene file gives itself (a glTF camera) as a dict of `eye`, `target`, `up`,
    /// `fov` (vertical, degrees) and `name`; None for a scene without one.
    #[getter]
    fn view<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.world.scene().view.as_ref().map(|view| view_dict(py, view)).transpose()
    }

    /// Refuses a scene without a triangle, before a render (`Scene::check_has_faces`).
    fn check_has_faces(&self) -> PyResult<()> {
        self.world.scene().check_has_faces().or_py()
    }

    /// What `lumiere info` prints, as a dict.
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let scene = self.world.scene();
        let info = PyDict::new(py);
        info.set_item("name", &scene.name)?;
        info.set_item("triangles", scene.mesh.triangle_count())?;
        info.set_item("vertices", scene.mesh.positions.len())?;
        info.set_item("normals", !scene.mesh.normal_indices.is_empty())?;
        info.set_item("texcoords", !scene.mesh.texcoord_indices.is_empty())?;
        let lights = self.world.lights().lights();
        let light_info = PyDict::new(py);
        light_info.set_item("triangles", lights.len())?;
        light_info.set_item("area", lights.iter().map(|l| l.area).fold(0.0, |a, b| a + b))?;
        light_info.set_item("power", lights.iter().map(|l| l.power()).fold(Vec3::ZERO, |a, b| a + b).to_array())?;
        info.set_item("lights", light_info)?;
        let bounds = scene.bounds();
        if bounds.is_empty() {
            info.set_item("bounds", py.None())?;
        } else {
            // `+ 0.0` turns a negative zero positive, as `lumiere info` prints it.
            info.set_item("bounds", ((bounds.min + 0.0).to_array(), (bounds.max + 0.0).to_array()))?;
        }
        let mut triangles = vec![0usize; scene.materials.len()];
        for &id in &scene.mesh.material_ids {
            triangles[id as usize] += 1;
        }
        let materials = PyDict::new(py);
        for (material, count) in scene.materials.iter().zip(triangles) {
            if let Some(existing) = materials.get_item(&material.name)? {
                // Two materials of one name: count their triangles together, keep the first's colours.
                let before: usize = existing.get_item("triangles")?.extract()?;
                existing.set_item("triangles", before + count)?;
                continue;
            }
            let entry = PyDict::new(py);
            entry.set_item("triangles", count)?;
            entry.set_item("kd", material.kd.to_array())?;
            entry.set_item("ke", material.ke.to_array())?;
            entry.set_item("texture", material.map_kd.as_ref().map(|p| p.display().to_string()))?;
            entry.set_item("texture_placement", placement(py, material.map_kd_transform)?)?;
            entry.set_item("cutout", material.cutout_mask().map(|p| p.display().to_string()))?;
            entry.set_item("cutout_placement", placement(py, material.map_d_transform)?)?;
            for (key, map) in [("metallic_texture", &material.map_pm), ("roughness_texture", &material.map_pr)] {
                entry.set_item(key, map.as_ref().map(|map| map.path.display().to_string()))?;
            }
            // A bump map's file under its own key: its texels are heights, unless they have a
            // normal map's colours (docs/MATERIALS.md).
            let (normals, bumps) = match &material.normal_map {
                Some(map) if map.relief == Relief::Directions => (Some(map), None),
                map => (None, map.as_ref()),
            };
            for (key, map) in [("normal_texture", normals), ("bump_texture", bumps)] {
                entry.set_item(key, map.map(|map| map.path.display().to_string()))?;
            }
            entry.set_item("light", material.is_emissive())?;
            materials.set_item(&material.name, entry)?;
        }
        info.set_item("materials", materials)?;
        info.set_item("view", self.view(py)?)?;
        info.set_item("warnings", self.warnings())?;
        info.set_item("load_seconds", self.load_seconds)?;
        info.set_item("build_seconds", self.build_seconds)?;
        Ok(info)
    }

    fn __repr__(&self) -> String {
        let scene = self.world.scene();
        format!("<lumiere scene {:?}: {} triangles>", scene.name, scene.mesh.triangle_count())
    }
}

/// A scene's view as Python sees it: vectors as tuples, which cannot be changed in place.
fn view_dict<'py>(py: Python<'py>, view: &View) -> PyResult<Bound<'py, PyDict>> {
    let tuple = |v: Vec3| (v.x, v.y, v.z);
    let entry = PyDict::new(py);
    entry.set_item("eye", tuple(view.eye))?;
    entry.set_item("target", tuple(view.target))?;
    entry.set_item("up", tuple(view.up))?;
    entry.set_item("fov", view.fov_degrees)?;
    entry.set_item("name", view.name.as_deref())?;
    Ok(entry)
}

/// A texture's `-s` and `-o` as `{'scale': (u, v), 'offset': (u, v)}`, or `None` where they leave
/// it in place.
fn placement(py: Python<'_>, transform: UvTransform) -> PyResult<Option<Bound<'_, PyDict>>> {
    if transform.is_identity() {
        return Ok(None);
    }
    let entry = PyDict::new(py);
    entry.set_item("scale", transform.scale.to_array())?;
    entry.set_item("offset", transform.offset.to_array())?;
    Ok(Some(entry))
}

/// [`PyScene::from_arrays`]'s buffers, copied out of Python: native-endian float32 and uint32
/// values.
struct Arrays {
    name: String,
    positions: Vec<u8>,
    indices: Vec<u8>,
    material_ids: Vec<u8>,
    materials: Vec<MaterialSpec>,
    normals: Option<Vec<u8>>,
}

impl Arrays {
    fn into_scene(self) -> lumiere::Result<Scene> {
        let name = self.name;
        let floats =
            |b: &[u8]| b.chunks_exact(4).map(|c| f32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect::<Vec<_>>();
        let ints =
            |b: &[u8]| b.chunks_exact(4).map(|c| u32::from_ne_bytes([c[0], c[1], c[2], c[3]])).collect::<Vec<_>>();
        let vec3s = |v: Vec<f32>| v.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect::<Vec<_>>();
        let positions = vec3s(floats(&self.positions));
        if let Some(bad) = positions.iter().position(|p| !p.is_finite()) {
            return Err(lumiere::Error::invalid(format!("{name}: vertex {bad} is not finite")));
        }
        let indices: Vec<[u32; 3]> = ints(&self.indices).chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let normals = self.normals.map(|n| vec3s(floats(&n))).unwrap_or_default();
        if !normals.is_empty() && normals.len() != positions.len() {
            let message = format!("{name}: {} normals for {} vertices", normals.len(), positions.len());
            return Err(lumiere::Error::invalid(message));
        }
        let normal_indices = if normals.is_empty() { Vec::new() } else { indices.clone() };
        let mesh = TriangleMesh {
            material_ids: ints(&self.material_ids),
            positions,
            indices,
            normals,
            normal_indices,
            texcoords: Vec::<Vec2>::new(),
            texcoord_indices: Vec::new(),
        };
        let materials = self
            .materials
            .into_iter()
            .map(|(name, kd, ke)| Material { kd: Vec3::from(kd), ke: Vec3::from(ke), ..Material::default_grey(&name) })
            .collect();
        Scene::from_parts(name, mesh, materials, Vec::new())
    }
}
