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
