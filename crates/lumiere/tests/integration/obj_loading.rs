//! OBJ/MTL loading: statement forms, fan order, materials and warnings, errors with line numbers,
//! chunked parallel parsing against the single-chunk path, and the scenes shipped in `shared/`.

use crate::common::TempDir;
use flate2::Compression;
use flate2::write::GzEncoder;
use glam::{Vec2, Vec3};
use lumiere::materials::{CoverageTest, Cut, MaterialKind, NormalMap, ParameterMap, Relief};
use lumiere::math::UvTransform;
use lumiere::scene::load::obj::{ObjScene, load_obj, parse_obj, parse_obj_with_chunk_size};
use lumiere::scene::mesh::NO_INDEX;
use lumiere::textures::Channel;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

const NONE: [u32; 3] = [NO_INDEX; 3];

/// In-memory MTL files for `parse_obj`, looked up by the name `mtllib` gives.
fn mtl_files(files: &[(&str, &str)]) -> impl Fn(&str) -> io::Result<(Vec<u8>, PathBuf)> + use<> {
    let files: Vec<(String, String)> = files.iter().map(|&(n, t)| (n.to_string(), t.to_string())).collect();
    move |name| match files.iter().find(|(n, _)| n == name) {
        Some((_, text)) => Ok((text.clone().into_bytes(), Path::new("mem").join(name))),
        None => Err(io::Error::new(io::ErrorKind::NotFound, format!("no file {name}"))),
    }
}

fn parse(text: &str) -> ObjScene {
    parse_with(text, &[])
}

fn parse_with(text: &str, mtls: &[(&str, &str)]) -> ObjScene {
    match parse_obj(text.as_bytes(), Path::new("test.obj"), &mtl_files(mtls)) {
        Ok(scene) => scene,
        Err(error) => panic!("unexpected error: {error}"),
    }
}

/// The error message for `bytes`, which must fail to parse.
fn parse_error(bytes: &[u8]) -> String {
    match parse_obj(bytes, Path::new("test.obj"), &mtl_files(&[])) {
        Ok(scene) => panic!("expected an error, got {} triangles", scene.mesh.triangle_count()),
        Err(error) => error.to_string(),
    }
}

fn assert_error(bytes: &[u8], line: usize, needle: &str) {
    let message = parse_error(bytes);
    assert!(message.starts_with(&format!("test.obj:{line}: ")), "wrong line in {message:?}, expected {line}");
    assert!(message.contains(needle), "{message:?} does not mention {needle:?}");
}

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

/// Loads a scene of `../shared/scenes`; `None` (the test is skipped) when this clone has none.
fn load_shared(relative: &str) -> Option<ObjScene> {
    let path = crate::common::shared_scene(relative)?;
    let start = Instant::now();
    let scene = load_obj(&path).unwrap_or_else(|error| panic!("{error}"));
    println!("{}: {} triangles in {:.3} s", path.display(), scene.mesh.triangle_count(), start.elapsed().as_secs_f64());
    Some(scene)
}

/// Asserts that `scene` has exactly one warning, and that it says `needle`.
fn assert_only_warning(scene: &ObjScene, needle: &str) {
    assert_eq!(scene.warnings.len(), 1, "{:#?}", scene.warnings);
    assert!(scene.warnings[0].contains(needle), "{}", scene.warnings[0]);
}

fn material_of(scene: &ObjScene, triangle: usize) -> &lumiere::materials::Material {
    &scene.materials[scene.mesh.material_ids[triangle] as usize]
}

#[test]
fn negative_indices_are_relative_to_the_line() {
    let scene = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -4 -2 -1\n");
    assert_eq!(scene.mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(scene.mesh.positions[3], Vec3::splat(5.0));
}

#[test]
fn crlf_tabs_trailing_spaces_and_no_final_newline() {
    let scene = parse("v\t0 0 0 \r\nv 1\t0 0\r\n\r\n  v 0 1 0\t\r\n# comment\r\nf\t1 2  3 \r\nf 1 2 3");
    assert_eq!(scene.mesh.indices, vec![[0, 1, 2], [0, 1, 2]]);
    assert_eq!(scene.mesh.positions[1], Vec3::X);
}

/// Classic Mac OS line ends (a lone `\r`) are refused at line 1, whatever the first line holds
/// (a comment made the whole file one comment, an empty scene); in an MTL file they cost one
/// warning and its materials, not one warning per statement read as a file name.
#[test]
fn lone_carriage_returns_are_refused_by_name() {
    let refused = "lone carriage-return line ends (classic Mac OS) are not supported";
    assert_error(b"# exported\rv -1 0 -1\rv 1 0 -1\rv 1 0 1\rf 1 2 3\r", 1, refused);
    assert_error(b"mtllib base.mtl\rv 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r", 1, refused);
    // A CRLF file, with a blank CRLF line doubled, still loads.
    assert_eq!(parse("v 0 0 0\r\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n").mesh.triangle_count(), 1);
    let scene = parse_with(
        "mtllib mac.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        &[("mac.mtl", "newmtl red\rKd 1 0 0\r")],
    );
    let carriage: Vec<_> = scene.warnings.iter().filter(|w| w.contains(refused)).collect();
    assert_eq!(carriage.len(), 1, "{:#?}", scene.warnings);
    assert!(carriage[0].contains("mac.mtl:1:"), "{}", carriage[0]);
}

#[test]
fn polygons_split_as_fans_in_file_order() {
    let text = format!("{SQUARE}v 2 2 0\nf 1 2 3 4\nf 5 4 3 2 1\n");
    let scene = parse(&text);
    let expected = vec![[0, 1, 2], [0, 2, 3], [4, 3, 2], [4, 2, 1], [4, 1, 0]];
    assert_eq!(scene.mesh.indices, expected);
}

/// An L-shaped hexagon, counter-clockwise seen from +z, with its corners' texture coordinates
/// and normals numbered as their positions, so that a corner's three indices can be told apart
/// from another corner's.
const L_SHAPE: &str = "v 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\n\
                       vt 0 0\nvt 0 0\nvt 0 0\nvt 0 0\nvt 0 0\nvt 0 0\n\
                       vn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n";

/// The position of corner `c` of triangle `t`.
fn corner_of(scene: &ObjScene, t: usize, c: usize) -> Vec3 {
    scene.mesh.positions[scene.mesh.indices[t][c] as usize]
}

/// A concave face is ear-clipped, as tinyobjloader splits it, where its fan `(1,2,3), (1,3,4),
/// ...` laid a triangle over the L's notch (the fan's areas summed to 4 over an L of area 3). Each
/// corner keeps its own texture coordinate and normal, the winding is the face's, the count is
/// n - 2, and the faces after it keep their ids.
#[test]
fn a_concave_face_is_ear_clipped_and_keeps_its_winding_and_corners() {
    let text = format!("{L_SHAPE}f 1/1/1 2/2/2 3/3/3 4/4/4 5/5/5 6/6/6\nf 1 2 5\n");
    let scene = parse(&text);
    assert_eq!(scene.mesh.triangle_count(), 5);
    let mut area = 0.0;
    for t in 0..4 {
        let [a, b, c] = [0, 1, 2].map(|k| corner_of(&scene, t, k));
        let normal = (b - a).cross(c - a);
        assert!(normal.z > 0.0 && normal.x == 0.0 && normal.y == 0.0, "triangle {t} winds as the face: {normal}");
        area += normal.z / 2.0;
        let centroid = (a + b + c) / 3.0;
        assert!(centroid.x < 1.0 || centroid.y < 1.0, "triangle {t} lies in the notch: {centroid}");
        for list in [&scene.mesh.texcoord_indices, &scene.mesh.normal_indices] {
            assert_eq!(list[t], scene.mesh.indices[t], "triangle {t}'s corners keep their attributes");
        }
    }
    assert_eq!(area, 3.0);
    assert_eq!(scene.mesh.indices[4], [0, 1, 4], "the next face keeps its id");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // Split in chunks of any size, the file gives the same triangles.
    for chunk in [1, 20, 64] {
        let chunked =
            parse_obj_with_chunk_size(text.as_bytes(), Path::new("test.obj"), &mtl_files(&[]), chunk).unwrap();
        assert_eq!(chunked.mesh.indices, scene.mesh.indices, "chunks of {chunk} bytes");
        assert_eq!(chunked.mesh.texcoord_indices, scene.mesh.texcoord_indices, "chunks of {chunk} bytes");
    }
}

/// A dart (a quad with one corner turned in) whose fan's diagonal 0-2 runs outside it, its turned
/// corner at 1 or at 3, is split along 1-3; turned in at 0 or 2, the fan's diagonal is the inside
/// one and the fan stays. Either way the two triangles cover the dart's area and wind as it does.
#[test]
fn a_concave_quad_is_split_along_its_inside_diagonal() {
    // Counter-clockwise, turned in at (1.5, 0.5); written from each corner in turn.
    let dart =
        [Vec3::new(0.0, 0.0, 0.0), Vec3::new(4.0, -1.0, 0.0), Vec3::new(1.5, 0.5, 0.0), Vec3::new(4.0, 2.0, 0.0)];
    for (turned_in_at, start) in [(2, 0), (1, 1), (0, 2), (3, 3)] {
        let corners: Vec<Vec3> = (0..4).map(|k| dart[(start + k) % 4]).collect();
        let mut text: String = corners.iter().map(|c| format!("v {} {} {}\n", c.x, c.y, c.z)).collect();
        text += "f 1 2 3 4\n";
        let scene = parse(&text);
        let mut total = 0.0;
        for t in 0..2 {
            let [a, b, c] = [0, 1, 2].map(|k| corner_of(&scene, t, k));
            let twice = (b - a).cross(c - a).z;
            assert!(twice > 0.0, "turned in at {turned_in_at}: triangle {t} is turned over");
            total += twice / 2.0;
        }
        let shoelace: f32 =
            (0..4).map(|k| corners[k].truncate().perp_dot(corners[(k + 1) % 4].truncate())).sum::<f32>() / 2.0;
        assert!((total - shoelace).abs() < 1e-5, "turned in at {turned_in_at}: {total} where {shoelace}");
        let fan = vec![[0, 1, 2], [0, 2, 3]];
        assert_eq!(
            scene.mesh.indices == fan,
            turned_in_at % 2 == 0,
            "turned in at {turned_in_at}: {:?}",
            scene.mesh.indices
        );
    }
}

/// Ear clipping's work grows as the cube of a face's corners: a file of thousands of concave
/// faces of 64 corners (a comb, here the same one 20,000 times) must not take minutes. The file's
/// budget clips the first faces and leaves the rest as fans, with a warning.
#[test]
fn a_file_of_many_large_concave_faces_is_split_within_a_budget() {
    // A comb: the bottom edge, then 62 teeth corners from right to left, alternately high and low.
    let mut text = "v 0 0 0\nv 31 0 0\n".to_string();
    for k in 0..62 {
        text += &format!("v {} {} 0\n", 31.0 * (1.0 - k as f32 / 61.0), if k % 2 == 0 { 2 } else { 1 });
    }
    let face = format!("f {}\n", (1..=64).map(|k| k.to_string()).collect::<Vec<_>>().join(" "));
    text += &face.repeat(20_000);
    let start = Instant::now();
    let scene = parse(&text);
    assert!(start.elapsed().as_secs_f64() < 10.0, "{:?}", start.elapsed());
    assert_eq!(scene.mesh.triangle_count(), 20_000 * 62);
    let fan: Vec<[u32; 3]> = (1..63).map(|k| [0, k, k + 1]).collect();
    assert_ne!(scene.mesh.indices[..62], fan[..], "the first face is clipped");
    assert_eq!(scene.mesh.indices[62 * 19_999..], fan[..], "the last one is left a fan");
    assert_only_warning(&scene, "concave face(s) keep their fan of triangles");
}

/// Random star-shaped faces (corners at random radii about a centre, in order of angle), concave
/// most of the time: their ear clipping covers each exactly, its triangles summing to the face's
/// area (the shoelace formula) and none of them turned over.
#[test]
fn ear_clipping_covers_random_star_shaped_faces_exactly() {
    let mut rng = crate::common::TestRng(11);
    for case in 0..200 {
        let n = 4 + rng.below(61);
        let corners: Vec<Vec2> = (0..n)
            .map(|k| {
                let angle = (k as f32 + rng.range(0.1, 0.9)) * std::f32::consts::TAU / n as f32;
                rng.range(0.2, 1.0) * Vec2::new(angle.cos(), angle.sin())
            })
            .collect();
        let mut text: String = corners.iter().map(|c| format!("v {} {} 0\n", c.x, c.y)).collect();
        text += &format!("f {}\n", (1..=n).map(|k| k.to_string()).collect::<Vec<_>>().join(" "));
        let scene = parse(&text);
        let shoelace: f64 = (0..n).map(|k| f64::from(corners[k].perp_dot(corners[(k + 1) % n]))).sum::<f64>() / 2.0;
        let mut area = 0.0;
        for t in 0..n - 2 {
            let [a, b, c] = [0, 1, 2].map(|k| corner_of(&scene, t, k).truncate().as_dvec2());
            let twice = (b - a).perp_dot(c - a);
            assert!(twice >= -1e-9, "case {case}: triangle {t} is turned over ({twice})");
            area += twice / 2.0;
        }
        assert!((area - shoelace).abs() < 1e-5 * shoelace, "case {case}, {n} corners: {area} where {shoelace}");
    }
}

/// A star of 66 corners is concave, and past the 64 corners ear clipping is given (its work
/// grows as the cube of the corners): it keeps its fan, and one warning says so. A convex face
/// of as many corners keeps its fan without a word.
#[test]
fn a_concave_face_of_too_many_corners_keeps_its_fan_with_a_warning() {
    let polygon = |radius: &dyn Fn(usize) -> f32| {
        let mut text = String::new();
        for k in 0..66 {
            let angle = k as f32 * std::f32::consts::TAU / 66.0;
            text += &format!("v {} {} 0\n", radius(k) * angle.cos(), radius(k) * angle.sin());
        }
        text + "f " + &(1..=66).map(|k| k.to_string()).collect::<Vec<_>>().join(" ") + "\n"
    };
    let fan: Vec<[u32; 3]> = (1..65).map(|k| [0, k, k + 1]).collect();
    let star = parse(&polygon(&|k| if k % 2 == 0 { 1.0 } else { 0.5 }));
    assert_eq!(star.mesh.indices, fan);
    assert_only_warning(&star, "1 concave face(s) of more than 64 corners keep their fan");
    let disc = parse(&polygon(&|_| 1.0));
    assert_eq!((disc.mesh.indices, disc.warnings.len()), (fan, 0));
}

#[test]
fn corner_forms_and_missing_attributes() {
    let text = format!(
        "{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1/1/1 2/2/1 3/3/1\nf 1/1 3/3 4/2\nf 1 2 3\n"
    );
    let scene = parse(&text);
    assert_eq!(scene.mesh.normal_indices, vec![[0; 3], [0; 3], NONE, NONE]);
    assert_eq!(scene.mesh.texcoord_indices, vec![NONE, [0, 1, 2], [0, 2, 1], NONE]);
    assert_eq!(scene.mesh.texcoords[2], Vec2::ONE);
    assert_eq!(scene.mesh.normals, vec![Vec3::Z]);
}

#[test]
fn vertices_with_w_colours_and_short_texcoords() {
    let scene = parse("v 0 0 0 1\nv 1 0 0 0.5 0.5 0.5\nv 0 1 0\nvt 0.25\nf 1/1 2/1 3/1\n");
    assert_eq!(scene.mesh.positions[1], Vec3::X);
    assert_eq!(scene.mesh.texcoords, vec![Vec2::new(0.25, 0.0)]);
}

#[test]
fn attribute_lists_are_empty_without_attributes() {
    let scene = parse(&format!("{SQUARE}vn 0 0 1\nvt 0 0\nf 1 2 3 4\n"));
    assert_eq!(scene.mesh.triangle_count(), 2);
    assert!(scene.mesh.normal_indices.is_empty() && scene.mesh.texcoord_indices.is_empty());
}

#[test]
fn ignored_statements_and_empty_file() {
    let text = format!("o thing\ng a b\ns off\nmg 1\n{SQUARE}vp 0.5\ncstype bspline\nf 1 2 3 # the face\n# end\n\n");
    let scene = parse(&text);
    assert_eq!(scene.mesh.triangle_count(), 1);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let empty = parse("");
    assert_eq!(empty.mesh.triangle_count(), 0);
    assert!(empty.materials.is_empty() && empty.warnings.is_empty());
}

/// Elements lumiere does not render and keywords that are not OBJ get one warning per keyword,
/// with their count and first line, whatever the chunks; the scene's faces still load.
#[test]
fn skipped_statements_are_named_once_per_keyword() {
    let text = format!("{SQUARE}l 1 2\nfoo 1\nl 2 3\np 3\nf 1 2 3\nfoo 2\ncurv 0 1 1 2\n");
    let read = mtl_files(&[]);
    let name = Path::new("test.obj");
    let single = parse_obj_with_chunk_size(text.as_bytes(), name, &read, usize::MAX).expect("parses");
    assert_eq!(single.mesh.triangle_count(), 1);
    let expected = [
        "test.obj:5: \"l\" statements (polylines) are not rendered: 2 lines ignored, the first on this line",
        "test.obj:6: unknown statement \"foo\": 2 lines ignored, the first on this line",
        "test.obj:8: \"p\" statements (points) are not rendered: 1 line ignored, the first on this line",
        "test.obj:11: \"curv\" statements (free-form curves) are not rendered: 1 line ignored, the first on this line",
    ];
    assert_eq!(single.warnings, expected);
    for chunk in [1, 9] {
        let chunked = parse_obj_with_chunk_size(text.as_bytes(), name, &read, chunk).expect("parses");
        assert_eq!(chunked.warnings, expected, "chunk {chunk}");
    }
    // Twenty kinds before a keyword that comes back later: its count and first line do not
    // depend on where the chunks are cut.
    let kinds: String = (0..20).map(|k| format!("kind{k} x\n")).collect();
    let text = format!("{SQUARE}f 1 2 3\n{kinds}call a.obj\n{}call b.obj\ncall c.obj\n", "# filler\n".repeat(50));
    let single = parse_obj_with_chunk_size(text.as_bytes(), name, &read, usize::MAX).expect("parses");
    let call = "test.obj:26: \"call\" statements (calls to other files) are not rendered: 3 lines ignored, the first on this line";
    assert!(single.warnings.iter().any(|w| w == call), "{:?}", single.warnings);
    for chunk in [1, 40, 300] {
        let chunked = parse_obj_with_chunk_size(text.as_bytes(), name, &read, chunk).expect("parses");
        assert_eq!(chunked.warnings, single.warnings, "chunk {chunk}");
    }
    // A file of many junk keywords: a few warnings, every line counted.
    let junk: String = (0..100).map(|k| format!("junk{k} x\n")).collect();
    let scene = parse(&format!("{SQUARE}f 1 2 3\n{junk}"));
    assert!(scene.warnings.len() <= 12, "{:?}", scene.warnings);
    assert!(scene.warnings.iter().any(|w| w.contains("more like this") || w.contains("more with other")));
}

/// Binary data under an `.obj` name, or text with no face and no OBJ statement, is refused with
/// the line that gave it away, instead of loading as an empty scene.
#[test]
fn files_that_are_not_obj_are_refused() {
    assert_error(b"ply\nformat binary_little_endian 1.0\nend_header\n\x00\x00\x80?\n", 4, "NUL byte");
    assert_error(b"# a comment with \x00 in it\nv 0 0 0\n", 1, "not an OBJ text file");
    assert_error(b"\x1f\x8b\x08\x00\x00\x00", 1, "NUL byte");
    assert_error(b"hello world\nthis is prose\n", 1, "unknown statement \"hello\" and not one face");
    // A NUL anywhere, in a statement the parser keeps or skips, or in a comment after one.
    for (bytes, line) in [
        (&b"v 0 0 0\no foo\x00bar\n"[..], 2),
        (b"g \x00\x00\n", 1),
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 # \x00\n", 4),
        (b"usemtl a\x00b\n", 1),
        (b"mtllib a\x00b.mtl\n", 1),
    ] {
        assert_error(bytes, line, "NUL byte");
    }
    // Unknown statements beside faces are only warned about; elements without faces too.
    assert_eq!(parse(&format!("hello\n{SQUARE}f 1 2 3\n")).mesh.triangle_count(), 1);
    assert_eq!(parse(&format!("{SQUARE}l 1 2 3\n")).warnings.len(), 1);
}

#[test]
fn non_utf8_comments_and_names_are_tolerated() {
    let mut bytes = b"# cr\xe9\xe9 par un logiciel\n".to_vec();
    bytes.extend_from_slice(SQUARE.as_bytes());
    bytes.extend_from_slice(b"usemtl mat\xff\nf 1 2 3\n");
    let scene = parse_obj(&bytes, Path::new("test.obj"), &mtl_files(&[])).expect("lenient parse");
    // Not UTF-8: read as Latin-1, byte for character.
    assert_eq!(scene.materials[0].name, "mat\u{ff}");
}

#[test]
fn faces_before_usemtl_get_the_default_material_only_when_they_exist() {
    let mtl = "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n";
    let with_default = parse_with(&format!("mtllib m.mtl\n{SQUARE}f 1 2 3\nusemtl blue\nf 1 3 4\n"), &[("m.mtl", mtl)]);
    let names: Vec<&str> = with_default.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["red", "blue", "default"]);
    assert_eq!(with_default.mesh.material_ids, vec![2, 1]);
    assert_eq!(with_default.materials[2], lumiere::materials::Material::default_grey("default"));
    assert!(with_default.warnings.is_empty(), "{:?}", with_default.warnings);

    let without = parse_with(&format!("mtllib m.mtl\n{SQUARE}usemtl red\nf 1 2 3\n"), &[("m.mtl", mtl)]);
    assert_eq!(without.materials.len(), 2);
    assert_eq!(without.mesh.material_ids, vec![0]);
}

#[test]
fn usemtl_of_an_undefined_name_gives_grey_and_one_warning() {
    let scene = parse(&format!("{SQUARE}usemtl ghost\nf 1 2 3\nusemtl other\nf 1 2 3\nusemtl ghost\nf 1 3 4\n"));
    assert_eq!(scene.mesh.material_ids, vec![0, 1, 0]);
    assert_eq!(scene.materials[0].name, "ghost");
    assert_eq!(scene.materials[0].kd, Vec3::splat(0.8));
    assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
    assert!(scene.warnings[0].starts_with("test.obj:5:") && scene.warnings[0].contains("ghost"));
}

#[test]
fn missing_mtl_warns_and_uses_grey() {
    let dir = TempDir::new("missing-mtl");
    let obj = dir.write("scene.obj", format!("mtllib nowhere.mtl\n{SQUARE}usemtl red\nf 1 2 3\n").as_bytes());
    let scene = load_obj(&obj).expect("load");
    assert_eq!(scene.materials.len(), 1);
    assert_eq!(scene.materials[0], lumiere::materials::Material::default_grey("red"));
    assert!(
        scene.warnings.iter().any(|w| w.contains("nowhere.mtl") && w.contains("scene.obj:1:")),
        "{:?}",
        scene.warnings
    );
}

/// A colour outside [0, 1] would reflect more light than arrives, or take some away: the scene
/// keeps it clamped, with one warning naming the MTL's line and the material; colours in range are
/// kept as given.
#[test]
fn colours_outside_zero_to_one_are_clamped_and_named() {
    let dir = TempDir::new("kd-range");
    dir.write("m.mtl", "newmtl hot\nKd -1 0.5 2\nnewmtl fine\nKd 0 0.25 1\n");
    let obj = dir.write("t.obj", format!("mtllib m.mtl\n{SQUARE}usemtl hot\nf 1 2 3\nusemtl fine\nf 1 3 4\n"));
    let scene = lumiere::scene::Scene::load(&obj).expect("load");
    let kd = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap().kd;
    assert_eq!(kd("hot"), Vec3::new(0.0, 0.5, 1.0));
    assert_eq!(kd("fine"), Vec3::new(0.0, 0.25, 1.0));
    let named: Vec<&String> = scene.warnings.iter().filter(|w| w.contains("clamped to [0, 1]")).collect();
    assert_eq!(named.len(), 1, "{:?}", scene.warnings);
    assert!(named[0].ends_with("m.mtl:2: material \"hot\": colour -1 0.5 2 clamped to [0, 1] (a surface reflects at most the light it receives)"), "{}", named[0]);
}

#[test]
fn broken_mtl_lines_warn_and_the_rest_is_kept() {
    let mtl = "Kd 1 1 1\nnewmtl a\nKd 0.5 zero 0.5\nKs 0.1\nNs 12 13\nillum x\nnewmtl b\nKe inf 0 0\nKd 0 1 0\n";
    let scene = parse_with(&format!("mtllib bad.mtl\n{SQUARE}usemtl b\nf 1 2 3\n"), &[("bad.mtl", mtl)]);
    let lines: Vec<&str> = scene.warnings.iter().map(|w| w.split(": ").next().unwrap_or("")).collect();
    assert_eq!(
        lines,
        ["mem/bad.mtl:1", "mem/bad.mtl:3", "mem/bad.mtl:5", "mem/bad.mtl:6", "mem/bad.mtl:8"],
        "{:?}",
        scene.warnings
    );
    assert!(scene.warnings[1].contains("\"zero\""));
    assert_eq!(scene.materials[0].ks, Vec3::splat(0.1));
    assert_eq!(scene.materials[0].kd, Vec3::splat(0.8));
    assert_eq!(material_of(&scene, 0).kd, Vec3::Y);
    assert_eq!(material_of(&scene, 0).ke, Vec3::ZERO);
}

/// Emitted radiance cannot be negative (light is not taken away, and a negative weight would
/// upset the choice of lights in proportion to their power): a `Ke` with a negative component is
/// refused with a warning that names it, while zero components, and the black `Ke` exporters write
/// on every surface that is no light, are read without a word.
#[test]
fn a_negative_emission_is_refused_and_zero_components_are_read() {
    let mtl = "newmtl dark\nKe 0 0 0\nnewmtl red\nKe 4 0 0\nnewmtl sink\nKe 1 -0.5 1\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}f 1 2 3\n"), &[("m.mtl", mtl)]);
    // The face comes before any `usemtl`: the fourth material is the default one.
    let [dark, red, sink, _] = &scene.materials[..] else { panic!("{:?}", scene.materials) };
    assert_eq!((dark.ke, red.ke, sink.ke), (Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0), Vec3::ZERO));
    assert_eq!(scene.warnings, ["mem/m.mtl:6: Ke must not be negative, found 1 -0.5 1; line ignored"]);
}

#[test]
fn mtl_statements_and_texture_paths() {
    let dir = TempDir::new("mtl-statements");
    std::fs::create_dir_all(dir.0.join("materials")).expect("mkdir");
    let mtl = "newmtl glass  # comment\n  Kd 0.1 0.2 0.3\n\tKs 0.5\nKe 1 2 3\nNs 50\nNi 1.5\nTr 0.25\nillum 7\n\
               map_Kd -bm 1 -o 0 0 0 tex\\wood.png\ndisp height.png\nKa 1 1 1\nnewmtl ghostly\nd -halo 0.5\n";
    dir.write("materials/glass.mtl", mtl.as_bytes());
    let obj = dir.write("scene.obj", format!("mtllib materials/glass.mtl\n{SQUARE}usemtl glass\nf 1 2 3\n").as_bytes());
    let scene = load_obj(&obj).expect("load");
    // The displacement map and the texture's options are not rendered: one warning names them; the
    // ambient `Ka` passes silently. "ghostly"'s `d 0.5` without `Ni` is not glass: partial coverage.
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0]
            .contains("material \"glass\" uses statements lumiere does not render: \"map_Kd -bm\", \"disp\""),
        "{:?}",
        scene.warnings
    );
    assert_eq!(scene.materials[1].map_d_test, CoverageTest { alpha_only: false, scale: 0.5, cut: Cut::Hashed });
    let glass = &scene.materials[0];
    assert_eq!(glass.name, "glass");
    assert_eq!((glass.kd, glass.ks, glass.ke), (Vec3::new(0.1, 0.2, 0.3), Vec3::splat(0.5), Vec3::new(1.0, 2.0, 3.0)));
    assert_eq!((glass.ns, glass.ni, glass.dissolve, glass.illum), (50.0, 1.5, 0.75, 7));
    assert_eq!(glass.map_kd.as_deref(), Some(dir.0.join("materials/tex/wood.png").as_path()));
    assert!(scene.materials[1].map_kd.is_none());
    assert_eq!(scene.materials[1].dissolve, 0.5);
}

/// Texture options take the values the MTL specification gives them, so the file is the rest of
/// the line, spaces included; `-s` and `-o` place the texture, options that ask for what lumiere
/// does anyway pass silently, the others are named once each.
#[test]
fn texture_options_and_file_names_with_spaces() {
    let mtl = "newmtl tiles\nmap_Kd -s 4 2 1 -o 0.5 0.25 -clamp OFF -blendu on -cc off -imfchan r my wood tiles.png\n\
               newmtl one\nmap_Kd -s 3 -o -0.5 tile.jpg # the tile\n\
               newmtl odd\nmap_d -foo 2 3 -mm 0 1 cut out.png\nmap_d -bm 2 -mm 0 1 cut out.png\n\
               newmtl plain\nmap_Kd -dash.png\n\
               newmtl broken\nmap_Kd -s\nmap_d -mm 1 x.png\nmap_Kd -s 1e39 1 a.png\nmap_Kd -o nan b.png\n";
    let scene = parse_with(&format!("mtllib t.mtl\n{SQUARE}usemtl tiles\nf 1 2 3\n"), &[("t.mtl", mtl)]);
    let [tiles, one, odd, plain, broken] = &scene.materials[..] else { panic!("{:?}", scene.materials) };
    assert_eq!(tiles.map_kd.as_deref(), Some(Path::new("mem/my wood tiles.png")));
    assert_eq!(tiles.map_kd_transform, UvTransform { scale: Vec2::new(4.0, 2.0), offset: Vec2::new(0.5, 0.25) });
    assert_eq!(one.map_kd.as_deref(), Some(Path::new("mem/tile.jpg")));
    assert_eq!(one.map_kd_transform, UvTransform { scale: Vec2::new(3.0, 1.0), offset: Vec2::new(-0.5, 0.0) });
    assert_eq!(odd.map_d.as_deref(), Some(Path::new("mem/cut out.png")));
    assert!(odd.map_d_transform.is_identity() && plain.map_kd_transform.is_identity());
    // A last token is the file, even one that looks like an option.
    assert_eq!(plain.map_kd.as_deref(), Some(Path::new("mem/-dash.png")));
    assert!(broken.map_kd.is_none() && broken.map_d.is_none());
    let expected = [
        "mem/t.mtl:11: map_Kd \"-s\": expected 1 value(s), found 0; line ignored",
        "mem/t.mtl:12: map_d \"-mm\": expected 2 value(s), found 1; line ignored",
        "mem/t.mtl:13: map_Kd \"-s\": number \"1e39\" is not finite; line ignored",
        "mem/t.mtl:14: map_Kd \"-o\": number \"nan\" is not finite; line ignored",
        "mem/t.mtl: material \"tiles\" uses statements lumiere does not render: \"map_Kd -imfchan\" (see docs/MATERIALS.md)",
        "mem/t.mtl: material \"odd\" uses statements lumiere does not render: \"map_d -foo\", \"map_d -mm\", \"map_d -bm\" (see docs/MATERIALS.md)",
    ];
    assert_eq!(scene.warnings, expected);
}

/// `map_Pm` and `map_Pr` (the PBR extension's maps, as tinyobjloader reads them) paint a
/// material's metallic weight and roughness: the file with its placement, the channel
/// `-imfchan` chooses (`r`, `g`, `b` or `l`, the luminance, by default), replacing the constant;
/// a channel lumiere does not read is named, and the luminance read.
#[test]
fn metallic_and_roughness_maps_read_their_channel_and_placement() {
    let mtl = "newmtl orm\nPm 0\nPr 0.5\nmap_Pm -imfchan B orm.png\nmap_Pr -s 2 2 -imfchan g orm.png\n\
               newmtl grey\nmap_Pr rough ness.png\n\
               newmtl matte\nKd 1 1 1\nmap_Pm -imfchan m metal.png\n";
    let scene = parse_with(&format!("mtllib t.mtl\n{SQUARE}usemtl orm\nf 1 2 3\n"), &[("t.mtl", mtl)]);
    let [orm, grey, matte] = &scene.materials[..] else { panic!("{:?}", scene.materials) };
    let map = |file: &str, scale: f32, channel| ParameterMap {
        path: PathBuf::from(format!("mem/{file}")),
        transform: UvTransform { scale: Vec2::splat(scale), offset: Vec2::ZERO },
        channel,
        scale: 1.0,
    };
    assert_eq!(orm.map_pm, Some(map("orm.png", 1.0, Channel::Blue)));
    assert_eq!(orm.map_pr, Some(map("orm.png", 2.0, Channel::Green)));
    assert_eq!(
        (grey.map_pm.as_ref(), grey.map_pr.as_ref()),
        (None, Some(&map("rough ness.png", 1.0, Channel::Luminance)))
    );
    assert_eq!(matte.map_pm, Some(map("metal.png", 1.0, Channel::Luminance)));
    // A map alone makes the material PBR: a plastic where the map does not paint it metal.
    assert_eq!(grey.kind(), MaterialKind::Plastic { ks: Vec3::splat(0.04), alpha: 1.0 });
    assert_eq!(matte.kind(), MaterialKind::Plastic { ks: Vec3::splat(0.04), alpha: 1.0 });
    assert_eq!(
        scene.warnings,
        [
            "mem/t.mtl: material \"matte\" uses statements lumiere does not render: \"map_Pm -imfchan\" (see docs/MATERIALS.md)"
        ]
    );
}

/// `norm` is a normal map and `bump`, `map_Bump` and `map_bump` height maps (luminance, or the
/// channel `-imfchan` chooses), each as strong as `-bm` says (1 without it) and placed by `-s` and
/// `-o`; `norm` wins over a bump map before or after it, naming the bump map it leaves. `-bm` on
/// another map is still named as not honoured, and `disp` too.
#[test]
fn normal_and_bump_maps_read_their_strength_channel_and_placement() {
    let mtl = "newmtl bumpy\nmap_Bump -bm 0.25 -s 2 2 bricks bump.png\n\
               newmtl short\nbump -imfchan r h.png\n\
               newmtl lower\nmap_bump h.png\n\
               newmtl normals\nnorm -bm 0.5 n.png\n\
               newmtl both\nbump h.png\nnorm n.png\n\
               newmtl both again\nnorm n.png\nmap_Bump h.png\n\
               newmtl other\nmap_Kd -bm 2 k.png\ndisp d.png\n";
    let scene = parse_with(&format!("mtllib t.mtl\n{SQUARE}usemtl bumpy\nf 1 2 3\n"), &[("t.mtl", mtl)]);
    let [bumpy, short, lower, normals, both, both_again, other] = &scene.materials[..] else {
        panic!("{:?}", scene.materials)
    };
    let map = |file: &str, scale: f32, tiles: f32, relief| NormalMap {
        path: PathBuf::from(format!("mem/{file}")),
        transform: UvTransform { scale: Vec2::splat(tiles), offset: Vec2::ZERO },
        scale,
        relief,
    };
    let heights = |channel| Relief::Heights { channel };
    assert_eq!(bumpy.normal_map, Some(map("bricks bump.png", 0.25, 2.0, heights(Channel::Luminance))));
    assert_eq!(short.normal_map, Some(map("h.png", 1.0, 1.0, heights(Channel::Red))));
    assert_eq!(lower.normal_map, Some(map("h.png", 1.0, 1.0, heights(Channel::Luminance))));
    assert_eq!(normals.normal_map, Some(map("n.png", 0.5, 1.0, Relief::Directions)));
    assert_eq!(both.normal_map, Some(map("n.png", 1.0, 1.0, Relief::Directions)));
    assert_eq!(both_again.normal_map, both.normal_map);
    assert_eq!(other.normal_map, None);
    let unrendered = |material: &str, what: &str| {
        format!(
            "mem/t.mtl: material \"{material}\" uses statements lumiere does not render: {what} (see docs/MATERIALS.md)"
        )
    };
    assert_eq!(
        scene.warnings,
        [
            unrendered("both", "\"bump\" (norm is used)"),
            unrendered("both again", "\"map_Bump\" (norm is used)"),
            unrendered("other", "\"map_Kd -bm\", \"disp\""),
        ]
    );
}

/// MTL names keep their bytes: a Latin-1 name stays apart from its neighbour (each byte read as
/// a Latin-1 character) and matches its UTF-8 spelling, a texture's file name is the bytes on disk, and a byte-order mark
/// does not hide the first `newmtl`; a binary MTL costs one warning, not one per line.
#[test]
fn mtl_names_keep_their_bytes_and_binary_files_one_warning() {
    let mtl: &[u8] = b"\xEF\xBB\xBFnewmtl caf\xe9\r\nKd 1 0 0\r\nmap_Kd t\xe9x.png\r\nnewmtl caf\xe8\r\nKd 0 0 1\r\n";
    let mut obj = format!("mtllib m.mtl\n{SQUARE}").into_bytes();
    obj.extend_from_slice(b"usemtl caf\xe9\nf 1 2 3\nusemtl caf\xe8\nf 1 3 4\n");
    let read = |name: &str| -> io::Result<(Vec<u8>, PathBuf)> {
        assert_eq!(name, "m.mtl");
        Ok((mtl.to_vec(), PathBuf::from("mem/m.mtl")))
    };
    let scene = parse_obj(&obj, Path::new("test.obj"), &read).expect("parses");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["caf\u{e9}", "caf\u{e8}"]);
    assert_eq!((material_of(&scene, 0).kd, material_of(&scene, 1).kd), (Vec3::X, Vec3::Z));
    // Names are compared as text: a `usemtl` spelt in UTF-8 finds the material its MTL spells in
    // Latin-1 (one of the files saved again by another editor), as a reader of the two would.
    let mut utf8 = format!("mtllib m.mtl\n{SQUARE}").into_bytes();
    utf8.extend_from_slice("usemtl caf\u{e9}\nf 1 2 3\n".as_bytes());
    let scene = parse_obj(&utf8, Path::new("test.obj"), &read).expect("parses");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(material_of(&scene, 0).kd, Vec3::X);
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let file = scene.materials[0].map_kd.as_deref().expect("a texture");
        assert_eq!(file.as_os_str().as_bytes(), b"mem/t\xe9x.png");
    }
    let binary = |_: &str| -> io::Result<(Vec<u8>, PathBuf)> {
        Ok((b"newmtl a\nKd 1 0 0\n\x00\x01\x02\nmore\nlines\n".to_vec(), PathBuf::from("mem/b.mtl")))
    };
    let scene =
        parse_obj(format!("mtllib b.mtl\n{SQUARE}usemtl a\nf 1 2 3\n").as_bytes(), Path::new("test.obj"), &binary)
            .expect("parses");
    assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
    assert_eq!(
        scene.warnings[0],
        "mem/b.mtl:3: a NUL byte: binary data, not an MTL text file; its materials are not read"
    );
    assert!(scene.warnings[1].contains("\"a\""), "{:?}", scene.warnings);
}

#[test]
fn values_without_effect_are_named_in_the_material_warning() {
    let mtl = "newmtl tinted\nKd 0.5 0.5 0.5\nTf 1 0 0\n\
               newmtl veil\nd 0.5\n\
               newmtl matte\nillum 10\n\
               newmtl scaled\nmap_Kd -s 2 2 1 -clamp on wood.png\n\
               newmtl fine\nillum 7\nTf 1 0 0\nd 0.5\nmap_d -clamp off leaf.png\n\
               newmtl leaf\nd 0.5\nmap_d leaf.png\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}usemtl fine\nf 1 2 3\n"), &[("m.mtl", mtl)]);
    let expected =
        [("tinted", "\"Tf\" (only glass filters light)"), ("matte", "\"illum 10\""), ("scaled", "\"map_Kd -clamp\"")];
    assert_eq!(scene.warnings.len(), expected.len(), "{:#?}", scene.warnings);
    for ((name, what), warning) in expected.iter().zip(&scene.warnings) {
        assert!(
            warning.contains(&format!("material \"{name}\" uses statements lumiere does not render: {what}")),
            "{warning}"
        );
    }
}

/// 3ds Max names its materials `Material #1`, `Material #2`, ...: a word that starts with `#`
/// and goes on is part of a name (`newmtl`, `usemtl`, a texture's file), as Blender and
/// tinyobjloader read it; a `#` standing alone starts a comment. Cut at the `#`, the two
/// materials were one, `Material`, and `usemtl #1` failed the load.
#[test]
fn a_hash_that_starts_a_word_of_a_name_is_part_of_it() {
    let mtl = "newmtl Material #1\nKd 0 0 1\nnewmtl Material #2 # the yellow one\nKd 1 1 0\n\
               newmtl #1\nKd 1 0 0\nmap_Kd wood #2.png\n";
    let obj =
        format!("mtllib m.mtl\n{SQUARE}usemtl Material #1\nf 1 2 3\nusemtl Material #2\nf 1 3 4\nusemtl #1\nf 2 3 4\n");
    let scene = parse_with(&obj, &[("m.mtl", mtl)]);
    assert!(scene.warnings.is_empty(), "{:#?}", scene.warnings);
    let names: Vec<&str> = (0..3).map(|t| material_of(&scene, t).name.as_str()).collect();
    assert_eq!(names, ["Material #1", "Material #2", "#1"]);
    assert_eq!([0, 1, 2].map(|t| material_of(&scene, t).kd), [Vec3::Z, Vec3::new(1.0, 1.0, 0.0), Vec3::X]);
    assert_eq!(material_of(&scene, 2).map_kd.as_deref(), Some(Path::new("mem/wood #2.png")));
}

/// Numbers as exporters write them, which tinyobjloader and Blender read: exponents (`1e-3`,
/// `2.5E+1`), no digit before or after the point (`-.5`, `1.`, `.0`), an explicit plus sign, on
/// coordinates as on face indices (`f +1/+1/+1 ...`) and MTL values.
#[test]
fn numbers_in_the_forms_exporters_write() {
    let obj = "mtllib m.mtl\nv 1e-3 -.5 +2\nv 1. 2.5E+1 -0\nv .25 -1.5e-2 +.5\nvt 1.e-1 +0.5\nvn -0. 1E0 .0\n\
               usemtl a\nf +1/+1/+1 +2/1/1 3/1/1\nf -3 +2 -1\n";
    let scene = parse_with(obj, &[("m.mtl", "newmtl a\nKd .5 1. 25e-2\nNi +1.5\n")]);
    assert!(scene.warnings.is_empty(), "{:#?}", scene.warnings);
    let positions = [Vec3::new(0.001, -0.5, 2.0), Vec3::new(1.0, 25.0, 0.0), Vec3::new(0.25, -0.015, 0.5)];
    assert_eq!(scene.mesh.positions, positions);
    assert_eq!(scene.mesh.texcoords, [Vec2::new(0.1, 0.5)]);
    assert_eq!(scene.mesh.normals, [Vec3::Y]);
    assert_eq!(scene.mesh.indices, [[0, 1, 2]; 2]);
    assert_eq!(scene.mesh.texcoord_indices, [[0; 3], NONE]);
    assert_eq!(scene.mesh.normal_indices, [[0; 3], NONE]);
    assert_eq!((material_of(&scene, 0).kd, material_of(&scene, 0).ni), (Vec3::new(0.5, 1.0, 0.25), 1.5));
}

/// A statement lumiere does not render, met before the first `newmtl`, belongs to no material: it
/// costs the warning any statement there does, and the materials after it are read.
#[test]
fn an_unrendered_statement_before_the_first_newmtl_is_one_warning() {
    let mtl = "disp heights.png\nnewmtl a\nKd 0 1 0\ndisp heights.png\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}usemtl a\nf 1 2 3\n"), &[("m.mtl", mtl)]);
    let expected = [
        "mem/m.mtl:1: statement before the first newmtl; line ignored",
        "mem/m.mtl: material \"a\" uses statements lumiere does not render: \"disp\" (see docs/MATERIALS.md)",
    ];
    assert_eq!(scene.warnings, expected);
    assert_eq!(material_of(&scene, 0).kd, Vec3::Y);
}

/// `illum 9` is the specification's glass without ray-traced reflections, rendered as `illum 7`
/// is (docs/MATERIALS.md): a glass, with its filter, and no warning; only a model past 9 is named.
#[test]
fn illumination_model_nine_is_a_glass_and_ten_is_named() {
    let mtl = "newmtl nine\nNi 1.33\nTf 1 0.5 0.5\nillum 9\nnewmtl ten\nillum 10\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}usemtl nine\nf 1 2 3\n"), &[("m.mtl", mtl)]);
    let expected =
        "mem/m.mtl: material \"ten\" uses statements lumiere does not render: \"illum 10\" (see docs/MATERIALS.md)";
    assert_eq!(scene.warnings, [expected]);
    let glass = lumiere::materials::MaterialKind::Dielectric { eta: 1.33, tf: Vec3::new(1.0, 0.5, 0.5) };
    assert_eq!(material_of(&scene, 0).kind(), glass);
}

/// A lone `-` is no texture option (an option is a `-` and a name): it is part of the file name.
#[test]
fn a_lone_dash_in_a_texture_statement_is_part_of_the_file_name() {
    let mtl = "newmtl a\nmap_Kd - scan.png\nnewmtl b\nmap_d -clamp off - mask.png\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}usemtl a\nf 1 2 3\n"), &[("m.mtl", mtl)]);
    assert!(scene.warnings.is_empty(), "{:#?}", scene.warnings);
    assert_eq!(scene.materials[0].map_kd.as_deref(), Some(Path::new("mem/- scan.png")));
    assert_eq!(scene.materials[1].map_d.as_deref(), Some(Path::new("mem/- mask.png")));
}

/// `d` wins over `Tr` whichever comes first, as tinyobjloader reads them (3ds Max writes both);
/// `Tr` alone is `1 - d`, and the warning about its coverage names `Tr`, what the file wrote.
/// `d 1` then `Tr 1` made an opaque material glass.
#[test]
fn d_wins_over_tr_in_either_order() {
    let mtl = "newmtl d_first\nNi 1.5\nd 1\nTr 1\nnewmtl tr_first\nNi 1.5\nTr 1\nd 1\n\
               newmtl tr_only\nTr 0.25\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}f 1 2 3\n"), &[("m.mtl", mtl)]);
    // The faces come before any `usemtl`: the fourth material is the default one.
    let [d_first, tr_first, tr_only, _] = &scene.materials[..] else { panic!("{:?}", scene.materials) };
    assert_eq!((d_first.dissolve, tr_first.dissolve, tr_only.dissolve), (1.0, 1.0, 0.75));
    for opaque in [d_first, tr_first] {
        assert!(!matches!(opaque.kind(), lumiere::materials::MaterialKind::Dielectric { .. }), "{opaque:?}");
    }
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    // `Tr 0.25` alone covers three quarters of the surface.
    assert_eq!(tr_only.map_d_test, CoverageTest { alpha_only: false, scale: 0.75, cut: Cut::Hashed });
}

/// `d` below 1 (or `Tr` above 0) on a surface that is neither glass nor cut out by `map_d` is
/// partial coverage, as Blender reads it: the share `d` of the surface is there, hashed, and rays
/// pass through the rest. Glass and `map_d` cutouts keep their own readings, a light stays whole
/// (named in the material's warning), and a coverage of 0 is named: nothing of it is seen.
#[test]
fn d_below_one_is_partial_coverage_where_the_surface_is_not_glass() {
    let dir = TempDir::new("mtl-partial-coverage");
    let mtl = "newmtl veil\nd 0.3\nnewmtl glass\nd 0.3\nNi 1.5\nnewmtl leaf\nd 0.3\nmap_d leaf.png\n\
               newmtl lamp\nKe 1 1 1\nd 0.3\nnewmtl gone\nTr 1\nnewmtl solid\nd 1\n";
    dir.write("m.mtl", mtl);
    let quads: String = (0..6)
        .map(|k| {
            let x = 2.0 * k as f32;
            let name = ["veil", "glass", "leaf", "lamp", "gone", "solid"][k];
            let first = 4 * k + 1;
            format!(
                "v {x} 0 0\nv {} 0 0\nv {} 1 0\nv {x} 1 0\nusemtl {name}\nf {first}/1 {}/1 {}/1\nf {first}/1 {}/1 {}/1\n",
                x + 1.0,
                x + 1.0,
                first + 1,
                first + 2,
                first + 2,
                first + 3
            )
        })
        .collect();
    let obj = dir.write("s.obj", format!("mtllib m.mtl\nvt 0.5 0.5\n{quads}"));
    let scene = lumiere::scene::Scene::load(&obj).unwrap();
    let hashed = |scale| CoverageTest { alpha_only: false, scale, cut: Cut::Hashed };
    let tests: Vec<CoverageTest> = scene.materials.iter().map(|m| m.map_d_test).collect();
    let mtl_rule = CoverageTest::MTL;
    assert_eq!(tests, [hashed(0.3), mtl_rule, mtl_rule, mtl_rule, hashed(0.0), mtl_rule]);
    let file = dir.path("m.mtl").display().to_string();
    assert_eq!(
        scene.warnings,
        [
            format!(
                "{file}: material \"lamp\" uses statements lumiere does not render: \"d\" below 1 on an emitter (a \
                 light is whole) (see docs/MATERIALS.md)"
            ),
            format!("{file}: material \"gone\": \"Tr 1\" leaves none of its surface: it is not seen"),
        ]
    );
    // Rays straight down onto 64 x 64 points of each quad: the veil stops about 30% of them (the
    // share's standard deviation is 0.006), the missing leaf texture leaves its quad opaque, and
    // nothing stops at the quad of no coverage.
    let world = lumiere::world::World::new(scene, Default::default());
    let stopped = |k: usize| {
        let rays = (0..64 * 64).map(|i| {
            let (x, y) = (2.0 * k as f32 + (0.5 + (i % 64) as f32) / 64.0, (0.5 + (i / 64) as f32) / 64.0);
            lumiere::math::Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z)
        });
        let stops: Vec<bool> = rays.map(|ray| world.intersect(&ray).is_some()).collect();
        stops.iter().filter(|&&s| s).count() as f64 / stops.len() as f64
    };
    assert!((stopped(0) - 0.3).abs() < 0.03, "the veil stops {}", stopped(0));
    assert_eq!([2, 3, 4, 5].map(stopped), [1.0, 1.0, 0.0, 1.0]);
}

/// A `newmtl` without a name starts a material no `usemtl` can name: its statements are not
/// read, where they overwrote the material before it (red turned green).
#[test]
fn the_statements_of_a_nameless_newmtl_leave_the_material_before_it_alone() {
    let mtl = "newmtl red\nKd 1 0 0\nnewmtl\nKd 0 1 0\nTf 0 0 1\nnewmtl blue\nKd 0 0 1\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}usemtl red\nf 1 2 3\n"), &[("m.mtl", mtl)]);
    let kds: Vec<Vec3> = scene.materials.iter().map(|m| m.kd).collect();
    assert_eq!(kds, [Vec3::X, Vec3::Z]);
    assert_eq!(scene.materials[0].tf, Vec3::ONE);
    assert_only_warning(&scene, "m.mtl:3: newmtl without a name: its statements, up to the next newmtl, are not read");
}

/// Some exporters write the illumination model as a float (`illum 2.0`); Blender and
/// tinyobjloader read its whole part. It was refused, and the glossy material became Lambertian.
/// What is not a number, negative or past `u32` is still refused.
#[test]
fn an_illumination_model_written_with_a_fraction_is_read_as_its_whole_part() {
    let mtl = "newmtl a\nillum 2.0\nnewmtl b\nillum 7.9\nnewmtl c\nillum 3\nillum -1\nillum 1e10\nillum two\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}f 1 2 3\n"), &[("m.mtl", mtl)]);
    let illums: Vec<u32> = scene.materials[..3].iter().map(|m| m.illum).collect();
    assert_eq!(illums, [2, 7, 3]);
    assert_eq!(scene.warnings.len(), 3, "{:#?}", scene.warnings);
    for (warning, value) in scene.warnings.iter().zip(["-1", "1e10", "two"]) {
        assert!(warning.contains(&format!("malformed illumination model \"{value}\"")), "{warning}");
    }
}

/// The MTL specification's other colour forms, CIE XYZ and a spectral file, are named as what
/// they are, not as a malformed number.
#[test]
fn xyz_and_spectral_colours_are_named_as_unsupported_forms() {
    let mtl = "newmtl a\nKd xyz 0.5 0.5 0.5\nTf spectral glass.rfl 1.0\n";
    let scene = parse_with(&format!("mtllib m.mtl\n{SQUARE}f 1 2 3\n"), &[("m.mtl", mtl)]);
    assert_eq!(scene.warnings.len(), 2, "{:#?}", scene.warnings);
    for (warning, form) in scene.warnings.iter().zip(["xyz", "spectral"]) {
        assert!(
            warning.contains(&format!("the \"{form}\" form of a colour is not supported (only r g b)")),
            "{warning}"
        );
    }
}

#[test]
fn mtllib_with_several_files_or_a_name_with_spaces() {
    let a = "newmtl a\nKd 1 0 0\n";
    let b = "newmtl b\nKd 0 1 0\n";
    let several =
        parse_with(&format!("mtllib a.mtl b.mtl\n{SQUARE}usemtl b\nf 1 2 3\n"), &[("a.mtl", a), ("b.mtl", b)]);
    assert_eq!(several.materials.len(), 2);
    assert_eq!(material_of(&several, 0).kd, Vec3::Y);
    let spaced =
        parse_with(&format!("mtllib my materials.mtl\n{SQUARE}usemtl a\nf 1 2 3\n"), &[("my materials.mtl", a)]);
    assert!(spaced.warnings.is_empty(), "{:?}", spaced.warnings);
    assert_eq!(material_of(&spaced, 0).kd, Vec3::X);
}

/// An `mtllib` name is read as a texture's is: its bytes are the file's name (a Latin-1 name is
/// found on disk, not its UTF-8 spelling), and a backslash is a folder separator, as Windows
/// exporters write it; `\ ` still escapes a space. Both were names of files that did not exist.
#[test]
fn mtllib_names_are_bytes_and_backslashes_separate_folders() {
    let dir = TempDir::new("mtllib-bytes");
    std::fs::create_dir_all(dir.0.join("sub")).expect("mkdir");
    dir.write("sub/scene.mtl", b"newmtl red\nKd 1 0 0\n");
    dir.write("sub/my file.mtl", b"newmtl blue\nKd 0 0 1\n");
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let latin1 = dir.0.join(std::ffi::OsStr::from_bytes(b"caf\xe9.mtl"));
        std::fs::write(latin1, b"newmtl green\nKd 0 1 0\n").expect("write");
    }
    let mut obj = b"mtllib sub\\scene.mtl\nmtllib sub\\my\\ file.mtl\nmtllib caf\xe9.mtl\n".to_vec();
    obj.extend_from_slice(
        format!("{SQUARE}usemtl red\nf 1 2 3\nusemtl blue\nf 1 3 4\nusemtl green\nf 2 3 4\n").as_bytes(),
    );
    let scene = load_obj(&dir.write("scene.obj", &obj)).expect("load");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!([0, 1].map(|t| material_of(&scene, t).kd), [Vec3::X, Vec3::Z]);
    #[cfg(unix)]
    assert_eq!(material_of(&scene, 2).kd, Vec3::Y);
}

#[test]
fn gzipped_obj_loads_and_corrupt_gzip_fails() {
    let dir = TempDir::new("gz");
    let mut encoder = GzEncoder::new(Vec::new(), Compression::default());
    encoder.write_all(format!("mtllib m.mtl\n{SQUARE}usemtl red\nf 1 2 3 4\n").as_bytes()).expect("gzip");
    let gz = encoder.finish().expect("gzip");
    dir.write("m.mtl", b"newmtl red\nKd 1 0 0\n");
    let scene = load_obj(&dir.write("scene.obj.gz", &gz)).expect("load gz");
    assert_eq!(scene.mesh.indices, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(material_of(&scene, 1).kd, Vec3::X);

    let corrupt = dir.write("corrupt.obj.gz", &gz[..gz.len() / 2]);
    assert!(load_obj(&corrupt).is_err());
    assert!(load_obj(&dir.write("plain.obj.gz", b"v 0 0 0\n")).is_err());
    assert!(matches!(load_obj(&dir.0.join("absent.obj")), Err(lumiere::Error::Io { .. })));
}

#[test]
fn malformed_numbers_are_named() {
    assert_error(b"v 0 0 0\nv 1 x 0\n", 2, "\"x\"");
    assert_error(b"v 0 0\n", 1, "at least 3");
    assert_error(b"vn 0 0 1.0.0\n", 1, "\"1.0.0\"");
    assert_error(b"vt \xff\xfe 0\n", 1, "malformed number");
}

#[test]
fn non_finite_coordinates_are_refused() {
    assert_error(b"\nv nan 0 0\n", 2, "\"nan\"");
    assert_error(b"v 0 inf 0\n", 1, "not finite");
    assert_error(b"v 0 0 1e39\n", 1, "not finite");
    assert_error(b"vn 0 0 -infinity\n", 1, "not finite");
}

#[test]
fn faces_need_three_valid_corners() {
    let square = SQUARE.as_bytes();
    let with = |face: &str| [square, face.as_bytes()].concat();
    assert_error(&with("f 1 2\n"), 5, "2 corner");
    assert_error(&with("f\n"), 5, "0 corner");
    assert_error(&with("f 1 0 2\n"), 5, "index 0");
    assert_error(&with("f 1 2 5\n"), 5, "position index 5 out of range");
    assert_error(&with("f 1 2 -5\n"), 5, "position index -5 out of range");
    // Texture-coordinate and normal indices out of range are dropped with a warning (see
    // hostile_inputs.rs), as mainstream loaders accept such files; positions stay errors.
    for face in ["f 1 2 3/1\n", "f 1 2 3//-1\n"] {
        let scene = parse_obj(&with(face), Path::new("test.obj"), &mtl_files(&[])).expect(face);
        assert_eq!(scene.mesh.triangle_count(), 1);
        assert!(scene.warnings[0].starts_with("test.obj:5: 1 face has"), "{:?}", scene.warnings);
    }
    assert_error(&with("f 1/2/3/4 2 3\n"), 5, "\"1/2/3/4\"");
    assert_error(&with("f a/b 2 3\n"), 5, "\"a/b\"");
    assert_error(&with("f 1/ 2 3\n"), 5, "malformed face corner");
    assert_error(&with("f 1// 2 3\n"), 5, "malformed face corner");
    assert_error(&with("f /1 2 3\n"), 5, "malformed face corner");
    assert_error(&with("f 1 2 3 --4\n"), 5, "malformed face corner");
    assert_error(&with("usemtl\n"), 5, "usemtl");
}

/// A trailing backslash continues a statement on the next line (the OBJ specification), in LF and
/// CRLF files, at the end of the file and across the chunks that are parsed in parallel; the
/// lines after a joined statement keep their numbers in messages, and a joined statement is
/// reported at its first line. A comment ending with a backslash continues nothing.
#[test]
fn trailing_backslashes_continue_statements() {
    let expected = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\n");
    for text in [
        "v 0 0 0\nv 1 0 \\\n0\nv 0 1 0\nv 1 1 0\nf 1 2 \\\n  3 \\\n 4\n",
        "v 0 0 0\r\nv 1 0 \\\r\n0\r\nv 0 1 0\r\nv 1 1 0\r\nf 1 2\\\r\n3 4",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4 \\\n",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 \\\n4 \\",
    ] {
        for chunk_bytes in [usize::MAX, 1, 9] {
            let scene = parse_obj_with_chunk_size(text.as_bytes(), Path::new("test.obj"), &mtl_files(&[]), chunk_bytes)
                .unwrap_or_else(|error| panic!("{text:?} in chunks of {chunk_bytes}: {error}"));
            assert_eq!(scene.mesh.positions, expected.mesh.positions, "{text:?}");
            assert_eq!(scene.mesh.indices, expected.mesh.indices, "{text:?}");
        }
    }
    assert_error(format!("{SQUARE}f 1 \\\n2 \\\n3\nv x 0 0\n").as_bytes(), 8, "\"x\"");
    assert_error(b"v 0 0 0\nv 0 \\\n0 \\\nq\n", 2, "\"q\"");
    let commented = parse("# exported to C:\\models\\\nv 0 0 0\nv 1 0 0\nv 0 1 0 # C:\\\nf 1 2 3\n");
    assert_eq!(commented.mesh.indices, vec![[0, 1, 2]]);
    // In an MTL file too; a warning names the line it was on, after joined statements.
    let mtl = "newmtl red\nKd 1 \\\r\n  0 0\nKs \\\n0.5\nNs x\n";
    let scene = parse_with(&format!("mtllib red.mtl\n{SQUARE}usemtl red\nf 1 2 3\n"), &[("red.mtl", mtl)]);
    assert_eq!((scene.materials[0].kd, scene.materials[0].ks), (Vec3::X, Vec3::splat(0.5)));
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(scene.warnings[0].starts_with("mem/red.mtl:6: "), "{:?}", scene.warnings);
}

#[test]
fn huge_indices_do_not_overflow() {
    for index in [
        "9223372036854775807",
        "-9223372036854775808",
        "99999999999999999999999",
        "-99999999999999999999",
        "4294967296",
        "-4294967295",
    ] {
        let text = format!("{SQUARE}f 1 2 {index}\n");
        assert_error(text.as_bytes(), 5, &format!("index {index} out of range"));
        let text = format!("{SQUARE}vn 0 0 1\nf 1 2 3//{index}\n");
        let scene = parse(&text);
        assert!(scene.mesh.normal_indices.is_empty());
        assert!(scene.warnings[0].starts_with("test.obj:6: 1 face has normal indices out of range"));
    }
}

/// A file with `lines` vertices and faces interleaved, negative indices reaching back across
/// many lines, `usemtl` switches, mixed corner forms, comments and CRLF lines.
fn generated_obj(faces: usize) -> String {
    let mut text = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\n");
    for i in 0..faces {
        let x = i as f32 * 0.5;
        text += &format!("v {x} 1 2\r\nv {x} 3 4\nvt {x} 0.5\n");
        if i % 7 == 0 {
            text += &format!("usemtl {}\n", ["red", "blue", "ghost"][i % 3]);
        }
        match i % 4 {
            0 => text += "f -1 -2 -3\n",
            1 => text += &format!("f {} -1/-1 -5/-2 -7//1\n", 2 * i + 1),
            2 => text += "# a comment line\nf -4/1/1 -3/2/-1 -2/-1 -1\n",
            _ => text += &format!("\tf -2//-1 -3//1 {}//1 -6 -7\n", i + 3),
        }
    }
    text
}

#[test]
fn chunked_parsing_matches_a_single_chunk() {
    let text = generated_obj(3000);
    let mtl = "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n";
    let read = mtl_files(&[("m.mtl", mtl)]);
    let name = Path::new("gen.obj");
    let single = parse_obj_with_chunk_size(text.as_bytes(), name, &read, usize::MAX).expect("single chunk");
    assert!(single.mesh.triangle_count() > 5000);
    for chunk in [1, 17, 100, 4096] {
        let chunked = parse_obj_with_chunk_size(text.as_bytes(), name, &read, chunk).expect("chunked");
        let (a, b) = (&single.mesh, &chunked.mesh);
        assert_eq!(a.indices, b.indices, "chunk {chunk}");
        assert_eq!(a.positions, b.positions);
        assert_eq!(a.normals, b.normals);
        assert_eq!(a.texcoords, b.texcoords);
        assert_eq!(a.normal_indices, b.normal_indices);
        assert_eq!(a.texcoord_indices, b.texcoord_indices);
        assert_eq!(a.material_ids, b.material_ids);
        assert_eq!(single.materials, chunked.materials);
        assert_eq!(single.warnings, chunked.warnings);
    }
    assert_eq!(single.materials.len(), 3);
    assert_eq!(single.warnings.len(), 1, "{:?}", single.warnings);
}

#[test]
fn chunked_errors_report_the_first_bad_line() {
    let mut text = generated_obj(2000);
    let bad_line = text.lines().count() + 1;
    text += "f 1 2 -999999\nv 0 0 nan\n";
    let read = mtl_files(&[]);
    for chunk in [1, 100, usize::MAX] {
        let error =
            parse_obj_with_chunk_size(text.as_bytes(), Path::new("gen.obj"), &read, chunk).expect_err("must fail");
        assert!(error.to_string().starts_with(&format!("gen.obj:{bad_line}: ")), "{error}");
    }
}

#[test]
fn gkit_cornell_box() {
    let Some(scene) = load_shared("cornell/cornell.obj") else { return };
    assert_eq!(scene.mesh.triangle_count(), 32);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let emissive: Vec<usize> = (0..32).filter(|&t| material_of(&scene, t).is_emissive()).collect();
    assert_eq!(emissive, [12, 13]);
    assert_eq!(material_of(&scene, 12).name, "light.001");
    assert_eq!(material_of(&scene, 12).ke, Vec3::splat(100.0));
    let left = scene.materials.iter().find(|m| m.name == "leftWall.001").expect("leftWall.001");
    assert_eq!(left.kd, Vec3::new(0.63, 0.065, 0.05));
}

#[test]
fn mcguire_cornell_box() {
    let Some(scene) = load_shared("cornell-mcguire/CornellBox-Original.obj") else { return };
    assert_eq!(scene.mesh.triangle_count(), 36);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let emissive: Vec<usize> = (0..36).filter(|&t| material_of(&scene, t).is_emissive()).collect();
    assert_eq!(emissive, [34, 35]);
    assert_eq!(material_of(&scene, 34).name, "light");
    assert_eq!(material_of(&scene, 34).ke, Vec3::new(17.0, 12.0, 4.0));
}

#[test]
fn stanford_bunny() {
    let Some(scene) = load_shared("bunny/stanford-bunny.obj") else { return };
    assert_eq!(scene.mesh.triangle_count(), 69_451);
    assert_eq!(scene.materials, [lumiere::materials::Material::default_grey("default")]);
    assert!(scene.mesh.material_ids.iter().all(|&id| id == 0));
    assert!(scene.warnings.is_empty());
}

#[test]
fn staircase_with_textures() {
    let Some(scene) = load_shared("staircase/staircase.obj.gz") else { return };
    assert_eq!(scene.mesh.triangle_count(), 262_663);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(scene.materials.len(), 25);
    let textured: Vec<&Path> = scene.materials.iter().filter_map(|m| m.map_kd.as_deref()).collect();
    assert!(!textured.is_empty());
    assert!(textured.iter().all(|path| path.exists()), "{textured:?}");
    let lights: Vec<&str> = scene.materials.iter().filter(|m| m.is_emissive()).map(|m| m.name.as_str()).collect();
    assert_eq!(lights, ["AreaLight"]);
}

#[test]
fn bunny_1m_loads_fast() {
    let Some(scene) = load_shared("bunny-1m/stanford-bunny-1m.obj.gz") else { return };
    assert_eq!(scene.mesh.triangle_count(), 1_111_216);
    assert_eq!(scene.mesh.positions.len(), 557_164);
    assert!(scene.mesh.normal_indices.is_empty() && scene.mesh.texcoord_indices.is_empty());
}

#[test]
fn a_utf8_byte_order_mark_is_skipped() {
    let no_mtl = |_: &str| Err(io::Error::new(io::ErrorKind::NotFound, "none"));
    let scene = parse_obj(b"\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", Path::new("bom.obj"), &no_mtl).unwrap();
    assert_eq!((scene.mesh.positions.len(), scene.mesh.triangle_count()), (3, 1));
}
