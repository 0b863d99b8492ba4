//! The files a render reads and writes, checked before any work: no output may be an input or
//! another output (same file, by device and inode, or by path when it does not exist yet), and an
//! existing output must be a regular file. Temporary files that killed runs left beside the
//! outputs are removed.

use lumiere::error::shown_path;
use std::path::{Path, PathBuf};

use lumiere::image_io::check_output_path;
use lumiere::scene::Scene;
use lumiere::util::write::{check_writable, remove_stale_temporaries};
use lumiere::{Error, Result};

use crate::cli::args::RenderArgs;

/// `--stats-json -` writes the statistics to stdout.
pub const STDOUT_ARG: &str = "-";

/// One file a render touches, with the flag that named it (for messages).
struct Named<'a> {
    flag: &'static str,
    path: &'a Path,
}

/// Refuses outputs that would clobber an input or each other, or that cannot be written; cleans
/// stale temporaries beside them.
pub fn check(args: &RenderArgs) -> Result<()> {
    // An EXR cannot hold one channel name twice: refused now, not after the render.
    if let Some(twice) = super::first_repeat(&args.aov) {
        return Err(Error::invalid(format!("--aov {} is given twice", twice.name())));
    }
    let mut outputs = vec![Named { flag: "-o", path: &args.output }];
    if let Some(path) = args.stats_json.as_deref().filter(|p| p.as_os_str() != STDOUT_ARG) {
        outputs.push(Named { flag: "--stats-json", path });
    }
    if let Some(path) = &args.checkpoint {
        outputs.push(Named { flag: "--checkpoint", path });
    }
    let mut inputs = Vec::new();
    if let Some(path) = &args.scene {
        inputs.push(Named { flag: "the scene", path });
    }
    if let Some(path) = &args.orbiter {
        inputs.push(Named { flag: "--orbiter", path });
    }
    if let Some(path) = &args.resume {
        inputs.push(Named { flag: "--resume", path });
    }
    check_output_path(&args.output)?;
    let exr = args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !args.aov.is_empty() && !exr {
        return Err(Error::invalid(format!(
            "{}: --aov writes extra channels, which only an .exr output can hold",
            shown_path(&args.output)
        )));
    }
    for output in &outputs[1..] {
        check_writable(output.path)?;
    }
    for (i, a) in outputs.iter().enumerate() {
        for b in &outputs[i + 1..] {
            if same_file(a.path, b.path) {
                return Err(clash(a, b, "both outputs"));
            }
        }
        for input in &inputs {
            // Continuing a checkpoint in place is the documented way to resume.
            let resume_in_place = a.flag == "--checkpoint" && input.flag == "--resume";
            if !resume_in_place && same_file(a.path, input.path) {
                return Err(clash(a, input, "an output would overwrite an input"));
            }
        }
    }
    for output in &outputs {
        remove_stale_temporaries(output.path.parent().unwrap_or(Path::new("")));
    }
    Ok(())
}

/// Refuses an output that is one of the files the loaded scene was read from: its material
/// libraries and textures.
pub fn check_against_sources(args: &RenderArgs, scene: &Scene) -> Result<()> {
    let textures = scene.materials.iter().flat_map(|m| [m.map_kd.as_deref(), m.map_d.as_deref()]).flatten();
    let sources: Vec<&Path> = scene.sources.iter().map(PathBuf::as_path).chain(textures).collect();
    let outputs = [Some(&args.output), args.stats_json.as_ref(), args.checkpoint.as_ref()];
    for output in outputs.into_iter().flatten() {
        if let Some(source) = sources.iter().find(|source| same_file(output, source)) {
            return Err(Error::invalid(format!(
                "{}: the output would overwrite {}, which the scene reads",
                shown_path(output),
                shown_path(source)
            )));
        }
    }
    Ok(())
}

fn clash(a: &Named, b: &Named, why: &str) -> Error {
    Error::invalid(format!(
        "{} ({}) and {} ({}) are the same file: {why}",
        shown_path(a.path),
        a.flag,
        shown_path(b.path),
        b.flag
    ))
}

/// Whether two paths name one file: the same device and inode when both exist, else the same
/// absolute path (with its folder resolved).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => same_inode(&x, &y),
        (Err(_), Err(_)) => resolved(a).is_some_and(|ra| resolved(b).is_some_and(|rb| ra == rb)),
        _ => false,
    }
}

#[cfg(unix)]
fn same_inode(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    (a.dev(), a.ino()) == (b.dev(), b.ino())
}

#[cfg(not(unix))]
fn same_inode(_: &std::fs::Metadata, _: &std::fs::Metadata) -> bool {
    false
}

/// The absolute path of a file that may not exist yet: its folder resolved, then its name.
fn resolved(path: &Path) -> Option<PathBuf> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    Some(std::fs::canonicalize(folder).ok()?.join(path.file_name()?))
}
