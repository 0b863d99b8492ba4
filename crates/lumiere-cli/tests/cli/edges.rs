//! Trust at the edges (docs/RELIABILITY.md): closed and full streams, budgets and signals inside a
//! costly pass, outputs that would clobber inputs or each other, flags that are out of range or do
//! nothing, and images that come out black. Every case runs the binary as a user would.

use std::fs;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use crate::common::TempDir;

fn lumiere() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lumiere"))
}

fn run(args: &[&str]) -> Output {
    lumiere().args(args).output().expect("the binary runs")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A scene with a material library that does not exist: loading it warns.
fn scene_with_a_warning(dir: &TempDir) -> String {
    dir.write("warn.obj", "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    dir.arg("warn.obj")
}

// ---------------------------------------------------------------------------------------------
// Closed and full streams

#[test]
fn a_closed_stdout_ends_the_command_quietly() {
    let dir = TempDir::new("closed-stdout");
    let scene = scene_with_a_warning(&dir);
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = lumiere().args(["info", &scene]).stdout(writer).stderr(Stdio::piped()).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(!stderr(&out).contains("panicked"), "{}", stderr(&out));
}

#[test]
fn a_full_stdout_is_an_error_not_a_panic() {
    let dir = TempDir::new("full-stdout");
    let scene = scene_with_a_warning(&dir);
    let full = fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let out = lumiere().args(["info", &scene]).stdout(full).stderr(Stdio::piped()).output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("<stdout>: No space left on device"), "{}", stderr(&out));
    // Help and version too: they exited 0 having written nothing.
    for args in [&["--help"][..], &["-V"], &["render", "-h"], &["help", "render"]] {
        let full = fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let out = lumiere().args(args).stdout(full).stderr(Stdio::piped()).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains("<stdout>: No space left on device"), "{args:?}: {}", stderr(&out));
    }
    // Written where it can be, help still exits 0.
    let out = lumiere().arg("--help").output().unwrap();
    assert!(out.status.success() && String::from_utf8_lossy(&out.stdout).contains("Usage"), "{}", stderr(&out));
}

/// Warnings that meet a closed stderr (`2>&1 | head`) must not cost the render.
#[test]
fn a_closed_stderr_does_not_lose_the_render() {
    let dir = TempDir::new("closed-stderr");
    let scene = scene_with_a_warning(&dir);
    let image = dir.arg("out.png");
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let status = lumiere()
        .args(["render", &scene, "--size", "16x12", "--mode", "hits", "-o", &image])
        .stderr(writer)
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(0));
    assert!(fs::metadata(&image).unwrap().len() > 0);
}

// ---------------------------------------------------------------------------------------------
// Budgets and signals inside a pass

/// Two million shadow rays per light per pixel: one pass would take minutes. The budget stops it
/// within the pixel, and the message says why the image is black. At 4x4 (one tile of one block,
/// 200 million rays per light per pixel: a pass of half a minute) the stop falls in the tile's
/// last block, after which nothing was checked: the cut pass was written as a whole one, black.
#[test]
fn the_time_budget_stops_inside_a_costly_pass() {
    for (size, samples) in [("64x48", "2000000"), ("4x4", "200000000")] {
        let dir = TempDir::new("costly-budget");
        let start = Instant::now();
        let out = run(&[
            "render",
            "--mode",
            "direct",
            "--samples",
            samples,
            "--size",
            size,
            "--time",
            "300ms",
            "-o",
            &dir.arg("o.png"),
        ]);
        let took = start.elapsed();
        assert_eq!(out.status.code(), Some(2), "{size}: {}", stderr(&out));
        assert!(took < Duration::from_secs(5), "{size}: took {took:?}");
        let message = stderr(&out);
        assert!(
            message.contains("time budget reached before the first pass completed, so nothing was written"),
            "{size}: {message}"
        );
        // No pass, no image: a black one would have replaced the file.
        assert!(!dir.path("o.png").exists(), "{size}");
    }
}

#[test]
fn ctrl_c_stops_inside_a_costly_pass() {
    let dir = TempDir::new("costly-signal");
    // An image already there is kept: the interrupted render completed no pass to replace it with.
    std::fs::write(dir.path("o.png"), b"an earlier render").unwrap();
    let child = lumiere()
        .args(["render", "--mode", "ao", "--samples", "5000000", "--size", "64x48", "-o", &dir.arg("o.png")])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(500));
    let sent = Instant::now();
    let status = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    assert!(sent.elapsed() < Duration::from_secs(5), "took {:?} to stop", sent.elapsed());
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("interrupted before the first pass completed: nothing was written"),
        "{}",
        stderr(&out)
    );
    assert_eq!(std::fs::read(dir.path("o.png")).unwrap(), b"an earlier render");
}

/// `--time` without `--spp` renders until the budget is met, not one pass.
#[test]
fn a_budget_without_spp_renders_until_it_is_met() {
    let dir = TempDir::new("budget-no-spp");
    let stats = dir.arg("s.json");
    let out = run(&[
        "render",
        "--mode",
        "ao",
        "--samples",
        "2",
        "--size",
        "16x12",
        "--time",
        "300ms",
        "--stats-json",
        &stats,
        "-o",
        &dir.arg("o.png"),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&fs::read(&stats).unwrap()).unwrap();
    assert!(json["spp"].as_u64().unwrap() > 1, "{json}");
    assert_eq!(json["stop"], "time budget reached");
    assert!(stderr(&out).contains("of unlimited spp"), "{}", stderr(&out));
}

// ---------------------------------------------------------------------------------------------
// Outputs never clobber

/// Runs a render that must be refused: exit code 2, `expected` in its one-line message, and the
/// files in `dir` unchanged.
fn assert_refused(dir: &TempDir, args: &[&str], expected: &str) {
    let before: Vec<(String, Vec<u8>)> =
        dir.entries().into_iter().map(|name| (name.clone(), fs::read(dir.path(&name)).unwrap_or_default())).collect();
    let out = run(args);
    let message = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {message}");
    assert!(message.contains(expected), "{args:?}: expected {expected:?} in {message}");
    assert_eq!(message.trim_end().lines().count(), 1, "{args:?}: not one line: {message}");
    let after: Vec<(String, Vec<u8>)> =
        dir.entries().into_iter().map(|name| (name.clone(), fs::read(dir.path(&name)).unwrap_or_default())).collect();
    assert_eq!(before, after, "{args:?} changed the folder");
}

/// Refused before any work, and with a message instead of an abort: an AOV asked twice (an EXR
/// cannot hold it), a benchmark's JSON that is not a `.json` file (`--json scene.obj` replaced the
/// scene) or that cannot be written (it was refused after the whole benchmark), repetitions whose
/// times do not fit in memory, more threads than `render` allows, and a sampler benchmark with no
/// seed (it printed a table of NaN) or no reference sample.
#[test]
fn bad_outputs_and_counts_are_refused_before_the_work() {
    let dir = TempDir::new("refused-early");
    let exr = dir.arg("o.exr");
    assert_refused(
        &dir,
        &["render", "--size", "8x6", "--aov", "albedo,depth,albedo", "-o", &exr],
        "--aov albedo is given twice",
    );
    fs::write(dir.path("scene.obj"), "v 0 0 0\n").unwrap();
    fs::create_dir(dir.path("folder.json")).unwrap();
    for (args, expected) in [
        (vec!["bench-bvh", "--scenes", "cornell", "--json", &dir.arg("folder.json")], "is a directory"),
        (vec!["bench-sampler", "--size", "65536x65536"], "beside its reference image needs"),
        (vec!["bench", "--quick", "--json", &dir.arg("scene.obj")], "expected a .json file name"),
        (vec!["bench", "--repeats", "4294967296"], "from 1 to 1000"),
        (vec!["bench", "--repeats", "0"], "from 1 to 1000"),
        (vec!["bench-bvh", "--scenes", "cornell", "--threads", "100000"], "at most 1024 threads"),
        (vec!["bench", "--quick", "--json", &dir.arg("missing/x.json")], "missing does not exist"),
        (vec!["bench-bvh", "--scenes", "cornell", "--json", &dir.arg("missing/x.json")], "missing does not exist"),
        (vec!["bench-sampler", "--size", "4x3", "--seeds", "0"], "from 1 to 1000"),
        (vec!["bench-sampler", "--size", "4x3", "--reference-samples", "0"], "from 1 to 65536"),
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(expected), "{args:?}: {}", stderr(&out));
        assert!(out.stdout.is_empty(), "{args:?} printed before refusing: {}", String::from_utf8_lossy(&out.stdout));
    }
    assert_eq!(fs::read(dir.path("scene.obj")).unwrap(), b"v 0 0 0\n");
}

#[test]
fn outputs_that_are_inputs_or_each_other_are_refused() {
    let dir = TempDir::new("clobber");
    let scene = dir.write("scene.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let scene = scene.to_str().unwrap();
    let out = dir.arg("out.png");
    let small = ["render", "--size", "8x6"];
    let json = dir.arg("out.json");
    assert_refused(
        &dir,
        &[&small[..], &["-o", &out, "--stats-json", &json, "--checkpoint", &json]].concat(),
        "are the same file",
    );
    assert_refused(
        &dir,
        &[&small[..], &[scene, "-o", &out, "--checkpoint", scene]].concat(),
        "an output would overwrite an input",
    );
    // The same file under another name (a relative path with `..`) is caught by device and inode.
    let other_name = format!("{}/../{}/scene.obj", dir.0.display(), dir.0.file_name().unwrap().to_string_lossy());
    assert_refused(&dir, &[&small[..], &[scene, "-o", &out, "--checkpoint", &other_name]].concat(), "same file");
    // As root, a rename over a device node would replace it with a regular file.
    assert_refused(&dir, &[&small[..], &["-o", &out, "--checkpoint", "/dev/null"]].concat(), "not a regular file");
    // Here stdout is a pipe: the link /dev/stdout leads to nothing a file can replace.
    assert_refused(&dir, &[&small[..], &["-o", &out, "--checkpoint", "/dev/stdout"]].concat(), "is a link to nothing");
    assert_refused(&dir, &[&small[..], &["-o", &dir.arg("out")]].concat(), "has no extension");
}

/// A slip of the name (`--stats-json notes.txt`, `--checkpoint notes.txt`) must not replace a file
/// that is no input of the render: the statistics go only to a .json file, and a checkpoint
/// replaces only a checkpoint (or an empty file).
#[test]
fn the_statistics_and_the_checkpoint_replace_only_their_own_kind_of_file() {
    let dir = TempDir::new("own-kind");
    dir.write("notes.txt", "a user's notes");
    let (notes, out) = (dir.arg("notes.txt"), dir.arg("out.png"));
    let small = ["render", "--size", "8x6", "--mode", "hits", "-o", &out];
    assert_refused(&dir, &[&small[..], &["--stats-json", &notes]].concat(), "expected a .json file name");
    assert_refused(&dir, &[&small[..], &["--checkpoint", &notes]].concat(), "is not a lumiere checkpoint");
    // A checkpoint is replaced by the next one, and an empty file (nothing to lose) is taken.
    dir.write("empty.ckpt", "");
    let checkpoint = dir.arg("empty.ckpt");
    for _ in 0..2 {
        let run = run(&[&small[..], &["--checkpoint", &checkpoint, "--stats-json", &dir.arg("s.json")]].concat());
        assert_eq!(run.status.code(), Some(0), "{}", stderr(&run));
    }
    assert!(fs::read(dir.path("empty.ckpt")).unwrap().starts_with(b"LUMCKPT"));
    assert_eq!(fs::read(dir.path("notes.txt")).unwrap(), b"a user's notes");
}

/// The files a scene's materials name (a texture, a cutout mask) are inputs too.
#[test]
fn outputs_that_are_textures_or_masks_are_refused() {
    let dir = TempDir::new("clobber-textures");
    dir.write("m.mtl", "newmtl leaf\nmap_Kd colour.png\nmap_d mask.png\n");
    let scene = dir.write("scene.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl leaf\nf 1/1 2/1 3/1\n");
    dir.write("colour.png", "not decoded before the refusal");
    dir.write("mask.png", "not decoded before the refusal");
    let scene = scene.to_str().unwrap();
    for file in ["colour.png", "mask.png"] {
        let args = ["render", "--size", "8x6", scene, "-o", &dir.arg(file)];
        assert_refused(&dir, &args, "which the scene reads");
    }
}

/// `--threads 0` (the default) follows `RAYON_NUM_THREADS`, as rayon does, but never past the cap
/// that `--threads` has: 100,000 threads would take minutes to start, or exhaust the system's limit.
#[test]
fn the_environments_thread_count_is_capped_as_the_flags() {
    let dir = TempDir::new("threads-environment");
    let out = lumiere()
        .args(["render", "--size", "16x12", "--mode", "hits", "--stats-json", "-", "-o", &dir.arg("o.png")])
        .env("RAYON_NUM_THREADS", "100000")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let stats = String::from_utf8_lossy(&out.stdout);
    assert!(stats.contains("\"threads\": 1024"), "{stats}");
    let out = lumiere().args(["info"]).env("RAYON_NUM_THREADS", "100000").output().unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    // The benchmarks' tables name the count that ran, not the 0 that asked for it.
    let json = dir.arg("bvh.json");
    let out = lumiere()
        .args(["bench-bvh", "--scenes", "cornell", "--threads", "0", "--repeats", "1", "--json", &json])
        .env("RAYON_NUM_THREADS", "3")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let rows: serde_json::Value = serde_json::from_slice(&fs::read(dir.path("bvh.json")).unwrap()).unwrap();
    let rows = rows.as_array().expect("a list of rows");
    assert!(!rows.is_empty() && rows.iter().all(|row| row["threads"] == 3), "{rows:?}");
}

#[test]
fn stats_go_to_stdout_with_a_dash() {
    let dir = TempDir::new("stats-stdout");
    let out = run(&["render", "--size", "8x6", "--mode", "hits", "--stats-json", "-", "-o", &dir.arg("o.png")]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["mode"], "hits");
    assert_eq!(dir.entries(), ["o.png"]);
}

/// A legal output name of 250 bytes still gets its temporary file, which is then gone.
#[test]
fn long_output_names_are_written() {
    let dir = TempDir::new("long-name");
    let name = format!("{}.png", "a".repeat(246));
    let out = run(&["render", "--size", "8x6", "--mode", "hits", "-o", &dir.arg(&name)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(dir.entries(), [name]);
}

/// `bench-bvh --export-rays` writes a scene's files as one folder, whole or not at all: a run
/// that fails half-way (here, files capped at 10 MB by `ulimit -f`, as a full disk would stop it)
/// leaves the last complete set as it was, with no stray folder beside it; the next run replaces
/// it. A scene folder that is a file is refused before anything is measured.
#[test]
fn exported_rays_replace_the_last_set_whole_or_not_at_all() {
    let dir = TempDir::new("export-rays");
    let export = ["bench-bvh", "--scenes", "cornell", "--threads", "1", "--repeats", "1", "--export-rays"];
    let out = run(&[&export[..], &[&dir.arg("rays")]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let files = |dir: &std::path::Path| {
        let mut names: Vec<String> =
            fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        names
    };
    let set = files(&dir.path("rays/cornell"));
    assert_eq!(set.len(), 9, "{set:?}");
    // Marks the complete set, to tell whether a later run replaced it, or any file of it.
    fs::write(dir.path("rays/cornell/kept"), "").unwrap();
    let inodes = || {
        use std::os::unix::fs::MetadataExt;
        set.iter().map(|name| fs::metadata(dir.path("rays/cornell").join(name)).unwrap().ino()).collect::<Vec<_>>()
    };
    let before = inodes();
    // A shell that ignores SIGXFSZ, so that the capped write fails with EFBIG rather than killing.
    let capped = Command::new("sh")
        .arg("-c")
        .arg("trap '' XFSZ; ulimit -f 20000; exec \"$@\"")
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_lumiere"))
        .args(export)
        .arg(dir.arg("rays"))
        .output()
        .unwrap();
    assert_eq!(capped.status.code(), Some(2), "{}", stderr(&capped));
    assert!(stderr(&capped).contains("cornell/"), "{}", stderr(&capped));
    assert!(dir.path("rays/cornell/kept").exists(), "the last set was replaced");
    assert_eq!(inodes(), before, "files of the last set were replaced");
    assert_eq!(files(&dir.path("rays")), ["cornell"], "a stray folder was left");
    let out = run(&[&export[..], &[&dir.arg("rays")]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(files(&dir.path("rays/cornell")), set, "the set was not replaced whole");
    assert_eq!(files(&dir.path("rays")), ["cornell"]);

    fs::create_dir(dir.path("other")).unwrap();
    dir.write("other/cornell", "mine");
    let out = run(&[&export[..], &[&dir.arg("other")]].concat());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("exists and is not a folder"), "{}", stderr(&out));
    assert!(out.stdout.is_empty(), "printed before refusing: {}", String::from_utf8_lossy(&out.stdout));
    assert_eq!(fs::read(dir.path("other/cornell")).unwrap(), b"mine");
    // An export folder that is a device or a dangling link is named as such, not "File exists".
    std::os::unix::fs::symlink(dir.path("nowhere"), dir.path("dangling")).unwrap();
    for (folder, expected) in
        [("/dev/null".to_string(), "exists and is not a folder"), (dir.arg("dangling"), "is a link to nothing")]
    {
        let out = run(&[&export[..], &[&folder]].concat());
        assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
        assert!(stderr(&out).contains(expected), "{}", stderr(&out));
        assert!(out.stdout.is_empty(), "printed before refusing: {}", String::from_utf8_lossy(&out.stdout));
    }
}

// ---------------------------------------------------------------------------------------------
// Flags

/// `--emission` names a material once (two values for it: which was meant?), and a name with a
/// newline or a terminal escape is shown escaped, on one line.
#[test]
fn emission_names_are_given_once_and_shown_on_one_line() {
    let dir = TempDir::new("emission-names");
    let out = dir.arg("o.png");
    let twice =
        ["render", "--size", "8x6", "--emission", "light.001=1,1,1", "--emission", "light.001=2,2,2", "-o", &out];
    assert_refused(&dir, &twice, "--emission 'light.001' is given twice");
    assert_refused(
        &dir,
        &["render", "--size", "8x6", "--emission", "a\nb=1,1,1", "-o", &out],
        r#"no material named "a\nb""#,
    );
    assert_refused(&dir, &["render", "--size", "8x6", "--emission", "z\u{1b}[2J=1,1,1", "-o", &out], r#""z\u{1b}[2J""#);
    // A name may hold `=`: the colour follows the last one, as `python -m lumiere.distributed` reads it.
    fs::write(dir.path("eq.mtl"), "newmtl a=b\nKd 1 1 1\n").unwrap();
    fs::write(dir.path("eq.obj"), "mtllib eq.mtl\nusemtl a=b\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let args = ["render", &dir.arg("eq.obj"), "--emission", "a=b=1,1,1", "--size", "8x6", "--eye", "0,0,3"];
    let run = lumiere().args(args).args(["--target", "0,0,0", "-o", &out]).output().unwrap();
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(!stderr(&run).contains("black"), "the triangle emits: {}", stderr(&run));
}

/// A field of view too narrow to frame a scene from a finite distance is named, not taken for
/// bounds too large to frame.
#[test]
fn a_field_of_view_too_narrow_to_frame_is_named() {
    let dir = TempDir::new("narrow-fov");
    fs::write(dir.path("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let args = ["render", &dir.arg("t.obj"), "--fov", "1e-40", "--size", "8x6", "-o", &dir.arg("o.png")];
    assert_refused(&dir, &args, "a field of view of 1e-40 degrees is too narrow to frame it; give --eye and --target");
    // Framed from a finite distance, but one at which single precision sees nothing (a black image).
    let args = ["render", &dir.arg("t.obj"), "--fov", "1e-30", "--size", "8x6", "-o", &dir.arg("o.png")];
    assert_refused(&dir, &args, "a field of view of 1e-30 degrees is too narrow to frame it");
    let args =
        ["render", &dir.arg("t.obj"), "--fov", "0.01", "--mode", "hits", "--size", "8x6", "-o", &dir.arg("o.png")];
    let out = lumiere().args(args).output().unwrap();
    assert!(out.status.success() && !stderr(&out).contains("black"), "{}", stderr(&out));
}

#[test]
fn numeric_flags_out_of_range_are_refused() {
    let cases: [(&[&str], &str); 15] = [
        (&["--fov", "0"], "between 0 and 180"),
        // The library's "unlimited": it would render without end.
        (&["--spp", "4294967295"], "not in 1..=4294967294"),
        (&["--fov", "1e40"], "between 0 and 180"),
        (&["--fov", "nan"], "finite"),
        (&["--threads", "10000"], "at most 1024 threads"),
        (&["--time", "-1s"], "positive"),
        (&["--time", "1e3x"], "expected a duration"),
        (&["--preview-every", "nan"], "finite"),
        (&["--preview-every", "-2"], "positive"),
        (&["--checkpoint-every", "-1"], "must not be negative"),
        (&["--noise", "0"], "positive"),
        (&["--eye", "1e38,0,0", "--target", "-3e38,0,0"], "too far apart"),
        // What clap refuses is one line too, as every other refusal.
        (&["--eye", "0,1,3"], "the following required arguments were not provided: --target <TARGET>"),
        (&["--bogus"], "unexpected argument '--bogus' found"),
        (&["--mode", "xyz"], "invalid value 'xyz' for '--mode <MODE>'; [possible values: hits,"),
    ];
    let dir = TempDir::new("flags");
    for (flags, expected) in cases {
        let out = run(&[&["render", "--size", "8x6", "-o", &dir.arg("o.png")][..], flags].concat());
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(expected), "{flags:?}: expected {expected:?} in {}", stderr(&out));
        assert_eq!(stderr(&out).trim_end().lines().count(), 1, "{flags:?}: not one line: {}", stderr(&out));
        assert!(dir.entries().is_empty(), "{flags:?} wrote a file");
    }
    // An exponent in a duration is a number, not a unit.
    let out =
        run(&["render", "--size", "8x6", "--mode", "hits", "--time", "1e3s", "--spp", "1", "-o", &dir.arg("o.png")]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn flags_that_do_nothing_are_warned() {
    let dir = TempDir::new("ignored");
    let out = run(&[
        "render",
        "--size",
        "8x6",
        "--mode",
        "hits",
        "--samples",
        "4",
        "--ao-distance",
        "2",
        "--light-sampling",
        "power",
        "--fov",
        "30",
        "--sampler",
        "sobol",
        "-o",
        &dir.arg("o.png"),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let message = stderr(&out);
    for flag in ["--samples", "--ao-distance", "--light-sampling", "--fov", "--sampler"] {
        assert!(message.contains(&format!("warning: {flag} has no effect")), "{flag}: {message}");
    }
    assert!(!message.contains("--up"), "{message}");
    // Jittered passes draw numbers: the sampler then matters in every mode.
    let jittered = format!("render --size 8x6 --mode hits --spp 2 --sampler sobol -o {}", dir.arg("o.png"));
    let out = run(&jittered.split(' ').collect::<Vec<_>>());
    assert!(out.status.success() && !stderr(&out).contains("--sampler"), "{}", stderr(&out));

    // The PNG's flags on a linear output, --up on the built-in scene's orbiter, and a checkpoint
    // period without a checkpoint.
    let out = run(&[
        "render",
        "--size",
        "8x6",
        "--spp",
        "1",
        "--exposure",
        "1",
        "--tonemap",
        "clamp",
        "--png-linear",
        "--up",
        "1,0,0",
        "--checkpoint-every",
        "5",
        "-o",
        &dir.arg("o.exr"),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let message = stderr(&out);
    for flag in ["--exposure", "--tonemap", "--png-linear", "--up", "--checkpoint-every"] {
        assert!(message.contains(&format!("warning: {flag} has no effect")), "{flag}: {message}");
    }
    assert!(message.contains("on a .exr output (PNG only"), "{message}");
}

/// A render of one sample per pixel centre cannot be continued with jittered samples: the
/// refusal says so instead of silently mixing the two.
#[test]
fn a_one_sample_checkpoint_is_not_continued_with_more() {
    let dir = TempDir::new("spp1");
    let checkpoint = dir.arg("c.ckpt");
    let base = ["render", "--size", "8x6", "--mode", "ao", "--samples", "2"];
    let out = run(&[&base[..], &["--spp", "1", "--checkpoint", &checkpoint, "-o", &dir.arg("a.png")]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let out = run(&[&base[..], &["--spp", "4", "--resume", &checkpoint, "-o", &dir.arg("b.png")]].concat());
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("pixel positions (checkpoint: centres (--spp 1)"), "{}", stderr(&out));
}

// ---------------------------------------------------------------------------------------------
// Black images explain themselves

#[test]
fn a_scene_without_emitters_says_why_it_is_black() {
    let dir = TempDir::new("unlit");
    let scene = dir.write("unlit.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n");
    let out = run(&["render", scene.to_str().unwrap(), "--size", "8x6", "-o", &dir.arg("o.png")]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("the scene has no emitters"), "{}", stderr(&out));
    assert!(stderr(&out).contains("--emission"), "{}", stderr(&out));
    // An emitting material whose only triangle has no area: not "make one emit", which was done.
    let flat = dir.write("flat.obj", "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nv 0 0 0\nf 1 2 3\nusemtl lamp\nf 4 4 4\n");
    let out =
        run(&["render", flat.to_str().unwrap(), "--emission", "lamp=1,1,1", "--size", "8x6", "-o", &dir.arg("f.png")]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains(r#"no triangle of the emitting material "lamp" can emit"#), "{}", stderr(&out));
    assert!(!stderr(&out).contains("make one emit"), "{}", stderr(&out));
}

#[test]
fn a_camera_that_sees_nothing_says_so() {
    let dir = TempDir::new("looks-away");
    let out = run(&[
        "render",
        "--size",
        "8x6",
        "--mode",
        "hits",
        "--eye",
        "0,1,3",
        "--target",
        "0,1,10",
        "-o",
        &dir.arg("o.png"),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    // The hit mask is the check the other modes' warning points to: it says what it saw itself.
    assert!(stderr(&out).contains("the image is black: no camera ray hit the scene"), "{}", stderr(&out));
}

/// A signal while a large scene loads exits at once with the documented code, writing nothing.
#[test]
fn ctrl_c_while_loading_exits_3_and_writes_nothing() {
    let dir = TempDir::new("signal-load");
    // Three million faces in 35 KB of gzip: loading and building take about half a second.
    let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    text.push_str(&"f 1 2 3\n".repeat(3_000_000));
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut gz, text.as_bytes()).unwrap();
    let scene = dir.write("big.obj.gz", gz.finish().unwrap());
    // `--samples` does nothing in the default mode: its warning is written after the handler is
    // installed and just before the scene loads, so the signal is sent once it is read rather than
    // at a guessed moment (150 ms after the start would be too early for a process slow to start,
    // and too late where loading and building take less than that).
    let mut child = lumiere()
        .args(["render", scene.to_str().unwrap(), "--samples", "4", "--size", "8x6", "-o", &dir.arg("o.png")])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut text = String::new();
    std::io::BufRead::read_line(&mut lines, &mut text).unwrap();
    assert!(text.contains("--samples has no effect in --mode path"), "{text}");
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    // Read to the end (the child's exit) before waiting: a child blocked on a full pipe never exits.
    std::io::Read::read_to_string(&mut lines, &mut text).unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(3), "{text}");
    assert!(text.contains("interrupted while loading"), "{text}");
    assert_eq!(dir.entries(), ["big.obj.gz"]);
}

/// `info` works on the built-in scene, names every material (what `--emission` needs) with its
/// triangle count and the scattering it maps to, and never prints a negative zero.
#[test]
fn info_names_materials_and_prints_no_negative_zero() {
    let out = run(&["info"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("\"light.001\": 2 triangles, lambert, Kd") && text.contains("(a light)"), "{text}");
    assert!(text.contains("materials  8"), "{text}");
    let dir = TempDir::new("info-kinds");
    dir.write(
        "kinds.mtl",
        "newmtl glass\nKd 0 0 0\nKs 1 1 1\nNi 1.5\nillum 7\nnewmtl mirror\nKd 0 0 0\nKs 1 1 1\nillum 3\n\
         newmtl brass\nKd 0.5 0.4 0.3\nPm 1\nPr 0.5\nnewmtl painted\nmap_Pm -imfchan b orm.png\nmap_Pr -imfchan g orm.png\n\
         newmtl worn\nPm 1\nmap_Pr -s 2 2 worn.png\nnewmtl bumpy\nmap_Bump -bm 0.5 bumps.png\n\
         newmtl normals\nnorm normals.png\nnewmtl veil\nd 0.3\n",
    );
    let scene = dir.write(
        "kinds.obj",
        "mtllib kinds.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl glass\nf 1 2 3\nusemtl mirror\nf 1 2 3\nusemtl brass\nf 1 2 3\n\
         usemtl painted\nf 1 2 3\nusemtl worn\nf 1 2 3\nusemtl bumpy\nf 1 2 3\nusemtl normals\nf 1 2 3\nusemtl veil\nf 1 2 3\n",
    );
    let out = run(&["info", scene.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("\"glass\": 1 triangles, dielectric (eta 1.500000, Tf (1.000000, 1.000000, 1.000000))\n"),
        "{text}"
    );
    assert!(text.contains("\"mirror\": 1 triangles, mirror (F0 (1.000000, 1.000000, 1.000000))\n"), "{text}");
    assert!(
        text.contains("\"brass\": 1 triangles, conductor (F0 the base colour, alpha 0.250000), Kd (0.500000"),
        "{text}"
    );
    // Where maps paint the metallic weight or the roughness, the kind varies over the surface.
    let orm = dir.path("orm.png").display().to_string();
    assert!(
        text.contains(&format!(
            "\"painted\": 1 triangles, conductor where map_Pm reaches 0.5, plastic (Ks 0.04) elsewhere (alpha from \
             map_Pr), Kd (0.800000, 0.800000, 0.800000), map_Pm {orm:?} (blue x 1.000000), map_Pr {orm:?} (green x 1.000000)\n"
        )),
        "{text}"
    );
    assert!(text.contains("\"worn\": 1 triangles, conductor (F0 the base colour, alpha from map_Pr)"), "{text}");
    assert!(text.contains("map_Pr -s 2.000000 2.000000 -o 0.000000 0.000000 \""), "{text}");
    let (bumps, normals) = (dir.path("bumps.png").display().to_string(), dir.path("normals.png").display().to_string());
    assert!(
        text.contains(&format!(
            "\"bumpy\": 1 triangles, lambert, Kd (0.800000, 0.800000, 0.800000), bump map {bumps:?} (heights: \
             luminance x 0.500000; directions if the image has a normal map's colours)\n"
        )),
        "{text}"
    );
    assert!(text.contains(&format!("normal map {normals:?} (scale 1.000000)\n")), "{text}");
    // `d` below 1 on a surface that is not glass: partial coverage.
    assert!(text.contains("\"veil\": 1 triangles, lambert, Kd (0.800000, 0.800000, 0.800000), covering 0.300000 of the surface, hashed\n"), "{text}");
    // The maps' files are missing: named once each, as a render would.
    for file in ["orm.png", "worn.png", "bumps.png", "normals.png"] {
        let warning = format!("{:?}: ", dir.path(file).display().to_string());
        assert_eq!(stderr(&out).matches(&warning).count(), 1, "{}", stderr(&out));
    }
    for instead in
        ["the material's metallic and roughness values are used instead", "the surface keeps its interpolated normals"]
    {
        assert!(stderr(&out).contains(&format!("; {instead}")), "{}", stderr(&out));
    }
    let dir = TempDir::new("info-unlit");
    let scene = dir.write("unlit.obj", "v 0 0 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\n");
    let out = run(&["info", scene.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("lights     0 triangles, area 0.000000"), "{text}");
    assert!(!text.contains("-0.000000"), "{text}");
}

/// A scene without a face renders nothing in any mode: refused, where a file of vertices alone
/// rendered black with a warning about its emitters, and an empty one asked for a camera.
#[test]
fn a_scene_without_faces_is_refused() {
    let dir = TempDir::new("no-faces");
    for (name, text) in [("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"), ("empty.obj", "")] {
        let scene = dir.write(name, text);
        let out = run(&["render", "--size", "8x6", "--mode", "ao", scene.to_str().unwrap(), "-o", &dir.arg("o.png")]);
        assert_eq!(out.status.code(), Some(2), "{name}: {}", stderr(&out));
        assert!(
            stderr(&out).ends_with(&format!("{name}: the scene has no faces, so there is nothing to render\n")),
            "{}",
            stderr(&out)
        );
    }
    assert!(!dir.path("o.png").exists());
}

/// `info` says what a render does with a mask on an emitter (ignores it, with the render's
/// warning), where it listed the mask as a cutout and asked for its file.
#[test]
fn info_warns_as_a_render_of_a_mask_on_an_emitter() {
    let dir = TempDir::new("info-emitter-mask");
    dir.write("m.mtl", "newmtl lamp\nKe 1 1 1\nmap_d missing-mask.png\n");
    let scene = dir.write("s.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\n");
    let warning = "warning: material 'lamp': map_d is ignored on an emitter; it stays opaque";
    let render = run(&["render", "--size", "8x6", "--spp", "1", scene.to_str().unwrap(), "-o", &dir.arg("o.png")]);
    assert!(render.status.success() && stderr(&render).contains(warning), "{}", stderr(&render));
    let info = run(&["info", scene.to_str().unwrap()]);
    let (text, message) = (String::from_utf8_lossy(&info.stdout), stderr(&info));
    assert!(info.status.success() && message.contains(warning), "{message}");
    assert!(!text.contains("cutout") && !message.contains("missing-mask.png"), "{text}{message}");
}

/// An existing output that its owner made read-only is refused and kept, as `cp` would refuse to
/// write into it (the atomic rename alone would replace it). Root may write into any file, so
/// when the tests run as root the binary runs as an unprivileged user.
#[test]
#[cfg(unix)]
fn a_read_only_output_is_refused_and_kept() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    use std::os::unix::process::CommandExt;
    let dir = TempDir::new("read-only");
    fs::set_permissions(&dir.0, fs::Permissions::from_mode(0o777)).unwrap();
    let target = dir.write("kept.png", b"precious");
    let render = |mode: u32| {
        fs::set_permissions(&target, fs::Permissions::from_mode(mode)).unwrap();
        let mut command = lumiere();
        if fs::metadata("/proc/self").is_ok_and(|m| m.uid() == 0) {
            command.uid(65534).gid(65534);
        }
        command.args(["render", "--mode", "hits", "--size", "8x6", "-o", &dir.arg("kept.png")]).output().unwrap()
    };
    let out = render(0o444);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("kept.png: exists and is read-only"), "{}", stderr(&out));
    assert_eq!(fs::read(&target).unwrap(), b"precious");
    assert_eq!(dir.entries(), ["kept.png"]);
    // Writable, it is replaced: the refusal above came from the permission alone.
    let out = render(0o666);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_ne!(fs::read(&target).unwrap(), b"precious");
}

/// `lumiere info` names a texture that is missing or not a file, as a render would, so that a
/// surface that comes out plain is explained before any render.
#[test]
fn info_names_missing_textures() {
    let dir = TempDir::new("info-textures");
    dir.write("m.mtl", "newmtl a\nmap_Kd -s 2 2 missing wood.png\nnewmtl b\nmap_d folder.png\nmap_Kd here.png\n");
    fs::create_dir(dir.path("folder.png")).unwrap();
    dir.write("here.png", b"any bytes: info does not decode");
    let obj = dir.write("s.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\nusemtl b\nf 1 2 3\n");
    let out = run(&["info", obj.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let warnings: Vec<String> =
        stderr(&out).lines().filter(|l| l.contains("warning: texture")).map(String::from).collect();
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(warnings[0].contains("missing wood.png") && warnings[0].contains("Kd is used instead"), "{warnings:?}");
    assert!(
        warnings[1].contains("folder.png\": is a directory, not a regular file; the material stays opaque"),
        "{warnings:?}"
    );
}
