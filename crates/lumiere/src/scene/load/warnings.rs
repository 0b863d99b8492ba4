//! Load warnings, capped: a file with 100 000 bad lines of one kind gives its first
//! [`SHOWN_PER_KIND`] warnings and one line "… and 99990 more like this", not 100 000 lines.

use crate::error::shown_path;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Warnings of one kind about one file that are shown before they are summed up.
pub const SHOWN_PER_KIND: usize = 10;

/// The warnings of one load, in the order they were met; every one is a single line.
#[derive(Debug, Default)]
pub(crate) struct Warnings {
    lines: Vec<String>,
    kinds: HashMap<(PathBuf, &'static str), KindCount>,
}

#[derive(Debug)]
struct KindCount {
    count: usize,
    /// Where the "… and N more" line goes: right after the last warning shown.
    summary_at: usize,
}

impl Warnings {
    /// Adds a warning of `kind` (a short plural noun phrase, e.g. "ignored MTL lines") about
    /// `file`; `message` makes the line, and is called only for warnings that are shown.
    pub(crate) fn push(&mut self, file: &Path, kind: &'static str, message: impl FnOnce() -> String) {
        let entry =
            self.kinds.entry((file.to_path_buf(), kind)).or_insert(KindCount { count: 0, summary_at: usize::MAX });
        entry.count += 1;
        match entry.count {
            n if n <= SHOWN_PER_KIND => {
                let line = message();
                debug_assert!(!line.contains('\n'), "a warning spans lines: {line:?}");
                self.lines.push(line);
            }
            n if n == SHOWN_PER_KIND + 1 => {
                entry.summary_at = self.lines.len();
                // Filled in by `finish`, when the count is known.
                self.lines.push(String::new());
            }
            _ => {}
        }
    }

    /// The warning lines, with one summary line per kind that had more than [`SHOWN_PER_KIND`].
    pub(crate) fn finish(mut self) -> Vec<String> {
        for ((file, kind), count) in self.kinds {
            if count.count > SHOWN_PER_KIND {
                self.lines[count.summary_at] =
                    format!("{}: … and {} more like this ({kind})", shown_path(&file), count.count - SHOWN_PER_KIND);
            }
        }
        self.lines
    }
}
