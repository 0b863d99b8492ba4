//! Inputs at the edges (issue 9): special files (FIFOs, devices, directories, sockets), scenes too
//! big for memory, names and paths that would make messages huge or split them, warnings that
//! repeat, and the real-world OBJ quirks mainstream loaders accept. Every hostile file is
//! generated here; every read that could block runs on a thread with a deadline.

use crate::common::TempDir;
use flate2::Compression;
use flate2::write::GzEncoder;
use lumiere::render::checkpoint::Checkpoint;
use lumiere::scene::Scene;
use lumiere::scene::camera::Orbiter;
use lumiere::scene::load::obj::{
    ObjScene, load_obj, load_obj_with_memory, parse_obj, parse_obj_with_chunk_size, parse_obj_with_memory,
};
use lumiere::scene::load::warnings::SHOWN_PER_KIND;
use lumiere::scene::mesh::NO_INDEX;
use lumiere::util::read::{gunzip, read_input, read_regular_file};
use std::cell::RefCell;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

const DEADLINE: Duration = Duration::from_secs(5);
const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// Runs `work` on its own thread and fails the test if it has not returned within [`DEADLINE`]
/// (the thread is left behind, blocked: the test process ends anyway).
fn within_deadline<T: Send + 'static>(what: &str, work: impl FnOnce() -> T + Send + 'static) -> T {
    let (send, receive) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = send.send(work());
    });
    receive.recv_timeout(DEADLINE).unwrap_or_else(|_| panic!("{what}: still blocked after {DEADLINE:?}"))
}

/// A FIFO at `dir/name`, made with `mkfifo`.
#[cfg(unix)]
fn fifo(dir: &TempDir, name: &str) -> PathBuf {
    let path = dir.path(name);
    let status = std::process::Command::new("mkfifo").arg(&path).status().expect("mkfifo runs");
    assert!(status.success(), "mkfifo {}", path.display());
    path
}

fn load_error(path: &Path) -> String {
    let owned = path.to_path_buf();
    let result = within_deadline(&format!("load_obj({})", path.display()), move || load_obj(&owned).map(|s| s.mesh));
    match result {
        Ok(mesh) => panic!("{}: expected an error, got {} triangles", path.display(), mesh.triangle_count()),
        Err(error) => error.to_string(),
    }
}

fn load_ok(path: &Path) -> ObjScene {
    let owned = path.to_path_buf();
    within_deadline(&format!("load_obj({})", path.display()), move || load_obj(&owned))
        .unwrap_or_else(|error| panic!("{error}"))
}

fn assert_one_line(messages: &[String]) {
    for message in messages {
        assert!(!message.contains('\n') && !message.contains('\r'), "message spans lines: {message:?}");
    }
}

// --- 1. Special files -----------------------------------------------------------------------

#[test]
#[cfg(unix)]
fn fifo_as_scene_is_refused_without_blocking() {
    let dir = TempDir::new("fifo-scene");
    let path = fifo(&dir, "scene.obj");
    let message = load_error(&path);
    assert_eq!(message, format!("{}: is a FIFO, not a regular file", path.display()));
    // The same through the extension dispatch, for a gzipped name.
    let gz = fifo(&dir, "scene.obj.gz");
    let message = within_deadline("Scene::load", move || Scene::load(&gz).map(|_| ()).unwrap_err().to_string());
    assert!(message.ends_with("scene.obj.gz: is a FIFO, not a regular file"), "{message}");
}

#[test]
#[cfg(unix)]
fn fifo_as_mtl_is_a_warning_not_a_hang() {
    let dir = TempDir::new("fifo-mtl");
    fifo(&dir, "pipe.mtl");
    let obj = dir.write("scene.obj", format!("mtllib pipe.mtl\n{TRIANGLE}usemtl red\nf 1 2 3\n"));
    let scene = load_ok(&obj);
    assert_eq!(scene.mesh.triangle_count(), 1);
    assert!(
        scene.warnings.iter().any(|w| w.contains("\"pipe.mtl\"") && w.contains("is a FIFO, not a regular file")),
        "{:?}",
        scene.warnings
    );
}

/// A 40-byte OBJ naming `/dev/zero` and `/dev/urandom` as material libraries grew until memory ran out.
#[test]
#[cfg(unix)]
fn devices_as_mtllib_are_refused_at_once() {
    let dir = TempDir::new("dev-mtl");
    let obj = dir.write("scene.obj", format!("mtllib /dev/zero\nmtllib /dev/urandom\n{TRIANGLE}f 1 2 3\n"));
    let start = Instant::now();
    let scene = load_ok(&obj);
    assert!(start.elapsed() < Duration::from_secs(1), "took {:?}", start.elapsed());
    assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
    for (warning, device) in scene.warnings.iter().zip(["/dev/zero", "/dev/urandom"]) {
        let expected =
            format!("cannot read material library \"{device}\" (is a character device, not a regular file);");
        assert!(warning.contains(&expected), "{warning}");
    }
}

#[test]
#[cfg(unix)]
fn every_kind_of_special_file_is_named() {
    let dir = TempDir::new("special-kinds");
    let fifo = fifo(&dir, "fifo");
    let socket = dir.path("socket");
    let _listener = std::os::unix::net::UnixListener::bind(&socket).expect("bind a socket");
    std::fs::create_dir(dir.path("folder.obj")).unwrap();
    let cases = [
        (fifo, "is a FIFO, not a regular file"),
        (socket, "is a socket, not a regular file"),
        (dir.path("folder.obj"), "is a directory, not a regular file"),
        (PathBuf::from("/dev/null"), "is a character device, not a regular file"),
        (PathBuf::from("/dev/zero"), "is a character device, not a regular file"),
    ];
    for (path, expected) in cases {
        let shown = path.display().to_string();
        let error = within_deadline(&shown, move || read_regular_file(&path)).expect_err(&shown);
        assert!(error.to_string().starts_with(expected), "{shown}: {error}");
        assert_eq!(error.kind(), io::ErrorKind::InvalidInput, "{shown}");
    }
    // A terminal, where there is one: refused by its type before it is opened.
    if Path::new("/dev/tty").exists() {
        let error = within_deadline("/dev/tty", || read_regular_file(Path::new("/dev/tty"))).unwrap_err();
        assert_eq!(error.to_string(), "is a character device, not a regular file");
    }
    // A symlink to a FIFO is a FIFO.
    let link = dir.path("link.obj");
    std::os::unix::fs::symlink(dir.path("fifo"), &link).unwrap();
    assert!(load_error(&link).ends_with("link.obj: is a FIFO, not a regular file"));
}

#[test]
#[cfg(unix)]
fn fifo_as_orbiter_or_checkpoint_is_refused() {
    let dir = TempDir::new("fifo-orbiter");
    let orbiter = fifo(&dir, "orbiter.txt");
    let checkpoint = fifo(&dir, "render.ckpt");
    let shown = orbiter.display().to_string();
    let message =
        within_deadline("Orbiter::load", move || Orbiter::load(&orbiter).map(|_| ()).unwrap_err().to_string());
    assert_eq!(message, format!("{shown}: is a FIFO, not a regular file"));
    let shown = checkpoint.display().to_string();
    let message =
        within_deadline("Checkpoint::load", move || Checkpoint::load(&checkpoint).map(|_| ()).unwrap_err().to_string());
    assert_eq!(message, format!("{shown}: is a FIFO, not a regular file"));
}

/// Procfs files say they are empty: read "at most the size the file had when opened", they read as
/// empty, like a file that grows while it is read is cut at its size when opened.
#[test]
#[cfg(target_os = "linux")]
fn reads_stop_at_the_size_when_opened() {
    assert_eq!(std::fs::metadata("/proc/self/status").unwrap().len(), 0);
    assert!(read_regular_file(Path::new("/proc/self/status")).unwrap().is_empty());
    // A file that grows while it is read: the read ends, with at least what was there.
    let dir = TempDir::new("growing");
    let path = dir.write("growing.obj", vec![b'#'; 1 << 20]);
    let writer_path = path.clone();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let writer_stop = stop.clone();
    let writer = std::thread::spawn(move || {
        let mut file = std::fs::OpenOptions::new().append(true).open(writer_path).unwrap();
        while !writer_stop.load(std::sync::atomic::Ordering::Relaxed) {
            file.write_all(&[b'#'; 4096]).unwrap();
        }
    });
    let bytes = within_deadline("growing file", move || read_regular_file(&path).unwrap());
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    writer.join().unwrap();
    assert!(bytes.len() >= 1 << 20);
}

// --- 2. Memory, estimated before allocating ---------------------------------------------------

/// `members` gzip members of 1 MiB each of `line` repeated (one compressed member, written again
/// and again): small on disk, `members` MiB inflated.
fn repetitive_gzip(path: &Path, head: &str, line: &str, members: usize) {
    assert_eq!((1 << 20) % line.len(), 0, "lines must not straddle members");
    let member_of = |text: &[u8]| {
        let mut encoder = GzEncoder::new(Vec::new(), Compression::best());
        encoder.write_all(text).unwrap();
        encoder.finish().unwrap()
    };
    let mut file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    file.write_all(&member_of(head.as_bytes())).unwrap();
    let member = member_of(line.repeat((1 << 20) / line.len()).as_bytes());
    for _ in 0..members {
        file.write_all(&member).unwrap();
    }
    file.flush().unwrap();
}

/// 16 MiB of `f 1 2 3` (2M triangles) in a gzip of about 20 KB: the mesh and BVH need about a
/// third of a GiB, so with 128 MiB "available" it is refused before anything is parsed.
#[test]
fn scene_too_big_for_memory_is_refused_before_parsing() {
    let dir = TempDir::new("too-big");
    let path = dir.path("faces.obj.gz");
    repetitive_gzip(&path, TRIANGLE, "f 1 2 3\n", 16);
    assert!(std::fs::metadata(&path).unwrap().len() < 200_000);
    let start = Instant::now();
    let error = load_obj_with_memory(&path, 128 << 20).map(|s| s.mesh.triangle_count()).unwrap_err();
    let message = error.to_string();
    assert!(start.elapsed() < Duration::from_secs(5), "took {:?}", start.elapsed());
    assert!(message.starts_with(&format!("{}: needs about ", path.display())), "{message}");
    assert!(message.contains("for its 2097152 triangles and 3 vertices"), "{message}");
    // Below 1 GiB in MiB: "0.3 GiB ... only 0.1 GiB" read as if both were rounded to nothing.
    assert!(message.contains("MiB of memory") && message.contains("only 128 MiB is available"), "{message}");
    assert!(matches!(error, lumiere::Error::Io { ref source, .. } if source.kind() == io::ErrorKind::OutOfMemory));
    // With room enough it loads.
    let scene = load_obj_with_memory(&path, 4 << 30).unwrap();
    assert_eq!(scene.mesh.triangle_count(), 2 << 20);
}

/// One polygon of a million corners fans into 999,998 triangles: corners are counted, not faces.
#[test]
fn polygon_corners_count_towards_the_estimate() {
    let mut text = String::from(TRIANGLE);
    text.push('f');
    text.push_str(&" 1 2 3".repeat(1_000_000 / 3));
    text.push('\n');
    let no_mtl = |_: &str| Err(io::Error::from(io::ErrorKind::NotFound));
    let error = parse_obj_with_memory(text.as_bytes(), Path::new("fan.obj"), &no_mtl, 64 << 20).unwrap_err();
    let message = error.to_string();
    assert!(message.starts_with("fan.obj: needs about") && message.contains("its 999997 triangles"), "{message}");
    assert_eq!(
        parse_obj_with_memory(text.as_bytes(), Path::new("fan.obj"), &no_mtl, 1 << 30).unwrap().mesh.triangle_count(),
        999_997
    );
}

/// Joining continued lines copies the text: refused up front, naming it, when the copy would not
/// fit in the memory left (a trailing backslash is enough to ask for it).
#[test]
fn a_continuation_whose_copy_does_not_fit_is_refused() {
    // 3.5 MiB and a few bytes, shown rounded up.
    let text = format!("{TRIANGLE}f 1 2 \\\n3\n# {}\n", "padding ".repeat(7 << 16));
    let no_mtl = |_: &str| Err(io::Error::from(io::ErrorKind::NotFound));
    let error = parse_obj_with_memory(text.as_bytes(), Path::new("long.obj"), &no_mtl, 2 << 20).unwrap_err();
    let message = error.to_string();
    assert!(message.starts_with("long.obj: joining its continued lines needs a copy of its 4 MiB"), "{message}");
    assert!(message.contains("but only 2 MiB is available"), "{message}");
    let scene = parse_obj_with_memory(text.as_bytes(), Path::new("long.obj"), &no_mtl, 1 << 30).unwrap();
    assert_eq!(scene.mesh.triangle_count(), 1);
}

/// The gzip cap follows the memory given too: a quarter of it.
#[test]
fn gzip_inflating_past_a_quarter_of_memory_is_refused() {
    let dir = TempDir::new("gzip-cap");
    let path = dir.path("zeros.obj.gz");
    repetitive_gzip(&path, "", "\n", 8);
    let error = load_obj_with_memory(&path, 16 << 20).map(|_| ()).unwrap_err().to_string();
    assert!(error.starts_with(&path.display().to_string()) && error.contains("decompresses to more than"), "{error}");
}

// --- 3. Messages: short, one line, once -------------------------------------------------------

fn parse_with(text: &[u8], mtls: &[(&str, &[u8])]) -> ObjScene {
    let files: Vec<(String, Vec<u8>)> = mtls.iter().map(|(n, t)| (n.to_string(), t.to_vec())).collect();
    let read = move |name: &str| match files.iter().find(|(n, _)| n == name) {
        Some((_, text)) => Ok((text.clone(), Path::new("mem").join(name))),
        None => Err(io::Error::new(io::ErrorKind::NotFound, "not found")),
    };
    parse_obj(text, Path::new("test.obj"), &read).unwrap_or_else(|error| panic!("{error}"))
}

#[test]
fn names_from_files_are_quoted_short() {
    let long = "n".repeat(10_000_000);
    let other = "m".repeat(10_000_000);
    let obj = format!("mtllib {long}.mtl\nmtllib lib.mtl\n{TRIANGLE}usemtl {other}\nf 1 2 3\nusemtl twice\nf 1 2 3\n");
    let mtl = format!("newmtl twice\nnewmtl twice\nnewmtl {long}\nnewmtl {long}\nKd {long}\n");
    let scene = parse_with(obj.as_bytes(), &[("lib.mtl", mtl.as_bytes())]);
    assert_one_line(&scene.warnings);
    assert_eq!(
        scene.warnings.len(),
        5,
        "{:#?}",
        scene.warnings.iter().map(|w| &w[..w.len().min(200)]).collect::<Vec<_>>()
    );
    for warning in &scene.warnings {
        assert!(warning.len() < 300, "a {}-byte warning: {}…", warning.len(), &warning[..200]);
    }
    let shown = format!("\"{}\"… (", "n".repeat(80));
    assert!(
        scene.warnings.iter().any(|w| w.contains(&shown) && w.contains("(10000004 bytes)")),
        "{:?}",
        scene.warnings
    );
    assert!(scene.warnings.iter().any(|w| w.contains(&shown) && w.contains("(10000000 bytes)")));
    let other_shown = format!("\"{}\"… (10000000 bytes)", "m".repeat(80));
    assert!(scene.warnings.iter().any(|w| w.contains(&other_shown)), "{:?}", scene.warnings);
}

#[test]
fn control_characters_in_names_and_paths_are_escaped() {
    // A material name and a library name with a newline's neighbours: CR, ESC, BEL, tab.
    let obj = format!("mtllib evil\x1b[31m.mtl\n{TRIANGLE}usemtl red\r\x07green\nf 1 2 3\n");
    let scene = parse_with(obj.as_bytes(), &[]);
    assert_one_line(&scene.warnings);
    assert!(scene.warnings.iter().all(|w| !w.contains('\x1b') && !w.contains('\x07')), "{:?}", scene.warnings);
    assert!(scene.warnings[0].contains(r#""evil\u{1b}[31m.mtl""#), "{}", scene.warnings[0]);

    // A file whose name holds a newline: the error names it escaped, on one line.
    let dir = TempDir::new("newline-path");
    let path = dir.write("bad\nname.obj", "v 0 0 x\n");
    let message = load_error(&path);
    assert_one_line(std::slice::from_ref(&message));
    assert!(message.ends_with(r#"bad\nname.obj":1: malformed number "x""#), "{message}");
    let missing = dir.path("absent\r\n.obj");
    let message = load_error(&missing);
    assert_one_line(std::slice::from_ref(&message));
    assert!(message.contains(r#"absent\r\n.obj""#), "{message}");
    let scene = Scene::load(&dir.path("x\n.ply")).map(|_| ()).unwrap_err().to_string();
    assert_one_line(&[scene]);
    // A name that is not UTF-8 keeps its byte as an escape: a U+FFFD in its place named a file no
    // one could find.
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let path = dir.0.join(std::ffi::OsStr::from_bytes(b"n\xffl.obj"));
        std::fs::write(&path, "v 0 0 x\n").unwrap();
        let message = load_error(&path);
        assert!(message.contains(r#"n\xFFl.obj""#) && !message.contains('\u{FFFD}'), "{message}");
    }
}

/// A folder or a device given as the scene is named for what it is, whatever its name: before,
/// `scenes/` and `/dev/zero` were "a file name with no extension".
#[test]
#[cfg(unix)]
fn a_scene_that_is_not_a_regular_file_is_named_for_what_it_is() {
    let dir = TempDir::new("scene-kinds");
    std::fs::create_dir(dir.path("scenes")).unwrap();
    std::fs::create_dir(dir.path("folder.obj")).unwrap();
    for (path, expected) in [
        (dir.path("scenes"), "is a directory, not a regular file"),
        (dir.path("folder.obj"), "is a directory, not a regular file"),
        (PathBuf::from("/dev/zero"), "is a character device, not a regular file"),
    ] {
        let message = load_error(&path);
        assert!(message.ends_with(expected), "{}: {message}", path.display());
    }
}

/// An MTL with 100 bad lines, named 2,000 times on one line and under five spellings on others:
/// read once, 10 of its warnings shown and one line for the other 90. (Before: one read and 100
/// warnings per name, 165 KB of OBJ gave 346 MB of warnings.)
#[test]
fn an_mtl_named_many_times_is_read_and_warned_about_once() {
    let dir = TempDir::new("mtl-many-times");
    std::fs::create_dir(dir.path("sub")).unwrap();
    dir.write("m.mtl", format!("newmtl red\n{}", "Kd x\n".repeat(100)));
    let mut obj = format!("mtllib {}\n", "m.mtl ".repeat(2000));
    for spelling in ["m.mtl", "./m.mtl", ".//m.mtl", "sub/../m.mtl", "./sub/../m.mtl"] {
        obj += &format!("mtllib {spelling}\nmtllib {spelling} {spelling}\n");
    }
    obj += &format!("{TRIANGLE}usemtl red\nf 1 2 3\n");
    let scene = load_ok(&dir.write("scene.obj", obj));
    assert_one_line(&scene.warnings);
    assert_eq!(scene.warnings.len(), SHOWN_PER_KIND + 1, "{:#?}", scene.warnings);
    assert!(scene.warnings[..10].iter().all(|w| w.contains("m.mtl:") && w.contains("line ignored")));
    assert!(
        scene.warnings[10].ends_with("m.mtl: … and 90 more like this (ignored MTL lines)"),
        "{}",
        scene.warnings[10]
    );
    assert_eq!(scene.materials.len(), 1);

    // In memory, the resolver is asked once per name, and a file returned twice is added once.
    let asked = RefCell::new(Vec::new());
    let read = |name: &str| {
        asked.borrow_mut().push(name.to_string());
        Ok((b"newmtl red\nKd x\n".to_vec(), PathBuf::from("same.mtl")))
    };
    let obj =
        format!("mtllib a.mtl a.mtl\nmtllib a.mtl\nmtllib b.mtl\nmtllib b.mtl a.mtl\n{TRIANGLE}usemtl red\nf 1 2 3\n");
    let scene = parse_obj(obj.as_bytes(), Path::new("test.obj"), &read).unwrap();
    assert_eq!(scene.warnings, ["same.mtl:2: malformed number \"x\"; line ignored"]);
    assert_eq!(*asked.borrow(), ["a.mtl a.mtl", "a.mtl", "b.mtl", "b.mtl a.mtl"]);
}

#[test]
fn a_missing_mtl_named_many_times_is_warned_about_once() {
    let dir = TempDir::new("missing-many-times");
    let obj = format!("mtllib gone.mtl gone.mtl\nmtllib ./gone.mtl\nmtllib gone.mtl\n{TRIANGLE}f 1 2 3\n");
    let scene = load_ok(&dir.write("scene.obj", obj));
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    assert!(
        scene.warnings[0]
            .starts_with(&format!("{}:1: cannot read material library \"gone.mtl\"", dir.path("scene.obj").display()))
    );
    assert!(scene.warnings[0].contains(&format!("looked in {}", dir.0.display())), "{}", scene.warnings[0]);
}

#[test]
fn repeated_warnings_of_one_kind_are_capped_per_file() {
    let mut obj = String::from(TRIANGLE);
    for i in 0..100 {
        obj += &format!("usemtl ghost{i}\nf 1 2 3\n");
    }
    for i in 0..30 {
        obj += &format!("mtllib missing{i}.mtl\n");
    }
    let scene = parse_with(obj.as_bytes(), &[]);
    assert_one_line(&scene.warnings);
    let undefined: Vec<&String> = scene.warnings.iter().filter(|w| w.contains("is not defined in any MTL")).collect();
    let unreadable: Vec<&String> =
        scene.warnings.iter().filter(|w| w.contains("cannot read material library")).collect();
    assert_eq!((undefined.len(), unreadable.len(), scene.warnings.len()), (10, 10, 22), "{:#?}", scene.warnings);
    assert!(scene.warnings.contains(&"test.obj: … and 20 more like this (unreadable material libraries)".to_string()));
    assert!(scene.warnings.contains(&"test.obj: … and 90 more like this (undefined materials)".to_string()));
    // Each summary comes right after the last warning it sums up.
    let summary = scene.warnings.iter().position(|w| w.contains("90 more")).unwrap();
    assert!(scene.warnings[summary - 1].contains("ghost9\""), "{:#?}", scene.warnings);
    // Every triangle still has its material.
    assert_eq!(scene.materials.len(), 100);
}

// --- 4. Real-world OBJ files that mainstream loaders accept -------------------------------------

#[test]
fn attribute_indices_out_of_range_are_dropped_with_one_warning() {
    let obj = format!(
        "{TRIANGLE}vt 0 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 2//7 3//1\nf 1/1/1 2/5/2 3/-4/1\nf 1//0 2//-9223372036854775808 3//1\nf 1/0 2/1 3/1\n"
    );
    for chunk in [1, 8, usize::MAX] {
        let read = |_: &str| Err(io::Error::from(io::ErrorKind::NotFound));
        let scene = parse_obj_with_chunk_size(obj.as_bytes(), Path::new("test.obj"), &read, chunk).unwrap();
        assert_eq!(scene.mesh.triangle_count(), 5);
        let n = NO_INDEX;
        assert_eq!(scene.mesh.normal_indices, [[0, 0, 0], [0, n, 0], [0, n, 0], [n, n, 0], [n, n, n]], "chunk {chunk}");
        assert_eq!(scene.mesh.texcoord_indices, [[n, n, n], [n, n, n], [0, n, n], [n, n, n], [n, 0, 0]]);
        assert_eq!(
            scene.warnings,
            [
                "test.obj:8: 2 faces have texture-coordinate indices out of range (the first on this line); those \
                 texture coordinates are ignored",
                "test.obj:7: 3 faces have normal indices out of range (the first on this line); those normals are \
                 ignored",
            ],
            "chunk {chunk}"
        );
    }
    // Positions out of range stay errors, with file and line.
    let read = |_: &str| Err(io::Error::from(io::ErrorKind::NotFound));
    let error = parse_obj(format!("{TRIANGLE}vn 0 0 1\nf 1//1 2//1 4//1\n").as_bytes(), Path::new("test.obj"), &read);
    assert_eq!(error.unwrap_err().to_string(), "test.obj:5: position index 4 out of range: the file defines 3");
    // One face: singular.
    let scene = parse_with(format!("{TRIANGLE}f 1//1 2//1 3//1\n").as_bytes(), &[]);
    assert_eq!(
        scene.warnings,
        ["test.obj:4: 1 face has normal indices out of range (the first on this line); its normals are ignored"]
    );
}

#[test]
fn mtllib_names_with_escaped_spaces() {
    let dir = TempDir::new("escaped-spaces");
    dir.write("my file.mtl", "newmtl red\nKd 1 0 0\n");
    dir.write("other lib.mtl", "newmtl blue\nKd 0 0 1\n");
    dir.write("plain.mtl", "newmtl green\nKd 0 1 0\n");
    let obj = format!(
        "mtllib my\\ file.mtl\nmtllib other\\ lib.mtl plain.mtl\n{TRIANGLE}usemtl red\nf 1 2 3\nusemtl blue\nf 1 2 3\nusemtl green\nf 1 2 3\n"
    );
    let scene = load_ok(&dir.write("scene.obj", obj));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let names: Vec<&str> = scene.mesh.material_ids.iter().map(|&m| scene.materials[m as usize].name.as_str()).collect();
    assert_eq!(names, ["red", "blue", "green"]);
    assert_eq!(scene.materials[scene.mesh.material_ids[1] as usize].kd, glam::Vec3::Z);
}

fn gzip(text: &[u8]) -> Vec<u8> {
    let mut encoder = GzEncoder::new(Vec::new(), Compression::default());
    encoder.write_all(text).unwrap();
    encoder.finish().unwrap()
}

#[test]
fn zero_padding_after_a_gzip_stream_is_accepted_and_garbage_is_named() {
    let dir = TempDir::new("gzip-padding");
    let text = format!("{TRIANGLE}f 1 2 3\n");
    let member = gzip(text.as_bytes());
    let padded = [&member[..], &member[..], &[0u8; 1024][..]].concat();
    let scene = load_ok(&dir.write("padded.obj.gz", &padded));
    assert_eq!(scene.mesh.triangle_count(), 2);
    assert_eq!(gunzip(&[&member[..], &[0]].concat(), 1 << 20).unwrap(), text.as_bytes());

    let garbage = [&member[..], b"garbage after the member"].concat();
    let path = dir.write("garbage.obj.gz", &garbage);
    assert_eq!(
        load_error(&path),
        format!(
            "{}: 24 bytes after the end of the gzip stream (from byte {}) are not gzip data; the file is corrupt or \
             has something appended",
            path.display(),
            member.len()
        )
    );
    let zeros_then_garbage = [&member[..], &[0u8; 16], b"x"].concat();
    assert!(load_error(&dir.write("zg.obj.gz", &zeros_then_garbage)).contains("17 bytes after the end"));
    let broken_second = [&member[..], &member[..10]].concat();
    let message = load_error(&dir.write("broken.obj.gz", &broken_second));
    assert!(message.contains(&format!("gzip member at byte {}", member.len())), "{message}");
    for (name, bytes) in [("empty.obj.gz", &b""[..]), ("plain.obj.gz", b"v 0 0 0\n")] {
        let message = load_error(&dir.write(name, bytes));
        assert!(message.starts_with(&format!("{}: ", dir.path(name).display())), "{message}");
    }
    assert!(read_input(&dir.path("plain.obj.gz")).unwrap_err().to_string().starts_with("not a valid gzip file"));
}

#[test]
fn an_mtl_given_as_the_scene_says_what_to_give() {
    let dir = TempDir::new("mtl-as-scene");
    let path = dir.write("materials.mtl", "newmtl red\nKd 1 0 0\n");
    let message = Scene::load(&path).map(|_| ()).unwrap_err().to_string();
    assert_eq!(
        message,
        format!(
            "{}: is a material library (.mtl), not a scene; give the .obj file that names it with mtllib",
            path.display()
        )
    );
}

/// The inflation cap is the most bytes a stream may give: exactly that many are accepted, over
/// several members too, and one more is refused.
#[test]
fn gzip_inflating_to_exactly_its_cap_is_accepted() {
    let text = b"v 0 0 0\nv 1 0 0\n";
    let member = gzip(text);
    let cap = text.len() as u64;
    assert_eq!(gunzip(&member, cap).unwrap(), text);
    assert_eq!(gunzip(&[&member[..], &member[..]].concat(), 2 * cap).unwrap(), [&text[..], &text[..]].concat());
    let error = gunzip(&member, cap - 1).unwrap_err();
    assert_eq!(error.kind(), io::ErrorKind::OutOfMemory, "{error}");
    assert!(gunzip(&[&member[..], &member[..]].concat(), 2 * cap - 1).is_err());
}
