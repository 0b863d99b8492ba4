//! glTF 2.0 loading (`.gltf` with its buffers and images, or `.glb`): the format of Khronos'
//! sample models, Sketchfab's downloads and Blender's, three.js' and most engines' exports.
//!
//! Read: the scene's node tree with every node's transform (`nodes.rs`); each mesh primitive of
//! triangles, strips or fans, with `POSITION`, `NORMAL` (as shading normals) and the texture
//! coordinates its material's base colour texture reads (`TEXCOORD_n`, `v` flipped to OBJ's
//! bottom-up convention), indexed or not, quantised (`KHR_mesh_quantization`) or sparse
//! (`accessor.rs`); the metallic-roughness materials with their base colour textures, glass from
//! `KHR_materials_transmission`, emission, and `alphaMode MASK` as cutouts (`materials.rs`). A
//! node whose transform mirrors (negative determinant) has its triangles' corners swapped, so that
//! a face keeps its front. The first perspective camera the node tree places is the scene's view
//! (`cameras.rs`: its position, direction and vertical field of view; not its aspect ratio or
//! clipping planes). Anything else (points and lines, orthographic and further cameras, skins,
//! animations, morph targets, unsupported extensions and material properties) is named in a
//! warning, never silently dropped; a file that *requires* an extension lumiere does not read is
//! refused.
//!
//! Every byte range is checked before it is read, and the whole flattened scene is refused before
//! its triangles are allocated when its mesh and BVH would not fit in the memory left (instancing
//! lets a small file draw a mesh a million times).

mod accessor;
mod buffers;
mod cameras;
mod container;
mod materials;
mod nodes;
mod uri;

use crate::error::{Error, Result, quote, shown_path};
use crate::materials::Material;
use crate::scene::Scene;
use crate::scene::load::memory::{Memory, MeshSize, check_mesh_memory};
use crate::scene::load::warnings::Warnings;
use crate::scene::mesh::{NO_INDEX, TriangleMesh};
use crate::textures::EmbeddedImages;
use crate::util::read;
use accessor::BufferData;
pub use buffers::ReadFile;
use glam::{DMat3, DMat4, Vec2, Vec3};
use gltf::accessor::Dimensions;
use gltf::mesh::{Mode, Semantic};
pub use materials::DEFAULT_NAME;
use nodes::Instance;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;

/// Loads `path` (`.gltf` or `.glb`, either also gzipped), reading the buffers it names beside it.
pub fn load_gltf(path: &Path) -> Result<Scene> {
    let bytes = read::read_input(path).map_err(|error| Error::io(path, error))?;
    parse_gltf(&bytes, path, &|file| read::read_regular_file(file))
}

/// Parses a glTF file's bytes; `name` names it in messages and locates the files it names, which
/// `read` reads (buffers; images are named for the renderer to decode).
pub fn parse_gltf(bytes: &[u8], name: &Path, read: ReadFile) -> Result<Scene> {
    parse_within(bytes, name, read, Memory::System)
}

/// [`parse_gltf`] as if `available` bytes of memory were left, so that tests can check the refusal
/// of scenes too big for memory without allocating gigabytes.
#[doc(hidden)]
pub fn parse_gltf_with_memory(bytes: &[u8], name: &Path, read: ReadFile, available: u64) -> Result<Scene> {
    parse_within(bytes, name, read, Memory::Given(available))
}

fn parse_within(bytes: &[u8], file: &Path, read: ReadFile, memory: Memory) -> Result<Scene> {
    let container = container::parse(bytes, file)?;
    let document = &container.document;
    let mut warnings = Warnings::default();
    warn_unread(document, file, &mut warnings);
    let buffers = buffers::load(&container, file, read)?;
    let walked = nodes::walk(document, file, &mut warnings)?;
    let view = cameras::view(document, &walked.cameras, file, &mut warnings);
    let instances = walked.instances;
    let meshes: Vec<gltf::Mesh> = document.meshes().collect();

    let mut embedded = EmbeddedImages::default();
    let mut copies = ViewCopies::default();
    let mut image_path = |image: &gltf::Image| image_source(image, &buffers.data, file, &mut embedded, &mut copies);
    // Every material the file defines is kept, drawn or not, at its index in the file, so that
    // `--emission NAME` finds any of them.
    let mut converted: Vec<materials::Converted> =
        document.materials().map(|m| materials::convert(&m, file, &mut image_path, &mut warnings)).collect();
    // glTF's default material, for primitives that name none, only where one is drawn.
    let default_id = converted.len();
    let drawn = instances.iter().flat_map(|instance| meshes[instance.mesh].primitives());
    if drawn.filter(|p| is_triangles(p.mode())).any(|p| p.material().index().is_none()) {
        converted.push(materials::default_material());
    }
    let texcoord_sets: Vec<u32> = converted.iter().map(|c| c.texcoord_set).collect();
    let primitives = Drawn { sets: texcoord_sets, drawn: converted.iter().map(|c| c.drawn).collect(), default_id };
    let materials: Vec<Material> = converted.into_iter().map(|c| c.material).collect();

    let size = counted(&meshes, &instances, &primitives, file, &mut warnings)?;
    let held = buffers.data.iter().map(|data| data.len() as u64).sum();
    check_mesh_memory(file, size, held, memory, "mesh and BVH, beside the file's buffers")?;

    let mut mesh = TriangleMesh::default();
    let mut decoded: Vec<Option<Rc<Vec<Primitive>>>> = vec![None; meshes.len()];
    for instance in &instances {
        let mesh_primitives = match &decoded[instance.mesh] {
            Some(primitives) => Rc::clone(primitives),
            None => {
                let source = &meshes[instance.mesh];
                let decoded_mesh = Rc::new(decode_mesh(source, &buffers.data, &primitives, file)?);
                decoded[instance.mesh] = Some(Rc::clone(&decoded_mesh));
                decoded_mesh
            }
        };
        for primitive in mesh_primitives.iter() {
            append(&mut mesh, primitive, instance, size, file)?;
        }
    }
    let mut scene = Scene::from_parts(shown_path(file), mesh, materials, warnings.finish())?;
    scene.sources = buffers.files;
    scene.embedded_images = embedded;
    scene.view = view;
    Ok(scene)
}

/// The path a material's texture names for `image`: a file beside the glTF file, or the name
/// under which its bytes (from a buffer view or a `data:` URI) are added to `embedded`.
fn image_source(
    image: &gltf::Image,
    buffers: BufferData,
    file: &Path,
    embedded: &mut EmbeddedImages,
    copies: &mut ViewCopies,
) -> Result<PathBuf, String> {
    let name = EmbeddedImages::name(file, image.index());
    let bytes: Arc<[u8]> = match image.source() {
        gltf::image::Source::Uri { uri, .. } => match uri::resolve(uri, file)? {
            uri::Uri::File(path) => return Ok(path),
            // Materials sharing an image take it once.
            _ if embedded.contains(&name) => return Ok(name),
            uri::Uri::Data(bytes) => bytes.into(),
        },
        gltf::image::Source::View { .. } if embedded.contains(&name) => return Ok(name),
        gltf::image::Source::View { view, .. } => copies.of(&view, buffers)?,
    };
    embedded.add(name.clone(), bytes);
    Ok(name)
}

/// The buffer views images are in, copied out of the buffers: each view once, however many images
/// it holds, and all of them together at most the buffers' size. A few bytes of JSON per image, or
/// per view over the same bytes, must not copy a large buffer again and again.
#[derive(Default)]
struct ViewCopies {
    by_view: HashMap<usize, Arc<[u8]>>,
    bytes: u64,
}

impl ViewCopies {
    fn of(&mut self, view: &gltf::buffer::View, buffers: BufferData) -> Result<Arc<[u8]>, String> {
        if let Some(copy) = self.by_view.get(&view.index()) {
            return Ok(Arc::clone(copy));
        }
        let bytes = accessor::view_bytes(view, buffers)?;
        let budget: u64 = buffers.iter().map(|buffer| buffer.len() as u64).sum();
        let total = self.bytes + bytes.len() as u64;
        if total > budget {
            return Err(format!(
                "the buffer views of the file's images overlap, holding more than the {budget} bytes of its buffers"
            ));
        }
        self.bytes = total;
        let copy: Arc<[u8]> = bytes.into();
        self.by_view.insert(view.index(), Arc::clone(&copy));
        Ok(copy)
    }
}

/// What the whole scene will hold, counted from the accessors' declared counts before anything is
/// read; warns about primitives that are not triangles. Each mesh is measured once, then counted
/// as many times as nodes draw it: a few bytes of nodes must not multiply the work by a mesh's
/// primitives.
fn counted(
    meshes: &[gltf::Mesh],
    instances: &[Instance],
    primitives: &Drawn,
    file: &Path,
    warnings: &mut Warnings,
) -> Result<MeshSize> {
    let mut uses = vec![0u64; meshes.len()];
    for instance in instances {
        uses[instance.mesh] += 1;
    }
    let mut totals = [0u64; 4];
    // In the order nodes first draw the meshes, so that warnings and errors come in the walk's
    // order; a mesh's uses are taken when it is measured.
    for instance in instances {
        let uses = std::mem::take(&mut uses[instance.mesh]);
        if uses == 0 {
            continue;
        }
        let size = measured_mesh(&meshes[instance.mesh], primitives, file, warnings)?;
        for (total, count) in totals.iter_mut().zip(size) {
            *total = total.saturating_add(count.saturating_mul(uses));
        }
    }
    let [positions, normals, texcoords, triangles] = totals;
    // Corners index vertices with 32 bits: a scene of more vertices (instanced, it takes few bytes
    // to ask for) is refused here, whatever the memory.
    for (count, what) in [(positions, "vertices"), (normals, "normals"), (texcoords, "texture coordinates")] {
        if count > u64::from(u32::MAX) {
            return Err(Error::invalid(format!(
                "{}: the scene draws {count} {what}, more than the {} lumiere can index",
                shown_path(file),
                u32::MAX
            )));
        }
    }
    let clamp = |n: u64| usize::try_from(n).unwrap_or(usize::MAX);
    Ok(MeshSize { positions: clamp(positions), normals: clamp(normals), texcoords: clamp(texcoords), triangles })
}

/// The positions, normals, texture coordinates and triangles one drawing of `mesh` adds;
/// warns about its primitives that are not triangles.
fn measured_mesh(mesh: &gltf::Mesh, primitives: &Drawn, file: &Path, warnings: &mut Warnings) -> Result<[u64; 4]> {
    let (mut positions, mut normals, mut texcoords, mut triangles) = (0u64, 0u64, 0u64, 0u64);
    for primitive in mesh.primitives() {
        let where_ = || format!("{}: mesh {} primitive {}", shown_path(file), mesh.index(), primitive.index());
        if !is_triangles(primitive.mode()) {
            warnings.push(file, "primitives not drawn", || {
                format!("{}: {:?} are not drawn (lumiere draws triangles)", where_(), primitive.mode())
            });
            continue;
        }
        if !primitives.draws(&primitive) {
            continue;
        }
        let Some(position) = primitive.get(&Semantic::Positions) else {
            return Err(Error::invalid(format!("{}: no POSITION attribute", where_())));
        };
        let vertices = position.count() as u64;
        let set = primitives.sets[primitives.material(&primitive)];
        for (semantic, total) in [(Semantic::Normals, &mut normals), (Semantic::TexCoords(set), &mut texcoords)] {
            if let Some(attribute) = primitive.get(&semantic) {
                if attribute.count() != position.count() {
                    return Err(Error::invalid(format!(
                        "{}: {} has {} elements, POSITION {}",
                        where_(),
                        semantic.to_string(),
                        attribute.count(),
                        position.count()
                    )));
                }
                *total = total.saturating_add(vertices);
            }
        }
        positions = positions.saturating_add(vertices);
        let corners = primitive.indices().map_or(vertices, |indices| indices.count() as u64);
        triangles = triangles.saturating_add(triangle_count(primitive.mode(), corners));
    }
    Ok([positions, normals, texcoords, triangles])
}

fn is_triangles(mode: Mode) -> bool {
    matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan)
}

/// Which primitives are drawn, with what: by their material's index (glTF's default material's
/// for those that name none).
struct Drawn {
    /// The texture coordinate set (`TEXCOORD_n`) each material's texture reads.
    sets: Vec<u32>,
    /// Whether each material's surface is there at all (see `materials::Converted::drawn`).
    drawn: Vec<bool>,
    default_id: usize,
}

impl Drawn {
    /// The index of `primitive`'s material.
    fn material(&self, primitive: &gltf::Primitive) -> usize {
        primitive.material().index().unwrap_or(self.default_id)
    }

    /// Whether `primitive` is drawn: triangles of a material that is there.
    fn draws(&self, primitive: &gltf::Primitive) -> bool {
        is_triangles(primitive.mode()) && self.drawn[self.material(primitive)]
    }
}

/// The triangles `corners` vertices make in `mode`.
fn triangle_count(mode: Mode, corners: u64) -> u64 {
    match mode {
        Mode::Triangles => corners / 3,
        _ => corners.saturating_sub(2),
    }
}

/// One primitive's vertices and triangles in its mesh's coordinates.
struct Primitive {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    texcoords: Option<Vec<Vec2>>,
    triangles: Vec<[u32; 3]>,
    material: u32,
}

fn decode_mesh(mesh: &gltf::Mesh, buffers: BufferData, drawn: &Drawn, file: &Path) -> Result<Vec<Primitive>> {
    let mut primitives = Vec::new();
    for primitive in mesh.primitives().filter(|p| drawn.draws(p)) {
        let fail = |what: String, accessor: &gltf::Accessor, reason: String| {
            Error::invalid(format!(
                "{}: mesh {} primitive {}: {what} (accessor {}): {reason}",
                shown_path(file),
                mesh.index(),
                primitive.index(),
                accessor.index()
            ))
        };
        let read_attribute = |semantic: Semantic, dimensions| {
            primitive
                .get(&semantic)
                .map(|accessor| {
                    accessor::read_floats::<3>(&accessor, dimensions, buffers)
                        .map_err(|reason| fail(semantic.to_string(), &accessor, reason))
                })
                .transpose()
        };
        let positions = read_attribute(Semantic::Positions, Dimensions::Vec3)?.expect("counted: POSITION is there");
        let positions: Vec<Vec3> = positions.into_iter().map(Vec3::from).collect();
        if let Some(bad) = positions.iter().position(|p| !p.is_finite()) {
            let accessor = primitive.get(&Semantic::Positions).expect("read above");
            return Err(fail("POSITION".into(), &accessor, format!("element {bad} is not finite")));
        }
        let normals = read_attribute(Semantic::Normals, Dimensions::Vec3)?.map(|normals| {
            normals.into_iter().map(Vec3::from).map(|n| if n.is_finite() { n } else { Vec3::ZERO }).collect()
        });
        let material = drawn.material(&primitive);
        let set = drawn.sets[material];
        let texcoords = match primitive.get(&Semantic::TexCoords(set)) {
            Some(accessor) => {
                let what = || format!("TEXCOORD_{set}");
                let values = accessor::read_floats::<2>(&accessor, Dimensions::Vec2, buffers)
                    .map_err(|reason| fail(what(), &accessor, reason))?;
                // As in OBJ, where a `vt` that is not finite is refused: a lookup needs a place.
                if let Some(bad) = values.iter().position(|uv| !uv.iter().all(|c| c.is_finite())) {
                    return Err(fail(what(), &accessor, format!("element {bad} is not finite")));
                }
                Some(values.into_iter().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect())
            }
            None => None,
        };
        let corners = match primitive.indices() {
            Some(accessor) => {
                let corners = accessor::read_indices(&accessor, buffers)
                    .map_err(|reason| fail("indices".into(), &accessor, reason))?;
                if let Some(&bad) = corners.iter().find(|&&i| i as usize >= positions.len()) {
                    let reason = format!("index {bad} out of range: POSITION has {} elements", positions.len());
                    return Err(fail("indices".into(), &accessor, reason));
                }
                corners
            }
            None => (0..positions.len() as u32).collect(),
        };
        // A primitive without vertices adds nothing (any index it has was refused above as out of
        // range): left out, it costs no time however many nodes draw its mesh.
        if positions.is_empty() {
            continue;
        }
        let triangles = assemble(primitive.mode(), &corners);
        primitives.push(Primitive { positions, normals, texcoords, triangles, material: material as u32 });
    }
    Ok(primitives)
}

/// The triangles of a primitive's corners: a list in threes (a leftover corner or two dropped), a
/// strip with every other triangle's first two corners swapped to keep its winding, or a fan.
fn assemble(mode: Mode, corners: &[u32]) -> Vec<[u32; 3]> {
    match mode {
        Mode::Triangles => corners.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => corners
            .windows(3)
            .enumerate()
            .map(|(i, c)| if i % 2 == 0 { [c[0], c[1], c[2]] } else { [c[1], c[0], c[2]] })
            .collect(),
        _ => corners.get(1..).unwrap_or_default().windows(2).map(|c| [corners[0], c[0], c[1]]).collect(),
    }
}

/// Appends `primitive` as `instance` places it. The mesh gets normal and texture coordinate
/// indices as soon as the scene has any (`size` counted them): corners without are [`NO_INDEX`].
fn append(
    mesh: &mut TriangleMesh,
    primitive: &Primitive,
    instance: &Instance,
    size: MeshSize,
    file: &Path,
) -> Result<()> {
    let base = mesh.positions.len() as u32;
    let transform: DMat4 = instance.transform;
    for (i, &p) in primitive.positions.iter().enumerate() {
        let placed = transform.transform_point3(p.as_dvec3()).as_vec3();
        if !placed.is_finite() {
            return Err(Error::invalid(format!(
                "{}: node {} places vertex {i} of mesh {} at a position that is not finite in single precision",
                shown_path(file),
                instance.node,
                instance.mesh
            )));
        }
        mesh.positions.push(placed);
    }
    // A mirroring transform turns counter-clockwise corners clockwise: swap two to keep the front.
    let mirrored = transform.determinant() < 0.0;
    let oriented = |[a, b, c]: [u32; 3]| if mirrored { [a, c, b] } else { [a, b, c] };
    let offset = |base: u32, t: [u32; 3]| oriented(t.map(|i| base + i));
    mesh.indices.extend(primitive.triangles.iter().map(|&t| offset(base, t)));
    mesh.material_ids.extend(std::iter::repeat_n(primitive.material, primitive.triangles.len()));
    if size.normals > 0 {
        let normal_matrix = DMat3::from_mat4(transform).inverse().transpose();
        let indices = match &primitive.normals {
            Some(normals) => {
                let base = mesh.normals.len() as u32;
                mesh.normals
                    .extend(normals.iter().map(|n| (normal_matrix * n.as_dvec3()).normalize_or_zero().as_vec3()));
                primitive.triangles.iter().map(|&t| offset(base, t)).collect::<Vec<_>>()
            }
            None => vec![[NO_INDEX; 3]; primitive.triangles.len()],
        };
        mesh.normal_indices.extend(indices);
    }
    if size.texcoords > 0 {
        let indices = match &primitive.texcoords {
            Some(texcoords) => {
                let base = mesh.texcoords.len() as u32;
                mesh.texcoords.extend_from_slice(texcoords);
                primitive.triangles.iter().map(|&t| offset(base, t)).collect::<Vec<_>>()
            }
            None => vec![[NO_INDEX; 3]; primitive.triangles.len()],
        };
        mesh.texcoord_indices.extend(indices);
    }
    Ok(())
}

/// Warns, once each, about what the file has that lumiere does not draw.
fn warn_unread(document: &gltf::Document, file: &Path, warnings: &mut Warnings) {
    let unread: Vec<String> =
        document.extensions_used().filter(|used| !container::SUPPORTED_EXTENSIONS.contains(used)).map(quote).collect();
    if !unread.is_empty() {
        let list = unread.join(", ");
        warnings.push(file, "extensions not read", || format!("{}: extensions not read: {list}", shown_path(file)));
    }
    let morphs = document.meshes().flat_map(|m| m.primitives()).any(|p| p.morph_targets().len() > 0);
    for (count, what) in [
        (document.skins().len(), "skins (meshes are drawn in their bind pose)"),
        (document.animations().len(), "animations (the scene is drawn at rest)"),
        (usize::from(morphs), "morph targets (meshes are drawn without them)"),
    ] {
        if count > 0 {
            warnings.push(file, "features not read", || format!("{}: not read: {what}", shown_path(file)));
        }
    }
}
