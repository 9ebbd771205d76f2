//! Rust errors to Python exceptions.

use pyo3::exceptions::{PyKeyboardInterrupt, PyMemoryError, PyOSError, PyValueError};
use pyo3::{PyErr, Python};
use wscg_math::Error;

/// Maps a `wscg_math::Error` to a Python exception with the same message: `MemoryError` for a
/// buffer that does not fit ([`Error::OutOfMemory`]), `KeyboardInterrupt` (or what the
/// process's SIGINT handler raises) for work stopped by Ctrl-C ([`Error::Interrupted`]),
/// `OSError` for files (I/O, decoding, unsupported formats) and `ValueError` for everything
/// else.
pub fn to_py(e: Error) -> PyErr {
    match e {
        Error::OutOfMemory { .. } => PyMemoryError::new_err(e.to_string()),
        Error::Interrupted => interrupted(),
        e if e.is_io() => PyOSError::new_err(e.to_string()),
        e => PyValueError::new_err(e.to_string()),
    }
}

/// The exception for work stopped by a cancellation: what the SIGINT handler raises (by
/// default `KeyboardInterrupt`), run now that `pool::detach` has set the signal pending
/// again; a plain `KeyboardInterrupt` when the handler raises nothing.
pub fn interrupted() -> PyErr {
    Python::attach(|py| py.check_signals().err())
        .unwrap_or_else(|| PyKeyboardInterrupt::new_err("interrupted"))
}

/// A `ValueError` with the given message.
pub fn value_error(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// Extension to turn `wscg_math::Result` into `PyResult`.
pub trait IntoPy<T> {
    /// Converts the error with [`to_py`].
    fn py_err(self) -> pyo3::PyResult<T>;
}

impl<T> IntoPy<T> for wscg_math::Result<T> {
    fn py_err(self) -> pyo3::PyResult<T> {
        self.map_err(to_py)
    }
}

/// The result of `crate::pool::detach` running a fallible closure: the panic (outer) or the
/// closure's error (inner), whichever happened.
impl<T> IntoPy<T> for pyo3::PyResult<wscg_math::Result<T>> {
    fn py_err(self) -> pyo3::PyResult<T> {
        self.and_then(|r| r.map_err(to_py))
    }
}

/// `(Rust name, Python name)` pairs of the arguments a binding passes under another name
/// than the Python API's (`n_subjects` for the crate's `subjects`).
pub type Renames = [(&'static str, &'static str)];

/// `e` naming the argument it refuses by its Python name (see [`Renames`]), so that the
/// message of the `ValueError` or `MemoryError` names what the caller passed.
pub fn renamed(e: Error, renames: &Renames) -> Error {
    let py = |n: &'static str| {
        renames
            .iter()
            .find(|(rust, _)| *rust == n)
            .map_or(n, |(_, python)| python)
    };
    match e {
        Error::InvalidArgument { name, reason } => Error::InvalidArgument {
            name: py(name),
            reason,
        },
        Error::OutOfMemory { what, bytes, limit } => Error::OutOfMemory {
            what: py(what),
            bytes,
            limit,
        },
        e => e,
    }
}

/// Extension to turn `wscg_math::Result` into `PyResult` with the refused argument under its
/// Python name.
pub trait IntoPyRenamed<T> {
    /// Converts the error with [`renamed`], then [`to_py`].
    fn py_err_renamed(self, renames: &Renames) -> pyo3::PyResult<T>;
}

impl<T> IntoPyRenamed<T> for wscg_math::Result<T> {
    fn py_err_renamed(self, renames: &Renames) -> pyo3::PyResult<T> {
        self.map_err(|e| to_py(renamed(e, renames)))
    }
}

impl<T> IntoPyRenamed<T> for pyo3::PyResult<wscg_math::Result<T>> {
    fn py_err_renamed(self, renames: &Renames) -> pyo3::PyResult<T> {
        self.and_then(|r| r.map_err(|e| to_py(renamed(e, renames))))
    }
}
