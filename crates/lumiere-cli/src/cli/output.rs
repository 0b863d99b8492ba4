//! Writing to stdout and stderr without ever panicking (`println!` panics when its stream is closed
//! or full). Messages on stderr are best effort: a closed stderr (`2>&1 | head`) must not cost a
//! render. Results on stdout are not: a full disk is an error; a reader that went away (`| head`)
//! ends the command quietly, as it wanted.

use std::fmt::Display;
use std::io::Write;

use lumiere::{Error, Result};

/// The name stdout goes by in errors.
pub const STDOUT: &str = "<stdout>";

/// One line of results on stdout.
pub fn print(line: impl Display) -> Result<()> {
    writeln!(std::io::stdout().lock(), "{line}").map_err(|e| Error::io(std::path::Path::new(STDOUT), e))
}

/// Bytes on stdout, flushed (a file written to `-`).
pub fn write_stdout(bytes: &[u8]) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes).and_then(|()| out.flush()).map_err(|e| Error::io(std::path::Path::new(STDOUT), e))
}

/// A one-line note on stderr (the closing summary, progress), if stderr can take it.
pub fn note(line: impl Display) {
    let _ = writeln!(std::io::stderr().lock(), "lumiere: {line}");
}

/// A one-line warning on stderr, if stderr can take it.
pub fn warn(line: impl Display) {
    let _ = writeln!(std::io::stderr().lock(), "lumiere: warning: {}", lumiere::error::one_line(&line.to_string()));
}

/// True when `error` says stdout's reader has gone (a closed pipe): the command stops quietly.
pub fn is_closed_stdout(error: &Error) -> bool {
    matches!(error, Error::Io { path, source } if path.as_os_str() == STDOUT && source.kind() == std::io::ErrorKind::BrokenPipe)
}
