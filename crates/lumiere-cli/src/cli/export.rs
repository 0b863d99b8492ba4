//! Binary export of a benchmark scene's triangles and ray sets, read by `bench/embree_compare.py`.
//!
//! All numbers little-endian. `mesh.bin`: `b"LMSH"`, u32 version 1, u64 triangle count, then per
//! triangle 9 f32 (three corners, in scene id order). `<kind>-<query>.rays`: `b"LRAY"`, u32 version 1,
//! u64 ray count, then per ray 7 f32 (origin, direction, tmax; tmax may be +inf). `<kind>-<query>.expect`:
//! lumiere's answers, per ray an i32 triangle id (-1 for a miss) for `closest`, a u8 0/1 for `occluded`.

use std::path::Path;

use crate::bench::rays::{Query, RaySet};
use lumiere::scene::mesh::TriangleMesh;
use lumiere::util::write::write_atomically;
use lumiere::world::World;
use lumiere::{Error, Result};

pub fn export_ray_sets(dir: &Path, world: &World, sets: &[RaySet]) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    write_atomically(&dir.join("mesh.bin"), &mesh_bytes(&world.scene().mesh))?;
    for set in sets {
        let stem = format!("{}-{}", set.kind, set.query.name());
        let mut rays = header(b"LRAY", set.rays.len());
        for r in &set.rays {
            for v in [r.origin.to_array(), r.dir.to_array()].concat().into_iter().chain([r.tmax]) {
                rays.extend_from_slice(&v.to_le_bytes());
            }
        }
        write_atomically(&dir.join(format!("{stem}.rays")), &rays)?;
        let expect: Vec<u8> = match set.query {
            Query::Closest => set
                .rays
                .iter()
                .flat_map(|r| world.intersect(r).map_or(-1, |h| h.triangle as i32).to_le_bytes())
                .collect(),
            Query::Occluded => set.rays.iter().map(|r| u8::from(world.occluded(r))).collect(),
        };
        write_atomically(&dir.join(format!("{stem}.expect")), &expect)?;
    }
    Ok(())
}

fn header(magic: &[u8; 4], count: usize) -> Vec<u8> {
    let mut bytes = magic.to_vec();
    bytes.extend_from_slice(&1u32.to_le_bytes());
    bytes.extend_from_slice(&(count as u64).to_le_bytes());
    bytes
}

fn mesh_bytes(mesh: &TriangleMesh) -> Vec<u8> {
    let mut bytes = header(b"LMSH", mesh.triangle_count());
    for id in 0..mesh.triangle_count() {
        for corner in mesh.vertices(id) {
            for v in corner.to_array() {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    bytes
}
