//! Rust errors to Python exceptions.

use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::PyErr;

/// Maps a `wscg_math::Error` to `OSError` (files: I/O, decoding, unsupported formats) or
/// `ValueError` (everything else), with the same message.
pub fn to_py(e: wscg_math::Error) -> PyErr {
    if e.is_io() {
        PyOSError::new_err(e.to_string())
    } else {
        PyValueError::new_err(e.to_string())
    }
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
