//! `set_memory_limit` / `set_max_image_pixels` and their getters: the process-wide limits of
//! `wscg_math::alloc` (largest buffer a size argument may ask for) and `wscg_math::io` (largest
//! image a file may declare).

use pyo3::prelude::*;
use pyo3::types::PyModule;

use crate::errors::value_error;

/// A limit given from Python: `None` or 0 restores the default, a positive count sets it.
fn limit_arg(name: &str, v: Option<i128>) -> PyResult<Option<u64>> {
    match v {
        None | Some(0) => Ok(None),
        Some(v) if v > 0 && v <= u64::MAX as i128 => Ok(Some(v as u64)),
        Some(v) => Err(value_error(format!(
            "`{name}` must be a positive count (or 0 or None for the default), got {v}"
        ))),
    }
}

/// Sets the largest single buffer, in bytes, that a size argument may make wscg allocate
/// (default: the machine's physical memory, or `WSCG_MAX_MEMORY`); `None` restores it.
#[pyfunction]
#[pyo3(signature = (nbytes))]
fn set_memory_limit(nbytes: Option<i128>) -> PyResult<()> {
    wscg_math::alloc::set_limit(limit_arg("nbytes", nbytes)?);
    Ok(())
}

/// The largest single buffer, in bytes, that a size argument may make wscg allocate.
#[pyfunction]
fn get_memory_limit() -> u64 {
    wscg_math::alloc::limit()
}

/// Sets the largest width x height an image file may declare to be decoded (default
/// 16384 x 16384, or `WSCG_MAX_IMAGE_PIXELS`); `None` restores it.
#[pyfunction]
#[pyo3(signature = (pixels))]
fn set_max_image_pixels(pixels: Option<i128>) -> PyResult<()> {
    wscg_math::io::set_max_image_pixels(limit_arg("pixels", pixels)?);
    Ok(())
}

/// The largest width x height an image file may declare to be decoded.
#[pyfunction]
fn get_max_image_pixels() -> u64 {
    wscg_math::io::max_image_pixels()
}

/// Adds the limit functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(set_memory_limit, m)?)?;
    m.add_function(wrap_pyfunction!(get_memory_limit, m)?)?;
    m.add_function(wrap_pyfunction!(set_max_image_pixels, m)?)?;
    m.add_function(wrap_pyfunction!(get_max_image_pixels, m)?)?;
    Ok(())
}
