//! Library errors as Python exceptions carrying the CLI's one-line messages: files that cannot be
//! read or written raise `lumiere.LumiereOSError` (an `OSError`, with `errno` and `filename`),
//! everything else `lumiere.LumiereError` (a `ValueError`). The classes live in
//! `lumiere/errors.py`, where Python can give them both bases.

use pyo3::prelude::*;

/// The Python exception for a library error.
pub fn to_py(error: lumiere::Error) -> PyErr {
    Python::attach(|py| build(py, &error).unwrap_or_else(|e| e))
}

fn build(py: Python<'_>, error: &lumiere::Error) -> PyResult<PyErr> {
    let errors = py.import("lumiere.errors")?;
    let instance = match error {
        lumiere::Error::Io { path, source } => {
            let instance = errors.getattr("LumiereOSError")?.call1((error.to_string(),))?;
            // An error lumiere words itself (an output's missing folder) carries no OS number:
            // its kind gives the one the OS would have, as `errno` promises one.
            let errno = match source.raw_os_error() {
                Some(number) => Some(number),
                None if source.kind() == std::io::ErrorKind::NotFound => {
                    Some(py.import("errno")?.getattr("ENOENT")?.extract::<i32>()?)
                }
                None => None,
            };
            instance.setattr("errno", errno)?;
            instance.setattr("filename", path.display().to_string())?;
            instance
        }
        _ => errors.getattr("LumiereError")?.call1((error.to_string(),))?,
    };
    Ok(PyErr::from_value(instance))
}

/// `LumiereError(message)`, for refusals the bindings make themselves.
pub fn invalid(message: impl Into<String>) -> PyErr {
    to_py(lumiere::Error::invalid(message))
}

/// An unsigned integer argument of at most `max`, or `LumiereError` naming `what`: PyO3's own
/// refusal of a negative or huge number is a bare `OverflowError` that names no argument.
pub fn unsigned(value: &Bound<'_, PyAny>, what: &str, max: u64) -> PyResult<u64> {
    value
        .extract::<u64>()
        .ok()
        .filter(|&v| v <= max)
        .ok_or_else(|| invalid(format!("{what} must be an integer between 0 and {max}, got {value}")))
}

/// Converts a library result.
pub trait OrPyErr<T> {
    fn or_py(self) -> PyResult<T>;
}

impl<T> OrPyErr<T> for lumiere::Result<T> {
    fn or_py(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}
