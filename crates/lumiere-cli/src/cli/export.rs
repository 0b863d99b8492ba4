//! Binary export of a benchmark scene's triangles and ray sets, read by `bench/embree_compare.py`.
//!
//! All numbers little-endian. `mesh.bin`: `b"LMSH"`, u32 version 1, u64 triangle count, then per
//! triangle 9 f32 (three corners, in scene id order). `<kind>-<query>.rays`: `b"LRAY"`, u32 version 1,
//! u64 ray count, then per ray 7 f32 (origin, direction, tmax; tmax may be +inf). `<kind>-<query>.expect`:
//! lumiere's answers, per ray an i32 triangle id (-1 for a miss) for `closest`, a u8 0/1 for `occluded`.

use std::fs;
use std::path::{Path, PathBuf};

use crate::bench::rays::{Query, RaySet};
use lumiere::error::shown_path;
use lumiere::scene::mesh::TriangleMesh;
use lumiere::util::write::{check_writable, write_atomically};
use lumiere::world::World;
use lumiere::{Error, Result};

/// Makes `dir` (and its parents) if needed and checks that files can be created in it and that
/// each scene's folder there (`scenes`) is one or does not exist yet: called before any
/// measurement, so that a bad folder is refused at once, not after minutes.
pub fn prepare_export_dir(dir: &Path, scenes: &[&str]) -> Result<()> {
    // What is there already, named: `create_dir_all` would only say "File exists".
    match fs::metadata(dir) {
        Ok(metadata) if !metadata.is_dir() => {
            return Err(Error::invalid(format!(
                "{}: exists and is not a folder (a file, a device or a FIFO); give a folder to export the rays into",
                shown_path(dir)
            )));
        }
        Err(_) if fs::symlink_metadata(dir).is_ok() => {
            return Err(Error::invalid(format!("{}: is a link to nothing; give a folder", shown_path(dir))));
        }
        _ => fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?,
    }
    check_writable(&dir.join("mesh.bin"))?;
    for scene in scenes {
        check_scene_dir(&dir.join(scene))?;
    }
    Ok(())
}

/// Refuses a scene folder that exists as anything but a folder (a file, a link): replacing it
/// would replace what the user put there.
fn check_scene_dir(dir: &Path) -> Result<()> {
    match fs::symlink_metadata(dir) {
        Ok(metadata) if !metadata.is_dir() => Err(Error::invalid(format!(
            "{}: exists and is not a folder; lumiere replaces only a folder of exported rays there",
            shown_path(dir)
        ))),
        _ => Ok(()),
    }
}

/// Writes a scene's set of files as the folder `dir`, whole or not at all: into a temporary
/// sibling first, which then takes `dir`'s place. A run that fails (a full disk) leaves the last
/// complete set as it was, and never a folder that mixes two runs' files.
pub fn export_ray_sets(dir: &Path, world: &World, sets: &[RaySet]) -> Result<()> {
    check_scene_dir(dir)?;
    let partial = new_sibling(dir, "partial")?;
    if let Err(e) = write_files(&partial, world, sets) {
        let _ = fs::remove_dir_all(&partial);
        // Named as the file it was for: the temporary folder is gone.
        return Err(match e {
            Error::Io { path, source } => {
                Error::io(&path.strip_prefix(&partial).map_or(path.clone(), |rest| dir.join(rest)), source)
            }
            other => other,
        });
    }
    replace_dir(&partial, dir)
}

/// A new empty folder beside `dir`, `.<dir's name>.<what>-<pid>-<n>`, at the first `n` whose name
/// is free: whatever else is there was not made by this run, and is neither reused nor removed.
fn new_sibling(dir: &Path, what: &str) -> Result<PathBuf> {
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    for n in 0u32.. {
        let sibling = dir.with_file_name(format!(".{name}.{what}-{}-{n}", std::process::id()));
        match fs::create_dir(&sibling) {
            Ok(()) => return Ok(sibling),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(Error::io(&sibling, e)),
        }
    }
    unreachable!("a free name among 2^32")
}

/// Moves the complete folder `new` to `dir`. The folder there before, if any, is first renamed
/// over a new empty sibling (a rename may replace an empty folder), then removed once `new` is in
/// place, or moved back if that fails.
fn replace_dir(new: &Path, dir: &Path) -> Result<()> {
    let old = if dir.exists() {
        let old = new_sibling(dir, "old").inspect_err(|_| {
            let _ = fs::remove_dir_all(new);
        })?;
        if let Err(e) = fs::rename(dir, &old) {
            let _ = fs::remove_dir_all(new);
            let _ = fs::remove_dir(&old);
            return Err(Error::io(dir, e));
        }
        Some(old)
    } else {
        None
    };
    if let Err(e) = fs::rename(new, dir) {
        let _ = fs::remove_dir_all(new);
        if let Some(old) = &old {
            let _ = fs::rename(old, dir);
        }
        return Err(Error::io(dir, e));
    }
    if let Some(old) = old {
        let _ = fs::remove_dir_all(old);
    }
    Ok(())
}

fn write_files(dir: &Path, world: &World, sets: &[RaySet]) -> Result<()> {
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
