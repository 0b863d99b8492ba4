//! The material list of an OBJ scene: every MTL material, plus grey stand-ins for names that no
//! MTL defines, created only when a triangle uses them.

use super::chunk::MaterialLibrary;
use super::mtl::parse_mtl;
use crate::materials::Material;
use std::collections::{HashMap, HashSet};
use std::io;
use std::path::{Path, PathBuf};

/// Reads an MTL file by the name an OBJ gives it; see [`super::parse_obj`].
pub(super) type ReadMtl<'r> = &'r dyn Fn(&str) -> io::Result<(Vec<u8>, PathBuf)>;

/// Name of the material of faces that come before any `usemtl`.
const DEFAULT_NAME: &str = "default";

#[derive(Debug, Default)]
pub(super) struct MaterialTable {
    pub(super) materials: Vec<Material>,
    pub(super) warnings: Vec<String>,
    ids: HashMap<String, u32>,
    default_id: Option<u32>,
}

impl MaterialTable {
    /// Loads every library named by `mtllib`, each once, whatever the order of the statements.
    pub(super) fn load<'a>(
        libraries: impl Iterator<Item = &'a MaterialLibrary<'a>>,
        obj: &Path,
        read_mtl: ReadMtl,
    ) -> Self {
        let mut table = MaterialTable::default();
        let mut seen = HashSet::new();
        for library in libraries {
            if seen.insert(library.names.as_ref()) {
                table.load_library(library, obj, read_mtl);
            }
        }
        table
    }

    /// `mtllib` may list several files, or one file whose name has spaces: the whole line is tried
    /// as one name first, then each word.
    fn load_library(&mut self, library: &MaterialLibrary, obj: &Path, read_mtl: ReadMtl) {
        let whole = library.names.as_ref();
        let error = match read_mtl(whole) {
            Ok((bytes, path)) => return self.add_file(&bytes, &path),
            Err(error) => error,
        };
        let words: Vec<&str> = whole.split_ascii_whitespace().collect();
        if words.len() < 2 {
            return self.warn_unreadable(obj, library.line, whole, &error);
        }
        for word in words {
            match read_mtl(word) {
                Ok((bytes, path)) => self.add_file(&bytes, &path),
                Err(error) => self.warn_unreadable(obj, library.line, word, &error),
            }
        }
    }

    fn warn_unreadable(&mut self, obj: &Path, line: usize, name: &str, error: &io::Error) {
        self.warnings.push(format!(
            "{}:{line}: cannot read material library {name:?} ({error}); its materials will be grey",
            obj.display()
        ));
    }

    /// Adds the materials of one MTL file. A name defined twice keeps its first definition.
    fn add_file(&mut self, bytes: &[u8], path: &Path) {
        let file = parse_mtl(bytes, path);
        self.warnings.extend(file.warnings);
        for material in file.materials {
            if self.ids.contains_key(&material.name) {
                self.warnings.push(format!(
                    "{}: material {:?} is defined again; keeping the first definition",
                    path.display(),
                    material.name
                ));
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
        self.warnings
            .push(format!("{}:{line}: material {name:?} is not defined in any MTL file; using grey", obj.display()));
        let id = self.push(Material::default_grey(name));
        self.ids.insert(name.to_string(), id);
        id
    }

    fn push(&mut self, material: Material) -> u32 {
        self.materials.push(material);
        u32::try_from(self.materials.len() - 1).unwrap_or(u32::MAX)
    }
}
