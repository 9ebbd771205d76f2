//! `wscg._native.hdr`: bindings of `wscg-hdr` (paper 13, multiscopic HDR image sequence
//! generation). The documented API is `python/wscg/hdr.py`, which passes C-contiguous uint16
//! code images, float32 radiance images, int32 offset fields and float32 response tables;
//! every function here validates its input again, so a direct call cannot panic.

use std::path::PathBuf;

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_hdr::metrics;
use wscg_hdr::synth::{layered_scene, Layer, SceneParams};
use wscg_hdr::{Align, Crf, MultiscopicParams, Nnf, PatchMatchParams, StereoParams, Synthesis};
use wscg_math::progress::NoProgress;
use wscg_math::Image;

use crate::convert::{array, image_dims, values, Arr};
use crate::errors::{value_error, IntoPy};

/// An image of codes, `(H, W)` or `(H, W, C)`.
fn codes_in(name: &str, a: &PyReadonlyArrayDyn<u16>) -> PyResult<Image<u16>> {
    let (h, w, c) = image_dims(name, a.shape())?;
    Image::new(h, w, c, values(a).into_owned()).py_err()
}

/// A float image, `(H, W)` or `(H, W, C)`, with finite values.
fn float_in(name: &'static str, a: &PyReadonlyArrayDyn<f32>) -> PyResult<Image<f32>> {
    let (h, w, c) = image_dims(name, a.shape())?;
    let img = Image::new(h, w, c, values(a).into_owned()).py_err()?;
    img.ensure_finite(name).py_err()?;
    Ok(img)
}

/// A field from an `(H, W, 2)` array of offsets `(dx, dy)` (costs zero).
fn nnf_in(name: &str, off: &PyReadonlyArrayDyn<i32>) -> PyResult<Nnf> {
    let (h, w) = match *off.shape() {
        [h, w, 2] if h > 0 && w > 0 => (h, w),
        ref s => {
            return Err(value_error(format!(
                "`{name}` must be a non-empty (H, W, 2) array of offsets (dx, dy), got shape {s:?}"
            )))
        }
    };
    let v = values(off);
    let o = v.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
    Nnf::new(h, w, o, vec![0.0; h * w]).py_err()
}

/// A field as `(offsets int32 (H, W, 2), cost float32 (H, W))`.
fn nnf_out<'py>(py: Python<'py>, f: Nnf) -> PyResult<(Arr<'py, i32>, Arr<'py, f32>)> {
    let (h, w) = (f.height(), f.width());
    let off = f.off.iter().flat_map(|o| [o[0], o[1]]).collect();
    Ok((array(py, &[h, w, 2], off)?, array(py, &[h, w], f.cost)?))
}

/// The codes of an 8- or 16-bit image file (PNG, TIFF, JPEG) as `(H, W)` or `(H, W, C)`
/// uint16, with the file's bit depth.
#[pyfunction]
fn load_codes(py: Python<'_>, path: PathBuf) -> PyResult<(Arr<'_, u16>, u8)> {
    let (img, bits) = crate::pool::detach(py, || Image::<u16>::load_codes(&path)).py_err()?;
    let (h, w, c) = img.shape();
    let shape = if c == 1 { vec![h, w] } else { vec![h, w, c] };
    Ok((array(py, &shape, img.into_data())?, bits))
}

/// The exposure times of image files: `given` checked against their EXIF exposures, or the
/// EXIF exposures (`wscg_math::io::exif::resolve_exposure_times`). Returns the times,
/// whether they came from EXIF, and one message per disagreement.
#[pyfunction]
#[pyo3(signature = (paths, given))]
fn exposure_times(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    given: Option<Vec<f64>>,
) -> PyResult<(Vec<f64>, bool, Vec<String>)> {
    let r = crate::pool::detach(py, || {
        wscg_math::io::exif::resolve_exposure_times(&paths, given.as_deref())
    })
    .py_err()?;
    let messages = r.mismatches.into_iter().map(|m| m.message).collect();
    Ok((r.times, r.from_exif, messages))
}

/// One inverse camera response as given from Python: a name or a table.
#[derive(FromPyObject)]
enum CrfArg<'py> {
    /// `"gamma2.2"` or `"linear"`.
    Name(String),
    /// `(levels,)` or `(levels, C)` table of `f^-1`.
    Table(PyReadonlyArrayDyn<'py, f32>),
}

/// The smallest bit depth (at least 1) whose codes reach `max_code`.
fn bits_for(max_code: u16) -> u8 {
    (16 - max_code.leading_zeros()).max(1) as u8
}

fn crf_in(arg: &CrfArg<'_>, bits: u8) -> PyResult<Crf> {
    match arg {
        CrfArg::Name(n) => match n.as_str() {
            "gamma2.2" => Crf::gamma(2.2, bits, 1).py_err(),
            "linear" => Crf::linear(bits, 1).py_err(),
            other => Err(value_error(format!(
                "unknown response {other:?}; use \"gamma2.2\", \"linear\" or a table of f^-1"
            ))),
        },
        CrfArg::Table(t) => {
            let (levels, c) = match *t.shape() {
                [l] => (l, 1),
                [l, c] => (l, c),
                ref s => {
                    return Err(value_error(format!(
                        "a response table must have shape (levels,) or (levels, C), got {s:?}"
                    )))
                }
            };
            Crf::from_table(&values(t), levels, c).py_err()
        }
    }
}

/// The responses of `images`: `bits` (or the smallest depth covering their codes) for named
/// responses, one shared or one per image.
fn crfs_in(
    py: Python<'_>,
    crfs: &[CrfArg<'_>],
    images: &[Image<u16>],
    bits: Option<u8>,
) -> PyResult<Vec<Crf>> {
    if crfs.is_empty() {
        return Err(value_error(
            "`crf`: give one response or one per view, got none",
        ));
    }
    if crfs.len() != 1 && crfs.len() != images.len() {
        return Err(value_error(format!(
            "`crf`: give one response or one per view ({}), got {}",
            images.len(),
            crfs.len()
        )));
    }
    let bits = match bits {
        Some(b) => b,
        None => bits_for(crate::pool::detach(py, || {
            images
                .iter()
                .map(wscg_hdr::radiance::max_code)
                .max()
                .unwrap_or(0)
        })?),
    };
    crfs.iter().map(|c| crf_in(c, bits)).collect()
}

fn codes_list(name: &str, v: &[PyReadonlyArrayDyn<u16>]) -> PyResult<Vec<Image<u16>>> {
    v.iter()
        .enumerate()
        .map(|(k, a)| codes_in(&format!("{name}[{k}]"), a))
        .collect()
}

/// Checks a disparity range against `i32` overflow (the crate checks it against the width).
fn check_range(d_min: i32, d_max: i32) -> PyResult<()> {
    const LIM: u32 = 1 << 24;
    if d_min.unsigned_abs() > LIM || d_max.unsigned_abs() > LIM {
        return Err(value_error(format!(
            "the disparity range [{d_min}, {d_max}] is out of bounds (|d| <= 2^24)"
        )));
    }
    Ok(())
}

type HdrResult<'py> = (Vec<Arr<'py, f32>>, Option<Bound<'py, PyDict>>, Vec<usize>);

#[pyfunction]
#[pyo3(signature = (views, times, crfs, bits, patch, n_iter, d_min, d_max, coherence, epipolar,
                    align, synthesis, ordered, weighted_cost, fill_saturated, seed, details))]
#[allow(clippy::too_many_arguments)]
fn multiscopic_hdr<'py>(
    py: Python<'py>,
    views: Vec<PyReadonlyArrayDyn<'py, u16>>,
    times: Vec<f64>,
    crfs: Vec<CrfArg<'py>>,
    bits: Option<u8>,
    patch: usize,
    n_iter: usize,
    d_min: i32,
    d_max: i32,
    coherence: bool,
    epipolar: bool,
    align: &str,
    synthesis: &str,
    ordered: bool,
    weighted_cost: bool,
    fill_saturated: bool,
    seed: u64,
    details: bool,
) -> PyResult<HdrResult<'py>> {
    if views.len() < 2 {
        return Err(value_error(format!(
            "multiscopic HDR needs at least 2 views, got {}; to merge an aligned exposure \
             stack of one view use merge_stack",
            views.len()
        )));
    }
    let flat = views[0].ndim() == 2;
    let imgs = codes_list("views", &views)?;
    let crfs = crfs_in(py, &crfs, &imgs, bits)?;
    check_range(d_min, d_max)?;
    let synthesis = match synthesis {
        "bds" => Synthesis::Bds,
        "direct" => Synthesis::Direct,
        other => {
            return Err(value_error(format!(
                "unknown synthesis {other:?}; use \"bds\" or \"direct\""
            )))
        }
    };
    let p = MultiscopicParams::default()
        .pm(PatchMatchParams::default()
            .patch(patch)
            .iters(n_iter)
            .d_min(d_min)
            .d_max(d_max)
            .coherence(coherence)
            .epipolar(epipolar)
            .weighted_cost(weighted_cost)
            .seed(seed))
        .align(Align::by_name(align).py_err()?)
        .synthesis(synthesis)
        .ordered(ordered)
        .fill_saturated(fill_saturated);
    let out = crate::pool::detach(py, || {
        wscg_hdr::multiscopic_hdr(&imgs, &times, &crfs, &p, &NoProgress)
    })
    .py_err()?;
    let fields = if details {
        let d = PyDict::new(py);
        for ((r, s), f) in out.nnfs {
            d.set_item((r, s), nnf_out(py, f)?.0)?;
        }
        Some(d)
    } else {
        None
    };
    let hdr = out
        .hdr
        .into_iter()
        .map(|im| crate::convert::image_array(py, im, flat))
        .collect::<PyResult<_>>()?;
    Ok((hdr, fields, out.fallback_pixels))
}

/// Merge of aligned radiance samples (eq. 6): one `(radiance, weight, level)` triple of
/// float images per input, with its exposure time.
#[pyfunction]
#[pyo3(signature = (radiances, weights, levels, times))]
fn merge<'py>(
    py: Python<'py>,
    radiances: Vec<PyReadonlyArrayDyn<'py, f32>>,
    weights: Vec<PyReadonlyArrayDyn<'py, f32>>,
    levels: Vec<PyReadonlyArrayDyn<'py, f32>>,
    times: Vec<f64>,
) -> PyResult<(Arr<'py, f32>, usize)> {
    let Some(first) = radiances.first() else {
        return Err(value_error("`radiances` is empty: nothing to merge"));
    };
    if weights.len() != radiances.len() || levels.len() != radiances.len() {
        return Err(value_error(format!(
            "{} radiance images need as many weights and levels, got {} and {}",
            radiances.len(),
            weights.len(),
            levels.len()
        )));
    }
    let flat = first.ndim() == 2;
    let samples = (0..radiances.len())
        .map(|k| {
            Ok(wscg_hdr::ViewSamples {
                radiance: float_in("radiances", &radiances[k])?,
                weight: float_in("weights", &weights[k])?,
                level: float_in("levels", &levels[k])?,
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let inputs: Vec<wscg_hdr::MergeInput> = samples
        .iter()
        .zip(&times)
        .map(|(s, &t)| wscg_hdr::MergeInput {
            samples: s,
            time: t,
        })
        .collect();
    if times.len() != samples.len() {
        return Err(value_error(format!(
            "{} exposure times for {} inputs",
            times.len(),
            samples.len()
        )));
    }
    let m = crate::pool::detach(py, || wscg_hdr::merge(&inputs)).py_err()?;
    Ok((
        crate::convert::image_array(py, m.hdr, flat)?,
        m.fallback_pixels,
    ))
}

#[pyfunction]
#[pyo3(signature = (images, times, crfs, bits))]
fn merge_stack<'py>(
    py: Python<'py>,
    images: Vec<PyReadonlyArrayDyn<'py, u16>>,
    times: Vec<f64>,
    crfs: Vec<CrfArg<'py>>,
    bits: Option<u8>,
) -> PyResult<(Arr<'py, f32>, usize)> {
    let Some(first) = images.first() else {
        return Err(value_error("`images` is empty: nothing to merge"));
    };
    let flat = first.ndim() == 2;
    let imgs = codes_list("images", &images)?;
    if let Some((k, im)) = imgs
        .iter()
        .enumerate()
        .find(|(_, im)| im.shape() != imgs[0].shape())
    {
        return Err(value_error(format!(
            "images[{k}] is {:?} but images[0] is {:?} (height, width, channels)",
            im.shape(),
            imgs[0].shape()
        )));
    }
    let crfs = crfs_in(py, &crfs, &imgs, bits)?;
    let m = crate::pool::detach(py, || wscg_hdr::merge_stack(&imgs, &times, &crfs)).py_err()?;
    Ok((
        crate::convert::image_array(py, m.hdr, flat)?,
        m.fallback_pixels,
    ))
}

#[pyfunction]
#[pyo3(signature = (image, crf, dt, bits))]
fn to_radiance<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<'py, u16>,
    crf: CrfArg<'py>,
    dt: f64,
    bits: Option<u8>,
) -> PyResult<Arr<'py, f32>> {
    let flat = image.ndim() == 2;
    let img = codes_in("image", &image)?;
    let crf = crfs_in(
        py,
        std::slice::from_ref(&crf),
        std::slice::from_ref(&img),
        bits,
    )?;
    let e = crate::pool::detach(py, || wscg_hdr::to_radiance(&img, &crf[0], dt)).py_err()?;
    crate::convert::image_array(py, e, flat)
}

#[pyfunction]
fn khan_weight<'py>(
    py: Python<'py>,
    z: PyReadonlyArrayDyn<'py, f32>,
    z_max: f32,
) -> PyResult<Arr<'py, f32>> {
    if !(z_max.is_finite() && z_max > 0.0) {
        return Err(value_error(format!(
            "`z_max` must be finite and > 0, got {z_max}"
        )));
    }
    let shape = z.shape().to_vec();
    let v = values(&z);
    if v.iter().any(|x| !x.is_finite()) {
        return Err(value_error(
            "`z` contains a non-finite value (NaN or infinity)",
        ));
    }
    let out = crate::pool::detach(py, || {
        v.iter().map(|&x| wscg_hdr::khan_weight(x, z_max)).collect()
    })?;
    array(py, &shape, out)
}

#[pyfunction]
#[pyo3(signature = (stack, times, n_samples, lam, bits))]
fn calibrate_debevec<'py>(
    py: Python<'py>,
    stack: Vec<PyReadonlyArrayDyn<'py, u16>>,
    times: Vec<f64>,
    n_samples: usize,
    lam: f64,
    bits: u8,
) -> PyResult<Arr<'py, f32>> {
    // Above 10 bits the codes are reduced to 10 for the dense solve (`calibrate_debevec`).
    if !(1..=16).contains(&bits) {
        return Err(value_error(format!(
            "`bits` must be in 1..=16 for calibration, got {bits}"
        )));
    }
    let imgs = codes_list("stack", &stack)?;
    let crf = crate::pool::detach(py, || {
        wscg_hdr::calibrate_debevec(&imgs, &times, bits, n_samples, lam)
    })
    .py_err()?;
    array(py, &[crf.levels(), crf.channels()], crf.table().to_vec())
}

#[pyfunction]
#[pyo3(signature = (stack, times, bits, degree, max_degree, n_samples, refine_ratios, tol, max_iter))]
#[allow(clippy::too_many_arguments)]
fn calibrate_mitsunaga_nayar<'py>(
    py: Python<'py>,
    stack: Vec<PyReadonlyArrayDyn<'py, u16>>,
    times: Vec<f64>,
    bits: u8,
    degree: Option<usize>,
    max_degree: usize,
    n_samples: usize,
    refine_ratios: bool,
    tol: f64,
    max_iter: usize,
) -> PyResult<(Arr<'py, f32>, Bound<'py, PyDict>)> {
    let imgs = codes_list("stack", &stack)?;
    let p = wscg_hdr::MitsunagaNayarParams::default()
        .degree(degree)
        .max_degree(max_degree)
        .samples(n_samples)
        .refine_ratios(refine_ratios)
        .tol(tol)
        .max_iter(max_iter);
    let fit = crate::pool::detach(py, || {
        wscg_hdr::calibrate_mitsunaga_nayar(&imgs, &times, bits, &p)
    })
    .py_err()?;
    let info = PyDict::new(py);
    let ch = &fit.channels;
    info.set_item(
        "coefficients",
        ch.iter()
            .map(|c| c.coefficients.clone())
            .collect::<Vec<_>>(),
    )?;
    info.set_item(
        "ratios",
        ch.iter().map(|c| c.ratios.clone()).collect::<Vec<_>>(),
    )?;
    info.set_item(
        "degree",
        ch.iter()
            .map(|c| c.coefficients.len() - 1)
            .collect::<Vec<_>>(),
    )?;
    info.set_item("rms", ch.iter().map(|c| c.rms).collect::<Vec<_>>())?;
    info.set_item(
        "equations",
        ch.iter().map(|c| c.equations).collect::<Vec<_>>(),
    )?;
    info.set_item(
        "iterations",
        ch.iter().map(|c| c.iterations).collect::<Vec<_>>(),
    )?;
    let table = array(
        py,
        &[fit.crf.levels(), fit.crf.channels()],
        fit.crf.table().to_vec(),
    )?;
    Ok((table, info))
}

#[allow(clippy::too_many_arguments)]
fn pm_params(
    patch: usize,
    n_iter: usize,
    d_min: i32,
    d_max: i32,
    v_tol: i32,
    coherence: bool,
    epipolar: bool,
    c_min: f32,
    alpha: f32,
    seed: u64,
) -> PyResult<PatchMatchParams> {
    check_range(d_min, d_max)?;
    Ok(PatchMatchParams::default()
        .patch(patch)
        .iters(n_iter)
        .d_min(d_min)
        .d_max(d_max)
        .v_tol(v_tol)
        .alpha(alpha)
        .epipolar(epipolar)
        .coherence(coherence)
        .c_min(c_min)
        .seed(seed)
        .weighted_cost(false))
}

type Field<'py> = (Arr<'py, i32>, Arr<'py, f32>);

#[pyfunction]
#[pyo3(signature = (a, b, patch, n_iter, d_min, d_max, v_tol, coherence, epipolar, c_min, alpha,
                    seed))]
#[allow(clippy::too_many_arguments)]
fn patchmatch<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<'py, f32>,
    b: PyReadonlyArrayDyn<'py, f32>,
    patch: usize,
    n_iter: usize,
    d_min: i32,
    d_max: i32,
    v_tol: i32,
    coherence: bool,
    epipolar: bool,
    c_min: f32,
    alpha: f32,
    seed: u64,
) -> PyResult<Field<'py>> {
    let (ia, ib) = (float_in("a", &a)?, float_in("b", &b)?);
    let p = pm_params(
        patch, n_iter, d_min, d_max, v_tol, coherence, epipolar, c_min, alpha, seed,
    )?;
    let f = crate::pool::detach(py, || wscg_hdr::patchmatch(&ia, &ib, &p)).py_err()?;
    nnf_out(py, f)
}

#[pyfunction]
fn patchmatch_2d<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<'py, f32>,
    b: PyReadonlyArrayDyn<'py, f32>,
    patch: usize,
    n_iter: usize,
    seed: u64,
) -> PyResult<Field<'py>> {
    let (ia, ib) = (float_in("a", &a)?, float_in("b", &b)?);
    let f = crate::pool::detach(py, || {
        wscg_hdr::patchmatch_2d(&ia, &ib, patch, n_iter, seed)
    })
    .py_err()?;
    nnf_out(py, f)
}

#[pyfunction]
fn zncc_stereo<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<'py, f32>,
    b: PyReadonlyArrayDyn<'py, f32>,
    window: usize,
    d_min: i32,
    d_max: i32,
    lr_tol: i32,
) -> PyResult<Field<'py>> {
    let (ia, ib) = (float_in("a", &a)?, float_in("b", &b)?);
    check_range(d_min, d_max)?;
    if lr_tol < 0 {
        return Err(value_error(format!("`lr_tol` must be >= 0, got {lr_tol}")));
    }
    let p = StereoParams::default()
        .window(window)
        .d_min(d_min)
        .d_max(d_max)
        .lr_tol(lr_tol);
    let f = crate::pool::detach(py, || wscg_hdr::zncc_stereo(&ia, &ib, &p)).py_err()?;
    nnf_out(py, f)
}

/// Checks that a field lies on the grid of `img`.
fn field_fits(name: &str, f: &Nnf, img: &Image<f32>) -> PyResult<()> {
    if (f.height(), f.width()) != (img.height(), img.width()) {
        return Err(value_error(format!(
            "`{name}` is {} x {} but the source image is {} x {}",
            f.height(),
            f.width(),
            img.height(),
            img.width()
        )));
    }
    Ok(())
}

#[pyfunction]
fn vote_bds<'py>(
    py: Python<'py>,
    src: PyReadonlyArrayDyn<'py, f32>,
    offsets_rs: PyReadonlyArrayDyn<'py, i32>,
    offsets_sr: PyReadonlyArrayDyn<'py, i32>,
    patch: usize,
) -> PyResult<Arr<'py, f32>> {
    let flat = src.ndim() == 2;
    let img = float_in("src", &src)?;
    let rs = nnf_in("offsets_rs", &offsets_rs)?;
    let sr = nnf_in("offsets_sr", &offsets_sr)?;
    field_fits("offsets_sr", &sr, &img)?;
    let out = crate::pool::detach(py, || wscg_hdr::vote_bds(&img, &rs, &sr, patch)).py_err()?;
    crate::convert::image_array(py, out, flat)
}

#[pyfunction]
fn warp_direct<'py>(
    py: Python<'py>,
    src: PyReadonlyArrayDyn<'py, f32>,
    offsets_rs: PyReadonlyArrayDyn<'py, i32>,
) -> PyResult<Arr<'py, f32>> {
    let flat = src.ndim() == 2;
    let img = float_in("src", &src)?;
    let rs = nnf_in("offsets_rs", &offsets_rs)?;
    let out = crate::pool::detach(py, || wscg_hdr::warp_direct(&img, &rs)).py_err()?;
    crate::convert::image_array(py, out, flat)
}

/// One layer from Python: disparity, `(y0, y1, x0, x1)`, disk, gain, texture seed.
type LayerArg = (f64, [f64; 4], bool, f64, u64);

#[pyfunction]
#[pyo3(signature = (height, width, times, emitter_peak, noise, seed, layers=None))]
#[allow(clippy::too_many_arguments)]
fn make_scene<'py>(
    py: Python<'py>,
    height: usize,
    width: usize,
    times: Vec<f64>,
    emitter_peak: f64,
    noise: f64,
    seed: u64,
    layers: Option<Vec<LayerArg>>,
) -> PyResult<Bound<'py, PyDict>> {
    const MAX_PIXELS: usize = 1 << 26;
    if height.saturating_mul(width) > MAX_PIXELS {
        return Err(value_error(format!(
            "a {height} x {width} scene is too large (at most 2^26 pixels per view)"
        )));
    }
    let mut cfg = SceneParams::default()
        .height(height)
        .width(width)
        .times(times)
        .emitter_peak(emitter_peak)
        .noise(noise);
    if let Some(layers) = layers {
        cfg.layers = layers
            .into_iter()
            .map(|(d, rect, disk, gain, seed)| Layer::new(d, rect, seed).disk(disk).gain(gain))
            .collect();
    }
    let sc = crate::pool::detach(py, || layered_scene(&cfg, seed)).py_err()?;
    let d = PyDict::new(py);
    let views = sc
        .views
        .iter()
        .map(|v| {
            let (h, w, c) = v.shape();
            // 8-bit scene: every code fits a byte.
            let b = v.data().iter().map(|&z| z.min(255) as u8).collect();
            array(py, &[h, w, c], b)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("views", views)?;
    d.set_item("exposure_times", sc.times.clone())?;
    d.set_item(
        "crf",
        array(
            py,
            &[sc.crf.levels(), sc.crf.channels()],
            sc.crf.table().to_vec(),
        )?,
    )?;
    let radiance = sc
        .radiance
        .into_iter()
        .map(|e| crate::convert::image_array(py, e, false))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("radiance", radiance)?;
    let disparity = sc
        .disparity
        .into_iter()
        .map(|e| crate::convert::image_array(py, e, true))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("disparity", disparity)?;
    let seen = sc
        .seen_by
        .into_iter()
        .map(|s| array(py, &[height, width], s))
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("seen_by", seen)?;
    Ok(d)
}

#[pyfunction]
#[pyo3(signature = (est, gt, mask=None))]
fn rmse_log2(
    py: Python<'_>,
    est: PyReadonlyArrayDyn<'_, f32>,
    gt: PyReadonlyArrayDyn<'_, f32>,
    mask: Option<PyReadonlyArrayDyn<'_, bool>>,
) -> PyResult<f64> {
    if est.shape() != gt.shape() {
        return Err(value_error(format!(
            "`est` has shape {:?} but `gt` has {:?}",
            est.shape(),
            gt.shape()
        )));
    }
    let (e, g) = (float_in("est", &est)?, float_in("gt", &gt)?);
    let m = match &mask {
        Some(m) if m.shape() == est.shape() => Some(values(m).into_owned()),
        Some(m) => {
            return Err(value_error(format!(
                "`mask` has shape {:?}, expected that of `est` {:?}",
                m.shape(),
                est.shape()
            )))
        }
        None => None,
    };
    crate::pool::detach(py, || metrics::rmse_log2(&e, &g, m.as_deref())).py_err()
}

#[pyfunction]
#[pyo3(signature = (offsets, truth, k, mask=None))]
fn bad_rate(
    py: Python<'_>,
    offsets: PyReadonlyArrayDyn<'_, i32>,
    truth: PyReadonlyArrayDyn<'_, f32>,
    k: f32,
    mask: Option<PyReadonlyArrayDyn<'_, bool>>,
) -> PyResult<f64> {
    let f = nnf_in("offsets", &offsets)?;
    let hw = [f.height(), f.width()];
    if truth.shape() != hw {
        return Err(value_error(format!(
            "`truth` has shape {:?}, expected the field's (H, W) = {hw:?}",
            truth.shape()
        )));
    }
    if !(k.is_finite() && k >= 0.0) {
        return Err(value_error(format!("`k` must be finite and >= 0, got {k}")));
    }
    let m = match &mask {
        Some(m) if m.shape() == hw => Some(values(m).into_owned()),
        Some(m) => {
            return Err(value_error(format!(
                "`mask` has shape {:?}, expected the field's (H, W) = {hw:?}",
                m.shape()
            )))
        }
        None => None,
    };
    let t = values(&truth);
    crate::pool::detach(py, || metrics::bad_rate(&f, &t, k, m.as_deref())).py_err()
}

#[pyfunction]
fn incoherence(py: Python<'_>, offsets: PyReadonlyArrayDyn<'_, i32>) -> PyResult<f64> {
    let f = nnf_in("offsets", &offsets)?;
    crate::pool::detach(py, || metrics::incoherence(&f))
}

/// Registers the submodule.
/// Reads a camera response table (CSV) as float32 `(levels, C)`.
#[pyfunction]
fn load_crf(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Arr<'_, f32>> {
    let crf = crate::pool::detach(py, || Crf::read_csv(&path)).py_err()?;
    array(
        py,
        &[crf.z_max() as usize + 1, crf.channels()],
        crf.table().to_vec(),
    )
}

/// Writes a camera response table `(levels,)` or `(levels, C)` as CSV.
#[pyfunction]
fn save_crf(
    py: Python<'_>,
    path: std::path::PathBuf,
    crf: PyReadonlyArrayDyn<f32>,
) -> PyResult<()> {
    let crf = crf_in(&CrfArg::Table(crf), 8)?;
    crate::pool::detach(py, || crf.write_csv(&path)).py_err()
}

/// Reads exposure times (text, or JSON for a `.json` file).
#[pyfunction]
fn load_exposure_times(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Vec<f64>> {
    crate::pool::detach(py, || wscg_hdr::read_exposure_times(&path)).py_err()
}

/// Writes exposure times as text, one a line.
#[pyfunction]
fn save_exposure_times(py: Python<'_>, path: std::path::PathBuf, times: Vec<f64>) -> PyResult<()> {
    crate::pool::detach(py, || wscg_hdr::write_exposure_times(&path, &times)).py_err()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load_crf, m)?)?;
    m.add_function(wrap_pyfunction!(save_crf, m)?)?;
    m.add_function(wrap_pyfunction!(load_exposure_times, m)?)?;
    m.add_function(wrap_pyfunction!(save_exposure_times, m)?)?;
    m.add_function(wrap_pyfunction!(multiscopic_hdr, m)?)?;
    m.add_function(wrap_pyfunction!(merge_stack, m)?)?;
    m.add_function(wrap_pyfunction!(load_codes, m)?)?;
    m.add_function(wrap_pyfunction!(exposure_times, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(to_radiance, m)?)?;
    m.add_function(wrap_pyfunction!(khan_weight, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_debevec, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate_mitsunaga_nayar, m)?)?;
    m.add_function(wrap_pyfunction!(patchmatch, m)?)?;
    m.add_function(wrap_pyfunction!(patchmatch_2d, m)?)?;
    m.add_function(wrap_pyfunction!(zncc_stereo, m)?)?;
    m.add_function(wrap_pyfunction!(vote_bds, m)?)?;
    m.add_function(wrap_pyfunction!(warp_direct, m)?)?;
    m.add_function(wrap_pyfunction!(make_scene, m)?)?;
    m.add_function(wrap_pyfunction!(rmse_log2, m)?)?;
    m.add_function(wrap_pyfunction!(bad_rate, m)?)?;
    m.add_function(wrap_pyfunction!(incoherence, m)?)?;
    Ok(())
}
