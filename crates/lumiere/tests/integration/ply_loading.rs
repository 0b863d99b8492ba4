//! PLY loading: ASCII and both binary byte orders read into the same mesh, faces split as OBJ's
//! are, what is not read named in warnings, and every malformed or hostile file refused with one
//! line that says where.

use crate::common::TempDir;
use flate2::Compression;
use flate2::write::GzEncoder;
use glam::Vec3;
use lumiere::scene::Scene;
use lumiere::scene::load::load;
use lumiere::scene::load::obj::parse_obj;
use lumiere::scene::load::ply::{MATERIAL_NAME, parse_ply, parse_ply_with_memory};
use std::io::Write;
use std::path::Path;

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Little,
    Big,
}

const FORMATS: [Format; 3] = [Format::Ascii, Format::Little, Format::Big];

impl Format {
    fn name(self) -> &'static str {
        match self {
            Format::Ascii => "ascii",
            Format::Little => "binary_little_endian",
            Format::Big => "binary_big_endian",
        }
    }
}

/// One value as a test writes it: its bytes in a binary body, its text in an ASCII one.
#[derive(Clone, Copy)]
enum Value {
    U8(u8),
    I16(i16),
    U32(u32),
    I32(i32),
    F32(f32),
    F64(f64),
}

impl Value {
    fn write(self, format: Format, out: &mut Vec<u8>) {
        if format == Format::Ascii {
            let text = match self {
                Value::U8(v) => v.to_string(),
                Value::I16(v) => v.to_string(),
                Value::U32(v) => v.to_string(),
                Value::I32(v) => v.to_string(),
                Value::F32(v) => v.to_string(),
                Value::F64(v) => v.to_string(),
            };
            out.extend_from_slice(text.as_bytes());
            out.push(b' ');
            return;
        }
        let mut bytes = match self {
            Value::U8(v) => v.to_le_bytes().to_vec(),
            Value::I16(v) => v.to_le_bytes().to_vec(),
            Value::U32(v) => v.to_le_bytes().to_vec(),
            Value::I32(v) => v.to_le_bytes().to_vec(),
            Value::F32(v) => v.to_le_bytes().to_vec(),
            Value::F64(v) => v.to_le_bytes().to_vec(),
        };
        if format == Format::Big {
            bytes.reverse();
        }
        out.extend_from_slice(&bytes);
    }
}

/// A PLY file: `header` is the lines between the format line and `end_header`; each row of
/// `rows` is one element instance (a line in ASCII).
fn ply(format: Format, header: &str, rows: &[Vec<Value>]) -> Vec<u8> {
    let mut out = format!("ply\nformat {} 1.0\n{header}end_header\n", format.name()).into_bytes();
    for row in rows {
        for value in row {
            value.write(format, &mut out);
        }
        if format == Format::Ascii {
            out.pop();
            out.push(b'\n');
        }
    }
    out
}

fn parse(bytes: &[u8]) -> Scene {
    parse_ply(bytes, Path::new("test.ply")).unwrap_or_else(|error| panic!("unexpected error: {error}"))
}

fn parse_error(bytes: &[u8]) -> String {
    match parse_ply(bytes, Path::new("test.ply")) {
        Ok(scene) => panic!("expected an error, got {} triangles", scene.mesh.triangle_count()),
        Err(error) => error.to_string(),
    }
}

/// A face row: its corner count as `uchar`, then its corners as `int`.
fn face(corners: &[i32]) -> Vec<Value> {
    let mut row = vec![Value::U8(corners.len() as u8)];
    row.extend(corners.iter().map(|&c| Value::I32(c)));
    row
}

const XYZ: &str = "property float x\nproperty float y\nproperty float z\n";
const FACES: &str = "property list uchar int vertex_indices\n";

fn xyz(p: [f32; 3]) -> Vec<Value> {
    p.map(Value::F32).to_vec()
}

#[test]
fn ascii_and_both_binary_orders_read_the_same_mesh() {
    // Double positions, float normals between other properties, an element the loader skips
    // (with a list, which a binary body can only skip value by value) between vertices and
    // faces, and corner lists of uint behind a ushort-sized count: every path of the body reader.
    let header = "element vertex 4\nproperty double x\nproperty double y\nproperty double z\n\
                  property uchar red\nproperty float nx\nproperty float ny\nproperty float nz\n\
                  element edge 2\nproperty list uchar short loop\nproperty float weight\n\
                  element face 2\nproperty uchar flags\nproperty list ushort uint vertex_indices\n";
    let positions: [[f64; 3]; 4] = [[0.5, -1.25, 3.0], [1.0, 0.0, 1e-3], [-2.0, 4.5, 0.125], [7.0, 7.0, -7.0]];
    let normals = [[0.0, 0.0, 1.0], [0.6, 0.8, 0.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]];
    let mut rows: Vec<Vec<Value>> = (0..4)
        .map(|i| {
            let mut row: Vec<Value> = positions[i].map(Value::F64).to_vec();
            row.push(Value::U8(200));
            row.extend(normals[i].map(Value::F32));
            row
        })
        .collect();
    rows.push(vec![Value::U8(3), Value::I16(1), Value::I16(-2), Value::I16(3), Value::F32(0.5)]);
    rows.push(vec![Value::U8(0), Value::F32(1.5)]);
    let corners = |c: &[u32]| {
        let mut row = vec![Value::U8(7), Value::U8(0)];
        // A ushort count: two bytes, written as `I16` (ASCII writes the same digits).
        row[1] = Value::I16(c.len() as i16);
        row.extend(c.iter().map(|&i| Value::U32(i)));
        row
    };
    rows.push(corners(&[0, 1, 2]));
    rows.push(corners(&[0, 2, 3]));
    for format in FORMATS {
        let scene = parse(&ply(format, header, &rows));
        let mesh = &scene.mesh;
        let expected: Vec<Vec3> = positions.iter().map(|p| Vec3::from(p.map(|x| x as f32))).collect();
        assert_eq!(mesh.positions, expected, "{}", format.name());
        assert_eq!(mesh.normals, normals.map(Vec3::from).to_vec(), "{}", format.name());
        assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3]], "{}", format.name());
        assert_eq!(mesh.normal_indices, mesh.indices, "{}", format.name());
        assert!(mesh.texcoord_indices.is_empty());
        assert_eq!(mesh.material_ids, vec![0, 0]);
        assert_eq!(scene.materials.len(), 1);
        assert_eq!(scene.materials[0].name, MATERIAL_NAME);
        // What was not read is named, once each.
        let warnings = scene.warnings.join("\n");
        assert!(warnings.contains("vertex properties not read: \"red\""), "{warnings}");
        assert!(warnings.contains("face properties not read: \"flags\""), "{warnings}");
        assert!(warnings.contains("elements not read (lumiere reads vertex and face): \"edge\" (2)"), "{warnings}");
        assert_eq!(scene.warnings.len(), 3, "{warnings}");
    }
}

#[test]
fn faces_are_split_as_the_obj_loader_splits_them() {
    // A convex quad (a fan), a pentagon and an L-shaped hexagon whose fan would cover its notch
    // (ear-clipped), against the same faces in an OBJ file.
    let points: [[f32; 3]; 15] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [3.0, 0.0, 0.0],
        [4.0, 0.0, 0.0],
        [4.5, 1.0, 0.0],
        [3.5, 1.5, 0.0],
        [2.5, 1.0, 0.0],
        [6.0, 0.0, 0.0],
        [8.0, 0.0, 0.0],
        [8.0, 1.0, 0.0],
        [7.0, 1.0, 0.0],
        [7.0, 2.0, 0.0],
        [6.0, 2.0, 0.0],
    ];
    let faces: [&[i32]; 3] = [&[0, 1, 2, 3], &[4, 5, 6, 7, 8], &[11, 12, 13, 14, 9, 10]];
    let header = format!("element vertex 15\n{XYZ}element face 3\n{FACES}");
    let mut rows: Vec<Vec<Value>> = points.iter().map(|&p| xyz(p)).collect();
    rows.extend(faces.iter().map(|f| face(f)));
    let mut obj = String::new();
    for p in points {
        obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for f in faces {
        obj += "f";
        for corner in f {
            obj += &format!(" {}", corner + 1);
        }
        obj += "\n";
    }
    let no_mtl = |_: &str| Err(std::io::Error::other("no MTL"));
    let from_obj = parse_obj(obj.as_bytes(), Path::new("test.obj"), &no_mtl).unwrap();
    for format in FORMATS {
        let from_ply = parse(&ply(format, &header, &rows));
        assert_eq!(from_ply.mesh.indices, from_obj.mesh.indices, "{}", format.name());
        assert_eq!(from_ply.mesh.positions, from_obj.mesh.positions);
    }
    // The hexagon's fan from its first corner would lay a triangle over the notch.
    assert_ne!(from_obj.mesh.indices[5..], [[11, 12, 13], [11, 13, 14], [11, 14, 9], [11, 9, 10]]);
}

#[test]
fn the_shared_bunny_reads_as_its_obj_does() {
    let Some(path) = crate::common::shared_scene("bunny/stanford-bunny.obj") else { return };
    let obj = lumiere::scene::load::obj::load_obj(&path).unwrap();
    let header =
        format!("element vertex {}\n{XYZ}element face {}\n{FACES}", obj.mesh.positions.len(), obj.mesh.indices.len());
    let mut rows: Vec<Vec<Value>> = obj.mesh.positions.iter().map(|p| xyz(p.to_array())).collect();
    rows.extend(obj.mesh.indices.iter().map(|t| face(&t.map(|i| i as i32))));
    for format in FORMATS {
        let scene = parse(&ply(format, &header, &rows));
        assert_eq!(scene.mesh.positions, obj.mesh.positions, "{}", format.name());
        assert_eq!(scene.mesh.indices, obj.mesh.indices, "{}", format.name());
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    }
}

#[test]
fn ply_files_load_by_their_extension_gzipped_or_not() {
    let dir = TempDir::new("ply-extension");
    let header = format!("element vertex 3\n{XYZ}element face 1\n{FACES}");
    let rows = vec![xyz([0.0, 0.0, 0.0]), xyz([1.0, 0.0, 0.0]), xyz([0.0, 1.0, 0.0]), face(&[0, 1, 2])];
    let bytes = ply(Format::Little, &header, &rows);
    let mut gzipped = GzEncoder::new(Vec::new(), Compression::default());
    gzipped.write_all(&bytes).unwrap();
    for path in [dir.write("tri.PLY", &bytes), dir.write("tri.ply.gz", gzipped.finish().unwrap())] {
        let mut scene = load(&path).unwrap_or_else(|error| panic!("{error}"));
        assert_eq!(scene.mesh.indices, vec![[0, 1, 2]]);
        // The one material is the one `--emission default=...` names.
        scene.set_emission(MATERIAL_NAME, Vec3::ONE).unwrap();
    }
}

#[test]
fn what_the_body_holds_past_its_elements_is_named() {
    let header = format!("element vertex 3\n{XYZ}element face 1\n{FACES}");
    let rows = vec![xyz([0.0, 0.0, 0.0]), xyz([1.0, 0.0, 0.0]), xyz([0.0, 1.0, 0.0]), face(&[0, 1, 2])];
    for format in FORMATS {
        let mut bytes = ply(format, &header, &rows);
        assert!(parse(&bytes).warnings.is_empty(), "{}", format.name());
        bytes.extend_from_slice(b"\n\n 9 9\n");
        let warnings = parse(&bytes).warnings;
        let expected = if format == Format::Ascii { "test.ply:16: 4 bytes" } else { "test.ply: 7 bytes" };
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].starts_with(expected), "{}: {warnings:?}", format.name());
    }
}

/// Refusals of the header, each with its line.
#[test]
fn malformed_headers_are_refused_with_their_line() {
    let cases: [(&[u8], &str); 16] = [
        (b"", "test.ply:1: not a PLY file"),
        (b"solid cube\nfacet normal 0 0 1\n", "test.ply:1: not a PLY file"),
        (b"ply\nformat ascii 1.0\nelement vertex 0\n", "test.ply:4: the header has no end_header line"),
        (b"ply\nelement vertex 0\nend_header\n", "test.ply:3: the header ends without a format line"),
        (b"ply\nformat binary 1.0\nend_header\n", "test.ply:2: unknown format \"binary\""),
        (b"ply\nformat ascii 2.0\nend_header\n", "test.ply:2: PLY version \"2.0\" is not supported"),
        (b"ply\nformat ascii 1.0\nformat ascii 1.0\nend_header\n", "test.ply:3: a second format line"),
        (b"ply\nformat ascii 1.0\nproperty float x\nend_header\n", "test.ply:3: a property before any element"),
        (b"ply\nformat ascii 1.0\nelement face 0\nproperty list uchar vertex_indices\nend_header\n", "test.ply:4: a list property line is `property list COUNT_TYPE ITEM_TYPE NAME`"),
        (b"ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n", "test.ply:4: unknown property type \"half\""),
        (b"ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", "test.ply:3: element count \"-1\" is not a whole number"),
        (b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n", "test.ply:3: element vertex has no property z"),
        (b"ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n", "test.ply:3: faces, but no vertex element"),
        (b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar float vertex_indices\nend_header\n", "test.ply:7: face corners of type float"),
        (b"ply\nformat ascii 1.0\nelement vertex 0\nproperty list float int x\nend_header\n", "test.ply:4: list \"x\" has a count of type \"float\""),
        (b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float x\nend_header\n", "test.ply:5: a second property \"x\" in element \"vertex\""),
    ];
    for (bytes, expected) in cases {
        let error = parse_error(bytes);
        assert!(error.starts_with(expected), "{error:?} should start with {expected:?}");
        assert!(!error.contains('\n'), "{error:?}");
    }
}

/// Refusals of the body: each names the element, the instance and where (the line of an ASCII
/// body, the byte of a binary one).
#[test]
fn malformed_bodies_are_refused_where_they_go_wrong() {
    let header = format!("element vertex 3\n{XYZ}element face 1\n{FACES}");
    let body = |last_face: Vec<Value>| {
        let rows = vec![xyz([0.0, 0.0, 0.0]), xyz([1.0, 0.0, 0.0]), xyz([0.0, 1.0, 0.0]), last_face];
        FORMATS.map(|format| ply(format, &header, &rows))
    };
    // The face is line 13 of the ASCII file, at byte 161 + 36 of the binary ones (the
    // big-endian header is three bytes shorter), its first corner one byte later.
    let header_bytes = |format: Format| ply(format, &header, &[]).len();
    let cases = [
        (face(&[0, 1, 3]), "face 0: vertex index 3 out of range: the file defines 3 vertices", 1 + 4 * 2),
        (face(&[0, -1, 2]), "face 0: vertex index -1 out of range: the file defines 3 vertices", 1 + 4),
        (face(&[0, 1]), "face 0: 2 corner(s); a face needs at least 3", 1 + 4),
    ];
    for (row, message, last_value) in cases {
        for (format, bytes) in FORMATS.into_iter().zip(body(row)) {
            let error = parse_error(&bytes);
            let place = match format {
                Format::Ascii => "test.ply:13: ".to_string(),
                _ => format!("test.ply: byte {}: ", header_bytes(format) + 36 + last_value),
            };
            assert_eq!(error, format!("{place}{message}"), "{}", format.name());
        }
    }
    // A body cut short, in each format: the first vertex it cannot read is named.
    for format in FORMATS {
        let mut bytes = ply(format, &header, &[xyz([0.0, 0.0, 0.0]), xyz([1.0, 0.0, 0.0]), xyz([0.0, 1.0, 0.0])]);
        bytes.extend_from_slice(if format == Format::Ascii { b"3 0 1" } else { &[3, 0, 0] });
        let error = parse_error(&bytes);
        assert!(error.contains("face 0: the file ends before the values its header declares"), "{error}");
    }
    // ASCII: numbers that are not, and integers out of their type's range, by line.
    let text = |rows: &str| format!("ply\nformat ascii 1.0\n{header}end_header\n{rows}").into_bytes();
    let cases = [
        ("0 0 0\n1 O 0\n0 1 0\n3 0 1 2\n", "test.ply:11: vertex 1: malformed number \"O\""),
        (
            "0 0 0\n1 0 0\n0 1 nan\n3 0 1 2\n",
            "test.ply:12: vertex 2: position 0.0 1.0 NaN is not finite in single precision",
        ),
        (
            "0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n",
            "test.ply:11: vertex 1: position 1e39 0.0 0.0 is not finite in single precision",
        ),
        ("0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n", "test.ply:13: face 0: \"300\" is out of the range of its type, uchar"),
        ("0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", "test.ply:13: face 0: malformed integer \"1.5\""),
    ];
    for (rows, expected) in cases {
        assert_eq!(parse_error(&text(rows)), expected);
    }
}

#[test]
fn counts_the_body_cannot_hold_are_refused_before_anything_is_allocated() {
    // A few bytes that claim a trillion vertices, or four billion corners for one face.
    for format in FORMATS {
        let bomb = ply(format, &format!("element vertex 1000000000000\n{XYZ}"), &[xyz([0.0, 0.0, 0.0])]);
        let error = parse_error(&bomb);
        assert!(
            error.starts_with("test.ply:3: element \"vertex\" declares 1000000000000 of them, more than the"),
            "{error}"
        );
    }
    let header = format!("element vertex 3\n{XYZ}element face 1\nproperty list uint int vertex_indices\n");
    let rows =
        [xyz([0.0, 0.0, 0.0]), xyz([1.0, 0.0, 0.0]), xyz([0.0, 1.0, 0.0]), vec![Value::U32(u32::MAX), Value::I32(0)]];
    for format in [Format::Little, Format::Big] {
        let error = parse_error(&ply(format, &header, &rows));
        assert!(error.ends_with("face 0: the file ends before the values its header declares"), "{error}");
    }
    // Elements of no properties take no bytes: any count of them is read at once.
    let empty =
        ply(Format::Little, &format!("element nothing 18446744073709551615\nelement vertex 3\n{XYZ}"), &rows[..3]);
    let scene = parse(&empty);
    assert_eq!(scene.mesh.positions.len(), 3);
}

#[test]
fn a_mesh_too_big_for_the_memory_left_is_refused() {
    let faces = 20_000;
    let header = format!("element vertex 3\n{XYZ}element face {faces}\n{FACES}");
    let mut rows = vec![xyz([0.0, 0.0, 0.0]), xyz([1.0, 0.0, 0.0]), xyz([0.0, 1.0, 0.0])];
    rows.extend((0..faces).map(|_| face(&[0, 1, 2])));
    let bytes = ply(Format::Little, &header, &rows);
    let error = parse_ply_with_memory(&bytes, Path::new("big.ply"), 1 << 20).unwrap_err().to_string();
    assert!(error.starts_with("big.ply: ") && error.contains("mesh and BVH"), "{error}");
    let scene = parse_ply_with_memory(&bytes, Path::new("big.ply"), 1 << 30).unwrap();
    assert_eq!(scene.mesh.triangle_count(), faces);
}

#[test]
fn headers_of_many_names_load_quickly_and_are_warned_about_in_a_line() {
    // Each name is checked against those before it through a set: compared one by one, these
    // 200,000 properties and elements took minutes. Warnings list eight names and count the rest.
    const N: usize = 200_000;
    let mut header = String::from("element vertex 1\n");
    header += &(0..N).map(|i| format!("property uchar p{i}\n")).collect::<String>();
    header += XYZ;
    header += &(0..N).map(|i| format!("element e{i} 1\n")).collect::<String>();
    let mut row = vec![Value::U8(0); N];
    row.extend(xyz([0.0, 0.0, 0.0]));
    let start = std::time::Instant::now();
    let scene = parse(&ply(Format::Ascii, &header, &[row]));
    assert!(start.elapsed() < std::time::Duration::from_secs(10), "took {:?}", start.elapsed());
    assert_eq!(scene.mesh.positions.len(), 1);
    let expected = [
        format!(
            "test.ply:3: vertex properties not read: \"p0\", \"p1\", \"p2\", \"p3\", \"p4\", \"p5\", \"p6\", \"p7\" and {} more",
            N - 8
        ),
        format!(
            "test.ply: elements not read (lumiere reads vertex and face): \"e0\" (1), \"e1\" (1), \"e2\" (1), \"e3\" (1), \"e4\" (1), \"e5\" (1), \"e6\" (1), \"e7\" (1) and {} more",
            N - 8
        ),
    ];
    assert_eq!(scene.warnings, expected);
}

#[test]
fn every_type_is_read_by_both_its_names() {
    // Files name their types the old way (`uchar`) or the new (`uint8`, as Open3D and trimesh
    // write): each of the sixteen names, as positions and, for the integer types, as the face's
    // count and corners. A binary face of one-byte corners ends the file with no byte to spare.
    // Writes a small whole number as a value of the type.
    type Write = fn(u8) -> Value;
    let types: [(&str, &str, Write, bool); 8] = [
        ("char", "int8", Value::U8, true),
        ("uchar", "uint8", Value::U8, true),
        ("short", "int16", |v| Value::I16(v.into()), true),
        ("ushort", "uint16", |v| Value::I16(v.into()), true),
        ("int", "int32", |v| Value::I32(v.into()), true),
        ("uint", "uint32", |v| Value::U32(v.into()), true),
        ("float", "float32", |v| Value::F32(v.into()), false),
        ("double", "float64", |v| Value::F64(v.into()), false),
    ];
    for (old, new, value, integer) in types {
        for name in [old, new] {
            let (list, corner) = if integer { (name, value) } else { ("uchar", Value::U8 as Write) };
            let header = format!(
                "element vertex 3\nproperty {name} x\nproperty {name} y\nproperty {name} z\n\
                 element face 1\nproperty list {list} {list} vertex_indices\n"
            );
            let mut rows: Vec<Vec<Value>> =
                [[0, 0, 0], [5, 0, 0], [0, 7, 0]].iter().map(|p| p.map(value).to_vec()).collect();
            rows.push([3, 0, 1, 2].map(corner).to_vec());
            for format in FORMATS {
                let scene = parse(&ply(format, &header, &rows));
                let expected = vec![Vec3::ZERO, Vec3::new(5.0, 0.0, 0.0), Vec3::new(0.0, 7.0, 0.0)];
                assert_eq!(scene.mesh.positions, expected, "{name}, {}", format.name());
                assert_eq!(scene.mesh.indices, vec![[0, 1, 2]], "{name}, {}", format.name());
            }
        }
    }
}

#[test]
fn elements_not_read_are_skipped_wherever_they_stand() {
    // Edges between the vertices and the faces, with values of several characters (an ASCII
    // element is skipped value by value: its fewest bytes would stop mid-line), and an element
    // after the faces, which must not be read as faces.
    let header = format!(
        "element vertex 3\n{XYZ}element edge 2\nproperty int vertex1\nproperty int vertex2\nproperty float crease\n\
         element face 1\n{FACES}element material 1\nproperty float shininess\n"
    );
    let edge = |a, b| vec![Value::I32(a), Value::I32(b), Value::F32(0.25)];
    let rows = vec![
        xyz([0.0, 0.0, 0.0]),
        xyz([1.0, 0.0, 0.0]),
        xyz([0.0, 1.0, 0.0]),
        edge(0, 1),
        edge(1, 2),
        face(&[0, 1, 2]),
        vec![Value::F32(12.5)],
    ];
    for format in FORMATS {
        let scene = parse(&ply(format, &header, &rows));
        assert_eq!(scene.mesh.indices, vec![[0, 1, 2]], "{}", format.name());
        let expected = "test.ply: elements not read (lumiere reads vertex and face): \"edge\" (2), \"material\" (1)";
        assert_eq!(scene.warnings, [expected], "{}", format.name());
    }
}

#[test]
fn warnings_name_what_is_not_read_only_where_there_are_values() {
    // One unread property is named alone (no "and 0 more"); an element, or the properties of an
    // element, with no instances hold nothing that is lost, so they go unmentioned.
    let header = format!(
        "element vertex 3\n{XYZ}property uchar confidence\nelement face 0\n{FACES}property uchar flags\n\
         element camera 0\nproperty float focal\nelement material 1\nproperty uchar kind\n"
    );
    let vertex = |p| [xyz(p), vec![Value::U8(9)]].concat();
    let rows = vec![vertex([0.0, 0.0, 0.0]), vertex([1.0, 0.0, 0.0]), vertex([0.0, 1.0, 0.0]), vec![Value::U8(2)]];
    for format in FORMATS {
        let scene = parse(&ply(format, &header, &rows));
        assert_eq!(scene.mesh.positions.len(), 3);
        let expected = [
            "test.ply:3: vertex properties not read: \"confidence\"",
            "test.ply: elements not read (lumiere reads vertex and face): \"material\" (1)",
        ];
        assert_eq!(scene.warnings, expected, "{}", format.name());
    }
}

#[test]
fn a_body_as_short_as_its_header_allows_is_read_and_one_byte_shorter_refused() {
    // A point cloud of one-digit values: an ASCII file need not end its last line, a binary one
    // holds its values and nothing more.
    let header = format!("element vertex 3\n{XYZ}");
    let rows = [xyz([0.0, 0.0, 0.0]), xyz([1.0, 0.0, 0.0]), xyz([0.0, 1.0, 0.0])];
    for format in FORMATS {
        let mut bytes = ply(format, &header, &rows);
        if format == Format::Ascii {
            assert_eq!(bytes.pop(), Some(b'\n'));
        }
        assert_eq!(parse(&bytes).mesh.positions.len(), 3, "{}", format.name());
    }
    // A binary file cut after its vertices: the element it has no byte for is named by its line.
    let header = format!("element vertex 3\n{XYZ}element face 1\n{FACES}");
    for format in [Format::Little, Format::Big] {
        assert_eq!(
            parse_error(&ply(format, &header, &rows)),
            "test.ply:7: element \"face\" declares 1 of them, more than the 36 bytes after the header can hold"
        );
    }
}

#[test]
fn the_memory_check_counts_the_triangles_of_polygons() {
    // One face of a hundred corners is 98 triangles and their BVH, about 18 kB: past the 10 kB
    // given here, though a check of the one face alone would let it through.
    let n = 100;
    let header = format!("element vertex {n}\n{XYZ}element face 1\n{FACES}");
    let mut rows: Vec<Vec<Value>> = (0..n)
        .map(|k| {
            let angle = std::f32::consts::TAU * k as f32 / n as f32;
            xyz([angle.cos(), angle.sin(), 0.0])
        })
        .collect();
    rows.push(face(&(0..n).collect::<Vec<i32>>()));
    let bytes = ply(Format::Little, &header, &rows);
    let error = parse_ply_with_memory(&bytes, Path::new("big.ply"), 10_000).unwrap_err().to_string();
    assert!(error.starts_with("big.ply: needs about"), "{error}");
    assert!(error.contains("for its 98 triangles and 100 vertices (mesh and BVH)"), "{error}");
    let scene = parse_ply_with_memory(&bytes, Path::new("big.ply"), 1 << 20).unwrap();
    assert_eq!(scene.mesh.triangle_count(), 98);
}

#[test]
fn a_list_past_the_end_in_an_element_not_read_is_refused_where_it_starts() {
    // A binary body skips an unread list in one step: a count past the bytes left is a short
    // file, named at the list's first value, not a jump past the end.
    let header =
        format!("element vertex 3\n{XYZ}element face 1\n{FACES}element edge 1\nproperty list uchar int verts\n");
    let rows = [xyz([0.0, 0.0, 0.0]), xyz([1.0, 0.0, 0.0]), xyz([0.0, 1.0, 0.0]), face(&[0, 1, 2]), face(&[0; 200])];
    for format in [Format::Little, Format::Big] {
        let mut bytes = ply(format, &header, &rows);
        // The edge's count, then one of its two hundred corners.
        let at = bytes.len() - 200 * 4;
        bytes.truncate(at + 4);
        let expected =
            format!("test.ply: byte {at}: element \"edge\": the file ends before the values its header declares");
        assert_eq!(parse_error(&bytes), expected, "{}", format.name());
    }
}
