//! The pickled state of native objects: their Rust state serialised with `serde` in
//! postcard's compact binary format (every float bit for bit), behind a one-byte format
//! version. A class pickles as `(restore function, (state bytes, ...))` from `__reduce__`.

use pyo3::prelude::*;
use pyo3::types::PyBytes;
use serde::de::DeserializeOwned;
use serde::Serialize;

use crate::errors::value_error;

/// What `__reduce__` returns: a restore function and its arguments.
pub type Reduced<'py> = (Bound<'py, PyAny>, (Bound<'py, PyBytes>,));

/// Version of the state format; bumped when a serialised layout changes.
const FORMAT: u8 = 1;

/// The state bytes of `value` (serialised with the GIL released).
pub fn to_bytes<'py, T: Serialize + Sync>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyBytes>> {
    let bytes = crate::pool::detach(py, || postcard::to_io(value, vec![FORMAT]))?
        .map_err(|e| value_error(format!("cannot serialise the state: {e}")))?;
    Ok(PyBytes::new(py, &bytes))
}

/// `(restore, (state,))` for `__reduce__`: the function `name` of the submodule
/// `wscg._native.{module}` applied to the state bytes of `value`.
pub fn reduce<'py, T: Serialize + Sync>(
    py: Python<'py>,
    module: &str,
    name: &str,
    value: &T,
) -> PyResult<Reduced<'py>> {
    let restore = py.import(format!("wscg._native.{module}"))?.getattr(name)?;
    Ok((restore, (to_bytes(py, value)?,)))
}

/// The value of state bytes from [`to_bytes`]; a `ValueError` naming `what` when they are
/// not the state of one (damaged, or written by another format version).
pub fn from_bytes<T: DeserializeOwned + Send>(
    py: Python<'_>,
    what: &str,
    data: &[u8],
) -> PyResult<T> {
    match data.split_first() {
        Some((&FORMAT, rest)) => crate::pool::detach(py, || postcard::from_bytes(rest))?
            .map_err(|e| value_error(format!("`state` is not the state of a {what}: {e}"))),
        Some((v, _)) => Err(value_error(format!(
            "`state` of a {what} has format version {v}; this wscg reads version {FORMAT}"
        ))),
        None => Err(value_error(format!("`state` of a {what} is empty"))),
    }
}
