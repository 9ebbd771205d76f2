//! Parameter dicts: typed entries of a `dict` of keyword settings, each error naming its key.

use pyo3::prelude::*;

use crate::args;
use crate::convert::{choice, values};
use crate::errors::value_error;

/// The entry `key` of a parameter dict, extracted as `T`; `None` when absent or `None`. A
/// value of the wrong type is a `ValueError` naming the key.
pub fn dict_item<'py, T: pyo3::conversion::FromPyObjectOwned<'py>>(
    spec: &Bound<'py, pyo3::types::PyDict>,
    key: &str,
) -> PyResult<Option<T>> {
    match spec.get_item(key)? {
        Some(v) if !v.is_none() => v.extract::<T>().map(Some).map_err(|e| {
            let e: PyErr = e.into();
            value_error(format!("`{key}`: {e}"))
        }),
        _ => Ok(None),
    }
}

/// Reads typed entries of the parameter dict, with defaults.
pub(crate) struct Cfg<'a, 'py>(pub(crate) &'a Bound<'py, pyo3::types::PyDict>);

impl<'py> Cfg<'_, 'py> {
    pub(crate) fn get<T: pyo3::conversion::FromPyObjectOwned<'py>>(
        &self,
        key: &str,
        default: T,
    ) -> PyResult<T> {
        Ok(dict_item(self.0, key)?.unwrap_or(default))
    }

    pub(crate) fn opt<T: pyo3::conversion::FromPyObjectOwned<'py>>(
        &self,
        key: &str,
    ) -> PyResult<Option<T>> {
        dict_item(self.0, key)
    }

    /// The entry `key` unless absent or `None`.
    fn entry(&self, key: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        Ok(self.0.get_item(key)?.filter(|v| !v.is_none()))
    }

    /// The entry `key` as `N` numbers (any array-like, as [`args::numbers`]).
    pub(crate) fn numbers<const N: usize>(&self, key: &str) -> PyResult<Option<[f64; N]>> {
        self.entry(key)?.map(|v| args::numbers(key, &v)).transpose()
    }

    /// The entry `key` as a flat list of numbers (any real array-like).
    pub(crate) fn floats(&self, key: &str) -> PyResult<Option<Vec<f64>>> {
        self.entry(key)?
            .map(|v| Ok(values(&args::array::<f64>(key, &v)?).into_owned()))
            .transpose()
    }

    /// The count or seed `key`, at least `lo` (out of range: as [`args::uint`]),
    /// `default` when absent.
    pub(crate) fn count<T>(&self, key: &str, default: T, lo: T) -> PyResult<T>
    where
        T: TryFrom<i128> + PartialOrd + Copy + std::fmt::Display,
    {
        match self.entry(key)? {
            None => Ok(default),
            Some(v) => args::uint(self.0.py(), key, args::integer(key, &v)?, lo),
        }
    }
}

/// The option named by the string entry `key` of `d` ([`choice`]), `default` when absent.
pub fn choice_item<T: Copy>(
    d: &Bound<'_, pyo3::types::PyDict>,
    key: &str,
    default: T,
    options: &[(&str, T)],
) -> PyResult<T> {
    dict_item::<String>(d, key)?.map_or(Ok(default), |s| choice(key, &s, options))
}
