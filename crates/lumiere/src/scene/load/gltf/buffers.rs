//! A glTF file's buffers, each as bytes: the GLB binary chunk, a `data:` URI or a file beside the
//! glTF file, checked to hold at least the bytes the file declares for it.

use super::container::Container;
use super::uri::{self, Uri};
use crate::error::{Error, Result, quote, shown_path};
use std::borrow::Cow;
use std::io;
use std::path::{Path, PathBuf};

/// Reads a file a glTF file names (a buffer), at its resolved path.
pub type ReadFile<'r> = &'r dyn Fn(&Path) -> io::Result<Vec<u8>>;

/// Every buffer's bytes, in the file's order, and the files read for them.
pub(super) struct Buffers<'b> {
    pub(super) data: Vec<Cow<'b, [u8]>>,
    pub(super) files: Vec<PathBuf>,
}

pub(super) fn load<'b>(container: &Container<'b>, file: &Path, read: ReadFile) -> Result<Buffers<'b>> {
    let mut buffers = Buffers { data: Vec::new(), files: Vec::new() };
    for buffer in container.document.buffers() {
        let index = buffer.index();
        let fail = |message: String| Error::invalid(format!("{}: buffer {index}: {message}", shown_path(file)));
        let data: Cow<[u8]> = match buffer.source() {
            gltf::buffer::Source::Bin => match container.bin {
                Some(bin) => Cow::Borrowed(bin),
                None => return Err(fail("names the GLB binary chunk, but the file has none".to_string())),
            },
            gltf::buffer::Source::Uri(text) => match uri::resolve(text, file).map_err(fail)? {
                Uri::Data(bytes) => Cow::Owned(bytes),
                Uri::File(path) => {
                    let bytes = read(&path)
                        .map_err(|error| fail(format!("{}: {error}", quote(path.as_os_str().as_encoded_bytes()))))?;
                    buffers.files.push(path);
                    Cow::Owned(bytes)
                }
            },
        };
        if data.len() < buffer.length() {
            return Err(fail(format!("declares {} bytes, but its data has {}", buffer.length(), data.len())));
        }
        // Views are bounded by the length declared, as the format bounds them.
        buffers.data.push(match data {
            Cow::Borrowed(bytes) => Cow::Borrowed(&bytes[..buffer.length()]),
            Cow::Owned(mut bytes) => {
                bytes.truncate(buffer.length());
                Cow::Owned(bytes)
            }
        });
    }
    Ok(buffers)
}
