//! Scene files in: the loader is chosen by the file's extension, and every loader hands its
//! triangles, materials and warnings to [`Scene::from_parts`]. Loaders know nothing of rendering.

pub mod gltf;
pub mod memory;
pub mod obj;
pub mod ply;
mod polygon;
pub mod warnings;

use std::path::{Path, PathBuf};

use crate::error::{Error, Result, shown_path};
use crate::scene::Scene;
use crate::util::read::refuse_special;

/// The scene formats lumiere reads, named as in messages.
const SUPPORTED: &str =
    ".obj (with its .mtl files), .gltf (with its buffers and images), .glb or .ply, each also gzipped (.obj.gz, ...)";

/// Loads the scene file at `path`, choosing the loader by its extension (case-insensitive).
pub fn load(path: &Path) -> Result<Scene> {
    // What the file is comes first: a folder's or a device's name says nothing of it (`scenes/`
    // and `/dev/zero` have no extension). A path that cannot be read is left to the loader's error.
    if let Ok(metadata) = std::fs::metadata(path) {
        refuse_special(&metadata).map_err(|e| Error::io(path, e))?;
    }
    let name = path.file_name().map(|n| n.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    let stem = name.strip_suffix(".gz").unwrap_or(&name);
    let extension = Path::new(stem).extension().map(|e| e.to_string_lossy().into_owned()).unwrap_or_default();
    match extension.as_str() {
        "obj" => obj::load_obj(path)?.into_scene(shown_path(path)),
        "ply" => ply::load_ply(path),
        "gltf" | "glb" => gltf::load_gltf(path),
        "mtl" => Err(Error::invalid(format!(
            "{}: is a material library (.mtl), not a scene; give the .obj file that names it with mtllib",
            shown_path(path)
        ))),
        "" if stem.len() < name.len() => Err(Error::invalid(format!(
            "{}: a gzip file whose name does not say what it holds; name a compressed scene .obj.gz, .gltf.gz, .glb.gz or .ply.gz",
            shown_path(path)
        ))),
        "" => Err(Error::invalid(format!(
            "{}: the file name has no extension, so its format is unknown; lumiere reads {SUPPORTED}",
            shown_path(path)
        ))),
        other => Err(Error::invalid(format!(
            "{}: .{} scenes are not supported; lumiere reads {SUPPORTED}",
            shown_path(path),
            crate::error::quote(other).trim_matches('"')
        ))),
    }
}

/// A file name from a scene file's bytes (an `mtllib` or texture statement, a glTF URI): as they
/// are on Unix, where names are bytes; elsewhere as text, bytes that are not UTF-8 read as Latin-1
/// (as OBJ text is).
pub(crate) fn path_from_bytes(bytes: Vec<u8>) -> PathBuf {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStringExt;
        PathBuf::from(std::ffi::OsString::from_vec(bytes))
    }
    #[cfg(not(unix))]
    {
        let text = String::from_utf8(bytes).unwrap_or_else(|e| e.into_bytes().iter().map(|&b| char::from(b)).collect());
        PathBuf::from(text)
    }
}
