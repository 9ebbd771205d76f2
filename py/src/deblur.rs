//! `wscg.deblur`'s functions (paper 12, gyroscope-driven multi-frame blur estimation and
//! removal): bindings of `wscg-deblur` that Python calls directly, re-exported by
//! `python/wscg/deblur.py` (which holds the module's documentation). Their arguments are
//! converted and checked here and by [`crate::args`]: images as real `(H, W)` arrays of any
//! dtype (a float64 image gives a float64 result), gyroscope traces as `(N, 4)` arrays.
//! `deblur_multiframe` keeps a Python layer, which builds its `MultiframeDeblur` and issues
//! its warnings; its binding takes and checks the arguments as given.

use nalgebra::{Matrix3, Rotation3};
use numpy::{PyArrayDescrMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_deblur::synth::{self, BlurRenderParams, ShakeParams};
use wscg_deblur::{
    AlignMode, AlignParams, FrameInput, Gamma, GyroSample, GyroTrack, HyperLaplacianParams,
    Intrinsics, Kernel, KernelGrid, KernelParams, Method, MultiframeParams, Tiling, Timing,
};
use wscg_math::progress::NoProgress;
use wscg_math::Image;

use crate::args::{self, finite, non_negative, number, positive, uint};
use crate::convert::{array, values, Arr};
use crate::errors::{value_error, IntoPy, IntoPyRenamed};

// ---------------------------------------------------------------- arguments

/// The gradient exponent `alpha` of the hyper-Laplacian prior, in `(0, 2]`.
fn alpha_arg(alpha: f64) -> PyResult<f64> {
    if alpha > 0.0 && alpha <= 2.0 {
        Ok(alpha)
    } else {
        Err(value_error(format!(
            "`alpha` must lie in (0, 2], got {alpha}"
        )))
    }
}

/// The camera intrinsics `(f, cx, cy)` in pixels.
fn intrinsics(f: f64, cx: f64, cy: f64) -> PyResult<Intrinsics> {
    let f = positive("f", f)?;
    if !(cx.is_finite() && cy.is_finite()) {
        return Err(value_error(format!(
            "the principal point (`cx`, `cy`) must be finite, got ({cx}, {cy})"
        )));
    }
    Ok(Intrinsics { f, cx, cy })
}

/// The frame timing of a frame of `height` rows.
fn timing(
    t_frame: f64,
    t_exposure: f64,
    t_readout: f64,
    t_delay: f64,
    height: usize,
) -> PyResult<Timing> {
    Ok(Timing {
        t_frame: finite("t_frame", t_frame)?,
        t_exposure: positive("t_exposure", t_exposure)?,
        t_readout: non_negative("t_readout", t_readout)?,
        t_delay: finite("t_delay", t_delay)?,
        height,
    })
}

/// The `gyro` argument: an `(N, 4)` real array of rows `(t, wx, wy, wz)`, at least two,
/// finite, with strictly increasing time stamps.
fn gyro_samples(gyro: &Bound<'_, PyAny>) -> PyResult<Vec<GyroSample>> {
    let a = args::real_array("gyro", gyro)?;
    let a = args::array::<f64>("gyro", a.as_any())?;
    let n = match *a.shape() {
        [n, 4] => n,
        ref s => {
            return Err(value_error(format!(
                "`gyro` must have shape (N, 4) with rows (t, wx, wy, wz), got shape {s:?}"
            )))
        }
    };
    if n < 2 {
        return Err(value_error(format!(
            "`gyro` needs at least 2 samples, got {n}"
        )));
    }
    let v = values(&a);
    if let Some(i) = v
        .chunks_exact(4)
        .position(|r| r.iter().any(|x| !x.is_finite()))
    {
        return Err(value_error(format!(
            "`gyro` contains a non-finite value (NaN or infinity) in row {i}"
        )));
    }
    if let Some(i) = (1..n).find(|&i| v[4 * i] <= v[4 * (i - 1)]) {
        return Err(value_error(format!(
            "`gyro` time stamps must be strictly increasing: sample {i} at t = {} follows \
             t = {}",
            v[4 * i],
            v[4 * (i - 1)]
        )));
    }
    Ok(v.chunks_exact(4)
        .map(|r| GyroSample::new(r[0], r[1], r[2], r[3]))
        .collect())
}

fn samples_out<'py>(py: Python<'py>, s: &[GyroSample]) -> PyResult<Arr<'py, f64>> {
    let data = s
        .iter()
        .flat_map(|g| [g.t, g.w[0], g.w[1], g.w[2]])
        .collect();
    array(py, &[s.len(), 4], data)
}

/// The camera-from-IMU rotation `r_cam_imu`: a `(3, 3)` rotation matrix (orthonormal,
/// determinant 1), the identity when absent.
fn rotation(r: Option<&Bound<'_, PyAny>>) -> PyResult<Rotation3<f64>> {
    let Some(r) = r else {
        return Ok(Rotation3::identity());
    };
    let r = args::array::<f64>("r_cam_imu", r)?;
    if r.shape() != [3, 3] {
        return Err(value_error(format!(
            "`r_cam_imu` must be a (3, 3) rotation matrix, got shape {:?}",
            r.shape()
        )));
    }
    let m = Matrix3::from_row_slice(&values(&r));
    if !m.iter().all(|v| v.is_finite()) {
        return Err(value_error("`r_cam_imu` contains a non-finite value"));
    }
    let err = (m.transpose() * m - Matrix3::identity()).abs().max();
    if err > 1e-6 || (m.determinant() - 1.0).abs() > 1e-6 {
        return Err(value_error(format!(
            "`r_cam_imu` must be a rotation (orthonormal with determinant +1); |R^T R - I| = \
             {err:.3e}, det = {:.6}",
            m.determinant()
        )));
    }
    Ok(Rotation3::from_matrix_unchecked(m))
}

/// The constant gyroscope `bias` (3 finite rates, rad/s), zero when absent.
fn bias(b: Option<&Bound<'_, PyAny>>) -> PyResult<[f64; 3]> {
    let Some(b) = b else {
        return Ok([0.0; 3]);
    };
    let bad = value_error(format!(
        "`bias` must be 3 finite rates (bx, by, bz) in rad/s, got {}",
        b.repr()?
    ));
    let a = args::array::<f64>("bias", b).map_err(|_| bad.clone_ref(b.py()))?;
    match *values(&a) {
        [x, y, z] if [x, y, z].iter().all(|v| v.is_finite()) => Ok([x, y, z]),
        _ => Err(bad),
    }
}

/// The integrated gyroscope trace of the `gyro`, `r_cam_imu` and `bias` arguments.
fn track(
    gyro: &Bound<'_, PyAny>,
    r_cam_imu: Option<&Bound<'_, PyAny>>,
    b: Option<&Bound<'_, PyAny>>,
) -> PyResult<GyroTrack> {
    let samples = gyro_samples(gyro)?;
    let r = rotation(r_cam_imu)?;
    let b = bias(b)?;
    GyroTrack::new(&samples, r, b).py_err()
}

/// The `(H, W)` array `a` as a non-empty image of finite float32 values, divided by `scale`
/// when given.
fn gray(name: &str, a: &Bound<'_, PyUntypedArray>, scale: Option<f32>) -> PyResult<Image<f32>> {
    if a.ndim() != 2 {
        return Err(value_error(format!(
            "`{name}` must be a 2-D grayscale array (H, W), got shape {:?}",
            a.shape()
        )));
    }
    let (h, w) = (a.shape()[0], a.shape()[1]);
    if h * w == 0 {
        return Err(value_error(format!("`{name}` is empty (shape ({h}, {w}))")));
    }
    let a = args::array::<f32>(name, a.as_any())?;
    let mut v = values(&a).into_owned();
    if let Some(s) = scale {
        v.iter_mut().for_each(|x| *x /= s);
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(value_error(format!(
            "`{name}` contains a non-finite value (NaN or infinity) at flat index {i}"
        )));
    }
    Image::new(h, w, 1, v).py_err()
}

/// A grayscale image argument: a non-empty real `(H, W)` array as float32 with finite values,
/// and whether it was float64 (the function then answers in float64).
fn image(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(Image<f32>, bool)> {
    let a = args::real_array(name, obj)?;
    let dtype = a.dtype();
    let f64_in = dtype.kind() == b'f' && dtype.itemsize() == 8;
    Ok((gray(name, &a, None)?, f64_in))
}

/// A frame of display values (`frames[i]` of `deblur_multiframe`): unsigned integers divided
/// by their maximum (8-bit: 255), floats already in `[0, 1]`.
fn display(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Image<f32>> {
    let a = args::real_array(name, obj)?;
    let dtype = a.dtype();
    let img = match dtype.kind() {
        b'u' => {
            let max = match dtype.itemsize() {
                1 => f32::from(u8::MAX),
                2 => f32::from(u16::MAX),
                4 => u32::MAX as f32,
                _ => u64::MAX as f32,
            };
            gray(name, &a, Some(max))?
        }
        b'i' => {
            return Err(value_error(format!(
                "`{name}` has signed integer dtype {dtype}; pass uint8 (0..255) or float \
                 display values in [0, 1]"
            )))
        }
        _ => gray(name, &a, None)?,
    };
    let (lo, hi) = img
        .data()
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if lo < -1e-6 || hi > 1.0 + 1e-6 {
        return Err(value_error(format!(
            "`{name}` holds floats in [{lo}, {hi}]; float frames must be display values in \
             [0, 1] (pass uint8 for 0..255 data)"
        )));
    }
    Ok(img)
}

/// A result image: float64 when the input image was, float32 otherwise.
fn image_out(py: Python<'_>, img: Image<f32>, f64_out: bool) -> PyResult<Bound<'_, PyAny>> {
    if f64_out {
        let (h, w, _) = img.shape();
        let v = img.data().iter().map(|&x| f64::from(x)).collect();
        Ok(array(py, &[h, w], v)?.into_any())
    } else {
        Ok(crate::convert::image_array(py, img, true)?.into_any())
    }
}

/// The `kernel` argument (a non-empty real 2-D array of finite weights `>= 0` with a
/// positive sum) with zero displacement at `origin` (`(row, col)`, default the centre
/// `(kh // 2, kw // 2)`).
fn kernel(kernel: &Bound<'_, PyAny>, origin: Option<&Bound<'_, PyAny>>) -> PyResult<Kernel> {
    let a = args::real_array("kernel", kernel)?;
    if a.ndim() != 2 || a.len() == 0 {
        return Err(value_error(format!(
            "`kernel` must be a non-empty 2-D array, got shape {:?}",
            a.shape()
        )));
    }
    let a = args::array::<f32>("kernel", a.as_any())?;
    let (kh, kw) = (a.shape()[0], a.shape()[1]);
    let v = values(&a);
    if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return Err(value_error("`kernel` weights must be finite and >= 0"));
    }
    if v.iter().map(|&x| f64::from(x)).sum::<f64>() <= 0.0 {
        return Err(value_error("`kernel` weights sum to zero"));
    }
    let (r, c) = match origin {
        None => ((kh / 2) as i64, (kw / 2) as i64),
        Some(o) => {
            let bad = value_error(format!(
                "`origin` must be a (row, col) pair of integers, got {}",
                o.repr()?
            ));
            let [r, c] = o.extract::<[i64; 2]>().map_err(|_| bad)?;
            (r, c)
        }
    };
    if !((0..kh as i64).contains(&r) && (0..kw as i64).contains(&c)) {
        return Err(value_error(format!(
            "`origin` ({r}, {c}) lies outside the {kh}x{kw} kernel"
        )));
    }
    Kernel::with_origin(kh, kw, v.into_owned(), (r as usize, c as usize)).py_err()
}

fn kernel_out<'py>(py: Python<'py>, k: Kernel) -> PyResult<(Arr<'py, f32>, (usize, usize))> {
    Ok((array(py, &[k.size, k.size], k.data)?, k.origin))
}

/// The kernels of a grid as one `(rows, cols, K, K)` array, every kernel embedded with its
/// origin at the centre `(K / 2, K / 2)`.
fn grid_out<'py>(py: Python<'py>, g: &KernelGrid) -> PyResult<Arr<'py, f32>> {
    let r = g.max_radius();
    let n = 2 * r + 1;
    let mut data = vec![0f32; g.rows * g.cols * n * n];
    for (idx, k) in g.kernels.iter().enumerate() {
        let dst = &mut data[idx * n * n..][..n * n];
        for i in 0..k.size {
            for j in 0..k.size {
                // Displacement (i - origin.0, j - origin.1) lies within the radius r.
                let (y, x) = (i + r - k.origin.0, j + r - k.origin.1);
                dst[y * n + x] = k.data[i * k.size + j];
            }
        }
    }
    array(py, &[g.rows, g.cols, n, n], data)
}

/// The data weight `lam` of the Krishnan-Fergus solver: `"auto"` or a number.
#[derive(FromPyObject)]
enum Lam {
    /// A weight (> 0).
    Value(f64),
    /// `"auto"`: the noise-aware weight.
    Name(String),
}

/// `lam` as the solver takes it: `None` for `"auto"` (`HyperLaplacianParams::lambda`).
fn lam_arg(lam: &Lam) -> PyResult<Option<f32>> {
    match lam {
        Lam::Value(v) => Ok(Some(positive("lam", *v)? as f32)),
        Lam::Name(s) if s == "auto" => Ok(None),
        Lam::Name(s) => Err(value_error(format!(
            "`lam` must be \"auto\" or a number > 0, got {s:?}"
        ))),
    }
}

fn hl_params(lam: Option<f32>, alpha: f64, beta_max: f64) -> HyperLaplacianParams {
    HyperLaplacianParams::default()
        .lambda(lam)
        .alpha(alpha as f32)
        .beta_max(beta_max as f32)
}

// ---------------------------------------------------------------- kernels

/// Render the blur kernel of pixel ``(x, y)`` from the gyroscope (paper section 3.2).
///
/// Parameters
/// ----------
/// gyro : array (N, 4)
///     Gyroscope samples ``(t, wx, wy, wz)``: seconds (strictly increasing) and rad/s.
/// t_frame : float
///     Frame time stamp (s, frame clock).
/// t_exposure : float
///     Exposure time ``t_e`` (s, > 0).
/// f, cx, cy : float
///     Focal length and principal point in pixels.
/// x, y : float
///     Pixel (column, row) whose kernel is rendered.
/// t_readout : float, default 0
///     Rolling-shutter readout time of the whole frame (s; 0 = global shutter).
/// t_delay : float, default 0
///     Gyroscope-camera delay: frame time + ``t_delay`` = gyroscope time.
/// height : int, optional
///     Frame height in rows; required when ``t_readout > 0`` (row ``y`` opens at
///     ``t_frame + t_delay + t_readout * y / height``).
/// r_cam_imu : array (3, 3), optional
///     Rotation from IMU axes to camera axes (rates are used as ``r_cam_imu @ w``);
///     identity by default.
/// bias : (3,) float, optional
///     Constant gyroscope bias (rad/s, IMU axes) subtracted from every sample.
///
/// Returns
/// -------
/// kernel : float32 array (k, k)
///     Non-negative weights summing to 1, ``k`` odd.
/// origin : (int, int)
///     ``(row, col)`` of zero displacement (the shutter-open pose): the kernel's centre.
///
/// Notes
/// -----
/// The latent point ``X = K^-1 [x, y, 1]`` (pose at the shutter opening ``t_open``) is seen
/// at ``pi(K R_rel^T X)``, ``R_rel = R(t_open)^T R(tau)``, for sub-steps ``tau`` of the
/// exposure (at least 32,
/// refined until consecutive positions are closer than 0.25 px); the positions are splatted
/// bilinearly with equal weight and the kernel is cropped to the smallest odd square centred
/// on the origin that holds all weights above ``1e-4`` of the peak. Orientations between gyro
/// samples come from SLERP of the integrated rates.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 3.2 and eqs. 5-6.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import deblur
/// >>> t = np.linspace(0, 0.1, 21)
/// >>> gyro = np.column_stack([t, 0 * t, 0.3 + 0 * t, 0 * t])   # pure yaw, 0.3 rad/s
/// >>> k, origin = deblur.render_kernel(gyro, 0.0, 1 / 30, 600, 320, 240, 320, 240)
/// >>> cols = np.arange(k.shape[1]) - origin[1]
/// >>> round(float((k.sum(axis=0) * cols).sum()), 2)     # mean shift -f w t_e / 2
/// -3.0
#[pyfunction]
#[pyo3(signature = (gyro, t_frame, t_exposure, f, cx, cy, x, y, t_readout=0.0, t_delay=0.0,
                    height=None, r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn render_kernel<'py>(
    py: Python<'py>,
    gyro: &Bound<'py, PyAny>,
    t_frame: f64,
    t_exposure: f64,
    f: f64,
    cx: f64,
    cy: f64,
    x: f64,
    y: f64,
    t_readout: f64,
    t_delay: f64,
    height: Option<i128>,
    r_cam_imu: Option<&Bound<'py, PyAny>>,
    bias: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Arr<'py, f32>, (usize, usize))> {
    let samples = gyro_samples(gyro)?;
    let mut t = timing(t_frame, t_exposure, t_readout, t_delay, 1)?;
    t.height = match height {
        Some(h) => uint(py, "height", h, 1)?,
        None if t.t_readout > 0.0 => {
            return Err(value_error(
                "`height` (the frame's rows) is required when t_readout > 0",
            ))
        }
        None => 1,
    };
    let k = intrinsics(f, cx, cy)?;
    let p = (number("x", x)?, number("y", y)?);
    let tr = GyroTrack::new(&samples, rotation(r_cam_imu)?, self::bias(bias)?).py_err()?;
    let kern = crate::pool::detach(py, || {
        wscg_deblur::render_kernel(&tr, &t, &k, p, &KernelParams::default())
    })
    .py_err()?;
    kernel_out(py, kern)
}

/// Render the piecewise-uniform kernels of a ``height x width`` frame: one kernel per
/// ``tile x tile`` region, at the region's centre with its centre row's timing (paper
/// section 3, Fig. 3).
///
/// Parameters
/// ----------
/// gyro, t_frame, t_exposure, f, cx, cy, t_readout, t_delay, r_cam_imu, bias
///     As in :func:`render_kernel`.
/// height, width : int
///     Frame size in pixels (rows, columns: the array's axis order).
/// tile : int, default 30
///     Region side (the last row and column of regions may be narrower).
///
/// Returns
/// -------
/// kernels : float32 array (rows, cols, K, K)
///     ``rows = ceil(height / tile)``, ``cols = ceil(width / tile)``; every kernel is padded
///     with zeros to the common odd size ``K`` with its origin at the centre ``(K // 2,
///     K // 2)``.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 3.
///
/// Examples
/// --------
/// >>> from wscg import deblur
/// >>> gyro = deblur.make_gyro(0.5, seed=1)
/// >>> deblur.kernel_grid(gyro, 0.1, 0.03, 600, 74.5, 59.5, 120, 150).shape[:2]
/// (4, 5)
#[pyfunction]
#[pyo3(signature = (gyro, t_frame, t_exposure, f, cx, cy, height, width, tile=30,
                    t_readout=0.0, t_delay=0.0, r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn kernel_grid<'py>(
    py: Python<'py>,
    gyro: &Bound<'py, PyAny>,
    t_frame: f64,
    t_exposure: f64,
    f: f64,
    cx: f64,
    cy: f64,
    height: i128,
    width: i128,
    tile: i128,
    t_readout: f64,
    t_delay: f64,
    r_cam_imu: Option<&Bound<'py, PyAny>>,
    bias: Option<&Bound<'py, PyAny>>,
) -> PyResult<Arr<'py, f32>> {
    let samples = gyro_samples(gyro)?;
    let mut t = timing(t_frame, t_exposure, t_readout, t_delay, 1)?;
    let k = intrinsics(f, cx, cy)?;
    let width: usize = uint(py, "width", width, 1)?;
    t.height = uint(py, "height", height, 1)?;
    let tile: usize = uint(py, "tile", tile, 1)?;
    let tr = GyroTrack::new(&samples, rotation(r_cam_imu)?, self::bias(bias)?).py_err()?;
    let g = crate::pool::detach(py, || {
        wscg_deblur::kernel_grid(&tr, &t, &k, width, t.height, tile, &KernelParams::default())
    })
    .py_err()?;
    grid_out(py, &g)
}

/// Spatial standard deviation of a kernel's mass in pixels,
/// ``sqrt(sum_d k(d) |d - mean|^2)`` (paper section 5: the frame weight is
/// ``1 / max(sigma, 0.5)``). The kernel is normalised first; ``origin`` does not change the
/// result.
#[pyfunction]
#[pyo3(signature = (kernel, origin=None))]
fn blurriness(kernel: &Bound<'_, PyAny>, origin: Option<&Bound<'_, PyAny>>) -> PyResult<f64> {
    Ok(wscg_deblur::blurriness(&self::kernel(kernel, origin)?))
}

/// Standard deviation of white Gaussian noise in a (blurred) grayscale image.
///
/// Parameters
/// ----------
/// image : array (H, W)
///     At least 2 x 2 pixels, finite.
///
/// Returns
/// -------
/// sigma : float
///     ``median(|HH|) / 0.6745`` over the finest diagonal Haar wavelet coefficients
///     ``HH = (a - b - c + d) / 2`` of disjoint 2 x 2 blocks (an odd last row or column is
///     left out).
///
/// Notes
/// -----
/// Donoho's robust estimator: the unit-norm ``HH`` filter passes white noise unchanged and
/// leaves almost nothing of a blurred photograph; the median ignores the edges that leak
/// in. One pass over the image and a linear-time median (about 1 ms for 512 x 512).
/// ``lam="auto"`` in :func:`deconv_krishnan` uses ``0.3 / max(sigma, 0.001) ** 2``.
///
/// References
/// ----------
/// D. L. Donoho, "De-noising by soft-thresholding", IEEE Trans. Inf. Theory 41(3), 1995;
/// D. L. Donoho and I. M. Johnstone, Biometrika 81(3), 1994.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import deblur
/// >>> noise = np.random.default_rng(0).normal(0, 0.01, (256, 256))
/// >>> round(deblur.estimate_noise(0.5 + noise), 3)
/// 0.01
#[pyfunction]
fn estimate_noise(py: Python<'_>, image: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (img, _) = self::image("image", image)?;
    let s = crate::pool::detach(py, || wscg_deblur::estimate_noise(&img)).py_err()?;
    Ok(f64::from(s))
}

// ---------------------------------------------------------------- uniform-kernel deconvolution

/// Non-blind deconvolution with a hyper-Laplacian gradient prior (Krishnan & Fergus 2009).
///
/// Parameters
/// ----------
/// image : array (H, W)
///     Blurred image of **linear** intensities, nominally in ``[0, 1]``.
/// kernel : array (kh, kw)
///     Blur kernel, non-negative; normalised to sum 1.
/// origin : (int, int), optional
///     ``(row, col)`` of zero displacement; default ``(kh // 2, kw // 2)`` (as
///     ``scipy.ndimage.convolve`` and ``skimage.restoration`` centre a PSF).
/// lam : float or "auto", default "auto"
///     Data weight ``lambda`` for intensities in ``[0, 1]`` (> 0). ``"auto"`` derives it from
///     the input's noise level: ``0.3 / sigma**2`` with ``sigma`` from
///     :func:`estimate_noise` (sigma floored at 0.001). The paper uses Krishnan and Fergus's
///     fixed ``lam=2000``, which under-weights the data for mild noise (sigma 0.005: 1.9 dB
///     below ``"auto"`` on a photograph with an 11-pixel box blur, BENCHMARKS.md).
/// alpha : float, default 0.5
///     Gradient exponent in ``(0, 2]`` (the paper's 1/2; 1 = total variation, 2 = Gaussian).
/// beta_max : float, default 256
///     End of the continuation ``beta = 1, 2 sqrt 2, 8, ...`` (six steps for 256).
///
/// Returns
/// -------
/// restored : array (H, W)
///     float64 for float64 input, float32 otherwise; not clipped.
///
/// Notes
/// -----
/// Minimises ``lambda/2 ||k * I - B||^2 + sum |dx I|^alpha + |dy I|^alpha`` (paper eq. 7) by
/// half-quadratic splitting (eq. 8): per ``beta``, the exact per-pixel w-step
/// (:func:`w_step`, tabulated) and the closed-form I-step in the Fourier domain. The image is
/// extended by a mirrored margin of the kernel radius + 4 pixels and edge-tapered (MATLAB
/// ``edgetaper``) before the periodic solve, so borders do not ring.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, eqs. 7-8. D. Krishnan and R. Fergus,
/// "Fast image deconvolution using hyper-Laplacian priors", NIPS 2009.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import deblur
/// >>> sharp = deblur.make_scene(64, 64, seed=1)
/// >>> k = np.ones((1, 7)) / 7
/// >>> blurred = deblur.convolve(sharp, k)
/// >>> restored = deblur.deconv_krishnan(blurred, k)
/// >>> bool(np.abs(restored - sharp).mean() < np.abs(blurred - sharp).mean())
/// True
#[pyfunction]
#[pyo3(signature = (image, kernel, origin=None, lam=Lam::Name(String::from("auto")), alpha=0.5,
                    beta_max=256.0),
       text_signature = "(image, kernel, origin=None, lam=\"auto\", alpha=0.5, beta_max=256.0)")]
fn deconv_krishnan<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    kernel: &Bound<'py, PyAny>,
    origin: Option<&Bound<'py, PyAny>>,
    lam: Lam,
    alpha: f64,
    beta_max: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let (img, f64_out) = self::image("image", image)?;
    let k = self::kernel(kernel, origin)?;
    let alpha = alpha_arg(alpha)?;
    let p = hl_params(lam_arg(&lam)?, alpha, positive("beta_max", beta_max)?);
    let out = crate::pool::detach(py, || wscg_deblur::deconv_hl(&img, &k, &p)).py_err()?;
    image_out(py, out, f64_out)
}

/// Krishnan-Fergus deconvolution with a multi-frame quadratic prior (paper eq. 9).
///
/// Parameters
/// ----------
/// image : array (H, W)
///     Blurred linear-intensity image.
/// kernel, origin, lam, alpha, beta_max
///     As in :func:`deconv_krishnan`.
/// prior : array (H, W)
///     The weighted mean ``sum_j nu_j I_j`` of other estimates of the latent image (e.g.
///     deblurred, aligned neighbouring frames), linear intensities.
/// mu : float, default 250
///     Weight of the prior (>= 0; 0 gives :func:`deconv_krishnan`).
///
/// Returns
/// -------
/// restored : array (H, W), float64 for float64 input, float32 otherwise.
///
/// Notes
/// -----
/// Minimises eq. 7 plus ``mu/2 ||I - prior||^2``: the I-step of the half-quadratic splitting
/// gains ``(mu/beta) P^`` in its numerator and ``mu/beta`` in its denominator.
/// :func:`deblur_multiframe` solves this per region with per-region priors.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, eq. 9.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import deblur
/// >>> sharp = deblur.make_scene(48, 48, seed=1)
/// >>> k = np.ones((1, 5)) / 5
/// >>> out = deblur.deconv_krishnan_multi(deblur.convolve(sharp, k), k, sharp, mu=1e6)
/// >>> bool(np.abs(out - sharp).max() < 1e-2)
/// True
#[pyfunction]
#[pyo3(signature = (image, kernel, prior, mu=250.0, origin=None,
                    lam=Lam::Name(String::from("auto")), alpha=0.5, beta_max=256.0),
       text_signature = "(image, kernel, prior, mu=250.0, origin=None, lam=\"auto\", alpha=0.5, \
                         beta_max=256.0)")]
#[allow(clippy::too_many_arguments)]
fn deconv_krishnan_multi<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    kernel: &Bound<'py, PyAny>,
    prior: &Bound<'py, PyAny>,
    mu: f64,
    origin: Option<&Bound<'py, PyAny>>,
    lam: Lam,
    alpha: f64,
    beta_max: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let (img, f64_out) = self::image("image", image)?;
    let (pr, _) = self::image("prior", prior)?;
    if pr.shape() != img.shape() {
        return Err(value_error(format!(
            "shape mismatch: `image` has shape {:?}, `prior` {:?}",
            (img.height(), img.width()),
            (pr.height(), pr.width())
        )));
    }
    let k = self::kernel(kernel, origin)?;
    let alpha = alpha_arg(alpha)?;
    let mu = non_negative("mu", mu)? as f32;
    let p = hl_params(lam_arg(&lam)?, alpha, positive("beta_max", beta_max)?);
    let out =
        crate::pool::detach(py, || wscg_deblur::deconv_hl_multi(&img, &k, &pr, mu, &p)).py_err()?;
    image_out(py, out, f64_out)
}

/// Wiener deconvolution ``I^ = K^* B^ / (|K|^2 + nsr)`` (the paper's "W" baseline).
///
/// Parameters
/// ----------
/// image : array (H, W)
///     Blurred linear-intensity image.
/// kernel, origin
///     As in :func:`deconv_krishnan`.
/// nsr : float, default 0.01
///     Noise-to-signal ratio (> 0); ``skimage.restoration.wiener``'s ``balance`` with
///     ``reg`` the identity.
///
/// Returns
/// -------
/// restored : array (H, W), float64 for float64 input, float32 otherwise.
///
/// Notes
/// -----
/// Unlike ``skimage.restoration.wiener`` (periodic image), the image is extended by a
/// mirrored margin and edge-tapered first, as in :func:`deconv_krishnan`.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, Table 1.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import deblur
/// >>> deblur.wiener(np.full((32, 32), 0.5), np.ones((3, 3))).shape
/// (32, 32)
#[pyfunction]
#[pyo3(signature = (image, kernel, origin=None, nsr=0.01))]
fn wiener<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    kernel: &Bound<'py, PyAny>,
    origin: Option<&Bound<'py, PyAny>>,
    nsr: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let (img, f64_out) = self::image("image", image)?;
    let k = self::kernel(kernel, origin)?;
    let nsr = positive("nsr", nsr)? as f32;
    let out = crate::pool::detach(py, || wscg_deblur::wiener(&img, &k, nsr)).py_err()?;
    image_out(py, out, f64_out)
}

/// Richardson-Lucy deconvolution ``I <- I . k^T (B / (k * I))`` from ``I = max(B, 0)``
/// (the paper's "RL" baseline, 30 iterations).
///
/// Parameters
/// ----------
/// image : array (H, W)
///     Blurred linear-intensity image (negative values are treated as 0).
/// kernel, origin
///     As in :func:`deconv_krishnan`.
/// n_iter : int, default 30
///     Iterations (>= 1); ``skimage.restoration.richardson_lucy``'s ``num_iter``.
///
/// Returns
/// -------
/// restored : array (H, W), float64 for float64 input, float32 otherwise; not clipped.
///
/// Notes
/// -----
/// The convolutions are periodic on the image extended by a mirrored margin and
/// edge-tapered, where scikit-image convolves with zero padding.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, Table 1.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import deblur
/// >>> deblur.richardson_lucy(np.full((32, 32), 0.5), np.ones((1, 5)), n_iter=5).shape
/// (32, 32)
#[pyfunction]
#[pyo3(signature = (image, kernel, origin=None, n_iter=30))]
fn richardson_lucy<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    kernel: &Bound<'py, PyAny>,
    origin: Option<&Bound<'py, PyAny>>,
    n_iter: i128,
) -> PyResult<Bound<'py, PyAny>> {
    let (img, f64_out) = self::image("image", image)?;
    let k = self::kernel(kernel, origin)?;
    let n_iter: usize = uint(py, "n_iter", n_iter, 1)?;
    let out = crate::pool::detach(py, || wscg_deblur::richardson_lucy(&img, &k, n_iter))
        .py_err_renamed(&[("iters", "n_iter")])?;
    image_out(py, out, f64_out)
}

/// The forward model ``B(x) = sum_d k(d) I(x - d)`` on the image extended by a mirrored
/// margin (``scipy.ndimage.convolve(image, kernel, mode="reflect")`` for a centred kernel,
/// up to float32 rounding). Returns float64 for float64 input, float32 otherwise.
#[pyfunction]
#[pyo3(signature = (image, kernel, origin=None))]
fn convolve<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    kernel: &Bound<'py, PyAny>,
    origin: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (img, f64_out) = self::image("image", image)?;
    let k = self::kernel(kernel, origin)?;
    let out = crate::pool::detach(py, || wscg_deblur::tiling::convolve(&img, &k)).py_err()?;
    image_out(py, out, f64_out)
}

// ---------------------------------------------------------------- frames

/// Valid `method` names of `deblur_piecewise` (`wscg.deblur.METHODS`).
const METHODS: [&str; 4] = ["krishnan", "wiener", "rl", "global"];

/// Deblur one frame region by region with its gyroscope kernels (paper sections 3-4).
///
/// Parameters
/// ----------
/// frame : array (H, W)
///     Blurred frame of **linear** intensities (linearise display values first, e.g.
///     ``frame ** 2.2``).
/// gyro, t_frame, t_exposure, f, cx, cy, t_readout, t_delay, r_cam_imu, bias
///     As in :func:`render_kernel`; the frame height is ``H``.
/// method : {"krishnan", "wiener", "rl", "global"}, default "krishnan"
///     Per-region solver: Krishnan-Fergus ("KS" of Table 1), Wiener ("W"), Richardson-Lucy
///     ("RL"), or Krishnan-Fergus on the whole frame with the kernel of the frame centre
///     ("global", the uniform-blur assumption of blind tools).
/// tile : int, default 30
///     Region side in pixels (> 8).
/// lam, alpha : float (lam also "auto")
///     Krishnan-Fergus parameters (see :func:`deconv_krishnan`); the paper's ``lam=2000`` by
///     default. ``lam="auto"`` estimates the noise once on the whole frame; on gyro-estimated
///     kernels it lost 0.03-2.1 dB against 2000 (the kernels' errors are not in the noise
///     estimate; BENCHMARKS.md).
/// nsr : float, default 0.03
///     Wiener noise-to-signal ratio.
/// rl_n_iter : int, default 20
///     Richardson-Lucy iterations (``method="rl"``).
/// return_kernels : bool, default False
///     Also return the region kernels as :func:`kernel_grid` does.
///
/// Returns
/// -------
/// restored : array (H, W)
///     float64 for float64 input, float32 otherwise; not clipped.
/// kernels : float32 array (rows, cols, K, K), when ``return_kernels``.
///
/// Notes
/// -----
/// Each region is solved on a window of the region plus a margin of at least
/// ``max(8, kernel radius + 4)`` pixels (mirrored at the frame border, FFT-friendly size),
/// edge-tapered; the solved regions are blended with linear ramps over 4 pixels across
/// region borders (a partition of unity, so no seams).
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 4 and Fig. 3.
///
/// Examples
/// --------
/// >>> from wscg import deblur
/// >>> gyro = deblur.make_gyro(0.5, seed=2)
/// >>> sharp = deblur.make_scene(90, 120, seed=2)
/// >>> b = deblur.render_blurred(sharp, gyro, 0.1, 0.03, 600, 59.5, 44.5, 0.1,
/// ...                                 gamma=None, quantise=False)
/// >>> deblur.deblur_piecewise(b, gyro, 0.1, 0.03, 600, 59.5, 44.5).shape
/// (90, 120)
#[pyfunction]
#[pyo3(signature = (frame, gyro, t_frame, t_exposure, f, cx, cy, t_readout=0.0, t_delay=0.0,
                    method="krishnan", tile=30, lam=Lam::Value(2000.0), alpha=0.5, nsr=0.03,
                    rl_n_iter=20, r_cam_imu=None, bias=None, return_kernels=false),
       text_signature = "(frame, gyro, t_frame, t_exposure, f, cx, cy, t_readout=0.0, \
                         t_delay=0.0, method=\"krishnan\", tile=30, lam=2000.0, alpha=0.5, \
                         nsr=0.03, rl_n_iter=20, r_cam_imu=None, bias=None, \
                         return_kernels=False)")]
#[allow(clippy::too_many_arguments)]
fn deblur_piecewise<'py>(
    py: Python<'py>,
    frame: &Bound<'py, PyAny>,
    gyro: &Bound<'py, PyAny>,
    t_frame: f64,
    t_exposure: f64,
    f: f64,
    cx: f64,
    cy: f64,
    t_readout: f64,
    t_delay: f64,
    method: &str,
    tile: i128,
    lam: Lam,
    alpha: f64,
    nsr: f64,
    rl_n_iter: i128,
    r_cam_imu: Option<&Bound<'py, PyAny>>,
    bias: Option<&Bound<'py, PyAny>>,
    return_kernels: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (img, f64_out) = self::image("frame", frame)?;
    let samples = gyro_samples(gyro)?;
    if !METHODS.contains(&method) {
        return Err(value_error(format!(
            "{method:?} is not a valid method. Valid methods are 'krishnan', 'wiener', \
             'rl', 'global'"
        )));
    }
    let alpha = alpha_arg(alpha)?;
    let t = timing(t_frame, t_exposure, t_readout, t_delay, img.height())?;
    let k = intrinsics(f, cx, cy)?;
    let tile: usize = uint(py, "tile", tile, 1)?;
    let hl = hl_params(lam_arg(&lam)?, alpha, 256.0);
    let nsr = positive("nsr", nsr)? as f32;
    let rl_n_iter: usize = uint(py, "rl_n_iter", rl_n_iter, 1)?;
    let tr = GyroTrack::new(&samples, rotation(r_cam_imu)?, self::bias(bias)?).py_err()?;
    let m = match Method::by_name(method).py_err()? {
        Method::Wiener { .. } => Method::Wiener { nsr },
        Method::RichardsonLucy { .. } => Method::RichardsonLucy { iters: rl_n_iter },
        Method::HyperLaplacian(_) => Method::HyperLaplacian(hl),
        Method::GlobalUniform(_) => Method::GlobalUniform(hl),
    };
    let tiling = Tiling {
        tile,
        ..Default::default()
    };
    tiling.validate().py_err()?;
    let (out, grid) = crate::pool::detach(py, || {
        let grid = wscg_deblur::kernel_grid(
            &tr,
            &t,
            &k,
            img.width(),
            img.height(),
            tile,
            &KernelParams::default(),
        )?;
        let out = wscg_deblur::deblur_piecewise(&img, &grid, &m, &tiling)?;
        Ok((out, grid))
    })
    .py_err_renamed(&[("iters", "rl_n_iter")])?;
    let out = image_out(py, out, f64_out)?;
    if return_kernels {
        Ok((out, grid_out(py, &grid)?).into_pyobject(py)?.into_any())
    } else {
        Ok(out)
    }
}

/// `wscg.deblur.deblur_multiframe`'s work, on its arguments as given (the Python function
/// issues the warnings and builds its `MultiframeDeblur` from the fields returned).
#[pyfunction]
#[pyo3(signature = (frames, frame_times, gyro, f, cx, cy, t_exposure, t_readout, t_delay, main,
                    mu, lam, alpha, gamma, align, min_ncc, temporal_radius, tile, r_cam_imu,
                    bias))]
#[allow(clippy::too_many_arguments)]
fn deblur_multiframe<'py>(
    py: Python<'py>,
    frames: Vec<Bound<'py, PyAny>>,
    frame_times: &Bound<'py, PyAny>,
    gyro: &Bound<'py, PyAny>,
    f: f64,
    cx: f64,
    cy: f64,
    t_exposure: f64,
    t_readout: f64,
    t_delay: f64,
    main: Option<i128>,
    mu: f64,
    lam: Lam,
    alpha: f64,
    gamma: Option<f64>,
    align: &str,
    min_ncc: f64,
    temporal_radius: Option<i128>,
    tile: i128,
    r_cam_imu: Option<&Bound<'py, PyAny>>,
    bias: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    if frames.is_empty() {
        return Err(value_error("`frames` is empty: need at least one frame"));
    }
    let imgs = frames
        .iter()
        .enumerate()
        .map(|(i, fr)| display(&format!("frames[{i}]"), fr))
        .collect::<PyResult<Vec<_>>>()?;
    if let Some((i, im)) = imgs
        .iter()
        .enumerate()
        .find(|(_, im)| im.shape() != imgs[0].shape())
    {
        return Err(value_error(format!(
            "frames differ in size: frames[0] is {:?}, frames[{i}] is {:?}",
            (imgs[0].height(), imgs[0].width()),
            (im.height(), im.width())
        )));
    }
    let n = imgs.len();
    let times = args::array::<f64>("frame_times", frame_times)?;
    let times = values(&times);
    if times.len() != n {
        return Err(value_error(format!(
            "`frame_times` must hold one time per frame: {n} frames, {} times",
            times.len()
        )));
    }
    if times.iter().any(|t| !t.is_finite()) {
        return Err(value_error("`frame_times` contains a non-finite value"));
    }
    let main = main.unwrap_or((n / 2) as i128);
    if !(0..n as i128).contains(&main) {
        return Err(value_error(format!(
            "`main` = {main} is out of range for {n} frames"
        )));
    }
    let align = match align {
        "ecc" => AlignMode::Ecc(AlignParams::default()),
        "gyro" => AlignMode::Gyro,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid align mode. Valid modes are 'ecc', 'gyro'"
            )))
        }
    };
    let alpha = alpha_arg(alpha)?;
    let mu = non_negative("mu", mu)? as f32;
    let gamma = gamma
        .map(|g| positive("gamma", g).map(|g| Gamma(g as f32)))
        .transpose()?;
    let radius = temporal_radius
        .map(|r| uint(py, "temporal_radius", r, 0))
        .transpose()?;
    let t = timing(0.0, t_exposure, t_readout, t_delay, 1)?;
    let tr = track(gyro, r_cam_imu, bias)?;
    let k = intrinsics(f, cx, cy)?;
    let hl = hl_params(lam_arg(&lam)?, alpha, 256.0);
    let tile: usize = uint(py, "tile", tile, 1)?;
    let inputs: Vec<FrameInput> = imgs
        .into_iter()
        .zip(times.iter())
        .map(|(image, &t)| FrameInput { image, t })
        .collect();
    let opts = MultiframeParams::default()
        .t_exposure(t.t_exposure)
        .t_readout(t.t_readout)
        .t_delay(t.t_delay)
        .gamma(gamma)
        .tiling(Tiling {
            tile,
            ..Default::default()
        })
        .hl(hl)
        .mu(mu)
        .align(align)
        .min_ncc(number("min_ncc", min_ncc)?)
        .radius(radius);
    let main = main as usize;
    let out = crate::pool::detach(py, || {
        wscg_deblur::deblur_multiframe(&inputs, main, &tr, &k, &opts, &NoProgress)
    })
    .py_err()?;
    let d = PyDict::new(py);
    let (rows, cols, nf) = (out.kernels.rows, out.kernels.cols, out.frames);
    d.set_item("kernels", grid_out(py, &out.kernels)?)?;
    d.set_item("weights", array(py, &[rows, cols, nf], out.weights)?)?;
    d.set_item("image", crate::convert::image_array(py, out.image, true)?)?;
    d.set_item("single", crate::convert::image_array(py, out.single, true)?)?;
    d.set_item("used_frames", out.used_frames)?;
    d.set_item("warnings", out.warnings)?;
    Ok(d)
}

/// Warp a rolling-shutter frame to a virtual global shutter at the opening of its middle
/// row (Karpenko et al. 2011; paper section 5).
///
/// Parameters
/// ----------
/// frame : array (H, W)
///     The frame (any intensity scale; bilinear resampling).
/// gyro, t_frame, t_exposure, t_readout, t_delay, f, cx, cy, r_cam_imu, bias
///     As in :func:`render_kernel`; the frame height is ``H``.
///
/// Returns
/// -------
/// rectified : array (H, W), float64 for float64 input, float32 otherwise. Pixels mapping
///     outside the frame take the nearest border value. ``t_readout = 0`` returns a copy.
///
/// Notes
/// -----
/// Output pixel ``p`` samples the frame at ``q = pi(K R(t(y))^T R(t_ref) K^-1 p)`` where
/// the row ``y`` of ``q`` decides its time ``t(y)``, found by three fixed-point steps.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 5. A. Karpenko et al.,
/// Stanford CS Tech Report CSTR 2011-03.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import deblur
/// >>> t = np.linspace(0, 0.2, 41)
/// >>> gyro = np.column_stack([t, 0 * t, 1.0 + 0 * t, 0 * t])
/// >>> deblur.rectify_rolling_shutter(np.zeros((40, 50)), gyro, 0.05, 0.01, 0.025, 0.0,
/// ...                                600, 24.5, 19.5).shape
/// (40, 50)
#[pyfunction]
#[pyo3(signature = (frame, gyro, t_frame, t_exposure, t_readout, t_delay, f, cx, cy,
                    r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn rectify_rolling_shutter<'py>(
    py: Python<'py>,
    frame: &Bound<'py, PyAny>,
    gyro: &Bound<'py, PyAny>,
    t_frame: f64,
    t_exposure: f64,
    t_readout: f64,
    t_delay: f64,
    f: f64,
    cx: f64,
    cy: f64,
    r_cam_imu: Option<&Bound<'py, PyAny>>,
    bias: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (img, f64_out) = self::image("frame", frame)?;
    let tr = track(gyro, r_cam_imu, bias)?;
    let t = timing(t_frame, t_exposure, t_readout, t_delay, img.height())?;
    let k = intrinsics(f, cx, cy)?;
    let out = crate::pool::detach(py, || {
        wscg_deblur::rectify_rolling_shutter(&img, &tr, &t, &k)
    })
    .py_err()?;
    image_out(py, out, f64_out)
}

/// Translation ``(dx, dy)`` taking image ``a`` to image ``b`` (``b(x) ~ a(x - d)``) by
/// phase correlation with a Hann window and a parabolic sub-pixel peak.
///
/// Parameters
/// ----------
/// a, b : array (H, W)
///     Images of the same shape.
///
/// Returns
/// -------
/// dx, dy : float
///     Shift in pixels (columns, rows), each within half the image size.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 3.1.
///
/// Examples
/// --------
/// >>> import numpy as np
/// >>> from wscg import deblur
/// >>> a = deblur.make_scene(64, 64, seed=4)
/// >>> dx, dy = deblur.phase_correlation(a, np.roll(a, (2, 5), axis=(0, 1)))
/// >>> round(dx), round(dy)
/// (5, 2)
#[pyfunction]
fn phase_correlation(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
) -> PyResult<(f64, f64)> {
    let (ia, _) = self::image("a", a)?;
    let (ib, _) = self::image("b", b)?;
    if ia.shape() != ib.shape() {
        return Err(value_error(format!(
            "shape mismatch: `a` has shape {:?}, `b` {:?}",
            (ia.height(), ia.width()),
            (ib.height(), ib.width())
        )));
    }
    crate::pool::detach(py, || wscg_deblur::phase_correlation(&ia, &ib)).py_err()
}

/// Estimate the gyroscope-camera delay ``t_d`` (paper section 3.1).
///
/// Parameters
/// ----------
/// gyro : array (N, 4)
///     Gyroscope samples.
/// frame_times : sequence of float, length M >= 3
///     Frame time stamps.
/// shifts : array (M - 1, 2)
///     Measured image shift ``(dx, dy)`` from frame ``i`` to frame ``i + 1``, e.g. from
///     :func:`phase_correlation`.
/// t_exposure, t_readout : float
///     Exposure and readout times (s).
/// f, cx, cy : float
///     Intrinsics in pixels.
/// lo, hi : float
///     Search range of the delay (s).
/// step : float, default 2.5e-4
///     Grid step of the search (s); the best candidate is refined by a parabola.
///
/// Returns
/// -------
/// t_delay : float
///     The delay minimising the squared difference between the measured shifts and those
///     the gyroscope predicts at the principal point between the frames' mid-exposure poses.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, section 3.1.
#[pyfunction]
#[pyo3(signature = (gyro, frame_times, shifts, t_exposure, t_readout, f, cx, cy, lo, hi,
                    step=2.5e-4, r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn estimate_time_delay(
    py: Python<'_>,
    gyro: &Bound<'_, PyAny>,
    frame_times: &Bound<'_, PyAny>,
    shifts: &Bound<'_, PyAny>,
    t_exposure: f64,
    t_readout: f64,
    f: f64,
    cx: f64,
    cy: f64,
    lo: f64,
    hi: f64,
    step: f64,
    r_cam_imu: Option<&Bound<'_, PyAny>>,
    bias: Option<&Bound<'_, PyAny>>,
) -> PyResult<f64> {
    let times = args::array::<f64>("frame_times", frame_times)?;
    let times = values(&times).into_owned();
    let s = args::real_array("shifts", shifts)?;
    let s = args::array::<f64>("shifts", s.as_any())?;
    let m = match *s.shape() {
        [m, 2] => m,
        ref sh => {
            return Err(value_error(format!(
                "`shifts` must have shape (M - 1, 2) with rows (dx, dy), got {sh:?}"
            )))
        }
    };
    if m + 1 != times.len() {
        return Err(value_error(format!(
            "{} frame times need {} shifts, got {m}",
            times.len(),
            times.len().saturating_sub(1)
        )));
    }
    let sv = values(&s);
    if !(sv.iter().chain(&times).all(|v| v.is_finite())) {
        return Err(value_error("`shifts` and `frame_times` must be finite"));
    }
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Err(value_error(format!(
            "need a finite search range lo < hi, got ({lo}, {hi})"
        )));
    }
    // The shift prediction uses the opening of the middle row, `t_d + t_r / 2`: the frame
    // height cancels, any positive height gives the same timing.
    let t = timing(0.0, t_exposure, t_readout, 0.0, 1)?;
    let tr = track(gyro, r_cam_imu, bias)?;
    let k = intrinsics(f, cx, cy)?;
    let step = positive("step", step)?;
    let sh: Vec<(f64, f64)> = sv.chunks_exact(2).map(|r| (r[0], r[1])).collect();
    crate::pool::detach(py, || {
        wscg_deblur::estimate_time_delay(&tr, &times, &sh, &t, &k, (lo, hi), step)
    })
    .py_err()
}

/// Exact minimiser of ``|w|^alpha + beta/2 (w - v)^2`` for every element of ``v`` (the
/// w-subproblem of Krishnan & Fergus, paper eq. 8).
///
/// Parameters
/// ----------
/// v : array_like
///     Values (any shape, finite).
/// alpha : float
///     Exponent in ``(0, 2]``.
/// beta : float
///     Penalty weight (> 0).
///
/// Returns
/// -------
/// w : float64 array of ``v``'s shape.
///
/// Notes
/// -----
/// ``alpha = 1`` is soft thresholding at ``1/beta``; ``alpha = 2`` is ``beta v / (2 + beta)``;
/// for ``alpha < 1`` the non-zero stationary point is found by Newton's method from
/// ``w = v`` (it covers the cubic of ``alpha = 1/2`` and the quartic of ``2/3`` without
/// spurious roots) and compared with ``w = 0``; ties go to 0.
///
/// References
/// ----------
/// Sörös et al., WSCG 2015, Journal of WSCG vol. 23, eq. 8. D. Krishnan and R. Fergus,
/// NIPS 2009.
///
/// Examples
/// --------
/// >>> from wscg import deblur
/// >>> deblur.w_step([-2.0, 0.5, 2.0], alpha=1.0, beta=1.0).tolist()
/// [-1.0, 0.0, 1.0]
#[pyfunction]
fn w_step<'py>(
    py: Python<'py>,
    v: &Bound<'py, PyAny>,
    alpha: f64,
    beta: f64,
) -> PyResult<Arr<'py, f64>> {
    let a = args::real_array("v", v)?;
    let a = args::array::<f64>("v", a.as_any())?;
    let shape = a.shape().to_vec();
    let data = values(&a);
    if data.iter().any(|x| !x.is_finite()) {
        return Err(value_error(
            "`v` contains a non-finite value (NaN or infinity)",
        ));
    }
    let alpha = alpha_arg(alpha)?;
    let beta = positive("beta", beta)?;
    let out: Vec<f64> = crate::pool::detach(py, || {
        data.iter()
            .map(|&x| wscg_deblur::wstep::w_exact(x, alpha, beta))
            .collect()
    })?;
    array(py, &shape, out)
}

// ---------------------------------------------------------------- synthetic data

/// A synthetic hand-shake gyroscope trace: Ornstein-Uhlenbeck angular rates per camera
/// axis (exact discretisation, started from the stationary distribution), noise-free.
///
/// Parameters
/// ----------
/// duration : float
///     Length of the trace (s); ``ceil(duration * rate) + 1`` samples from ``t0``.
/// rate : float, default 200
///     Sampling rate (Hz; the paper's phone gyroscope).
/// tau : float, default 0.05
///     Correlation time (s).
/// std : (float, float, float), default (0.35, 0.35, 0.10)
///     Stationary standard deviation of the pitch, yaw and roll rates (rad/s).
/// t0 : float, default 0
///     Time of the first sample.
/// seed : int, default 0
///
/// Returns
/// -------
/// gyro : float64 array (N, 4) of rows ``(t, wx, wy, wz)``.
#[pyfunction]
#[pyo3(signature = (duration, rate=200.0, tau=0.05, std=[0.35, 0.35, 0.10], t0=0.0, seed=0),
       text_signature = "(duration, rate=200.0, tau=0.05, std=(0.35, 0.35, 0.1), t0=0.0, \
                         seed=0)")]
fn make_gyro<'py>(
    py: Python<'py>,
    duration: f64,
    rate: f64,
    tau: f64,
    std: [f64; 3],
    t0: f64,
    seed: i128,
) -> PyResult<Arr<'py, f64>> {
    if !std.iter().all(|v| v.is_finite() && *v >= 0.0) {
        return Err(value_error(format!(
            "`std` must be 3 finite deviations >= 0 (rad/s), got {std:?}"
        )));
    }
    let p = ShakeParams::default()
        .rate(positive("rate", rate)?)
        .tau(positive("tau", tau)?)
        .std(std)
        .t0(number("t0", t0)?)
        .duration(positive("duration", duration)?);
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let s = crate::pool::detach(py, || synth::ou_gyro(&p, seed)).py_err()?;
    samples_out(py, &s)
}

/// ``gyro`` with white Gaussian noise of standard deviation ``sigma`` (rad/s) added to
/// every rate (time stamps unchanged).
#[pyfunction]
#[pyo3(signature = (gyro, sigma=0.002, seed=0))]
fn add_gyro_noise<'py>(
    py: Python<'py>,
    gyro: &Bound<'py, PyAny>,
    sigma: f64,
    seed: i128,
) -> PyResult<Arr<'py, f64>> {
    let sigma = non_negative("sigma", sigma)?;
    let s = gyro_samples(gyro)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let out = crate::pool::detach(py, || synth::add_gyro_noise(&s, sigma, seed)).py_err()?;
    samples_out(py, &out)
}

/// Render a blurred frame of a planar scene densely (eq. 2 with the homography of eq. 5).
///
/// Parameters
/// ----------
/// sharp : array (H, W)
///     Linear sharp image seen in the camera pose at gyroscope time ``t_world``.
/// gyro, t_frame, t_exposure, f, cx, cy, t_readout, t_delay, r_cam_imu, bias
///     As in :func:`render_kernel`; the frame height is ``H``.
/// t_world : float
///     Gyroscope time of the ground-truth pose. The deblurring functions restore the
///     pose of the shutter opening, ``t_frame + t_delay`` (plus ``t_readout / 2`` for
///     :func:`deblur_multiframe`, which rectifies to the middle row).
/// noise_sigma : float, default 0.005
///     Gaussian noise added to the linear image.
/// gamma : float or None, default 2.2
///     Camera response applied after the noise (display = linear ** (1 / gamma)),
///     ``None`` keeps linear values (clipped to [0, 1]).
/// quantise : bool, default True
///     Round to 8-bit levels (multiples of 1/255).
/// seed : int, default 0
///     Noise seed.
///
/// Returns
/// -------
/// frame : float32 array (H, W) in [0, 1].
///
/// Notes
/// -----
/// Row ``y`` averages, over at least 64 time sub-steps of its exposure (more when the
/// image moves by more than half a pixel per step), the sharp image warped by
/// ``K R(t_world)^T R(tau) K^-1`` (bicubic, borders replicated).
#[pyfunction]
#[pyo3(signature = (sharp, gyro, t_frame, t_exposure, f, cx, cy, t_world, t_readout=0.0,
                    t_delay=0.0, noise_sigma=0.005, gamma=Some(2.2), quantise=true, seed=0,
                    r_cam_imu=None, bias=None),
       text_signature = "(sharp, gyro, t_frame, t_exposure, f, cx, cy, t_world, \
                         t_readout=0.0, t_delay=0.0, noise_sigma=0.005, gamma=2.2, \
                         quantise=True, seed=0, r_cam_imu=None, bias=None)")]
#[allow(clippy::too_many_arguments)]
fn render_blurred<'py>(
    py: Python<'py>,
    sharp: &Bound<'py, PyAny>,
    gyro: &Bound<'py, PyAny>,
    t_frame: f64,
    t_exposure: f64,
    f: f64,
    cx: f64,
    cy: f64,
    t_world: f64,
    t_readout: f64,
    t_delay: f64,
    noise_sigma: f64,
    gamma: Option<f64>,
    quantise: bool,
    seed: i128,
    r_cam_imu: Option<&Bound<'py, PyAny>>,
    bias: Option<&Bound<'py, PyAny>>,
) -> PyResult<Arr<'py, f32>> {
    let (img, _) = self::image("sharp", sharp)?;
    let noise_sigma = non_negative("noise_sigma", noise_sigma)? as f32;
    let gamma = gamma
        .map(|g| positive("gamma", g).map(|g| Gamma(g as f32)))
        .transpose()?;
    if let Some(g) = gamma {
        g.validate().py_err()?;
    }
    let t_world = finite("t_world", t_world)?;
    let tr = track(gyro, r_cam_imu, bias)?;
    let t = timing(t_frame, t_exposure, t_readout, t_delay, img.height())?;
    let k = intrinsics(f, cx, cy)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let opts = BlurRenderParams::default()
        .noise_sigma(noise_sigma)
        .gamma(gamma)
        .quantise(quantise);
    let out = crate::pool::detach(py, || {
        synth::render_blurred(&img, &tr, &t, &k, t_world, &opts, seed)
    })
    .py_err()?;
    crate::convert::image_array(py, out, true)
}

/// A textured test scene of linear intensities in [0.02, 0.98] (smooth blobs,
/// sharp-edged discs and bars, fine stripes): float32 ``(height, width)``.
#[pyfunction]
#[pyo3(signature = (height, width, seed=0))]
fn make_scene(py: Python<'_>, height: i128, width: i128, seed: i128) -> PyResult<Arr<'_, f32>> {
    let height: usize = uint(py, "height", height, 1)?;
    let width: usize = uint(py, "width", width, 1)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let img = crate::pool::detach(py, || synth::scene(height, width, seed)).py_err()?;
    crate::convert::image_array(py, img, true)
}

/// Registers the submodule's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(render_kernel, m)?)?;
    m.add_function(wrap_pyfunction!(kernel_grid, m)?)?;
    m.add_function(wrap_pyfunction!(blurriness, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_noise, m)?)?;
    m.add_function(wrap_pyfunction!(deconv_krishnan, m)?)?;
    m.add_function(wrap_pyfunction!(deconv_krishnan_multi, m)?)?;
    m.add_function(wrap_pyfunction!(wiener, m)?)?;
    m.add_function(wrap_pyfunction!(richardson_lucy, m)?)?;
    m.add_function(wrap_pyfunction!(convolve, m)?)?;
    m.add_function(wrap_pyfunction!(deblur_piecewise, m)?)?;
    m.add_function(wrap_pyfunction!(deblur_multiframe, m)?)?;
    m.add_function(wrap_pyfunction!(rectify_rolling_shutter, m)?)?;
    m.add_function(wrap_pyfunction!(phase_correlation, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_time_delay, m)?)?;
    m.add_function(wrap_pyfunction!(w_step, m)?)?;
    m.add_function(wrap_pyfunction!(make_gyro, m)?)?;
    m.add_function(wrap_pyfunction!(add_gyro_noise, m)?)?;
    m.add_function(wrap_pyfunction!(render_blurred, m)?)?;
    m.add_function(wrap_pyfunction!(make_scene, m)?)?;
    Ok(())
}
