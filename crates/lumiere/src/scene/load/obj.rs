//! Wavefront OBJ + MTL loading, written for this crate rather than taken from tobj because we need
//! errors with file and line, gKit's exact triangle order, and parallel parsing of 45 MB scans.
//!
//! Large files are cut into chunks at line boundaries and parsed in parallel with rayon. A cheap
//! first pass counts lines and vertices per chunk; their prefix sums give every chunk its first
//! line number and the number of vertices defined before it, so the second pass resolves relative
//! indices and reports errors exactly as a sequential parser would (see `obj/chunk.rs`).
//!
//! Line continuations (a trailing `\`) are joined before the file is cut (`obj/continued.rs`).
//!
//! Not supported: free-form geometry, polylines and points (each skipped keyword is warned about
//! once, with its count), and lone `\r` line ends (refused with an error, as an MTL file with them
//! is warned about and not read).

mod chunk;
mod continued;
mod materials;
mod mtl;
mod skipped;
mod text;

use crate::error::{Error, Result, shown_bytes, shown_path};
use crate::materials::Material;
use crate::scene::Scene;
use crate::scene::load::memory::{Memory, MeshSize, check_mesh_memory};
use crate::scene::load::path_from_bytes;
use crate::scene::load::polygon;
use crate::scene::mesh::{NO_INDEX, TriangleMesh};
use crate::util::read;
use chunk::{ChunkCounts, ChunkMesh, ChunkStart, Dropped, VertexCounts, parse_chunk};
use materials::{MaterialTable, MtlSource, ReadMtl};
use rayon::prelude::*;
use skipped::SkippedStatements;
use std::io;
use std::path::{Path, PathBuf};
use text::text;

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
    /// The MTL files read, as resolved.
    pub material_files: Vec<std::path::PathBuf>,
}

impl ObjScene {
    /// The scene these parts make, named `name` in messages (see [`Scene::from_parts`]).
    pub fn into_scene(self, name: String) -> Result<Scene> {
        let mut scene = Scene::from_parts(name, self.mesh, self.materials, self.warnings)?;
        scene.sources = self.material_files;
        Ok(scene)
    }
}

/// Loads `path` (`.obj` or `.obj.gz`); `mtllib` files resolve relative to the OBJ's folder.
///
/// Every file is read through [`read::read_regular_file`] (FIFOs, devices and directories are
/// refused); a scene whose mesh and BVH would not fit in the memory left is refused before its
/// triangles are allocated; an MTL file named many times is read once.
pub fn load_obj(path: &Path) -> Result<ObjScene> {
    load_obj_within(path, Memory::System)
}

/// [`load_obj`] as if `available` bytes of memory were left, so that tests can check the
/// refusal of scenes too big for memory without allocating gigabytes.
#[doc(hidden)]
pub fn load_obj_with_memory(path: &Path, available: u64) -> Result<ObjScene> {
    load_obj_within(path, Memory::Given(available))
}

fn load_obj_within(path: &Path, memory: Memory) -> Result<ObjScene> {
    let given = match memory {
        Memory::System => read::available_memory(),
        Memory::Given(bytes) => Some(bytes),
    };
    let bytes = read::read_input_with_memory(path, given).map_err(|error| Error::io(path, error))?;
    let folder = path.parent().unwrap_or(Path::new(""));
    // `a.mtl`, `./a.mtl` and `.//a.mtl` are one file, and so is `x/../a.mtl` when it exists.
    let lexical = |name: &Path| folder.join(name).components().collect::<PathBuf>();
    let locate = |name: &[u8]| {
        let name = path_from_bytes(name.to_vec());
        Some(std::fs::canonicalize(folder.join(&name)).unwrap_or_else(|_| lexical(&name)))
    };
    let read_mtl = |name: &[u8]| {
        let name = path_from_bytes(name.to_vec());
        let mtl = lexical(&name);
        match read::read_input(&mtl) {
            Ok(bytes) => Ok((bytes, mtl)),
            // The OBJ only knows the name; the warning should say where a relative one was looked for.
            Err(error) if name.is_relative() => {
                let looked_in = if folder.as_os_str().is_empty() { Path::new(".") } else { folder };
                Err(io::Error::new(error.kind(), format!("{error}; looked in {}", shown_path(looked_in))))
            }
            Err(error) => Err(error),
        }
    };
    parse_obj_within(&bytes, path, MtlSource { read: &read_mtl, locate: &locate }, CHUNK_BYTES, memory)
}

/// Parses OBJ text. `name` is used in error messages; `read_mtl(file_name)` returns the MTL file's
/// bytes and the path it came from (for messages and for resolving `map_Kd`), or an I/O error. It
/// gets each name as text ([`text::text`]: Latin-1 where the bytes are not UTF-8), unescaped, with
/// backslashes read as `/`; files on disk ([`load_obj`]) are found by the name's bytes.
/// Each MTL file (by the path `read_mtl` returns) is read and warned about once.
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
    let read = |name: &[u8]| read_mtl(&text(name));
    parse_obj_within(bytes, name, MtlSource { read: &read, locate: &|_| None }, chunk_bytes, Memory::System)
}

/// [`parse_obj`] as if `available` bytes of memory were left (see [`load_obj_with_memory`]).
#[doc(hidden)]
pub fn parse_obj_with_memory(bytes: &[u8], name: &Path, read_mtl: ReadMtl, available: u64) -> Result<ObjScene> {
    let read = |name: &[u8]| read_mtl(&text(name));
    let source = MtlSource { read: &read, locate: &|_| None };
    parse_obj_within(bytes, name, source, CHUNK_BYTES, Memory::Given(available))
}

fn parse_obj_within(
    bytes: &[u8],
    name: &Path,
    source: MtlSource,
    chunk_bytes: usize,
    memory: Memory,
) -> Result<ObjScene> {
    // Editors on Windows may start the file with a UTF-8 byte-order mark.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if text::has_lone_carriage_returns(bytes) {
        return Err(Error::parse(name, 1, text::LONE_CARRIAGE_RETURNS));
    }
    let joined =
        if continued::has_continuations(bytes) { Some(join_continued_lines(bytes, name, memory)?) } else { None };
    let bytes = joined.as_deref().unwrap_or(bytes);
    let chunks = split_lines(bytes, chunk_bytes.max(1));
    let counts: Vec<ChunkCounts> = chunks.par_iter().map(|chunk| ChunkCounts::of(chunk)).collect();
    let (starts, totals) = chunk_starts(&counts);
    let triangles = counts.iter().map(|count| count.triangles as u64).sum();
    let size =
        MeshSize { positions: totals.positions, texcoords: totals.texcoords, normals: totals.normals, triangles };
    check_mesh_memory(name, size, 0, memory, "mesh and BVH")?;
    let parsed: Vec<Result<ChunkMesh>> = (chunks.par_iter().zip(&counts).zip(starts))
        .map(|((chunk, counts), start)| parse_chunk(chunk, counts, start, totals, name))
        .collect();
    // Sequentially, so that the error reported is the first one in the file.
    let parsed = parsed.into_iter().collect::<Result<Vec<_>>>()?;
    let skipped = SkippedStatements::of(parsed.iter().map(|chunk| &chunk.skipped));
    skipped.refuse_if_not_obj(parsed.iter().any(|chunk| !chunk.indices.is_empty()), name)?;
    let libraries = parsed.iter().flat_map(|chunk| &chunk.libraries);
    let mut table = MaterialTable::load(libraries, name, source);
    let material_ids = material_ids(&parsed, &mut table, name);
    let dropped = |field: fn(&ChunkMesh) -> Dropped| parsed.iter().fold(Dropped::default(), |a, c| a.merge(field(c)));
    let (texcoords, normals) = (dropped(|c| c.dropped_texcoords), dropped(|c| c.dropped_normals));
    let kind = "texture-coordinate indices out of range";
    warn_dropped(&mut table, name, texcoords, "texture-coordinate", "texture coordinates", kind);
    warn_dropped(&mut table, name, normals, "normal", "normals", "normal indices out of range");
    skipped.warn(&mut table.warnings, name);
    let mut mesh = merge(&parsed, material_ids);
    polygon::clip_concave_faces(&mut mesh, &polygons_in_file(&parsed)).warn(&mut table.warnings, name);
    let warnings = std::mem::take(&mut table.warnings).finish();
    Ok(ObjScene { mesh, materials: table.materials, warnings, material_files: table.files })
}

/// The text with its continued lines joined (`obj/continued.rs`), in a copy refused up front, as
/// a mesh is, when it would not fit in the memory left.
fn join_continued_lines(bytes: &[u8], name: &Path, memory: Memory) -> Result<Vec<u8>> {
    let needed = bytes.len() as u64;
    let refuse = |available: Option<u64>| {
        let available =
            available.map_or(String::new(), |bytes| format!(", but only {} is available", shown_bytes(bytes)));
        let message =
            format!("joining its continued lines needs a copy of its {}{available}; refusing it", shown_bytes(needed));
        Error::io(name, io::Error::new(io::ErrorKind::OutOfMemory, message))
    };
    match memory.available(needed) {
        Some(available) if needed > available => Err(refuse(Some(available))),
        _ => continued::joined(bytes).map_err(|_| refuse(None)),
    }
}

/// One warning for all the faces that lost `what` indices because they pointed at nothing.
fn warn_dropped(table: &mut MaterialTable, obj: &Path, dropped: Dropped, what: &str, plural: &str, kind: &'static str) {
    let (Some(line), faces) = (dropped.first_line, dropped.faces) else { return };
    table.warnings.push(obj, kind, || {
        let (have, those) = if faces == 1 { ("face has", "its") } else { ("faces have", "those") };
        format!(
            "{}:{line}: {faces} {have} {what} indices out of range (the first on this line); {those} {plural} are ignored",
            shown_path(obj)
        )
    });
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

/// The faces of more than three corners of every chunk, with their first triangle in the file.
fn polygons_in_file(chunks: &[ChunkMesh]) -> Vec<polygon::Polygon> {
    let mut polygons = Vec::with_capacity(chunks.iter().map(|chunk| chunk.polygons.len()).sum());
    let mut triangles = 0;
    for chunk in chunks {
        let offset = |p: &polygon::Polygon| polygon::Polygon { first_triangle: p.first_triangle + triangles, ..*p };
        polygons.extend(chunk.polygons.iter().map(offset));
        triangles += chunk.indices.len();
    }
    polygons
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
