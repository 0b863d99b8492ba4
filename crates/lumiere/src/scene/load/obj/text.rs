//! Byte-level helpers shared by the OBJ and MTL parsers: lines, whitespace tokens, numbers.
//!
//! Both parsers read raw bytes, not `&str`: validating UTF-8 up front would cost a pass over 45 MB
//! files and would reject old files whose comments are Latin-1. Only the tokens that must be text
//! (numbers, names) are converted, each on its own, so a stray byte never aborts a whole file.

use crate::error::quote;
use std::borrow::Cow;

/// The lines of `bytes`, split at `\n`. A CRLF line keeps its `\r`, which the tokenizer treats as
/// whitespace. There is always exactly one more piece than there are `\n` bytes.
pub(super) fn lines(bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    bytes.split(|&b| b == b'\n')
}

/// Whether the file's line ends are lone `\r`s (classic Mac OS), which neither parser reads: such
/// a file is one long first line, with a `\r` inside it followed by more text (a CRLF file's first
/// line has its `\r` last; a stray one elsewhere ends up inside a statement, which its parser
/// refuses or warns about with the line's number).
pub(super) fn has_lone_carriage_returns(bytes: &[u8]) -> bool {
    let first_line = lines(bytes).next().unwrap_or_default();
    first_line.windows(2).any(|pair| pair[0] == b'\r' && pair[1] != b'\r')
}

/// The message for a file [`has_lone_carriage_returns`] refuses.
pub(super) const LONE_CARRIAGE_RETURNS: &str =
    "lone carriage-return line ends (classic Mac OS) are not supported: convert the file to LF or CRLF line ends";

/// Whitespace-separated tokens of one line, without allocating. A token that starts with `#` ends
/// the line: MTL files in the wild put comments after values (`Ka 0.7 0.7 0.7 # White`), while a
/// `#` inside a token (`Material#1`) is kept. Cloning one looks ahead.
#[derive(Clone)]
pub(super) struct Tokens<'a> {
    rest: &'a [u8],
}

impl<'a> Tokens<'a> {
    pub(super) fn new(line: &'a [u8]) -> Self {
        Tokens { rest: line }
    }

    /// What is left of the line, trimmed and without a trailing comment (see
    /// [`name_comment_start`]), as its bytes: file names keep them, so that a name in the file's
    /// own encoding finds its file.
    pub(super) fn remainder_bytes(self) -> &'a [u8] {
        let rest = self.rest.trim_ascii_start();
        rest[..name_comment_start(rest).unwrap_or(rest.len())].trim_ascii_end()
    }

    /// What is left of the line, trimmed, as one name (see [`text`]): material and file names may
    /// contain spaces.
    pub(super) fn remainder(self) -> Cow<'a, str> {
        text(self.remainder_bytes())
    }
}

/// Where a comment starts in `line`: at a `#` that begins a token (`Material#1` keeps its `#`).
pub(super) fn comment_start(line: &[u8]) -> Option<usize> {
    line.iter().enumerate().position(|(i, &b)| b == b'#' && (i == 0 || line[i - 1].is_ascii_whitespace()))
}

/// Where a comment starts after a name (`newmtl`, `usemtl`, `mtllib`, a texture's file): at a `#`
/// that stands alone as a word (`glass # the chandelier`). A word that starts with `#` and goes on
/// is part of the name: 3ds Max names its materials `Material #1`, `Material #2`, ..., which
/// Blender's and tinyobjloader's readers keep whole, where cutting at the `#` made them all one
/// material, `Material`.
fn name_comment_start(name: &[u8]) -> Option<usize> {
    let starts_word = |i: usize| i == 0 || name[i - 1].is_ascii_whitespace();
    let ends_word = |i: usize| name.get(i + 1).is_none_or(u8::is_ascii_whitespace);
    (0..name.len()).find(|&i| name[i] == b'#' && starts_word(i) && ends_word(i))
}

/// A name as text: UTF-8 where it is valid, otherwise each byte read as Latin-1, as older
/// exporters wrote names. Two Latin-1 names whose bytes differ stay two names (a lossy decoding
/// would make `caf\xe9` and `caf\xe8` one material), and a Latin-1 name is the same name as its
/// UTF-8 spelling: names are compared as text, so an OBJ and an MTL saved in different encodings
/// still agree on `café`.
pub(super) fn text(bytes: &[u8]) -> Cow<'_, str> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Cow::Borrowed(text),
        Err(_) => Cow::Owned(bytes.iter().map(|&b| char::from(b)).collect()),
    }
}

impl<'a> Iterator for Tokens<'a> {
    type Item = &'a [u8];

    fn next(&mut self) -> Option<&'a [u8]> {
        let rest = self.rest.trim_ascii_start();
        if rest.first().is_none_or(|&b| b == b'#') {
            self.rest = &[];
            return None;
        }
        let end = rest.iter().position(u8::is_ascii_whitespace).unwrap_or(rest.len());
        let (token, rest) = rest.split_at(end);
        self.rest = rest;
        Some(token)
    }
}

/// Parses a finite `f32`. NaN and infinities are refused: they would poison the BVH bounds.
pub(super) fn finite_f32(token: &[u8]) -> Result<f32, String> {
    let value = std::str::from_utf8(token).ok().and_then(|text| text.parse::<f32>().ok());
    match value {
        Some(x) if x.is_finite() => Ok(x),
        Some(_) => Err(format!("number {} is not finite", quote(token))),
        None => Err(format!("malformed number {}", quote(token))),
    }
}

/// Parses a signed decimal integer. Values past the `i64` range saturate instead of failing: an
/// index that large is out of range anyway, and the caller reports it with the token's own text.
pub(super) fn saturating_i64(token: &[u8]) -> Option<i64> {
    let (negative, digits) = match token {
        [b'-', digits @ ..] => (true, digits),
        [b'+', digits @ ..] => (false, digits),
        digits => (false, digits),
    };
    if digits.is_empty() {
        return None;
    }
    let mut value: i64 = 0;
    for &digit in digits {
        if !digit.is_ascii_digit() {
            return None;
        }
        value = value.saturating_mul(10).saturating_add(i64::from(digit - b'0'));
    }
    Some(if negative { -value } else { value })
}
