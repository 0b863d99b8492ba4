//! What a render is about: triangles and their materials, in a format-neutral [`Scene`], and the
//! camera. Loaders (`load/`) turn files into scenes; the built-in scene is embedded.

pub mod builtin;
pub mod camera;
pub mod load;
pub mod mesh;
mod texcoords;

use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::error::{Error, Result, shown_name};
use crate::materials::Material;
use crate::math::Aabb;
use crate::textures::EmbeddedImages;
use camera::View;
use mesh::TriangleMesh;

/// A loaded scene: triangles in file order and their materials. Lights, the BVH and everything
/// else derived from it are built once in `World::new`.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub mesh: TriangleMesh,
    pub materials: Vec<Material>,
    /// Non-fatal problems met while loading (missing MTL, unknown material), for the user to see.
    pub warnings: Vec<String>,
    /// The files read besides the scene file itself (material libraries, glTF buffers), so that
    /// no output ever overwrites one; textures are named by their materials.
    pub sources: Vec<std::path::PathBuf>,
    /// The images the scene file carries inside itself (glTF), under the names its materials'
    /// `map_kd` give them in place of a file's path.
    pub embedded_images: EmbeddedImages,
    /// The view the scene file gives itself (a glTF camera), which front ends use when the user
    /// gives no camera; `None` from OBJ, PLY, arrays and the built-in scene.
    pub view: Option<View>,
}

impl Scene {
    /// Loads a scene file, choosing the loader by its extension (see [`load::load`]).
    pub fn load(path: &Path) -> Result<Scene> {
        load::load(path)
    }

    /// The files read besides the scene file itself: the material libraries or buffers, then every
    /// texture file the materials name (`map_Kd`, `map_d`, `map_Pm`, `map_Pr`, normal maps; not the images embedded in the scene
    /// file), whether or not it could be decoded. No output may overwrite one
    /// (`util::overwrite::check_scene_files`).
    pub fn files_read(&self) -> impl Iterator<Item = &Path> {
        let textures = self.materials.iter().flat_map(|m| {
            let parameter_maps = [&m.map_pm, &m.map_pr].map(|map| map.as_ref().map(|map| map.path.as_path()));
            let normal_map = m.normal_map.as_ref().map(|map| map.path.as_path());
            [m.map_kd.as_deref(), m.map_d.as_deref(), normal_map].into_iter().chain(parameter_maps)
        });
        let textures = textures.flatten();
        let textures = textures.filter(|texture| !self.embedded_images.contains(texture));
        self.sources.iter().map(PathBuf::as_path).chain(textures)
    }

    /// gKit's Cornell box, embedded in the binary.
    pub fn builtin() -> Result<Scene> {
        builtin::cornell_box()?.into_scene(builtin::NAME.to_string())
    }

    /// A scene from its parts, whatever their source (a file loader, a binding, a test); refuses
    /// parts that do not fit together (an index or material id out of range).
    pub fn from_parts(
        name: String,
        mesh: TriangleMesh,
        mut materials: Vec<Material>,
        mut warnings: Vec<String>,
    ) -> Result<Scene> {
        if let Some(bad) = mesh.material_ids.iter().find(|&&m| m as usize >= materials.len()) {
            return Err(Error::invalid(format!("{name}: material id {bad} out of range")));
        }
        if mesh.material_ids.len() != mesh.indices.len() {
            return Err(Error::invalid(format!(
                "{name}: {} triangles but {} material ids",
                mesh.indices.len(),
                mesh.material_ids.len()
            )));
        }
        if let Some(bad) = mesh.indices.iter().flatten().find(|&&i| i as usize >= mesh.positions.len()) {
            return Err(Error::invalid(format!("{name}: vertex index {bad} out of range")));
        }
        // The loaders check these already; scenes made from arrays (Python) are checked here.
        for material in &materials {
            check_emission(&name, &material.name, material.ke)?;
        }
        if let Some(bad) = materials.iter().find(|m| !m.kd.is_finite()) {
            return Err(Error::invalid(format!(
                "{name}: material {}: colour {} {} {} must be finite",
                shown_name(&bad.name),
                bad.kd.x,
                bad.kd.y,
                bad.kd.z
            )));
        }
        if let Some(bad) = mesh.normals.iter().position(|n| !n.is_finite()) {
            return Err(Error::invalid(format!("{name}: normal {bad} is not finite")));
        }
        // The MTL loader clamps its colours where it can name their line; this catches the rest
        // (materials given as arrays).
        for material in &mut materials {
            if let Some(clamped) = material.clamp_kd() {
                warnings.push(format!("{name}: material {}: {clamped}", shown_name(&material.name)));
            }
        }
        warnings.extend(texcoords::warnings(&name, &mesh, &materials));
        Ok(Scene {
            name,
            mesh,
            materials,
            warnings,
            sources: Vec::new(),
            embedded_images: EmbeddedImages::default(),
            view: None,
        })
    }

    /// Sets the emission of every material called `name`.
    pub fn set_emission(&mut self, name: &str, emission: Vec3) -> Result<()> {
        check_emission(&self.name, name, emission)?;
        let mut found = false;
        for material in self.materials.iter_mut().filter(|m| m.name == name) {
            material.ke = emission;
            found = true;
        }
        if !found {
            return Err(Error::invalid(format!("{}: no material named {}", self.name, shown_name(name))));
        }
        Ok(())
    }

    /// Refuses, before a render, a scene without a triangle (a file of vertices alone, or an
    /// empty one), which every mode would render black.
    pub fn check_has_faces(&self) -> Result<()> {
        if self.mesh.triangle_count() > 0 {
            return Ok(());
        }
        Err(Error::invalid(format!("{}: the scene has no faces, so there is nothing to render", self.name)))
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(&self.mesh.positions)
    }

    /// The material of triangle `id`.
    #[inline]
    pub fn material(&self, id: u32) -> &Material {
        &self.materials[self.mesh.material_ids[id as usize] as usize]
    }
}

/// Refuses an emission that is negative or not finite (the light table's weights would be
/// meaningless), naming the scene and the material: from files, from arrays or from `--emission`.
fn check_emission(scene: &str, material: &str, ke: Vec3) -> Result<()> {
    if ke.is_finite() && ke.min_element() >= 0.0 {
        return Ok(());
    }
    Err(Error::invalid(format!(
        "{scene}: material {}: emission {} {} {} must be finite and not negative",
        shown_name(material),
        ke.x,
        ke.y,
        ke.z
    )))
}
