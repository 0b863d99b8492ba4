//! No output may overwrite an input or another output. Every front end (the CLI, the Python
//! module, `lumiere.distributed`) checks its files here before any work, so that a render can never
//! replace the scene it reads (its OBJ, material libraries, textures, orbiter file) or one of its
//! own outputs, and the same mistake gets the same message whatever the front end. Files are
//! compared by device and inode, or by resolved path when one does not exist yet.

use std::path::{Path, PathBuf};

use crate::error::{Error, Result, shown_path};

/// A file a run reads or writes, with the name the user gave it by (a flag such as `-o`, a
/// Python argument), for messages.
#[derive(Clone, Copy, Debug)]
pub struct Named<'a> {
    pub name: &'a str,
    pub path: &'a Path,
}

/// Refuses two outputs that are one file, and an output that is one of the `inputs`, except the
/// pair named by `in_place` (output, input): a checkpoint continued where it is.
pub fn check_outputs(outputs: &[Named], inputs: &[Named], in_place: Option<(&str, &str)>) -> Result<()> {
    for (i, a) in outputs.iter().enumerate() {
        for b in &outputs[i + 1..] {
            if same_file(a.path, b.path) {
                return Err(clash(a, b, "both outputs"));
            }
        }
        for input in inputs {
            let allowed = in_place == Some((a.name, input.name));
            if !allowed && same_file(a.path, input.path) {
                return Err(clash(a, input, "an output would overwrite an input"));
            }
        }
    }
    Ok(())
}

/// Refuses an output that is one of the files a loaded scene read besides the scene file itself
/// (`Scene::files_read`: its material libraries and the textures its materials name).
pub fn check_scene_files<'a>(
    outputs: impl IntoIterator<Item = &'a Path>,
    read: impl IntoIterator<Item = &'a Path>,
) -> Result<()> {
    let read: Vec<&Path> = read.into_iter().collect();
    for output in outputs {
        if let Some(source) = read.iter().find(|source| same_file(output, source)) {
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
        a.name,
        shown_path(b.path),
        b.name
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_clash_with_each_other_and_inputs_but_not_in_place() {
        let dir = std::env::temp_dir().join(format!("lumiere-overwrite-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let scene = dir.join("a.obj");
        std::fs::write(&scene, b"").unwrap();
        let image = Named { name: "-o", path: &scene };
        let input = Named { name: "the scene", path: &scene };
        let error = check_outputs(&[image], &[input], None).unwrap_err().to_string();
        assert!(error.contains("(-o) and ") && error.ends_with("an output would overwrite an input"), "{error}");
        assert!(check_outputs(&[image], &[input], Some(("-o", "the scene"))).is_ok());
        // A file that does not exist yet, named two ways.
        let later = dir.join("b.exr");
        let other = dir.join(".").join("b.exr");
        let outputs = [Named { name: "-o", path: &later }, Named { name: "--checkpoint", path: &other }];
        let error = check_outputs(&outputs, &[], None).unwrap_err().to_string();
        assert!(error.ends_with("are the same file: both outputs"), "{error}");
        let error = check_scene_files([scene.as_path()], [scene.as_path()]).unwrap_err().to_string();
        assert!(error.ends_with("which the scene reads"), "{error}");
        assert!(check_scene_files([later.as_path()], [scene.as_path()]).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
