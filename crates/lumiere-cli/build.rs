//! Embeds the commit the binary is built from as `LUMIERE_COMMIT` (`lumiere --version`, the
//! statistics' `commit`), so that a benchmark names the binary it ran, not whatever the work tree
//! holds by then: the short hash, `+changes` when tracked files differ from it, or `unknown`
//! outside a git checkout (a source archive) or without git.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    println!("cargo:rustc-env=LUMIERE_COMMIT={}", commit(&root).unwrap_or_else(|| "unknown".into()));
    // Run again when HEAD moves (a commit, a checkout) or a source changes (which may make the tree
    // differ from HEAD, or stop differing); only paths that exist, since a missing one would make
    // every build run it again.
    let mut watched =
        vec![PathBuf::from("build.rs"), root.join("crates/lumiere/src"), root.join("crates/lumiere-cli/src")];
    // HEAD is in a worktree's own folder, the branches in the folder all worktrees share.
    if let (Some(git), Some(common)) = (git_path(&root, "--git-dir"), git_path(&root, "--git-common-dir")) {
        watched.push(git.join("HEAD"));
        watched.push(common.join("packed-refs"));
        if let Ok(head) = std::fs::read_to_string(git.join("HEAD"))
            && let Some(branch) = head.trim().strip_prefix("ref: ")
        {
            watched.push(common.join(branch));
        }
    }
    for path in watched.iter().filter(|p| p.exists()) {
        println!("cargo:rerun-if-changed={}", path.display());
    }
}

/// The short hash of HEAD, with `+changes` when tracked files differ from it.
fn commit(root: &Path) -> Option<String> {
    let git = |args: &[&str]| {
        let out = Command::new("git").arg("-C").arg(root).args(args).output().ok()?;
        out.status.success().then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
    };
    let hash = git(&["rev-parse", "--short=7", "HEAD"])?;
    let changed = !git(&["status", "--porcelain", "--untracked-files=no"])?.is_empty();
    Some(if changed { format!("{hash}+changes") } else { hash })
}

/// A folder `git rev-parse` names (`--git-dir`: `.git`, or a worktree's own; `--git-common-dir`).
fn git_path(root: &Path, which: &str) -> Option<PathBuf> {
    let out = Command::new("git").arg("-C").arg(root).args(["rev-parse", which]).output().ok()?;
    let dir = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    out.status.success().then(|| if dir.is_absolute() { dir } else { root.join(dir) })
}
