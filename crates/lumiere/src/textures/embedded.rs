//! Images a scene file carries inside itself (a glTF file's PNG and JPEG images in its buffers or
//! in `data:` URIs), each under the name its materials use in place of a file's path, so that the
//! rest of the renderer (decoding once, fingerprints, `info`) treats them as it treats files.

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Keyed by name: a file may embed tens of thousands of images, and a list searched for each
/// would cost their square.
#[derive(Clone, Default)]
pub struct EmbeddedImages {
    images: BTreeMap<PathBuf, Arc<[u8]>>,
}

impl EmbeddedImages {
    /// The name an image embedded in `file` as its image number `index` goes by:
    /// `scene.glb#image3`.
    pub fn name(file: &Path, index: usize) -> PathBuf {
        let mut name = file.as_os_str().to_owned();
        name.push(format!("#image{index}"));
        PathBuf::from(name)
    }

    /// Adds `bytes` under `name`, unless an image goes by that name already.
    pub fn add(&mut self, name: PathBuf, bytes: Arc<[u8]>) {
        self.images.entry(name).or_insert(bytes);
    }

    /// The bytes of the image named `name`, if it is embedded.
    pub fn get(&self, name: &Path) -> Option<&[u8]> {
        self.images.get(name).map(|bytes| &**bytes)
    }

    pub fn contains(&self, name: &Path) -> bool {
        self.images.contains_key(name)
    }

    pub fn is_empty(&self) -> bool {
        self.images.is_empty()
    }
}

/// Names and sizes, not megabytes of bytes.
impl fmt::Debug for EmbeddedImages {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map().entries(self.images.iter().map(|(name, bytes)| (name, bytes.len()))).finish()
    }
}
