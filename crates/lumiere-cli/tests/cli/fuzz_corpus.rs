//! The corpus of hostile inputs as regression tests (see docs/FUZZING.md).
//!
//! * `tests/corpus/{obj,mtl,orbiter,checkpoint}/`: small hand-written nasty files (truncations,
//!   binary garbage, integer and float limits, odd MTL, broken gzip, forged checkpoints). Every one
//!   must load into a consistent scene or fail with a one-line error naming the file (and the line
//!   for text errors), in-process and through the binary. Files named `fixed-bug-*` reproduce a
//!   bug fuzzing found (since fixed): the loops skip them and a dedicated test checks each.
//! * `fuzz/corpus/<target>/`: the minimised corpus the libFuzzer targets grew; replayed through the
//!   same harness functions (`fuzz/src/harness.rs`), so CI checks them on stable Rust.
//! * Inputs too big to commit are generated here: a face with 10^6 corners, a gzip bomb, absurd
//!   image sizes.

use crate::harness::{check_error, check_obj_scene, check_orbiter, guarded, line_count, mtl_resolver};
use crate::process::{Limits, TempDir, check_exit, error_line, run};
use flate2::Compression;
use flate2::write::GzEncoder;
use lumiere::Error;
use lumiere::integrators::Technique;
use lumiere::render::checkpoint::Checkpoint;
use lumiere::render::{RenderOptions, render};
use lumiere::scene::camera::{Camera, Orbiter};
use lumiere::scene::load::obj::{ObjScene, load_obj, parse_obj};
use lumiere::world::World;
use std::ffi::OsStr;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/corpus");
const FUZZ_CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fuzz/corpus");
const DEADLINE: Duration = Duration::from_secs(20);

fn lumiere() -> &'static Path {
    Path::new(env!("CARGO_BIN_EXE_lumiere"))
}

/// The files of `dir` whose names end with one of `suffixes`, sorted; none if `dir` is missing.
fn files(dir: &str, suffixes: &[&str]) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut files: Vec<PathBuf> = entries
        .map(|entry| entry.expect("read corpus dir").path())
        .filter(|path| path.is_file())
        .filter(|path| suffixes.is_empty() || suffixes.iter().any(|s| path.to_string_lossy().ends_with(s)))
        .collect();
    files.sort();
    files
}

/// Corpus files that reproduce a bug fuzzing found (each has its own test).
fn is_fixed_bug(path: &Path) -> bool {
    path.file_name().is_some_and(|name| name.to_string_lossy().starts_with("fixed-bug-"))
}

/// Runs `check` on every file, in a guarded thread each, and fails listing every file that broke.
fn check_all(files: &[PathBuf], check: crate::harness::Target) {
    assert!(!files.is_empty(), "no corpus files found");
    let failures: Vec<String> = files
        .iter()
        .filter(|path| !is_fixed_bug(path))
        .filter_map(|path| {
            let name = path.to_str().expect("corpus paths are UTF-8").as_bytes();
            guarded(check, name, DEADLINE).err().map(|problem| format!("{}: {problem}", path.display()))
        })
        .collect();
    assert!(failures.is_empty(), "{} of {} corpus files failed:\n{}", failures.len(), files.len(), failures.join("\n"));
}

fn path_of(data: &[u8]) -> PathBuf {
    PathBuf::from(std::str::from_utf8(data).expect("UTF-8 path"))
}

/// `load_obj(path)`: a consistent scene, or an error naming the file (and a line of it for text).
fn load_checked(data: &[u8]) -> Result<(), String> {
    let path = path_of(data);
    let gzipped = path.extension().is_some_and(|e| e == "gz");
    match load_obj(&path) {
        Ok(scene) => check_obj_scene(&scene),
        Err(Error::Io { path: named, .. }) if gzipped && named == path => Ok(()),
        Err(error) if gzipped => check_error(&error, &path, usize::MAX),
        Err(error) => check_error(&error, &path, line_count(&std::fs::read(&path).unwrap())),
    }
}

fn orbiter_checked(data: &[u8]) -> Result<(), String> {
    let path = path_of(data);
    let bytes = std::fs::read(&path).unwrap();
    check_orbiter(&Orbiter::parse(&bytes, &path), &path, &bytes)?;
    match Orbiter::load(&path) {
        Ok(orbiter) => {
            let camera = Camera::from_orbiter(&orbiter, 8, 6);
            std::hint::black_box(camera.ray(4.0, 3.0));
            Ok(())
        }
        Err(error) => check_error(&error, &path, line_count(&bytes)),
    }
}

fn mtl_checked(data: &[u8]) -> Result<(), String> {
    crate::harness::mtl_target(&std::fs::read(path_of(data)).unwrap())
}

/// A checkpoint file: the `checkpoint` fuzz target's checks on its bytes, and `Checkpoint::load`
/// must refuse it with its own path or accept it.
fn checkpoint_checked(data: &[u8]) -> Result<(), String> {
    let path = path_of(data);
    let bytes = std::fs::read(&path).unwrap();
    crate::harness::checkpoint_target(&[&[0u8][..], &bytes].concat())?;
    match Checkpoint::load(&path) {
        Ok(_) => Ok(()),
        Err(error) if error.to_string().starts_with(&format!("{}: ", path.display())) => Ok(()),
        Err(error) => Err(format!("error does not name the file: {error}")),
    }
}

#[test]
fn corpus_checkpoint_files_load_or_fail_naming_the_file() {
    check_all(&files(&format!("{CORPUS}/checkpoint"), &[]), checkpoint_checked);
}

#[test]
fn forged_checkpoints_are_refused_for_their_reason() {
    let cases = [
        ("empty.ckpt", "no checkpoint header"),
        ("magic-only.ckpt", "no checkpoint header"),
        ("truncated-header.ckpt", "no checkpoint header"),
        ("wrong-magic.ckpt", "no checkpoint header"),
        ("binary-garbage.ckpt", "no checkpoint header"),
        ("truncated-pixels.ckpt", "checksum does not match"),
        ("bad-checksum.ckpt", "checksum does not match"),
        // Written when version 2 did not exist: a version-2 header over a version-1 body.
        ("version-2.ckpt", "its size does not match its pixel data"),
        ("valid-1x1.ckpt", "version 1, written by an older lumiere"),
        ("valid-3x2.ckpt", "version 1, written by an older lumiere"),
        ("zero-width.ckpt", "its size does not match its pixel data"),
        ("size-mismatch.ckpt", "its size does not match its pixel data"),
        ("nan-elapsed.ckpt", "invalid elapsed time"),
        ("negative-elapsed.ckpt", "invalid elapsed time"),
        ("inf-elapsed.ckpt", "invalid elapsed time"),
    ];
    for (file, reason) in cases {
        let path = Path::new(CORPUS).join("checkpoint").join(file);
        match Checkpoint::load(&path) {
            Ok(_) => panic!("{file}: accepted"),
            Err(error) => {
                let message = error.to_string();
                let prefix = format!("{}: not a valid lumiere checkpoint", path.display());
                assert!(message.starts_with(&prefix) && message.contains(reason), "{file}: {message}");
            }
        }
    }
    // A valid file written field by field (not by `Checkpoint::encode`) loads exactly.
    let dir = TempDir::new("valid-ckpt");
    let path = dir.write("valid-3x2.ckpt", &crate::harness::raw_checkpoint(3, 2, 16, 12.5, 6));
    let valid = Checkpoint::load(&path).unwrap();
    assert_eq!((valid.film.width, valid.film.height, valid.film.samples, valid.seed), (3, 2, 16, 7));
    assert_eq!(valid.stats.elapsed, Duration::from_secs_f64(12.5));
    assert_eq!(valid.options, crate::harness::RAW_OPTIONS);
    let mut future = crate::harness::raw_checkpoint(1, 1, 1, 0.0, 1);
    future[8..12].copy_from_slice(&9u32.to_le_bytes());
    let future = dir.write("future.ckpt", &crate::harness::with_checksum(&future[..future.len() - 8]));
    let message = Checkpoint::load(&future).unwrap_err().to_string();
    assert!(message.contains("unsupported version 9"), "{message}");
    // With a recomputed checksum, sums no render can hold: a NaN, a negative value, and sums in
    // a film of no samples (which resumed as a NaN pixel, and as an AO of 1.5).
    let pixel_value = |pixel: usize, value: usize| 72 + (pixel * 4 + value) * 8;
    let forged = |samples: u32, change: &[(usize, f64)]| {
        let mut bytes = crate::harness::raw_checkpoint(3, 2, samples, 1.0, 6);
        for &(at, v) in change {
            bytes[at..at + 8].copy_from_slice(&v.to_le_bytes());
        }
        crate::harness::with_checksum(&bytes[..bytes.len() - 8])
    };
    let impossible = [
        ("nan.ckpt", forged(4, &[(pixel_value(1, 2), f64::NAN)]), "pixel 1 holds a negative or non-finite sum"),
        ("negative.ckpt", forged(4, &[(pixel_value(0, 3), -1.0)]), "pixel 0 holds a negative or non-finite sum"),
        ("infinite.ckpt", forged(4, &[(pixel_value(5, 0), f64::INFINITY)]), "pixel 5 holds a negative or non-finite"),
        ("no-samples.ckpt", forged(0, &[]), "pixel 0 holds sums in a film of no samples"),
    ];
    for (file, bytes, reason) in impossible {
        let path = dir.write(file, &bytes);
        let message = Checkpoint::load(&path).map(|_| ()).unwrap_err().to_string();
        assert!(message.contains("not a valid lumiere checkpoint") && message.contains(reason), "{file}: {message}");
    }
    // A film of no samples whose sums are all zero is a checkpoint written before the first pass.
    let empty = forged(0, &(0..24).map(|value| (72 + value * 8, 0.0)).collect::<Vec<_>>());
    assert_eq!(Checkpoint::load(&dir.write("empty.ckpt", &empty)).unwrap().film.samples, 0);
}

/// A checkpoint with a valid checksum whose elapsed time (1e20 s) is finite but does not fit a
/// `Duration`: `Duration::from_secs_f64` panics ("cannot convert float seconds to Duration: value
/// is either too big or NaN"). Found by the `checkpoint` fuzz target in under a second.
#[test]
fn checkpoint_with_huge_elapsed_time_is_refused() {
    for elapsed in [1e20, f64::MAX, u64::MAX as f64] {
        let bytes = crate::harness::raw_checkpoint(1, 1, 1, elapsed, 1);
        let outcome = guarded(
            |bytes| match Checkpoint::decode(bytes, Path::new("huge.ckpt")) {
                Ok(c) => Err(format!("accepted an elapsed time of {:?}", c.stats.elapsed)),
                Err(e) if e.to_string().starts_with("huge.ckpt: ") => Ok(()),
                Err(e) => Err(format!("error does not name the file: {e}")),
            },
            &bytes,
            DEADLINE,
        );
        outcome.unwrap_or_else(|problem| panic!("elapsed {elapsed:e}: {problem}"));
    }
}

/// A 2147483648 x 2147483648 checkpoint with no pixel data and a valid checksum: the byte count
/// `width * height * 32` wraps to 0 in release builds and matches the empty data (in debug builds
/// the multiplication overflows and panics), then `Film::new`'s memory check wraps too
/// (`width * height * 76` = 0 bytes) and `vec!` panics with "capacity overflow".
#[test]
fn checkpoint_with_wrapping_size_is_refused() {
    let bytes = crate::harness::raw_checkpoint(1 << 31, 1 << 31, 1, 0.0, 0);
    let outcome = guarded(
        |bytes| match Checkpoint::decode(bytes, Path::new("wrap.ckpt")) {
            Ok(c) => Err(format!("accepted a {}x{} film", c.film.width, c.film.height)),
            Err(e) if e.to_string().starts_with("wrap.ckpt: ") => Ok(()),
            Err(e) => Err(format!("error does not name the file: {e}")),
        },
        &bytes,
        DEADLINE,
    );
    outcome.unwrap_or_else(|problem| panic!("{problem}"));
}

/// Every corpus checkpoint through `lumiere render --resume`: one error line naming the file
/// (none of them matches the built-in scene's fingerprints), never a panic.
#[test]
fn cli_resume_refuses_every_corpus_checkpoint() {
    let dir = TempDir::new("cli-resume");
    let mut failures = Vec::new();
    for checkpoint in files(&format!("{CORPUS}/checkpoint"), &[]).into_iter().filter(|p| !is_fixed_bug(p)) {
        let outcome = resume(&dir, &checkpoint);
        if let Err(problem) = outcome {
            failures.push(problem);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `lumiere render --resume <checkpoint>` must exit 2 with one error line naming the checkpoint.
fn resume(dir: &TempDir, checkpoint: &Path) -> Result<(), String> {
    let out = dir.path("resumed.png");
    let args: Vec<&OsStr> = ["render", "--size", "8x6", "--mode", "hits", "--threads", "1", "--resume"]
        .map(OsStr::new)
        .into_iter()
        .chain([checkpoint.as_os_str(), "-o".as_ref(), out.as_os_str()])
        .collect();
    let result = run(lumiere(), &args, &dir.0, Limits::default());
    let named = format!("lumiere: error: {}: ", checkpoint.display());
    check_exit(&result, false)
        .and_then(|()| match error_line(&result) {
            Some(error) if error.starts_with(&named) => Ok(()),
            Some(error) => Err(format!("error does not name the checkpoint: {error}")),
            None => Err("resumed from a checkpoint of another scene".to_string()),
        })
        .map_err(|problem| format!("{problem}: {}", result.describe(&args)))
}

/// The two checkpoint bugs through the binary: exit 2 with a clear error (they panicked, exit 101).
#[test]
fn cli_resume_refuses_fixed_bug_checkpoints() {
    let dir = TempDir::new("cli-resume-bugs");
    let failures: Vec<String> = files(&format!("{CORPUS}/checkpoint"), &[])
        .into_iter()
        .filter(|p| is_fixed_bug(p))
        .filter_map(|checkpoint| resume(&dir, &checkpoint).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn corpus_obj_files_load_or_fail_naming_file_and_line() {
    check_all(&files(&format!("{CORPUS}/obj"), &[".obj", ".obj.gz"]), load_checked);
}

#[test]
fn corpus_mtl_files_give_consistent_materials() {
    let mut all = files(&format!("{CORPUS}/mtl"), &[]);
    all.extend(files(&format!("{CORPUS}/obj"), &[".mtl"]));
    check_all(&all, mtl_checked);
}

#[test]
fn corpus_orbiter_files_parse_or_fail_naming_file_and_line() {
    check_all(&files(&format!("{CORPUS}/orbiter"), &[]), orbiter_checked);
}

/// Replays what the libFuzzer targets found (`fuzz/corpus/<target>/`) through the same checks.
#[test]
fn libfuzzer_corpus_replays_cleanly() {
    let mut failures = Vec::new();
    let mut count = 0;
    for (target, check) in crate::harness::TARGETS {
        for path in files(&format!("{FUZZ_CORPUS}/{target}"), &[]) {
            count += 1;
            let data = std::fs::read(&path).unwrap();
            if let Err(problem) = guarded(check, &data, DEADLINE) {
                failures.push(format!("{target} {}: {problem}", path.display()));
            }
        }
    }
    assert!(count > 0, "no libFuzzer corpus under {FUZZ_CORPUS}");
    assert!(failures.is_empty(), "{} of {count} entries failed:\n{}", failures.len(), failures.join("\n"));
}

fn obj_error(path: &str) -> String {
    let path = Path::new(CORPUS).join(path);
    match load_obj(&path) {
        Ok(scene) => panic!("{}: expected an error, got {} triangles", path.display(), scene.mesh.triangle_count()),
        Err(error) => {
            let message = error.to_string();
            let relative = message.strip_prefix(&format!("{}", Path::new(CORPUS).display())).map(str::to_string);
            relative.unwrap_or(message)
        }
    }
}

fn obj_ok(path: &str) -> ObjScene {
    let path = Path::new(CORPUS).join(path);
    let scene = load_obj(&path).unwrap_or_else(|error| panic!("{error}"));
    check_obj_scene(&scene).unwrap();
    scene
}

#[test]
fn truncated_obj_files_fail_at_the_cut() {
    let cases = [
        ("obj/truncated-mid-line.obj", "/obj/truncated-mid-line.obj:4: face with 2 corner(s)"),
        ("obj/truncated-mid-number.obj", "/obj/truncated-mid-number.obj:5: malformed number \"1.5e\""),
        ("obj/truncated-after-sign.obj", "/obj/truncated-after-sign.obj:5: malformed number \"-\""),
        ("obj/truncated-mid-corner.obj", "/obj/truncated-mid-corner.obj:5: malformed face corner \"1/\""),
    ];
    for (file, expected) in cases {
        let message = obj_error(file);
        assert!(message.starts_with(expected), "{file}: {message:?} does not start with {expected:?}");
    }
    // An unknown keyword cut short is skipped like any unknown statement.
    assert_eq!(obj_ok("obj/truncated-mid-keyword.obj").mesh.triangle_count(), 1);
    for gz in ["truncated.obj.gz", "truncated-header.obj.gz", "bad-crc.obj.gz", "not-gzip.obj.gz"] {
        let message = obj_error(&format!("obj/{gz}"));
        assert!(message.starts_with(&format!("/obj/{gz}: ")), "{gz}: {message:?}");
    }
}

#[test]
fn indices_near_integer_limits_are_refused_with_their_line() {
    let cases = [
        ("index-i64-limits.obj", 4, "position index 9223372036854775807 out of range: the file defines 3"),
        ("index-i64-min-relative.obj", 4, "position index -9223372036854775808 out of range: 3 defined before"),
        ("index-past-i64.obj", 4, "position index 99999999999999999999999999 out of range"),
        ("index-past-i64-negative.obj", 4, "position index -99999999999999999999999999 out of range"),
        ("index-u32-max.obj", 4, "position index 4294967295 out of range"),
        ("index-u32-max-plus-one.obj", 4, "position index 4294967296 out of range"),
        ("index-zero.obj", 4, "position index 0: OBJ indices start at 1"),
        ("index-relative-before-any-vertex.obj", 1, "position index -1 out of range: 0 defined before"),
    ];
    for (file, line, needle) in cases {
        let message = obj_error(&format!("obj/{file}"));
        let prefix = format!("/obj/{file}:{line}: ");
        assert!(message.starts_with(&prefix) && message.contains(needle), "{file}: {message:?}");
    }
    // Indices past the end are fine when the vertex comes later in the file (as tinyobjloader).
    assert_eq!(obj_ok("obj/forward-reference.obj").mesh.indices, vec![[0, 1, 2]]);
    // Texture-coordinate and normal indices out of range are dropped for their corner, with one
    // warning naming the first such face, as mainstream loaders accept them.
    let cases = [
        ("texcoord-index-i64-max.obj", "5: 1 face has texture-coordinate indices out of range", 1),
        ("normal-index-i64-min.obj", "5: 1 face has normal indices out of range", 2),
    ];
    for (file, needle, corner) in cases {
        let scene = obj_ok(&format!("obj/{file}"));
        assert_eq!(scene.warnings.len(), 1, "{file}: {:?}", scene.warnings);
        assert!(scene.warnings[0].contains(&format!("{file}:{needle}")), "{file}: {:?}", scene.warnings);
        let indices = [&scene.mesh.texcoord_indices, &scene.mesh.normal_indices][corner - 1];
        assert_eq!(indices[0][corner - 1], lumiere::scene::mesh::NO_INDEX, "{file}");
    }
}

#[test]
fn non_finite_numbers_are_refused_like_nan() {
    let cases = [
        ("vertex-1e39.obj", "number \"1e39\" is not finite"),
        ("vertex-minus-1e39.obj", "number \"-1e39\" is not finite"),
        ("vertex-nan.obj", "number \"NaN\" is not finite"),
        ("vertex-inf.obj", "number \"inf\" is not finite"),
        ("vertex-minus-infinity.obj", "number \"-infinity\" is not finite"),
        ("normal-nan.obj", "number \"nan\" is not finite"),
        ("texcoord-1e39.obj", "number \"1e39\" is not finite"),
    ];
    for (file, needle) in cases {
        let message = obj_error(&format!("obj/{file}"));
        assert!(message.starts_with(&format!("/obj/{file}:4: ")) && message.contains(needle), "{file}: {message:?}");
    }
    // The largest finite f32 and subnormals are numbers like any other.
    assert_eq!(obj_ok("obj/vertex-f32-max.obj").mesh.positions[3].x, f32::MAX);
    assert_eq!(obj_ok("obj/vertex-subnormal.obj").mesh.triangle_count(), 1);
}

#[test]
fn odd_mtl_gives_warnings_not_errors() {
    let scene = obj_ok("obj/uses-odd-mtl.obj");
    assert_eq!(scene.mesh.triangle_count(), 4);
    let names: Vec<&str> =
        scene.mesh.material_ids.iter().map(|&id| scene.materials[id as usize].name.as_str()).collect();
    // Bytes that are not UTF-8 are read as Latin-1 (`\xff\xfe`).
    assert_eq!(names, ["a b", "Material#1", "nan", "\u{ff}\u{fe}"]);
    let a_b = &scene.materials[scene.mesh.material_ids[0] as usize];
    // The first definition of "a b" wins; its only valid Kd line is `Kd 0.5`, `d -halo -halo 0.5` sets d.
    assert_eq!((a_b.kd, a_b.dissolve), (glam::Vec3::splat(0.5), 0.5));
    assert!(scene.materials[scene.mesh.material_ids[3] as usize].is_emissive());
    // odd.mtl has 19 bad lines (`Ke -1 -1 -1` among them; `illum 2.5` reads as 2, as Blender and
    // tinyobjloader read it): the first 10 are shown (so "newmtl without a name", line 24, is only
    // counted), then one line for the other 9.
    assert!(scene.warnings.iter().any(|w| w.ends_with("odd.mtl: … and 9 more like this (ignored MTL lines)")));
    for needle in [
        "statement before the first newmtl",
        "not finite",
        "expected 1 or 3 numbers",
        "defined again",
        "Ke must not be negative",
    ] {
        assert!(
            scene.warnings.iter().any(|w| w.contains(needle)),
            "no warning mentions {needle:?}: {:#?}",
            scene.warnings
        );
    }
    assert!(scene.warnings.iter().all(|w| w.contains("odd.mtl:") || w.contains("uses-odd-mtl.obj:")));
}

#[test]
fn orbiter_files_with_missing_lines_huge_numbers_or_nan_are_refused() {
    let cases = [
        ("missing-s.txt", 3, "missing 's' line"),
        ("missing-c.txt", 3, "missing 'c' line"),
        ("empty.txt", 1, "missing 'c' line"),
        ("truncated-mid-line.txt", 4, "'s' expects 2 numbers, found 1"),
        ("truncated-mid-exponent.txt", 4, "'s' expects finite numbers, found \"3.4e\""),
        ("nan.txt", 1, "'c' expects finite numbers, found \"nan\""),
        ("inf.txt", 2, "'p' expects finite numbers, found \"inf\""),
        ("overflow-1e400.txt", 4, "'s' expects finite numbers, found \"1e400\""),
        ("extra-number.txt", 1, "'c' expects 3 numbers, found 4"),
        ("unknown-field.txt", 5, "unknown orbiter field \"zoom\""),
        ("not-utf8.txt", 5, "not UTF-8"),
        ("zero-radius.txt", 4, "'s' gives a radius of 0.0 at a distance of 2.78"),
        ("tiny-radius.txt", 4, "'s' gives a radius of 1e-320 at a distance of 1.27"),
        ("huge-finite.txt", 4, "the camera's rays are not finite"),
        (
            "huge-radius.txt",
            4,
            "the camera's rays are not finite: its numbers overflow, or its near and far planes (0.1 and 1e39",
        ),
    ];
    for (file, line, needle) in cases {
        let path = Path::new(CORPUS).join("orbiter").join(file);
        let message = match Orbiter::load(&path) {
            Ok(orbiter) => panic!("{file}: expected an error, got {orbiter:?}"),
            Err(error) => error.to_string(),
        };
        let prefix = format!("{}:{line}: ", path.display());
        assert!(message.starts_with(&prefix) && message.contains(needle), "{file}: {message:?}");
    }
    for file in ["valid-2022.txt", "valid-2020.txt", "crlf.txt", "truncated-mid-number.txt", "zeros.txt"] {
        let path = Path::new(CORPUS).join("orbiter").join(file);
        Orbiter::load(&path).unwrap_or_else(|error| panic!("{file}: {error}"));
    }
}

/// A million vertices on a circle and one face through all of them: 999,998 fan triangles in file
/// order, loaded in seconds, and rendered as a disk (hit in the centre, sky in the corners).
#[test]
fn million_vertex_face_loads_as_a_fan_and_renders() {
    const N: usize = 1_000_000;
    let mut obj = String::with_capacity(40 * N);
    for i in 0..N {
        let angle = i as f64 / N as f64 * std::f64::consts::TAU;
        obj.push_str(&format!("v {:.7} {:.7} 0\n", angle.cos(), angle.sin()));
    }
    for relative in [false, true] {
        let mut text = obj.clone();
        text.push('f');
        for i in 1..=N {
            let index = if relative { i as i64 - N as i64 - 1 } else { i as i64 };
            text.push_str(&format!(" {index}"));
        }
        text.push('\n');
        let start = Instant::now();
        let scene = parse_obj(text.as_bytes(), Path::new("million.obj"), &mtl_resolver(None)).unwrap();
        let load = start.elapsed();
        assert!(load < Duration::from_secs(10), "loading took {load:?}");
        check_obj_scene(&scene).unwrap();
        assert_eq!(scene.mesh.triangle_count(), N - 2);
        for (t, triangle) in scene.mesh.indices.iter().enumerate() {
            assert_eq!(*triangle, [0, t as u32 + 1, t as u32 + 2]);
        }
        if relative {
            continue;
        }
        let scene = scene.into_scene("million.obj".to_string()).unwrap();
        let world = World::new(scene, Default::default());
        let camera = Camera::look_at(glam::Vec3::Z * 3.0, glam::Vec3::ZERO, glam::Vec3::Y, 60.0, 9, 9).unwrap();
        let image =
            render(&world, &camera, &RenderOptions::new(Technique::Hits(Default::default())), &|_| {}).unwrap().image;
        let pixel = |x: usize, y: usize| image.pixels[y * 9 + x].x;
        assert_eq!((pixel(4, 4), pixel(0, 0), pixel(8, 8)), (1.0, 0.0, 0.0), "a disk in the middle");
    }
}

/// A face with a million corners that all name the same vertex: a million degenerate triangles.
#[test]
fn million_corner_degenerate_face_loads() {
    let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
    text.push_str(&" 1".repeat(1_000_000));
    let scene = parse_obj(text.as_bytes(), Path::new("degenerate.obj"), &mtl_resolver(None)).unwrap();
    check_obj_scene(&scene).unwrap();
    assert_eq!(scene.mesh.triangle_count(), 999_998);
}

/// A 10 MB number must be refused quickly (it overflows to infinity).
#[test]
fn ten_megabyte_number_is_refused_quickly() {
    let text = format!("v {} 0 0\n", "9".repeat(10_000_000));
    let start = Instant::now();
    let result = parse_obj(text.as_bytes(), Path::new("long.obj"), &mtl_resolver(None));
    assert!(start.elapsed() < Duration::from_secs(5), "took {:?}", start.elapsed());
    let error = result.expect_err("an infinite number");
    assert!(error.to_string().starts_with("long.obj:1: number"), "{}", &error.to_string()[..80]);
}

/// Error messages quote the offending token whole: a 10 MB token gives a 10 MB message, which a
/// terminal cannot show and a log should not hold.
#[test]
fn error_messages_stay_short_for_huge_tokens() {
    let text = format!("v {} 0 0\n", "9".repeat(10_000_000));
    let error = parse_obj(text.as_bytes(), Path::new("long.obj"), &mtl_resolver(None)).expect_err("infinite");
    let message = error.to_string();
    assert!(message.len() < 1000, "error message is {} bytes long: {}...", message.len(), &message[..120]);
}

/// 100 000 materials, each used: no quadratic blow-up in the material table.
#[test]
fn hundred_thousand_materials_load_quickly() {
    const N: usize = 100_000;
    let mut mtl = String::new();
    let mut obj = String::from("mtllib many.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for i in 0..N {
        mtl.push_str(&format!("newmtl m{i}\nKd 0.5 0.5 0.5\n"));
        obj.push_str(&format!("usemtl m{}\nf 1 2 3\nmtllib lib{i}.mtl\n", N - 1 - i));
    }
    let start = Instant::now();
    let resolver = move |name: &str| {
        if name == "many.mtl" {
            Ok((mtl.clone().into_bytes(), PathBuf::from(name)))
        } else {
            Err(std::io::Error::new(std::io::ErrorKind::NotFound, "missing"))
        }
    };
    let scene = parse_obj(obj.as_bytes(), Path::new("many.obj"), &resolver).unwrap();
    assert!(start.elapsed() < Duration::from_secs(10), "took {:?}", start.elapsed());
    check_obj_scene(&scene).unwrap();
    assert_eq!(scene.materials.len(), N);
    // One warning per missing library, capped at 10 and a line for the rest.
    assert_eq!(scene.warnings.len(), 11, "{:?}", &scene.warnings[..scene.warnings.len().min(20)]);
    assert_eq!(
        scene.warnings[10],
        format!("many.obj: … and {} more like this (unreadable material libraries)", N - 10)
    );
    assert_eq!(scene.materials[scene.mesh.material_ids[0] as usize].name, format!("m{}", N - 1));
}

/// Writes a multi-member gzip file of `members` x `member_mib` MiB of zeros (compressed once).
fn gzip_bomb(path: &Path, member_mib: usize, members: usize) {
    let mut encoder = GzEncoder::new(Vec::new(), Compression::best());
    let zeros = vec![0u8; 1 << 20];
    for _ in 0..member_mib {
        encoder.write_all(&zeros).unwrap();
    }
    let member = encoder.finish().unwrap();
    let mut file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for _ in 0..members {
        file.write_all(&member).unwrap();
    }
    file.flush().unwrap();
}

/// A small bomb (64 MiB of zeros, 64 KB on disk): one long line of NULs, no geometry.
#[test]
fn small_gzip_bomb_loads_or_fails_cleanly() {
    let dir = TempDir::new("small-bomb");
    let path = dir.path("zeros.obj.gz");
    gzip_bomb(&path, 64, 1);
    let start = Instant::now();
    match load_obj(&path) {
        Ok(scene) => assert_eq!((scene.mesh.triangle_count(), scene.mesh.positions.len()), (0, 0)),
        Err(error) => assert!(error.to_string().starts_with(&path.display().to_string()), "{error}"),
    }
    assert!(start.elapsed() < Duration::from_secs(10), "took {:?}", start.elapsed());
}

/// 16 GiB of zeros in a 16 MB `.obj.gz`: the loader decompresses everything into one buffer, so
/// memory grows with the decompressed size, unbounded. Run under a 4 GiB address-space limit, the
/// read only fails when that limit is hit ("out of memory"); without the limit the process takes
/// all the machine's memory. Expected: a refusal of its own, naming the file, well before.
#[test]
#[cfg(unix)]
fn gzip_bomb_is_refused_before_exhausting_memory() {
    let dir = TempDir::new("bomb");
    let path = dir.path("bomb.obj.gz");
    gzip_bomb(&path, 256, 64);
    let args: [&OsStr; 2] = ["info".as_ref(), path.as_os_str()];
    let limits = Limits { deadline: Duration::from_secs(120), memory_mib: Some(4096) };
    let result = run(lumiere(), &args, &dir.0, limits);
    check_exit(&result, false).unwrap_or_else(|problem| panic!("{problem}: {}", result.describe(&args)));
    let error = error_line(&result).unwrap_or_else(|| panic!("the bomb loaded: {}", result.describe(&args)));
    assert!(error.contains("bomb.obj.gz"), "{error}");
    let hit_the_limit = ["out of memory", "memory allocation", "Cannot allocate"].iter().any(|s| error.contains(s));
    assert!(!hit_the_limit, "refused only when the address-space limit was hit: {error}");
}

/// Every corpus OBJ through `lumiere render`: exit 0 with an image, or exit 2 with one
/// `lumiere: error:` line that names the file; never a panic, a signal or a hang.
#[test]
fn cli_renders_or_refuses_every_corpus_scene() {
    let dir = TempDir::new("cli-corpus");
    let out = dir.path("out.png");
    let mut failures = Vec::new();
    for scene in files(&format!("{CORPUS}/obj"), &[".obj", ".obj.gz"]) {
        // Known bug, tested on its own by `cli_huge_extent_scene_gets_an_error_naming_the_file`.
        if scene.ends_with("vertex-f32-max.obj") {
            continue;
        }
        let args: Vec<&OsStr> = ["render".as_ref(), scene.as_os_str()]
            .into_iter()
            .chain(["--size", "8x6", "--mode", "hits", "--threads", "1", "-o"].map(OsStr::new))
            .chain([out.as_os_str()])
            .collect();
        let _ = std::fs::remove_file(&out);
        let result = run(lumiere(), &args, &dir.0, Limits::default());
        let named = format!("lumiere: error: {}", scene.display());
        let outcome = check_exit(&result, false).and_then(|()| match error_line(&result) {
            Some(error) if !error.starts_with(&named) => Err(format!("error does not name the file: {error}")),
            Some(_) => Ok(()),
            None if out.exists() => Ok(()),
            None => Err("exit 0 without an image".to_string()),
        });
        if let Err(problem) = outcome {
            failures.push(format!("{problem}: {}", result.describe(&args)));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// An OBJ whose extent overflows f32 (coordinates at +-f32::MAX) is accepted by the parser, but the
/// default framing then fails with "camera: the eye and the target are the same point", an error about
/// options the user did not give that does not name the file.
#[test]
fn cli_huge_extent_scene_gets_an_error_naming_the_file() {
    let dir = TempDir::new("cli-huge-extent");
    let scene = Path::new(CORPUS).join("obj/vertex-f32-max.obj");
    let out = dir.path("out.png");
    let args: Vec<&OsStr> = ["render".as_ref(), scene.as_os_str()]
        .into_iter()
        .chain(["--size", "8x6", "--mode", "hits", "-o"].map(OsStr::new))
        .chain([out.as_os_str()])
        .collect();
    let result = run(lumiere(), &args, &dir.0, Limits::default());
    check_exit(&result, false).unwrap_or_else(|problem| panic!("{problem}: {}", result.describe(&args)));
    if let Some(error) = error_line(&result) {
        assert!(error.starts_with(&format!("lumiere: error: {}", scene.display())), "{error}");
    }
}

/// Every corpus orbiter through `lumiere render --orbiter`: an image, or one error line naming it.
#[test]
fn cli_renders_or_refuses_every_corpus_orbiter() {
    let dir = TempDir::new("cli-orbiters");
    let out = dir.path("out.png");
    let mut failures = Vec::new();
    for orbiter in files(&format!("{CORPUS}/orbiter"), &[]) {
        let args: Vec<&OsStr> = ["render", "--size", "8x6", "--mode", "hits", "--threads", "1", "--orbiter"]
            .map(OsStr::new)
            .into_iter()
            .chain([orbiter.as_os_str(), "-o".as_ref(), out.as_os_str()])
            .collect();
        let result = run(lumiere(), &args, &dir.0, Limits::default());
        let named = format!("lumiere: error: {}:", orbiter.display());
        let outcome = check_exit(&result, false).and_then(|()| match error_line(&result) {
            Some(error) if !error.starts_with(&named) => Err(format!("error does not name the file: {error}")),
            _ => Ok(()),
        });
        if let Err(problem) = outcome {
            failures.push(format!("{problem}: {}", result.describe(&args)));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn cli_size_1x1_renders() {
    let dir = TempDir::new("cli-1x1");
    let out = dir.path("one.png");
    let args: Vec<&OsStr> = ["render", "--size", "1x1", "--mode", "hits", "-o"]
        .map(OsStr::new)
        .into_iter()
        .chain([out.as_os_str()])
        .collect();
    let result = run(lumiere(), &args, &dir.0, Limits::default());
    assert_eq!(result.status.and_then(|s| s.code()), Some(0), "{}", result.describe(&args));
    assert!(out.exists());
}

/// Malformed sizes are usage errors (exit 2), not panics.
#[test]
fn cli_malformed_sizes_are_usage_errors() {
    let dir = TempDir::new("cli-bad-size");
    for size in ["0x0", "0x1", "1x0", "-1x1", "x", "", "4294967296x1", "1x4294967296", "1e9x1", "1.5x1", "12"] {
        let args = ["render", "--size", size, "--mode", "hits", "-o", "never.png"];
        let result = run(lumiere(), &args, &dir.0, Limits::default());
        check_exit(&result, true).unwrap_or_else(|problem| panic!("{problem}: {}", result.describe(&[])));
        assert_eq!(result.status.and_then(|s| s.code()), Some(2), "{size}: {}", result.describe(&[]));
    }
}

/// Sizes whose image cannot fit in memory must be refused before allocating, with one error line
/// that says how much memory the image would need. Run under a 2 GiB address-space limit and a
/// deadline, so that without the refusal the test fails instead of taking the machine down.
#[test]
#[cfg(unix)]
fn cli_absurd_sizes_are_refused_naming_the_memory_needed() {
    let dir = TempDir::new("cli-huge-size");
    let mut sizes = vec!["100000x100000", "4294967295x1", "1x4294967295", "65536x65536"];
    // In builds with overflow checks the memory computation itself panics for this one (bug 3 in
    // docs/FUZZING.md, `cli_size_whose_memory_computation_wraps_is_refused`); release builds refuse it.
    if !cfg!(debug_assertions) {
        sizes.push("4294967295x4294967295");
    }
    for size in sizes {
        for mode in ["hits", "shadows"] {
            let args = ["render", "--size", size, "--mode", mode, "-o", "huge.png"];
            let result = refuse_size(&dir, &args);
            let error = error_line(&result).expect("checked by refuse_size");
            let units = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB", "GB", "TB", "PB", "EB"];
            assert!(units.iter().any(|unit| error.contains(unit)), "{size}: the error names no memory: {error}");
            assert!(result.elapsed < Duration::from_secs(5), "{size}: refused only after {:?}", result.elapsed);
            assert!(!dir.path("huge.png").exists());
        }
    }
}

/// A film that fits beside outputs that do not (AOVs, a checkpoint's encoding) is refused before
/// rendering, naming them: the AOVs' buffers and EXR layers, allocated after the passes, aborted
/// with a backtrace (a 4000x3000 render with three AOVs under a 1.5 GB limit), and so did a
/// checkpoint as large as the film. Under the tests' 2 GiB limit, each film below would fit alone
/// (1.1 and 1.3 GiB).
#[test]
#[cfg(unix)]
fn outputs_that_do_not_fit_beside_the_film_are_refused_before_rendering() {
    let dir = TempDir::new("cli-outputs-memory");
    let cases: [(&[&str], &str, &str); 2] = [
        (&["--size", "5000x4000", "--aov", "albedo,normal,depth", "-o", "x.exr"], "with its AOVs needs", "x.exr"),
        (&["--size", "5000x5000", "--checkpoint", "c.ckpt", "-o", "c.png"], "with its checkpoint needs", "c.png"),
    ];
    for (extra, expected, output) in cases {
        let args = [&["render", "--mode", "hits"][..], extra].concat();
        let result = refuse_size(&dir, &args);
        let error = error_line(&result).expect("checked by refuse_size");
        assert!(error.contains(expected), "{error}");
        assert!(result.elapsed < Duration::from_secs(5), "refused only after {:?}", result.elapsed);
        assert!(!dir.path(output).exists());
    }
}

/// Runs `args` (an absurd `--size`) under a 2 GiB address-space limit and a deadline, so that a
/// missing refusal fails the test instead of taking the machine down; it must exit 2 with an error.
#[cfg(unix)]
fn refuse_size(dir: &TempDir, args: &[&str]) -> crate::process::Run {
    let limits = Limits { deadline: Duration::from_secs(20), memory_mib: Some(2048) };
    let result = run(lumiere(), args, &dir.0, limits);
    let describe = || result.describe(&args.iter().map(OsStr::new).collect::<Vec<_>>());
    check_exit(&result, false).unwrap_or_else(|problem| panic!("{problem}: {}", describe()));
    assert!(error_line(&result).is_some(), "rendered: {}", describe());
    result
}

/// The memory check computes `width * height * bytes per pixel` in u64 without overflow checks:
/// `--size 2147483648x2147483648` (2^62 pixels) wraps to 0 bytes, passes, and the allocation
/// panics with "capacity overflow" (exit 101); `4294967295x4294967295` is refused in release
/// builds but with a wrapped, too small GiB figure (and panics with "attempt to multiply with
/// overflow" in builds with overflow checks). Expected: refused, naming at least the 12 bytes per
/// pixel of the final image.
#[test]
#[cfg(unix)]
fn cli_size_whose_memory_computation_wraps_is_refused() {
    let dir = TempDir::new("cli-wrap-size");
    for (size, pixels) in [("2147483648x2147483648", 2f64.powi(62)), ("4294967295x4294967295", 4294967295f64.powi(2))] {
        let args = ["render", "--size", size, "--mode", "hits", "-o", "huge.png"];
        let result = refuse_size(&dir, &args);
        let error = error_line(&result).expect("checked by refuse_size");
        let gib: f64 = error
            .split(" GiB")
            .next()
            .and_then(|before| before.rsplit(' ').next())
            .and_then(|number| number.parse().ok())
            .unwrap_or_else(|| panic!("{size}: no GiB figure in {error}"));
        let at_least = pixels * 12.0 / 2f64.powi(30);
        assert!(gib >= at_least, "{size}: says {gib} GiB, the image alone needs {at_least:.0} GiB: {error}");
    }
}
