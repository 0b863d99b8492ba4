//! Wavefront OBJ + MTL loading, written for this crate rather than taken from tobj because we need
//! errors with file and line, gKit's exact triangle order, and parallel parsing of 45 MB scans.
//!
//! Large files are cut into chunks at line boundaries and parsed in parallel with rayon. A cheap
//! first pass counts lines and vertices per chunk; their prefix sums give every chunk its first
//! line number and the number of vertices defined before it, so the second pass resolves relative
//! indices and reports errors exactly as a sequential parser would (see `obj/chunk.rs`).
//!
//! Not supported: line continuations (a trailing `\`), free-form geometry, and lone `\r` line ends.

mod chunk;
mod materials;
mod mtl;
mod text;

use crate::error::{Error, Result};
use crate::materials::Material;
use crate::scene::Scene;
use crate::scene::mesh::{NO_INDEX, TriangleMesh};
use crate::util::read;
use chunk::{ChunkCounts, ChunkMesh, ChunkStart, VertexCounts, parse_chunk};
use materials::{MaterialTable, ReadMtl};
use rayon::prelude::*;
use std::io;
use std::path::Path;

/// Chunk size for parallel parsing: large enough that per-chunk overhead is noise, small enough
/// that a 45 MB file gives dozens of chunks to balance across cores.
const CHUNK_BYTES: usize = 1 << 20;

/// What an OBJ file (with its MTL files) gives: the triangles, their materials, and warnings
/// (missing/broken MTL, unknown material names) for the caller to show.
#[derive(Debug, Default)]
pub struct ObjScene {
    pub mesh: TriangleMesh,
    pub materials: Vec<Material>,
    pub warnings: Vec<String>,
}

impl ObjScene {
    /// The scene these parts make, named `name` in messages (see [`Scene::from_parts`]).
    pub fn into_scene(self, name: String) -> Result<Scene> {
        Scene::from_parts(name, self.mesh, self.materials, self.warnings)
    }
}

/// Loads `path` (`.obj` or `.obj.gz`); `mtllib` files resolve relative to the OBJ's folder.
pub fn load_obj(path: &Path) -> Result<ObjScene> {
    let bytes = read::read_input(path).map_err(|error| Error::io(path, error))?;
    let folder = path.parent().unwrap_or(Path::new(""));
    let read_mtl = |name: &str| {
        let mtl = folder.join(name);
        match read::read_input(&mtl) {
            Ok(bytes) => Ok((bytes, mtl)),
            // The OBJ only knows the name; the warning should say where we looked.
            Err(error) => Err(io::Error::new(error.kind(), format!("{}: {error}", mtl.display()))),
        }
    };
    parse_obj(&bytes, path, &read_mtl)
}

/// Parses OBJ text. `name` is used in error messages; `read_mtl(file_name)` returns the MTL file's
/// bytes and the path it came from (for messages and for resolving `map_Kd`), or an I/O error.
#[expect(clippy::type_complexity, reason = "the closure type is spelled out so callers see it in the docs")]
pub fn parse_obj(
    bytes: &[u8],
    name: &Path,
    read_mtl: &dyn Fn(&str) -> std::io::Result<(Vec<u8>, std::path::PathBuf)>,
) -> Result<ObjScene> {
    parse_obj_with_chunk_size(bytes, name, read_mtl, CHUNK_BYTES)
}

/// [`parse_obj`] with a chosen chunk size, so tests can force many chunk boundaries on small
/// inputs and compare with a single chunk (`usize::MAX`).
#[doc(hidden)]
pub fn parse_obj_with_chunk_size(bytes: &[u8], name: &Path, read_mtl: ReadMtl, chunk_bytes: usize) -> Result<ObjScene> {
    // Editors on Windows may start the file with a UTF-8 byte-order mark.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let chunks = split_lines(bytes, chunk_bytes.max(1));
    let counts: Vec<ChunkCounts> = chunks.par_iter().map(|chunk| ChunkCounts::of(chunk)).collect();
    let (starts, totals) = chunk_starts(&counts);
    let parsed: Vec<Result<ChunkMesh>> = (chunks.par_iter().zip(&counts).zip(starts))
        .map(|((chunk, counts), start)| parse_chunk(chunk, counts, start, totals, name))
        .collect();
    // Sequentially, so that the error reported is the first one in the file.
    let parsed = parsed.into_iter().collect::<Result<Vec<_>>>()?;
    let libraries = parsed.iter().flat_map(|chunk| &chunk.libraries);
    let mut table = MaterialTable::load(libraries, name, read_mtl);
    let material_ids = material_ids(&parsed, &mut table, name);
    Ok(ObjScene { mesh: merge(&parsed, material_ids), materials: table.materials, warnings: table.warnings })
}

/// Cuts `bytes` into pieces of about `target` bytes, each ending just after a `\n` (but the last).
fn split_lines(bytes: &[u8], target: usize) -> Vec<&[u8]> {
    let mut chunks = Vec::new();
    let mut rest = bytes;
    while rest.len() > target {
        let Some(newline) = rest[target..].iter().position(|&b| b == b'\n') else {
            break;
        };
        let (chunk, tail) = rest.split_at(target + newline + 1);
        chunks.push(chunk);
        rest = tail;
    }
    chunks.push(rest);
    chunks
}

/// Prefix sums of the chunk counts: where each chunk starts, and the file's vertex totals.
fn chunk_starts(counts: &[ChunkCounts]) -> (Vec<ChunkStart>, VertexCounts) {
    let mut next = ChunkStart::default();
    let starts = counts
        .iter()
        .map(|count| {
            let start = next;
            next = ChunkStart { line: start.line + count.lines, vertices: start.vertices + count.vertices };
            start
        })
        .collect();
    (starts, next.vertices)
}

/// Gives every triangle the material of the last `usemtl` before it. Names are resolved only for
/// materials that triangles use, so the default material appears only when some face needs it.
fn material_ids(chunks: &[ChunkMesh], table: &mut MaterialTable, obj: &Path) -> Vec<u32> {
    let mut ids = Vec::with_capacity(chunks.iter().map(|chunk| chunk.indices.len()).sum());
    let mut current = None;
    let mut first_triangle = 0;
    for chunk in chunks {
        for switch in &chunk.material_switches {
            fill_material(&mut ids, first_triangle + switch.triangle, current, table, obj);
            current = Some((switch.name.as_ref(), switch.line));
        }
        first_triangle += chunk.indices.len();
    }
    fill_material(&mut ids, first_triangle, current, table, obj);
    ids
}

/// Extends `ids` up to triangle `end` with material `used`, if that covers any triangle.
fn fill_material(ids: &mut Vec<u32>, end: usize, used: Option<(&str, usize)>, table: &mut MaterialTable, obj: &Path) {
    if ids.len() < end {
        let id = table.id(used, obj);
        ids.resize(end, id);
    }
}

/// Concatenates the chunks; their indices are already absolute.
fn merge(chunks: &[ChunkMesh], material_ids: Vec<u32>) -> TriangleMesh {
    TriangleMesh {
        positions: concat(chunks, |chunk| &chunk.positions),
        indices: concat(chunks, |chunk| &chunk.indices),
        material_ids,
        normals: concat(chunks, |chunk| &chunk.normals),
        normal_indices: concat_per_triangle(chunks, |chunk| &chunk.normal_indices),
        texcoords: concat(chunks, |chunk| &chunk.texcoords),
        texcoord_indices: concat_per_triangle(chunks, |chunk| &chunk.texcoord_indices),
    }
}

fn concat<'a, T: Copy>(chunks: &[ChunkMesh<'a>], field: impl for<'c> Fn(&'c ChunkMesh<'a>) -> &'c Vec<T>) -> Vec<T> {
    let mut all = Vec::with_capacity(chunks.iter().map(|chunk| field(chunk).len()).sum());
    for chunk in chunks {
        all.extend_from_slice(field(chunk));
    }
    all
}

/// Concatenates per-triangle normal or texture-coordinate indices: empty when no chunk has any,
/// otherwise one entry per triangle, `NO_INDEX` for chunks (or chunk starts) without them.
fn concat_per_triangle<'a>(
    chunks: &[ChunkMesh<'a>],
    field: impl for<'c> Fn(&'c ChunkMesh<'a>) -> &'c Vec<[u32; 3]>,
) -> Vec<[u32; 3]> {
    if chunks.iter().all(|chunk| field(chunk).is_empty()) {
        return Vec::new();
    }
    let mut all = Vec::with_capacity(chunks.iter().map(|chunk| chunk.indices.len()).sum());
    let mut triangles = 0;
    for chunk in chunks {
        all.resize(triangles, [NO_INDEX; 3]);
        all.extend_from_slice(field(chunk));
        triangles += chunk.indices.len();
    }
    all.resize(triangles, [NO_INDEX; 3]);
    all
}
