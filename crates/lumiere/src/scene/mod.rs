//! Everything a render needs to know about the world: triangles, materials, lights, camera.

pub mod builtin;
pub mod camera;
pub mod material;
pub mod mesh;
pub mod obj;

use std::path::Path;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::lights::{AreaLight, collect_lights};
use crate::math::Aabb;
use material::Material;
use mesh::TriangleMesh;
use obj::ObjScene;

/// A loaded scene: triangles in file order, their materials and the lights derived from them.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub mesh: TriangleMesh,
    pub materials: Vec<Material>,
    pub lights: Vec<AreaLight>,
    /// Non-fatal problems met while loading (missing MTL, unknown material), for the user to see.
    pub warnings: Vec<String>,
}

impl Scene {
    /// Loads an OBJ (or `.obj.gz`) file with its MTL files.
    pub fn load(path: &Path) -> Result<Scene> {
        Scene::from_obj(obj::load_obj(path)?, path.display().to_string())
    }

    /// gKit's Cornell box, embedded in the binary.
    pub fn builtin() -> Result<Scene> {
        Scene::from_obj(builtin::cornell_box()?, builtin::NAME.to_string())
    }

    pub fn from_obj(obj: ObjScene, name: String) -> Result<Scene> {
        let ObjScene { mesh, materials, warnings } = obj;
        if let Some(bad) = mesh.material_ids.iter().find(|&&m| m as usize >= materials.len()) {
            return Err(Error::invalid(format!("{name}: material id {bad} out of range")));
        }
        let lights = collect_lights(&mesh, &materials);
        Ok(Scene { name, mesh, materials, lights, warnings })
    }

    /// Sets the emission of every material called `name` and recomputes the lights.
    pub fn set_emission(&mut self, name: &str, emission: Vec3) -> Result<()> {
        let mut found = false;
        for material in self.materials.iter_mut().filter(|m| m.name == name) {
            material.ke = emission;
            found = true;
        }
        if !found {
            return Err(Error::invalid(format!("{}: no material named '{name}'", self.name)));
        }
        self.lights = collect_lights(&self.mesh, &self.materials);
        Ok(())
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
