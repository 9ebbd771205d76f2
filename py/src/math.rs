//! `wscg.math`'s functions: bindings of `wscg-math` that Python calls directly, re-exported by
//! `python/wscg/math.py` (which holds the module's documentation and the functions that build
//! its result classes: `cg`, `solve_cg`, `load_exif`, `load_volume`, `load_raw_volume`,
//! `load_mesh`, which call the private bindings at the end of this file). Arguments are
//! converted and checked by [`crate::args`]: array-likes of any real dtype, counts and seeds
//! as Python ints.

use std::path::PathBuf;

use num_complex::Complex64;
use numpy::ndarray::ArrayView3;
use numpy::{
    PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
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

use crate::args::{self, number, uint};
use crate::convert::{
    self, array, choice, image_dims, mat, mat_out, plane, rows3, same_shape, shape_of, values, Arr,
};
use crate::errors::{value_error, IntoPy};

// ---------------------------------------------------------------- metrics

/// The two arrays `a` and `b` of a metric, as float64, of the same shape.
fn pair<'py>(
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<(PyReadonlyArrayDyn<'py, f64>, PyReadonlyArrayDyn<'py, f64>)> {
    let (a, b) = (args::array::<f64>("a", a)?, args::array::<f64>("b", b)?);
    same_shape(a.shape(), b.shape())?;
    Ok((a, b))
}

/// Mean squared error of two arrays of the same shape.
///
/// Parameters
/// ----------
/// a, b : array_like
///     Arrays of equal shape (any numeric dtype).
///
/// Returns
/// -------
/// float
///     ``mean((a - b) ** 2)``.
///
/// Raises
/// ------
/// ValueError
///     Shapes differ, arrays are empty or hold NaN/inf.
///
/// Examples
/// --------
/// >>> mse([0.0, 0.0], [3.0, 4.0])
/// 12.5
#[pyfunction]
fn mse(py: Python<'_>, a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (a, b) = pair(a, b)?;
    let (va, vb) = (values(&a), values(&b));
    crate::pool::detach(py, || metrics::mse(&va, &vb)).py_err()
}

/// Root mean squared error ``sqrt(mse(a, b))``.
///
/// Parameters
/// ----------
/// a, b : array_like
///     Arrays of equal shape.
///
/// Returns
/// -------
/// float
///
/// Raises
/// ------
/// ValueError
///     As :func:`mse`.
#[pyfunction]
fn rmse(py: Python<'_>, a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<f64> {
    mse(py, a, b).map(f64::sqrt)
}

/// Peak signal-to-noise ratio in dB, ``10 log10(data_range**2 / mse)``.
///
/// Parameters
/// ----------
/// a, b : array_like
///     Reference and test arrays of equal shape.
/// data_range : float, default 1.0
///     Dynamic range of the data (1 for images in [0, 1], 255 for 8-bit values).
///
/// Returns
/// -------
/// float
///     PSNR in dB; ``inf`` for identical inputs.
///
/// Raises
/// ------
/// ValueError
///     Shapes differ, empty input, NaN/inf, ``data_range <= 0``.
///
/// Notes
/// -----
/// Equals ``skimage.metrics.peak_signal_noise_ratio(a, b, data_range=data_range)``.
#[pyfunction]
#[pyo3(signature = (a, b, data_range=1.0))]
fn psnr(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    data_range: f64,
) -> PyResult<f64> {
    let (a, b) = pair(a, b)?;
    let (va, vb) = (values(&a), values(&b));
    crate::pool::detach(py, || metrics::psnr(&va, &vb, data_range)).py_err()
}

/// Mean structural similarity (SSIM) of two images.
///
/// Parameters
/// ----------
/// a, b : array_like
///     Images of equal shape, ``(H, W)`` or ``(H, W, C)`` (channels are averaged).
/// data_range : float, default 1.0
///     Dynamic range ``R`` of the data.
/// sigma : float, default 1.5
///     Standard deviation of the Gaussian window.
/// truncate : float, default 3.5
///     Window radius in standard deviations (11 x 11 at sigma 1.5).
/// k1, k2 : float, default 0.01, 0.03
///     Stabilising constants, ``C1 = (k1 R)^2``, ``C2 = (k2 R)^2``.
///
/// Returns
/// -------
/// float
///     Mean SSIM over the image, cropped by the window radius.
///
/// Raises
/// ------
/// ValueError
///     Shapes differ, images smaller than the window, NaN/inf, bad parameters.
///
/// Notes
/// -----
/// SSIM (eq. 13 of the reference) is computed from Gaussian-weighted local means,
/// variances and covariance with ``reflect`` borders. The result equals
/// ``skimage.metrics.structural_similarity(a, b, data_range=R, gaussian_weights=True,
/// sigma=1.5, use_sample_covariance=False, channel_axis=-1 for colour)``.
///
/// References
/// ----------
/// Z. Wang, A. C. Bovik, H. R. Sheikh, E. P. Simoncelli, "Image quality assessment: from
/// error visibility to structural similarity", IEEE TIP 13(4), 2004,
/// :doi:`10.1109/TIP.2003.819861`.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> img = np.linspace(0, 1, 64 * 64).reshape(64, 64)
/// >>> round(ssim(img, img), 6)
/// 1.0
#[pyfunction]
#[pyo3(signature = (a, b, data_range=1.0, sigma=1.5, truncate=3.5, k1=0.01, k2=0.03))]
#[allow(clippy::too_many_arguments)]
fn ssim(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    data_range: f64,
    sigma: f64,
    truncate: f64,
    k1: f64,
    k2: f64,
) -> PyResult<f64> {
    let (a, b) = pair(a, b)?;
    let (h, w, c) = image_dims("a", a.shape())?;
    let (va, vb) = (values(&a), values(&b));
    let p = SsimParams::default()
        .data_range(number("data_range", data_range)?)
        .sigma(number("sigma", sigma)?)
        .truncate(number("truncate", truncate)?)
        .k1(number("k1", k1)?)
        .k2(number("k2", k2)?);
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

/// The mask argument `name` of [`dice`] as booleans with its shape: a boolean mask, a
/// numeric one (float masks hold only 0 and 1), or with `label` the entries of a label map
/// equal to it.
fn mask(
    name: &str,
    obj: &Bound<'_, PyAny>,
    label: Option<i64>,
) -> PyResult<(Vec<usize>, Vec<bool>)> {
    let a = args::asarray(name, obj)?;
    let kind = a.dtype().kind();
    if !matches!(kind, b'b' | b'i' | b'u' | b'f') {
        return Err(value_error(format!(
            "`{name}` must be a boolean mask or a label map, got dtype {}",
            a.dtype()
        )));
    }
    if a.ndim() == 0 {
        return Err(value_error(format!(
            "`{name}` must be a mask array, got a scalar {}",
            a.repr()?
        )));
    }
    if kind == b'b' && label.is_none() {
        let m = args::array::<bool>(name, a.as_any())?;
        return Ok((m.shape().to_vec(), values(&m).into_owned()));
    }
    let m = args::array::<f64>(name, a.as_any())?;
    let v = values(&m);
    if kind == b'f' {
        if let Some(i) = v.iter().position(|x| !x.is_finite()) {
            return Err(value_error(format!(
                "`{name}` contains a non-finite value (NaN or infinity) at flat index {i}"
            )));
        }
        if label.is_none() && v.iter().any(|&x| x != 0.0 && x != 1.0) {
            return Err(value_error(format!(
                "`{name}` holds values other than 0 and 1; pass a boolean mask or give \
                 `label` to compare label maps"
            )));
        }
    }
    let out = match label {
        Some(l) => v.iter().map(|&x| x == l as f64).collect(),
        None => v.iter().map(|&x| x != 0.0).collect(),
    };
    Ok((m.shape().to_vec(), out))
}

/// Dice coefficient ``2 |A & B| / (|A| + |B|)`` of two masks.
///
/// Parameters
/// ----------
/// a, b : array_like
///     Boolean masks of equal shape, or label maps when ``label`` is given.
/// label : int, optional
///     Compare the regions ``a == label`` and ``b == label``.
///
/// Returns
/// -------
/// float
///     In [0, 1]; two empty masks give 1.
///
/// Raises
/// ------
/// ValueError
///     Shapes differ or the masks are empty arrays.
#[pyfunction]
#[pyo3(signature = (a, b, label=None))]
fn dice(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    label: Option<i64>,
) -> PyResult<f64> {
    let (sa, ma) = mask("a", a, label)?;
    let (sb, mb) = mask("b", b, label)?;
    same_shape(&sa, &sb)?;
    crate::pool::detach(py, || metrics::dice(&ma, &mb)).py_err()
}

// ---------------------------------------------------------------- filters and resizing

/// The border handling named by `mode`, `cval` outside the image for `"constant"`.
fn border(mode: &str, cval: f64) -> PyResult<Border> {
    let cval = number("cval", cval)?;
    choice(
        "mode",
        mode,
        &[
            ("reflect", Border::Reflect),
            ("mirror", Border::Mirror),
            ("nearest", Border::Nearest),
            ("wrap", Border::Wrap),
            ("constant", Border::Constant(cval)),
        ],
    )
}

/// Filters every channel of the `(H, W)` or `(H, W, C)` argument `image` with the separable
/// kernel `k`.
fn filter_channels<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    k: &[f64],
    b: Border,
) -> PyResult<Arr<'py, f64>> {
    let img = args::array::<f64>("image", image)?;
    let shape = shape_of(&img);
    let (h, w, c) = image_dims("image", &shape)?;
    let v = values(&img);
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

/// Gaussian blur of every channel of an image.
///
/// Parameters
/// ----------
/// image : array_like
///     ``(H, W)`` or ``(H, W, C)``; channels are filtered independently.
/// sigma : float
///     Standard deviation in pixels (> 0).
/// truncate : float, default 4.0
///     Kernel radius ``int(truncate * sigma + 0.5)``.
/// mode : {'reflect', 'mirror', 'nearest', 'wrap', 'constant'}, default 'reflect'
///     Border handling, as in ``scipy.ndimage``.
/// cval : float, default 0.0
///     Value outside the image for ``mode='constant'``.
///
/// Returns
/// -------
/// ndarray of float64, same shape as ``image``.
///
/// Raises
/// ------
/// ValueError
///     Bad shape, NaN/inf, ``sigma <= 0``, unknown ``mode``.
///
/// Notes
/// -----
/// Equals ``scipy.ndimage.gaussian_filter(image, sigma=(sigma, sigma[, 0]), truncate=...,
/// mode=..., cval=...)``.
#[pyfunction]
#[pyo3(signature = (image, sigma, truncate=4.0, mode="reflect", cval=0.0))]
fn gaussian_filter<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    sigma: f64,
    truncate: f64,
    mode: &str,
    cval: f64,
) -> PyResult<Arr<'py, f64>> {
    let b = border(mode, cval)?;
    let k = gaussian_kernel(number("sigma", sigma)?, number("truncate", truncate)?).py_err()?;
    filter_channels(py, image, &k, b)
}

/// Mean over a ``(2 radius + 1)^2`` window of every channel.
///
/// Parameters
/// ----------
/// image : array_like
///     ``(H, W)`` or ``(H, W, C)``.
/// radius : int
///     Window radius (>= 0).
/// mode : {'reflect', 'mirror', 'nearest', 'wrap', 'constant'}, default 'reflect'
///     Border handling.
/// cval : float, default 0.0
///     Value outside for ``mode='constant'``.
///
/// Returns
/// -------
/// ndarray of float64, same shape as ``image``.
///
/// Raises
/// ------
/// ValueError
///     Bad shape, NaN/inf, negative radius, unknown ``mode``.
///
/// Notes
/// -----
/// Equals ``scipy.ndimage.uniform_filter(image, size=(2r+1, 2r+1[, 1]), mode=...)``.
#[pyfunction]
#[pyo3(signature = (image, radius, mode="reflect", cval=0.0))]
fn box_filter<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    radius: i128,
    mode: &str,
    cval: f64,
) -> PyResult<Arr<'py, f64>> {
    let radius: usize = uint(py, "radius", radius, 0)?;
    let b = border(mode, cval)?;
    let k = box_kernel(radius).py_err()?;
    filter_channels(py, image, &k, b)
}

/// An image of `f32` from its values `v` in C order and its array shape.
fn to_image(name: &str, shape: &[usize], v: Vec<f32>) -> PyResult<Image<f32>> {
    let (h, w, c) = image_dims(name, shape)?;
    Image::new(h, w, c, v).py_err()
}

/// Resizes an image to ``shape = (height, width)``.
///
/// Parameters
/// ----------
/// image : array_like
///     ``(H, W)`` or ``(H, W, C)``.
/// shape : (int, int)
///     Output height and width (> 0).
/// method : {'area', 'bilinear'}, default 'area'
///     ``'area'``: exact area-weighted mean of the covered input pixels (block mean for
///     integer factors, OpenCV's ``INTER_AREA`` when downscaling). ``'bilinear'``:
///     interpolation with half-pixel centres, clamped at the border (``INTER_LINEAR``).
///
/// Returns
/// -------
/// ndarray of float32, ``(height, width[, C])``.
///
/// Raises
/// ------
/// ValueError
///     Bad shape, zero output size, NaN/inf, unknown ``method``.
#[pyfunction]
#[pyo3(signature = (image, shape, method="area"))]
fn resize<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    shape: [i128; 2],
    method: &str,
) -> PyResult<Arr<'py, f32>> {
    let [h, w] = shape;
    if h <= 0 || w <= 0 {
        return Err(value_error(format!(
            "`shape` must be positive, got ({h}, {w})"
        )));
    }
    let (height, width): (usize, usize) = (uint(py, "shape", h, 1)?, uint(py, "shape", w, 1)?);
    let m = choice(
        "method",
        method,
        &[
            ("area", Interpolation::Area),
            ("bilinear", Interpolation::Bilinear),
        ],
    )?;
    let a = args::array::<f64>("image", image)?;
    let dims = shape_of(&a);
    let img = to_image(
        "image",
        &dims,
        values(&a).iter().map(|&x| x as f32).collect(),
    )?;
    let out = crate::pool::detach(py, || resize_image(&img, height, width, m)).py_err()?;
    convert::image_array(py, out, dims.len() == 2)
}

// ---------------------------------------------------------------- wavelets

/// The order `N` of the Daubechies wavelet named `"dbN"`.
fn db_order(wavelet: &str) -> PyResult<usize> {
    wavelet
        .strip_prefix("db")
        .filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
        .and_then(|d| d.parse().ok())
        .ok_or_else(|| {
            value_error(format!(
                "`wavelet` must be one of 'db1' ... 'db8', got {wavelet:?}"
            ))
        })
}

/// The periodized Daubechies wavelet transform of the 2-D argument `name` (or its inverse).
fn wavelet2<'py>(
    py: Python<'py>,
    name: &str,
    x: &Bound<'py, PyAny>,
    wavelet: &str,
    level: i128,
    inverse: bool,
) -> PyResult<Arr<'py, f64>> {
    use wscg_math::wavelet::{Daubechies, Wavelet2};
    let order = db_order(wavelet)?;
    let level: usize = uint(py, "level", level, 0)?;
    let x = args::array::<f64>(name, x)?;
    let (r, c) = convert::dims2(name, &x)?;
    let w = Wavelet2::new(r, c, Daubechies::new(order).py_err()?, level).py_err()?;
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

/// Multi-level 2-D orthonormal Daubechies wavelet transform with periodic extension.
///
/// Parameters
/// ----------
/// x : array_like (H, W)
///     Real image; both sizes divisible by ``2**level``.
/// wavelet : {'db1', ..., 'db8'}, default 'db4'
/// level : int, default 4
///
/// Returns
/// -------
/// ndarray (H, W), float64, in the in-place (Mallat) layout: after level ``l`` the
/// approximation is the top-left ``H / 2^l x W / 2^l`` block; each level's details sit beside
/// it (top-right: high-pass along columns, PyWavelets' ``cV``; bottom-left: along rows,
/// ``cH``; bottom-right: ``cD``).
///
/// Notes
/// -----
/// The coefficients equal PyWavelets' ``wavedec2(x, wavelet, mode="periodization",
/// level=level)``; the transform is orthogonal, so :func:`waverec2` is its transpose.
#[pyfunction]
#[pyo3(signature = (x, wavelet="db4", level=4))]
fn wavedec2<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    wavelet: &str,
    level: i128,
) -> PyResult<Arr<'py, f64>> {
    wavelet2(py, "x", x, wavelet, level, false)
}

/// Inverse of :func:`wavedec2`: the image from its Mallat-layout coefficients.
///
/// Parameters
/// ----------
/// coeffs : array_like (H, W)
///     Coefficients as :func:`wavedec2` returns them.
/// wavelet : {'db1', ..., 'db8'}, default 'db4'
/// level : int, default 4
///     The number of levels the coefficients were computed with.
///
/// Returns
/// -------
/// ndarray (H, W), float64. The transform is orthogonal: this is also its transpose.
#[pyfunction]
#[pyo3(signature = (coeffs, wavelet="db4", level=4))]
fn waverec2<'py>(
    py: Python<'py>,
    coeffs: &Bound<'py, PyAny>,
    wavelet: &str,
    level: i128,
) -> PyResult<Arr<'py, f64>> {
    wavelet2(py, "coeffs", coeffs, wavelet, level, true)
}

// ---------------------------------------------------------------- FFT

/// The array-like argument `x` of a transform as an array, refused when it is a scalar.
fn at_least_1d<'py>(x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    let a = args::asarray("x", x)?;
    if a.ndim() == 0 {
        return Err(value_error("`x` must have at least one dimension"));
    }
    Ok(a)
}

/// The DFT of `x` (any real or complex array-like) over `axes` (negative ones count from the
/// end; default all).
fn dft<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    axes: Option<Vec<i64>>,
    norm: &str,
    dir: Direction,
) -> PyResult<Arr<'py, Complex64>> {
    let x = args::complex("x", at_least_1d(x)?.as_any())?;
    let shape = shape_of(&x);
    let nd = shape.len() as i64;
    let axes: Vec<usize> = match axes {
        None => (0..shape.len()).collect(),
        Some(a) => a
            .iter()
            .map(|&i| {
                if (-nd..nd).contains(&i) {
                    Ok(i.rem_euclid(nd) as usize)
                } else {
                    Err(value_error(format!(
                        "`axes` entry {i} is out of range for a {nd}-D array"
                    )))
                }
            })
            .collect::<PyResult<_>>()?,
    };
    let n = choice(
        "norm",
        norm,
        &[
            ("backward", Norm::Backward),
            ("ortho", Norm::Ortho),
            ("forward", Norm::Forward),
        ],
    )?;
    let mut data = values(&x).into_owned();
    crate::pool::detach(py, || fft::fft_axes(&mut data, &shape, &axes, dir, n)).py_err()?;
    array(py, &shape, data)
}

/// N-dimensional discrete Fourier transform.
///
/// Parameters
/// ----------
/// x : array_like
///     Input (real or complex), any number of dimensions.
/// axes : sequence of int, optional
///     Axes to transform (default: all).
/// norm : {'backward', 'ortho', 'forward'}, default 'backward'
///     Scaling, as numpy's ``norm`` argument.
///
/// Returns
/// -------
/// ndarray of complex128, same shape as ``x``.
///
/// Raises
/// ------
/// ValueError
///     Empty axis, repeated or out-of-range axes, unknown ``norm``.
///
/// Notes
/// -----
/// ``X[k] = sum_n x[n] exp(-2 pi i k n / N)`` along each axis; equals ``numpy.fft.fftn``.
#[pyfunction]
#[pyo3(signature = (x, axes=None, norm="backward"))]
fn fftn<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    axes: Option<Vec<i64>>,
    norm: &str,
) -> PyResult<Arr<'py, Complex64>> {
    dft(py, x, axes, norm, Direction::Forward)
}

/// Inverse N-dimensional DFT (``numpy.fft.ifftn``); see :func:`fftn`.
///
/// Parameters
/// ----------
/// x : array_like
///     Spectrum.
/// axes : sequence of int, optional
///     Axes to transform (default: all).
/// norm : {'backward', 'ortho', 'forward'}, default 'backward'
///     Scaling.
///
/// Returns
/// -------
/// ndarray of complex128.
#[pyfunction]
#[pyo3(signature = (x, axes=None, norm="backward"))]
fn ifftn<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    axes: Option<Vec<i64>>,
    norm: &str,
) -> PyResult<Arr<'py, Complex64>> {
    dft(py, x, axes, norm, Direction::Inverse)
}

/// Two-dimensional DFT over ``axes`` (default the last two), as ``numpy.fft.fft2``.
///
/// Parameters
/// ----------
/// x : array_like
///     At least 2-D.
/// axes : (int, int), default (-2, -1)
///     The two axes.
/// norm : {'backward', 'ortho', 'forward'}, default 'backward'
///     Scaling.
///
/// Returns
/// -------
/// ndarray of complex128.
#[pyfunction]
#[pyo3(signature = (x, axes=Some(vec![-2, -1]), norm="backward"),
       text_signature = "(x, axes=(-2, -1), norm=\"backward\")")]
fn fft2<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    axes: Option<Vec<i64>>,
    norm: &str,
) -> PyResult<Arr<'py, Complex64>> {
    dft(py, x, axes, norm, Direction::Forward)
}

/// Inverse two-dimensional DFT, as ``numpy.fft.ifft2``.
///
/// Parameters
/// ----------
/// x : array_like
///     At least 2-D.
/// axes : (int, int), default (-2, -1)
///     The two axes.
/// norm : {'backward', 'ortho', 'forward'}, default 'backward'
///     Scaling.
///
/// Returns
/// -------
/// ndarray of complex128.
#[pyfunction]
#[pyo3(signature = (x, axes=Some(vec![-2, -1]), norm="backward"),
       text_signature = "(x, axes=(-2, -1), norm=\"backward\")")]
fn ifft2<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    axes: Option<Vec<i64>>,
    norm: &str,
) -> PyResult<Arr<'py, Complex64>> {
    dft(py, x, axes, norm, Direction::Inverse)
}

/// The array-like `x` (real: float64, complex: complex128) rolled by `fftshift`, or by
/// `ifftshift` when `inverse`.
fn shift<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    inverse: bool,
) -> PyResult<Bound<'py, PyAny>> {
    fn rolled<'py, T: numpy::Element + Copy + Send + Sync>(
        py: Python<'py>,
        x: PyReadonlyArrayDyn<'py, T>,
        inverse: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
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
        Ok(array(py, &shape, out)?.into_any())
    }
    let a = at_least_1d(x)?;
    if a.dtype().kind() == b'c' {
        rolled(py, args::complex("x", a.as_any())?, inverse)
    } else {
        rolled(py, args::array::<f64>("x", a.as_any())?, inverse)
    }
}

/// Moves the zero frequency to the centre of every axis (``numpy.fft.fftshift``).
///
/// Parameters
/// ----------
/// x : array_like
///     Real or complex array.
///
/// Returns
/// -------
/// ndarray (float64 or complex128), same shape.
#[pyfunction]
fn fftshift<'py>(py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    shift(py, x, false)
}

/// Inverse of :func:`fftshift` (``numpy.fft.ifftshift``).
///
/// Parameters
/// ----------
/// x : array_like
///     Real or complex array.
///
/// Returns
/// -------
/// ndarray (float64 or complex128), same shape.
#[pyfunction]
fn ifftshift<'py>(py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    shift(py, x, true)
}

/// Sample frequencies of a length-``n`` DFT with spacing ``d`` (``numpy.fft.fftfreq``).
///
/// Parameters
/// ----------
/// n : int
///     Transform length (> 0).
/// d : float, default 1.0
///     Sample spacing (> 0).
///
/// Returns
/// -------
/// ndarray of float64, length ``n``.
#[pyfunction]
#[pyo3(signature = (n, d=1.0))]
fn fftfreq(py: Python<'_>, n: i128, d: f64) -> PyResult<Arr<'_, f64>> {
    let n: usize = uint(py, "n", n, 1)?;
    wscg_math::error::ensure_positive("d", d).py_err()?;
    array(py, &[n], fft::fftfreq(n, d).py_err()?)
}

// ---------------------------------------------------------------- sparse

type Csr<'py> = (Arr<'py, i64>, Arr<'py, i64>, Arr<'py, f64>);

/// CSR arrays of the 7-point Laplacian of an ``nx x ny x nz`` grid (Dirichlet).
///
/// Parameters
/// ----------
/// nx, ny, nz : int
///     Grid size (> 0); unknowns are ordered with x fastest.
///
/// Returns
/// -------
/// indptr, indices, data : ndarray
///     int64, int64 and float64 CSR arrays (diagonal 6, neighbours -1): symmetric positive
///     definite, for tests and benchmarks.
#[pyfunction]
fn laplacian_3d(py: Python<'_>, nx: i128, ny: i128, nz: i128) -> PyResult<Csr<'_>> {
    let (nx, ny, nz): (usize, usize, usize) = (
        uint(py, "nx", nx, 1)?,
        uint(py, "ny", ny, 1)?,
        uint(py, "nz", nz, 1)?,
    );
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

/// Eigenpairs of a real symmetric matrix.
///
/// Parameters
/// ----------
/// a : array_like
///     Symmetric ``(n, n)`` matrix.
/// k : int, optional
///     Number of eigenpairs (default: all).
/// which : {'largest', 'smallest'}, default 'largest'
///     Which end of the spectrum; values come in that order (descending for
///     ``'largest'``, ascending for ``'smallest'``).
///
/// Returns
/// -------
/// values : ndarray, (k,)
/// vectors : ndarray, (n, k)
///     Unit eigenvectors as columns.
///
/// Raises
/// ------
/// ValueError
///     Not square, not symmetric, NaN/inf, ``k`` out of range, unknown ``which``.
#[pyfunction]
#[pyo3(signature = (a, k=None, which="largest"))]
fn eigh<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    k: Option<i128>,
    which: &str,
) -> PyResult<Eig<'py>> {
    let largest = choice("which", which, &[("largest", true), ("smallest", false)])?;
    let k: Option<usize> = k.map(|k| uint(py, "k", k, 0)).transpose()?;
    let m = mat("a", &args::array::<f64>("a", a)?)?;
    let e = crate::pool::detach(py, || match (k, largest) {
        (None, false) => dense::eigh(m.as_ref()),
        (None, true) => {
            dense::eigh(m.as_ref()).and_then(|e| dense::eigh_largest(m.as_ref(), e.values.len()))
        }
        (Some(k), true) => dense::eigh_largest(m.as_ref(), k),
        (Some(k), false) => dense::eigh_smallest(m.as_ref(), k),
    })
    .py_err()?;
    eig_out(py, e)
}

/// Generalized symmetric-definite eigenproblem ``A v = lambda B v``.
///
/// Parameters
/// ----------
/// a : array_like
///     Symmetric ``(n, n)``.
/// b : array_like
///     Symmetric positive definite ``(n, n)``.
///
/// Returns
/// -------
/// values : ndarray, (n,)
///     Ascending.
/// vectors : ndarray, (n, n)
///     ``B``-orthonormal eigenvectors as columns (``V.T @ B @ V = I``).
///
/// Raises
/// ------
/// ValueError
///     Shapes, asymmetry, NaN, ``b`` not positive definite.
///
/// Notes
/// -----
/// Cholesky ``B = L L^T``, then the standard problem for ``L^-1 A L^-T``; eigenvalues equal
/// ``scipy.linalg.eigh(a, b)``.
#[pyfunction]
fn eigh_generalized<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Eig<'py>> {
    let ma = mat("a", &args::array::<f64>("a", a)?)?;
    let mb = mat("b", &args::array::<f64>("b", b)?)?;
    let e =
        crate::pool::detach(py, || dense::eigh_generalized(ma.as_ref(), mb.as_ref())).py_err()?;
    eig_out(py, e)
}

/// Thin singular value decomposition ``a = u @ diag(s) @ vt``.
///
/// Parameters
/// ----------
/// a : array_like
///     ``(m, n)`` matrix.
///
/// Returns
/// -------
/// u : ndarray, (m, r)
/// s : ndarray, (r,)
///     Non-increasing, ``r = min(m, n)``.
/// vt : ndarray, (r, n)
///
/// Raises
/// ------
/// ValueError
///     Not 2-D, empty, NaN/inf.
#[pyfunction]
fn svd<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
) -> PyResult<(Arr<'py, f64>, Arr<'py, f64>, Arr<'py, f64>)> {
    let m = mat("a", &args::array::<f64>("a", a)?)?;
    let d = crate::pool::detach(py, || dense::svd(m.as_ref())).py_err()?;
    let vt = d.v.transpose().to_owned();
    let n = d.s.len();
    Ok((mat_out(py, &d.u)?, array(py, &[n], d.s)?, mat_out(py, &vt)?))
}

/// Minimum-norm least-squares solution of ``a @ x = b``.
///
/// Parameters
/// ----------
/// a : array_like
///     ``(m, n)`` matrix.
/// b : array_like
///     ``(m,)`` or ``(m, k)``.
/// rcond : float, optional
///     Relative cut-off for small singular values (default ``eps * max(m, n)``, numpy's).
///
/// Returns
/// -------
/// ndarray
///     ``(n,)`` or ``(n, k)``, matching ``b``.
///
/// Raises
/// ------
/// ValueError
///     Shapes, NaN/inf, negative ``rcond``.
#[pyfunction]
#[pyo3(signature = (a, b, rcond=None))]
fn lstsq<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    rcond: Option<f64>,
) -> PyResult<Arr<'py, f64>> {
    let rcond = rcond.map(|r| number("rcond", r)).transpose()?;
    let ma = mat("a", &args::array::<f64>("a", a)?)?;
    let b = args::array::<f64>("b", b)?;
    let one = b.ndim() == 1;
    let mb = if one {
        let v = values(&b);
        crate::pool::detach(py, || dense::from_row_major(&v, v.len(), 1))?
    } else {
        mat("b", &b)?
    };
    let x = crate::pool::detach(py, || dense::lstsq(ma.as_ref(), mb.as_ref(), rcond)).py_err()?;
    if one {
        array(
            py,
            &[x.nrows()],
            (0..x.nrows()).map(|i| x[(i, 0)]).collect(),
        )
    } else {
        mat_out(py, &x)
    }
}

// ---------------------------------------------------------------- random numbers

/// ``n`` normal samples from a seeded, portable generator (ChaCha8).
///
/// Parameters
/// ----------
/// seed : int
///     Seed (>= 0); the same seed gives the same values on every machine and thread count.
/// n : int
///     Number of samples.
/// mean, std : float
///     Distribution parameters (``std >= 0``).
///
/// Returns
/// -------
/// ndarray of float64.
#[pyfunction]
#[pyo3(signature = (seed, n, mean=0.0, std=1.0))]
fn normal(py: Python<'_>, seed: i128, n: i128, mean: f64, std: f64) -> PyResult<Arr<'_, f64>> {
    let (seed, n): (u64, usize) = (uint(py, "seed", seed, 0)?, uint(py, "n", n, 0)?);
    let (mean, std) = (number("mean", mean)?, number("std", std)?);
    let v = crate::pool::detach(py, || rng::normal_vec(seed, n, mean, std)).py_err()?;
    array(py, &[n], v)
}

/// ``n`` samples uniform in ``[low, high)`` from a seeded generator.
///
/// Parameters
/// ----------
/// seed : int
///     Seed (>= 0).
/// n : int
///     Number of samples.
/// low, high : float
///     Bounds, ``low < high``.
///
/// Returns
/// -------
/// ndarray of float64.
#[pyfunction]
#[pyo3(signature = (seed, n, low=0.0, high=1.0))]
fn uniform(py: Python<'_>, seed: i128, n: i128, low: f64, high: f64) -> PyResult<Arr<'_, f64>> {
    let (seed, n): (u64, usize) = (uint(py, "seed", seed, 0)?, uint(py, "n", n, 0)?);
    let (low, high) = (number("low", low)?, number("high", high)?);
    let v = crate::pool::detach(py, || rng::uniform_vec(seed, n, low, high)).py_err()?;
    array(py, &[n], v)
}

/// A seeded random permutation of ``range(n)``.
///
/// Parameters
/// ----------
/// seed : int
///     Seed (>= 0).
/// n : int
///     Length.
///
/// Returns
/// -------
/// ndarray of int64.
#[pyfunction]
fn permutation(py: Python<'_>, seed: i128, n: i128) -> PyResult<Arr<'_, i64>> {
    let (seed, n): (u64, usize) = (uint(py, "seed", seed, 0)?, uint(py, "n", n, 0)?);
    let v: Vec<i64> = crate::pool::detach(py, || {
        rng::permutation(seed, n).map(|p| p.into_iter().map(|i| i as i64).collect())
    })
    .py_err()?;
    array(py, &[n], v)
}

// ---------------------------------------------------------------- images

/// Reads a PNG or TIFF (8/16-bit; TIFF also 32-bit float), JPEG, OpenEXR or Radiance HDR
/// image. A multi-page TIFF is read from its first page.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     The file (only read).
///
/// Returns
/// -------
/// ndarray of float32
///     ``(H, W)`` for grey images, ``(H, W, C)`` otherwise; integer formats scaled to
///     ``[0, 1]`` (``v / 255``, ``v / 65535``: ``np.round(x * 65535).astype(np.uint16)``
///     gives back a 16-bit file's codes exactly), float formats unchanged.
///
/// Raises
/// ------
/// OSError
///     Missing, unreadable, truncated or unsupported file.
#[pyfunction]
fn load_image<'py>(py: Python<'py>, path: &Bound<'py, PyAny>) -> PyResult<Arr<'py, f32>> {
    let path = args::path("path", path)?;
    let img = crate::pool::detach(py, || Image::load(&path)).py_err()?;
    convert::image_array(py, img, true)
}

/// The values of the integer `image` array divided by `full` (its largest code), as
/// `f32` in C order, with its shape.
fn codes<T: numpy::Element + Copy + Into<f64>>(
    a: &Bound<'_, PyArrayDyn<T>>,
    full: f64,
) -> (Vec<usize>, Vec<f32>) {
    let a = a.readonly();
    let v = values(&a)
        .iter()
        .map(|&x| (x.into() / full) as f32)
        .collect();
    (a.shape().to_vec(), v)
}

/// Writes an image; the format follows the extension (png, tif/tiff, jpg/jpeg, exr,
/// hdr). The file is written atomically (a temporary file renamed over ``path``).
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     Output file.
/// image : array_like
///     ``(H, W)`` or ``(H, W, C)`` with C in 1..4 (TIFF: 1, 3 or 4). A uint8 array holds
///     codes ``0..255`` and a uint16 array codes ``0..65535`` (written exactly at their own
///     depth); other arrays hold values in ``[0, 1]`` for integer formats (clamped), any
///     finite values for exr/hdr and 32-bit TIFF.
/// bit_depth : {8, 16, 32}, optional
///     8, 16 (png and tiff) or 32 (float: exr, hdr, and RGB/RGBA tiff). Default: 16 for a
///     uint16 array written to png or tiff, 32 for exr/hdr, else 8.
///
/// Raises
/// ------
/// ValueError
///     Bad shape, NaN/inf.
/// OSError
///     Unsupported extension or depth for the format, unwritable path.
#[pyfunction]
#[pyo3(signature = (path, image, bit_depth=None))]
fn save_image(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    image: &Bound<'_, PyAny>,
    bit_depth: Option<i64>,
) -> PyResult<()> {
    let path = args::path("path", path)?;
    let name = path.to_string_lossy().to_ascii_lowercase();
    let sixteen_bit_format = [".png", ".tif", ".tiff"].iter().any(|e| name.ends_with(e));
    let mut bit_depth = bit_depth;
    let (shape, v) = if let Ok(a) = image.cast::<PyArrayDyn<u8>>() {
        codes(a, 255.0)
    } else if let Ok(a) = image.cast::<PyArrayDyn<u16>>() {
        if sixteen_bit_format {
            bit_depth = bit_depth.or(Some(16));
        }
        codes(a, 65535.0)
    } else {
        let a = args::array::<f64>("image", image)?;
        let v = values(&a).iter().map(|&x| x as f32).collect();
        (a.shape().to_vec(), v)
    };
    let img = to_image("image", &shape, v)?;
    let depth = match bit_depth {
        None => None,
        Some(8) => Some(PixelDepth::U8),
        Some(16) => Some(PixelDepth::U16),
        Some(32) => Some(PixelDepth::F32),
        Some(other) => {
            return Err(value_error(format!(
                "`bit_depth` must be 8, 16 or 32, got {other}"
            )))
        }
    };
    crate::pool::detach(py, || match depth {
        None => img.save(&path),
        Some(d) => img.save_with_depth(&path, d),
    })
    .py_err()
}

// ---------------------------------------------------------------- volumes

/// Whether `|a - b| <= atol + rtol |b|` for every pair (numpy's `allclose`).
fn allclose(a: &[f64], b: &[f64], rtol: f64, atol: f64) -> bool {
    a.iter()
        .zip(b)
        .all(|(&x, &y)| (x - y).abs() <= atol + rtol * y.abs())
}

/// The rows x, y, z of the voxel-to-world `affine` argument (4 x 4 with the last row
/// (0, 0, 0, 1), or 3 x 4) and the spacing `(dz, dy, dx)` of its columns' lengths.
fn affine_rows(obj: &Bound<'_, PyAny>) -> PyResult<([[f64; 4]; 3], [f64; 3])> {
    let a = args::array::<f64>("affine", obj)?;
    let shape = a.shape().to_vec();
    if shape != [4, 4] && shape != [3, 4] {
        return Err(value_error(format!(
            "`affine` must be a 4 x 4 or 3 x 4 matrix, got shape {shape:?}"
        )));
    }
    let v = values(&a);
    if shape[0] == 4 && !allclose(&v[12..], &[0.0, 0.0, 0.0, 1.0], 1e-5, 1e-8) {
        return Err(value_error(format!(
            "`affine`'s last row must be (0, 0, 0, 1), got {:?}",
            &v[12..]
        )));
    }
    let row = |i: usize| [v[4 * i], v[4 * i + 1], v[4 * i + 2], v[4 * i + 3]];
    let rows = [row(0), row(1), row(2)];
    let norm = |j: usize| rows.iter().map(|r| r[j] * r[j]).sum::<f64>().sqrt();
    Ok((rows, [norm(2), norm(1), norm(0)]))
}

/// Writes a volume as .nii / .nii.gz (NIfTI-1, float32), .npy or .raw (f32 little endian).
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     Output file; the extension picks the format.
/// volume : array_like
///     3-D array indexed ``[z, y, x]``.
/// spacing : (dz, dy, dx), optional
///     Voxel size (> 0), default (1, 1, 1), or the lengths of ``affine``'s columns when it is
///     given (a ``spacing`` that differs from them is an error). Without ``affine`` a NIfTI
///     file gets the affine of ``py/API.md``: its voxel ``(i, j, k)``, which is
///     ``volume[k, j, i]``, maps to ``(x, y, z) = (i dx, j dy, k dz)``.
/// affine : array_like (4, 4) or (3, 4), optional
///     Voxel-to-world matrix acting on ``(i, j, k, 1)`` (RAS+ mm, as
///     :attr:`VolumeFile.affine`): the NIfTI sform, and the qform when it is a rotation.
///     Ignored by .npy and .raw, which hold no geometry.
///
/// Raises
/// ------
/// ValueError
///     Not 3-D, bad spacing, a singular or non-finite affine, or one that disagrees with
///     ``spacing``.
/// OSError
///     Unsupported extension, unwritable path.
#[pyfunction]
#[pyo3(signature = (path, volume, spacing=None, affine=None))]
fn save_volume(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    volume: &Bound<'_, PyAny>,
    spacing: Option<[f64; 3]>,
    affine: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let path = args::path("path", path)?;
    let (affine, spacing) = match affine {
        Some(a) => {
            let (rows, implied) = affine_rows(a)?;
            if let Some(s) = spacing {
                if !allclose(&s, &implied, 1e-5, 0.0) {
                    return Err(value_error(format!(
                        "`spacing` {s:?} differs from the lengths of `affine`'s columns \
                         {implied:?} (dz, dy, dx)"
                    )));
                }
            }
            (Some(rows), implied)
        }
        None => (None, spacing.unwrap_or([1.0; 3])),
    };
    let volume = args::array::<f32>("volume", volume)?;
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
        let mut vol = Volume::from_zyx(view, args::xyz(spacing))?;
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

/// Writes a triangle mesh as .obj or .ply.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     Output file; the extension picks the format.
/// vertices : array_like, (N, 3)
///     ``(x, y, z)`` positions.
/// faces : array_like of int, (M, 3)
///     Vertex indices, 0-based.
/// colors : array_like, (N, 3), optional
///     Per-vertex RGB in [0, 1].
/// normals : array_like, (N, 3), optional
///     Per-vertex normals.
/// binary : bool, default True
///     Binary little-endian PLY (ignored for OBJ).
///
/// Raises
/// ------
/// ValueError
///     Bad shapes, NaN, indices out of range or repeated within a face.
/// OSError
///     Unsupported extension, unwritable path.
#[pyfunction]
#[pyo3(signature = (path, vertices, faces, colors=None, normals=None, binary=true))]
fn save_mesh(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    colors: Option<&Bound<'_, PyAny>>,
    normals: Option<&Bound<'_, PyAny>>,
    binary: bool,
) -> PyResult<()> {
    let path = args::path("path", path)?;
    let mesh = args::colored_mesh(vertices, faces, colors)?;
    let normals = match normals {
        Some(n) => {
            let n = args::array::<f64>("normals", n)?;
            Some(rows3("normals", &values(&n), n.shape())?)
        }
        None => None,
    };
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

// ------------------------------------------- private: called by python/wscg/math.py and others

/// `wscg.math.cg`'s solve: the solution, the iterations run, the relative residual and
/// whether it converged (the Python function builds its `CgInfo`).
#[pyfunction]
#[pyo3(signature = (indptr, indices, data, b, shape, x0, tol, max_iter, preconditioner))]
#[allow(clippy::too_many_arguments)]
fn cg<'py>(
    py: Python<'py>,
    indptr: &Bound<'py, PyAny>,
    indices: &Bound<'py, PyAny>,
    data: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    shape: Option<[i128; 2]>,
    x0: Option<&Bound<'py, PyAny>>,
    tol: f64,
    max_iter: Option<i128>,
    preconditioner: Option<&str>,
) -> PyResult<(Arr<'py, f64>, usize, f64, bool)> {
    let p = convert::indices("indptr", &values(&args::array::<i64>("indptr", indptr)?))?;
    let c = convert::indices("indices", &values(&args::array::<i64>("indices", indices)?))?;
    if p.is_empty() {
        return Err(value_error("`indptr` must have length nrows + 1 >= 1"));
    }
    let n = p.len() - 1;
    let ncols = match shape {
        None => n,
        Some([rows, cols]) => {
            if rows != n as i128 {
                return Err(value_error(format!(
                    "`shape` ({rows}, {cols}) does not match len(indptr) - 1 = {n}"
                )));
            }
            uint(py, "shape", cols, 0)?
        }
    };
    let max_iter: Option<usize> = max_iter.map(|m| uint(py, "max_iter", m, 0)).transpose()?;
    let data = args::array::<f64>("data", data)?;
    let d = values(&data);
    let a =
        crate::pool::detach(py, || CsrMatrix::from_csr_arrays(n, ncols, &p, &c, &d)).py_err()?;
    let b = args::array::<f64>("b", b)?;
    let bv = values(&b);
    let x0 = x0.map(|x| args::array::<f64>("x0", x)).transpose()?;
    let x0v = x0.as_ref().map(|x| values(x));
    let guess = match &x0v {
        Some(x) => InitialGuess::Given(x),
        None => InitialGuess::Zero,
    };
    let opts = PcgParams::default()
        .tol(number("tol", tol)?)
        .max_iter(max_iter);
    let res = match preconditioner {
        None | Some("none") => {
            crate::pool::detach(py, || pcg(&a, &bv, guess, &IdentityPrecond, &opts))?
        }
        Some("jacobi") => crate::pool::detach(py, || {
            pcg(&a, &bv, guess, &Jacobi::new(&a.diagonal())?, &opts)
        })?,
        Some(other) => {
            return Err(value_error(format!(
                "`preconditioner` must be 'jacobi' or None, got {other:?}"
            )))
        }
    }
    .py_err()?;
    let n = res.x.len();
    Ok((
        array(py, &[n], res.x)?,
        res.iterations,
        res.relative_residual,
        res.converged,
    ))
}

/// The EXIF exposure settings of an image file: `(exposure_time, f_number, iso)`, each
/// `None` when the block lacks it.
#[pyfunction]
fn read_exif(py: Python<'_>, path: PathBuf) -> PyResult<(Option<f64>, Option<f64>, Option<f64>)> {
    let e = crate::pool::detach(py, || wscg_math::io::exif::load_exif(&path)).py_err()?;
    Ok((e.exposure_time, e.f_number, e.iso))
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

/// `wscg.math.load_volume`'s read (the Python function builds its `VolumeFile`).
#[pyfunction]
#[pyo3(signature = (path, spacing, series))]
fn load_volume(
    py: Python<'_>,
    path: PathBuf,
    spacing: Option<[f64; 3]>,
    series: Option<String>,
) -> PyResult<VolumeOut<'_>> {
    let v = crate::pool::detach(py, || match series {
        Some(uid) => {
            let params = wscg_math::io::dicom::DicomParams::default().series(uid);
            let mut v = Volume::read_dicom_with(&path, &params)?;
            if let Some(s) = spacing {
                v.set_spacing(args::xyz(s))?;
            }
            Ok(v)
        }
        None => Volume::read(&path, spacing.map(args::xyz)),
    })
    .py_err()?;
    volume_out(py, v)
}

/// `wscg.math.load_raw_volume`'s read (the Python function builds its `VolumeFile`).
#[pyfunction]
fn load_raw_volume<'py>(
    py: Python<'py>,
    path: PathBuf,
    shape: [i128; 3],
    dtype: &str,
    spacing: [f64; 3],
) -> PyResult<VolumeOut<'py>> {
    let t = dtype.parse::<RawType>().py_err()?;
    let mut dims = [0usize; 3];
    for (d, &s) in dims.iter_mut().rev().zip(&shape) {
        *d = uint(py, "shape", s, 0)?;
    }
    let v = crate::pool::detach(py, || Volume::read_raw(&path, dims, args::xyz(spacing), t))
        .py_err()?;
    volume_out(py, v)
}

/// `wscg.math.load_mesh`'s read: the mesh's arrays by field of `wscg.math.Mesh`.
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

/// Writes `data` to `path` atomically (`wscg_math::io::atomic`): the writer of the files the
/// Python package writes itself (model JSON), so that they too leave no truncated file.
#[pyfunction]
fn write_file(py: Python<'_>, path: PathBuf, data: Vec<u8>) -> PyResult<()> {
    crate::pool::detach(py, || wscg_math::io::atomic::write(&path, &data)).py_err()
}

/// Registers the submodule's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mse, m)?)?;
    m.add_function(wrap_pyfunction!(rmse, m)?)?;
    m.add_function(wrap_pyfunction!(psnr, m)?)?;
    m.add_function(wrap_pyfunction!(ssim, m)?)?;
    m.add_function(wrap_pyfunction!(dice, m)?)?;
    m.add_function(wrap_pyfunction!(gaussian_filter, m)?)?;
    m.add_function(wrap_pyfunction!(box_filter, m)?)?;
    m.add_function(wrap_pyfunction!(resize, m)?)?;
    m.add_function(wrap_pyfunction!(wavedec2, m)?)?;
    m.add_function(wrap_pyfunction!(waverec2, m)?)?;
    m.add_function(wrap_pyfunction!(fftn, m)?)?;
    m.add_function(wrap_pyfunction!(ifftn, m)?)?;
    m.add_function(wrap_pyfunction!(fft2, m)?)?;
    m.add_function(wrap_pyfunction!(ifft2, m)?)?;
    m.add_function(wrap_pyfunction!(fftshift, m)?)?;
    m.add_function(wrap_pyfunction!(ifftshift, m)?)?;
    m.add_function(wrap_pyfunction!(fftfreq, m)?)?;
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
    m.add_function(wrap_pyfunction!(save_volume, m)?)?;
    m.add_function(wrap_pyfunction!(save_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(cg, m)?)?;
    m.add_function(wrap_pyfunction!(read_exif, m)?)?;
    m.add_function(wrap_pyfunction!(load_volume, m)?)?;
    m.add_function(wrap_pyfunction!(load_raw_volume, m)?)?;
    m.add_function(wrap_pyfunction!(load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_file, m)?)?;
    Ok(())
}
