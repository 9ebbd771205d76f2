//! Argument conversion shared by the bindings that Python calls directly (no Python wrapper
//! in between): each function turns one Python argument into the value the binding needs,
//! or raises a `ValueError` that names the argument, with the messages of py/API.md
//! ("`name` must be ...").
//!
//! - arrays: [`array`] takes any array-like of real numbers (lists, other dtypes,
//!   non-contiguous views) and gives a C-contiguous array of the element type the binding
//!   works in, refusing complex, string and object data by name; [`floats`] keeps float64
//!   data in double precision and takes anything else as float32; [`asarray`] leaves the
//!   dtype to the binding (8-bit data taken as it is); [`complex`] takes complex data;
//!   [`indices`] reads an optional list of indices, [`mesh`] a triangle mesh;
//! - numbers: [`uint`] checks a count, size or seed taken as `i128` (so that a negative or
//!   too large value is the package's `IntegerRangeError`, a `ValueError` naming the
//!   argument, not the conversion's bare `OverflowError`); [`number`] refuses NaN;
//!   [`numbers`] reads a fixed count of numbers ([`pair`] a range, [`triple`] a spacing or an
//!   origin), [`finite3`] checks them; [`counts`] reads a list of non-negative integers and
//!   [`size2`] a shape `(rows, cols)`;
//! - files: [`path`] takes a `str` or `os.PathLike`;
//! - choices among names are [`crate::convert::choice`].

use numpy::{
    Element, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

use crate::errors::value_error;

/// `numpy`, imported once.
fn numpy(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    static NUMPY: PyOnceLock<Py<PyModule>> = PyOnceLock::new();
    Ok(NUMPY
        .get_or_try_init(py, || py.import("numpy").map(Bound::unbind))?
        .bind(py))
}

/// `obj` as a C-contiguous array of `T`: an array of `T` as it is (a view is copied later by
/// [`crate::convert::values`]), anything else through `numpy.asarray` and a cast. Booleans,
/// integers and floats are numeric; complex data is refused ("must be real-valued") and so
/// is any other dtype ("must be a numeric array"), naming `name`. Integer targets refuse
/// floats with a fractional part ("must be an integer array").
pub fn array<'py, T: Element>(
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<T>>() {
        return Ok(a.readonly());
    }
    let py = obj.py();
    let np = numpy(py)?;
    let a = np
        .call_method1("asarray", (obj,))
        .map_err(|e| value_error(format!("`{name}` must be a numeric array: {e}")))?;
    let dtype = a.getattr("dtype")?;
    let kind: char = dtype.getattr("kind")?.extract()?;
    let target = T::get_dtype(py);
    let integral_target = matches!(target.kind(), b'i' | b'u');
    match kind {
        'b' | 'i' | 'u' => {}
        'f' if !integral_target => {}
        'f' => {
            let whole: bool = np
                .call_method1("array_equal", (&a, np.call_method1("trunc", (&a,))?))?
                .extract()?;
            if !whole {
                return Err(value_error(format!(
                    "`{name}` must be an integer array, got dtype {dtype} with a fractional value"
                )));
            }
        }
        'c' => {
            return Err(value_error(format!(
                "`{name}` must be real-valued, got dtype {dtype}"
            )))
        }
        _ => {
            return Err(value_error(format!(
                "`{name}` must be a numeric array, got dtype {dtype}"
            )))
        }
    }
    let c = np.call_method1("ascontiguousarray", (a, target))?;
    Ok(c.cast_into::<PyArrayDyn<T>>()?.readonly())
}

/// `numpy.asarray(obj)`, for the arguments whose dtype the binding inspects itself (it
/// takes 8-bit data as it is, without a cast that would change its values); a failure is a
/// `ValueError` naming `name`.
pub fn asarray<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    numpy(obj.py())?
        .call_method1("asarray", (obj,))
        .map_err(|e| value_error(format!("`{name}` must be a numeric array: {e}")))?
        .cast_into::<PyUntypedArray>()
        .map_err(|e| value_error(format!("`{name}` must be a numeric array: {e}")))
}

/// A real array in the precision the binding computes in: float64 data as it is, anything
/// else as float32 (see [`floats`]).
pub enum Floats<'py> {
    /// float64 input (an array of float64, a list of Python floats).
    F64(PyReadonlyArrayDyn<'py, f64>),
    /// Any other real input (float32, float16, integers, booleans), converted.
    F32(PyReadonlyArrayDyn<'py, f32>),
}

impl Floats<'_> {
    /// The array's shape.
    pub fn shape(&self) -> &[usize] {
        match self {
            Floats::F64(a) => a.shape(),
            Floats::F32(a) => a.shape(),
        }
    }
}

/// `obj` (any real array-like, as [`array`]) as float64 when numpy reads it as float64 (a
/// float64 array, a list of Python floats), as float32 otherwise: for the functions that
/// compute in double precision on double-precision input and in single precision on the
/// rest.
pub fn floats<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<Floats<'py>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        return Ok(Floats::F64(a.readonly()));
    }
    let a = numpy(obj.py())?
        .call_method1("asarray", (obj,))
        .map_err(|e| value_error(format!("`{name}` must be a numeric array: {e}")))?;
    if let Ok(a) = a.cast::<PyArrayDyn<f64>>() {
        return Ok(Floats::F64(a.readonly()));
    }
    Ok(Floats::F32(array(name, &a)?))
}

/// `obj` (any numeric array-like: complex, real, integer or boolean) as a C-contiguous
/// complex128 array, for the functions that take complex values (k-space, MR images); other
/// data is refused ("must be a numeric array"), naming `name`.
pub fn complex<'py>(
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<PyReadonlyArrayDyn<'py, num_complex::Complex64>> {
    type C = num_complex::Complex64;
    if let Ok(a) = obj.cast::<PyArrayDyn<C>>() {
        return Ok(a.readonly());
    }
    let a = asarray(name, obj)?;
    let dtype = a.dtype();
    if !matches!(dtype.kind(), b'b' | b'i' | b'u' | b'f' | b'c') {
        return Err(value_error(format!(
            "`{name}` must be a numeric array, got dtype {dtype}"
        )));
    }
    let np = numpy(obj.py())?;
    let c = np.call_method1("ascontiguousarray", (a, C::get_dtype(obj.py())))?;
    Ok(c.cast_into::<PyArrayDyn<C>>()?.readonly())
}

/// `wscg.IntegerRangeError` (`wscg._checks`), imported once.
fn integer_range_error(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    static CLASS: PyOnceLock<Py<PyType>> = PyOnceLock::new();
    CLASS.import(py, "wscg._checks", "IntegerRangeError")
}

/// `wscg.ArgumentTypeError` (`wscg._checks`), imported once.
fn argument_type_error(py: Python<'_>) -> PyResult<&Bound<'_, PyType>> {
    static CLASS: PyOnceLock<Py<PyType>> = PyOnceLock::new();
    CLASS.import(py, "wscg._checks", "ArgumentTypeError")
}

/// The file path `obj` (a `str` or `os.PathLike`); anything else raises
/// `wscg.ArgumentTypeError` (a `ValueError` and a `TypeError`) naming `name`, as the
/// Python functions' checks do.
pub fn path(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<std::path::PathBuf> {
    obj.extract().or_else(|_| {
        let msg = format!(
            "`{name}` must be a file path (str or os.PathLike), got {}",
            obj.repr()?
        );
        Err(PyErr::from_type(
            argument_type_error(obj.py())?.clone(),
            msg,
        ))
    })
}

/// The integer `obj` (a Python `int` or a numpy integer); anything else raises
/// `wscg.ArgumentTypeError` naming `name`. For arguments whose name in the error differs
/// from the binding's parameter, or that come from a dict.
pub fn integer(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<i128> {
    obj.extract().or_else(|_| {
        let msg = format!("`{name}` must be an integer, got {}", obj.repr()?);
        Err(PyErr::from_type(
            argument_type_error(obj.py())?.clone(),
            msg,
        ))
    })
}

/// `v` as the unsigned integer type `T`, at least `lo`. Outside `T`'s range (negative, or
/// beyond its bits) it raises `wscg.IntegerRangeError` (a `ValueError` and an
/// `OverflowError`) naming `name`, as the Python wrappers do; below `lo` a `ValueError`.
pub fn uint<T>(py: Python<'_>, name: &str, v: i128, lo: T) -> PyResult<T>
where
    T: TryFrom<i128> + PartialOrd + Copy + std::fmt::Display,
{
    let Ok(x) = T::try_from(v) else {
        let bits = 8 * std::mem::size_of::<T>();
        let msg = format!(
            "`{name}` is out of range (got {v}): counts, sizes and seeds are non-negative \
             integers that fit the native parameter ({bits} bits)"
        );
        return Err(PyErr::from_type(integer_range_error(py)?.clone(), msg));
    };
    if x < lo {
        return Err(value_error(format!("`{name}` must be >= {lo}, got {x}")));
    }
    Ok(x)
}

/// `v`, or a `ValueError` naming `name` when it is NaN (infinities pass: the functions that
/// cannot use them say so).
pub fn number(name: &str, v: f64) -> PyResult<f64> {
    if v.is_nan() {
        Err(value_error(format!("`{name}` must be a number, got NaN")))
    } else {
        Ok(v)
    }
}

/// The `N` numbers of `obj` (a tuple, list or array of `N` real numbers, as [`array`]); any
/// other length is a `ValueError` naming `name`.
pub fn numbers<const N: usize>(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<[f64; N]> {
    let a = array::<f64>(name, obj)?;
    let v = crate::convert::values(&a);
    if a.ndim() == 1 && v.len() == N {
        Ok(std::array::from_fn(|i| v[i]))
    } else {
        Err(value_error(format!(
            "`{name}` must be {N} numbers, got shape {}",
            shape_repr(a.shape())
        )))
    }
}

/// The uint8 array `obj` as it is (no cast that would change its values); another dtype is
/// a `ValueError` naming `name`.
pub fn u8s<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArrayDyn<'py, u8>> {
    let a = asarray(name, obj)?;
    match a.cast::<PyArrayDyn<u8>>() {
        Ok(a) => Ok(a.readonly()),
        Err(_) => Err(value_error(format!(
            "`{name}` must be a uint8 array, got dtype {}",
            a.dtype()
        ))),
    }
}

/// The Python type name of `obj`, for messages.
pub fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map_or_else(|_| "?".to_owned(), |n| n.to_string())
}

/// The 3 numbers of `obj`, e.g. a volume's `spacing` `(dz, dy, dx)` (see [`numbers`]).
pub fn triple(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    numbers(name, obj)
}

/// The 2 numbers of `obj`, e.g. a `(lo, hi)` range (see [`numbers`]).
pub fn pair(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(f64, f64)> {
    let [a, b] = numbers(name, obj)?;
    Ok((a, b))
}

/// The non-negative integers of `obj` (any array-like of integers, flattened), e.g. a list of
/// levels; a negative or too large one is `IntegerRangeError` naming `name`.
pub fn counts(py: Python<'_>, name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<usize>> {
    uints(
        py,
        name,
        crate::convert::values(&array::<i64>(name, obj)?)
            .iter()
            .map(|&v| i128::from(v)),
    )
}

/// The integers `v` as counts (see [`uint`]), each named `name` in an error.
pub fn uints(
    py: Python<'_>,
    name: &str,
    v: impl IntoIterator<Item = i128>,
) -> PyResult<Vec<usize>> {
    v.into_iter().map(|c| uint(py, name, c, 0)).collect()
}

/// The 2 non-negative integers of `obj`, e.g. an image shape `(rows, cols)`.
pub fn size2(py: Python<'_>, name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(usize, usize)> {
    match counts(py, name, obj)?[..] {
        [a, b] => Ok((a, b)),
        ref v => Err(value_error(format!(
            "`{name}` must be 2 integers (rows, cols), got {} values",
            v.len()
        ))),
    }
}

/// A per-axis triple in array axis order `(z, y, x)` (a `spacing`, py/API.md) as the
/// libraries' `[x, y, z]`.
pub fn xyz(s: [f64; 3]) -> [f64; 3] {
    [s[2], s[1], s[0]]
}

/// Errors unless every component of the 3-vector `p` is finite.
pub fn finite3(name: &str, p: [f64; 3]) -> PyResult<[f64; 3]> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(p)
    } else {
        Err(value_error(format!("`{name}` must be finite, got {p:?}")))
    }
}

/// Indices (any array-like of integers, or `None` for none) as `usize`; a negative one is a
/// `ValueError` naming `name`.
pub fn indices(name: &str, obj: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<usize>> {
    match obj.filter(|o| !o.is_none()) {
        None => Ok(Vec::new()),
        Some(o) => crate::convert::indices(name, &crate::convert::values(&array::<i64>(name, o)?)),
    }
}

/// The triangle mesh of the `vertices` `(V, 3)` and `faces` `(F, 3)` arguments (array-likes,
/// converted by [`array`] and [`faces`]).
pub fn mesh(vertices: &Bound<'_, PyAny>, faces: &Bound<'_, PyAny>) -> PyResult<wscg_math::TriMesh> {
    crate::convert::mesh_in(&array("vertices", vertices)?, &self::faces(faces)?, None)
}

/// The triangle mesh of the `vertices` `(V, 3)`, `faces` `(F, 3)` and optional per-vertex
/// `colors` `(V, 3)` arguments.
pub fn colored_mesh(
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    colors: Option<&Bound<'_, PyAny>>,
) -> PyResult<wscg_math::TriMesh> {
    let colors = colors
        .filter(|c| !c.is_none())
        .map(|c| array::<f32>("colors", c))
        .transpose()?;
    crate::convert::mesh_in(
        &array("vertices", vertices)?,
        &self::faces(faces)?,
        colors.as_ref(),
    )
}

/// The `faces` argument: vertex indices, an array-like of integers (a float array, even of
/// whole numbers, is refused: it is usually vertices passed in the wrong place; other
/// dtypes as [`array`]).
pub fn faces<'py>(obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArrayDyn<'py, i64>> {
    let a = asarray("faces", obj)?;
    let dtype = a.dtype();
    if dtype.kind() == b'f' {
        return Err(value_error(format!(
            "`faces` must be an integer array, got dtype {dtype}"
        )));
    }
    array("faces", a.as_any())
}

/// `numpy.asarray(obj)` when it holds real numbers (integers or floats); booleans, complex
/// and other data are refused ("must be a real numeric array"), naming `name`. For the
/// bindings that treat integer and float data differently before [`array`] converts it.
pub fn real_array<'py>(
    name: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    let a = asarray(name, obj)?;
    let dtype = a.dtype();
    if !matches!(dtype.kind(), b'i' | b'u' | b'f') {
        return Err(value_error(format!(
            "`{name}` must be a real numeric array, got dtype {dtype}"
        )));
    }
    Ok(a)
}

/// A numpy shape as Python prints it, `(4, 4)` or `(4,)`, for the messages that quote a
/// shape as the Python checks did.
pub fn shape_repr(s: &[usize]) -> String {
    match s {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            s.iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// `v`, which must be finite ("`name` must be finite, got ...").
pub fn finite(name: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(value_error(format!("`{name}` must be finite, got {v}")))
    }
}

/// `v`, which must be finite and `> 0`.
pub fn positive(name: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(value_error(format!(
            "`{name}` must be finite and > 0, got {v}"
        )))
    }
}

/// `v`, which must be finite and `>= 0`.
pub fn non_negative(name: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(value_error(format!(
            "`{name}` must be finite and >= 0, got {v}"
        )))
    }
}
