//! Running the `lumiere` binary on hostile arguments from the stable tests (`tests/fuzz_*.rs`
//! include this file with `#[path]`): a deadline instead of a hang, an optional address-space
//! limit instead of an out-of-memory kill, and the CLI's exit contract as a check.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// A fresh folder under the system temp dir, removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("lumiere-fuzz-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).expect("create temp dir");
        TempDir(dir)
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    pub fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.path(name);
        fs::write(&path, bytes).expect("write temp file");
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

/// How a run of the binary ended.
#[derive(Debug)]
pub struct Run {
    /// `None` when it was killed at the deadline.
    pub status: Option<ExitStatus>,
    pub stderr: String,
    pub elapsed: Duration,
}

impl Run {
    /// What happened, for assertion messages.
    pub fn describe(&self, args: &[&OsStr]) -> String {
        let status = match self.status {
            None => "killed at the deadline (hang?)".to_string(),
            Some(status) => status.to_string(),
        };
        format!("lumiere {args:?}: {status} after {:.2?}; stderr:\n{}", self.elapsed, self.stderr)
    }
}

/// Limits for [`run`].
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// The child is killed after this long.
    pub deadline: Duration,
    /// Address-space limit (`ulimit -v`) in MiB, so a runaway allocation fails fast instead of
    /// taking the machine down. Unix only; rayon is held to 2 threads and malloc to 2 arenas so
    /// that the limit measures the data, not per-thread reservations.
    pub memory_mib: Option<u64>,
}

impl Default for Limits {
    fn default() -> Self {
        Limits { deadline: Duration::from_secs(60), memory_mib: Some(2048) }
    }
}

/// Runs `binary args` with `limits`, in `dir` (stdout and stderr go to files there).
pub fn run<S: AsRef<OsStr>>(binary: &Path, args: &[S], dir: &Path, limits: Limits) -> Run {
    static COUNTER: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let id = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let stderr_path = dir.join(format!("stderr-{id}.txt"));
    let mut command = match limits.memory_mib {
        Some(mib) if cfg!(unix) => {
            let mut command = Command::new("/bin/sh");
            command
                .arg("-c")
                .arg(format!("ulimit -v {} && exec \"$0\" \"$@\"", mib * 1024))
                .arg(binary)
                .env("RAYON_NUM_THREADS", "2")
                .env("MALLOC_ARENA_MAX", "2");
            command
        }
        _ => Command::new(binary),
    };
    command.args(args).current_dir(dir).stdin(Stdio::null()).stdout(Stdio::null());
    command.stderr(fs::File::create(&stderr_path).expect("create stderr file"));
    let start = Instant::now();
    let mut child = command.spawn().expect("the binary starts");
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for the binary") {
            break Some(status);
        }
        if start.elapsed() > limits.deadline {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let elapsed = start.elapsed();
    let stderr = String::from_utf8_lossy(&fs::read(&stderr_path).unwrap_or_default()).into_owned();
    let _ = fs::remove_file(&stderr_path);
    Run { status, stderr, elapsed }
}

/// The CLI's contract on hostile input: exit 0, or exit 2 with a clear message. An error found by
/// lumiere is one `lumiere: error: ...` line, the last one, after `lumiere: warning:` lines and the
/// success line at most; a usage error found by clap (`allow_usage_error`) starts with `error:`.
/// Never a panic (exit 101), a signal, or a hang.
pub fn check_exit(run: &Run, allow_usage_error: bool) -> Result<(), String> {
    let Some(status) = run.status else { return Err("killed at the deadline (hang?)".to_string()) };
    if run.stderr.contains("panicked") {
        return Err("panicked".to_string());
    }
    match status.code() {
        Some(0) => Ok(()),
        Some(2) if allow_usage_error && run.stderr.starts_with("error:") => Ok(()),
        Some(2) => {
            let lines: Vec<&str> = run.stderr.lines().collect();
            let errors = lines.iter().filter(|line| line.starts_with("lumiere: error:")).count();
            let last_is_error = lines.last().is_some_and(|line| line.starts_with("lumiere: error:"));
            let others_are_warnings =
                lines[..lines.len().saturating_sub(1)].iter().all(|line| line.starts_with("lumiere: warning:"));
            if errors == 1 && last_is_error && others_are_warnings {
                Ok(())
            } else {
                Err("exit 2 without exactly one final `lumiere: error:` line".to_string())
            }
        }
        Some(code) => Err(format!("exit code {code}, expected 0 or 2")),
        None => Err(format!("killed by a signal: {status}")),
    }
}

/// The `lumiere: error:` line of a failed run, if any.
pub fn error_line(run: &Run) -> Option<&str> {
    run.stderr.lines().find(|line| line.starts_with("lumiere: error:"))
}
