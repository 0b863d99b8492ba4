//! Hostile inputs through the binary (issue 9): a FIFO as scene, orbiter or checkpoint, devices as
//! material libraries, a small `.obj.gz` whose mesh cannot fit in memory, warnings that would
//! flood stderr, a material library given as the scene, a file name with a newline. Each run has
//! a deadline and a 2 GiB address-space limit (`fuzz/src/process.rs`): exit 0, or exit 2 with one
//! `lumiere: error:` line, never a hang, a panic or an abort. The library-level tests of the same
//! edges are in `crates/lumiere/tests/integration/hostile_inputs.rs`.

use crate::process::{Limits, Run, TempDir, check_exit, error_line, run};
use flate2::Compression;
use flate2::write::GzEncoder;
use std::ffi::OsStr;
use std::io::Write;
use std::path::Path;
use std::time::Duration;

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

fn lumiere() -> &'static Path {
    Path::new(env!("CARGO_BIN_EXE_lumiere"))
}

fn limits() -> Limits {
    Limits { deadline: Duration::from_secs(20), memory_mib: Some(2048) }
}

/// `lumiere render <args> --size 8x6 --mode hits -o <dir>/out.png`, checked against the CLI's exit
/// contract.
fn render(dir: &TempDir, args: &[&OsStr]) -> Run {
    let out = dir.path("out.png");
    let mut all: Vec<&OsStr> = vec!["render".as_ref()];
    all.extend_from_slice(args);
    all.extend(["--size", "8x6", "--mode", "hits", "--threads", "1", "-o"].map(OsStr::new));
    all.push(out.as_os_str());
    let result = run(lumiere(), &all, &dir.0, limits());
    check_exit(&result, false).unwrap_or_else(|problem| panic!("{problem}: {}", result.describe(&all)));
    result
}

/// The one error line of a run that must fail.
fn refused(result: &Run) -> &str {
    error_line(result).unwrap_or_else(|| panic!("expected an error: {}", result.describe(&[])))
}

#[cfg(unix)]
fn mkfifo(dir: &TempDir, name: &str) -> std::path::PathBuf {
    let path = dir.path(name);
    assert!(std::process::Command::new("mkfifo").arg(&path).status().unwrap().success());
    path
}

#[test]
#[cfg(unix)]
fn cli_fifo_as_scene_orbiter_or_checkpoint_is_refused_at_once() {
    let dir = TempDir::new("cli-fifo");
    let scene = mkfifo(&dir, "scene.obj");
    let orbiter = mkfifo(&dir, "orbiter.txt");
    let checkpoint = mkfifo(&dir, "render.ckpt");
    let cases: [(Vec<&OsStr>, &Path); 3] = [
        (vec![scene.as_os_str()], &scene),
        (vec!["--orbiter".as_ref(), orbiter.as_os_str()], &orbiter),
        (vec!["--resume".as_ref(), checkpoint.as_os_str()], &checkpoint),
    ];
    for (args, fifo) in cases {
        let result = render(&dir, &args);
        let expected = format!("lumiere: error: {}: is a FIFO, not a regular file", fifo.display());
        assert_eq!(refused(&result), expected);
        assert!(result.elapsed < Duration::from_secs(5), "{:?}", result.elapsed);
    }
    let result = run(lumiere(), &["info".as_ref(), scene.as_os_str()], &dir.0, limits());
    assert!(refused(&result).ends_with("scene.obj: is a FIFO, not a regular file"));
}

/// A 40-byte OBJ whose `mtllib` names `/dev/zero` used to read until memory ran out.
#[test]
#[cfg(unix)]
fn cli_devices_as_material_libraries_cost_a_warning() {
    let dir = TempDir::new("cli-dev-mtl");
    let scene =
        dir.write("scene.obj", format!("mtllib /dev/zero\nmtllib /dev/urandom\n{TRIANGLE}f 1 2 3\n").as_bytes());
    let result = render(&dir, &[scene.as_os_str()]);
    assert!(error_line(&result).is_none(), "{}", result.describe(&[]));
    let warnings: Vec<&str> = result.stderr.lines().filter(|l| l.starts_with("lumiere: warning:")).collect();
    assert_eq!(warnings.len(), 2, "{}", result.stderr);
    assert!(warnings.iter().all(|w| w.contains("is a character device")), "{warnings:?}");
}

/// 200 MiB of `f 1 2 3` lines (26M triangles) in a gzip of a few hundred KB: the mesh and its BVH
/// need about 4 GiB. It used to parse into an allocation failure and an abort (SIGABRT); now it is
/// refused before the triangles are allocated, naming the memory needed and available.
#[test]
#[cfg(unix)]
fn cli_small_gzip_of_a_huge_mesh_is_refused_before_allocating() {
    let dir = TempDir::new("cli-huge-mesh");
    let member = |text: &[u8]| {
        let mut encoder = GzEncoder::new(Vec::new(), Compression::best());
        encoder.write_all(text).unwrap();
        encoder.finish().unwrap()
    };
    let faces = member("f 1 2 3\n".repeat((1 << 20) / 8).as_bytes());
    let mut gz = member(TRIANGLE.as_bytes());
    for _ in 0..200 {
        gz.extend_from_slice(&faces);
    }
    assert!(gz.len() < 2 << 20, "{} bytes on disk", gz.len());
    let scene = dir.write("huge.obj.gz", &gz);
    let result = render(&dir, &[scene.as_os_str()]);
    let error = refused(&result);
    let prefix = format!("lumiere: error: {}: needs about ", scene.display());
    assert!(error.starts_with(&prefix) && error.contains("for its 26214400 triangles"), "{error}");
    assert!(error.contains("GiB of memory") && error.contains("GiB is available"), "{error}");
}

/// An MTL with 10,000 bad lines, named 20,000 times on one 160 KB `mtllib` line: every name was
/// read and every bad line warned about again (gigabytes of stderr). Now: 10 warnings and a count.
#[test]
fn cli_warnings_do_not_flood_stderr() {
    let dir = TempDir::new("cli-flood");
    dir.write("m.mtl", format!("newmtl red\n{}", "Kd x\n".repeat(10_000)).as_bytes());
    let mut obj = format!("mtllib {}\n", "./m.mtl ".repeat(20_000));
    for i in 0..1000 {
        obj += &format!("usemtl ghost{i}\n");
    }
    obj += &format!("{TRIANGLE}usemtl red\nf 1 2 3\n");
    for i in 0..1000 {
        obj += &format!("usemtl ghost{i}\nf 1 2 3\n");
    }
    let scene = dir.write("scene.obj", obj.as_bytes());
    let result = render(&dir, &[scene.as_os_str()]);
    assert!(error_line(&result).is_none(), "{}", result.describe(&[]));
    assert!(result.stderr.len() < 8000, "{} bytes of stderr:\n{}", result.stderr.len(), result.stderr);
    let warnings: Vec<&str> = result.stderr.lines().filter(|l| l.starts_with("lumiere: warning:")).collect();
    assert_eq!(warnings.len(), 22, "{}", result.stderr);
    assert!(warnings.iter().any(|w| w.ends_with("m.mtl: … and 9990 more like this (ignored MTL lines)")));
    assert!(warnings.iter().any(|w| w.ends_with("scene.obj: … and 990 more like this (undefined materials)")));
}

#[test]
fn cli_material_library_as_scene_says_what_to_give() {
    let dir = TempDir::new("cli-mtl-scene");
    let mtl = dir.write("scene.mtl", b"newmtl red\nKd 1 0 0\n");
    let result = render(&dir, &[mtl.as_os_str()]);
    let expected = format!(
        "lumiere: error: {}: is a material library (.mtl), not a scene; give the .obj file that names it with mtllib",
        mtl.display()
    );
    assert_eq!(refused(&result), expected);
}

/// A scene whose file name holds a newline and an escape sequence: the error stays one line.
#[test]
#[cfg(unix)]
fn cli_control_characters_in_file_names_stay_on_one_line() {
    let dir = TempDir::new("cli-newline");
    let scene = dir.write("bad\n\x1b[2Jname.obj", b"v 0 0 0\nv 1 x 0\n");
    let result = render(&dir, &[scene.as_os_str()]);
    let error = refused(&result);
    assert!(error.ends_with(r#"bad\n\u{1b}[2Jname.obj":2: malformed number "x""#), "{error}");
    assert!(!result.stderr.contains('\x1b'));
}
