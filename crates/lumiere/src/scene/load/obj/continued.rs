//! Line continuations: a statement whose line ends with a backslash goes on on the next line (the
//! OBJ specification's `\`, which some exporters use to wrap long `f` lines), in OBJ and MTL files.
//!
//! An OBJ file's continued lines are joined before it is cut into chunks, so that no chunk
//! starts inside a statement. The text keeps its length and its number of lines: a continuation's
//! backslash (and the `\r` of a CRLF line) becomes a space, and the newline it swallowed moves to
//! the end of the statement, as a blank line. So every line after a joined statement keeps its
//! number in messages, and a joined statement is reported at its first line.

use super::text::{comment_start, lines};
use std::collections::TryReserveError;

/// Whether a line of `bytes` continues on the next: the common answer, no, is found by one
/// search for a backslash in files without any.
pub(super) fn has_continuations(bytes: &[u8]) -> bool {
    bytes.contains(&b'\\') && lines(bytes).any(|line| continuation(line).is_some())
}

/// `bytes` with every continued statement joined onto its first line, in a copy of the same
/// length; `Err` if the copy does not fit in memory.
pub(super) fn joined(bytes: &[u8]) -> Result<Vec<u8>, TryReserveError> {
    let mut joined = Vec::new();
    joined.try_reserve_exact(bytes.len())?;
    let mut swallowed_newlines = 0;
    let mut pieces = lines(bytes).peekable();
    while let Some(line) = pieces.next() {
        let last = pieces.peek().is_none();
        match continuation(line) {
            Some(backslash) => {
                joined.extend_from_slice(&line[..backslash]);
                // The backslash and the whitespace after it (a CRLF line's `\r`), as spaces.
                joined.resize(joined.len() + line.len() - backslash, b' ');
                // A file's last line has no newline to move.
                swallowed_newlines += usize::from(!last);
            }
            None => {
                joined.extend_from_slice(line);
                joined.resize(joined.len() + usize::from(!last) + swallowed_newlines, b'\n');
                swallowed_newlines = 0;
            }
        }
    }
    // A continuation on the last line but one or the last: the statement ends with the file.
    joined.resize(joined.len() + swallowed_newlines, b'\n');
    debug_assert_eq!(joined.len(), bytes.len(), "joining keeps the text's length");
    Ok(joined)
}

/// Where the continuing backslash of `line` is: its last byte before trailing whitespace, on a
/// line without a comment (a comment ends the line, as the tokenizer reads it: `# C:\models\`
/// continues nothing, and a statement with a comment after it has already ended).
fn continuation(line: &[u8]) -> Option<usize> {
    let body = line.trim_ascii_end();
    let backslash = body.len().checked_sub(1).filter(|&last| body[last] == b'\\')?;
    comment_start(line).is_none().then_some(backslash)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joined(text: &str) -> Option<String> {
        let bytes = text.as_bytes();
        has_continuations(bytes).then(|| String::from_utf8(super::joined(bytes).expect("fits")).expect("UTF-8"))
    }

    #[test]
    fn continued_lines_join_and_keep_the_line_count() {
        assert_eq!(joined("f 1 2 \\\n 3\nv 0 0 0\n").as_deref(), Some("f 1 2   3\n\nv 0 0 0\n"));
        assert_eq!(joined("f 1\\\r\n2\\\r\n3\r\n").as_deref(), Some("f 1  2  3\r\n\n\n"));
        // At the end of the file, with and without a final newline.
        assert_eq!(joined("f 1 2 3 \\\n").as_deref(), Some("f 1 2 3  \n"));
        assert_eq!(joined("f 1 2 \\\n3 \\").as_deref(), Some("f 1 2  3  \n"));
    }

    #[test]
    fn backslashes_that_continue_nothing_leave_the_text_alone() {
        assert_eq!(joined("v 0 0 0\nf 1 2 3\n"), None);
        // Inside a line (an escaped space in a file name), or in a comment.
        assert_eq!(joined("mtllib my\\ scene.mtl\nf 1 2 3\n"), None);
        assert_eq!(joined("# exported to C:\\models\\\nv 0 0 0\n"), None);
        assert_eq!(joined("f 1 2 3 # wraps \\\nv 0 0 0\n"), None);
    }
}
