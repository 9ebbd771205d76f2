//! `wscg._native.math`: bindings of `wscg-math`. The documented public functions are the
//! wrappers in `python/wscg/math.py`, which coerce inputs and call these.

use std::path::PathBuf;

use num_complex::Complex64;
use numpy::ndarray::ArrayView3;
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_math::dense::{self, SymEigen};
use wscg_math::fft::{self, Direction, Norm};
use wscg_math::filter::{box_kernel, gaussian_kernel, separable_plane, Border};
use wscg_math::image::Image;
use wscg_math::io::{PixelDepth, PlyEncoding, RawType};
use wscg_math::mesh::TriMesh;
use wscg_math::metrics::{self, SsimParams};
use wscg_math::resize::{resize as resize_image, Interpolation};
use wscg_math::sparse::{pcg, CsrMatrix, IdentityPrecond, InitialGuess, Jacobi, PcgParams};
use wscg_math::volume::Volume;
use wscg_math::{rng, Error, ImageView};

use crate::convert::{
    self, array, image_dims, mat, mat_out, mesh_in, plane, rows3, same_shape, shape_of, values, Arr,
};
use crate::errors::{value_error, IntoPy};

// ---------------------------------------------------------------- metrics

#[pyfunction]
fn mse(py: Python<'_>, a: PyReadonlyArrayDyn<f64>, b: PyReadonlyArrayDyn<f64>) -> PyResult<f64> {
    same_shape(a.shape(), b.shape())?;
    let (va, vb) = (values(&a), values(&b));
    crate::pool::detach(py, || metrics::mse(&va, &vb)).py_err()
}

#[pyfunction]
fn psnr(
    py: Python<'_>,
    a: PyReadonlyArrayDyn<f64>,
    b: PyReadonlyArrayDyn<f64>,
    data_range: f64,
) -> PyResult<f64> {
    same_shape(a.shape(), b.shape())?;
    let (va, vb) = (values(&a), values(&b));
    crate::pool::detach(py, || metrics::psnr(&va, &vb, data_range)).py_err()
}

#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn ssim(
    py: Python<'_>,
    a: PyReadonlyArrayDyn<f64>,
    b: PyReadonlyArrayDyn<f64>,
    data_range: f64,
    sigma: f64,
    truncate: f64,
    k1: f64,
    k2: f64,
) -> PyResult<f64> {
    same_shape(a.shape(), b.shape())?;
    let (h, w, c) = image_dims("a", a.shape())?;
    let (va, vb) = (values(&a), values(&b));
    let p = SsimParams::default()
        .data_range(data_range)
        .sigma(sigma)
        .truncate(truncate)
        .k1(k1)
        .k2(k2);
    crate::pool::detach(py, || {
        let mut total = 0.0;
        for ch in 0..c {
            let (pa, pb) = (plane(&va, c, ch), plane(&vb, c, ch));
            total += metrics::ssim_plane(
                ImageView::plane(h, w, &pa)?,
                ImageView::plane(h, w, &pb)?,
                &p,
            )?;
        }
        Ok(total / c as f64)
    })
    .py_err()
}

#[pyfunction]
fn dice(py: Python<'_>, a: PyReadonlyArrayDyn<bool>, b: PyReadonlyArrayDyn<bool>) -> PyResult<f64> {
    same_shape(a.shape(), b.shape())?;
    let (va, vb) = (values(&a), values(&b));
    crate::pool::detach(py, || metrics::dice(&va, &vb)).py_err()
}

// ---------------------------------------------------------------- filters and resizing

fn border(mode: &str, cval: f64) -> PyResult<Border> {
    Ok(match mode {
        "reflect" => Border::Reflect,
        "mirror" => Border::Mirror,
        "nearest" => Border::Nearest,
        "wrap" => Border::Wrap,
        "constant" => Border::Constant(cval),
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid mode. Valid modes are 'reflect', 'mirror', \
                 'nearest', 'wrap', 'constant'"
            )))
        }
    })
}

/// Filters every channel of an `(H, W)` or `(H, W, C)` array with the separable kernel `k`.
fn filter_channels<'py>(
    py: Python<'py>,
    img: &PyReadonlyArrayDyn<f64>,
    k: &[f64],
    b: Border,
) -> PyResult<Arr<'py, f64>> {
    let shape = shape_of(img);
    let (h, w, c) = image_dims("image", &shape)?;
    let v = values(img);
    wscg_math::error::ensure_finite("image", &v).py_err()?;
    let out = crate::pool::detach(py, || -> wscg_math::Result<Vec<f64>> {
        let mut out = vec![0.0; v.len()];
        for ch in 0..c {
            let p = plane(&v, c, ch);
            let res = separable_plane(ImageView::plane(h, w, &p)?, k, k, b)?;
            for (o, &r) in out.iter_mut().skip(ch).step_by(c).zip(res.data()) {
                *o = r;
            }
        }
        Ok(out)
    })
    .py_err()?;
    array(py, &shape, out)
}

#[pyfunction]
fn gaussian_filter<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<f64>,
    sigma: f64,
    truncate: f64,
    mode: &str,
    cval: f64,
) -> PyResult<Arr<'py, f64>> {
    let k = gaussian_kernel(sigma, truncate).py_err()?;
    filter_channels(py, &image, &k, border(mode, cval)?)
}

#[pyfunction]
fn box_filter<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<f64>,
    radius: usize,
    mode: &str,
    cval: f64,
) -> PyResult<Arr<'py, f64>> {
    let k = box_kernel(radius).py_err()?;
    filter_channels(py, &image, &k, border(mode, cval)?)
}

fn to_image(name: &str, shape: &[usize], v: &[f64]) -> PyResult<Image<f32>> {
    let (h, w, c) = image_dims(name, shape)?;
    Image::new(h, w, c, v.iter().map(|&x| x as f32).collect()).py_err()
}

fn image_out<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    two_d: bool,
    img: Image<T>,
) -> PyResult<Arr<'py, T>> {
    let (h, w, c) = img.shape();
    let shape: Vec<usize> = if two_d && c == 1 {
        vec![h, w]
    } else {
        vec![h, w, c]
    };
    array(py, &shape, img.into_data())
}

#[pyfunction]
fn resize<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<f64>,
    height: usize,
    width: usize,
    method: &str,
) -> PyResult<Arr<'py, f32>> {
    let m = match method {
        "area" => Interpolation::Area,
        "bilinear" => Interpolation::Bilinear,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid method. Valid methods are 'area', 'bilinear'"
            )))
        }
    };
    let shape = shape_of(&image);
    let img = to_image("image", &shape, &values(&image))?;
    let out = crate::pool::detach(py, || resize_image(&img, height, width, m)).py_err()?;
    image_out(py, shape.len() == 2, out)
}

// ---------------------------------------------------------------- FFT

fn norm(s: &str) -> PyResult<Norm> {
    match s {
        "backward" => Ok(Norm::Backward),
        "ortho" => Ok(Norm::Ortho),
        "forward" => Ok(Norm::Forward),
        other => Err(value_error(format!(
            "{other:?} is not a valid norm. Valid norms are 'backward', 'ortho', 'forward'"
        ))),
    }
}

#[pyfunction]
#[pyo3(signature = (x, axes, inverse, norm_mode))]
fn fftn<'py>(
    py: Python<'py>,
    x: PyReadonlyArrayDyn<Complex64>,
    axes: Option<Vec<usize>>,
    inverse: bool,
    norm_mode: &str,
) -> PyResult<Arr<'py, Complex64>> {
    let shape = shape_of(&x);
    if shape.is_empty() {
        return Err(value_error("`x` must have at least one dimension"));
    }
    let axes = axes.unwrap_or_else(|| (0..shape.len()).collect());
    let n = norm(norm_mode)?;
    let dir = if inverse {
        Direction::Inverse
    } else {
        Direction::Forward
    };
    let mut data = values(&x).into_owned();
    crate::pool::detach(py, || fft::fft_axes(&mut data, &shape, &axes, dir, n)).py_err()?;
    array(py, &shape, data)
}

#[pyfunction]
fn fftshift_c<'py>(
    py: Python<'py>,
    x: PyReadonlyArrayDyn<Complex64>,
    inverse: bool,
) -> PyResult<Arr<'py, Complex64>> {
    let shape = shape_of(&x);
    let v = values(&x);
    let out = crate::pool::detach(py, || {
        if inverse {
            fft::ifftshift(&v, &shape)
        } else {
            fft::fftshift(&v, &shape)
        }
    })
    .py_err()?;
    array(py, &shape, out)
}

#[pyfunction]
fn fftshift_f<'py>(
    py: Python<'py>,
    x: PyReadonlyArrayDyn<f64>,
    inverse: bool,
) -> PyResult<Arr<'py, f64>> {
    let shape = shape_of(&x);
    let v = values(&x);
    let out = crate::pool::detach(py, || {
        if inverse {
            fft::ifftshift(&v, &shape)
        } else {
            fft::fftshift(&v, &shape)
        }
    })
    .py_err()?;
    array(py, &shape, out)
}

#[pyfunction]
fn fftfreq<'py>(py: Python<'py>, n: usize, d: f64) -> PyResult<Arr<'py, f64>> {
    if n == 0 {
        return Err(value_error("`n` must be > 0"));
    }
    wscg_math::error::ensure_positive("d", d).py_err()?;
    array(py, &[n], fft::fftfreq(n, d).py_err()?)
}

// ---------------------------------------------------------------- sparse

#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn cg<'py>(
    py: Python<'py>,
    indptr: PyReadonlyArrayDyn<i64>,
    indices: PyReadonlyArrayDyn<i64>,
    data: PyReadonlyArrayDyn<f64>,
    ncols: usize,
    b: PyReadonlyArrayDyn<f64>,
    x0: Option<PyReadonlyArrayDyn<f64>>,
    tol: f64,
    max_iter: Option<usize>,
    preconditioner: Option<&str>,
) -> PyResult<(Arr<'py, f64>, Bound<'py, PyDict>)> {
    let p = convert::indices("indptr", &values(&indptr))?;
    let c = convert::indices("indices", &values(&indices))?;
    if p.is_empty() {
        return Err(value_error("`indptr` must have length nrows + 1 >= 1"));
    }
    let d = values(&data);
    let a = crate::pool::detach(py, || {
        CsrMatrix::from_csr_arrays(p.len() - 1, ncols, &p, &c, &d)
    })
    .py_err()?;
    let bv = values(&b);
    let x0v = x0.as_ref().map(|x| values(x));
    let guess = match &x0v {
        Some(x) => InitialGuess::Given(x),
        None => InitialGuess::Zero,
    };
    let opts = PcgParams::default().tol(tol).max_iter(max_iter);
    let res = match preconditioner {
        None | Some("none") => {
            crate::pool::detach(py, || pcg(&a, &bv, guess, &IdentityPrecond, &opts))?
        }
        Some("jacobi") => crate::pool::detach(py, || {
            pcg(&a, &bv, guess, &Jacobi::new(&a.diagonal())?, &opts)
        })?,
        Some(other) => {
            return Err(value_error(format!(
                "{other:?} is not a valid preconditioner. Valid values are 'jacobi', None"
            )))
        }
    }
    .py_err()?;
    let info = PyDict::new(py);
    info.set_item("iterations", res.iterations)?;
    info.set_item("relative_residual", res.relative_residual)?;
    info.set_item("converged", res.converged)?;
    let n = res.x.len();
    Ok((array(py, &[n], res.x)?, info))
}

type Csr<'py> = (Arr<'py, i64>, Arr<'py, i64>, Arr<'py, f64>);

#[pyfunction]
fn laplacian_3d(py: Python<'_>, nx: usize, ny: usize, nz: usize) -> PyResult<Csr<'_>> {
    let a = crate::pool::detach(py, || CsrMatrix::laplacian_3d(nx, ny, nz)).py_err()?;
    let p: Vec<i64> = a.indptr().iter().map(|&v| v as i64).collect();
    let c: Vec<i64> = a.indices().iter().map(|&v| v as i64).collect();
    Ok((
        array(py, &[p.len()], p)?,
        array(py, &[c.len()], c)?,
        array(py, &[a.nnz()], a.values().to_vec())?,
    ))
}

// ---------------------------------------------------------------- dense

type Eig<'py> = (Arr<'py, f64>, Arr<'py, f64>);

fn eig_out(py: Python<'_>, e: SymEigen) -> PyResult<Eig<'_>> {
    let n = e.values.len();
    Ok((array(py, &[n], e.values)?, mat_out(py, &e.vectors)?))
}

#[pyfunction]
#[pyo3(signature = (a, k, which))]
fn eigh<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<f64>,
    k: Option<usize>,
    which: &str,
) -> PyResult<Eig<'py>> {
    let m = mat("a", &a)?;
    let e = crate::pool::detach(py, || match (k, which) {
        (None, "smallest") => dense::eigh(m.as_ref()),
        (None, "largest") => {
            dense::eigh(m.as_ref()).and_then(|e| dense::eigh_largest(m.as_ref(), e.values.len()))
        }
        (Some(k), "largest") => dense::eigh_largest(m.as_ref(), k),
        (Some(k), "smallest") => dense::eigh_smallest(m.as_ref(), k),
        (_, other) => Err(Error::invalid(
            "which",
            format!("{other:?} is not valid; use 'largest' or 'smallest'"),
        )),
    })
    .py_err()?;
    eig_out(py, e)
}

#[pyfunction]
fn eigh_generalized<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<f64>,
    b: PyReadonlyArrayDyn<f64>,
) -> PyResult<Eig<'py>> {
    let (ma, mb) = (mat("a", &a)?, mat("b", &b)?);
    let e =
        crate::pool::detach(py, || dense::eigh_generalized(ma.as_ref(), mb.as_ref())).py_err()?;
    eig_out(py, e)
}

#[pyfunction]
fn svd<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<f64>,
) -> PyResult<(Arr<'py, f64>, Arr<'py, f64>, Arr<'py, f64>)> {
    let m = mat("a", &a)?;
    let d = crate::pool::detach(py, || dense::svd(m.as_ref())).py_err()?;
    let vt = d.v.transpose().to_owned();
    let n = d.s.len();
    Ok((mat_out(py, &d.u)?, array(py, &[n], d.s)?, mat_out(py, &vt)?))
}

#[pyfunction]
fn lstsq<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<f64>,
    b: PyReadonlyArrayDyn<f64>,
    rcond: Option<f64>,
) -> PyResult<Arr<'py, f64>> {
    let (ma, mb) = (mat("a", &a)?, mat("b", &b)?);
    let x = crate::pool::detach(py, || dense::lstsq(ma.as_ref(), mb.as_ref(), rcond)).py_err()?;
    mat_out(py, &x)
}

// ---------------------------------------------------------------- random numbers

#[pyfunction]
fn normal(py: Python<'_>, seed: u64, n: usize, mean: f64, std: f64) -> PyResult<Arr<'_, f64>> {
    let v = crate::pool::detach(py, || rng::normal_vec(seed, n, mean, std)).py_err()?;
    array(py, &[n], v)
}

#[pyfunction]
fn uniform(py: Python<'_>, seed: u64, n: usize, low: f64, high: f64) -> PyResult<Arr<'_, f64>> {
    let v = crate::pool::detach(py, || rng::uniform_vec(seed, n, low, high)).py_err()?;
    array(py, &[n], v)
}

#[pyfunction]
fn permutation(py: Python<'_>, seed: u64, n: usize) -> PyResult<Arr<'_, i64>> {
    let v: Vec<i64> = crate::pool::detach(py, || {
        rng::permutation(seed, n).map(|p| p.into_iter().map(|i| i as i64).collect())
    })
    .py_err()?;
    array(py, &[n], v)
}

// ---------------------------------------------------------------- images

#[pyfunction]
fn load_image(py: Python<'_>, path: PathBuf) -> PyResult<Arr<'_, f32>> {
    let img = crate::pool::detach(py, || Image::load(&path)).py_err()?;
    image_out(py, true, img)
}

#[pyfunction]
fn save_image(
    py: Python<'_>,
    path: PathBuf,
    image: PyReadonlyArrayDyn<f64>,
    bit_depth: Option<u32>,
) -> PyResult<()> {
    let img = to_image("image", image.shape(), &values(&image))?;
    let depth = match bit_depth {
        None => None,
        Some(8) => Some(PixelDepth::U8),
        Some(16) => Some(PixelDepth::U16),
        Some(32) => Some(PixelDepth::F32),
        Some(other) => {
            return Err(value_error(format!(
                "bit_depth {other} is not valid. Valid values are 8, 16, 32"
            )))
        }
    };
    crate::pool::detach(py, || match depth {
        None => img.save(&path),
        Some(d) => img.save_with_depth(&path, d),
    })
    .py_err()
}

/// The EXIF exposure settings of an image file: `(exposure_time, f_number, iso)`, each
/// `None` when the block lacks it.
#[pyfunction]
fn read_exif(py: Python<'_>, path: PathBuf) -> PyResult<(Option<f64>, Option<f64>, Option<f64>)> {
    let e = crate::pool::detach(py, || wscg_math::io::exif::load_exif(&path)).py_err()?;
    Ok((e.exposure_time, e.f_number, e.iso))
}

// ---------------------------------------------------------------- volumes

/// Python spacing (dz, dy, dx) to Rust spacing [sx, sy, sz].
fn spacing_xyz(s: (f64, f64, f64)) -> [f64; 3] {
    [s.2, s.1, s.0]
}

/// A loaded volume as Python gets it: the array `[z, y, x]`, the spacing `(dz, dy, dx)` and
/// the file's voxel-to-world affine (RAS+ mm, rows x, y, z of the 4 x 4 matrix acting on
/// `(i, j, k, 1)`), `None` when the file has none.
type VolumeOut<'py> = (Arr<'py, f32>, (f64, f64, f64), Option<[[f64; 4]; 3]>);

fn volume_out(py: Python<'_>, v: Volume<f32>) -> PyResult<VolumeOut<'_>> {
    let [sx, sy, sz] = v.spacing();
    let [nx, ny, nz] = v.dims();
    let affine = v.affine();
    let data = v.into_data();
    Ok((array(py, &[nz, ny, nx], data)?, (sz, sy, sx), affine))
}

#[pyfunction]
#[pyo3(signature = (path, spacing, series=None))]
fn load_volume(
    py: Python<'_>,
    path: PathBuf,
    spacing: Option<(f64, f64, f64)>,
    series: Option<String>,
) -> PyResult<VolumeOut<'_>> {
    let v = crate::pool::detach(py, || match series {
        Some(uid) => {
            let params = wscg_math::io::dicom::DicomParams::default().series(uid);
            let mut v = Volume::read_dicom_with(&path, &params)?;
            if let Some(s) = spacing {
                v.set_spacing(spacing_xyz(s))?;
            }
            Ok(v)
        }
        None => Volume::read(&path, spacing.map(spacing_xyz)),
    })
    .py_err()?;
    volume_out(py, v)
}

#[pyfunction]
fn load_raw_volume<'py>(
    py: Python<'py>,
    path: PathBuf,
    shape: (usize, usize, usize),
    dtype: &str,
    spacing: (f64, f64, f64),
) -> PyResult<VolumeOut<'py>> {
    let t = dtype.parse::<RawType>().py_err()?;
    let dims = [shape.2, shape.1, shape.0];
    let v = crate::pool::detach(py, || {
        Volume::read_raw(&path, dims, spacing_xyz(spacing), t)
    })
    .py_err()?;
    volume_out(py, v)
}

#[pyfunction]
#[pyo3(signature = (path, volume, spacing, affine=None))]
fn save_volume(
    py: Python<'_>,
    path: PathBuf,
    volume: PyReadonlyArrayDyn<f32>,
    spacing: (f64, f64, f64),
    affine: Option<[[f64; 4]; 3]>,
) -> PyResult<()> {
    let shape = volume.shape().to_vec();
    if shape.len() != 3 {
        return Err(value_error(format!(
            "`volume` must be a 3-D array indexed [z, y, x], got shape {shape:?}"
        )));
    }
    let data = values(&volume);
    let view = ArrayView3::from_shape((shape[0], shape[1], shape[2]), &data)
        .map_err(|e| value_error(e.to_string()))?;
    let name = path.to_string_lossy().to_ascii_lowercase();
    crate::pool::detach(py, || {
        let mut vol = Volume::from_zyx(view, spacing_xyz(spacing))?;
        vol.set_affine(affine)?;
        if name.ends_with(".nii") || name.ends_with(".nii.gz") {
            vol.write_nifti(&path)
        } else if name.ends_with(".npy") {
            vol.write_npy(&path)
        } else if name.ends_with(".raw") {
            vol.write_raw_f32_le(&path)
        } else {
            Err(Error::UnsupportedFormat(format!(
                "{}: volumes are written as .nii, .nii.gz, .npy or .raw",
                path.display()
            )))
        }
    })
    .py_err()
}

// ---------------------------------------------------------------- meshes

#[pyfunction]
fn load_mesh(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let m = crate::pool::detach(py, || TriMesh::read(&path)).py_err()?;
    let d = PyDict::new(py);
    let nv = m.positions.len();
    d.set_item("vertices", array(py, &[nv, 3], m.positions.concat())?)?;
    let faces: Vec<i64> = m.faces.iter().flatten().map(|&i| i as i64).collect();
    d.set_item("faces", array(py, &[m.faces.len(), 3], faces)?)?;
    if let Some(n) = m.normals {
        d.set_item("normals", array(py, &[nv, 3], n.concat())?)?;
    }
    if let Some(c) = m.colors {
        d.set_item("colors", array(py, &[nv, 3], c.concat())?)?;
    }
    Ok(d)
}

#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn save_mesh(
    py: Python<'_>,
    path: PathBuf,
    vertices: PyReadonlyArrayDyn<f64>,
    faces: PyReadonlyArrayDyn<i64>,
    colors: Option<PyReadonlyArrayDyn<f32>>,
    normals: Option<PyReadonlyArrayDyn<f64>>,
    binary: bool,
) -> PyResult<()> {
    let mesh = mesh_in(&vertices, &faces, colors.as_ref())?;
    let normals = normals
        .map(|n| rows3("normals", &values(&n), n.shape()))
        .transpose()?;
    let is_ply = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ply"));
    crate::pool::detach(py, || {
        let mesh = match normals {
            Some(n) => mesh.with_normals(n)?,
            None => mesh,
        };
        if is_ply && !binary {
            mesh.write_ply(&path, PlyEncoding::Ascii)
        } else {
            mesh.write(&path)
        }
    })
    .py_err()
}

/// Writes `data` to `path` atomically (`wscg_math::io::atomic`): the writer of the files the
/// Python package writes itself (model JSON), so that they too leave no truncated file.
#[pyfunction]
fn write_file(py: Python<'_>, path: PathBuf, data: Vec<u8>) -> PyResult<()> {
    crate::pool::detach(py, || wscg_math::io::atomic::write(&path, &data)).py_err()
}

/// Multi-level periodized Daubechies wavelet transform (Mallat layout), or its inverse.
#[pyfunction]
fn wavelet2<'py>(
    py: Python<'py>,
    x: PyReadonlyArrayDyn<f64>,
    order: usize,
    levels: usize,
    inverse: bool,
) -> PyResult<Arr<'py, f64>> {
    use wscg_math::wavelet::{Daubechies, Wavelet2};
    let (r, c) = crate::convert::dims2("x", &x)?;
    let w = Wavelet2::new(r, c, Daubechies::new(order).py_err()?, levels).py_err()?;
    let v = values(&x);
    let mut out = vec![0.0; r * c];
    crate::pool::detach(py, || {
        if inverse {
            w.inverse(&v, &mut out)
        } else {
            w.forward(&v, &mut out)
        }
    })?;
    array(py, &[r, c], out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(wavelet2, m)?)?;
    m.add_function(wrap_pyfunction!(mse, m)?)?;
    m.add_function(wrap_pyfunction!(psnr, m)?)?;
    m.add_function(wrap_pyfunction!(ssim, m)?)?;
    m.add_function(wrap_pyfunction!(dice, m)?)?;
    m.add_function(wrap_pyfunction!(gaussian_filter, m)?)?;
    m.add_function(wrap_pyfunction!(box_filter, m)?)?;
    m.add_function(wrap_pyfunction!(resize, m)?)?;
    m.add_function(wrap_pyfunction!(fftn, m)?)?;
    m.add_function(wrap_pyfunction!(fftshift_c, m)?)?;
    m.add_function(wrap_pyfunction!(fftshift_f, m)?)?;
    m.add_function(wrap_pyfunction!(fftfreq, m)?)?;
    m.add_function(wrap_pyfunction!(cg, m)?)?;
    m.add_function(wrap_pyfunction!(laplacian_3d, m)?)?;
    m.add_function(wrap_pyfunction!(eigh, m)?)?;
    m.add_function(wrap_pyfunction!(eigh_generalized, m)?)?;
    m.add_function(wrap_pyfunction!(svd, m)?)?;
    m.add_function(wrap_pyfunction!(lstsq, m)?)?;
    m.add_function(wrap_pyfunction!(normal, m)?)?;
    m.add_function(wrap_pyfunction!(uniform, m)?)?;
    m.add_function(wrap_pyfunction!(permutation, m)?)?;
    m.add_function(wrap_pyfunction!(load_image, m)?)?;
    m.add_function(wrap_pyfunction!(save_image, m)?)?;
    m.add_function(wrap_pyfunction!(read_exif, m)?)?;
    m.add_function(wrap_pyfunction!(load_volume, m)?)?;
    m.add_function(wrap_pyfunction!(load_raw_volume, m)?)?;
    m.add_function(wrap_pyfunction!(save_volume, m)?)?;
    m.add_function(wrap_pyfunction!(load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(save_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_file, m)?)?;
    Ok(())
}
