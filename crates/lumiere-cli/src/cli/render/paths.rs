//! The files a render reads and writes, checked before any work: no output may be an input or
//! another output (the library's `util::overwrite`, which the Python module shares), and an
//! existing output must be a regular file. Temporary files that killed runs left beside the
//! outputs are removed.

use lumiere::error::shown_path;
use std::path::{Path, PathBuf};

use lumiere::image_io::check_output_path;
use lumiere::render::checkpoint::Checkpoint;
use lumiere::scene::Scene;
use lumiere::util::overwrite::{Named, check_outputs, check_scene_files};
use lumiere::util::write::{check_writable, remove_stale_temporaries};
use lumiere::{Error, Result};

use crate::cli::args::{RenderArgs, STDOUT_ARG};

/// Refuses outputs that would clobber an input or each other, or that cannot be written; cleans
/// stale temporaries beside them.
pub fn check(args: &RenderArgs) -> Result<()> {
    // An EXR cannot hold one channel name twice: refused now, not after the render.
    if let Some(twice) = super::first_repeat(&args.aov) {
        return Err(Error::invalid(format!("--aov {} is given twice", twice.name())));
    }
    let mut outputs = vec![Named { name: "-o", path: &args.output }];
    if let Some(path) = args.stats_json.as_deref().filter(|p| p.as_os_str() != STDOUT_ARG) {
        outputs.push(Named { name: "--stats-json", path });
    }
    if let Some(path) = &args.checkpoint {
        outputs.push(Named { name: "--checkpoint", path });
    }
    let mut inputs = Vec::new();
    if let Some(path) = &args.scene {
        inputs.push(Named { name: "the scene", path });
    }
    if let Some(path) = &args.orbiter {
        inputs.push(Named { name: "--orbiter", path });
    }
    if let Some(path) = &args.resume {
        inputs.push(Named { name: "--resume", path });
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
    // Continuing a checkpoint in place is the documented way to resume.
    check_outputs(&outputs, &inputs, Some(("--checkpoint", "--resume")))?;
    if let Some(path) = &args.checkpoint {
        Checkpoint::check_replaceable(path)?;
    }
    for output in &outputs {
        remove_stale_temporaries(output.path.parent().unwrap_or(Path::new("")));
    }
    Ok(())
}

/// Refuses an output that is one of the files the loaded scene was read from: its material
/// libraries and textures.
pub fn check_against_sources(args: &RenderArgs, scene: &Scene) -> Result<()> {
    let outputs = [Some(&args.output), args.stats_json.as_ref(), args.checkpoint.as_ref()];
    check_scene_files(outputs.into_iter().flatten().map(PathBuf::as_path), scene.files_read())
}
