//! glTF loading: `.gltf` and `.glb` read into the same mesh, the node tree's transforms applied,
//! every accessor layout decoded, materials mapped onto lumiere's kinds, embedded and external
//! images found, what is not read named in warnings, and every malformed or hostile file refused
//! with one line that says where.

use crate::common::TempDir;
use base64::Engine;
use glam::{Vec2, Vec3};
use lumiere::materials::{Bsdf, CoverageTest, Cut, MaterialBsdf, MaterialKind, pbr_alpha};
use lumiere::math::Ray;
use lumiere::scene::Scene;
use lumiere::scene::load::gltf::{DEFAULT_NAME, parse_gltf, parse_gltf_with_memory};
use lumiere::scene::load::load;
use lumiere::scene::load::obj::parse_obj;
use lumiere::textures::Channel;
use lumiere::util::hash::hash_bytes;
use std::io;
use std::path::{Path, PathBuf};

const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const UNSIGNED_BYTE: u32 = 5121;
const SHORT: u32 = 5122;

/// A glTF file under construction: one binary buffer with its views and accessors, written as a
/// `.gltf` (the buffer a base64 `data:` URI) or as a `.glb` (the buffer its binary chunk).
#[derive(Default)]
pub(super) struct Builder {
    blob: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
}

impl Builder {
    /// A view of `bytes`, started at a multiple of 4 as the format asks.
    fn view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.blob.len().is_multiple_of(4) {
            self.blob.push(0);
        }
        let stride = stride.map(|s| format!(r#", "byteStride": {s}"#)).unwrap_or_default();
        self.views.push(format!(
            r#"{{"buffer": 0, "byteOffset": {}, "byteLength": {}{stride}}}"#,
            self.blob.len(),
            bytes.len()
        ));
        self.blob.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// An accessor; `extra` is more JSON members (`"normalized": true`, `"sparse": {...}`).
    fn accessor(
        &mut self,
        view: Option<usize>,
        offset: usize,
        component: u32,
        count: usize,
        kind: &str,
        extra: &str,
    ) -> usize {
        let view = view.map(|v| format!(r#""bufferView": {v}, "byteOffset": {offset}, "#)).unwrap_or_default();
        self.accessors
            .push(format!(r#"{{{view}"componentType": {component}, "count": {count}, "type": "{kind}"{extra}}}"#));
        self.accessors.len() - 1
    }

    /// Floats, `kind` (`VEC3`, `VEC2`) elements of them, in a view of their own.
    pub(super) fn floats(&mut self, values: &[f32], kind: &str) -> usize {
        let per = match kind {
            "VEC2" => 2,
            "VEC3" => 3,
            _ => 1,
        };
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, None);
        self.accessor(Some(view), 0, FLOAT, values.len() / per, kind, "")
    }

    pub(super) fn indices(&mut self, values: &[u16]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, None);
        self.accessor(Some(view), 0, UNSIGNED_SHORT, values.len(), "SCALAR", "")
    }

    /// The JSON, with `rest` (more members of the root object: meshes, nodes, scenes, ...) and the
    /// buffer at `uri` (none: the GLB binary chunk).
    fn json(&self, rest: &str, uri: Option<&str>) -> String {
        let uri = uri.map(|u| format!(r#", "uri": "{u}""#)).unwrap_or_default();
        let mut members = String::new();
        if !self.blob.is_empty() {
            members += &format!(
                r#""buffers": [{{"byteLength": {}{uri}}}], "bufferViews": [{}], "#,
                self.blob.len(),
                self.views.join(", ")
            );
        }
        if !self.accessors.is_empty() {
            members += &format!(r#""accessors": [{}], "#, self.accessors.join(", "));
        }
        format!(r#"{{"asset": {{"version": "2.0"}}, {members}{rest}}}"#)
    }

    pub(super) fn gltf(&self, rest: &str) -> Vec<u8> {
        let data = base64::engine::general_purpose::STANDARD.encode(&self.blob);
        self.json(rest, Some(&format!("data:application/octet-stream;base64,{data}"))).into_bytes()
    }

    fn glb(&self, rest: &str) -> Vec<u8> {
        glb(self.json(rest, None).as_bytes(), Some(&self.blob))
    }
}

/// A GLB container of `json` and `bin`, each chunk padded to 4 bytes as the format asks.
fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut chunks = Vec::new();
    for (data, kind, pad) in [(Some(json), b"JSON", b' '), (bin, b"BIN\0", 0)] {
        let Some(data) = data else { continue };
        let mut data = data.to_vec();
        while !data.len().is_multiple_of(4) {
            data.push(pad);
        }
        chunks.extend_from_slice(&(data.len() as u32).to_le_bytes());
        chunks.extend_from_slice(kind);
        chunks.extend_from_slice(&data);
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(12 + chunks.len() as u32).to_le_bytes());
    out.extend_from_slice(&chunks);
    out
}

pub(super) fn no_files(path: &Path) -> io::Result<Vec<u8>> {
    Err(io::Error::new(io::ErrorKind::NotFound, format!("{} is not there", path.display())))
}

fn parse_named(bytes: &[u8], name: &str) -> Scene {
    parse_gltf(bytes, Path::new(name), &no_files).unwrap_or_else(|error| panic!("unexpected error: {error}"))
}

fn parse(bytes: &[u8]) -> Scene {
    parse_named(bytes, "test.gltf")
}

fn parse_error(bytes: &[u8]) -> String {
    match parse_gltf(bytes, Path::new("test.gltf"), &no_files) {
        Ok(scene) => panic!("expected an error, got {} triangles", scene.mesh.triangle_count()),
        Err(error) => error.to_string(),
    }
}

/// One mesh of one primitive drawn by one node at the origin.
fn one_mesh(primitive: &str) -> String {
    format!(
        r#""meshes": [{{"primitives": [{primitive}]}}], "nodes": [{{"mesh": 0}}], "scenes": [{{"nodes": [0]}}], "scene": 0"#
    )
}

/// A unit quad in the z = 0 plane, facing +z, as two indexed triangles with normals and texture
/// coordinates.
fn quad(builder: &mut Builder) -> String {
    let positions = builder.floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.], "VEC3");
    let normals = builder.floats(&[0., 0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1.], "VEC3");
    let texcoords = builder.floats(&[0., 1., 1., 1., 1., 0., 0., 0.], "VEC2");
    let indices = builder.indices(&[0, 1, 2, 0, 2, 3]);
    format!(
        r#"{{"attributes": {{"POSITION": {positions}, "NORMAL": {normals}, "TEXCOORD_0": {texcoords}}}, "indices": {indices}}}"#
    )
}

#[test]
fn a_gltf_and_a_glb_of_one_quad_read_as_the_same_mesh() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let rest = one_mesh(&primitive);
    for scene in [parse(&builder.gltf(&rest)), parse_named(&builder.glb(&rest), "test.glb")] {
        let mesh = &scene.mesh;
        assert_eq!(mesh.positions, [Vec3::ZERO, Vec3::X, Vec3::new(1., 1., 0.), Vec3::Y]);
        assert_eq!(mesh.indices, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.normals, [Vec3::Z; 4]);
        assert_eq!(mesh.normal_indices, mesh.indices);
        // glTF's v runs down from the image's top; lumiere's up from its bottom, as OBJ's.
        assert_eq!(mesh.texcoords, [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y]);
        assert_eq!(mesh.texcoord_indices, mesh.indices);
        // No material named: glTF's default, white, metallic and rough.
        assert_eq!(scene.materials.len(), 1);
        assert_eq!(scene.materials[0].name, DEFAULT_NAME);
        assert_eq!(scene.materials[0].kind(), MaterialKind::Conductor { alpha: 1.0 });
        assert_eq!(scene.materials[0].kd, Vec3::ONE);
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    }
}

/// The shared 69k-triangle bunny, written as glTF (its positions as floats, its faces as 32-bit
/// indices), reads as its OBJ does: the same positions and triangles, bit for bit.
#[test]
fn the_shared_bunny_reads_as_its_obj_does() {
    let Some(path) = crate::common::shared_scene("bunny/stanford-bunny.obj") else { return };
    let bytes = std::fs::read(&path).unwrap();
    let obj = parse_obj(&bytes, &path, &|_| Err(io::Error::other("no MTL"))).unwrap().into_scene("obj".into()).unwrap();
    let mut builder = Builder::default();
    let floats: Vec<f32> = obj.mesh.positions.iter().flat_map(|p| p.to_array()).collect();
    let positions = builder.floats(&floats, "VEC3");
    let corners: Vec<u8> = obj.mesh.indices.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
    let view = builder.view(&corners, None);
    let indices = builder.accessor(Some(view), 0, UNSIGNED_INT, corners.len() / 4, "SCALAR", "");
    let rest = one_mesh(&format!(r#"{{"attributes": {{"POSITION": {positions}}}, "indices": {indices}}}"#));
    let gltf = parse_named(&builder.glb(&rest), "bunny.glb");
    assert_eq!(gltf.mesh.positions, obj.mesh.positions);
    assert_eq!(gltf.mesh.indices, obj.mesh.indices);
}

#[test]
fn node_transforms_compose_down_the_tree_and_a_mirror_keeps_the_front() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    // Node 0 moves by (10, 0, 0) and holds node 1, which turns a quarter about +z (a quaternion)
    // and holds node 2, which mirrors x by a matrix; each draws the quad.
    let rest = format!(
        r#""meshes": [{{"primitives": [{primitive}]}}], "scenes": [{{"nodes": [0]}}], "nodes": [
            {{"mesh": 0, "translation": [10, 0, 0], "children": [1]}},
            {{"mesh": 0, "rotation": [0, 0, 0.70710678, 0.70710678], "children": [2]}},
            {{"mesh": 0, "matrix": [-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}}]"#
    );
    let scene = parse(&builder.gltf(&rest));
    let mesh = &scene.mesh;
    assert_eq!(mesh.triangle_count(), 6);
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() < 1e-6;
    // Node 0: the quad moved.
    assert_eq!(mesh.positions[1], Vec3::new(11., 0., 0.));
    // Node 1: (1, 0, 0) turned to (0, 1, 0), then moved.
    assert!(close(mesh.positions[5], Vec3::new(10., 1., 0.)), "{}", mesh.positions[5]);
    // Node 2: (1, 0, 0) mirrored to (-1, 0, 0), turned to (0, -1, 0), moved.
    assert!(close(mesh.positions[9], Vec3::new(10., -1., 0.)), "{}", mesh.positions[9]);
    // The mirrored copy's corners are swapped, so its triangles still face +z, as its normals do.
    for (id, triangle) in mesh.indices.iter().enumerate() {
        let [a, b, c] = triangle.map(|i| mesh.positions[i as usize]);
        let facing = (b - a).cross(c - a).normalize();
        assert!(close(facing, Vec3::Z), "triangle {id} faces {facing}");
        let normal = mesh.normals[mesh.normal_indices[id][0] as usize];
        assert!(close(normal, Vec3::Z), "triangle {id}'s normal {normal}");
    }
    assert_eq!(mesh.indices[4], [8, 10, 9], "the mirrored quad's first triangle, b and c swapped");
}

#[test]
fn strips_and_fans_split_as_the_format_says() {
    let mut builder = Builder::default();
    let ring: Vec<f32> = (0..6).flat_map(|i| [i as f32, (i % 2) as f32, 0.]).collect();
    let positions = builder.floats(&ring, "VEC3");
    let primitives = [
        format!(r#"{{"attributes": {{"POSITION": {positions}}}, "mode": 5}}"#),
        format!(r#"{{"attributes": {{"POSITION": {positions}}}, "mode": 6}}"#),
        format!(r#"{{"attributes": {{"POSITION": {positions}}}, "mode": 4}}"#),
    ];
    let scene = parse(&builder.gltf(&one_mesh(&primitives.join(", "))));
    let strip = [[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5]];
    let fan = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]].map(|t| t.map(|i| i + 6));
    let list = [[0, 1, 2], [3, 4, 5]].map(|t| t.map(|i| i + 12));
    let expected: Vec<[u32; 3]> = strip.into_iter().chain(fan).chain(list).collect();
    assert_eq!(scene.mesh.indices, expected);
}

#[test]
fn interleaved_quantised_normalised_sparse_and_viewless_accessors_decode() {
    let mut builder = Builder::default();
    // Positions as shorts (KHR_mesh_quantization) interleaved with unsigned-byte texture
    // coordinates, normalised: 6 + 2 bytes, padded to a stride of 12.
    let mut interleaved = Vec::new();
    for (p, t) in [([0i16, 0, 0], [0u8, 255]), ([2, 0, 0], [255, 255]), ([0, -2, 7], [0, 51])] {
        interleaved.extend(p.iter().flat_map(|c| c.to_le_bytes()));
        interleaved.extend(t);
        interleaved.extend([0u8; 4]);
    }
    let view = builder.view(&interleaved, Some(12));
    let positions = builder.accessor(Some(view), 0, SHORT, 3, "VEC3", "");
    let texcoords = builder.accessor(Some(view), 6, UNSIGNED_BYTE, 3, "VEC2", r#", "normalized": true"#);
    // Normals without a view (all zero) but for element 2, set by a sparse substitution.
    let sparse_indices = builder.view(&[2u8], None);
    let sparse_values: Vec<u8> = [0f32, 0., 1.].iter().flat_map(|v| v.to_le_bytes()).collect();
    let sparse_values = builder.view(&sparse_values, None);
    let sparse = format!(
        r#", "sparse": {{"count": 1, "indices": {{"bufferView": {sparse_indices}, "componentType": {UNSIGNED_BYTE}}}, "values": {{"bufferView": {sparse_values}}}}}"#
    );
    let normals = builder.accessor(None, 0, FLOAT, 3, "VEC3", &sparse);
    let rest = one_mesh(&format!(
        r#"{{"attributes": {{"POSITION": {positions}, "TEXCOORD_0": {texcoords}, "NORMAL": {normals}}}}}"#
    ));
    let rest = format!(
        r#"{rest}, "extensionsUsed": ["KHR_mesh_quantization"], "extensionsRequired": ["KHR_mesh_quantization"]"#
    );
    let scene = parse(&builder.glb(&rest));
    assert_eq!(scene.mesh.positions, [Vec3::ZERO, Vec3::new(2., 0., 0.), Vec3::new(0., -2., 7.)]);
    assert_eq!(scene.mesh.texcoords, [Vec2::new(0., 0.), Vec2::new(1., 0.), Vec2::new(0., 1. - 51. / 255.)]);
    assert_eq!(scene.mesh.normals, [Vec3::ZERO, Vec3::ZERO, Vec3::Z]);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

/// Found by fuzzing (`fuzz/`, target `gltf`): the `gltf` crates panicked on these files, which they
/// assume valid without checking: a `POSITION` accessor index out of range (gltf-json's own
/// validation indexed the accessors with it: "index out of bounds: the len is 3 but the index is
/// 3"), and an image without a source, or of a buffer view without a MIME type (`Image::source`
/// unwraps them: "called `Option::unwrap()` on a `None` value").
#[test]
fn files_the_gltf_crates_assume_valid_are_refused_not_panicked_on() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let good = one_mesh(&primitive);
    let textured = |image: &str| {
        format!(
            r#"{good}, "materials": [{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}}}}}], "textures": [{{"source": 0}}], "images": [{image}]"#
        )
    };
    let cases = [
        (
            good.replace(r#""POSITION": 0"#, r#""POSITION": 9"#),
            "test.gltf: invalid glTF: meshes[0].primitives[0].attributes[\"POSITION\"]: index out of bounds",
        ),
        (textured(r#"{"bufferView": 0}"#), "test.gltf: invalid glTF: images[0].mimeType: missing data"),
        (textured(r#"{"name": "nowhere"}"#), "test.gltf: invalid glTF: images[0].uri: missing data"),
    ];
    for (json, expected) in cases {
        assert_eq!(parse_error(&builder.gltf(&json)), expected);
        assert_eq!(parse_error(&builder.glb(&json)), expected);
    }
    // The same image with its MIME type, or a URI, is read.
    assert!(
        parse_gltf(
            &builder.gltf(&textured(r#"{"bufferView": 0, "mimeType": "image/png"}"#)),
            Path::new("test.gltf"),
            &no_files
        )
        .is_ok()
    );
}

/// Found by fuzzing: serde's message quotes a string of the file whole, so a 3,000-byte value of
/// the wrong type made a 3,000-byte error line; it is cut in the middle now.
#[test]
fn a_long_string_of_the_wrong_type_gives_a_short_error() {
    let json = format!(r#"{{"asset": {{"version": "2.0"}}, "scene": "{}"}}"#, "a".repeat(3000));
    let message = parse_error(json.as_bytes());
    assert!(message.len() < 400, "{} bytes: {message}", message.len());
    assert!(message.starts_with("test.gltf: not glTF JSON: invalid type: string \"aaaa"), "{message}");
    assert!(
        message.ends_with("expected index into child of root at line 1 column 3041 (3080 characters in all)"),
        "{message}"
    );
}

/// A 2×1 PNG: a red texel and a blue one.
fn png() -> Vec<u8> {
    encoded(image::RgbImage::from_raw(2, 1, vec![255, 0, 0, 0, 0, 255]).unwrap().into())
}

/// The bytes of a PNG file of `image`.
fn encoded(image: image::DynamicImage) -> Vec<u8> {
    let mut bytes = io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

#[test]
fn materials_map_onto_lumieres_kinds() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let materials = r#""materials": [
        {"name": "brass", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.7, 0.3, 1], "metallicFactor": 1, "roughnessFactor": 0.3}},
        {"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1], "metallicFactor": 0, "roughnessFactor": 0.5}},
        {"name": "water", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 1, 1, 1], "roughnessFactor": 0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": 1.33}}},
        {"name": "lamp", "emissiveFactor": [1, 0.5, 0.25],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 8}}}],
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength"]"#;
    let primitives: Vec<String> =
        (0..4).map(|m| primitive.replace(r#""indices""#, &format!(r#""material": {m}, "indices""#))).collect();
    let scene = parse(&builder.gltf(&format!("{}, {materials}", one_mesh(&primitives.join(", ")))));
    let kinds: Vec<MaterialKind> = scene.materials.iter().map(|m| m.kind()).collect();
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["brass", "material1", "water", "lamp"], "no default material: every primitive names one");
    assert_eq!(kinds[0], MaterialKind::Conductor { alpha: 0.3f32 * 0.3 });
    assert_eq!(scene.materials[0].kd, Vec3::new(0.9, 0.7, 0.3));
    assert_eq!(kinds[1], MaterialKind::Plastic { ks: Vec3::splat(0.04), alpha: 0.25 });
    assert_eq!(kinds[2], MaterialKind::Dielectric { eta: 1.33, tf: Vec3::new(0.9, 1., 1.) });
    // An index past f32's range reads as infinite: the material keeps the default index instead.
    let huge = builder.gltf(&format!("{}, {}", one_mesh(&primitives.join(", ")), materials.replace("1.33", "1e39")));
    assert_eq!(parse(&huge).materials[2].ni, lumiere::materials::DEFAULT_IOR);
    assert_eq!(scene.materials[3].ke, Vec3::new(8., 4., 2.));
    assert_eq!(scene.mesh.material_ids, [0, 0, 1, 1, 2, 2, 3, 3]);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
}

/// The members of a file drawing `primitive` once per material of `materials`, the `m`-th at
/// x = 2m, with `images` (more members: images, textures).
fn quad_per_material(primitive: &str, materials: &[&str], images: &str) -> String {
    let meshes: Vec<String> = (0..materials.len())
        .map(|m| {
            let primitive = primitive.replace(r#""indices""#, &format!(r#""material": {m}, "indices""#));
            format!(r#"{{"primitives": [{primitive}]}}"#)
        })
        .collect();
    let nodes: Vec<String> =
        (0..materials.len()).map(|m| format!(r#"{{"mesh": {m}, "translation": [{}, 0, 0]}}"#, 2 * m)).collect();
    let roots: Vec<String> = (0..materials.len()).map(|m| m.to_string()).collect();
    format!(
        r#""meshes": [{}], "nodes": [{}], "scenes": [{{"nodes": [{}]}}], "materials": [{}], {images}"#,
        meshes.join(", "),
        nodes.join(", "),
        roots.join(", "),
        materials.join(", ")
    )
}

/// A 2×1 PNG with alpha: a left texel of alpha 0.2, a right one of alpha 0.8.
fn png_with_alpha() -> Vec<u8> {
    encoded(image::RgbaImage::from_raw(2, 1, vec![255, 255, 255, 51, 255, 255, 255, 204]).unwrap().into())
}

#[test]
fn alpha_mask_materials_cut_their_surface_where_the_base_colour_alpha_is_below_the_cutoff() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let with_alpha = builder.view(&png_with_alpha(), None);
    let without_alpha = builder.view(&png(), None);
    // Each material on a quad of its own, the i-th at x = 2i; the texture's left texel (alpha 0.2)
    // covers x < 0.5 of the quad, its right one (alpha 0.8) the rest.
    let materials = [
        r#"{"name": "leaf", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#,
        r#"{"alphaMode": "MASK", "alphaCutoff": 0.05, "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [1, 1, 1, 0.5]}}"#,
        r#"{"alphaMode": "MASK", "alphaCutoff": 0.9, "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#,
        r#"{"alphaCutoff": 0.9, "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#,
        r#"{"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}}"#,
        r#"{"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}, "baseColorFactor": [1, 1, 1, 0.4]}}"#,
        r#"{"name": "hidden", "alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.4]}}"#,
        r#"{"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.6]}}"#,
    ];
    // Whether each quad is there at its left and right halves, or not drawn at all.
    let expected = [
        Some([false, true]), // alpha below the default cutoff of one half on the left
        Some([true, true]),  // 0.2 × 0.5 and 0.8 × 0.5 both reach 0.05
        Some([false, false]),
        Some([true, true]),   // OPAQUE: alpha is ignored
        Some([true, true]),   // no alpha channel: opaque
        Some([false, false]), // ... times 0.4, below one half
        None,                 // no texture, alpha below the cutoff: cut whole
        Some([true, true]),
    ];
    let images = format!(
        r#""images": [{{"bufferView": {with_alpha}, "mimeType": "image/png"}}, {{"bufferView": {without_alpha}, "mimeType": "image/png"}}],
        "textures": [{{"source": 0}}, {{"source": 1}}]"#
    );
    let rest = quad_per_material(&primitive, &materials, &images);
    let scene = parse(&builder.gltf(&rest));
    let leaf = &scene.materials[0];
    assert_eq!(leaf.map_d, leaf.map_kd, "the cutout reads the base colour texture");
    assert_eq!(leaf.map_d_test, CoverageTest { alpha_only: true, scale: 1.0, cut: Cut::Below(0.5) });
    assert_eq!(scene.materials[1].map_d_test, CoverageTest { alpha_only: true, scale: 0.5, cut: Cut::Below(0.05) });
    assert_eq!(scene.materials[3].map_d, None, "an OPAQUE material is not cut");
    assert_eq!(scene.materials[7].map_d, None);
    assert_eq!(
        scene.warnings,
        ["test.gltf: material 'hidden': alphaMode MASK cuts it out (baseColorFactor alpha 0.4 below alphaCutoff \
          0.5), without a texture: its primitives are not drawn"]
    );
    let drawn: Vec<u32> = expected.iter().enumerate().filter(|(_, e)| e.is_some()).map(|(m, _)| m as u32).collect();
    let mut materials_drawn = scene.mesh.material_ids.clone();
    materials_drawn.dedup();
    assert_eq!(materials_drawn, drawn);
    let world = lumiere::world::World::new(scene, lumiere::accel::BuildPreset::Default);
    assert!(world.warnings().is_empty(), "{:?}", world.warnings());
    for (m, expected) in expected.iter().enumerate() {
        let there = [0.25, 0.75].map(|x| {
            let ray = Ray::new(Vec3::new(2.0 * m as f32 + x, 0.5, 1.0), -Vec3::Z);
            let hit = world.intersect(&ray);
            assert_eq!(hit.is_some(), world.occluded(&ray), "material {m}: occlusion as intersection");
            hit.is_some()
        });
        assert_eq!(there, expected.unwrap_or([false, false]), "material {m}");
    }
}

/// Asserts that `actual` scatters as `expected` does: the same lobe, and the same `f` for a few
/// pairs of directions, to within the rounding of the texture lookup's weights.
fn assert_scatters_as(actual: MaterialBsdf, expected: MaterialBsdf, what: &str) {
    assert_eq!(std::mem::discriminant(&actual), std::mem::discriminant(&expected), "{what}: {actual:?}");
    let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
    for wi in [Vec3::new(-0.3, 0.2, 0.9), Vec3::new(0.1, 0.5, 0.6), Vec3::Z].map(Vec3::normalize) {
        let (a, e) = (actual.eval(wo, wi), expected.eval(wo, wi));
        assert!((a - e).abs().max_element() <= 1e-4 * e.max_element().max(1.0), "{what}: f {a} vs {e}");
    }
}

/// A `metallicRoughnessTexture` paints its material's kind: at each hit, the blue channel times
/// `metallicFactor` makes it a metal from one half up, and the green times `roughnessFactor` is
/// its roughness (GGX `α` its square), read as data (not sRGB-decoded); under transmission the
/// glass ignores it, and a texture that does not decode leaves the factors.
#[test]
fn metallic_roughness_textures_paint_the_kind_at_each_hit() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    // Left texel: metal, roughness 0.2; right texel: not metal, roughness 0.8.
    let orm =
        builder.view(&encoded(image::RgbImage::from_raw(2, 1, vec![0, 51, 255, 0, 204, 0]).unwrap().into()), None);
    let broken = builder.view(b"\x89PNG not an image", None);
    let materials = [
        r#"{"name": "painted", "pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0}}}"#,
        r#"{"name": "scaled", "pbrMetallicRoughness": {"metallicFactor": 0.4, "roughnessFactor": 0.5, "metallicRoughnessTexture": {"index": 0}}}"#,
        r#"{"name": "glass", "pbrMetallicRoughness": {"roughnessFactor": 0, "metallicRoughnessTexture": {"index": 0}},
           "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}}}"#,
        r#"{"name": "broken", "pbrMetallicRoughness": {"roughnessFactor": 0.3, "metallicRoughnessTexture": {"index": 1}}}"#,
    ];
    let images = format!(
        r#""images": [{{"bufferView": {orm}, "mimeType": "image/png"}}, {{"bufferView": {broken}, "mimeType": "image/png"}}],
        "textures": [{{"source": 0}}, {{"source": 1}}], "extensionsUsed": ["KHR_materials_transmission"]"#
    );
    let scene = parse(&builder.gltf(&quad_per_material(&primitive, &materials, &images)));
    let painted = &scene.materials[0];
    let (metallic, rough) = (painted.map_pm.as_ref().unwrap(), painted.map_pr.as_ref().unwrap());
    assert_eq!(
        (metallic.channel, metallic.scale, rough.channel, rough.scale),
        (Channel::Blue, 1.0, Channel::Green, 1.0)
    );
    assert_eq!(metallic.path, rough.path, "one texture, two channels");
    assert_eq!(scene.materials[2].map_pr, None, "glass is smooth");
    assert_eq!(
        scene.warnings,
        ["test.gltf: material 'glass': not read: metallicRoughnessTexture under transmission (the glass is smooth)"]
    );
    let world = lumiere::world::World::new(scene, lumiere::accel::BuildPreset::Default);
    assert_eq!(world.warnings().len(), 1, "{:?}", world.warnings());
    assert!(
        world.warnings()[0].contains("#image1")
            && world.warnings()[0].ends_with("metallic and roughness values are used instead")
    );
    let pbr = |metallic: f32, roughness: f32| MaterialKind::pbr(metallic, pbr_alpha(roughness)).bsdf(Vec3::ONE);
    let (low, high) = (51.0 / 255.0, 204.0 / 255.0);
    let expected = [
        [pbr(1.0, low), pbr(0.0, high)],
        [pbr(0.4, 0.5 * low), pbr(0.0, 0.5 * high)],
        [MaterialKind::Dielectric { eta: 1.5, tf: Vec3::ONE }.bsdf(Vec3::ONE); 2],
        [pbr(1.0, 0.3); 2],
    ];
    for (m, expected) in expected.into_iter().enumerate() {
        for (x, expected) in [0.25, 0.75].into_iter().zip(expected) {
            let ray = Ray::new(Vec3::new(2.0 * m as f32 + x, 0.5, 1.0), -Vec3::Z);
            let hit = world.intersect(&ray).unwrap();
            let surface = world.surface(&ray, &hit);
            assert_scatters_as(world.bsdf(&surface), expected, &format!("material {m} at x = {x}"));
        }
    }
}

/// A `normalTexture` bends the shading normal: its texel's direction (`2c - 1`, x and y times
/// `scale`) in the frame of the triangle's texture axes and its normal, so a texture mirrored in
/// `u` bends it the other way, and the back of the surface shows the opposite of its front's
/// normal (as glTF's reference viewer flips the frame on back faces); a direction that would face
/// away from the surface, or a map that does not decode, leaves the interpolated normal. The rows
/// a packet shades from agree with the single point.
#[test]
fn normal_textures_bend_the_shading_normal_in_the_triangles_texture_frame() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    // The same quad with its texture mirrored in u: `∂p/∂u` along -x.
    let positions = builder.floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.], "VEC3");
    let texcoords = builder.floats(&[1., 1., 0., 1., 0., 0., 1., 0.], "VEC2");
    let indices = builder.indices(&[0, 1, 2, 0, 2, 3]);
    let mirrored =
        format!(r#"{{"attributes": {{"POSITION": {positions}, "TEXCOORD_0": {texcoords}}}, "indices": {indices}}}"#);
    let texel = [204u8, 100, 230];
    let tilted = builder.view(&encoded(image::RgbImage::from_raw(1, 1, texel.to_vec()).unwrap().into()), None);
    let below = builder.view(&encoded(image::RgbImage::from_raw(1, 1, vec![255, 128, 0]).unwrap().into()), None);
    let broken = builder.view(b"\x89PNG not an image", None);
    let materials = [
        r#"{"name": "tilted", "normalTexture": {"index": 0}}"#,
        r#"{"name": "gentle", "normalTexture": {"index": 0, "scale": 0.5}}"#,
        r#"{"name": "below", "normalTexture": {"index": 1}}"#,
        r#"{"name": "broken", "normalTexture": {"index": 2}}"#,
        r#"{"name": "mirrored", "normalTexture": {"index": 0}}"#,
    ];
    let images = format!(
        r#""images": [{{"bufferView": {tilted}, "mimeType": "image/png"}}, {{"bufferView": {below}, "mimeType": "image/png"}},
        {{"bufferView": {broken}, "mimeType": "image/png"}}], "textures": [{{"source": 0}}, {{"source": 1}}, {{"source": 2}}]"#
    );
    let mut rest = quad_per_material(&primitive, &materials, &images);
    // The last material's quad is the mirrored one.
    let last = primitive.replace(r#""indices""#, r#""material": 4, "indices""#);
    rest = rest.replacen(&last, &mirrored.replace(r#""indices""#, r#""material": 4, "indices""#), 1);
    let scene = parse(&builder.gltf(&rest));
    assert_eq!(scene.materials[1].normal_map.as_ref().map(|map| map.scale), Some(0.5));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let world = lumiere::world::World::new(scene, lumiere::accel::BuildPreset::Default);
    assert_eq!(world.warnings().len(), 1, "{:?}", world.warnings());
    assert!(world.warnings()[0].ends_with("the surface keeps its interpolated normals"), "{:?}", world.warnings());
    let c = Vec3::from(texel.map(|code| f32::from(code) / 255.0 * 2.0 - 1.0));
    let expected =
        [Vec3::new(c.x, c.y, c.z), Vec3::new(0.5 * c.x, 0.5 * c.y, c.z), Vec3::Z, Vec3::Z, Vec3::new(-c.x, c.y, c.z)]
            .map(Vec3::normalize);
    for (m, expected) in expected.into_iter().enumerate() {
        let x = 2.0 * m as f32 + 0.3;
        // From above, and from below, where the surface shows the opposite of its front's normal.
        for (z, expected) in [(1.0, expected), (-1.0, -expected)] {
            let ray = Ray::new(Vec3::new(x, 0.6, z), Vec3::new(0.0, 0.0, -z));
            let hits = [world.intersect(&ray), None];
            let surface = world.surface(&ray, &hits[0].unwrap());
            assert!(
                (surface.ns - expected).abs().max_element() < 1e-5,
                "material {m}, z {z}: {} vs {expected}",
                surface.ns
            );
            let points = world.surfaces(&[ray, ray], &hits);
            assert_eq!(points[0].ns, surface.ns, "material {m}, z {z}: the rows' normal");
        }
    }
}

/// The share of `rays` that `world` lets through.
fn share_through(world: &lumiere::world::World, rays: impl Iterator<Item = Ray>) -> f64 {
    let (mut through, mut count) = (0, 0);
    for ray in rays {
        let hit = world.intersect(&ray);
        assert_eq!(hit.is_some(), world.occluded(&ray), "occlusion as intersection");
        assert_eq!(world.intersect(&ray), hit, "the same ray, the same answer");
        through += usize::from(hit.is_none());
        count += 1;
    }
    through as f64 / count as f64
}

/// Rays straight down onto 64 × 64 points of `[x - 0.1, x + 0.1] × [0.05, 0.95]`, in the z = 0 plane.
fn rays_down_around(x: f32) -> impl Iterator<Item = Ray> {
    (0..64 * 64).map(move |i| {
        let (x, y) = (x - 0.1 + 0.2 * (i % 64) as f32 / 64.0, 0.05 + 0.9 * (i / 64) as f32 / 64.0);
        Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z)
    })
}

#[test]
fn blend_materials_stop_the_share_of_rays_their_alpha_covers() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let with_alpha = builder.view(&png_with_alpha(), None);
    let materials = [
        r#"{"name": "veil", "alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.3]}}"#,
        r#"{"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [1, 1, 1, 0.5]}}"#,
        r#"{"name": "gone", "alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0]}}"#,
        r#"{"alphaMode": "BLEND"}"#,
        r#"{"name": "lamp", "alphaMode": "BLEND", "emissiveFactor": [1, 1, 1], "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.3]}}"#,
    ];
    // The share of each quad that is there within 0.1 of x = 0.25 and of x = 0.75, the centres of
    // the texture's texels of alpha 0.2 and 0.8: filtered, the alpha runs from a centre's value
    // towards its neighbour's, by 0.6 a half texel, so it is 0.26 and 0.74 there on average.
    let expected = [Some([0.3, 0.3]), Some([0.13, 0.37]), None, Some([1.0, 1.0]), Some([1.0, 1.0])];
    let images = format!(
        r#""images": [{{"bufferView": {with_alpha}, "mimeType": "image/png"}}], "textures": [{{"source": 0}}]"#
    );
    let rest = quad_per_material(&primitive, &materials, &images);
    let scene = parse(&builder.gltf(&rest));
    assert_eq!(scene.materials[0].map_d_test, CoverageTest { alpha_only: true, scale: 0.3, cut: Cut::Hashed });
    assert_eq!(scene.materials[0].map_d, None);
    assert_eq!(scene.materials[1].map_d, scene.materials[1].map_kd);
    let mut warnings = scene.warnings.clone();
    warnings.sort();
    assert_eq!(
        warnings,
        [
            "test.gltf: material 'gone': alphaMode BLEND covers none of it (baseColorFactor alpha 0), without a \
             texture: its primitives are not drawn",
            "test.gltf: material 'lamp': not read: alphaMode BLEND on an emitter (drawn opaque: a light is whole)"
        ]
    );
    let mut materials_drawn = scene.mesh.material_ids.clone();
    materials_drawn.dedup();
    assert_eq!(materials_drawn, [0, 1, 3, 4]);
    let world = lumiere::world::World::new(scene, lumiere::accel::BuildPreset::Default);
    for (m, expected) in expected.iter().enumerate() {
        let Some(covered) = expected else { continue };
        for (half, covered) in covered.iter().enumerate() {
            let through = share_through(&world, rays_down_around(2.0 * m as f32 + 0.25 + 0.5 * half as f32));
            // 4096 rays: the share's standard deviation is at most 0.0078; allow five of them.
            assert!((through - (1.0 - covered)).abs() < 0.04, "material {m}, half {half}: {through} through");
        }
    }
}

#[test]
fn rough_glass_a_lone_ior_and_a_clamped_texture_axis_are_named_as_not_read() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let materials = [
        r#"{"name": "frosted", "pbrMetallicRoughness": {"roughnessFactor": 0.3},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}}}"#,
        r#"{"name": "diamond", "extensions": {"KHR_materials_ior": {"ior": 2.4}}}"#,
        r#"{"name": "plain", "extensions": {"KHR_materials_ior": {"ior": 1.5}}}"#,
        r#"{"name": "clamped", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#,
    ];
    // Only `t` is clamped (33071, CLAMP_TO_EDGE): one axis that does not repeat is enough.
    let images = r#""images": [{"uri": "a.png"}], "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapT": 33071}], "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"]"#;
    let scene = parse(&builder.gltf(&quad_per_material(&primitive, &materials, images)));
    assert_eq!(
        scene.warnings,
        [
            "test.gltf: material 'frosted': not read: roughness under transmission (the glass is smooth)",
            "test.gltf: material 'diamond': not read: KHR_materials_ior without transmission (the specular layer \
             reflects 4%)",
            "test.gltf: material 'clamped': not read: the sampler's wrapping (textures repeat)",
        ],
        "glTF's own index of 1.5 alone changes nothing, so 'plain' has no warning"
    );
}

/// A primitive without `TEXCOORD_0` under a textured material reads its texture at one point:
/// the scene names the material and how many of its triangles, as for OBJ faces without `vt`.
#[test]
fn a_textured_primitive_without_texture_coordinates_is_named() {
    let mut builder = Builder::default();
    let positions = builder.floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.], "VEC3");
    let indices = builder.indices(&[0, 1, 2, 0, 2, 3]);
    let primitive = format!(r#"{{"attributes": {{"POSITION": {positions}}}, "indices": {indices}}}"#);
    let image = builder.view(&png(), None);
    let materials = [r#"{"name": "painted", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#];
    let images =
        format!(r#""images": [{{"bufferView": {image}, "mimeType": "image/png"}}], "textures": [{{"source": 0}}]"#);
    let scene = parse(&builder.gltf(&quad_per_material(&primitive, &materials, &images)));
    assert_eq!(
        scene.warnings,
        ["test.gltf: material 'painted': 2 of its 2 triangles have no texture coordinates: its textures are \
          read at u = v = 0 there"]
    );
}

/// A base colour texture's colour is multiplied by `baseColorFactor`, as glTF says; the factor
/// alone is the colour where the texture cannot be used.
#[test]
fn base_colour_factors_tint_their_textures() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let texel = [200u8, 100, 50];
    let image = builder.view(&encoded(image::RgbImage::from_raw(1, 1, texel.to_vec()).unwrap().into()), None);
    let broken = builder.view(b"\x89PNG not an image", None);
    let materials = [
        r#"{"name": "tinted", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [0.5, 1, 0.25, 1]}}"#,
        r#"{"name": "white", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}"#,
        r#"{"name": "broken", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}, "baseColorFactor": [0.5, 1, 0.25, 1]}}"#,
    ];
    let images = format!(
        r#""images": [{{"bufferView": {image}, "mimeType": "image/png"}}, {{"bufferView": {broken}, "mimeType": "image/png"}}],
        "textures": [{{"source": 0}}, {{"source": 1}}]"#
    );
    let scene = parse(&builder.gltf(&quad_per_material(&primitive, &materials, &images)));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let factor = Vec3::new(0.5, 1.0, 0.25);
    assert_eq!([0, 1, 2].map(|m| scene.materials[m].map_kd_factor), [factor, Vec3::ONE, factor]);
    let world = lumiere::world::World::new(scene, lumiere::accel::BuildPreset::Default);
    assert_eq!(world.warnings().len(), 1, "{:?}", world.warnings());
    let colour = Vec3::from(texel.map(|code| lumiere::textures::srgb_to_linear(f32::from(code) / 255.0)));
    // glTF's default metallic weight, 1, makes each a metal whose F0 (its albedo) is the base colour.
    for (m, expected) in [colour * factor, colour, factor].into_iter().enumerate() {
        let ray = Ray::new(Vec3::new(2.0 * m as f32 + 0.5, 0.5, 1.0), -Vec3::Z);
        let surface = world.surface(&ray, &world.intersect(&ray).unwrap());
        let albedo = world.bsdf(&surface).albedo();
        assert!((albedo - expected).abs().max_element() < 1e-6, "material {m}: {albedo} vs {expected}");
    }
}

#[test]
fn base_colour_textures_are_found_beside_the_file_or_embedded_and_placed() {
    let dir = TempDir::new("gltf-textures");
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let image_view = builder.view(&png(), None);
    let data_uri = format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(png()));
    let textured = |m: usize| primitive.replace(r#""indices""#, &format!(r#""material": {m}, "indices""#));
    let rest = format!(
        r#"{}, "images": [{{"uri": "tiles%20a.png"}}, {{"bufferView": {image_view}, "mimeType": "image/png"}}, {{"uri": "{data_uri}"}}],
        "textures": [{{"source": 0}}, {{"source": 1}}, {{"source": 2}}],
        "materials": [
            {{"name": "file", "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0,
                "extensions": {{"KHR_texture_transform": {{"offset": [0.5, 0.25], "scale": [2, 4]}}}}}}}}}},
            {{"name": "view", "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 1}}}}}},
            {{"name": "data", "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 2}}}}}}],
        "extensionsUsed": ["KHR_texture_transform"]"#,
        one_mesh(&[textured(0), textured(1), textured(2)].join(", "))
    );
    let file = dir.path("scene.glb");
    let scene = parse_gltf(&builder.glb(&rest), &file, &no_files).unwrap();
    let [from_file, from_view, from_data] = [0, 1, 2].map(|m| scene.materials[m].map_kd.clone().unwrap());
    assert_eq!(from_file, dir.path("tiles a.png"), "relative to the glTF file, percent-decoded");
    // glTF's `uv · (2, 4) + (0.5, 0.25)`, v down, is lumiere's `uv · (2, 4) + (0.5, 1 − 0.25 − 4)`, v up.
    let placement = scene.materials[0].map_kd_transform;
    assert_eq!((placement.scale, placement.offset), (Vec2::new(2., 4.), Vec2::new(0.5, -3.25)));
    assert_eq!(from_view, PathBuf::from(format!("{}#image1", file.display())));
    assert_eq!(scene.embedded_images.get(&from_view), Some(&png()[..]));
    assert_eq!(scene.embedded_images.get(&from_data), Some(&png()[..]));
    let read: Vec<&Path> = scene.files_read().collect();
    assert_eq!(read, [from_file.as_path()], "embedded images are not files an output could overwrite");
    // Each decodes, from the file or from the scene's bytes.
    std::fs::write(&from_file, png()).unwrap();
    let world = lumiere::world::World::new(scene, lumiere::accel::BuildPreset::Default);
    assert!(world.warnings().is_empty(), "{:?}", world.warnings());
    for material in 0..3 {
        assert_eq!(
            world.texture_contents(material),
            [Some(hash_bytes(&png())), None, None, None, None],
            "material {material}"
        );
    }
}

/// The members of a file whose `i`-th material's base colour texture is an image in view
/// `views[i]`, each on a quad of its own.
fn textured_from_views(primitive: &str, views: &[usize]) -> String {
    let materials: Vec<String> = (0..views.len())
        .map(|i| format!(r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": {i}}}}}}}"#))
        .collect();
    let textures: Vec<String> = (0..views.len()).map(|i| format!(r#"{{"source": {i}}}"#)).collect();
    let images: Vec<String> =
        views.iter().map(|v| format!(r#"{{"bufferView": {v}, "mimeType": "image/png"}}"#)).collect();
    let images = format!(r#""images": [{}], "textures": [{}]"#, images.join(", "), textures.join(", "));
    quad_per_material(primitive, &materials.iter().map(String::as_str).collect::<Vec<_>>(), &images)
}

/// Images in buffer views are copied out of the buffers once per view, and no more than the
/// buffers hold in all: before, each image copied its view, so that a few dozen bytes of JSON per
/// image or per view over the same bytes copied a large buffer as often as they liked.
#[test]
fn images_in_buffer_views_copy_no_more_than_the_buffers_hold() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let view = builder.view(&png(), None);
    // 50 images of one view share one copy of its bytes.
    let scene = parse(&builder.gltf(&textured_from_views(&primitive, &[view; 50])));
    let copies: Vec<*const u8> = scene
        .materials
        .iter()
        .map(|m| scene.embedded_images.get(m.map_kd.as_ref().expect("a texture")).expect("embedded").as_ptr())
        .collect();
    assert!(copies.iter().all(|&copy| copy == copies[0]), "{} images, not one copy", copies.len());
    // Views over the same bytes are copied each, up to the buffer's size; the textures past it are
    // not read, with a warning each.
    let fits = builder.blob.len() / png().len();
    let same = builder.views[view].clone();
    let views: Vec<usize> = (0..fits + 3)
        .map(|_| {
            builder.views.push(same.clone());
            builder.views.len() - 1
        })
        .collect();
    let scene = parse(&builder.gltf(&textured_from_views(&primitive, &views)));
    let textured = scene.materials.iter().filter(|m| m.map_kd.is_some()).count();
    assert_eq!(textured, fits, "{:?}", scene.warnings);
    assert_eq!(scene.warnings.len(), 3, "{:?}", scene.warnings);
    assert!(scene.warnings[0].starts_with(&format!("test.gltf: material 'material{fits}': baseColorTexture not read: the buffer views of the file's images overlap")), "{}", scene.warnings[0]);
}

#[test]
fn a_mesh_is_drawn_once_per_node_and_a_scene_instanced_past_memory_is_refused() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let nodes: Vec<String> = (0..100).map(|i| format!(r#"{{"mesh": 0, "translation": [{i}, 0, 0]}}"#)).collect();
    let roots: Vec<String> = (0..100).map(|i| i.to_string()).collect();
    let rest = format!(
        r#""meshes": [{{"primitives": [{primitive}]}}], "nodes": [{}], "scenes": [{{"nodes": [{}]}}]"#,
        nodes.join(", "),
        roots.join(", ")
    );
    let bytes = builder.gltf(&rest);
    let scene = parse(&bytes);
    assert_eq!(scene.mesh.triangle_count(), 200);
    assert_eq!(scene.mesh.positions[4 * 99 + 1], Vec3::new(100., 0., 0.));
    // The same file with less memory than its 200 triangles need is refused before they are made.
    let error = parse_gltf_with_memory(&bytes, Path::new("test.gltf"), &no_files, 10_000).unwrap_err().to_string();
    assert!(error.starts_with("test.gltf: needs about "), "{error}");
    assert!(error.contains("for its 200 triangles and 400 vertices"), "{error}");
    assert!(parse_gltf_with_memory(&bytes, Path::new("test.gltf"), &no_files, 1 << 30).is_ok());
    // Vertices past what 32-bit indices reach are refused whatever the memory: 2^30 positions
    // without a view (zeros but for one sparse substitution), drawn by four nodes.
    let mut builder = Builder::default();
    let (indices, values) = (builder.view(&[0u8], None), builder.view(&[0u8; 12], None));
    let sparse = format!(
        r#", "sparse": {{"count": 1, "indices": {{"bufferView": {indices}, "componentType": {UNSIGNED_BYTE}}}, "values": {{"bufferView": {values}}}}}"#
    );
    let zeros = builder.accessor(None, 0, FLOAT, 1 << 30, "VEC3", &sparse);
    let rest = format!(
        r#""meshes": [{{"primitives": [{{"attributes": {{"POSITION": {zeros}}}}}]}}],
        "nodes": [{{"mesh": 0}}, {{"mesh": 0}}, {{"mesh": 0}}, {{"mesh": 0}}], "scenes": [{{"nodes": [0, 1, 2, 3]}}]"#
    );
    let bytes = builder.gltf(&rest);
    let error = parse_gltf_with_memory(&bytes, Path::new("test.gltf"), &no_files, u64::MAX).unwrap_err();
    assert_eq!(
        error.to_string(),
        "test.gltf: the scene draws 4294967296 vertices, more than the 4294967295 lumiere can index"
    );
}

/// A hang: 20,000 nodes drawing a mesh of 20,000 primitives without vertices, a file of under
/// 1 MB, took half a minute to load as empty, every primitive visited once per node.
#[test]
fn many_nodes_drawing_a_mesh_of_many_empty_primitives_load_at_once() {
    const COUNT: usize = 20_000;
    let mut builder = Builder::default();
    let view = builder.view(&[0; 12], None);
    let nothing = builder.accessor(Some(view), 0, FLOAT, 0, "VEC3", "");
    let primitive = format!(r#"{{"attributes": {{"POSITION": {nothing}}}}}"#);
    let rest = format!(
        r#""meshes": [{{"primitives": [{}]}}], "nodes": [{}]"#,
        vec![primitive.as_str(); COUNT].join(", "),
        vec![r#"{"mesh": 0}"#; COUNT].join(", ")
    );
    let bytes = builder.gltf(&rest);
    let start = std::time::Instant::now();
    assert_eq!(parse(&bytes).mesh.triangle_count(), 0);
    assert!(start.elapsed().as_secs_f64() < 5.0, "{:?} for {} bytes", start.elapsed(), bytes.len());
}

/// A file of tens of thousands of images, each in a `data:` URI and each its own material's base
/// colour, loads at once: the embedded images and the textures are found by name, where lists
/// searched for each took the square of their number (a minute for these 20,000).
#[test]
fn tens_of_thousands_of_embedded_images_load_at_once() {
    const COUNT: usize = 20_000;
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let data_uri = format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(png()));
    let material = |i| format!(r#"{{"pbrMetallicRoughness": {{"baseColorTexture": {{"index": {i}}}}}}}"#);
    let rest = format!(
        r#""materials": [{}], "textures": [{}], "images": [{}]"#,
        (0..COUNT).map(material).collect::<Vec<_>>().join(", "),
        (0..COUNT).map(|i| format!(r#"{{"source": {i}}}"#)).collect::<Vec<_>>().join(", "),
        vec![format!(r#"{{"uri": "{data_uri}"}}"#); COUNT].join(", ")
    );
    let rest = format!("{}, {rest}", one_mesh(&primitive.replace(r#""indices""#, r#""material": 0, "indices""#)));
    let bytes = builder.gltf(&rest);
    let start = std::time::Instant::now();
    let scene = parse(&bytes);
    let materials: Vec<_> = scene.materials.iter().map(|m| m.map_kd.clone()).collect();
    let paths = materials.iter().map(|path| path.as_deref());
    let (ids, set, warnings) = lumiere::textures::TextureSet::for_materials(paths, &scene.embedded_images);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!((ids.iter().flatten().count(), set.len()), (COUNT, COUNT));
    assert!(start.elapsed().as_secs_f64() < 10.0, "{:?} for {} bytes", start.elapsed(), bytes.len());
}

#[test]
fn what_is_not_drawn_is_named_in_warnings() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let points = primitive.replace(r#""indices""#, r#""mode": 0, "indices""#);
    let rest = format!(
        r#""meshes": [{{"primitives": [{primitive}, {points}]}}], "nodes": [{{"mesh": 0}}, {{"camera": 0}}, {{"mesh": 0}}],
        "cameras": [{{"type": "orthographic", "orthographic": {{"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 9}}}}],
        "scenes": [{{"nodes": [0, 1, 2]}}, {{"name": "other", "nodes": []}}], "scene": 0,
        "materials": [{{"name": "rough", "occlusionTexture": {{"index": 0}},
            "emissiveFactor": [1, 1, 1], "emissiveTexture": {{"index": 0}}}}],
        "textures": [{{"source": 0}}], "images": [{{"uri": "n.png"}}],
        "extensionsUsed": ["KHR_materials_clearcoat", "KHR_lights_punctual"]"#
    );
    let rest = rest.replacen(r#""indices""#, r#""material": 0, "indices""#, 1);
    let scene = parse(&builder.gltf(&rest));
    assert_eq!(scene.mesh.triangle_count(), 4, "the points are not drawn, by either node");
    assert!(!scene.materials[0].is_emissive(), "an emissive texture is not painted as its factor over the surface");
    let expected = [
        r#"test.gltf: extensions not read: "KHR_materials_clearcoat", "KHR_lights_punctual""#,
        "test.gltf: the file has 2 scenes; drawing scene 0",
        "test.gltf: camera 0 of node 1: orthographic camera not read (lumiere has no orthographic projection)",
        "test.gltf: material 'rough': not read: emissiveTexture (the material does not emit; --emission NAME=R,G,B \
         makes it a light), occlusionTexture",
        "test.gltf: mesh 0 primitive 1: Points are not drawn (lumiere draws triangles)",
    ];
    let mut warnings = scene.warnings.clone();
    warnings.sort();
    let mut expected = expected.map(String::from).to_vec();
    expected.sort();
    assert_eq!(warnings, expected);
}

#[test]
fn files_load_by_extension_with_their_buffers_beside_them() {
    let dir = TempDir::new("gltf-files");
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let rest = one_mesh(&primitive);
    std::fs::write(dir.path("quad data.bin"), &builder.blob).unwrap();
    std::fs::write(dir.path("quad.gltf"), builder.json(&rest, Some("quad%20data.bin"))).unwrap();
    std::fs::write(dir.path("quad.GLB"), builder.glb(&rest)).unwrap();
    let mut gzipped = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    io::Write::write_all(&mut gzipped, &builder.glb(&rest)).unwrap();
    std::fs::write(dir.path("quad.glb.gz"), gzipped.finish().unwrap()).unwrap();
    for name in ["quad.gltf", "quad.GLB", "quad.glb.gz"] {
        let scene = load(&dir.path(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(scene.mesh.triangle_count(), 2, "{name}");
    }
    let scene = load(&dir.path("quad.gltf")).unwrap();
    assert_eq!(scene.files_read().collect::<Vec<_>>(), [dir.path("quad data.bin")], "no output may overwrite it");
    std::fs::remove_file(dir.path("quad data.bin")).unwrap();
    let error = load(&dir.path("quad.gltf")).unwrap_err().to_string();
    assert!(error.contains("quad.gltf: buffer 0: ") && error.contains("quad data.bin"), "{error}");
}

/// Every malformed file is refused with one line that names the file and what is wrong where.
#[test]
fn malformed_and_hostile_files_are_refused_with_one_line() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder);
    let good = one_mesh(&primitive);
    let json = |rest: &str| builder.gltf(rest);
    // The good file with its first `from` made `to` (views and accessors are not in `good`).
    let edit = |from: &str, to: &str| {
        let text = String::from_utf8(builder.gltf(&good)).unwrap();
        assert!(text.contains(from), "{from}");
        text.replacen(from, to, 1).into_bytes()
    };
    let header = |version: u32, length: u32| [&b"glTF"[..], &version.to_le_bytes(), &length.to_le_bytes()].concat();
    let mut short_chunk = header(2, 20);
    short_chunk.extend_from_slice(&[100, 0, 0, 0, b'J', b'S', b'O', b'N']);
    let bin_first = {
        let mut bytes = glb(b"{}", None);
        bytes[16..20].copy_from_slice(b"BIN\0");
        bytes
    };
    let towering: Vec<String> =
        (1..=10).map(|child| format!(r#"{{"scale": [3e38, 3e38, 3e38], "children": [{child}]}}"#)).collect();
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"glTF\x02\0\0".to_vec(), "test.gltf: GLB: the header needs 12 bytes, the file has 7"),
        (header(1, 12), "test.gltf: GLB: version 1; lumiere reads glTF 2"),
        (header(2, 99), "test.gltf: GLB: the header gives a length of 99 bytes, the file has 12"),
        (short_chunk, "test.gltf: GLB: byte 12: a chunk of 100 bytes, but 0 are left"),
        (bin_first, "test.gltf: GLB: the first chunk is not the JSON chunk"),
        (b"{\"asset\": ".to_vec(), "test.gltf: not glTF JSON: EOF while parsing a value at line 1 column 10"),
        (b"ply\n".to_vec(), "test.gltf: not glTF JSON: expected value at line 1 column 1"),
        (
            json(&good.replace(r#""nodes": [0]"#, r#""nodes": [7]"#)),
            "test.gltf: invalid glTF: scenes[0].nodes[0]: index out of bounds",
        ),
        (
            json(&format!(r#"{good}, "extensionsRequired": ["KHR_draco_mesh_compression"]"#)),
            "test.gltf: requires the extension \"KHR_draco_mesh_compression\", which lumiere does not read",
        ),
        (
            glb(builder.json(&good, None).as_bytes(), None),
            "test.gltf: buffer 0: names the GLB binary chunk, but the file has none",
        ),
        (
            builder.json(&good, Some("data:application/octet-stream;base64,AAAA")).into_bytes(),
            "test.gltf: buffer 0: declares 140 bytes, but its data has 3",
        ),
        (
            builder.json(&good, Some("https://example.com/x.bin")).into_bytes(),
            "test.gltf: buffer 0: a URI of scheme \"https\"",
        ),
        (builder.json(&good, Some("x.bin")).into_bytes(), "test.gltf: buffer 0: \"x.bin\": x.bin is not there"),
        (
            edit(r#""byteOffset": 0, "byteLength": 48"#, r#""byteOffset": 100, "byteLength": 48"#),
            "test.gltf: mesh 0 primitive 0: POSITION (accessor 0): buffer view 0 spans bytes 100 to 148 of buffer 0, \
             which has 140",
        ),
        (edit(r#""count": 4"#, r#""count": 5"#), "test.gltf: mesh 0 primitive 0: NORMAL has 4 elements, POSITION 5"),
        (
            edit(r#""byteOffset": 0, "componentType": 5123"#, r#""byteOffset": 2, "componentType": 5123"#),
            "test.gltf: mesh 0 primitive 0: indices (accessor 3): 6 elements of 2 bytes, 2 apart, from byte 2 of \
             buffer view 3, which has 12",
        ),
        (
            edit(r#""type": "VEC3""#, r#""type": "VEC2""#),
            "test.gltf: mesh 0 primitive 0: POSITION (accessor 0): holds Vec2 elements; lumiere reads Vec3 here",
        ),
        (
            edit(r#""componentType": 5123"#, r#""componentType": 5126"#),
            "test.gltf: mesh 0 primitive 0: indices (accessor 3): indices of type F32; they must be unsigned integers",
        ),
        (
            json(&good.replace(r#""attributes": {"POSITION": 0, "#, r#""attributes": {"#)),
            "test.gltf: invalid glTF: meshes[0].primitives[0].attributes[\"POSITION\"]: missing data",
        ),
        (
            json(&good.replace(r#""nodes": [{"mesh": 0}]"#, r#""nodes": [{"mesh": 0, "children": [0]}]"#)),
            "test.gltf: node 0 is reached twice from the scene's roots; glTF nodes must form a tree",
        ),
        (
            json(&good.replace(r#""nodes": [{"mesh": 0}]"#, r#""nodes": [{"children": [1, 1]}, {"mesh": 0}]"#)),
            "test.gltf: node 1 is reached twice",
        ),
        (
            // Nine scales of 3e38 overflow even double precision.
            json(&good.replace(
                r#""nodes": [{"mesh": 0}]"#,
                &format!(r#""nodes": [{}, {{"mesh": 0}}]"#, towering.join(", ")),
            )),
            "test.gltf: node 8: its transform is not finite",
        ),
        (
            json(&good.replace(
                r#""nodes": [{"mesh": 0}]"#,
                r#""nodes": [{"mesh": 0, "scale": [3e38, 1, 1], "translation": [3e38, 0, 0]}]"#,
            )),
            "test.gltf: node 0 places vertex 1 of mesh 0 at a position that is not finite in single precision",
        ),
    ];
    for (bytes, expected) in cases {
        let Err(error) = parse_gltf(&bytes, Path::new("test.gltf"), &no_files) else {
            panic!("not refused: {expected}")
        };
        let error = error.to_string();
        assert!(error.starts_with(expected), "expected {expected:?}, got {error:?}");
        assert!(!error.contains('\n'), "one line: {error:?}");
    }
}

#[test]
fn indices_out_of_range_and_bad_sparse_substitutions_are_refused() {
    let mut builder = Builder::default();
    let positions = builder.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], "VEC3");
    let indices = builder.indices(&[0, 1, 3]);
    let error = parse_error(
        &builder.gltf(&one_mesh(&format!(r#"{{"attributes": {{"POSITION": {positions}}}, "indices": {indices}}}"#))),
    );
    assert_eq!(
        error,
        "test.gltf: mesh 0 primitive 0: indices (accessor 1): index 3 out of range: POSITION has 3 elements"
    );
    let sparse_indices = builder.view(&[5u8], None);
    let sparse_values = builder.view(&[0u8; 12], None);
    let sparse = format!(
        r#", "sparse": {{"count": 1, "indices": {{"bufferView": {sparse_indices}, "componentType": {UNSIGNED_BYTE}}}, "values": {{"bufferView": {sparse_values}}}}}"#
    );
    let texcoords = builder.floats(&[0., 0., 1., 0., f32::INFINITY, 1.], "VEC2");
    let error = parse_error(
        &builder
            .gltf(&one_mesh(&format!(r#"{{"attributes": {{"POSITION": {positions}, "TEXCOORD_0": {texcoords}}}}}"#))),
    );
    assert_eq!(error, "test.gltf: mesh 0 primitive 0: TEXCOORD_0 (accessor 2): element 2 is not finite");
    let moved = builder.accessor(None, 0, FLOAT, 3, "VEC3", &sparse);
    let error = parse_error(&builder.gltf(&one_mesh(&format!(r#"{{"attributes": {{"POSITION": {moved}}}}}"#))));
    assert_eq!(
        error,
        "test.gltf: mesh 0 primitive 0: POSITION (accessor 3): sparse index 5 out of range: the accessor has 3 elements"
    );
}

#[test]
fn a_texture_placement_that_is_not_finite_is_left_out_with_a_warning() {
    let mut builder = Builder::default();
    let primitive = quad(&mut builder).replace(r#""indices""#, r#""material": 0, "indices""#);
    let rest = format!(
        r#"{}, "images": [{{"uri": "a.png"}}], "textures": [{{"source": 0}}],
        "materials": [{{"name": "far", "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0,
            "extensions": {{"KHR_texture_transform": {{"scale": [1e39, 1]}}}}}}}}}}],
        "extensionsUsed": ["KHR_texture_transform"]"#,
        one_mesh(&primitive)
    );
    let scene = parse(&builder.gltf(&rest));
    assert!(scene.materials[0].map_kd_transform.is_identity());
    assert_eq!(
        scene.warnings,
        ["test.gltf: material 'far': not read: KHR_texture_transform with numbers that are not finite"]
    );
}
