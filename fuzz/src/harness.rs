//! The bodies of the fuzz targets and the invariants they check, shared by the libFuzzer targets
//! (`fuzz/fuzz_targets/*.rs`) and the stable test suites (`tests/fuzz_parsers.rs` and
//! `tests/fuzz_corpus.rs` include this file with `#[path]`, and replay the committed libFuzzer
//! corpus through the same functions). Everything returns `Err(what is wrong)` rather than
//! panicking, so callers can print the offending input with the message; a panic inside a parser
//! still unwinds to the caller (libFuzzer reports it, the tests catch it).
//!
//! A parser may refuse any input, but only with a one-line error that names the file (and a line
//! that exists in it); when it accepts an input, everything it returns must be usable by the
//! renderer: indices in range, material ids in range, finite numbers.
#![allow(dead_code)]

use lumiere::Error;
use lumiere::integrators::Technique;
use lumiere::materials::Material;
use lumiere::render::checkpoint::Checkpoint;
use lumiere::render::{RenderOptions, render};
use lumiere::scene::Scene;
use lumiere::scene::camera::{Camera, Orbiter};
use lumiere::scene::load::gltf::parse_gltf;
use lumiere::scene::load::obj::{ObjScene, parse_obj, parse_obj_with_chunk_size};
use lumiere::scene::load::ply::parse_ply;
use lumiere::scene::mesh::{NO_INDEX, TriangleMesh};
use lumiere::util::hash::StableHasher;
use lumiere::world::World;
use std::io;
use std::path::{Path, PathBuf};

/// The name parse errors must carry in the OBJ targets.
pub const OBJ_NAME: &str = "fuzz.obj";
/// The name errors must carry in the PLY target.
pub const PLY_NAME: &str = "fuzz.ply";
/// The name errors must carry in the glTF target (the loader tells `.glb` from JSON by its magic).
pub const GLTF_NAME: &str = "fuzz.gltf";
/// The name parse errors must carry in the orbiter target.
pub const ORBITER_NAME: &str = "fuzz_orbiter.txt";
/// The name errors must carry in the checkpoint target.
pub const CHECKPOINT_NAME: &str = "fuzz.ckpt";

/// A fuzz target's body: `Err(what is wrong)` for an input that breaks an invariant.
pub type Target = fn(&[u8]) -> Result<(), String>;

/// Every target, by the name of its `fuzz_targets/*.rs` file and `fuzz/corpus/` folder.
pub const TARGETS: [(&str, Target); 9] = [
    ("obj", obj_target),
    ("ply", ply_target),
    ("gltf", gltf_target),
    ("obj_chunks", obj_chunks_target),
    ("mtl", mtl_target),
    ("orbiter", orbiter_target),
    ("scene", scene_target),
    ("checkpoint", checkpoint_target),
    ("gunzip", gunzip_target),
];

/// Splits a fuzz input at its first NUL byte: the OBJ text before it and, when there is one, the
/// MTL text after it (given for every `mtllib` name; without a NUL every MTL is NotFound).
pub fn split_obj_mtl(data: &[u8]) -> (&[u8], Option<Vec<u8>>) {
    match data.iter().position(|&b| b == 0) {
        Some(nul) => (&data[..nul], Some(data[nul + 1..].to_vec())),
        None => (data, None),
    }
}

/// Target `obj`: `parse_obj` on OBJ text, optionally followed by a NUL and the MTL text that every
/// `mtllib` resolves to.
pub fn obj_target(data: &[u8]) -> Result<(), String> {
    let (obj, mtl) = split_obj_mtl(data);
    let file = Path::new(OBJ_NAME);
    check_obj(&parse_obj(obj, file, &mtl_resolver(mtl)), file, obj)
}

/// Target `obj_chunks`, differential: the chunked parallel OBJ parser must give exactly what one
/// chunk gives. The first byte picks the chunk size (1 to 256 bytes), the rest is the OBJ text.
pub fn obj_chunks_target(data: &[u8]) -> Result<(), String> {
    let Some((&size, obj)) = data.split_first() else { return Ok(()) };
    let file = Path::new(OBJ_NAME);
    let resolver = mtl_resolver(None);
    let chunked = parse_obj_with_chunk_size(obj, file, &resolver, usize::from(size) + 1);
    let whole = parse_obj_with_chunk_size(obj, file, &resolver, usize::MAX);
    check_obj(&whole, file, obj)?;
    same_obj(&chunked, &whole)
}

/// The OBJ that target `mtl` pairs with an MTL: one triangle without material, then one per
/// named `newmtl` among the MTL's first 16 lines (named as written), then one with an unknown name.
pub fn obj_using_mtl(mtl: &[u8]) -> Vec<u8> {
    let mut obj = b"mtllib fuzz.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec();
    for line in mtl.split(|&b| b == b'\n').take(16) {
        let name = line.trim_ascii_start().strip_prefix(b"newmtl").map(<[u8]>::trim_ascii);
        // `usemtl` without a name is an OBJ error, as is a NUL byte in an OBJ; such MTL lines
        // only cost a warning.
        if let Some(name) = name.filter(|name| name.first().is_some_and(|&b| b != b'#') && !name.contains(&0)) {
            obj.extend_from_slice(b"usemtl ");
            obj.extend_from_slice(name);
            obj.extend_from_slice(b"\nf 1 2 3\n");
        }
    }
    obj.extend_from_slice(b"usemtl not-in-the-mtl\nf -3 -2 -1\n");
    obj
}

/// Target `mtl`: the MTL parser, through `parse_obj` and [`obj_using_mtl`].
pub fn mtl_target(mtl: &[u8]) -> Result<(), String> {
    let obj = obj_using_mtl(mtl);
    let file = Path::new(OBJ_NAME);
    let result = parse_obj(&obj, file, &mtl_resolver(Some(mtl.to_vec())));
    check_obj(&result, file, &obj)?;
    let scene = result.map_err(|error| format!("the generated OBJ must parse: {error}"))?;
    if scene.mesh.indices.len() < 2 {
        return Err(format!("{} triangles from the generated OBJ", scene.mesh.indices.len()));
    }
    Ok(())
}

/// Target `orbiter`: `Orbiter::parse` on arbitrary bytes; an accepted orbiter must be finite and
/// give a camera whose rays can be generated without panicking.
pub fn orbiter_target(data: &[u8]) -> Result<(), String> {
    let file = Path::new(ORBITER_NAME);
    let result = Orbiter::parse(data, file);
    check_orbiter(&result, file, data)?;
    if let Ok(orbiter) = result {
        let camera = Camera::from_orbiter(&orbiter, 16, 12);
        for (x, y) in [(0.0, 0.0), (8.0, 6.0), (16.0, 12.0)] {
            std::hint::black_box(camera.ray(x, y));
        }
    }
    Ok(())
}

/// Target `ply`: `parse_ply` on a PLY file's bytes, ASCII or binary.
pub fn ply_target(data: &[u8]) -> Result<(), String> {
    let file = Path::new(PLY_NAME);
    match parse_ply(data, file) {
        Ok(scene) => check_ply_scene(&scene),
        Err(error) => check_ply_error(&error, file, data),
    }
}

/// Target `gltf`: `parse_gltf` on a `.gltf` (JSON) or `.glb` file's bytes, with a reader that
/// refuses every file it names (buffers must be in the GLB binary chunk or in `data:` URIs).
pub fn gltf_target(data: &[u8]) -> Result<(), String> {
    let file = Path::new(GLTF_NAME);
    let refuse = |path: &Path| Err(io::Error::new(io::ErrorKind::NotFound, format!("no file {}", path.display())));
    match parse_gltf(data, file, &refuse) {
        Ok(scene) => check_gltf_scene(&scene, file),
        Err(error) => check_gltf_error(&error, file),
    }
}

/// An accepted glTF scene is consistent and finite like any mesh; no file was read (the reader
/// refuses them all); every texture named as embedded in the file (`fuzz.gltf#imageN`) is in
/// `embedded_images`; texture transforms are finite; the scene's view (a camera) makes a camera
/// with finite rays, as the CLI takes it.
pub fn check_gltf_scene(scene: &Scene, file: &Path) -> Result<(), String> {
    check_mesh(&scene.mesh, &scene.materials, &scene.warnings)?;
    if let Some(view) = &scene.view {
        let camera = Camera::look_at(view.eye, view.target, view.up, view.fov_degrees, 8, 6)
            .map_err(|error| format!("a view the camera refuses ({error}): {view:?}"))?;
        let ray = camera.ray(0.0, 0.0);
        if !(ray.origin.is_finite() && ray.dir.is_finite()) {
            return Err(format!("a view whose rays are not finite ({ray:?}): {view:?}"));
        }
    }
    if !scene.sources.is_empty() {
        return Err(format!("files read through a reader that refuses them all: {:?}", scene.sources));
    }
    let embedded_prefix = format!("{}#image", file.display());
    for material in &scene.materials {
        let transform = &material.map_kd_transform;
        if !transform.scale.is_finite() || !transform.offset.is_finite() {
            return Err(format!("material {:?} has a non-finite texture transform: {transform:?}", material.name));
        }
        let Some(texture) = &material.map_kd else { continue };
        let embedded = texture.to_str().is_some_and(|name| name.starts_with(&embedded_prefix));
        if embedded && !scene.embedded_images.contains(texture) {
            return Err(format!("material {:?} uses {}, which is not embedded", material.name, texture.display()));
        }
    }
    Ok(())
}

/// A glTF error is one line that starts with the file's name, and short (a quoted token is cut).
pub fn check_gltf_error(error: &Error, file: &Path) -> Result<(), String> {
    let message = error.to_string();
    if message.contains('\n') {
        return Err(format!("error message spans several lines: {message:?}"));
    }
    if !message.starts_with(&format!("{}: ", file.display())) {
        return Err(format!("error does not start with \"{}: \": {message}", file.display()));
    }
    if message.len() > GLTF_MESSAGE_MAX {
        return Err(format!(
            "error message of {} bytes: {}...",
            message.len(),
            message.chars().take(200).collect::<String>()
        ));
    }
    Ok(())
}

/// The longest glTF error message accepted: a few quoted names (80 characters each) and numbers.
pub const GLTF_MESSAGE_MAX: usize = 1000;

/// Target `scene`, end to end: input as for `obj`; whatever parses must also become a scene, a
/// BVH and an 8x6 image in every mode (1 sample) without panicking, with finite pixels.
pub fn scene_target(data: &[u8]) -> Result<(), String> {
    let (obj, mtl) = split_obj_mtl(data);
    let file = Path::new(OBJ_NAME);
    let result = parse_obj(obj, file, &mtl_resolver(mtl));
    check_obj(&result, file, obj)?;
    let Ok(obj) = result else { return Ok(()) };
    let scene = obj.into_scene(OBJ_NAME.to_string()).map_err(|e| format!("consistent OBJ refused: {e}"))?;
    let bounds = scene.bounds();
    // The CLI's default framing (src/cli/render.rs), or a fixed view of an empty scene.
    let (eye, target) = if bounds.is_empty() {
        (glam::Vec3::new(0.0, 0.0, 5.0), glam::Vec3::ZERO)
    } else {
        let radius = 0.5 * bounds.extent().length();
        let distance = radius / (0.5 * 45f32.to_radians()).sin();
        (bounds.center() + glam::Vec3::Z * distance.max(1e-6), bounds.center())
    };
    // Framing a scene with coordinates near f32::MAX can fail (eye == target); the CLI reports it.
    let Ok(camera) = Camera::look_at(eye, target, glam::Vec3::Y, 45.0, 8, 6) else { return Ok(()) };
    let world = World::new(scene, Default::default());
    let techniques = [
        Technique::Hits(Default::default()),
        Technique::Materials(Default::default()),
        Technique::Shadows(Default::default()),
        Technique::direct(1),
        Technique::ambient_occlusion(1),
        Technique::Path(Default::default()),
    ];
    for mode in techniques {
        let output = render(&world, &camera, &RenderOptions::new(mode), &|_| {})
            .map_err(|e| format!("{mode:?}: valid options refused: {e}"))?;
        if output.image.pixels.len() != 8 * 6 {
            return Err(format!("{mode:?}: {} pixels for 8x6", output.image.pixels.len()));
        }
        if let Some(p) = output.image.pixels.iter().find(|p| !p.is_finite()) {
            return Err(format!("{mode:?}: non-finite pixel {p}"));
        }
    }
    Ok(())
}

/// An MTL resolver for `parse_obj`: every name resolves to `mtl` (read from `folder/<name>`), or,
/// with `None`, to a NotFound error.
pub fn mtl_resolver(mtl: Option<Vec<u8>>) -> impl Fn(&str) -> io::Result<(Vec<u8>, PathBuf)> {
    move |name: &str| match &mtl {
        Some(bytes) => Ok((bytes.clone(), Path::new("fuzz").join(name))),
        None => Err(io::Error::new(io::ErrorKind::NotFound, format!("no file {name:?}"))),
    }
}

/// Number of lines as the parsers count them: one more than the number of `\n` bytes.
pub fn line_count(bytes: &[u8]) -> usize {
    bytes.iter().filter(|&&b| b == b'\n').count() + 1
}

/// A parse error must be one line, name `file`, and point at a line of the input.
pub fn check_error(error: &Error, file: &Path, lines: usize) -> Result<(), String> {
    let message = error.to_string();
    if message.contains('\n') {
        return Err(format!("error message spans several lines: {message:?}"));
    }
    match error {
        Error::Parse { file: named, line, .. } => {
            if named != file {
                return Err(format!("error names {} instead of {}: {message}", named.display(), file.display()));
            }
            if *line == 0 || *line > lines {
                return Err(format!("error at line {line} of a {lines}-line input: {message}"));
            }
            if !message.starts_with(&format!("{}:{line}: ", file.display())) {
                return Err(format!("error does not start with file:line: {message}"));
            }
            Ok(())
        }
        other => Err(format!("expected a parse error with file and line, got {other:?}")),
    }
}

/// Everything `parse_obj` returned is consistent and finite.
pub fn check_obj_scene(scene: &ObjScene) -> Result<(), String> {
    check_mesh(&scene.mesh, &scene.materials, &scene.warnings)
}

/// Everything `parse_ply` returned is consistent and finite.
pub fn check_ply_scene(scene: &Scene) -> Result<(), String> {
    check_mesh(&scene.mesh, &scene.materials, &scene.warnings)
}

/// A PLY error is one line naming the file and where: a line of the header or of an ASCII body,
/// or a byte of a binary body (`fuzz.ply: byte N: ...`, N within the input).
pub fn check_ply_error(error: &Error, file: &Path, bytes: &[u8]) -> Result<(), String> {
    let Error::Invalid(message) = error else { return check_error(error, file, line_count(bytes)) };
    let place = message.strip_prefix(&format!("{}: byte ", file.display())).and_then(|rest| rest.split_once(": "));
    match place.map(|(byte, _)| byte.parse::<usize>()) {
        _ if message.contains('\n') => Err(format!("error message spans several lines: {message:?}")),
        Some(Ok(byte)) if byte <= bytes.len() => Ok(()),
        _ => Err(format!("expected file:line or file: byte N within the {} bytes, got: {message}", bytes.len())),
    }
}

/// A mesh, its materials and warnings are consistent and finite.
fn check_mesh(mesh: &TriangleMesh, materials: &[Material], warnings: &[String]) -> Result<(), String> {
    let triangles = mesh.indices.len();
    if let Some((i, p)) = mesh.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
        return Err(format!("position {i} is not finite: {p}"));
    }
    if let Some((i, n)) = mesh.normals.iter().enumerate().find(|(_, n)| !n.is_finite()) {
        return Err(format!("normal {i} is not finite: {n}"));
    }
    if let Some((i, t)) = mesh.texcoords.iter().enumerate().find(|(_, t)| !t.is_finite()) {
        return Err(format!("texture coordinate {i} is not finite: {t}"));
    }
    for (t, triangle) in mesh.indices.iter().enumerate() {
        if let Some(&i) = triangle.iter().find(|&&i| i as usize >= mesh.positions.len()) {
            return Err(format!("triangle {t} uses position {i} of {}", mesh.positions.len()));
        }
    }
    if mesh.material_ids.len() != triangles {
        return Err(format!("{} material ids for {triangles} triangles", mesh.material_ids.len()));
    }
    if let Some((t, &m)) = mesh.material_ids.iter().enumerate().find(|(_, m)| **m as usize >= materials.len()) {
        return Err(format!("triangle {t} has material {m} of {}", materials.len()));
    }
    let attributes = [
        ("normal", &mesh.normal_indices, mesh.normals.len()),
        ("texture coordinate", &mesh.texcoord_indices, mesh.texcoords.len()),
    ];
    for (what, list, len) in attributes {
        if !list.is_empty() && list.len() != triangles {
            return Err(format!("{} {what} index triples for {triangles} triangles", list.len()));
        }
        for (t, corners) in list.iter().enumerate() {
            if let Some(&i) = corners.iter().find(|&&i| i != NO_INDEX && i as usize >= len) {
                return Err(format!("triangle {t} uses {what} {i} of {len}"));
            }
        }
    }
    for material in materials {
        let numbers = [material.kd, material.ks, material.ke];
        let scalars = [material.ns, material.ni, material.dissolve];
        if !numbers.iter().all(|v| v.is_finite()) || !scalars.iter().all(|v| v.is_finite()) {
            return Err(format!("material {:?} has a non-finite value: {material:?}", material.name));
        }
    }
    if let Some(warning) = warnings.iter().find(|w| w.contains('\n')) {
        return Err(format!("warning spans several lines: {warning:?}"));
    }
    Ok(())
}

/// Checks a `parse_obj(bytes, file, ..)` result.
pub fn check_obj(result: &lumiere::Result<ObjScene>, file: &Path, bytes: &[u8]) -> Result<(), String> {
    match result {
        Ok(scene) => check_obj_scene(scene),
        Err(error) => check_error(error, file, line_count(bytes)),
    }
}

/// Checks an `Orbiter::parse(bytes, file)` result; an accepted orbiter must be finite and give a
/// camera whose rays are finite.
pub fn check_orbiter(result: &lumiere::Result<Orbiter>, file: &Path, bytes: &[u8]) -> Result<(), String> {
    match result {
        Ok(orbiter) => {
            let (fov, w, h) = orbiter.frame.unwrap_or((45.0, 1.0, 1.0));
            let finite = orbiter.center.is_finite()
                && orbiter.pan.is_finite()
                && orbiter.rotation.is_finite()
                && orbiter.size.is_finite()
                && orbiter.radius.is_finite()
                && [fov, w, h].iter().all(|v| v.is_finite());
            if !finite {
                return Err(format!("accepted a non-finite orbiter: {orbiter:?}"));
            }
            let ray = Camera::from_orbiter(orbiter, 8, 6).ray(4.0, 3.0);
            if !(ray.origin.is_finite() && ray.dir.is_finite()) {
                return Err(format!("accepted an orbiter whose rays are not finite ({ray:?}): {orbiter:?}"));
            }
            Ok(())
        }
        Err(error) => check_error(error, file, line_count(bytes)),
    }
}

/// Target `checkpoint`: `Checkpoint::decode`. The first byte is a flag: when its low bit is set,
/// the last 8 bytes of the rest are replaced by the checksum of the bytes before them, so that the
/// fuzzer gets past the checksum to the header and size checks behind it. An accepted checkpoint
/// must be consistent and encode back to the same bytes.
pub fn checkpoint_target(data: &[u8]) -> Result<(), String> {
    let Some((&flags, rest)) = data.split_first() else { return Ok(()) };
    let bytes = if flags & 1 == 1 && rest.len() >= 8 { with_checksum(&rest[..rest.len() - 8]) } else { rest.to_vec() };
    let file = Path::new(CHECKPOINT_NAME);
    match Checkpoint::decode(&bytes, file) {
        Ok(checkpoint) => {
            let film = &checkpoint.film;
            if film.width == 0 || film.height == 0 || film.pixel_count() != film.width as usize * film.height as usize {
                return Err(format!(
                    "accepted a {}x{} film with {} pixels",
                    film.width,
                    film.height,
                    film.pixel_count()
                ));
            }
            // Elapsed time goes through `Duration` (nanoseconds): compare everything but it.
            let mut encoded =
                checkpoint.encode().map_err(|e| format!("cannot encode the checkpoint it accepted: {e}"))?;
            let elapsed = 8 + 4 + 8 + 8 + 4 + 4 + 4 + 8 + 8 + 8;
            let mut original = bytes.clone();
            for buffer in [&mut encoded, &mut original] {
                buffer[elapsed..elapsed + 8].fill(0);
                let len = buffer.len();
                buffer.truncate(len - 8);
            }
            if encoded != original { Err("decode then encode changes the checkpoint".to_string()) } else { Ok(()) }
        }
        Err(error) => {
            let message = error.to_string();
            if message.contains('\n') || !message.starts_with(&format!("{CHECKPOINT_NAME}: ")) {
                return Err(format!("error is not one line naming the file: {message:?}"));
            }
            Ok(())
        }
    }
}

/// Target `gunzip`: `util::read::gunzip`, the inflation of `.obj.gz` files with its size limit.
/// First byte: the limit, in units of 64 bytes (0 to 16,320, small so that inputs meet it often);
/// rest: the file. Whatever it accepts must fit the limit and come back the same when the limit
/// is exactly its size or when zero padding follows the stream, and one byte less must be refused
/// as too large; whatever it refuses, it refuses with one line.
pub fn gunzip_target(data: &[u8]) -> Result<(), String> {
    use lumiere::util::read::gunzip;
    let Some((&units, raw)) = data.split_first() else { return Ok(()) };
    let limit = u64::from(units) * 64;
    let text = match gunzip(raw, limit) {
        Ok(text) => text,
        Err(error) => {
            let message = error.to_string();
            return if message.is_empty() || message.contains('\n') {
                Err(format!("error is not one line: {message:?}"))
            } else {
                Ok(())
            };
        }
    };
    let size = text.len() as u64;
    if size > limit {
        return Err(format!("inflated {size} bytes over a limit of {limit}"));
    }
    let same = |result: io::Result<Vec<u8>>, what: &str| match result {
        Ok(again) if again == text => Ok(()),
        Ok(again) => Err(format!("{what}: {} bytes, not the {size} inflated first", again.len())),
        Err(error) => Err(format!("{what}: refused ({error}) after {size} bytes were accepted")),
    };
    same(gunzip(raw, size), "a limit of exactly the inflated size")?;
    same(gunzip(&[raw, &[0; 16]].concat(), limit), "the same stream followed by zero padding")?;
    if size > 0 {
        match gunzip(raw, size - 1) {
            Err(error) if error.kind() == io::ErrorKind::OutOfMemory => {}
            Err(error) => return Err(format!("a limit one byte short gives another error: {error}")),
            Ok(short) => return Err(format!("a limit one byte short still gives {} bytes", short.len())),
        }
    }
    Ok(())
}

/// Header fields of checkpoint bytes (after the magic), if they are long enough to hold them:
/// `(width, height, elapsed seconds)`.
pub fn checkpoint_header(bytes: &[u8]) -> Option<(u32, u32, f64)> {
    let field = |at: usize, len: usize| bytes.get(at..at + len);
    let u32_at = |at| field(at, 4).map(|b| u32::from_le_bytes(b.try_into().unwrap()));
    let elapsed = field(8 + 4 + 8 + 8 + 4 + 4 + 4 + 8 + 8 + 8, 8).map(|b| f64::from_le_bytes(b.try_into().unwrap()))?;
    Some((u32_at(8 + 4 + 8 + 8)?, u32_at(8 + 4 + 8 + 8 + 4)?, elapsed))
}

/// `body` followed by its checkpoint checksum (the file layout of `src/checkpoint.rs`).
pub fn with_checksum(body: &[u8]) -> Vec<u8> {
    use std::hash::Hasher;
    let mut hasher = StableHasher::default();
    hasher.write(body);
    [body, &hasher.finish().to_le_bytes()].concat()
}

/// The options text of [`raw_checkpoint`]'s files.
pub const RAW_OPTIONS: &str = "technique: Hits(Hits)\nseed: 7\n";

/// A checkpoint file written field by field, with a valid checksum: `pixels` pixels of data
/// (whatever `width` and `height` say), for crafting inconsistent files.
pub fn raw_checkpoint(width: u32, height: u32, samples: u32, elapsed: f64, pixels: usize) -> Vec<u8> {
    let mut body = b"LUMCKPT1".to_vec();
    body.extend_from_slice(&2u32.to_le_bytes());
    body.extend_from_slice(&0x5C3u64.to_le_bytes());
    body.extend_from_slice(&0x0F7u64.to_le_bytes());
    for v in [width, height, samples] {
        body.extend_from_slice(&v.to_le_bytes());
    }
    for v in [7u64, 1000, 0] {
        body.extend_from_slice(&v.to_le_bytes());
    }
    body.extend_from_slice(&elapsed.to_le_bytes());
    for i in 0..pixels * 4 {
        body.extend_from_slice(&(i as f64 * 0.25).to_le_bytes());
    }
    body.extend_from_slice(&(RAW_OPTIONS.len() as u32).to_le_bytes());
    body.extend_from_slice(RAW_OPTIONS.as_bytes());
    with_checksum(&body)
}

/// Two results of the same input must agree: same error text, or the same mesh and materials.
/// Used to compare chunked parallel parsing with a single chunk.
pub fn same_obj(a: &lumiere::Result<ObjScene>, b: &lumiere::Result<ObjScene>) -> Result<(), String> {
    match (a, b) {
        (Err(a), Err(b)) if a.to_string() == b.to_string() => Ok(()),
        (Ok(a), Ok(b)) => {
            let (x, y) = (&a.mesh, &b.mesh);
            // Compare bit patterns: -0.0 and 0.0 differ, and NaN never appears (checked elsewhere).
            let bits = |v: &[glam::Vec3]| v.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
            let same = bits(&x.positions) == bits(&y.positions)
                && x.indices == y.indices
                && x.material_ids == y.material_ids
                && bits(&x.normals) == bits(&y.normals)
                && x.normal_indices == y.normal_indices
                && x.texcoords == y.texcoords
                && x.texcoord_indices == y.texcoord_indices
                && a.materials == b.materials
                && a.warnings == b.warnings;
            if same { Ok(()) } else { Err("chunked and single-chunk parses differ".to_string()) }
        }
        (a, b) => Err(format!(
            "chunked and single-chunk parses differ: {:?} vs {:?}",
            a.as_ref().map(|s| s.mesh.indices.len()).map_err(ToString::to_string),
            b.as_ref().map(|s| s.mesh.indices.len()).map_err(ToString::to_string)
        )),
    }
}

/// Runs `target(data)` on its own thread: a panic becomes `Err(panic message)` and a run longer
/// than `deadline` becomes `Err` too (the thread is left behind), so a test reports the input
/// instead of dying or hanging. Errors quote the input (its first 400 bytes, escaped).
pub fn guarded(target: Target, data: &[u8], deadline: std::time::Duration) -> Result<(), String> {
    let (send, receive) = std::sync::mpsc::channel();
    let input = data.to_vec();
    let start = std::time::Instant::now();
    std::thread::spawn(move || {
        let result = std::panic::catch_unwind(|| target(&input)).unwrap_or_else(|panic| {
            let message = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(format!("PANIC: {message}"))
        });
        let _ = send.send(result);
    });
    let result = match receive.recv_timeout(deadline) {
        Ok(result) => result,
        Err(_) => Err(format!("HANG: still running after {deadline:?}")),
    };
    result.map_err(|problem| {
        format!("{problem} ({:.2?})\n  input ({} bytes): {}", start.elapsed(), data.len(), escaped(data, 400))
    })
}

/// `data` as a Rust byte-string literal, cut after `max` bytes.
pub fn escaped(data: &[u8], max: usize) -> String {
    let shown: String = data[..data.len().min(max)].escape_ascii().to_string();
    if data.len() > max { format!("b\"{shown}\"...") } else { format!("b\"{shown}\"") }
}
