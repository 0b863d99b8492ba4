//! `lumiere render --denoise`: a clear error before rendering when Intel Open Image Denoise is not
//! there, and a denoised image closer to a converged one than the noisy render when it is.
//!
//! OIDN is found as the binary finds it (`OIDN_DIR`, or `python3`'s pyoidn); without it the second
//! test says it is skipped, unless `LUMIERE_REQUIRE_EXTRAS=1` makes that a failure.

use std::fs;
use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::common::TempDir;

fn lumiere() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lumiere"))
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Reads a PFM written by lumiere as its floats (the row order does not matter here).
fn read_pfm(path: &Path) -> Vec<f32> {
    let bytes = fs::read(path).unwrap();
    let mut header_end = 0;
    let mut newlines = 0;
    while newlines < 3 {
        newlines += usize::from(bytes[header_end] == b'\n');
        header_end += 1;
    }
    bytes[header_end..].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect()
}

fn rmse(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = a.iter().zip(b).map(|(x, y)| f64::from(x - y).powi(2)).sum();
    (sum / a.len() as f64).sqrt()
}

/// `lumiere render --denoise <extra> -o <image>` looking for OIDN in `oidn_dir` only.
fn denoise_looking_in(oidn_dir: &Path, image: &Path, extra: &[&str]) -> Command {
    let mut command = lumiere();
    command.args(["render", "--denoise"]).args(extra).arg("-o").arg(image);
    command.env("OIDN_DIR", oidn_dir).env("LUMIERE_NO_PYOIDN", "1");
    command
}

#[test]
fn denoise_without_oidn_fails_before_rendering() {
    let dir = TempDir::new("denoise-missing");
    fs::create_dir(dir.path("empty")).unwrap();
    let image = dir.path("out.png");
    let start = Instant::now();
    // A render that would take minutes: the error must come before it.
    let out =
        denoise_looking_in(&dir.path("empty"), &image, &["--spp", "100000", "--size", "512x384"]).output().unwrap();
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert_eq!(text.lines().count(), 1, "one line: {text}");
    assert!(text.contains("Open Image Denoise") && text.contains("pip install pyoidn"), "{text}");
    assert!(text.contains("OIDN_DIR"), "{text}");
    assert!(!text.contains("panicked"), "{text}");
    assert!(!image.exists(), "no output file");
    assert!(start.elapsed() < Duration::from_secs(20), "took {:?}", start.elapsed());
}

/// A `pyoidn.py` in the folder the user renders from (a downloaded scene's, say) is never
/// imported by the library lookup, and a `python3` that never answers does not stall the render.
#[cfg(unix)]
#[test]
fn the_pyoidn_lookup_runs_nothing_from_the_working_folder_and_gives_up() {
    use std::os::unix::fs::PermissionsExt;
    let dir = TempDir::new("denoise-lookup");
    let marker = dir.path("ran");
    fs::write(dir.path("pyoidn.py"), format!("open({:?}, 'w').write('ran')\n", marker.to_str().unwrap())).unwrap();
    let lookup = |path: &std::ffi::OsStr| {
        lumiere()
            .args(["render", "--denoise", "--size", "8x6", "-o", "out.png"])
            .current_dir(dir.path(""))
            .env("OIDN_DIR", dir.path("no-such-folder"))
            .env_remove("LUMIERE_NO_PYOIDN")
            .env("PATH", path)
            .output()
            .unwrap()
    };
    // The system's python3 (where there is one): the scene folder's module must not run.
    let out = lookup(&std::env::var_os("PATH").unwrap_or_default());
    assert!(!marker.exists(), "the working folder's pyoidn.py ran: {}", stderr(&out));

    // A python3 that hangs: the lookup gives up, the render goes on (here to the missing library).
    let bin = dir.path("bin");
    fs::create_dir(&bin).unwrap();
    let python = bin.join("python3");
    fs::write(&python, "#!/bin/sh\nexec /bin/sleep 60\n").unwrap();
    fs::set_permissions(&python, fs::Permissions::from_mode(0o755)).unwrap();
    let start = Instant::now();
    let out = lookup(bin.as_os_str());
    let text = stderr(&out);
    assert!(start.elapsed() < Duration::from_secs(30), "took {:?}: {text}", start.elapsed());
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(text.contains("was not found"), "{text}");
}

/// A library that is a FIFO is refused at once: opening it waited for a writer forever, inside the
/// dynamic loader, where not even a signal could end the process.
#[cfg(unix)]
#[test]
fn a_library_that_is_a_fifo_is_refused_not_waited_on() {
    let dir = TempDir::new("denoise-fifo");
    let fifo = dir.path("libOpenImageDenoise.so.2");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let mut child = denoise_looking_in(&dir.path(""), &dir.path("out.png"), &["--size", "8x6"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            panic!("still waiting on the FIFO after {:?}", start.elapsed());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert!(text.contains("libOpenImageDenoise.so.2: is a FIFO, not a regular file"), "{text}");
}

/// A file that is not a library is named with the loader's reason, not only "dlopen failed".
#[cfg(target_os = "linux")]
#[test]
fn a_library_that_cannot_be_loaded_is_named_with_the_reason() {
    let dir = TempDir::new("denoise-not-a-library");
    fs::write(dir.path("libOpenImageDenoise.so.2"), "not a library\n").unwrap();
    let out = denoise_looking_in(&dir.path(""), &dir.path("out.png"), &["--size", "8x6"]).output().unwrap();
    let text = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{text}");
    assert_eq!(text.lines().count(), 1, "one line: {text}");
    assert!(text.contains("dlopen failed (") && text.contains("libOpenImageDenoise.so.2: "), "{text}");
}

#[test]
fn denoising_four_samples_comes_closer_to_the_converged_image() {
    let dir = TempDir::new("denoise-rmse");
    let render = |extra: &[&str], name: &str| -> Output {
        lumiere()
            .args(["render", "--size", "128x96", "-o"])
            .arg(dir.path(name))
            .args(extra)
            .output()
            .expect("the binary runs")
    };
    let denoised = render(&["--spp", "4", "--denoise"], "denoised.pfm");
    if denoised.status.code() == Some(2) && stderr(&denoised).contains("was not found") {
        let why = stderr(&denoised);
        assert!(
            std::env::var("LUMIERE_REQUIRE_EXTRAS").as_deref() != Ok("1"),
            "LUMIERE_REQUIRE_EXTRAS=1 but OIDN is missing: {why}"
        );
        eprintln!("skipped: OIDN is not available (pip install pyoidn or set OIDN_DIR): {why}");
        return;
    }
    assert!(denoised.status.success(), "{}", stderr(&denoised));
    assert!(stderr(&denoised).contains("denoised in"), "{}", stderr(&denoised));
    let raw = render(&["--spp", "4"], "raw.pfm");
    assert!(raw.status.success(), "{}", stderr(&raw));
    // A reference of another seed, so that its noise does not share the first four samples.
    let reference = render(&["--spp", "64", "--seed", "1"], "reference.pfm");
    assert!(reference.status.success(), "{}", stderr(&reference));

    let reference = read_pfm(&dir.path("reference.pfm"));
    let raw_error = rmse(&read_pfm(&dir.path("raw.pfm")), &reference);
    let denoised_error = rmse(&read_pfm(&dir.path("denoised.pfm")), &reference);
    eprintln!("RMSE against 64 spp: raw 4 spp {raw_error:.5}, denoised {denoised_error:.5}");
    assert!(denoised_error < 0.75 * raw_error, "raw {raw_error}, denoised {denoised_error}");

    // An EXR keeps the noisy image as a layer beside the denoised one and the asked-for AOVs.
    let exr = render(&["--spp", "4", "--denoise", "--aov", "depth"], "denoised.exr");
    assert!(exr.status.success(), "{}", stderr(&exr));
    let bytes = fs::read(dir.path("denoised.exr")).unwrap();
    let has = |name: &[u8]| bytes.windows(name.len()).any(|w| w == name);
    assert!(has(b"noisy.R\0") && has(b"depth.Z\0"), "the EXR's channels");
}
