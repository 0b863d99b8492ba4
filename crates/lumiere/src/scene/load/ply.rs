//! Stanford PLY loading: the polygon files of the Stanford repository, scanners and mesh tools
//! (MeshLab, Blender, Open3D, trimesh), in ASCII or binary of either byte order (`ply/body.rs`),
//! as the header (`ply/header.rs`) lays them out.
//!
//! Read: the `vertex` element's `x`, `y`, `z` (any numeric type; non-finite positions are refused,
//! as in OBJ) and, when all three are there, `nx`, `ny`, `nz` as shading normals; the `face`
//! element's `vertex_indices` (or `vertex_index`) lists, split as fans in OBJ's order, concave ones
//! ear-clipped as OBJ's are. Every triangle gets one grey material, `default`, as an OBJ face
//! without `usemtl` does (`--emission default=R,G,B` makes it a light). Anything else (vertex
//! colours, texture coordinates, other elements, bytes after the last element) is named in one
//! warning per kind, never silently dropped.
//!
//! A header whose counts the body cannot hold is refused before anything is allocated, and so is
//! a mesh whose making and BVH would not fit in the memory left; every index is checked against
//! the vertex count as it is read.

mod body;
mod header;

use crate::error::{Error, Result, quote, shown_path};
use crate::materials::Material;
use crate::scene::Scene;
use crate::scene::load::memory::{Memory, MeshSize, check_mesh_memory};
use crate::scene::load::polygon::{self, Polygon};
use crate::scene::load::warnings::Warnings;
use crate::scene::mesh::TriangleMesh;
use crate::util::read;
use body::Body;
use glam::{DVec3, Vec3};
use header::{Element, Format, Header, Kind, Scalar, parse_header};
use std::path::Path;

/// The name of the one material every triangle of a PLY file gets (an OBJ's default material).
pub const MATERIAL_NAME: &str = "default";

/// Loads `path` (`.ply` or `.ply.gz`). The file is read through [`read::read_input`] (FIFOs,
/// devices and directories are refused, gzip is inflated within the memory left).
pub fn load_ply(path: &Path) -> Result<Scene> {
    let bytes = read::read_input(path).map_err(|error| Error::io(path, error))?;
    parse_ply_within(&bytes, path, Memory::System)
}

/// Parses a PLY file's bytes; `name` names it in messages.
pub fn parse_ply(bytes: &[u8], name: &Path) -> Result<Scene> {
    parse_ply_within(bytes, name, Memory::System)
}

/// [`parse_ply`] as if `available` bytes of memory were left, so that tests can check the refusal
/// of meshes too big for memory without allocating gigabytes.
#[doc(hidden)]
pub fn parse_ply_with_memory(bytes: &[u8], name: &Path, available: u64) -> Result<Scene> {
    parse_ply_within(bytes, name, Memory::Given(available))
}

fn parse_ply_within(bytes: &[u8], file: &Path, memory: Memory) -> Result<Scene> {
    let header = parse_header(bytes, file)?;
    let mut warnings = Warnings::default();
    let layout = Layout::of(&header, file, &mut warnings)?;
    check_counts(&header, bytes.len() - header.body_start, file)?;
    let vertex_count = layout.vertices.as_ref().map_or(0, |v| header.elements[v.element].count as usize);
    let face_count = layout.faces.as_ref().map_or(0, |f| header.elements[f.element].count);
    let has_normals = layout.vertices.as_ref().is_some_and(|v| v.has_normals);
    let normal_count = if has_normals { vertex_count } else { 0 };
    let size = MeshSize { positions: vertex_count, texcoords: 0, normals: normal_count, triangles: face_count };
    check_mesh_memory(file, size, 0, memory, "mesh and BVH")?;

    let mut body = Body::new(bytes, &header);
    let (mut positions, mut normals, mut faces) = (Vec::new(), Vec::new(), Faces::default());
    for (index, element) in header.elements.iter().enumerate() {
        match &layout {
            Layout { vertices: Some(vertices), .. } if vertices.element == index => {
                (positions, normals) = read_vertices(&mut body, element, vertices, file)?;
            }
            Layout { faces: Some(face), .. } if face.element == index => {
                faces = read_faces(&mut body, element, face.indices, vertex_count, file)?;
            }
            _ => body
                .skip_element(element)
                .map_err(|message| body.error(file, format!("element {}: {message}", quote(&element.name))))?,
        }
    }
    if let Some((bytes, line)) = body.trailing() {
        warnings.push(file, "bytes after the last element", || match header.format {
            Format::Ascii => format!("{}:{line}: {bytes} bytes after the last element are not read", shown_path(file)),
            _ => format!("{}: {bytes} bytes after the last element are not read", shown_path(file)),
        });
    }

    let size = MeshSize { triangles: faces.triangles, ..size };
    check_mesh_memory(file, size, faces.bytes(), memory, "mesh and BVH")?;
    let (indices, polygons) = faces.fans();
    let normal_indices = if has_normals { indices.clone() } else { Vec::new() };
    let material_ids = vec![0; indices.len()];
    let mut mesh =
        TriangleMesh { positions, indices, material_ids, normals, normal_indices, ..TriangleMesh::default() };
    polygon::clip_concave_faces(&mut mesh, &polygons).warn(&mut warnings, file);
    Scene::from_parts(shown_path(file), mesh, vec![Material::default_grey(MATERIAL_NAME)], warnings.finish())
}

/// Which elements and properties the loader reads.
struct Layout {
    vertices: Option<VertexLayout>,
    faces: Option<FaceLayout>,
}

struct VertexLayout {
    element: usize,
    /// Per property: where its value goes among `x y z nx ny nz`, or `None` if it is not read.
    slots: Vec<Option<usize>>,
    has_normals: bool,
}

struct FaceLayout {
    element: usize,
    /// The property that holds a face's corners.
    indices: usize,
}

impl Layout {
    /// Finds what the loader reads in `header`, refusing a header without what a mesh needs and
    /// warning about what is not read.
    fn of(header: &Header, file: &Path, warnings: &mut Warnings) -> Result<Layout> {
        let find = |name: &str| header.elements.iter().position(|element| element.name == name);
        let vertices = find("vertex").map(|index| vertex_layout(index, &header.elements[index], file)).transpose()?;
        let faces = find("face").map(|index| face_layout(index, &header.elements[index], file)).transpose()?;
        if let (None, Some(faces)) = (&vertices, &faces) {
            let line = header.elements[faces.element].line;
            return Err(Error::parse(file, line, "faces, but no vertex element for them to index"));
        }
        let mut ignored_elements = Vec::new();
        for (index, element) in header.elements.iter().enumerate() {
            let ignored: Vec<&str> = match (&vertices, &faces) {
                (Some(read), _) if read.element == index => {
                    let unread = element.properties.iter().zip(&read.slots).filter(|(_, slot)| slot.is_none());
                    unread.map(|(property, _)| &*property.name).collect()
                }
                (_, Some(read)) if read.element == index => {
                    let unread = element.properties.iter().enumerate().filter(|&(i, _)| i != read.indices);
                    unread.map(|(_, property)| &*property.name).collect()
                }
                _ => {
                    if element.count > 0 {
                        ignored_elements.push(format!("{} ({})", quote(&element.name), element.count));
                    }
                    continue;
                }
            };
            if !ignored.is_empty() && element.count > 0 {
                let names = listed(ignored.iter().map(quote).collect());
                warnings.push(file, "properties not read", || {
                    format!("{}:{}: {} properties not read: {names}", shown_path(file), element.line, element.name)
                });
            }
        }
        if !ignored_elements.is_empty() {
            warnings.push(file, "elements not read", || {
                let elements = listed(std::mem::take(&mut ignored_elements));
                format!("{}: elements not read (lumiere reads vertex and face): {elements}", shown_path(file))
            });
        }
        Ok(Layout { vertices, faces })
    }
}

/// Names as a warning lists them: the first [`LISTED`], then how many more, so that a header of a
/// hundred thousand properties gives a line, not megabytes.
fn listed(names: Vec<String>) -> String {
    let more = names.len().saturating_sub(LISTED);
    let shown = names.into_iter().take(LISTED).collect::<Vec<_>>().join(", ");
    if more > 0 { format!("{shown} and {more} more") } else { shown }
}

const LISTED: usize = 8;

const COORDINATES: [&str; 6] = ["x", "y", "z", "nx", "ny", "nz"];

fn vertex_layout(index: usize, element: &Element, file: &Path) -> Result<VertexLayout> {
    let scalar = |name: &str| {
        let property = &element.properties[element.property(name)?];
        matches!(property.kind, Kind::Scalar(_)).then_some(())
    };
    if let Some(missing) = COORDINATES[..3].iter().find(|name| scalar(name).is_none()) {
        let message = format!("element vertex has no property {missing} holding one number");
        return Err(Error::parse(file, element.line, message));
    }
    let has_normals = COORDINATES[3..].iter().all(|name| scalar(name).is_some());
    let read = if has_normals { &COORDINATES[..] } else { &COORDINATES[..3] };
    let slots = element.properties.iter().map(|property| read.iter().position(|&name| name == property.name)).collect();
    Ok(VertexLayout { element: index, slots, has_normals })
}

fn face_layout(index: usize, element: &Element, file: &Path) -> Result<FaceLayout> {
    let found = ["vertex_indices", "vertex_index"].iter().find_map(|name| element.property(name));
    let Some(indices) = found else {
        return Err(Error::parse(file, element.line, "element face has no property vertex_indices"));
    };
    match element.properties[indices].kind {
        Kind::List { item, .. } if item.is_integer() => Ok(FaceLayout { element: index, indices }),
        Kind::List { item, .. } => Err(Error::parse(
            file,
            element.line,
            format!("face corners of type {}: vertex indices are integers", item.name()),
        )),
        Kind::Scalar(_) => Err(Error::parse(file, element.line, "face property vertex_indices is not a list")),
    }
}

/// Refuses a header whose elements the body cannot hold, before anything is allocated for them: a
/// few bytes claiming a billion vertices.
fn check_counts(header: &Header, body_bytes: usize, file: &Path) -> Result<()> {
    // An ASCII body's last value needs no separator after it.
    let available = body_bytes as u128 + u128::from(header.format == Format::Ascii);
    let mut needed: u128 = 0;
    for element in &header.elements {
        needed += u128::from(element.count) * u128::from(element.min_bytes(header.format));
        if needed > available {
            let message = format!(
                "element {} declares {} of them, more than the {body_bytes} bytes after the header can hold",
                quote(&element.name),
                element.count
            );
            return Err(Error::parse(file, element.line, message));
        }
    }
    Ok(())
}

fn read_vertices(
    body: &mut Body,
    element: &Element,
    layout: &VertexLayout,
    file: &Path,
) -> Result<(Vec<Vec3>, Vec<Vec3>)> {
    let count = element.count as usize;
    let mut positions = Vec::with_capacity(count);
    let mut normals = Vec::with_capacity(if layout.has_normals { count } else { 0 });
    let mut values = [0.0f64; 6];
    for vertex in 0..count {
        let fail = |body: &Body, message: String| body.error(file, format!("vertex {vertex}: {message}"));
        for (property, &slot) in element.properties.iter().zip(&layout.slots) {
            match (slot, property.kind) {
                (Some(slot), Kind::Scalar(scalar)) => values[slot] = body.real(scalar).map_err(|m| fail(body, m))?,
                (_, kind) => body.skip(kind).map_err(|m| fail(body, m))?,
            }
        }
        let position = DVec3::new(values[0], values[1], values[2]).as_vec3();
        if !position.is_finite() {
            let [x, y, z, ..] = values;
            return Err(fail(body, format!("position {x:?} {y:?} {z:?} is not finite in single precision")));
        }
        positions.push(position);
        if layout.has_normals {
            let normal = DVec3::new(values[3], values[4], values[5]).as_vec3();
            if !normal.is_finite() {
                let [_, _, _, x, y, z] = values;
                return Err(fail(body, format!("normal {x:?} {y:?} {z:?} is not finite in single precision")));
            }
            normals.push(normal);
        }
    }
    Ok((positions, normals))
}

/// The faces as read: their corners one after another, and each face's corner count.
#[derive(Default)]
struct Faces {
    corners: Vec<u32>,
    counts: Vec<u32>,
    /// The triangles their fans make.
    triangles: u64,
}

impl Faces {
    fn bytes(&self) -> u64 {
        4 * (self.corners.len() + self.counts.len()) as u64
    }

    /// Every face split as a fan `(a,b,c), (a,c,d), …`, and the faces of more than three corners.
    fn fans(self) -> (Vec<[u32; 3]>, Vec<Polygon>) {
        let mut triangles = Vec::with_capacity(self.triangles as usize);
        let mut polygons = Vec::new();
        let mut start = 0;
        for &count in &self.counts {
            let corners = &self.corners[start..start + count as usize];
            if count > 3 {
                polygons.push(Polygon { first_triangle: triangles.len(), corners: count as usize });
            }
            triangles.extend(corners[1..].windows(2).map(|pair| [corners[0], pair[0], pair[1]]));
            start += count as usize;
        }
        (triangles, polygons)
    }
}

fn read_faces(body: &mut Body, element: &Element, indices: usize, vertex_count: usize, file: &Path) -> Result<Faces> {
    let mut faces = Faces::default();
    faces.counts.reserve_exact(element.count as usize);
    for face in 0..element.count {
        let fail = |body: &Body, message: String| body.error(file, format!("face {face}: {message}"));
        for (number, property) in element.properties.iter().enumerate() {
            let Kind::List { count, item } = property.kind else {
                body.skip(property.kind).map_err(|m| fail(body, m))?;
                continue;
            };
            if number != indices {
                body.skip(property.kind).map_err(|m| fail(body, m))?;
                continue;
            }
            let corners =
                read_corners(body, count, item, vertex_count, &mut faces.corners).map_err(|m| fail(body, m))?;
            if corners < 3 {
                return Err(fail(body, format!("{corners} corner(s); a face needs at least 3")));
            }
            faces.counts.push(corners);
            faces.triangles += u64::from(corners - 2);
        }
    }
    Ok(faces)
}

/// Reads one face's corners onto `corners`; returns how many.
fn read_corners(
    body: &mut Body,
    count: Scalar,
    item: Scalar,
    vertex_count: usize,
    corners: &mut Vec<u32>,
) -> Result<u32, String> {
    let length = body.list_count(count)?;
    // Every corner takes a byte or more, so a count past the bytes left is a short file, not a
    // reason to reserve gigabytes.
    if length > body.remaining() as u64 {
        return Err(body::SHORT.to_string());
    }
    let length = u32::try_from(length).map_err(|_| format!("a face of {length} corners"))?;
    corners.try_reserve(length as usize).map_err(|_| format!("no memory left for a face of {length} corners"))?;
    for _ in 0..length {
        let index = body.integer(item)?;
        match usize::try_from(index) {
            Ok(index) if index < vertex_count => corners.push(index as u32),
            _ => return Err(format!("vertex index {index} out of range: the file defines {vertex_count} vertices")),
        }
    }
    Ok(length)
}
