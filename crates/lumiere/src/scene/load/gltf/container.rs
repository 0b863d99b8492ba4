//! The outside of a glTF file: a `.gltf` is its JSON; a `.glb` is a 12-byte header, a JSON chunk
//! and an optional binary chunk (glTF 2.0 §4.4). The container is read here, within its bounds,
//! then the JSON is deserialised and validated by the `gltf` crate (every reference in range).

use crate::error::{Error, QUOTED_CHARS, Result, quote, shown_path};
use gltf::Document;
use std::path::Path;

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// The extensions lumiere reads; a file that requires any other is refused, as the format asks.
pub(super) const SUPPORTED_EXTENSIONS: [&str; 5] = [
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_transmission",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
];

/// A parsed glTF file: its validated document and, for a `.glb`, its binary chunk.
pub(super) struct Container<'b> {
    pub(super) document: Document,
    pub(super) bin: Option<&'b [u8]>,
}

/// Reads `bytes` as a `.glb` when they start with its magic, otherwise as JSON.
pub(super) fn parse<'b>(bytes: &'b [u8], file: &Path) -> Result<Container<'b>> {
    let (json, bin) = if bytes.starts_with(GLB_MAGIC) { split_glb(bytes, file)? } else { (bytes, None) };
    let root: gltf::json::Root = gltf::json::deserialize::from_slice(json)
        .map_err(|error| Error::invalid(format!("{}: not glTF JSON: {}", shown_path(file), shortened(&error))))?;
    if let Some(required) = root.extensions_required.iter().find(|e| !SUPPORTED_EXTENSIONS.contains(&e.as_str())) {
        return Err(Error::invalid(format!(
            "{}: requires the extension {}, which lumiere does not read (it reads {})",
            shown_path(file),
            quote(required),
            SUPPORTED_EXTENSIONS.join(", ")
        )));
    }
    validate(&root, file)?;
    Ok(Container { document: Document::from_json_without_validation(root), bin })
}

/// serde's message, cut in the middle when long: it quotes a string of the file whole
/// (`invalid type: string "aaaa…", expected u32 at line 1 column 9000`).
fn shortened(error: &impl std::fmt::Display) -> String {
    let message = error.to_string();
    let chars: Vec<char> = message.chars().collect();
    if chars.len() <= 3 * QUOTED_CHARS {
        return message;
    }
    let head: String = chars[..2 * QUOTED_CHARS].iter().collect();
    let tail: String = chars[chars.len() - QUOTED_CHARS..].iter().collect();
    format!("{head}…{tail} ({} characters in all)", chars.len())
}

/// Refuses a document whose references are out of range or whose values are invalid, naming the
/// first problem: `accessors[2].bufferView: index out of bounds`. The bounds of `POSITION`
/// (`min`, `max`), which the format requires but lumiere does not read, may be missing: exporters
/// that leave them out are common, and refusing their files would help no one.
fn validate(root: &gltf::json::Root, file: &Path) -> Result<()> {
    use gltf::json::validation::{Error as Problem, Validate};
    let mut problems = unchecked_by_the_crate(root);
    // Only when those are fine: the crate's check of POSITION's bounds would index out of range.
    if problems.is_empty() {
        root.validate(root, gltf::json::Path::new, &mut |path, problem| {
            let path = path().to_string();
            let unread_bounds =
                matches!(problem, Problem::Missing) && (path.ends_with(".min") || path.ends_with(".max"));
            // Required extensions were checked against lumiere's list, which the crate's does not hold.
            let required = matches!(problem, Problem::Unsupported) && path.starts_with("extensionsRequired");
            if !unread_bounds && !required {
                problems.push((path, problem));
            }
        });
    }
    let Some((path, problem)) = problems.first() else { return Ok(()) };
    let more = match problems.len() {
        1 => String::new(),
        n => format!(" (and {} more problems)", n - 1),
    };
    let problem = problem.to_string().to_lowercase();
    Err(Error::invalid(format!("{}: invalid glTF: {path}: {problem}{more}", shown_path(file))))
}

/// What the `gltf` crates do not check but assume, panicking on a file that breaks it: a
/// primitive's `POSITION` accessor index in range (its validation indexes the accessors with it),
/// and an image with a `uri` or a `bufferView`, the latter with its `mimeType` (`Image::source`
/// unwraps them), as the format requires.
fn unchecked_by_the_crate(root: &gltf::json::Root) -> Vec<(String, gltf::json::validation::Error)> {
    use gltf::json::validation::{Checked, Error as Problem};
    let mut problems = Vec::new();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive.attributes.get(&Checked::Valid(gltf::json::mesh::Semantic::Positions));
            if position.is_some_and(|index| index.value() >= root.accessors.len()) {
                let path = format!("meshes[{m}].primitives[{p}].attributes[\"POSITION\"]");
                problems.push((path, Problem::IndexOutOfBounds));
            }
        }
    }
    for (i, image) in root.images.iter().enumerate() {
        match (&image.uri, &image.buffer_view, &image.mime_type) {
            (None, None, _) => problems.push((format!("images[{i}].uri"), Problem::Missing)),
            (_, Some(_), None) => problems.push((format!("images[{i}].mimeType"), Problem::Missing)),
            _ => {}
        }
    }
    problems
}

/// The JSON chunk and the binary chunk (if any) of a `.glb` file.
fn split_glb<'b>(bytes: &'b [u8], file: &Path) -> Result<(&'b [u8], Option<&'b [u8]>)> {
    let fail = |message: String| Error::invalid(format!("{}: GLB: {message}", shown_path(file)));
    let word = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(fail(format!("the header needs 12 bytes, the file has {}", bytes.len())));
    };
    if version != 2 {
        return Err(fail(format!("version {version}; lumiere reads glTF 2")));
    }
    if length as usize != bytes.len() {
        return Err(fail(format!("the header gives a length of {length} bytes, the file has {}", bytes.len())));
    }
    let mut chunks = Vec::new();
    let mut at = 12;
    while at < bytes.len() {
        let (Some(chunk_length), Some(kind)) = (word(at), word(at + 4)) else {
            return Err(fail(format!("byte {at}: a chunk header needs 8 bytes, {} are left", bytes.len() - at)));
        };
        let start = at + 8;
        let end = start.checked_add(chunk_length as usize).filter(|&end| end <= bytes.len());
        let Some(end) = end else {
            return Err(fail(format!(
                "byte {at}: a chunk of {chunk_length} bytes, but {} are left",
                bytes.len() - start
            )));
        };
        chunks.push((kind, &bytes[start..end], at));
        at = end;
    }
    match chunks.as_slice() {
        [(CHUNK_JSON, json, _), rest @ ..] => {
            // Chunks of other types are for extensions and are skipped, as the format says; a
            // second binary chunk is not allowed.
            let mut bins = rest.iter().filter(|(kind, ..)| *kind == CHUNK_BIN);
            let bin = bins.next().map(|(_, data, _)| *data);
            if let Some((_, _, at)) = bins.next() {
                return Err(fail(format!("byte {at}: a second binary chunk")));
            }
            Ok((json, bin))
        }
        _ => Err(fail("the first chunk is not the JSON chunk".to_string())),
    }
}
