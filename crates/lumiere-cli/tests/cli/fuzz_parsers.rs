//! Property-based fuzzing of every parser, on stable Rust and fast enough for CI: random bytes,
//! random token soup, and random mutations (bit flips, truncations, deletions, line duplication
//! and swaps, splices, hostile tokens) of the shipped scenes, orbiter files and PLY seeds, and
//! random PLY bodies under the seeds' headers. Each input goes
//! through the same checks as the libFuzzer targets in `fuzz/` (`fuzz/src/harness.rs`): no panic,
//! no hang (each input has a deadline), and an Ok result must be consistent (indices and material
//! ids in range, finite numbers) while an error must be one line naming the file and a real line.
//! The CLI's value parsers (`--size`, `--eye`, ...) are fuzzed through the binary, a few cases.
//!
//! Case counts are fixed (about 3 s in all with `--release`); the seed is random per run, so each
//! CI run searches new inputs, and a failure prints the minimal input. Reproduce a run with
//! `PROPTEST_RNG_SEED=<n>`, search longer with `FUZZ_CASES_SCALE=<k>` (k times the cases), e.g.
//! `FUZZ_CASES_SCALE=50 cargo test --release -p lumiere-cli --test cli fuzz_parsers`. See
//! docs/FUZZING.md.

use crate::harness::{
    checkpoint_target, gltf_target, guarded, mtl_target, obj_chunks_target, obj_target, orbiter_target, ply_target,
    raw_checkpoint, scene_target, with_checksum,
};
use crate::process::{Limits, TempDir, check_exit, run};
use proptest::prelude::*;
use proptest::sample::Index;
use std::ffi::OsStr;
use std::path::Path;
use std::time::Duration;

// Mutation seeds: gKit's box and orbiters as embedded in the library, McGuire's box from the corpus.
const CORNELL_OBJ: &[u8] = include_bytes!("../../../lumiere/assets/cornell/cornell.obj");
const CORNELL_MTL: &[u8] = include_bytes!("../../../lumiere/assets/cornell/cornell.mtl");
const MCGUIRE_OBJ: &[u8] = include_bytes!("../corpus/seeds/CornellBox-Original.obj");
const MCGUIRE_MTL: &[u8] = include_bytes!("../corpus/seeds/CornellBox-Original.mtl");
const ORBITER_2022: &[u8] = include_bytes!("../../../lumiere/assets/cornell/cornell_orbiter.txt");
const ORBITER_2020: &[u8] = include_bytes!("../../../lumiere/assets/cornell/cornell_orbiter_2020.txt");

// PLY seeds: ASCII quads with normals and colours; binary doubles, lists of each byte order, an
// element skipped between vertices and faces, a concave face.
const CUBE_PLY: &[u8] = include_bytes!("../corpus/seeds/cube-ascii.ply");
const HEXAGON_LE_PLY: &[u8] = include_bytes!("../corpus/seeds/hexagon-le.ply");
const HEXAGON_BE_PLY: &[u8] = include_bytes!("../corpus/seeds/hexagon-be.ply");

// glTF seeds: a `.gltf` with a base64 `data:` buffer (an emissive quad, the default material); a
// `.glb` with a binary chunk (u16 indices, normals, texture coordinates, a sparse accessor, a PNG in
// a buffer view, a texture transform, glass); a `.gltf` node tree (TRS, a matrix, a mirror) of
// strips and fans with u8 indices, interleaved quantised attributes, a viewless accessor, lines.
const QUAD_GLTF: &[u8] = include_bytes!("../corpus/seeds/quad-data-uri.gltf");
const TEXTURED_GLB: &[u8] = include_bytes!("../corpus/seeds/textured-sparse.glb");
const HIERARCHY_GLTF: &[u8] = include_bytes!("../corpus/seeds/hierarchy-strips-fans.gltf");

const OBJS: [&[u8]; 2] = [CORNELL_OBJ, MCGUIRE_OBJ];
const PLYS: [&[u8]; 3] = [CUBE_PLY, HEXAGON_LE_PLY, HEXAGON_BE_PLY];
const MTLS: [&[u8]; 2] = [CORNELL_MTL, MCGUIRE_MTL];
const ORBITERS: [&[u8]; 2] = [ORBITER_2022, ORBITER_2020];
const GLTFS: [&[u8]; 3] = [QUAD_GLTF, TEXTURED_GLB, HIERARCHY_GLTF];

/// Generous: a parse of a few KB takes microseconds; only a hang (or a quadratic blow-up) gets here.
const DEADLINE: Duration = Duration::from_secs(10);

/// Tokens that have broken parsers before: limits of every integer and float type, non-finite
/// spellings, empty and odd index fields, keywords, control and non-ASCII bytes.
const NASTY: &[&[u8]] = &[
    b"",
    b"0",
    b"-0",
    b"+1",
    b"-1",
    b"1e39",
    b"-1e39",
    b"1e400",
    b"NaN",
    b"nan",
    b"inf",
    b"-inf",
    b"infinity",
    b"1e-45",
    b"1e-46",
    b"3.4028235e38",
    b"-3.4028235e38",
    b"1.7976931348623157e308",
    b"0x10",
    b"1_000",
    b"1.",
    b".5",
    b"1e",
    b"-",
    b"2147483647",
    b"-2147483648",
    b"4294967295",
    b"4294967296",
    b"-4294967296",
    b"9223372036854775807",
    b"-9223372036854775808",
    b"9223372036854775808",
    b"99999999999999999999999999",
    b"-99999999999999999999999999",
    b"1/1/1",
    b"1//1",
    b"1/1",
    b"1/",
    b"/1",
    b"//",
    b"/",
    b"1/2/3/4",
    b"-1/-1/-1",
    b"#",
    b"# comment",
    b"\\",
    b"v",
    b"vt",
    b"vn",
    b"f",
    b"usemtl",
    b"mtllib",
    b"newmtl",
    b"Kd",
    b"Ke",
    b"d -halo",
    b"illum",
    b"map_Kd",
    b"map_d",
    b"c",
    b"p",
    b"r",
    b"s",
    b"\r",
    b"\t",
    b"\x0b",
    b"\x0c",
    b"\x00",
    b"\xef\xbb\xbf",
    b"\xff\xfe",
    b"\xc3\xa9",
    b"\xc3",
];

/// One edit of a file. Positions are [`Index`]es, resolved against the current length.
#[derive(Clone, Debug)]
enum Mutation {
    FlipBit(Index, u8),
    SetByte(Index, u8),
    Truncate(Index),
    Delete(Index, usize),
    DuplicateLine(Index, usize),
    SwapLines(Index, Index),
    DeleteLine(Index),
    /// Copies a piece of another seed file (`Index` picks the file) into this one.
    Splice {
        file: Index,
        from: Index,
        len: usize,
        at: Index,
    },
    InsertToken(Index, Index),
    /// Replaces the n-th whitespace-separated token with a nasty one.
    ReplaceToken(Index, Index),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<Index>(), 0u8..8).prop_map(|(at, bit)| Mutation::FlipBit(at, bit)),
        (any::<Index>(), any::<u8>()).prop_map(|(at, byte)| Mutation::SetByte(at, byte)),
        any::<Index>().prop_map(Mutation::Truncate),
        (any::<Index>(), 1usize..64).prop_map(|(at, len)| Mutation::Delete(at, len)),
        (any::<Index>(), 1usize..4).prop_map(|(line, times)| Mutation::DuplicateLine(line, times)),
        (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        any::<Index>().prop_map(Mutation::DeleteLine),
        (any::<Index>(), any::<Index>(), 1usize..200, any::<Index>())
            .prop_map(|(file, from, len, at)| Mutation::Splice { file, from, len, at }),
        (any::<Index>(), any::<Index>()).prop_map(|(at, token)| Mutation::InsertToken(at, token)),
        (any::<Index>(), any::<Index>()).prop_map(|(n, token)| Mutation::ReplaceToken(n, token)),
        // Weighted twice: the token-level edits are the ones that reach number and index parsing.
        (any::<Index>(), any::<Index>()).prop_map(|(n, token)| Mutation::ReplaceToken(n, token)),
    ]
}

fn split_lines(bytes: &[u8]) -> Vec<Vec<u8>> {
    bytes.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect()
}

/// Applies `mutations` in order; `seeds` are the files a splice copies from.
fn mutate(original: &[u8], mutations: &[Mutation], seeds: &[&[u8]]) -> Vec<u8> {
    let mut bytes = original.to_vec();
    for mutation in mutations {
        let len = bytes.len();
        match mutation {
            Mutation::FlipBit(at, bit) if len > 0 => bytes[at.index(len)] ^= 1 << bit,
            Mutation::SetByte(at, byte) if len > 0 => bytes[at.index(len)] = *byte,
            Mutation::Truncate(at) => bytes.truncate(at.index(len + 1)),
            Mutation::Delete(at, n) if len > 0 => {
                let start = at.index(len);
                bytes.drain(start..(start + n).min(len));
            }
            Mutation::DuplicateLine(line, times) => {
                let mut lines = split_lines(&bytes);
                let i = line.index(lines.len());
                for _ in 0..*times {
                    lines.insert(i, lines[i].clone());
                }
                bytes = lines.join(&b'\n');
            }
            Mutation::SwapLines(a, b) => {
                let mut lines = split_lines(&bytes);
                let n = lines.len();
                lines.swap(a.index(n), b.index(n));
                bytes = lines.join(&b'\n');
            }
            Mutation::DeleteLine(line) => {
                let mut lines = split_lines(&bytes);
                lines.remove(line.index(lines.len()));
                bytes = lines.join(&b'\n');
            }
            Mutation::Splice { file, from, len: n, at } => {
                let source = seeds[file.index(seeds.len())];
                if !source.is_empty() {
                    let start = from.index(source.len());
                    let piece = &source[start..(start + n).min(source.len())];
                    let at = at.index(len + 1);
                    bytes.splice(at..at, piece.iter().copied());
                }
            }
            Mutation::InsertToken(at, token) => {
                let at = at.index(len + 1);
                let token = NASTY[token.index(NASTY.len())];
                bytes.splice(at..at, token.iter().copied());
            }
            Mutation::ReplaceToken(n, token) => {
                let tokens: Vec<(usize, usize)> = token_spans(&bytes);
                if !tokens.is_empty() {
                    let (start, end) = tokens[n.index(tokens.len())];
                    let token = NASTY[token.index(NASTY.len())];
                    bytes.splice(start..end, token.iter().copied());
                }
            }
            _ => {}
        }
    }
    bytes
}

/// Byte ranges of the whitespace-separated tokens.
fn token_spans(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = None;
    for (i, &b) in bytes.iter().enumerate() {
        match (b.is_ascii_whitespace(), start) {
            (false, None) => start = Some(i),
            (true, Some(s)) => {
                spans.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        spans.push((s, bytes.len()));
    }
    spans
}

/// Random lines of keywords, numbers and hostile tokens: reaches deeper than random bytes.
fn token_soup() -> impl Strategy<Value = Vec<u8>> {
    const KEYWORDS: &[&[u8]] =
        &[b"v", b"v", b"v", b"vt", b"vn", b"f", b"f", b"f", b"usemtl", b"mtllib", b"#", b"g", b"o", b"s", b""];
    let keyword = prop::sample::select(KEYWORDS);
    let small_number = (-6i32..7).prop_map(|n| n.to_string().into_bytes());
    let nasty = prop::sample::select(NASTY).prop_map(<[u8]>::to_vec);
    let token = prop_oneof![3 => small_number, 1 => nasty];
    let line = (keyword, prop::collection::vec(token, 0..7)).prop_map(|(keyword, tokens)| {
        let mut line = keyword.to_vec();
        for token in tokens {
            line.push(b' ');
            line.extend_from_slice(&token);
        }
        line
    });
    prop::collection::vec(line, 0..40).prop_map(|lines| lines.join(&b'\n'))
}

/// JSON numbers for glTF: indices and counts at and past every limit, component types and
/// targets, floats that overflow `f32`, and spellings JSON refuses.
const JSON_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-0.0",
    "1",
    "-1",
    "2",
    "3",
    "4",
    "5",
    "6",
    "7",
    "8",
    "12",
    "16",
    "255",
    "256",
    "65535",
    "65536",
    "2147483647",
    "2147483648",
    "-2147483648",
    "4294967295",
    "4294967296",
    "9007199254740993",
    "9223372036854775807",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775808",
    "5120",
    "5121",
    "5122",
    "5123",
    "5125",
    "5126",
    "34962",
    "34963",
    "0.5",
    "1e-45",
    "1e-300",
    "3.4028235e38",
    "3.5e38",
    "-3.5e38",
    "1e300",
    "-1e300",
    "1.7976931348623157e308",
    "1e400",
    "1e",
    "01",
    "NaN",
];

/// JSON strings for glTF: accessor types, attribute names, URIs (data, relative, escaping,
/// percent-encoded, with a scheme), extension names, and odd text.
const JSON_STRINGS: &[&str] = &[
    "\"\"",
    "\"SCALAR\"",
    "\"VEC2\"",
    "\"VEC3\"",
    "\"VEC4\"",
    "\"MAT2\"",
    "\"MAT3\"",
    "\"MAT4\"",
    "\"POSITION\"",
    "\"NORMAL\"",
    "\"TEXCOORD_0\"",
    "\"TEXCOORD_1\"",
    "\"TEXCOORD_4294967296\"",
    "\"COLOR_0\"",
    "\"_X\"",
    "\"data:application/octet-stream;base64,\"",
    "\"data:;base64,AAAAAAAAAAAAAAAA\"",
    "\"data:,abc\"",
    "\"data:;base64,%%%\"",
    "\"x.bin\"",
    "\"../../etc/passwd\"",
    "\"/abs/x.bin\"",
    "\"%41%zz\"",
    "\"%\"",
    "\"C:/x.png\"",
    "\"http://example.com/x.bin\"",
    "\"image/png\"",
    "\"image/jpeg\"",
    "\"KHR_materials_transmission\"",
    "\"KHR_texture_transform\"",
    "\"KHR_mesh_quantization\"",
    "\"KHR_draco_mesh_compression\"",
    "\"\\u0000\\n\\ud800\"",
    "\"\u{e9}\"",
    "[]",
    "{}",
    "null",
    "true",
];

/// One structural edit of a glTF file's JSON (for a `.glb`, of its JSON chunk).
#[derive(Clone, Debug)]
enum JsonEdit {
    /// Replaces the n-th number (outside strings) with one of [`JSON_NUMBERS`].
    Number(Index, Index),
    /// Replaces the n-th string (a key or a value) with one of [`JSON_STRINGS`].
    Text(Index, Index),
    /// Replaces the n-th number with a number or string of the same file (an index elsewhere).
    Copy(Index, Index),
}

fn json_edit() -> impl Strategy<Value = JsonEdit> {
    prop_oneof![
        4 => (any::<Index>(), any::<Index>()).prop_map(|(n, v)| JsonEdit::Number(n, v)),
        2 => (any::<Index>(), any::<Index>()).prop_map(|(n, v)| JsonEdit::Text(n, v)),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(n, v)| JsonEdit::Copy(n, v)),
    ]
}

/// Byte ranges `(start, end)` of a file.
type Spans = Vec<(usize, usize)>;

/// The byte ranges of the JSON numbers and of the strings (quotes included) in `json`.
fn json_spans(json: &[u8]) -> (Spans, Spans) {
    let (mut numbers, mut strings) = (Vec::new(), Vec::new());
    let mut i = 0;
    while i < json.len() {
        match json[i] {
            b'"' => {
                let start = i;
                i += 1;
                while i < json.len() && json[i] != b'"' {
                    i += if json[i] == b'\\' { 2 } else { 1 };
                }
                i = (i + 1).min(json.len());
                strings.push((start, i));
            }
            b'-' | b'0'..=b'9' => {
                let start = i;
                while i < json.len() && matches!(json[i], b'-' | b'+' | b'.' | b'e' | b'E' | b'0'..=b'9') {
                    i += 1;
                }
                numbers.push((start, i));
            }
            _ => i += 1,
        }
    }
    (numbers, strings)
}

fn edit_json(original: &[u8], edits: &[JsonEdit]) -> Vec<u8> {
    let mut json = original.to_vec();
    for edit in edits {
        let (numbers, strings) = json_spans(&json);
        let (spans, value): (&[(usize, usize)], Vec<u8>) = match edit {
            JsonEdit::Number(_, v) => (&numbers[..], JSON_NUMBERS[v.index(JSON_NUMBERS.len())].as_bytes().to_vec()),
            JsonEdit::Text(_, v) => (&strings[..], JSON_STRINGS[v.index(JSON_STRINGS.len())].as_bytes().to_vec()),
            JsonEdit::Copy(n, v) if !numbers.is_empty() => {
                let (start, end) = numbers[v.index(numbers.len())];
                (&numbers[..], json[start..end].to_vec())
            }
            JsonEdit::Copy(..) => continue,
        };
        let n = match edit {
            JsonEdit::Number(n, _) | JsonEdit::Text(n, _) | JsonEdit::Copy(n, _) => n,
        };
        if !spans.is_empty() {
            let (start, end) = spans[n.index(spans.len())];
            json.splice(start..end, value);
        }
    }
    json
}

/// A `.glb`'s JSON chunk and the rest of the file after it (its other chunks), if it is one.
fn glb_json(glb: &[u8]) -> Option<(&[u8], &[u8])> {
    let length = u32::from_le_bytes(glb.get(12..16)?.try_into().ok()?) as usize;
    Some((glb.get(20..20 + length)?, &glb[20 + length..]))
}

/// A `.glb` of `json` (padded with spaces to 4 bytes) and the chunks `rest`, lengths recomputed.
fn rewrapped_glb(json: &[u8], rest: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + rest.len();
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(rest);
    out
}

/// `cases` cases, times `FUZZ_CASES_SCALE` when set (to search longer than CI does). The seed is
/// random per run (proptest's default) unless `PROPTEST_RNG_SEED` is set.
fn config(cases: u32) -> ProptestConfig {
    let scale = std::env::var("FUZZ_CASES_SCALE").ok().and_then(|s| s.parse::<u32>().ok()).unwrap_or(1).max(1);
    // No regression files: they would land in tests/; failing inputs belong in tests/corpus/.
    ProptestConfig { cases: cases.saturating_mul(scale), failure_persistence: None, ..ProptestConfig::default() }
}

/// `guarded` as a proptest assertion.
macro_rules! check {
    ($target:expr, $data:expr) => {
        if let Err(problem) = guarded($target, &$data, DEADLINE) {
            return Err(TestCaseError::fail(problem));
        }
    };
}

/// OBJ text, a NUL, then MTL text: the input format of the `obj` and `scene` fuzz targets.
fn with_mtl(obj: &[u8], mtl: &[u8]) -> Vec<u8> {
    [obj, b"\0", mtl].concat()
}

proptest! {
    #![proptest_config(config(5000))]

    #[test]
    fn obj_random_bytes(data in prop::collection::vec(any::<u8>(), 0..1024)) {
        check!(obj_target, data);
    }

    #[test]
    fn orbiter_random_bytes(data in prop::collection::vec(any::<u8>(), 0..256)) {
        check!(orbiter_target, data);
    }

    #[test]
    fn mtl_random_bytes(data in prop::collection::vec(any::<u8>(), 0..512)) {
        check!(mtl_target, data);
    }
}

proptest! {
    #![proptest_config(config(4000))]

    #[test]
    fn obj_token_soup(obj in token_soup(), chunk in any::<u8>()) {
        check!(obj_target, obj);
        check!(obj_chunks_target, [&[chunk][..], &obj].concat());
    }

    #[test]
    fn obj_mutated_shipped_scenes(
        scene in 0..OBJS.len(),
        mutations in prop::collection::vec(mutation(), 1..10),
        chunk in any::<u8>(),
    ) {
        let obj = mutate(OBJS[scene], &mutations, &[CORNELL_OBJ, MCGUIRE_OBJ, CORNELL_MTL, MCGUIRE_MTL]);
        check!(obj_target, with_mtl(&obj, MTLS[scene]));
        check!(obj_chunks_target, [&[chunk][..], &obj].concat());
    }

    #[test]
    fn mtl_mutated_shipped_materials(scene in 0..MTLS.len(), mutations in prop::collection::vec(mutation(), 1..10)) {
        let mtl = mutate(MTLS[scene], &mutations, &[CORNELL_MTL, MCGUIRE_MTL, CORNELL_OBJ]);
        // Through the scene's own OBJ (its material names) and through the synthetic one.
        check!(obj_target, with_mtl(OBJS[scene], &mtl));
        check!(mtl_target, mtl);
    }

    #[test]
    fn ply_mutated_seeds(file in 0..PLYS.len(), mutations in prop::collection::vec(mutation(), 1..10)) {
        let ply = mutate(PLYS[file], &mutations, &PLYS);
        check!(ply_target, ply);
    }

    /// A seed's header over random bytes: every value of a binary body read from noise.
    #[test]
    fn ply_random_bodies(file in 0..PLYS.len(), body in prop::collection::vec(any::<u8>(), 0..600)) {
        let header = PLYS[file].windows(11).position(|w| w == b"end_header\n").map_or(0, |at| at + 11);
        check!(ply_target, [&PLYS[file][..header], &body].concat());
    }

    /// Byte-level edits of the glTF seeds (a `.glb`'s lengths left as they are).
    #[test]
    fn gltf_mutated_seeds(file in 0..GLTFS.len(), mutations in prop::collection::vec(mutation(), 1..6)) {
        let gltf = mutate(GLTFS[file], &mutations, &GLTFS);
        check!(gltf_target, gltf);
    }

    /// Structural edits of the seeds' JSON: numbers (indices, counts, offsets, strides, component
    /// types, factors) and strings (types, attribute names, URIs) replaced, a `.glb` rewrapped
    /// with its lengths recomputed, so that the edit reaches the loader past the container.
    #[test]
    fn gltf_json_edits(file in 0..GLTFS.len(), edits in prop::collection::vec(json_edit(), 1..4)) {
        let gltf = match glb_json(GLTFS[file]).filter(|_| GLTFS[file].starts_with(b"glTF")) {
            Some((json, rest)) => rewrapped_glb(&edit_json(json, &edits), rest),
            None => edit_json(GLTFS[file], &edits),
        };
        check!(gltf_target, gltf);
    }

    #[test]
    fn orbiter_mutated_shipped_files(file in 0..ORBITERS.len(), mutations in prop::collection::vec(mutation(), 1..8)) {
        let orbiter = mutate(ORBITERS[file], &mutations, &ORBITERS);
        check!(orbiter_target, orbiter);
    }
}

proptest! {
    #![proptest_config(config(400))]

    /// Whatever parses must also build a BVH and render in every mode (8x6, 1 sample).
    #[test]
    fn scene_mutated_shipped_scenes(scene in 0..OBJS.len(), mutations in prop::collection::vec(mutation(), 1..6)) {
        let obj = mutate(OBJS[scene], &mutations, &[CORNELL_OBJ, MCGUIRE_OBJ]);
        check!(scene_target, with_mtl(&obj, MTLS[scene]));
    }
}

/// A valid checkpoint to mutate: `width` x `height` pixels of data, checksum included.
fn valid_checkpoint(width: u32, height: u32) -> Vec<u8> {
    raw_checkpoint(width, height, 4, 1.5, (width * height) as usize)
}

proptest! {
    #![proptest_config(config(4000))]

    #[test]
    fn checkpoint_random_bytes(data in prop::collection::vec(any::<u8>(), 0..256)) {
        check!(checkpoint_target, data);
    }

    /// Mutations of valid checkpoints, with the checksum recomputed afterwards (flag 1) so that
    /// the header and size checks behind it are exercised, or left stale (flag 0).
    #[test]
    fn checkpoint_mutated_valid_files(
        width in 1u32..4,
        height in 1u32..4,
        mutations in prop::collection::vec(mutation(), 1..6),
        fix_checksum in any::<bool>(),
    ) {
        let valid = valid_checkpoint(width, height);
        let body = mutate(&valid[..valid.len() - 8], &mutations, &[&valid]);
        let bytes = if fix_checksum { with_checksum(&body) } else { [&body[..], &valid[valid.len() - 8..]].concat() };
        // Flag 0: decode these exact bytes.
        check!(checkpoint_target, [&[0u8][..], &bytes].concat());
    }
}

/// Values for the CLI's own parsers: a few valid ones (kept tiny: every valid `--size` renders),
/// and pieces that must be refused. Sizes whose product is large are not generated here: the
/// refusal of absurd sizes is checked on its own in `tests/fuzz_corpus.rs`.
fn size_value() -> impl Strategy<Value = String> {
    let number = prop::sample::select(
        &[
            "1",
            "3",
            "8",
            "+4",
            " 5",
            "6 ",
            "0",
            "-1",
            "",
            "1e3",
            "0x10",
            "3.5",
            "4294967296",
            "18446744073709551616",
            "99999999999999999999",
            "abc",
            "\u{663}",
            "\u{bd}",
            "nan",
        ][..],
    );
    let separator = prop::sample::select(&["x", "X", "*", ",", "xx", "", " x ", "x-", "×"][..]);
    prop_oneof![
        (1u32..16, 1u32..16).prop_map(|(w, h)| format!("{w}x{h}")),
        (number.clone(), separator, number).prop_map(|(w, s, h)| format!("{w}{s}{h}")),
    ]
}

fn vec3_value() -> impl Strategy<Value = String> {
    let number = prop::sample::select(
        &["0", "1", "-1", "0.5", " 2", "1e39", "-1e39", "nan", "inf", "-inf", "", "1e-45", "3.4028235e38", "x", "0x1"]
            [..],
    );
    prop_oneof![
        (-3i32..4, -3i32..4, -3i32..4).prop_map(|(x, y, z)| format!("{x},{y},{z}")),
        prop::collection::vec(number, 0..5).prop_map(|parts| parts.join(",")),
    ]
}

fn scalar_value() -> impl Strategy<Value = String> {
    prop::sample::select(
        &[
            "0",
            "1",
            "2",
            "45",
            "90",
            "179.9",
            "180",
            "-1",
            "nan",
            "inf",
            "1e39",
            "",
            "abc",
            "4294967296",
            "-0",
            "1e-45",
        ][..],
    )
    .prop_map(str::to_string)
}

/// Arguments after `render --mode hits`: some hostile options, always a tiny image.
fn render_arguments() -> impl Strategy<Value = Vec<String>> {
    (
        prop::option::of(size_value()),
        prop::option::of((vec3_value(), vec3_value())),
        prop::option::of(vec3_value()),
        prop::option::of(scalar_value()),
        prop::option::of(scalar_value()),
        prop::option::of(scalar_value()),
        prop::option::of((prop::sample::select(&["", "light", "Light", "x", "="][..]), vec3_value())),
    )
        .prop_map(|(size, look_at, up, fov, spp, ao_distance, emission)| {
            let mut args: Vec<String> = Vec::new();
            let mut push = |flag: &str, value: String| {
                args.push(flag.to_string());
                args.push(value);
            };
            push("--size", size.unwrap_or_else(|| "8x6".to_string()));
            if let Some((eye, target)) = look_at {
                push("--eye", eye);
                push("--target", target);
            }
            if let Some(up) = up {
                push("--up", up);
            }
            if let Some(fov) = fov {
                push("--fov", fov);
            }
            if let Some(spp) = spp {
                // Only small sample counts can be valid: `--spp 4294967295` would render for hours.
                push("--spp", if spp.parse::<f64>().is_ok_and(|n| n > 2.0) { "2".to_string() } else { spp });
            }
            if let Some(distance) = ao_distance {
                push("--ao-distance", distance);
            }
            if let Some((name, value)) = emission {
                push("--emission", format!("{name}={value}"));
            }
            args
        })
}

proptest! {
    #![proptest_config(config(60))]

    /// `render --mode hits` with hostile option values: exit 0, or 2 with a clap usage error or
    /// one `lumiere: error:` line; never a panic, a signal or a hang.
    #[test]
    fn cli_hostile_option_values(extra in render_arguments()) {
        let dir = TempDir::new("cli-options");
        let out = dir.path("out.png");
        let mut args: Vec<&OsStr> = ["render", "--mode", "hits", "--threads", "1", "-o"].map(OsStr::new).to_vec();
        args.push(out.as_os_str());
        args.extend(extra.iter().map(OsStr::new));
        let result = run(Path::new(env!("CARGO_BIN_EXE_lumiere")), &args, &dir.0, Limits::default());
        if let Err(problem) = check_exit(&result, true) {
            return Err(TestCaseError::fail(format!("{problem}: {}", result.describe(&args))));
        }
        prop_assert_eq!(result.status.and_then(|s| s.code()) == Some(0), out.exists(), "{}", result.describe(&args));
    }

    /// `render --orbiter <mutated file>` end to end: the file's errors reach the user as one line
    /// naming the file and the line.
    #[test]
    fn cli_mutated_orbiter_files(file in 0..ORBITERS.len(), mutations in prop::collection::vec(mutation(), 1..6)) {
        let dir = TempDir::new("cli-orbiter");
        let orbiter = dir.write("hostile_orbiter.txt", &mutate(ORBITERS[file], &mutations, &ORBITERS));
        let out = dir.path("out.png");
        let args: Vec<&OsStr> = vec![
            "render".as_ref(), "--mode".as_ref(), "hits".as_ref(), "--size".as_ref(), "8x6".as_ref(),
            "--threads".as_ref(), "1".as_ref(), "--orbiter".as_ref(), orbiter.as_os_str(), "-o".as_ref(),
            out.as_os_str(),
        ];
        let result = run(Path::new(env!("CARGO_BIN_EXE_lumiere")), &args, &dir.0, Limits::default());
        if let Err(problem) = check_exit(&result, false) {
            return Err(TestCaseError::fail(format!("{problem}: {}", result.describe(&args))));
        }
        if let Some(error) = crate::process::error_line(&result) {
            let named = format!("lumiere: error: {}:", orbiter.display());
            prop_assert!(error.starts_with(&named), "error does not name the orbiter file and line: {}", error);
        }
    }
}
