//! Textured materials on triangles without texture coordinates. Their textures are read at
//! `u = v = 0` there (one texel over the whole triangle) and their normal or bump maps are not
//! applied: a file that leaves the coordinates out (an OBJ face `f 1 2 3` under a material with a
//! `map_Kd`, a glTF primitive without `TEXCOORD_0`) renders without an error but not as drawn, so
//! the scene says so, once per material.

use super::mesh::{NO_INDEX, TriangleMesh};
use crate::error::shown_name;
use crate::materials::Material;

/// One warning for each textured material of `materials` some of whose triangles in `mesh` have
/// no texture coordinates, naming how many, for the scene `name`.
pub(super) fn warnings(name: &str, mesh: &TriangleMesh, materials: &[Material]) -> Vec<String> {
    let textured: Vec<bool> = materials.iter().map(Material::reads_texture_coordinates).collect();
    if !textured.contains(&true) {
        return Vec::new();
    }
    let (mut without, mut total) = (vec![0usize; materials.len()], vec![0usize; materials.len()]);
    for (id, &material) in mesh.material_ids.iter().enumerate() {
        let m = material as usize;
        if textured[m] {
            total[m] += 1;
            let given = mesh.texcoord_indices.get(id).is_some_and(|corners| !corners.contains(&NO_INDEX));
            without[m] += usize::from(!given);
        }
    }
    let warning = |(m, material): (usize, &Material)| {
        (without[m] > 0).then(|| {
            let relief = if material.normal_map.is_some() { ", and its normal or bump map is not applied" } else { "" };
            format!(
                "{name}: material {}: {} of its {} triangles have no texture coordinates: its textures are read at \
                 u = v = 0 there{relief}",
                shown_name(&material.name),
                without[m],
                total[m]
            )
        })
    };
    materials.iter().enumerate().filter_map(warning).collect()
}
