//! The OBJ statements the parser skips: which pass silently, which a reader should hear about
//! (elements lumiere does not render, keywords that are not OBJ at all), tallied per chunk and
//! merged for the whole file into one warning per keyword, with its count and first line.

use crate::error::{Error, Result, quote, shown_path};
use crate::scene::load::warnings::Warnings;
use std::path::Path;

/// Keywords skipped without a word: grouping, smoothing and display attributes, and the parts of
/// free-form geometry that mean nothing without the `curv`/`surf` statements (which are warned
/// about).
const SILENT: [&[u8]; 26] = [
    b"o",
    b"g",
    b"s",
    b"mg",
    b"vp",
    b"cstype",
    b"deg",
    b"bmat",
    b"step",
    b"parm",
    b"trim",
    b"hole",
    b"scrv",
    b"sp",
    b"end",
    b"con",
    b"bevel",
    b"c_interp",
    b"d_interp",
    b"lod",
    b"usemap",
    b"maplib",
    b"shadow_obj",
    b"trace_obj",
    b"ctech",
    b"stech",
];

/// Elements of the OBJ format that lumiere does not render, with what they are.
const UNRENDERED: [(&[u8], &str); 6] = [
    (b"l", "polylines"),
    (b"p", "points"),
    (b"curv", "free-form curves"),
    (b"curv2", "free-form curves"),
    (b"surf", "free-form surfaces"),
    (b"call", "calls to other files"),
];

/// How many distinct skipped keywords a chunk keeps; past them a file of junk is only counted
/// (its memory stays bounded). Only a file with more kinds than this in one chunk can see a
/// keyword's count or first line depend on where the chunks were cut, and its warnings say so.
const KEPT_KEYWORDS: usize = 256;

/// Whether `keyword` passes without a word.
pub(super) fn is_silent(keyword: &[u8]) -> bool {
    SILENT.contains(&keyword)
}

/// The lines of one keyword that were skipped.
#[derive(Clone, Copy, Debug)]
struct Skipped<'a> {
    keyword: &'a [u8],
    lines: usize,
    first_line: usize,
}

/// A chunk's skipped statements, by keyword in order of first use.
#[derive(Debug, Default)]
pub(super) struct SkippedKeywords<'a> {
    kept: Vec<Skipped<'a>>,
    /// Lines whose keyword came after the chunk had kept [`KEPT_KEYWORDS`] others.
    others: usize,
}

impl<'a> SkippedKeywords<'a> {
    /// Counts a skipped statement of `keyword` on line `line`.
    pub(super) fn note(&mut self, keyword: &'a [u8], line: usize) {
        if let Some(known) = self.kept.iter_mut().find(|s| s.keyword == keyword) {
            known.lines += 1;
        } else if self.kept.len() < KEPT_KEYWORDS {
            self.kept.push(Skipped { keyword, lines: 1, first_line: line });
        } else {
            self.others += 1;
        }
    }
}

/// The statements of the whole file that its chunks skipped, by keyword in order of first use.
pub(super) struct SkippedStatements<'a> {
    by_keyword: Vec<Skipped<'a>>,
    others: usize,
}

impl<'a> SkippedStatements<'a> {
    /// Merges the chunks' tallies, given in file order.
    pub(super) fn of<'c>(chunks: impl Iterator<Item = &'c SkippedKeywords<'a>>) -> Self
    where
        'a: 'c,
    {
        let mut merged = SkippedStatements { by_keyword: Vec::new(), others: 0 };
        for chunk in chunks {
            for skipped in &chunk.kept {
                match merged.by_keyword.iter_mut().find(|s| s.keyword == skipped.keyword) {
                    Some(known) => known.lines += skipped.lines,
                    None => merged.by_keyword.push(*skipped),
                }
            }
            merged.others += chunk.others;
        }
        merged
    }

    fn unknown(&self) -> impl Iterator<Item = &Skipped<'a>> {
        self.by_keyword.iter().filter(|s| !UNRENDERED.iter().any(|(keyword, _)| *keyword == s.keyword))
    }

    /// A file without a single face (`has_faces` false) whose other lines are not OBJ either is
    /// not an OBJ file: say so, rather than render nothing.
    pub(super) fn refuse_if_not_obj(&self, has_faces: bool, obj: &Path) -> Result<()> {
        match self.unknown().next() {
            Some(first) if !has_faces => {
                let message = format!(
                    "unknown statement {} and not one face in the file: is it an OBJ file?",
                    quote(first.keyword)
                );
                Err(Error::parse(obj, first.first_line, message))
            }
            _ => Ok(()),
        }
    }

    /// One warning per keyword: what lumiere does not render, and what it does not know.
    pub(super) fn warn(&self, warnings: &mut Warnings, obj: &Path) {
        let lines = |n: usize| if n == 1 { "1 line".to_string() } else { format!("{n} lines") };
        for skipped in &self.by_keyword {
            let (keyword, count, line) = (quote(skipped.keyword), skipped.lines, skipped.first_line);
            match UNRENDERED.iter().find(|(k, _)| *k == skipped.keyword) {
                Some((_, what)) => warnings.push(obj, "unrendered OBJ elements", || {
                    format!(
                        "{}:{line}: {keyword} statements ({what}) are not rendered: {} ignored, the first on this line",
                        shown_path(obj),
                        lines(count)
                    )
                }),
                None => warnings.push(obj, "unknown OBJ statements", || {
                    format!(
                        "{}:{line}: unknown statement {keyword}: {} ignored, the first on this line",
                        shown_path(obj),
                        lines(count)
                    )
                }),
            }
        }
        if self.others > 0 {
            warnings.push(obj, "unknown OBJ statements", || {
                format!(
                    "{}: {} more with other unknown statements ignored (over {KEPT_KEYWORDS} kinds in one part of \
                     the file, so the counts above may be short)",
                    shown_path(obj),
                    lines(self.others)
                )
            });
        }
    }
}
