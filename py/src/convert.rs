//! numpy <-> Rust conversions shared by the binding modules.
//!
//! The Python wrappers pass C-contiguous arrays of the expected dtype, so the native side
//! borrows their memory without copying; a non-contiguous array (from a direct call to the
//! native module) is copied.

use std::borrow::Cow;

use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{
    Element, IntoPyArray, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use wscg_math::Image;

use crate::errors::value_error;

/// A numpy array bound to the interpreter.
pub type Arr<'py, T> = Bound<'py, PyArrayDyn<T>>;

/// The array's values in C order, borrowed when C-contiguous and aligned, copied otherwise
/// (a Fortran-ordered array is contiguous too, but its memory is not in C order). An array
/// whose data is not aligned for `T` (numpy allows it: `np.frombuffer` at an odd offset, or
/// the arrays that Dask and pickle protocol 5 rebuild on a buffer received from another
/// process) is copied element by element with unaligned reads.
pub fn values<'a, T: Element + Copy>(a: &'a PyReadonlyArrayDyn<'_, T>) -> Cow<'a, [T]> {
    match a.as_slice() {
        Ok(s) if a.is_c_contiguous() => Cow::Borrowed(s),
        _ if a.is_aligned() => Cow::Owned(a.as_array().iter().copied().collect()),
        _ => Cow::Owned(unaligned_values(a)),
    }
}

/// The values of an array whose data is not aligned for `T`, in C order.
fn unaligned_values<T: Element + Copy>(a: &PyReadonlyArrayDyn<'_, T>) -> Vec<T> {
    let shape = a.shape();
    let strides = a.strides();
    let base = a.data().cast::<u8>().cast_const();
    let n = a.len();
    let mut out = Vec::with_capacity(n);
    let mut index = vec![0usize; shape.len()];
    for _ in 0..n {
        let offset: isize = index
            .iter()
            .zip(strides)
            .map(|(&i, &s)| i as isize * s)
            .sum();
        // SAFETY: `index` stays inside `shape`, so `offset` (numpy's byte strides) addresses
        // an element of the array, which the borrow keeps alive and unchanged; the read
        // makes no assumption on alignment, and `T: Copy` is a plain value.
        out.push(unsafe { std::ptr::read_unaligned(base.offset(offset).cast::<T>()) });
        for d in (0..shape.len()).rev() {
            index[d] += 1;
            if index[d] < shape[d] {
                break;
            }
            index[d] = 0;
        }
    }
    out
}

/// A new numpy array of `shape` holding `data` (C order).
pub fn array<'py, T: Element>(
    py: Python<'py>,
    shape: &[usize],
    data: Vec<T>,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let a = ArrayD::from_shape_vec(IxDyn(shape), data)
        .map_err(|e| value_error(format!("internal shape error: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// `v` as a 1-D array.
pub fn vector<T: Element>(py: Python<'_>, v: Vec<T>) -> PyResult<Bound<'_, PyArrayDyn<T>>> {
    let n = v.len();
    array(py, &[n], v)
}

/// Indices as a 1-D int64 array.
pub fn index_vector(
    py: Python<'_>,
    v: impl IntoIterator<Item = usize>,
) -> PyResult<Bound<'_, PyArrayDyn<i64>>> {
    vector(py, v.into_iter().map(|i| i as i64).collect())
}

/// An image as an array of `(H, W)` when `flat` and single-channel, `(H, W, C)` otherwise.
pub fn image_array<'py, T: Element + Copy>(
    py: Python<'py>,
    img: Image<T>,
    flat: bool,
) -> PyResult<Arr<'py, T>> {
    let (h, w, c) = img.shape();
    if flat && c == 1 {
        array(py, &[h, w], img.into_data())
    } else {
        array(py, &[h, w, c], img.into_data())
    }
}

/// `(height, width, channels)` of an image array of shape `(H, W)` or `(H, W, C)`.
pub fn image_dims(name: &str, shape: &[usize]) -> PyResult<(usize, usize, usize)> {
    match *shape {
        [h, w] => Ok((h, w, 1)),
        [h, w, c] => Ok((h, w, c)),
        _ => Err(value_error(format!(
            "`{name}` must be a 2-D (H, W) or 3-D (H, W, C) array, got shape {shape:?}"
        ))),
    }
}

/// Errors unless the two arrays have the same shape.
pub fn same_shape(a: &[usize], b: &[usize]) -> PyResult<()> {
    if a == b {
        Ok(())
    } else {
        Err(value_error(format!(
            "shape mismatch: inputs have shapes {a:?} and {b:?}"
        )))
    }
}

/// Channel `c` of interleaved `(h, w, channels)` data as a plane.
pub fn plane(data: &[f64], channels: usize, c: usize) -> Vec<f64> {
    data.iter().skip(c).step_by(channels).copied().collect()
}

/// Shape of a readonly array as a vector.
pub fn shape_of<T: Element>(a: &PyReadonlyArrayDyn<'_, T>) -> Vec<usize> {
    a.shape().to_vec()
}

/// A 2-D float64 array as a faer matrix (copied, by a parallel blocked transpose from C order,
/// in the process's pool).
pub fn mat(name: &str, a: &PyReadonlyArrayDyn<f64>) -> PyResult<faer::Mat<f64>> {
    let (r, c) = dims2(name, a)?;
    let v = values(a);
    crate::pool::detach(a.py(), || wscg_math::dense::from_row_major(&v, r, c))
}

/// A faer matrix as a new 2-D numpy array.
pub fn mat_out<'py>(py: Python<'py>, m: &faer::Mat<f64>) -> PyResult<Arr<'py, f64>> {
    let (r, c) = (m.nrows(), m.ncols());
    let mut v = Vec::with_capacity(r * c);
    for i in 0..r {
        for j in 0..c {
            v.push(m[(i, j)]);
        }
    }
    array(py, &[r, c], v)
}

/// `(rows, cols)` of a 2-D array.
pub fn dims2<T: Element>(name: &str, a: &PyReadonlyArrayDyn<'_, T>) -> PyResult<(usize, usize)> {
    match *a.shape() {
        [r, c] => Ok((r, c)),
        ref s => Err(value_error(format!(
            "`{name}` must be a 2-D array, got shape {s:?}"
        ))),
    }
}

/// The per-block results of `f`, a row-wise map (every output row depends on its input row
/// only: projections, predictions), over the 2-D float64 array `a`, in the process's pool
/// with the GIL released.
/// The rows go through one reused column-major buffer
/// ([`wscg_math::dense::map_row_blocks`]), so a large input is never copied whole.
pub fn row_blocks<T: Send>(
    py: Python<'_>,
    name: &str,
    a: &PyReadonlyArrayDyn<f64>,
    f: impl Fn(faer::MatRef<'_, f64>) -> wscg_math::Result<T> + Send + Sync,
) -> PyResult<Vec<T>> {
    use crate::errors::IntoPy;
    let (r, c) = dims2(name, a)?;
    let v = values(a);
    crate::pool::detach(py, || wscg_math::dense::map_row_blocks(&v, r, c, &f)).py_err()
}

/// [`row_blocks`] for a map to a matrix: the stacked result as a new `(rows, k)` array.
pub fn mat_map<'py>(
    py: Python<'py>,
    name: &str,
    a: &PyReadonlyArrayDyn<f64>,
    f: impl Fn(faer::MatRef<'_, f64>) -> wscg_math::Result<faer::Mat<f64>> + Send + Sync,
) -> PyResult<Arr<'py, f64>> {
    let blocks = row_blocks(py, name, a, f)?;
    let k = blocks.first().map_or(0, |b| b.ncols());
    let rows: usize = blocks.iter().map(|b| b.nrows()).sum();
    let mut v = Vec::with_capacity(rows * k);
    for b in &blocks {
        for i in 0..b.nrows() {
            v.extend((0..k).map(|j| b[(i, j)]));
        }
    }
    array(py, &[rows, k], v)
}

/// Rows of an `(N, 3)` array.
pub fn rows3<T: Copy>(name: &str, a: &[T], shape: &[usize]) -> PyResult<Vec<[T; 3]>> {
    if shape.len() != 2 || shape[1] != 3 {
        return Err(value_error(format!(
            "`{name}` must have shape (N, 3), got {shape:?}"
        )));
    }
    Ok(a.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// Vertex indices of an `(F, 3)` face array; a negative or too large index is a
/// `ValueError`.
pub fn faces_u32(faces: &PyReadonlyArrayDyn<i64>) -> PyResult<Vec<[u32; 3]>> {
    rows3("faces", &values(faces), faces.shape())?
        .iter()
        .map(|f| {
            let conv = |i: i64| {
                u32::try_from(i)
                    .map_err(|_| value_error(format!("`faces` holds an invalid index {i}")))
            };
            Ok([conv(f[0])?, conv(f[1])?, conv(f[2])?])
        })
        .collect()
}

/// A triangle mesh from `(V, 3)` vertices, `(F, 3)` faces and optional `(V, 3)` colours in
/// `[0, 1]` (checked in parallel, in the process's pool).
pub fn mesh_in(
    vertices: &PyReadonlyArrayDyn<f64>,
    faces: &PyReadonlyArrayDyn<i64>,
    colors: Option<&PyReadonlyArrayDyn<f32>>,
) -> PyResult<wscg_math::TriMesh> {
    use crate::errors::IntoPy;
    let pos = rows3("vertices", &values(vertices), vertices.shape())?;
    let faces = faces_u32(faces)?;
    let colors = colors
        .map(|c| rows3("colors", &values(c), c.shape()))
        .transpose()?;
    crate::pool::detach(vertices.py(), || {
        let mesh = wscg_math::TriMesh::new(pos, faces)?;
        match colors {
            Some(c) => mesh.with_colors(c),
            None => Ok(mesh),
        }
    })
    .py_err()
}

/// A 1-D int64 label array as `u32` labels.
pub fn labels_from(name: &str, a: &PyReadonlyArrayDyn<i64>) -> PyResult<Vec<u32>> {
    if a.shape().len() != 1 {
        return Err(value_error(format!(
            "`{name}` must be a 1-D array, got shape {:?}",
            a.shape()
        )));
    }
    values(a)
        .iter()
        .map(|&v| {
            u32::try_from(v)
                .map_err(|_| value_error(format!("`{name}` holds {v}, not a label in 0..2^32")))
        })
        .collect()
}

/// The value of the option named `s` among `options`, or a `ValueError` listing them.
pub fn choice<T: Copy>(name: &str, s: &str, options: &[(&str, T)]) -> PyResult<T> {
    options
        .iter()
        .find(|(o, _)| *o == s)
        .map(|&(_, v)| v)
        .ok_or_else(|| {
            let names: Vec<String> = options.iter().map(|(o, _)| format!("'{o}'")).collect();
            value_error(format!(
                "`{name}` must be one of {}, got {s:?}",
                names.join(", ")
            ))
        })
}

/// `v` as an index, or a `ValueError` naming `name` when it is negative (for arguments taken
/// as `i64` so that a negative index is a `ValueError`, not the conversion's `OverflowError`).
pub fn index(name: &str, v: i64) -> PyResult<usize> {
    usize::try_from(v).map_err(|_| value_error(format!("`{name}` must be an index >= 0, got {v}")))
}

/// [`index`] of every value of `v`.
pub fn indices(name: &str, v: &[i64]) -> PyResult<Vec<usize>> {
    v.iter().map(|&i| index(name, i)).collect()
}
