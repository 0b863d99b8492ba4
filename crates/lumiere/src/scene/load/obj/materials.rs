//! The material list of an OBJ scene: every MTL material, plus grey stand-ins for names that no
//! MTL defines, created only when a triangle uses them.

use super::chunk::MaterialLibrary;
use super::mtl::parse_mtl;
use crate::error::{quote, shown_path};
use crate::materials::Material;
use crate::scene::load::warnings::Warnings;
use std::collections::{HashMap, HashSet};
use std::io;
use std::path::{Path, PathBuf};

/// Reads an MTL file by the name an OBJ gives it, as text; see [`super::parse_obj`].
pub(super) type ReadMtl<'r> = &'r dyn Fn(&str) -> io::Result<(Vec<u8>, PathBuf)>;

/// Reads an MTL file by its name's bytes (file names are bytes on Unix), returning its bytes and
/// the path they came from.
pub(super) type ReadMtlBytes<'r> = &'r dyn Fn(&[u8]) -> io::Result<(Vec<u8>, PathBuf)>;

/// Where the MTL files of an OBJ come from.
#[derive(Clone, Copy)]
pub(super) struct MtlSource<'r> {
    pub(super) read: ReadMtlBytes<'r>,
    /// The file a name resolves to, known before reading it (on the file system), so that a
    /// library named under many spellings (`a.mtl`, `./a.mtl`, `x/../a.mtl`) is read once. `None`
    /// where only reading tells (in-memory sources); the path the read returns is used then.
    pub(super) locate: &'r dyn Fn(&[u8]) -> Option<PathBuf>,
}

/// Name of the material of faces that come before any `usemtl`.
const DEFAULT_NAME: &str = "default";

#[derive(Debug, Default)]
pub(super) struct MaterialTable {
    pub(super) materials: Vec<Material>,
    pub(super) warnings: Warnings,
    /// Every MTL file read, as resolved.
    pub(super) files: Vec<PathBuf>,
    ids: HashMap<String, u32>,
    default_id: Option<u32>,
}

/// What became of one name `mtllib` gave.
enum Outcome {
    /// Read now, or already read (or already refused) under this name or this path.
    Done,
    Failed(io::Error),
}

/// The libraries tried so far: each name is tried once, and each file is read (or warned about)
/// once, however many `mtllib` lines or spellings name it.
struct Tried<'r> {
    source: MtlSource<'r>,
    names: HashSet<Vec<u8>>,
    paths: HashSet<PathBuf>,
}

impl MaterialTable {
    /// Loads every library named by `mtllib`, each file once, whatever the order of the statements.
    pub(super) fn load<'a>(
        libraries: impl Iterator<Item = &'a MaterialLibrary<'a>>,
        obj: &Path,
        source: MtlSource,
    ) -> Self {
        let mut table = MaterialTable::default();
        let mut tried = Tried { source, names: HashSet::new(), paths: HashSet::new() };
        let mut lines = HashSet::new();
        for library in libraries {
            if lines.insert(library.names) {
                table.load_library(library, obj, &mut tried);
            }
        }
        table
    }

    /// `mtllib` may list several files, or one file whose name has spaces, escaped (`my\ file.mtl`)
    /// or not: the whole line is tried as one name first, then each word.
    fn load_library(&mut self, library: &MaterialLibrary, obj: &Path, tried: &mut Tried) {
        let whole = unescape(library.names);
        let Outcome::Failed(error) = self.try_library(&whole, tried) else { return };
        let words = split_names(library.names);
        if words.len() < 2 {
            return self.warn_unreadable(obj, library.line, &whole, &error);
        }
        for word in &words {
            if let Outcome::Failed(error) = self.try_library(word, tried) {
                self.warn_unreadable(obj, library.line, word, &error);
            }
        }
    }

    fn try_library(&mut self, name: &[u8], tried: &mut Tried) -> Outcome {
        if !tried.names.insert(name.to_vec()) {
            return Outcome::Done;
        }
        let located = (tried.source.locate)(name);
        if let Some(path) = &located
            && !tried.paths.insert(path.clone())
        {
            return Outcome::Done;
        }
        match (tried.source.read)(name) {
            Ok((bytes, path)) => {
                if located.is_some() || tried.paths.insert(path.clone()) {
                    self.add_file(&bytes, &path);
                }
                Outcome::Done
            }
            Err(error) => Outcome::Failed(error),
        }
    }

    fn warn_unreadable(&mut self, obj: &Path, line: usize, name: &[u8], error: &io::Error) {
        self.warnings.push(obj, "unreadable material libraries", || {
            format!(
                "{}:{line}: cannot read material library {} ({error}); its materials will be grey",
                shown_path(obj),
                quote(name)
            )
        });
    }

    /// Adds the materials of one MTL file. A name defined twice keeps its first definition.
    fn add_file(&mut self, bytes: &[u8], path: &Path) {
        self.files.push(path.to_path_buf());
        for material in parse_mtl(bytes, path, &mut self.warnings) {
            if self.ids.contains_key(&material.name) {
                self.warnings.push(path, "materials defined again", || {
                    format!(
                        "{}: material {} is defined again; keeping the first definition",
                        shown_path(path),
                        quote(&material.name)
                    )
                });
                continue;
            }
            let name = material.name.clone();
            let id = self.push(material);
            self.ids.insert(name, id);
        }
    }

    /// The id of material `name` (set by `usemtl` at `line`), or of the default material when no
    /// `usemtl` came yet. An unknown name gets a grey material of that name and one warning.
    pub(super) fn id(&mut self, used: Option<(&str, usize)>, obj: &Path) -> u32 {
        let Some((name, line)) = used else {
            if let Some(id) = self.default_id {
                return id;
            }
            let id = self.push(Material::default_grey(DEFAULT_NAME));
            self.default_id = Some(id);
            return id;
        };
        if let Some(&id) = self.ids.get(name) {
            return id;
        }
        self.warnings.push(obj, "undefined materials", || {
            format!("{}:{line}: material {} is not defined in any MTL file; using grey", shown_path(obj), quote(name))
        });
        let id = self.push(Material::default_grey(name));
        self.ids.insert(name.to_string(), id);
        id
    }

    fn push(&mut self, material: Material) -> u32 {
        self.materials.push(material);
        u32::try_from(self.materials.len() - 1).unwrap_or(u32::MAX)
    }
}

/// The line as one file name: escaped whitespace (`\ `) unescaped, and every other backslash read
/// as `/`, as in texture statements (Windows exporters write `sub\scene.mtl`).
fn unescape(line: &[u8]) -> Vec<u8> {
    let mut names = names(line, false);
    names.pop().unwrap_or_default()
}

/// The file names of an `mtllib` line: split at whitespace, except where a backslash escapes it
/// (`my\ file.mtl` is `my file.mtl`, as Blender and 3ds Max write names with spaces); every other
/// backslash is read as `/`.
fn split_names(line: &[u8]) -> Vec<Vec<u8>> {
    names(line, true)
}

/// The names of `line`, one for the whole line or one per word (`split`), unescaped.
fn names(line: &[u8], split: bool) -> Vec<Vec<u8>> {
    let mut names = Vec::new();
    let mut name = Vec::new();
    let mut bytes = line.iter().copied().peekable();
    while let Some(b) = bytes.next() {
        match b {
            b'\\' if bytes.peek().is_some_and(u8::is_ascii_whitespace) => name.extend(bytes.next()),
            b'\\' => name.push(b'/'),
            b if split && b.is_ascii_whitespace() => {
                if !name.is_empty() {
                    names.push(std::mem::take(&mut name));
                }
            }
            b => name.push(b),
        }
    }
    if !name.is_empty() {
        names.push(name);
    }
    names
}
