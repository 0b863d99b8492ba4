//! One chunk of OBJ lines, parsed on its own so that chunks can run in parallel.
//!
//! A chunk is parsed in two passes. [`ChunkCounts::of`] only counts lines and vertices; the prefix
//! sums of those counts tell every chunk where it starts ([`ChunkStart`]) and how many vertices the
//! whole file has. [`parse_chunk`] then turns relative (negative) indices into absolute ones at
//! once and reports errors with their line number in the file, with no fix-up pass afterwards.

use super::skipped::{SkippedKeywords, is_silent};
use super::text::{Tokens, finite_f32, lines, saturating_i64};
use crate::error::{Error, Result, quote};
use crate::scene::load::polygon::Polygon;
use crate::scene::mesh::NO_INDEX;
use glam::{Vec2, Vec3};
use std::borrow::Cow;
use std::ops::Add;
use std::path::Path;

/// How many of each vertex attribute a stretch of the file defines.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct VertexCounts {
    pub(super) positions: usize,
    pub(super) texcoords: usize,
    pub(super) normals: usize,
}

impl Add for VertexCounts {
    type Output = Self;

    fn add(self, other: Self) -> Self {
        VertexCounts {
            positions: self.positions + other.positions,
            texcoords: self.texcoords + other.texcoords,
            normals: self.normals + other.normals,
        }
    }
}

/// The first pass over a chunk: what it defines, without parsing any number.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ChunkCounts {
    /// Number of `\n` in the chunk; chunks end right after a `\n`, except the last one.
    pub(super) lines: usize,
    pub(super) vertices: VertexCounts,
    /// Triangles the `f` lines make once fanned (a face of n corners makes n - 2), to size the
    /// triangle vectors and estimate the memory before allocating any.
    pub(super) triangles: usize,
    /// Whether the chunk holds a NUL byte, which text never does: its lines are then checked one
    /// by one, to name the first.
    pub(super) binary: bool,
}

impl ChunkCounts {
    pub(super) fn of(chunk: &[u8]) -> Self {
        let mut counts = ChunkCounts::default();
        for line in lines(chunk) {
            counts.lines += 1;
            match Tokens::new(line).next() {
                Some(b"v") => counts.vertices.positions += 1,
                Some(b"vt") => counts.vertices.texcoords += 1,
                Some(b"vn") => counts.vertices.normals += 1,
                Some(b"f") => counts.triangles += corners(line).saturating_sub(2),
                _ => {}
            }
        }
        // `lines` yields one more piece than there are `\n` bytes.
        counts.lines -= 1;
        counts.binary = chunk.contains(&0);
        counts
    }
}

/// The corners of an `f` line: its tokens after the keyword, up to a comment. A loop the compiler
/// vectorises rather than [`Tokens`], since it runs on every face line of the first pass; control
/// bytes count as separators, which only matters for malformed lines the second pass refuses.
fn corners(line: &[u8]) -> usize {
    let line = line.split(|&b| b == b'#').next().unwrap_or_default();
    let mut count: usize = 0;
    let mut after_space = true;
    for &byte in line {
        let space = byte <= b' ';
        count += usize::from(after_space && !space);
        after_space = space;
    }
    // The first token is the `f` itself.
    count.saturating_sub(1)
}

/// Where a chunk starts: lines and vertices before its first line.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ChunkStart {
    pub(super) line: usize,
    pub(super) vertices: VertexCounts,
}

/// A `usemtl` statement: triangles from `triangle` (chunk-local) on use material `name`.
#[derive(Debug)]
pub(super) struct MaterialSwitch<'a> {
    pub(super) triangle: usize,
    pub(super) line: usize,
    pub(super) name: Cow<'a, str>,
}

/// A `mtllib` statement, with the rest of its line (one or several file names).
#[derive(Debug)]
pub(super) struct MaterialLibrary<'a> {
    pub(super) line: usize,
    /// The rest of the line, as bytes: file names are bytes on Unix.
    pub(super) names: &'a [u8],
}

/// What a chunk defines, with vertex indices already absolute in the file.
#[derive(Debug, Default)]
pub(super) struct ChunkMesh<'a> {
    pub(super) positions: Vec<Vec3>,
    pub(super) texcoords: Vec<Vec2>,
    pub(super) normals: Vec<Vec3>,
    pub(super) indices: Vec<[u32; 3]>,
    /// Empty until the chunk's first corner with a texture coordinate, then one entry per triangle.
    pub(super) texcoord_indices: Vec<[u32; 3]>,
    /// Empty until the chunk's first corner with a normal, then one entry per triangle.
    pub(super) normal_indices: Vec<[u32; 3]>,
    /// The faces of more than three corners (their first triangle chunk-local), whose fans are
    /// checked once the mesh is whole (`polygon.rs`).
    pub(super) polygons: Vec<Polygon>,
    pub(super) material_switches: Vec<MaterialSwitch<'a>>,
    pub(super) libraries: Vec<MaterialLibrary<'a>>,
    /// Faces with a texture-coordinate index out of range (dropped for those corners).
    pub(super) dropped_texcoords: Dropped,
    /// Faces with a normal index out of range (dropped for those corners).
    pub(super) dropped_normals: Dropped,
    /// Statements skipped that a reader should hear about.
    pub(super) skipped: SkippedKeywords<'a>,
}

/// Faces that lost an attribute index because it pointed at nothing.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Dropped {
    pub(super) faces: usize,
    /// The line of the first such face.
    pub(super) first_line: Option<usize>,
}

impl Dropped {
    fn add(&mut self, line: usize) {
        self.faces += 1;
        self.first_line.get_or_insert(line);
    }

    /// Sums the counts of consecutive chunks: the first line is the earliest.
    pub(super) fn merge(self, later: Dropped) -> Dropped {
        Dropped { faces: self.faces + later.faces, first_line: self.first_line.or(later.first_line) }
    }
}

/// Parses the lines of `chunk`. `totals` are the file's vertex counts, which positive indices are
/// checked against: like tinyobjloader we accept a face that names a vertex defined further down.
pub(super) fn parse_chunk<'a>(
    chunk: &'a [u8],
    counts: &ChunkCounts,
    start: ChunkStart,
    totals: VertexCounts,
    file: &Path,
) -> Result<ChunkMesh<'a>> {
    let mut parser = ChunkParser { start: start.vertices, totals, mesh: ChunkMesh::default() };
    parser.reserve(counts);
    for (i, line) in lines(chunk).enumerate() {
        let line_number = start.line + i + 1;
        // Some other format under an `.obj` name (a binary PLY, an archive), whose lines would
        // otherwise load as nothing or as stray numbers.
        if counts.binary && line.contains(&0) {
            return Err(Error::parse(file, line_number, "a NUL byte: binary data, not an OBJ text file".to_string()));
        }
        parser.statement(line, line_number).map_err(|message| Error::parse(file, line_number, message))?;
    }
    Ok(parser.mesh)
}

/// The three indices of a face corner; `NO_INDEX` where the corner has no such attribute.
#[derive(Clone, Copy)]
struct Corner {
    position: u32,
    texcoord: u32,
    normal: u32,
}

/// Which attribute indices of a corner were dropped.
#[derive(Clone, Copy, Default)]
struct CornerDropped {
    texcoord: bool,
    normal: bool,
}

/// Which vertex array an index points into.
#[derive(Clone, Copy)]
enum Attribute {
    Position,
    Texcoord,
    Normal,
}

struct ChunkParser<'a> {
    start: VertexCounts,
    totals: VertexCounts,
    mesh: ChunkMesh<'a>,
}

impl<'a> ChunkParser<'a> {
    fn reserve(&mut self, counts: &ChunkCounts) {
        self.mesh.positions.reserve_exact(counts.vertices.positions);
        self.mesh.texcoords.reserve_exact(counts.vertices.texcoords);
        self.mesh.normals.reserve_exact(counts.vertices.normals);
        self.mesh.indices.reserve_exact(counts.triangles);
    }

    /// Parses one line; the error message gets the file and line from the caller.
    fn statement(&mut self, line: &'a [u8], line_number: usize) -> Result<(), String> {
        let mut tokens = Tokens::new(line);
        match tokens.next() {
            Some(b"v") => self.mesh.positions.push(Vec3::from(numbers(tokens, 3)?)),
            Some(b"vt") => self.mesh.texcoords.push(Vec2::from(numbers(tokens, 1)?)),
            Some(b"vn") => self.mesh.normals.push(Vec3::from(numbers(tokens, 3)?)),
            Some(b"f") => self.face(tokens, line_number)?,
            Some(b"usemtl") => self.use_material(tokens, line_number)?,
            Some(b"mtllib") => {
                let names = tokens.remainder_bytes();
                self.mesh.libraries.push(MaterialLibrary { line: line_number, names });
            }
            Some(keyword) if is_silent(keyword) => {}
            Some(keyword) => self.mesh.skipped.note(keyword, line_number),
            // Blank lines and comments (`Tokens` ends a line at `#`).
            None => {}
        }
        Ok(())
    }

    fn use_material(&mut self, tokens: Tokens<'a>, line: usize) -> Result<(), String> {
        let name = tokens.remainder();
        if name.is_empty() {
            return Err("usemtl without a material name".to_string());
        }
        let triangle = self.mesh.indices.len();
        self.mesh.material_switches.push(MaterialSwitch { triangle, line, name });
        Ok(())
    }

    /// Splits a polygon into the fan `(a,b,c), (a,c,d), ...` in file order, as gKit does, so that
    /// triangle ids match its renders (a concave one is split again once the mesh is whole).
    fn face(&mut self, tokens: Tokens, line: usize) -> Result<(), String> {
        let first_triangle = self.mesh.indices.len();
        let mut first = None;
        let mut previous = None;
        let mut count = 0;
        let (mut texcoord_dropped, mut normal_dropped) = (false, false);
        for token in tokens {
            let (corner, dropped) = self.corner(token)?;
            texcoord_dropped |= dropped.texcoord;
            normal_dropped |= dropped.normal;
            count += 1;
            let Some(a) = first else {
                first = Some(corner);
                continue;
            };
            if let Some(b) = previous {
                self.push_triangle(a, b, corner);
            }
            previous = Some(corner);
        }
        if count < 3 {
            return Err(format!("face with {count} corner(s); a face needs at least 3"));
        }
        if count > 3 {
            self.mesh.polygons.push(Polygon { first_triangle, corners: count });
        }
        if texcoord_dropped {
            self.mesh.dropped_texcoords.add(line);
        }
        if normal_dropped {
            self.mesh.dropped_normals.add(line);
        }
        Ok(())
    }

    /// The corner's indices, and which attribute indices were dropped for pointing at nothing.
    /// A position out of range is an error; a texture coordinate or a normal out of range (or 0)
    /// is dropped (the corner has none), as mainstream loaders accept such files.
    fn corner(&self, token: &[u8]) -> Result<(Corner, CornerDropped), String> {
        let malformed = || format!("malformed face corner {} (expected v, v/vt, v//vn or v/vt/vn)", quote(token));
        let CornerFields { position, texcoord, normal } = corner_fields(token).ok_or_else(malformed)?;
        let raw = |field: &[u8]| saturating_i64(field).ok_or_else(malformed);
        let position = self.resolve(raw(position)?, position, Attribute::Position)?;
        let mut dropped = CornerDropped::default();
        let attribute = |field: Option<&[u8]>, attribute, dropped: &mut bool| -> Result<u32, String> {
            let Some(field) = field else { return Ok(NO_INDEX) };
            Ok(self.resolve(raw(field)?, field, attribute).unwrap_or_else(|_| {
                *dropped = true;
                NO_INDEX
            }))
        };
        let texcoord = attribute(texcoord, Attribute::Texcoord, &mut dropped.texcoord)?;
        let normal = attribute(normal, Attribute::Normal, &mut dropped.normal)?;
        Ok((Corner { position, texcoord, normal }, dropped))
    }

    /// Turns a 1-based or negative (relative to the vertices defined so far) index into a 0-based
    /// one, refusing anything outside the file's vertices without overflowing on huge values.
    fn resolve(&self, raw: i64, field: &[u8], attribute: Attribute) -> Result<u32, String> {
        let (what, defined, total) = match attribute {
            Attribute::Position => {
                ("position", self.start.positions + self.mesh.positions.len(), self.totals.positions)
            }
            Attribute::Texcoord => {
                ("texture coordinate", self.start.texcoords + self.mesh.texcoords.len(), self.totals.texcoords)
            }
            Attribute::Normal => ("normal", self.start.normals + self.mesh.normals.len(), self.totals.normals),
        };
        // Digits only (the field parsed as an integer), but maybe 10 MB of them: cut like names.
        let field = || if field.len() <= 40 { String::from_utf8_lossy(field).into_owned() } else { quote(field) };
        if raw == 0 {
            return Err(format!("{what} index 0: OBJ indices start at 1"));
        }
        let resolved = if raw > 0 {
            usize::try_from(raw).ok().filter(|&i| i <= total).map(|i| i - 1)
        } else {
            usize::try_from(raw.unsigned_abs()).ok().filter(|&back| back <= defined).map(|back| defined - back)
        };
        let resolved = resolved.and_then(|i| u32::try_from(i).ok()).filter(|&i| i != NO_INDEX);
        resolved.ok_or_else(|| {
            if raw > 0 {
                format!("{what} index {} out of range: the file defines {total}", field())
            } else {
                format!("{what} index {} out of range: {defined} defined before this line", field())
            }
        })
    }

    fn push_triangle(&mut self, a: Corner, b: Corner, c: Corner) {
        let triangle = self.mesh.indices.len();
        self.mesh.indices.push([a.position, b.position, c.position]);
        push_attribute(&mut self.mesh.texcoord_indices, triangle, [a.texcoord, b.texcoord, c.texcoord]);
        push_attribute(&mut self.mesh.normal_indices, triangle, [a.normal, b.normal, c.normal]);
    }
}

/// Reads the numbers of a `v`, `vt` or `vn` line: the first `N` (missing ones past `min` are 0),
/// checking that any extra ones (`w`, vertex colours) are numbers too.
fn numbers<const N: usize>(tokens: Tokens, min: usize) -> Result<[f32; N], String> {
    let mut values = [0.0; N];
    let mut count = 0;
    for token in tokens {
        let value = finite_f32(token)?;
        if let Some(slot) = values.get_mut(count) {
            *slot = value;
        }
        count += 1;
    }
    if count < min {
        return Err(format!("expected at least {min} numbers, found {count}"));
    }
    Ok(values)
}

/// The index fields of a face corner, as written.
struct CornerFields<'t> {
    position: &'t [u8],
    texcoord: Option<&'t [u8]>,
    normal: Option<&'t [u8]>,
}

/// Splits `v`, `v/vt`, `v//vn` or `v/vt/vn` into its fields; `None` for any other shape.
fn corner_fields(token: &[u8]) -> Option<CornerFields<'_>> {
    let mut fields = token.split(|&b| b == b'/');
    let position = fields.next().filter(|field| !field.is_empty())?;
    let texcoord = fields.next();
    let normal = fields.next();
    if fields.next().is_some() {
        return None;
    }
    let texcoord = match (texcoord, normal) {
        (Some(b""), Some(_)) => None,
        (texcoord, _) => texcoord,
    };
    Some(CornerFields { position, texcoord, normal })
}

/// Appends a triangle's texture-coordinate or normal indices, keeping the list empty while no
/// corner has any (most large scans have neither) and back-filling `NO_INDEX` once one appears.
fn push_attribute(list: &mut Vec<[u32; 3]>, triangle: usize, corners: [u32; 3]) {
    if list.is_empty() && corners == [NO_INDEX; 3] {
        return;
    }
    list.resize(triangle, [NO_INDEX; 3]);
    list.push(corners);
}
