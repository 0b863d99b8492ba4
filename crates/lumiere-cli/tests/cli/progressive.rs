//! Long renders: progressive passes, budgets, interruption, checkpoint and resume, and images that
//! stay finite on degenerate input.

use std::fs;
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use lumiere::integrators::Technique;
use lumiere::render::film::Film;
use lumiere::render::{Hooks, RenderOptions, RenderStats, StopReason, render, render_progressive};
use lumiere::scene::camera::Camera;
use lumiere::scene::{Scene, builtin};
use lumiere::world::World;

use crate::common::TempDir;

fn lumiere(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lumiere")).args(args).output().expect("the binary runs")
}

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_lumiere")).args(args).stderr(Stdio::piped()).spawn().expect("the binary runs")
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill").args([&format!("-{name}"), &child.id().to_string()]).status().unwrap();
    assert!(status.success());
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn small_world() -> (World, Camera) {
    let world = World::new(Scene::builtin().unwrap(), Default::default());
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter().unwrap(), 48, 36);
    (world, camera)
}

/// A render stopped after S passes holds exactly the bits of one asked for S samples.
#[test]
fn stopping_at_s_samples_equals_asking_for_s() {
    let (world, camera) = small_world();
    let options = RenderOptions { spp: 20, ..RenderOptions::new(Technique::direct(4)) };
    let cancel = AtomicBool::new(false);
    let mut passes = 0;
    let mut pass_done = |film: &Film, _: &RenderStats| {
        passes += 1;
        if film.samples == 3 {
            cancel.store(true, Ordering::Relaxed);
        }
        Ok(())
    };
    let hooks = Hooks { progress: &|_| {}, pass_done: &mut pass_done, cancel: &cancel };
    let film = Film::new(camera.width, camera.height).unwrap();
    let stopped = render_progressive(&world, &camera, &options, film, RenderStats::default(), hooks).unwrap();
    assert_eq!((stopped.stop, stopped.film.samples, passes), (StopReason::Interrupted, 3, 3));

    let asked = render(&world, &camera, &RenderOptions { spp: 3, ..options.clone() }, &|_| {}).unwrap();
    assert_eq!(asked.stop, StopReason::Completed);
    assert_eq!(stopped.image, asked.image);
    assert_eq!(stopped.film, asked.film);
}

/// Ambient occlusion until the relative error is 5% (a few passes at 48x36).
fn to_noise_target() -> RenderOptions {
    RenderOptions { spp: 10_000, noise_target: Some(0.05), ..RenderOptions::new(Technique::ambient_occlusion(8)) }
}

#[test]
fn noise_target_stops_early_with_the_error_reached() {
    let (world, camera) = small_world();
    let options = to_noise_target();
    let out = render(&world, &camera, &options, &|_| {}).unwrap();
    assert_eq!(out.stop, StopReason::NoiseTarget);
    assert!(out.film.samples < 10_000);
    assert!(out.film.relative_error().unwrap() <= 0.05);
    // One pass fewer would not have been enough (the stop is the first pass below the target).
    let fewer =
        render(&world, &camera, &RenderOptions { spp: out.film.samples - 1, noise_target: None, ..options }, &|_| {});
    assert!(fewer.unwrap().film.relative_error().unwrap() > 0.05);
}

/// A run killed after its last pass's checkpoint was written, but before it stopped, resumes to
/// the film it had: a film that already meets the target gets no further pass.
#[test]
fn a_resumed_film_that_meets_its_noise_target_gets_no_further_pass() {
    let (world, camera) = small_world();
    let options = to_noise_target();
    let done = render(&world, &camera, &options, &|_| {}).unwrap();
    assert_eq!(done.stop, StopReason::NoiseTarget);

    let cancel = AtomicBool::new(false);
    let mut passes = 0;
    let mut pass_done = |_: &Film, _: &RenderStats| {
        passes += 1;
        Ok(())
    };
    let hooks = Hooks { progress: &|_| {}, pass_done: &mut pass_done, cancel: &cancel };
    let resumed = render_progressive(&world, &camera, &options, done.film.clone(), done.stats, hooks).unwrap();
    assert_eq!((resumed.stop, passes), (StopReason::NoiseTarget, 0));
    assert_eq!(resumed.film, done.film);
    assert_eq!(resumed.image, done.image);
}

#[test]
fn time_budget_stops_after_the_crossing_pass_and_says_why() {
    let dir = TempDir::new("time");
    let out = dir.arg("t.png");
    let start = Instant::now();
    let run = lumiere(&[
        "render",
        "--mode",
        "ao",
        "--samples",
        "8",
        "--spp",
        "100000",
        "--size",
        "64x48",
        "--time",
        "300ms",
        "-o",
        &out,
    ]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(start.elapsed() < Duration::from_secs(20));
    let message = stderr(&run);
    assert!(message.contains("time budget reached after"), "{message}");
    assert!(fs::metadata(&out).unwrap().len() > 0);
}

/// A noise target hours away at the render's rate is said once, early, with what it would take;
/// one that a time budget cuts short first is not (the budget ends the render).
#[test]
fn a_noise_target_out_of_reach_is_said_once() {
    use std::io::{BufRead, BufReader};
    let dir = TempDir::new("noise-forecast");
    let out = dir.arg("o.png");
    let mut child =
        spawn(&["render", "--mode", "ao", "--samples", "4", "--size", "32x24", "--noise", "1e-9", "-o", &out]);
    let lines = BufReader::new(child.stderr.take().unwrap());
    let (send, receive) = std::sync::mpsc::channel();
    let reader = std::thread::spawn(move || {
        for line in lines.lines().map_while(Result::ok) {
            let _ = send.send(line);
        }
    });
    let first = receive.recv_timeout(Duration::from_secs(30));
    signal(&child, "INT");
    let status = child.wait().unwrap();
    reader.join().unwrap();
    let rest: Vec<String> = receive.try_iter().collect();
    let first = first.expect("a line on stderr within 30 s");
    assert!(
        first.starts_with("lumiere: warning: --noise 1e-9: the relative error is ")
            && first.contains("years more; the render goes on until then"),
        "{first}"
    );
    assert!(rest.iter().all(|line| !line.contains("--noise")), "one warning: {rest:?}");
    assert_eq!(status.code(), Some(3), "{rest:?}");

    let run = lumiere(&[
        "render",
        "--mode",
        "ao",
        "--samples",
        "4",
        "--size",
        "32x24",
        "--noise",
        "1e-9",
        "--time",
        "3s",
        "-o",
        &out,
    ]);
    let text = stderr(&run);
    assert!(run.status.success(), "{text}");
    assert!(!text.contains("--noise"), "the time budget ends it first: {text}");
}

/// SIGINT, SIGTERM and SIGHUP (a closed terminal or ssh session): the completed samples are
/// written, the summary says so, exit code 3.
#[test]
fn interruption_writes_the_completed_samples_and_exits_3() {
    let dir = TempDir::new("interrupt");
    for name in ["INT", "TERM", "HUP"] {
        let out = dir.arg(&format!("{name}.png"));
        let stats = dir.arg(&format!("{name}.json"));
        let child = spawn(&[
            "render",
            "--mode",
            "ao",
            "--samples",
            "16",
            "--spp",
            "100000",
            "--size",
            "64x48",
            "--stats-json",
            &stats,
            "-o",
            &out,
        ]);
        std::thread::sleep(Duration::from_millis(700));
        signal(&child, name);
        let run = child.wait_with_output().unwrap();
        assert_eq!(run.status.code(), Some(3), "{name}: {}", stderr(&run));
        assert!(stderr(&run).contains("interrupted after"), "{}", stderr(&run));
        let json: serde_json::Value = serde_json::from_slice(&fs::read(&stats).unwrap()).unwrap();
        assert!(json["spp"].as_u64().unwrap() >= 1, "{json}");
        assert!(fs::metadata(&out).unwrap().len() > 0);
    }
    let leftovers: Vec<_> = fs::read_dir(&dir.0).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(leftovers.len(), 6, "temporary files left: {leftovers:?}");
}

/// SIGKILL at several moments, then resume until done: the same bytes as a render never interrupted.
#[test]
fn killed_and_resumed_renders_give_identical_bytes() {
    let dir = TempDir::new("kill");
    // About 1.5 s of work alone (1.8 s with its checkpoints, on the 2-core machine of 2026-12-02),
    // so that most kill points land mid-render; at 96x72 faster batches had brought it to 0.2 s,
    // and too few kills landed.
    let args =
        ["render", "--mode", "direct", "--samples", "8", "--spp", "96", "--size", "256x192", "--sampler", "sobol"];
    let reference = dir.arg("reference.pfm");
    let start = Instant::now();
    let run = lumiere(&[&args[..], &["-o", &reference]].concat());
    let took = start.elapsed();
    assert!(run.status.success(), "{}", stderr(&run));
    let expected = fs::read(&reference).unwrap();

    // The kill points are fractions of the reference render's time (40, 150, 330 and 520 ms of
    // the 1.5 s it took on the 2-core machine), so that they land at the same points of the
    // render on a faster or slower machine: with fixed times, a machine twice as fast would see
    // fewer kills land, and the count below could fall short.
    let mut total_kills = 0;
    let delays = [40u32, 150, 330, 520].map(|ms| took * ms / 1500);
    for (attempt, delay) in delays.into_iter().enumerate() {
        let out = dir.arg(&format!("resumed{attempt}.pfm"));
        let checkpoint = dir.arg(&format!("run{attempt}.ckpt"));
        let mut kills = 0;
        loop {
            let mut command = vec!["--checkpoint", &checkpoint, "-o", &out];
            if fs::metadata(&checkpoint).is_ok() {
                command.extend(["--resume", &checkpoint]);
            }
            let mut child = spawn(&[&args[..], &command].concat());
            if kills < 3 {
                std::thread::sleep(delay * (kills + 1));
                if child.try_wait().unwrap().is_none() {
                    signal(&child, "KILL");
                    let _ = child.wait();
                    kills += 1;
                    continue;
                }
            }
            let run = child.wait_with_output().unwrap();
            assert!(run.status.success(), "{}", stderr(&run));
            break;
        }
        assert_eq!(fs::read(&out).unwrap(), expected, "attempt {attempt} ({kills} kills) differs");
        total_kills += kills;
    }
    assert!(total_kills >= 6, "only {total_kills} kills landed mid-render");
}

/// Renders AO for its 2 s budget with `outputs` (which write into `dir/folder`), takes that folder
/// away (renamed to `<folder>-gone`: atomic, so it cannot race a file being written there) as soon
/// as `watched` appears in it, as a full disk would refuse the next writes; returns the run and
/// when it started.
fn render_losing_a_folder(dir: &TempDir, folder: &str, watched: &str, outputs: &[&str]) -> (Output, Instant) {
    fs::create_dir(dir.path(folder)).unwrap();
    let args = ["render", "--mode", "ao", "--samples", "4", "--size", "32x24", "--spp", "1000000", "--time", "2s"];
    let start = Instant::now();
    let child =
        Command::new(env!("CARGO_BIN_EXE_lumiere")).args(args).args(outputs).stderr(Stdio::piped()).spawn().unwrap();
    let watched = dir.path(&format!("{folder}/{watched}"));
    while fs::metadata(&watched).is_err() {
        assert!(start.elapsed() < Duration::from_secs(20), "{} was never written", watched.display());
        std::thread::sleep(Duration::from_millis(2));
    }
    fs::rename(dir.path(folder), dir.path(&format!("{folder}-gone"))).unwrap();
    (child.wait_with_output().unwrap(), start)
}

/// A checkpoint that cannot be written mid-render (its folder gone, as a full disk would refuse
/// it) costs a warning, once, not the render: the passes go on, the image is written, and the
/// final checkpoint's failure, after it, makes the exit code.
#[test]
fn a_checkpoint_that_cannot_be_written_does_not_lose_the_image() {
    let dir = TempDir::new("checkpoint-fails");
    let (checkpoint, out) = (dir.arg("ck/c.ckpt"), dir.arg("o.png"));
    let (run, _) = render_losing_a_folder(&dir, "ck", "c.ckpt", &["--checkpoint", &checkpoint, "-o", &out]);
    let text = stderr(&run);
    assert_eq!(run.status.code(), Some(2), "{text}");
    assert_eq!(text.matches("the checkpoint was not updated").count(), 1, "one warning: {text}");
    assert!(text.lines().last().unwrap().starts_with("lumiere: error: "), "{text}");
    assert!(fs::metadata(&out).is_ok_and(|m| m.len() > 0), "the image was written: {text}");
}

/// A preview that cannot be written (its folder gone, as a full disk would refuse it) costs a
/// warning, once, as a checkpoint's does: the render goes on to its budget, and the final image's
/// write reports its own error. It used to end the render at the first failed preview.
#[test]
fn a_preview_that_cannot_be_written_does_not_end_the_render() {
    let dir = TempDir::new("preview-fails");
    let out = dir.arg("out/o.png");
    let (run, start) = render_losing_a_folder(&dir, "out", "o.png", &["--preview-every", "0.01", "-o", &out]);
    let text = stderr(&run);
    assert_eq!(run.status.code(), Some(2), "{text}");
    assert_eq!(text.matches("the preview was not written").count(), 1, "one warning: {text}");
    assert!(text.lines().last().unwrap().starts_with("lumiere: error: "), "{text}");
    // The render ran to its 2 s budget rather than stopping at the first failed preview.
    assert!(start.elapsed() >= Duration::from_millis(1900), "ended after {:?}: {text}", start.elapsed());
    assert!(fs::metadata(dir.path("out-gone/o.png")).is_ok_and(|m| m.len() > 0), "the first preview stays");
}

/// A checkpoint whose film is not the size its options name (a film saved apart from them, as
/// Python's film API can) is refused naming the file, not at the render with a bare message.
#[test]
fn a_checkpoint_whose_film_is_another_size_is_refused_by_name() {
    let dir = TempDir::new("checkpoint-size");
    let (checkpoint, out) = (dir.arg("c.ckpt"), dir.arg("o.png"));
    let base = ["render", "--mode", "hits", "--spp", "2", "--size", "3x2", "-o", &out];
    assert!(lumiere(&[&base[..], &["--checkpoint", &checkpoint]].concat()).status.success());
    let mut saved = lumiere::render::checkpoint::Checkpoint::load(std::path::Path::new(&checkpoint)).unwrap();
    saved.film = Film::new(2, 2).unwrap();
    saved.save(std::path::Path::new(&checkpoint)).unwrap();
    let run = lumiere(&[&base[..], &["--resume", &checkpoint]].concat());
    let text = stderr(&run);
    assert_eq!(run.status.code(), Some(2), "{text}");
    assert!(
        text.contains(&format!("{checkpoint}: cannot resume: the checkpoint's film is 2x2, but the image is 3x2")),
        "{text}"
    );
}

#[test]
fn resuming_with_other_inputs_or_a_broken_file_is_refused() {
    let dir = TempDir::new("refuse");
    let checkpoint = dir.arg("c.ckpt");
    let out = dir.arg("o.png");
    let base = ["render", "--mode", "ao", "--samples", "4", "--spp", "2", "--size", "32x24"];
    let run = lumiere(&[&base[..], &["--checkpoint", &checkpoint, "-o", &out]].concat());
    assert!(run.status.success(), "{}", stderr(&run));

    let mcguire = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/corpus/seeds/CornellBox-Original.obj");
    let cases: [(&[&str], &str); 5] = [
        (&["render", mcguire, "--mode", "ao", "--samples", "4", "--spp", "4", "--size", "32x24"], "different scene"),
        // A refusal names the option that differs, with both values.
        (
            &["render", "--mode", "ao", "--samples", "8", "--spp", "4", "--size", "32x24"],
            "other options: technique (checkpoint: --mode ao --samples 4; now: --mode ao --samples 8",
        ),
        (
            &["render", "--mode", "ao", "--samples", "4", "--spp", "4", "--size", "32x24", "--seed", "9"],
            "other options: seed (checkpoint: 0; now: 9)",
        ),
        // The camera's matrices are too long to quote; the size is named.
        (
            &["render", "--mode", "ao", "--samples", "4", "--spp", "4", "--size", "32x20"],
            "other options: image size (checkpoint: 32x24; now: 32x20), camera (differs from the checkpoint's);",
        ),
        (
            &[
                "render",
                "--mode",
                "ao",
                "--samples",
                "4",
                "--spp",
                "4",
                "--size",
                "32x24",
                "--emission",
                "floor.001=1,1,1",
            ],
            "different scene",
        ),
    ];
    for (args, expected) in cases {
        let run = lumiere(&[args, &["--resume", &checkpoint, "-o", &dir.arg("x.png")]].concat());
        assert_eq!(run.status.code(), Some(2), "{args:?}");
        assert!(stderr(&run).contains(expected), "{args:?}: {}", stderr(&run));
    }
    // A truncated checkpoint is refused with a clear message, never a panic.
    let bytes = fs::read(&checkpoint).unwrap();
    fs::write(&checkpoint, &bytes[..bytes.len() / 2]).unwrap();
    let run = lumiere(&[&base[..], &["--resume", &checkpoint, "-o", &out]].concat());
    assert_eq!(run.status.code(), Some(2));
    assert!(stderr(&run).contains("not a valid lumiere checkpoint"), "{}", stderr(&run));
}

/// A checkpoint that already holds more samples than `--spp` asks for is resumed with a warning
/// that the image keeps them all (samples cannot be taken out of a film), and the image is the
/// checkpoint's.
#[test]
fn resuming_with_fewer_spp_warns_and_keeps_the_checkpoints_samples() {
    let dir = TempDir::new("fewer");
    let checkpoint = dir.arg("c.ckpt");
    let base = ["render", "--mode", "ao", "--samples", "4", "--size", "16x12"];
    let run = lumiere(&[&base[..], &["--spp", "4", "--checkpoint", &checkpoint, "-o", &dir.arg("a.pfm")]].concat());
    assert!(run.status.success(), "{}", stderr(&run));
    let run = lumiere(&[&base[..], &["--spp", "2", "--resume", &checkpoint, "-o", &dir.arg("b.pfm")]].concat());
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(
        stderr(&run)
            .contains("c.ckpt already holds 4 spp, more than --spp 2: nothing is added, and the image keeps all 4"),
        "{}",
        stderr(&run)
    );
    assert!(stderr(&run).contains("all samples done after 4 of 4 spp"), "{}", stderr(&run));
    assert_eq!(fs::read(dir.path("a.pfm")).unwrap(), fs::read(dir.path("b.pfm")).unwrap());
}

#[test]
fn absurd_sizes_are_refused_before_allocating() {
    for size in ["100000x100000", "4294967295x4294967295"] {
        let run = lumiere(&["render", "--size", size, "-o", "/tmp/never-written.png"]);
        assert_eq!(run.status.code(), Some(2), "{size}: {}", stderr(&run));
        assert!(stderr(&run).contains("GiB of memory"), "{size}: {}", stderr(&run));
    }
}

/// Degenerate input (zero-area and back-facing lights, zero-length normals, coordinates near the
/// f32 limit, a camera inside geometry) renders finite images in every mode.
#[test]
fn degenerate_scenes_render_finite_images() {
    let dir = TempDir::new("degenerate");
    let mtl = "newmtl light\nKd 0.5 0.5 0.5\nKe 10 10 10\nnewmtl white\nKd 0.8 0.8 0.8\n";
    fs::write(dir.0.join("d.mtl"), mtl).unwrap();
    let obj = "mtllib d.mtl\n\
        v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n\
        v 0 2 0\nv 0 2 0\nv 1 2 0\n\
        v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0 1 0.5\n\
        v 3e38 0 0\nv -3e38 1 0\nv 0 3e38 3e38\n\
        vn 0 0 0\n\
        usemtl white\nf 1//1 2//1 3//1 4//1\nf 11 12 13\n\
        usemtl light\nf 5 6 7\nf 8 9 10\n";
    let scene = dir.arg("d.obj");
    fs::write(&scene, obj).unwrap();
    let views: [&[&str]; 2] = [&["--eye", "0,3,4", "--target", "0,0,0"], &["--eye", "0,0.5,0", "--target", "0,0.5,-1"]];
    for mode in ["hits", "materials", "shadows", "direct", "ao"] {
        for view in views {
            let out = dir.arg("d.pfm");
            let stats = dir.arg("d.json");
            let args = [
                "render",
                &scene,
                "--mode",
                mode,
                "--samples",
                "4",
                "--size",
                "24x18",
                "-o",
                &out,
                "--stats-json",
                &stats,
            ];
            let run = lumiere(&[&args[..], view].concat());
            assert!(run.status.success(), "{mode} {view:?}: {}", stderr(&run));
            let bytes = fs::read(&out).unwrap();
            let header = bytes.iter().enumerate().filter(|(_, b)| **b == b'\n').nth(2).unwrap().0 + 1;
            let floats = bytes[header..].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap()));
            assert!(floats.into_iter().all(f32::is_finite), "{mode} {view:?}: non-finite pixel");
            let json: serde_json::Value = serde_json::from_slice(&fs::read(&stats).unwrap()).unwrap();
            assert!(json["discarded_samples"].is_u64(), "{json}");
        }
    }
}

#[test]
fn shipped_scenes_discard_no_samples() {
    let (world, camera) = small_world();
    for mode in [Technique::Shadows(Default::default()), Technique::direct(8), Technique::ambient_occlusion(8)] {
        let out = render(&world, &camera, &RenderOptions { spp: 2, ..RenderOptions::new(mode) }, &|_| {}).unwrap();
        assert_eq!(out.film.discarded, 0, "{mode:?}");
    }
}
