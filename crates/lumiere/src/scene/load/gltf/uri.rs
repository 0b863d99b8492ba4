//! The URIs a glTF file names its buffers and images by: `data:` URIs carry their bytes in base64;
//! any other URI without a scheme is a path relative to the glTF file, percent-encoded.

use crate::scene::load::path_from_bytes;
use base64::Engine;
use std::path::{Path, PathBuf};

/// Where the bytes a URI names are.
#[derive(Debug, PartialEq)]
pub(super) enum Uri {
    /// A `data:` URI's bytes, decoded.
    Data(Vec<u8>),
    /// A file, resolved relative to the glTF file's folder.
    File(PathBuf),
}

/// Resolves `uri`, found in the glTF file `file`; the error is a reason, without the URI.
pub(super) fn resolve(uri: &str, file: &Path) -> Result<Uri, String> {
    if let Some(data) = uri.strip_prefix("data:") {
        let Some((media_type, payload)) = data.split_once(',') else {
            return Err("a data URI without a comma before its data".to_string());
        };
        let Some(_) = media_type.strip_suffix(";base64") else {
            return Err("a data URI that is not base64-encoded".to_string());
        };
        let engine = base64::engine::general_purpose::STANDARD;
        return engine
            .decode(payload)
            .map(Uri::Data)
            .map_err(|error| format!("a data URI whose base64 is bad: {error}"));
    }
    if let Some((scheme, _)) = uri.split_once(':')
        && is_scheme(scheme)
    {
        return Err(format!("a URI of scheme {scheme:?}: lumiere reads files relative to the glTF file and data URIs"));
    }
    let relative = percent_decoded(uri)?;
    if relative.is_empty() {
        return Err("an empty URI".to_string());
    }
    let folder = file.parent().unwrap_or(Path::new(""));
    Ok(Uri::File(folder.join(path_from_bytes(relative))))
}

/// RFC 3986's scheme: a letter, then letters, digits, `+`, `-` or `.`. A single letter is read as
/// a Windows drive (`C:/textures/a.png`), which is a path, not a scheme.
fn is_scheme(text: &str) -> bool {
    let mut chars = text.chars();
    text.len() > 1
        && chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
}

/// `uri` with its `%XX` escapes decoded to bytes (`my%20file.bin` is `my file.bin`).
fn percent_decoded(uri: &str) -> Result<Vec<u8>, String> {
    let bytes = uri.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] != b'%' {
            decoded.push(bytes[i]);
            i += 1;
            continue;
        }
        let hex = bytes.get(i + 1..i + 3).and_then(|h| std::str::from_utf8(h).ok());
        match hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
            Some(byte) => decoded.push(byte),
            None => return Err(format!("a URI with a bad escape at character {}", i + 1)),
        }
        i += 3;
    }
    Ok(decoded)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_resolve_to_data_or_files_beside_the_gltf_file() {
        let file = Path::new("scenes/box.gltf");
        assert_eq!(resolve("data:application/octet-stream;base64,AAEC/w==", file), Ok(Uri::Data(vec![0, 1, 2, 255])));
        assert_eq!(resolve("box%20data.bin", file), Ok(Uri::File(PathBuf::from("scenes/box data.bin"))));
        assert_eq!(resolve("C:/a.bin", file), Ok(Uri::File(PathBuf::from("scenes/C:/a.bin"))));
        assert!(resolve("https://example.com/a.bin", file).unwrap_err().contains("scheme \"https\""));
        assert!(resolve("data:application/octet-stream,abc", file).unwrap_err().contains("not base64"));
        assert!(resolve("data:;base64,@@", file).unwrap_err().contains("base64 is bad"));
        assert!(resolve("a%2", file).unwrap_err().contains("bad escape at character 2"));
        assert!(resolve("a%zz", file).unwrap_err().contains("bad escape"));
        assert_eq!(resolve("", file), Err("an empty URI".to_string()));
    }
}
