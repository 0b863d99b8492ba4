//! One error type for everything the library can refuse: bad files, bad options, failed writes.
//!
//! Every variant formats as a single line that names what was wrong and where, so the CLI can print
//! it as is and exit with code 2.

use std::fmt;
use std::path::{Path, PathBuf};

#[derive(Debug)]
pub enum Error {
    /// A file could be read but its content is wrong at a known line (1-based).
    Parse { file: PathBuf, line: usize, message: String },
    /// Reading or writing a file failed.
    Io { path: PathBuf, source: std::io::Error },
    /// An option or a scene property that cannot be rendered (zero-size image, unknown mode, ...).
    Invalid(String),
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub fn parse(file: &Path, line: usize, message: impl Into<String>) -> Self {
        Error::Parse { file: file.to_path_buf(), line, message: message.into() }
    }

    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io { path: path.to_path_buf(), source }
    }

    pub fn invalid(message: impl Into<String>) -> Self {
        Error::Invalid(message.into())
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Parse { file, line, message } => write!(f, "{}:{line}: {message}", shown_path(file)),
            Error::Io { path, source } => write!(f, "{}: {source}", shown_path(path)),
            Error::Invalid(message) => f.write_str(message),
        }
    }
}

/// How many characters of a name taken from a file a message quotes.
pub const QUOTED_CHARS: usize = 80;

/// A name taken from a file (a material, an `mtllib` name, a texture path, a token) as messages
/// quote it: escaped like a Rust string literal, so that newlines and control characters cannot
/// split or garble the line, and cut after [`QUOTED_CHARS`] characters, with the name's full length:
/// `"aaaa…aaaa"… (10000000 bytes)`. Bytes that are not UTF-8 show as U+FFFD.
pub fn quote(name: impl AsRef<[u8]>) -> String {
    let bytes = name.as_ref();
    // A character takes at most 4 bytes and an invalid byte becomes one U+FFFD, so this prefix holds
    // more than QUOTED_CHARS characters whenever the name is cut: a 10 MB name is never converted whole.
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(4 * QUOTED_CHARS + 4)]);
    match head.char_indices().nth(QUOTED_CHARS) {
        None => format!("{head:?}"),
        Some((cut, _)) => format!("{:?}… ({} bytes)", &head[..cut], bytes.len()),
    }
}

/// A size of memory as people read one: GiB to one decimal from 1 GiB up, whole MiB below it
/// (rounded up, so that a size above zero never reads "0"). "0.2 GiB is available" hid that a
/// refused file of 0.15 GiB and a limit of 0.24 GiB were not the same number.
pub fn shown_bytes(bytes: impl Into<u128>) -> String {
    let bytes: u128 = bytes.into();
    if bytes >= 1 << 30 {
        format!("{:.1} GiB", bytes as f64 / (1u64 << 30) as f64)
    } else {
        format!("{} MiB", bytes.div_ceil(1 << 20))
    }
}

/// A path as messages show it: as it is when it prints on one line, otherwise escaped and quoted
/// like [`quote`] (but never cut), so that a file name with a newline cannot split a message; a
/// name that is not UTF-8 keeps its bytes as `\xFF` escapes (a lossy `U+FFFD` in their place named
/// a file no one could find).
pub fn shown_path(path: &Path) -> String {
    match path.to_str() {
        Some(text) if !text.chars().any(char::is_control) => text.to_string(),
        Some(text) => format!("{text:?}"),
        None => format!("{path:?}"),
    }
}

/// A name (a material's) as messages show it: in single quotes when it prints on one line,
/// otherwise escaped and double-quoted, so that a name given with a newline or a terminal escape
/// (`--emission "$(printf 'a\nb')=1,1,1"`) cannot split a message or reach the terminal raw.
pub fn shown_name(name: &str) -> String {
    if name.chars().any(char::is_control) { format!("{name:?}") } else { format!("'{name}'") }
}

/// `text` on one line: its lines trimmed and joined with spaces. For messages that quote another
/// library's (an image decoder's ends with a newline), so that every error and warning stays one
/// line.
pub fn one_line(text: &str) -> String {
    text.split(['\n', '\r']).map(str::trim).filter(|line| !line.is_empty()).collect::<Vec<_>>().join(" ")
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
