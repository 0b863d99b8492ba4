//! The `lumiere` binary end to end: the lab's modes on the built-in scene, determinism across thread
//! counts, statistics, and a clear error (exit code 2, no output file) for every bad input.

use std::fs;
use std::path::Path;
use std::process::{Command, Output};

use crate::common::TempDir;
use lumiere::accel::Isa;

fn lumiere(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lumiere")).args(args).output().expect("the binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Reads a PFM written by lumiere into rows from the top, as (width, height, pixels).
fn read_pfm(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
    let bytes = fs::read(path).unwrap();
    let mut header_end = 0;
    let mut newlines = 0;
    while newlines < 3 {
        newlines += usize::from(bytes[header_end] == b'\n');
        header_end += 1;
    }
    let header = std::str::from_utf8(&bytes[..header_end]).unwrap();
    let mut fields = header.split_whitespace().skip(1);
    let width: usize = fields.next().unwrap().parse().unwrap();
    let height: usize = fields.next().unwrap().parse().unwrap();
    let floats: Vec<f32> =
        bytes[header_end..].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
    let mut pixels = vec![[0.0; 3]; width * height];
    for row in 0..height {
        for x in 0..width {
            let src = 3 * ((height - 1 - row) * width + x);
            pixels[row * width + x] = [floats[src], floats[src + 1], floats[src + 2]];
        }
    }
    (width, height, pixels)
}

fn assert_rgb(actual: [f32; 3], expected: [f32; 3], what: &str) {
    let close = actual.iter().zip(expected).all(|(a, e)| (a - e).abs() < 1e-5);
    assert!(close, "{what}: got {actual:?}, expected {expected:?}");
}

#[test]
fn materials_mode_shows_the_walls_and_the_light_with_their_kd() {
    let dir = TempDir::new("materials");
    let out = dir.path("m.pfm");
    let run = lumiere(&["render", "--mode", "materials", "-o", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
    let (w, h, px) = read_pfm(&out);
    assert_eq!((w, h), (1024, 768));
    assert_rgb(px[384 * w + 20], [0.63, 0.065, 0.05], "red left wall");
    assert_rgb(px[200 * w + 900], [0.14, 0.45, 0.091], "green right wall");
    assert_rgb(px[100 * w + 400], [0.725, 0.71, 0.68], "back wall");

    // Looking straight up from the floor, the centre pixel sees the light (Kd 0.78).
    let up = dir.path("up.pfm");
    let args = ["render", "--mode", "materials", "--size", "64x48", "--eye", "0,0.1,0", "--target", "0,1,0"];
    let run = lumiere(&[&args[..], &["--up", "0,0,1", "-o", up.to_str().unwrap()]].concat());
    assert!(run.status.success(), "{}", stderr(&run));
    let (w, _, px) = read_pfm(&up);
    assert_rgb(px[24 * w + 32], [0.78, 0.78, 0.78], "light seen from below");
}

#[test]
fn hits_mode_is_white_on_geometry_and_black_on_background() {
    let dir = TempDir::new("hits");
    let out = dir.path("h.pfm");
    // From outside the box, looking at it from the side: the box is hit, the sky above it is not.
    let run = lumiere(&[
        "render",
        "--mode",
        "hits",
        "--size",
        "80x60",
        "--eye",
        "0,1,8",
        "--target",
        "0,1,0",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let (w, _, px) = read_pfm(&out);
    assert_rgb(px[30 * w + 40], [1.0; 3], "centre hits the box");
    assert_rgb(px[2 * w + 2], [0.0; 3], "corner sees the background");
    assert!(px.iter().all(|p| p[0] == 0.0 || p[0] == 1.0), "hits is a pure mask");
}

#[test]
fn shadows_mode_lights_the_floor_and_is_black_behind_the_tall_box() {
    let dir = TempDir::new("shadows");
    let out = dir.path("s.pfm");
    let run = lumiere(&["render", "--mode", "shadows", "-o", out.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
    let (w, _, px) = read_pfm(&out);
    // Floor between the tall box and the red wall: both light centroids hidden by the tall box.
    assert_rgb(px[600 * w + 150], [0.0; 3], "floor in the tall box's shadow");
    // Open floor in front of the boxes is lit, with the floor's colour balance (Kd 0.725 0.71 0.68).
    let lit = px[740 * w + 400];
    assert!(lit[0] > 0.1 && lit[0] > lit[2], "lit floor {lit:?}");
    assert!((lit[1] / lit[0] - 0.71 / 0.725).abs() < 1e-4, "lit floor ratio {lit:?}");

    // Seen directly, the light shows its emission Ke = 100.
    let up = dir.path("up.pfm");
    let run = lumiere(&[
        "render",
        "--mode",
        "shadows",
        "--size",
        "64x48",
        "--eye",
        "0,0.1,0",
        "--target",
        "0,1,0",
        "--up",
        "0,0,1",
        "-o",
        up.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let (w, _, px) = read_pfm(&up);
    assert_rgb(px[24 * w + 32], [100.0; 3], "light seen directly");
}

#[test]
fn thread_count_does_not_change_the_bytes() {
    let dir = TempDir::new("threads");
    for mode in [&["--mode", "shadows"][..], &["--mode", "path", "--spp", "4", "--size", "256x192"]] {
        let one = dir.path("one.pfm");
        let two = dir.path("two.pfm");
        for (threads, out) in [("1", &one), ("2", &two)] {
            let run = lumiere(&[&["render", "--threads", threads, "-o", out.to_str().unwrap()][..], mode].concat());
            assert!(run.status.success(), "{}", stderr(&run));
        }
        assert_eq!(fs::read(&one).unwrap(), fs::read(&two).unwrap(), "{mode:?}");
    }
}

/// `--png-linear` writes as gKit does, and gKit clamps: in path mode too, whose default curve is
/// ACES, unless `--tonemap aces` asks for the curve.
#[test]
fn png_linear_clamps_unless_told_to_tone_map() {
    let dir = TempDir::new("png-linear");
    let png = |name: &str, extra: &[&str]| {
        let out = dir.path(name);
        let args = ["render", "--mode", "path", "--spp", "2", "--size", "16x12", "--png-linear", "-o"];
        let run = lumiere(&[&args[..], &[out.to_str().unwrap()], extra].concat());
        assert!(run.status.success(), "{}", stderr(&run));
        fs::read(out).unwrap()
    };
    let (plain, clamp, aces) =
        (png("a.png", &[]), png("b.png", &["--tonemap", "clamp"]), png("c.png", &["--tonemap", "aces"]));
    assert!(plain == clamp, "--png-linear alone does not clamp");
    assert!(plain != aces, "--tonemap aces is ignored with --png-linear");
}

#[test]
fn stats_json_has_the_promised_fields() {
    let dir = TempDir::new("stats");
    let stats = dir.path("stats.json");
    let out = dir.path("r.png");
    let run = lumiere(&[
        "render",
        "--mode",
        "hits",
        "--size",
        "32x24",
        "-o",
        out.to_str().unwrap(),
        "--stats-json",
        stats.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let json: serde_json::Value = serde_json::from_slice(&fs::read(&stats).unwrap()).unwrap();
    for key in [
        "mode",
        "width",
        "height",
        "samples",
        "threads",
        "triangles",
        "load_ms",
        "build_ms",
        "render_ms",
        "rays",
        "mrays_per_s",
    ] {
        assert!(json.get(key).is_some(), "missing {key} in {json}");
    }
    assert_eq!(json["mode"], "hits");
    assert_eq!(json["isa"], lumiere::accel::Isa::detect().name(), "the widest ISA by default");
    assert_eq!(json["triangles"], 32);
    assert_eq!(json["rays"], 32 * 24);
    assert!(stderr(&run).contains("Mrays/s"), "closing line: {}", stderr(&run));
    // The commit the binary was built from, as --version says it (benchmarks name what they ran).
    let commit = json["commit"].as_str().expect("a commit");
    assert!(!commit.is_empty());
    let version = lumiere(&["--version"]);
    assert_eq!(
        String::from_utf8_lossy(&version.stdout).trim(),
        format!("lumiere {} ({commit})", env!("CARGO_PKG_VERSION"))
    );
}

/// The statistics name each technique's options as the flags do, in an object a script can index
/// (it held Rust's Debug text, `Path(Path { max_depth: 8, .. })`).
#[test]
fn stats_json_holds_the_techniques_options_by_their_flags_names() {
    let dir = TempDir::new("stats-technique");
    let out = dir.path("r.pfm");
    let technique = |flags: &[&str]| {
        let mut args = vec!["render", "--size", "8x6", "-o", out.to_str().unwrap(), "--stats-json", "-"];
        args.extend_from_slice(flags);
        let run = lumiere(&args);
        assert!(run.status.success(), "{flags:?}: {}", stderr(&run));
        serde_json::from_slice::<serde_json::Value>(&run.stdout).unwrap()["technique"].clone()
    };
    let path = technique(&["--mode", "path", "--spp", "1", "--max-depth", "3"]);
    assert_eq!(path, serde_json::json!({"max_depth": 3, "rr_depth": 5, "strategy": "mis"}));
    let direct = technique(&["--mode", "direct", "--samples", "2", "--light-sampling", "power"]);
    assert_eq!(direct, serde_json::json!({"samples": 2, "light_sampling": "power"}));
    let ao = technique(&["--mode", "ao", "--samples", "4", "--ao-distance", "0.5"]);
    assert_eq!(ao, serde_json::json!({"samples": 4, "ao_distance": 0.5}));
    // Unbounded (the default) is null: JSON has no infinity.
    assert_eq!(technique(&["--mode", "ao"]), serde_json::json!({"samples": 16, "ao_distance": null}));
    assert_eq!(technique(&["--mode", "shadows"]), serde_json::json!({}));
}

#[test]
fn mcguire_box_renders_with_the_issue_camera() {
    let Some(scene) = crate::common::shared_scene("cornell-mcguire/CornellBox-Original.obj") else { return };
    let scene = scene.to_str().unwrap();
    let dir = TempDir::new("mcguire");
    let out = dir.path("m.pfm");
    let run = lumiere(&[
        "render",
        scene,
        "--size",
        "64x64",
        "--eye",
        "0,1,3.9",
        "--target",
        "0,1,0",
        "--up",
        "0,1,0",
        "--fov",
        "45",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    let (w, _, px) = read_pfm(&out);
    // The floor in front of the boxes is lit by the warm light (Ke 17 12 4): red > green > blue.
    let floor = px[55 * w + 18];
    assert!(floor[0] > floor[1] && floor[1] > floor[2] && floor[2] > 0.0, "floor {floor:?}");
}

/// Runs a command that must fail: exit code 2, a one-line message containing `expected`, no output file.
fn assert_refused(dir: &TempDir, args: &[&str], expected: &str) {
    let out = dir.path("out.png");
    let _ = fs::remove_file(&out);
    let all: Vec<&str> = args.iter().copied().chain(["-o", out.to_str().unwrap()]).collect();
    let run = lumiere(&all);
    let message = stderr(&run);
    assert_eq!(run.status.code(), Some(2), "{args:?}: {message}");
    assert!(message.contains(expected), "{args:?}: expected '{expected}' in: {message}");
    assert!(!message.contains("panicked"), "{args:?}: {message}");
    assert!(!out.exists(), "{args:?} left an output file");
}

/// A PLY file renders as the OBJ file of the same faces does, byte for byte: the same triangles
/// in the same order, and the same grey default material.
#[test]
fn a_ply_scene_renders_as_its_obj_twin() {
    let dir = TempDir::new("ply-twin");
    let corners = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.5, 1.0, 0.0], [-1.0, 1.0, 0.5], [0.0, 0.0, 1.0]];
    let faces: [&[usize]; 2] = [&[0, 1, 2, 3], &[0, 1, 4]];
    let mut obj = String::new();
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        corners.len(),
        faces.len()
    );
    for [x, y, z] in corners {
        obj += &format!("v {x} {y} {z}\n");
        ply += &format!("{x} {y} {z}\n");
    }
    for face in faces {
        obj += &format!("f{}\n", face.iter().map(|i| format!(" {}", i + 1)).collect::<String>());
        ply += &format!("{}{}\n", face.len(), face.iter().map(|i| format!(" {i}")).collect::<String>());
    }
    let mut images = Vec::new();
    for (name, text) in [("twin.obj", obj), ("twin.ply", ply)] {
        let scene = dir.write(name, text);
        let out = dir.arg(&format!("{name}.pfm"));
        let args = ["render", scene.to_str().unwrap(), "--mode", "ao", "--samples", "4", "--size", "32x24", "-o", &out];
        let run = lumiere(&args);
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        assert_eq!(stderr(&run).matches("warning").count(), 0, "{name}: {}", stderr(&run));
        images.push(fs::read(&out).unwrap());
    }
    assert!(images[0] == images[1], "the PLY's image differs from the OBJ's");
}

/// A GLB file (its texture embedded) renders as the OBJ file of the same quad and light with the
/// same PBR statements and a texture file does, byte for byte, path-traced: the same triangles,
/// materials, texture coordinates and texels, the same cutouts, and the same metallic weight and
/// roughness painted by the texture (glTF's `metallicRoughnessTexture`, MTL's `map_Pm` and
/// `map_Pr` reading its blue and green channels).
#[test]
fn a_glb_scene_renders_as_its_obj_twin() {
    let dir = TempDir::new("gltf-twin");
    // The texture: colours, a roughness (green) and a metallic weight (blue) on both sides of one
    // half, and an alpha that cuts holes (MTL's `map_d`, glTF's `alphaMode MASK`) on both sides of
    // one half.
    let texels: Vec<u8> =
        (0..16u8).flat_map(|i| [i * 16, 255 - i * 8, 255 - i * 16, [0, 255, 127, 128][i as usize % 4]]).collect();
    let mut png = std::io::Cursor::new(Vec::new());
    image::RgbaImage::from_raw(4, 4, texels).unwrap().write_to(&mut png, image::ImageFormat::Png).unwrap();
    let png = png.into_inner();
    dir.write("tex.png", &png);
    let corners = [
        [-1.0f32, 0.0, -1.0],
        [1.0, 0.0, -1.0],
        [1.0, 0.0, 1.0],
        [-1.0, 0.0, 1.0],
        [0.0, 1.0, 0.5],
        [-0.5, 1.0, -0.5],
        [0.5, 1.0, -0.5],
    ];
    // OBJ's v up from the image's bottom; glTF's down from its top (values whose 1 - v is exact).
    let uv = [[0.0f32, 0.0], [1.0, 0.0], [1.0, 0.75], [0.25, 1.0]];
    let mut obj = String::from("mtllib twin.mtl\n");
    for [x, y, z] in corners {
        obj += &format!("v {x} {y} {z}\n");
    }
    for [u, v] in uv {
        obj += &format!("vt {u} {v}\n");
    }
    obj += "usemtl floor\nf 1/1 2/2 3/3 4/4\nusemtl lamp\nf 5 6 7\n";
    dir.write("twin.obj", &obj);
    let mtl = "newmtl floor\nKd 1 1 1\nPm 0\nPr 0.5\nmap_Kd tex.png\nmap_d tex.png\n\
               map_Pm -imfchan b tex.png\nmap_Pr -imfchan g tex.png\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\nPm 0\nPr 1\n";
    dir.write("twin.mtl", mtl);
    // The same without the maps: the twins must differ from it for the maps to be tested.
    dir.write("plain.mtl", mtl.replace("map_Pm -imfchan b tex.png\nmap_Pr -imfchan g tex.png\n", ""));
    dir.write("plain.obj", obj.replace("twin.mtl", "plain.mtl"));
    let mut bin: Vec<u8> = corners.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    bin.extend(uv.iter().flat_map(|[u, v]| [*u, 1.0 - v]).flat_map(|c| c.to_le_bytes()));
    bin.extend([0u16, 1, 2, 0, 2, 3, 0, 1, 2].iter().flat_map(|i| i.to_le_bytes()));
    bin.extend([0u8; 2]);
    let image_at = bin.len();
    bin.extend(&png);
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
        "meshes": [{{"primitives": [
            {{"attributes": {{"POSITION": 0, "TEXCOORD_0": 1}}, "indices": 2, "material": 0}},
            {{"attributes": {{"POSITION": 3}}, "indices": 4, "material": 1}}]}}],
        "materials": [
            {{"name": "floor", "alphaMode": "MASK", "pbrMetallicRoughness": {{"baseColorTexture": {{"index": 0}}, "metallicRoughnessTexture": {{"index": 0}}}}}},
            {{"name": "lamp", "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}}, "emissiveFactor": [1, 1, 1],
              "extensions": {{"KHR_materials_emissive_strength": {{"emissiveStrength": 5}}}}}}],
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "textures": [{{"source": 0}}], "images": [{{"bufferView": 3, "mimeType": "image/png"}}],
        "buffers": [{{"byteLength": {}}}],
        "bufferViews": [{{"buffer": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 84, "byteLength": 32}},
            {{"buffer": 0, "byteOffset": 116, "byteLength": 18}}, {{"buffer": 0, "byteOffset": {image_at}, "byteLength": {}}},
            {{"buffer": 0, "byteOffset": 48, "byteLength": 36}}],
        "accessors": [
            {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}},
            {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"}},
            {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}},
            {{"bufferView": 4, "componentType": 5126, "count": 3, "type": "VEC3"}},
            {{"bufferView": 2, "byteOffset": 12, "componentType": 5123, "count": 3, "type": "SCALAR"}}]}}"#,
        bin.len(),
        png.len()
    );
    let mut json = json.into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    dir.write("twin.glb", glb);
    let mut images = Vec::new();
    for name in ["twin.obj", "twin.glb", "plain.obj"] {
        let scene = dir.path(name);
        let out = dir.arg(&format!("{name}.pfm"));
        let args = [
            "render",
            scene.to_str().unwrap(),
            "--spp",
            "4",
            "--size",
            "32x24",
            "--eye",
            "0,2,3",
            "--target",
            "0,0,0",
            "-o",
            &out,
        ];
        let run = lumiere(&args);
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        assert_eq!(stderr(&run).matches("warning").count(), 0, "{name}: {}", stderr(&run));
        images.push(fs::read(&out).unwrap());
    }
    assert!(images[0] == images[1], "the GLB's image differs from the OBJ's");
    assert!(images[0] != images[2], "the maps change nothing");
    // Cut short inside its binary chunk: refused, naming the file and the chunk.
    let cut = dir.write("cut.glb", &fs::read(dir.path("twin.glb")).unwrap()[..200]);
    assert_refused(&dir, &["render", cut.to_str().unwrap()], "cut.glb: GLB: the header gives a length of");
}

/// A glTF scene whose node tree places a camera renders from it when no camera is given, byte for
/// byte as the same look-at given in flags; `--fov` replaces its field of view, `--eye` and
/// `--target` replace it, and `lumiere info` shows it.
#[test]
fn a_gltf_camera_is_the_default_view_and_camera_flags_override_it() {
    let dir = TempDir::new("gltf-camera");
    let floor = [[-1.0f32, 0.0, -1.0], [1.0, 0.0, -1.0], [1.0, 0.0, 1.0], [-1.0, 0.0, 1.0]];
    let block = [[-0.5f32, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 1.0, 0.5]];
    let mut bin: Vec<u8> = floor.iter().chain(&block).flatten().flat_map(|c| c.to_le_bytes()).collect();
    bin.extend([0u16, 2, 1, 0, 3, 2, 0, 1, 2, 0].iter().flat_map(|i| i.to_le_bytes()));
    dir.write("scene.bin", &bin);
    let gltf = |camera_node: &str, cameras: &str| {
        format!(
            r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0, 1]}}],
            "nodes": [{{"mesh": 0}}, {camera_node}], "cameras": [{cameras}],
            "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 2, "material": 0}},
                {{"attributes": {{"POSITION": 1}}, "indices": 3, "material": 1}}]}}],
            "materials": [{{"pbrMetallicRoughness": {{"baseColorFactor": [0.2, 0.6, 0.8, 1], "metallicFactor": 0}}}},
                {{"pbrMetallicRoughness": {{"baseColorFactor": [0.9, 0.3, 0.1, 1], "metallicFactor": 0}}}}],
            "buffers": [{{"byteLength": {}, "uri": "scene.bin"}}],
            "bufferViews": [{{"buffer": 0, "byteLength": 48}}, {{"buffer": 0, "byteOffset": 48, "byteLength": 36}},
                {{"buffer": 0, "byteOffset": 84, "byteLength": 12}}, {{"buffer": 0, "byteOffset": 96, "byteLength": 6}}],
            "accessors": [{{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}},
                {{"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}},
                {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}},
                {{"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}}]}}"#,
            bin.len()
        )
    };
    // Half a turn about +Y: the camera at z = -4 looks down +Z, at the floor and the block.
    let node = r#"{"camera": 0, "translation": [0.5, 1.5, -4], "rotation": [0, 1, 0, 0]}"#;
    let camera = r#"{"type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.1, "aspectRatio": 2}}"#;
    let with_camera = dir.write("camera.gltf", gltf(node, camera));
    let without = dir.write("plain.gltf", gltf("{}", ""));
    // The view's field of view as the loader converts it, printed so that it parses back to itself.
    let fov = format!("{}", f64::from(0.6f32).to_degrees() as f32);
    let explicit = ["--eye", "0.5,1.5,-4", "--target", "0.5,1.5,0", "--up", "0,1,0"];
    let render = |scene: &Path, flags: &[&str], name: &str| {
        let out = dir.arg(name);
        let args = ["render", scene.to_str().unwrap(), "--mode", "materials", "--size", "48x24", "-o", &out];
        let run = lumiere(&args.iter().chain(flags).copied().collect::<Vec<_>>());
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        assert!(!stderr(&run).contains("warning"), "{name}: {}", stderr(&run));
        fs::read(&out).unwrap()
    };
    let from_file = render(&with_camera, &[], "file.pfm");
    let given: Vec<&str> = explicit.iter().copied().chain(["--fov", &fov]).collect();
    assert!(from_file == render(&without, &given, "given.pfm"), "the file's camera is not the flags' look-at");
    let framed = render(&without, &[], "framed.pfm");
    assert!(from_file != framed, "the file's camera renders as the framing view");

    let narrower = render(&with_camera, &["--fov", "20"], "narrower.pfm");
    let given: Vec<&str> = explicit.iter().copied().chain(["--fov", "20"]).collect();
    assert!(narrower == render(&without, &given, "given-narrower.pfm"), "--fov does not replace the file's");
    assert!(narrower != from_file, "--fov changes nothing");

    let elsewhere = ["--eye", "2,3,3", "--target", "0,0,0"];
    let overridden = render(&with_camera, &elsewhere, "overridden.pfm");
    assert!(
        overridden == render(&without, &elsewhere, "elsewhere.pfm"),
        "--eye/--target do not replace the file's camera"
    );
    assert!(overridden != from_file, "--eye/--target change nothing");

    let info = lumiere(&["info", with_camera.to_str().unwrap()]);
    assert!(info.status.success(), "{}", stderr(&info));
    let text = String::from_utf8_lossy(&info.stdout);
    let expected = "view       eye (0.500000, 1.500000, -4.000000), target (0.500000, 1.500000, 0.000000), up (0.000000, \
                    1.000000, 0.000000), fov 34.377468 degrees";
    assert!(text.contains(expected), "{text}");
    let plain = lumiere(&["info", without.to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&plain.stdout).contains("view"), "a scene without a camera shows a view");
}

#[test]
fn bad_inputs_give_a_clear_error_and_no_file() {
    let dir = TempDir::new("bad");
    let missing = dir.path("missing.obj");
    assert_refused(&dir, &["render", missing.to_str().unwrap()], "missing.obj");

    let bad_number = dir.write("bad_number.obj", "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n");
    assert_refused(&dir, &["render", bad_number.to_str().unwrap()], "bad_number.obj:3");

    let out_of_range = dir.write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n");
    assert_refused(&dir, &["render", out_of_range.to_str().unwrap()], "range.obj:5");

    let nan = dir.write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_refused(&dir, &["render", nan.to_str().unwrap()], "nan.obj:2");
    let inf = dir.write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n");
    assert_refused(&dir, &["render", inf.to_str().unwrap()], "inf.obj:3");
    // A binary PLY cut short inside its second vertex: refused from its header's count.
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    let short = dir.write("short.ply", [header.as_bytes(), &[0; 16]].concat());
    let expected =
        "short.ply:3: element \"vertex\" declares 3 of them, more than the 16 bytes after the header can hold";
    assert_refused(&dir, &["render", short.to_str().unwrap()], expected);

    assert_refused(&dir, &["render", "--size", "0x768"], "no pixels");
    assert_refused(&dir, &["render", "--size", "banana"], "WIDTHxHEIGHT");
    assert_refused(&dir, &["render", "--samples", "0"], "samples");
    // A negative number is refused as a value of its flag, where clap took it for another flag
    // and advised `-- -1`, which would have made it the scene's file name.
    for (flag, value, expected) in [
        ("--size", "-5x10", "'-5' is not a positive integer"),
        ("--threads", "-1", "expected a thread count"),
        ("--max-depth", "-1", "-1 is not in 0.."),
        ("--spp", "-3", "-3 is not in 1.."),
        ("--samples", "-2", "-2 is not in 1.."),
        ("--seed", "-1", "for '--seed <SEED>'"),
        ("--emission", "=5,5,5", "expected NAME=r,g,b, got '=5,5,5'"),
    ] {
        assert_refused(&dir, &["render", flag, value], expected);
    }
    assert_refused(&dir, &["render", "--mode", "teapot"], "teapot");
    assert_refused(&dir, &["render", "--eye", "0,0,nan", "--target", "0,0,1"], "finite");
    assert_refused(&dir, &["render", "--isa", "mmx"], "unknown ISA \"mmx\" (expected portable, sse2, avx2, avx512)");
    if let Some(missing) = lumiere::accel::Isa::ALL.into_iter().find(|isa| !isa.is_supported()) {
        assert_refused(&dir, &["render", "--isa", missing.name()], "this CPU cannot run");
    }

    let unreadable_orbiter = dir.path("no_such_orbiter.txt");
    assert_refused(&dir, &["render", "--orbiter", unreadable_orbiter.to_str().unwrap()], "no_such_orbiter.txt");

    // Unwritable output paths: a directory that does not exist, an unsupported extension, a
    // directory (named as one, not as a file name without an extension).
    let folder = std::env::temp_dir();
    let folder = folder.to_str().unwrap();
    for (path, expected) in [
        (
            "/nonexistent-dir/x.png",
            "/nonexistent-dir/x.png: cannot be created: the folder /nonexistent-dir does not exist",
        ),
        ("out.jpg", ".png"),
        (folder, "is a directory, expected a file name"),
    ] {
        let run = lumiere(&["render", "--mode", "hits", "-o", path]);
        assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
        assert!(stderr(&run).contains(expected), "{}", stderr(&run));
        assert!(path == folder || !Path::new(path).exists());
    }
    assert_eq!(dir.entries(), ["bad_number.obj", "inf.obj", "nan.obj", "range.obj", "short.ply"]);
}

/// `$LUMIERE_ISA` forces the ISA when `--isa` is absent, and is checked like the flag.
#[test]
fn isa_environment_variable_is_honoured_and_checked() {
    let dir = TempDir::new("isa-env");
    let (out, stats) = (dir.path("r.png"), dir.path("s.json"));
    let run = |value: &str, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_lumiere"))
            .args(["render", "--mode", "hits", "--size", "16x12", "-o", out.to_str().unwrap()])
            .args(["--stats-json", stats.to_str().unwrap()])
            .args(extra)
            .env("LUMIERE_ISA", value)
            .output()
            .unwrap()
    };
    let isa_used = || serde_json::from_slice::<serde_json::Value>(&fs::read(&stats).unwrap()).unwrap()["isa"].clone();
    assert!(run("sse2", &[]).status.success());
    assert_eq!(isa_used(), "sse2");
    assert!(run("sse2", &["--isa", "portable"]).status.success(), "the flag wins");
    assert_eq!(isa_used(), "portable");
    // Set but empty is unset: the widest ISA this CPU has.
    assert!(run("", &[]).status.success());
    assert_eq!(isa_used(), Isa::detect().name());
    let _ = fs::remove_file(&out);
    let refused = run("avx9000", &[]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(stderr(&refused).contains("LUMIERE_ISA: unknown ISA"), "{}", stderr(&refused));
    assert!(!out.exists());
    // A huge value is quoted cut short, on one line.
    let huge = run(&"a".repeat(100_000), &[]);
    assert_eq!(huge.status.code(), Some(2));
    let message = stderr(&huge);
    assert!(message.len() < 400 && message.lines().count() == 1 && message.contains("(100000 bytes)"), "{message}");
}

#[test]
fn monte_carlo_modes_render_and_are_deterministic() {
    let dir = TempDir::new("mc");
    for (mode, extra) in
        [("direct", &["--sampler", "sobol"][..]), ("ao", &["--spp", "2"][..]), ("ao", &["--ao-distance", "0.3"][..])]
    {
        let mut outputs = Vec::new();
        for threads in ["1", "2"] {
            let out = dir.path(&format!("{mode}-{threads}.pfm"));
            let args = [
                "render",
                "--mode",
                mode,
                "--samples",
                "8",
                "--size",
                "64x48",
                "--threads",
                threads,
                "-o",
                out.to_str().unwrap(),
            ];
            let run = lumiere(&[&args[..], extra].concat());
            assert!(run.status.success(), "{mode} {extra:?}: {}", stderr(&run));
            outputs.push(fs::read(&out).unwrap());
        }
        assert_eq!(outputs[0], outputs[1], "{mode} {extra:?}: thread count changed the image");
        let (_, _, px) = read_pfm(&dir.path(&format!("{mode}-1.pfm")));
        assert!(px.iter().all(|p| p.iter().all(|c| c.is_finite() && *c >= 0.0)));
        assert!(px.iter().any(|p| p[0] > 0.0), "{mode}: black image");
    }
}

#[test]
fn staircase_emission_turns_many_small_emitters_into_lights() {
    let Some(scene) = crate::common::shared_scene("staircase/staircase.obj.gz") else { return };
    let scene = scene.to_str().unwrap();
    let dir = TempDir::new("stairs");
    let out = dir.path("s.pfm");
    let stats = dir.path("s.json");
    let camera = [
        "--eye",
        "0.0324209,1.52673,4.88197",
        "--target",
        "0.0247749,1.571785,3.883015",
        "--up",
        "0.000344842,0.998984,0.0450537",
        "--fov",
        "58.54",
    ];
    let args = [
        "render",
        scene,
        "--mode",
        "direct",
        "--light-sampling",
        "power",
        "--emission",
        "Emission=5,5,5",
        "--samples",
        "4",
        "--size",
        "36x64",
    ];
    let run = lumiere(
        &[&args[..], &camera[..], &["-o", out.to_str().unwrap(), "--stats-json", stats.to_str().unwrap()]].concat(),
    );
    assert!(run.status.success(), "{}", stderr(&run));
    let json: serde_json::Value = serde_json::from_slice(&fs::read(&stats).unwrap()).unwrap();
    assert!(json["lights"].as_u64().unwrap() > 6000, "lights: {}", json["lights"]);
    let (_, _, px) = read_pfm(&out);
    assert!(px.iter().all(|p| p.iter().all(|c| c.is_finite())));
    assert!(px.iter().filter(|p| p[0] > 0.0).count() > px.len() / 4, "mostly black");

    let unknown = lumiere(&[
        "render",
        scene,
        "--emission",
        "NoSuchMaterial=1,1,1",
        "--size",
        "8x8",
        "-o",
        dir.path("u.png").to_str().unwrap(),
    ]);
    assert_eq!(unknown.status.code(), Some(2));
    assert!(stderr(&unknown).contains("NoSuchMaterial"), "{}", stderr(&unknown));
}

#[test]
fn lab_bench_quick_prints_every_row() {
    let dir = TempDir::new("bench");
    let json = dir.path("bench.json");
    let run = lumiere(&["bench", "--quick", "--json", json.to_str().unwrap()]);
    assert!(run.status.success(), "{}", stderr(&run));
    let table = String::from_utf8_lossy(&run.stdout);
    for row in ["hard shadows", "soft shadows N=16", "soft shadows N=256", "AO N=16", "AO N=256"] {
        assert!(table.contains(&format!("| {row} |")), "missing {row}:\n{table}");
    }
    // Nor does the JSON set the lab's 1024x768 figures beside the 256x192 times.
    let rows: Vec<serde_json::Value> = serde_json::from_slice(&fs::read(&json).unwrap()).unwrap();
    assert_eq!(rows.len(), 7);
    for row in &rows {
        assert_eq!((row["width"].as_u64(), row["parallel_ms"].is_f64()), (Some(256), true), "{row}");
        assert!(row["lab_parallel_ms"].is_null() && row["lab_serial_ms"].is_null(), "{row}");
    }
}
