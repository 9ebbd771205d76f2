//! `wscg._native.deblur`: bindings of `wscg-deblur` (paper 12, gyroscope-driven multi-frame
//! blur estimation and removal). The documented API is `python/wscg/deblur.py`, which passes
//! C-contiguous float32 images and float64 gyroscope arrays.

use nalgebra::{Matrix3, Rotation3};
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_deblur::synth::{self, BlurRenderParams, ShakeParams};
use wscg_deblur::{
    AlignMode, AlignParams, FrameInput, Gamma, GyroSample, GyroTrack, HyperLaplacianParams,
    Intrinsics, Kernel, KernelGrid, KernelParams, Method, MultiframeParams, Tiling, Timing,
};
use wscg_math::progress::NoProgress;
use wscg_math::Image;

use crate::convert::{array, dims2, values, Arr};
use crate::errors::{value_error, IntoPy, IntoPyRenamed};

/// Camera intrinsics `(f, cx, cy)` in pixels.
type Cam = (f64, f64, f64);
/// Frame timing `(t_frame, t_exposure, t_readout, t_delay)` in seconds.
type Tim = (f64, f64, f64, f64);

fn intrinsics(c: Cam) -> Intrinsics {
    Intrinsics {
        f: c.0,
        cx: c.1,
        cy: c.2,
    }
}

fn timing(t: Tim, height: usize) -> Timing {
    Timing {
        t_frame: t.0,
        t_exposure: t.1,
        t_readout: t.2,
        t_delay: t.3,
        height,
    }
}

/// Samples of an `(N, 4)` array of rows `(t, wx, wy, wz)`.
fn samples_in(gyro: &PyReadonlyArrayDyn<f64>) -> PyResult<Vec<GyroSample>> {
    match *gyro.shape() {
        [_, 4] => {}
        ref s => {
            return Err(value_error(format!(
                "`gyro` must have shape (N, 4) with rows (t, wx, wy, wz), got {s:?}"
            )))
        }
    }
    Ok(values(gyro)
        .chunks_exact(4)
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

/// The camera-from-IMU rotation: a `(3, 3)` rotation matrix (orthonormal, determinant 1).
fn rotation_in(r: Option<&PyReadonlyArrayDyn<f64>>) -> PyResult<Rotation3<f64>> {
    let Some(r) = r else {
        return Ok(Rotation3::identity());
    };
    if r.shape() != [3, 3] {
        return Err(value_error(format!(
            "`r_cam_imu` must be a (3, 3) rotation matrix, got shape {:?}",
            r.shape()
        )));
    }
    let m = Matrix3::from_row_slice(&values(r));
    if !m.iter().all(|v| v.is_finite()) {
        return Err(value_error("`r_cam_imu` contains a non-finite value"));
    }
    let err = (m.transpose() * m - Matrix3::identity()).abs().max();
    if err > 1e-6 || (m.determinant() - 1.0).abs() > 1e-6 {
        return Err(value_error(format!(
            "`r_cam_imu` must be a rotation (orthonormal with determinant +1); |R^T R - I| = {err:.3e}, det = {:.6}",
            m.determinant()
        )));
    }
    Ok(Rotation3::from_matrix_unchecked(m))
}

/// The integrated gyroscope trace.
fn track_in(
    gyro: &PyReadonlyArrayDyn<f64>,
    r_cam_imu: Option<&PyReadonlyArrayDyn<f64>>,
    bias: Option<(f64, f64, f64)>,
) -> PyResult<GyroTrack> {
    let samples = samples_in(gyro)?;
    let r = rotation_in(r_cam_imu)?;
    let b = bias.map_or([0.0; 3], |b| [b.0, b.1, b.2]);
    GyroTrack::new(&samples, r, b).py_err()
}

/// A `(H, W)` float32 array as a single-channel image.
fn image_in(name: &str, a: &PyReadonlyArrayDyn<f32>) -> PyResult<Image<f32>> {
    let (h, w) = dims2(name, a)?;
    Image::new(h, w, 1, values(a).into_owned()).py_err()
}

/// A `(kh, kw)` float32 array with zero displacement at `origin` as a kernel.
fn kernel_in(k: &PyReadonlyArrayDyn<f32>, origin: (usize, usize)) -> PyResult<Kernel> {
    let (h, w) = dims2("kernel", k)?;
    Kernel::with_origin(h, w, values(k).into_owned(), origin).py_err()
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

#[pyfunction]
#[pyo3(signature = (gyro, tim, height, cam, x, y, r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn render_kernel<'py>(
    py: Python<'py>,
    gyro: PyReadonlyArrayDyn<f64>,
    tim: Tim,
    height: usize,
    cam: Cam,
    x: f64,
    y: f64,
    r_cam_imu: Option<PyReadonlyArrayDyn<f64>>,
    bias: Option<(f64, f64, f64)>,
) -> PyResult<(Arr<'py, f32>, (usize, usize))> {
    let track = track_in(&gyro, r_cam_imu.as_ref(), bias)?;
    let t = timing(tim, height);
    let k = crate::pool::detach(py, || {
        wscg_deblur::render_kernel(
            &track,
            &t,
            &intrinsics(cam),
            (x, y),
            &KernelParams::default(),
        )
    })
    .py_err()?;
    kernel_out(py, k)
}

#[pyfunction]
#[pyo3(signature = (gyro, tim, cam, width, height, tile, r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn kernel_grid<'py>(
    py: Python<'py>,
    gyro: PyReadonlyArrayDyn<f64>,
    tim: Tim,
    cam: Cam,
    width: usize,
    height: usize,
    tile: usize,
    r_cam_imu: Option<PyReadonlyArrayDyn<f64>>,
    bias: Option<(f64, f64, f64)>,
) -> PyResult<Arr<'py, f32>> {
    let track = track_in(&gyro, r_cam_imu.as_ref(), bias)?;
    let t = timing(tim, height);
    let g = crate::pool::detach(py, || {
        wscg_deblur::kernel_grid(
            &track,
            &t,
            &intrinsics(cam),
            width,
            height,
            tile,
            &KernelParams::default(),
        )
    })
    .py_err()?;
    grid_out(py, &g)
}

#[pyfunction]
fn blurriness(kernel: PyReadonlyArrayDyn<f32>, origin: (usize, usize)) -> PyResult<f64> {
    Ok(wscg_deblur::blurriness(&kernel_in(&kernel, origin)?))
}

/// Noise deviation of a blurred image (see `wscg.deblur.estimate_noise`).
#[pyfunction]
fn estimate_noise(py: Python<'_>, image: PyReadonlyArrayDyn<f32>) -> PyResult<f64> {
    let img = image_in("image", &image)?;
    let s = crate::pool::detach(py, || wscg_deblur::estimate_noise(&img)).py_err()?;
    Ok(s as f64)
}

/// `lam = None`: the noise-aware weight (`HyperLaplacianParams::lambda`).
fn hl_params(lam: Option<f32>, alpha: f32, beta_max: f32) -> HyperLaplacianParams {
    HyperLaplacianParams::default()
        .lambda(lam)
        .alpha(alpha)
        .beta_max(beta_max)
}

#[pyfunction]
fn deconv_krishnan<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<f32>,
    kernel: PyReadonlyArrayDyn<f32>,
    origin: (usize, usize),
    lam: Option<f32>,
    alpha: f32,
    beta_max: f32,
) -> PyResult<Arr<'py, f32>> {
    let img = image_in("image", &image)?;
    let k = kernel_in(&kernel, origin)?;
    let p = hl_params(lam, alpha, beta_max);
    let out = crate::pool::detach(py, || wscg_deblur::deconv_hl(&img, &k, &p)).py_err()?;
    crate::convert::image_array(py, out, true)
}

#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn deconv_krishnan_multi<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<f32>,
    kernel: PyReadonlyArrayDyn<f32>,
    origin: (usize, usize),
    prior: PyReadonlyArrayDyn<f32>,
    mu: f32,
    lam: Option<f32>,
    alpha: f32,
    beta_max: f32,
) -> PyResult<Arr<'py, f32>> {
    let img = image_in("image", &image)?;
    let pr = image_in("prior", &prior)?;
    let k = kernel_in(&kernel, origin)?;
    let p = hl_params(lam, alpha, beta_max);
    let out =
        crate::pool::detach(py, || wscg_deblur::deconv_hl_multi(&img, &k, &pr, mu, &p)).py_err()?;
    crate::convert::image_array(py, out, true)
}

#[pyfunction]
fn wiener<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<f32>,
    kernel: PyReadonlyArrayDyn<f32>,
    origin: (usize, usize),
    nsr: f32,
) -> PyResult<Arr<'py, f32>> {
    let img = image_in("image", &image)?;
    let k = kernel_in(&kernel, origin)?;
    let out = crate::pool::detach(py, || wscg_deblur::wiener(&img, &k, nsr)).py_err()?;
    crate::convert::image_array(py, out, true)
}

#[pyfunction]
fn richardson_lucy<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<f32>,
    kernel: PyReadonlyArrayDyn<f32>,
    origin: (usize, usize),
    n_iter: usize,
) -> PyResult<Arr<'py, f32>> {
    let img = image_in("image", &image)?;
    let k = kernel_in(&kernel, origin)?;
    let out = crate::pool::detach(py, || wscg_deblur::richardson_lucy(&img, &k, n_iter))
        .py_err_renamed(&[("iters", "n_iter")])?;
    crate::convert::image_array(py, out, true)
}

#[pyfunction]
fn convolve<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<f32>,
    kernel: PyReadonlyArrayDyn<f32>,
    origin: (usize, usize),
) -> PyResult<Arr<'py, f32>> {
    let img = image_in("image", &image)?;
    let k = kernel_in(&kernel, origin)?;
    let out = crate::pool::detach(py, || wscg_deblur::tiling::convolve(&img, &k)).py_err()?;
    crate::convert::image_array(py, out, true)
}

fn method_in(
    name: &str,
    lam: Option<f32>,
    alpha: f32,
    beta_max: f32,
    nsr: f32,
    rl_n_iter: usize,
) -> PyResult<Method> {
    let hl = hl_params(lam, alpha, beta_max);
    Ok(match Method::by_name(name).py_err()? {
        Method::Wiener { .. } => Method::Wiener { nsr },
        Method::RichardsonLucy { .. } => Method::RichardsonLucy { iters: rl_n_iter },
        Method::HyperLaplacian(_) => Method::HyperLaplacian(hl),
        Method::GlobalUniform(_) => Method::GlobalUniform(hl),
    })
}

#[pyfunction]
#[pyo3(signature = (frame, gyro, tim, cam, method, tile, lam, alpha, beta_max, nsr, rl_n_iter,
                    r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn deblur_piecewise<'py>(
    py: Python<'py>,
    frame: PyReadonlyArrayDyn<f32>,
    gyro: PyReadonlyArrayDyn<f64>,
    tim: Tim,
    cam: Cam,
    method: &str,
    tile: usize,
    lam: Option<f32>,
    alpha: f32,
    beta_max: f32,
    nsr: f32,
    rl_n_iter: usize,
    r_cam_imu: Option<PyReadonlyArrayDyn<f64>>,
    bias: Option<(f64, f64, f64)>,
) -> PyResult<(Arr<'py, f32>, Arr<'py, f32>)> {
    let img = image_in("frame", &frame)?;
    let track = track_in(&gyro, r_cam_imu.as_ref(), bias)?;
    let m = method_in(method, lam, alpha, beta_max, nsr, rl_n_iter)?;
    let tiling = Tiling {
        tile,
        ..Default::default()
    };
    tiling.validate().py_err()?;
    let t = timing(tim, img.height());
    let k = intrinsics(cam);
    let (out, grid) = crate::pool::detach(py, || {
        let grid = wscg_deblur::kernel_grid(
            &track,
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
    Ok((
        crate::convert::image_array(py, out, true)?,
        grid_out(py, &grid)?,
    ))
}

#[pyfunction]
#[pyo3(signature = (frames, frame_times, gyro, cam, tim, main, mu, lam, alpha, beta_max, gamma, align, min_ncc, temporal_radius, tile, r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn deblur_multiframe<'py>(
    py: Python<'py>,
    frames: Vec<PyReadonlyArrayDyn<f32>>,
    frame_times: Vec<f64>,
    gyro: PyReadonlyArrayDyn<f64>,
    cam: Cam,
    tim: (f64, f64, f64),
    main: usize,
    mu: f32,
    lam: Option<f32>,
    alpha: f32,
    beta_max: f32,
    gamma: Option<f32>,
    align: &str,
    min_ncc: f64,
    temporal_radius: Option<usize>,
    tile: usize,
    r_cam_imu: Option<PyReadonlyArrayDyn<f64>>,
    bias: Option<(f64, f64, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    if frames.len() != frame_times.len() {
        return Err(value_error(format!(
            "{} frames but {} frame_times",
            frames.len(),
            frame_times.len()
        )));
    }
    let inputs = frames
        .iter()
        .zip(&frame_times)
        .map(|(f, &t)| {
            Ok(FrameInput {
                image: image_in("frames", f)?,
                t,
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let track = track_in(&gyro, r_cam_imu.as_ref(), bias)?;
    let align = match align {
        "ecc" => AlignMode::Ecc(AlignParams::default()),
        "gyro" => AlignMode::Gyro,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid align mode. Valid modes are 'ecc', 'gyro'"
            )))
        }
    };
    let opts = MultiframeParams::default()
        .t_exposure(tim.0)
        .t_readout(tim.1)
        .t_delay(tim.2)
        .gamma(gamma.map(Gamma))
        .tiling(Tiling {
            tile,
            ..Default::default()
        })
        .hl(hl_params(lam, alpha, beta_max))
        .mu(mu)
        .align(align)
        .min_ncc(min_ncc)
        .radius(temporal_radius);
    let k = intrinsics(cam);
    let out = crate::pool::detach(py, || {
        wscg_deblur::deblur_multiframe(&inputs, main, &track, &k, &opts, &NoProgress)
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

#[pyfunction]
#[pyo3(signature = (frame, gyro, tim, cam, r_cam_imu=None, bias=None))]
fn rectify_rolling_shutter<'py>(
    py: Python<'py>,
    frame: PyReadonlyArrayDyn<f32>,
    gyro: PyReadonlyArrayDyn<f64>,
    tim: Tim,
    cam: Cam,
    r_cam_imu: Option<PyReadonlyArrayDyn<f64>>,
    bias: Option<(f64, f64, f64)>,
) -> PyResult<Arr<'py, f32>> {
    let img = image_in("frame", &frame)?;
    let track = track_in(&gyro, r_cam_imu.as_ref(), bias)?;
    let t = timing(tim, img.height());
    let out = crate::pool::detach(py, || {
        wscg_deblur::rectify_rolling_shutter(&img, &track, &t, &intrinsics(cam))
    })
    .py_err()?;
    crate::convert::image_array(py, out, true)
}

#[pyfunction]
fn phase_correlation(
    py: Python<'_>,
    a: PyReadonlyArrayDyn<f32>,
    b: PyReadonlyArrayDyn<f32>,
) -> PyResult<(f64, f64)> {
    let (ia, ib) = (image_in("a", &a)?, image_in("b", &b)?);
    crate::pool::detach(py, || wscg_deblur::phase_correlation(&ia, &ib)).py_err()
}

#[pyfunction]
#[pyo3(signature = (gyro, frame_times, shifts, t_exposure, t_readout, cam, lo, hi, step, r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn estimate_time_delay(
    py: Python<'_>,
    gyro: PyReadonlyArrayDyn<f64>,
    frame_times: Vec<f64>,
    shifts: PyReadonlyArrayDyn<f64>,
    t_exposure: f64,
    t_readout: f64,
    cam: Cam,
    lo: f64,
    hi: f64,
    step: f64,
    r_cam_imu: Option<PyReadonlyArrayDyn<f64>>,
    bias: Option<(f64, f64, f64)>,
) -> PyResult<f64> {
    let track = track_in(&gyro, r_cam_imu.as_ref(), bias)?;
    let (n, c) = dims2("shifts", &shifts)?;
    if c != 2 {
        return Err(value_error(format!(
            "`shifts` must have shape (N - 1, 2) with rows (dx, dy), got ({n}, {c})"
        )));
    }
    let sh: Vec<(f64, f64)> = values(&shifts)
        .chunks_exact(2)
        .map(|r| (r[0], r[1]))
        .collect();
    // The shift prediction uses the opening of the middle row, `t_d + t_r / 2`: the frame
    // height cancels, any positive height gives the same timing.
    let t = timing((0.0, t_exposure, t_readout, 0.0), 1);
    crate::pool::detach(py, || {
        wscg_deblur::estimate_time_delay(
            &track,
            &frame_times,
            &sh,
            &t,
            &intrinsics(cam),
            (lo, hi),
            step,
        )
    })
    .py_err()
}

#[pyfunction]
fn w_step<'py>(
    py: Python<'py>,
    v: PyReadonlyArrayDyn<f64>,
    alpha: f64,
    beta: f64,
) -> PyResult<Arr<'py, f64>> {
    if !(alpha > 0.0 && alpha <= 2.0) {
        return Err(value_error(format!(
            "`alpha` must lie in (0, 2], got {alpha}"
        )));
    }
    if !(beta.is_finite() && beta > 0.0) {
        return Err(value_error(format!(
            "`beta` must be finite and > 0, got {beta}"
        )));
    }
    let shape = v.shape().to_vec();
    let data = values(&v);
    if let Some(i) = data.iter().position(|x| !x.is_finite()) {
        return Err(value_error(format!(
            "`v` contains a non-finite value at flat index {i}"
        )));
    }
    let out: Vec<f64> = crate::pool::detach(py, || {
        data.iter()
            .map(|&x| wscg_deblur::wstep::w_exact(x, alpha, beta))
            .collect()
    })?;
    array(py, &shape, out)
}

#[pyfunction]
#[pyo3(signature = (duration, rate, tau, std, t0, seed))]
fn make_gyro<'py>(
    py: Python<'py>,
    duration: f64,
    rate: f64,
    tau: f64,
    std: (f64, f64, f64),
    t0: f64,
    seed: u64,
) -> PyResult<Arr<'py, f64>> {
    let p = ShakeParams::default()
        .rate(rate)
        .tau(tau)
        .std([std.0, std.1, std.2])
        .t0(t0)
        .duration(duration);
    let s = crate::pool::detach(py, || synth::ou_gyro(&p, seed)).py_err()?;
    samples_out(py, &s)
}

#[pyfunction]
fn add_gyro_noise<'py>(
    py: Python<'py>,
    gyro: PyReadonlyArrayDyn<f64>,
    sigma: f64,
    seed: u64,
) -> PyResult<Arr<'py, f64>> {
    let s = samples_in(&gyro)?;
    let out = crate::pool::detach(py, || synth::add_gyro_noise(&s, sigma, seed)).py_err()?;
    samples_out(py, &out)
}

#[pyfunction]
#[pyo3(signature = (sharp, gyro, tim, cam, t_world, noise_sigma, gamma, quantise, seed, r_cam_imu=None, bias=None))]
#[allow(clippy::too_many_arguments)]
fn render_blurred<'py>(
    py: Python<'py>,
    sharp: PyReadonlyArrayDyn<f32>,
    gyro: PyReadonlyArrayDyn<f64>,
    tim: Tim,
    cam: Cam,
    t_world: f64,
    noise_sigma: f32,
    gamma: Option<f32>,
    quantise: bool,
    seed: u64,
    r_cam_imu: Option<PyReadonlyArrayDyn<f64>>,
    bias: Option<(f64, f64, f64)>,
) -> PyResult<Arr<'py, f32>> {
    let img = image_in("sharp", &sharp)?;
    let track = track_in(&gyro, r_cam_imu.as_ref(), bias)?;
    if !(noise_sigma.is_finite() && noise_sigma >= 0.0) {
        return Err(value_error(format!(
            "`noise_sigma` must be finite and >= 0, got {noise_sigma}"
        )));
    }
    let g = gamma.map(Gamma);
    if let Some(g) = g {
        g.validate().py_err()?;
    }
    let opts = BlurRenderParams::default()
        .noise_sigma(noise_sigma)
        .gamma(g)
        .quantise(quantise);
    let t = timing(tim, img.height());
    let out = crate::pool::detach(py, || {
        synth::render_blurred(&img, &track, &t, &intrinsics(cam), t_world, &opts, seed)
    })
    .py_err()?;
    crate::convert::image_array(py, out, true)
}

#[pyfunction]
fn make_scene<'py>(
    py: Python<'py>,
    height: usize,
    width: usize,
    seed: u64,
) -> PyResult<Arr<'py, f32>> {
    let img = crate::pool::detach(py, || synth::scene(height, width, seed)).py_err()?;
    crate::convert::image_array(py, img, true)
}

/// Registers the submodule.
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
