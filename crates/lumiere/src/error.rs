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
            Error::Parse { file, line, message } => write!(f, "{}:{line}: {message}", file.display()),
            Error::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Error::Invalid(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
