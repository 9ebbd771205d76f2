//! `wscg._native.video`: bindings of `wscg-video` (paper 06, localized-search HD video
//! completion). The documented API is `python/wscg/video.py`.

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_video::metrics;
use wscg_video::synth;
use wscg_video::{
    CompletionParams, InitMethod, LocalSearchParams, LowResParams, Mask3, PatchSize, RefineParams,
    SearchMethod, UpscaleStep, Video, WexlerParams,
};

use wscg_math::ImageView;

use crate::convert::{array, values, Arr};
use crate::errors::{value_error, IntoPy, IntoPyRenamed};

/// A `(F, H, W, C)` (C = 1 or 3) or `(F, H, W)` uint8 array as a video.
fn video_in(name: &str, a: &PyReadonlyArrayDyn<u8>) -> PyResult<Video> {
    let (f, h, w, c) = match *a.shape() {
        [f, h, w] => (f, h, w, 1),
        [f, h, w, c] => (f, h, w, c),
        ref s => {
            return Err(value_error(format!(
                "`{name}` must be a (frames, height, width, channels) or (frames, height, width) uint8 array, got shape {s:?}"
            )))
        }
    };
    Video::new(f, h, w, c, values(a).into_owned()).py_err()
}

fn mask_in(a: &PyReadonlyArrayDyn<u8>, v: &Video) -> PyResult<Mask3> {
    let s = a.shape();
    if s != [v.frames, v.height, v.width] {
        return Err(value_error(format!(
            "`mask` has shape {s:?}, expected (frames, height, width) = ({}, {}, {}) of the video",
            v.frames, v.height, v.width
        )));
    }
    Mask3::from_bytes(v.frames, v.height, v.width, &values(a)).py_err()
}

fn video_out<'py>(py: Python<'py>, v: Video) -> PyResult<Arr<'py, u8>> {
    let shape = [v.frames, v.height, v.width, v.channels];
    array(py, &shape, v.data)
}

fn patch(p: (usize, usize, usize)) -> PatchSize {
    PatchSize {
        px: p.0,
        py: p.1,
        pt: p.2,
    }
}

fn init_method(name: &str, seed: u64) -> PyResult<InitMethod> {
    match name {
        "harmonic2d" => Ok(InitMethod::Harmonic2D),
        "harmonic3d" => Ok(InitMethod::Harmonic3D),
        "random" => Ok(InitMethod::Random { seed }),
        "telea" => Ok(InitMethod::Telea),
        other => Err(value_error(format!(
            "{other:?} is not a valid init. Valid inits are 'harmonic2d', 'harmonic3d', 'telea', 'random'"
        ))),
    }
}

/// The completed frames, the dense match field (when asked for) and the statistics.
type Completed<'py> = (Arr<'py, u8>, Option<Arr<'py, i32>>, Bound<'py, PyDict>);

/// Localized-search video completion (see `wscg.video.complete_video`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn complete_video<'py>(
    py: Python<'py>,
    frames: PyReadonlyArrayDyn<u8>,
    mask: PyReadonlyArrayDyn<u8>,
    patch_size: (usize, usize, usize),
    lowres_width: usize,
    n_levels: Option<usize>,
    lowres_max_iter: Vec<usize>,
    init: &str,
    search: &str,
    patchmatch_n_iter: usize,
    seed: u64,
    onion_order: bool,
    causal_first_sweep: bool,
    refine_max_iter: usize,
    windows: Vec<usize>,
    fine_max_iter: usize,
    min_energy_drop: f64,
    temporal_radius: Vec<usize>,
    max_candidates: usize,
    propagate: bool,
    temporal_candidates: bool,
    step: &str,
    global_fine_search: bool,
    return_matches: bool,
) -> PyResult<Completed<'py>> {
    let mut v = video_in("frames", &frames)?;
    let m = mask_in(&mask, &v)?;
    let search = match search {
        "patchmatch" => SearchMethod::PatchMatch3D {
            iters: patchmatch_n_iter,
            seed,
        },
        "exact" => SearchMethod::Exact,
        "pca_kdtree" => SearchMethod::PcaKdTree(wscg_video::PcaKdParams::default().seed(seed)),
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid search. Valid searches are 'patchmatch', 'pca_kdtree', 'exact'"
            )))
        }
    };
    let step = match step {
        "double" => UpscaleStep::Double,
        "direct" => UpscaleStep::Direct,
        other => {
            return Err(value_error(format!(
                "{other:?} is not a valid step. Valid steps are 'double', 'direct'"
            )))
        }
    };
    let cfg = CompletionParams::default()
        .low(
            LowResParams::default()
                .target_width(lowres_width)
                .levels(n_levels)
                .patch(patch(patch_size))
                .iters(lowres_max_iter)
                .init(init_method(init, seed)?)
                .search(search)
                .onion_order(onion_order)
                .causal_first_sweep(causal_first_sweep)
                .temporal_candidates(temporal_candidates),
        )
        .refine((refine_max_iter > 0).then(|| RefineParams::default().iterations(refine_max_iter)))
        .local(
            LocalSearchParams::default()
                .windows(windows)
                .max_iterations(fine_max_iter)
                .min_energy_drop(min_energy_drop)
                .temporal_radius(temporal_radius)
                .max_candidates(max_candidates)
                .step(step)
                .propagate(propagate)
                .temporal_candidates(temporal_candidates),
        )
        .global_fine_search(global_fine_search);
    // The owned copy of the frames becomes the output: no second copy of the video.
    let (field, s) = crate::pool::detach(py, || {
        wscg_video::complete_in_place(&mut v, &m, &cfg, &wscg_math::progress::NoProgress)
    })
    .py_err_renamed(&[("iters", "lowres_max_iter")])?;
    let stats = PyDict::new(py);
    let s = &s;
    stats.set_item("working_size", s.working_size)?;
    stats.set_item("working_factor", s.working_factor)?;
    stats.set_item("seconds", s.seconds.to_vec())?;
    stats.set_item(
        "lowres_energy",
        s.lowres
            .iter()
            .map(|l| l.energy.clone())
            .collect::<Vec<_>>(),
    )?;
    stats.set_item(
        "local_energy",
        s.local.iter().map(|l| l.energy.clone()).collect::<Vec<_>>(),
    )?;
    stats.set_item(
        "local_candidates",
        s.local.iter().map(|l| l.candidates).collect::<Vec<_>>(),
    )?;
    if let Some(r) = &s.refine {
        stats.set_item("refine_changed", r.changed.clone())?;
        stats.set_item("refine_initial_set_mean", r.initial_set_mean)?;
    }
    stats.set_item("energy", field.energy())?;
    let dense = if return_matches {
        let dims = [v.frames, v.height, v.width];
        let mut dense = vec![-1i32; dims.iter().product::<usize>() * 3];
        for (i, mt) in field.matches.iter().enumerate() {
            let p = field.targets.get(i);
            let k = m.index(p) * 3;
            dense[k..k + 3].copy_from_slice(&mt.source.map(|c| c as i32));
        }
        Some(array(py, &[dims[0], dims[1], dims[2], 3], dense)?)
    } else {
        None
    };
    Ok((video_out(py, v)?, dense, stats))
}

/// Wexler et al. 2007 completion, or per-frame PatchMatch inpainting with `per_frame` (see
/// `wscg.video.wexler_complete` and `wscg.video.per_frame_patchmatch`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn wexler<'py>(
    py: Python<'py>,
    frames: PyReadonlyArrayDyn<u8>,
    mask: PyReadonlyArrayDyn<u8>,
    patch_size: (usize, usize, usize),
    min_width: usize,
    max_iter: Vec<usize>,
    patchmatch_n_iter: usize,
    seed: u64,
    per_frame: bool,
    seed_per_frame: bool,
) -> PyResult<Arr<'py, u8>> {
    let v = video_in("frames", &frames)?;
    let m = mask_in(&mask, &v)?;
    let cfg = WexlerParams::default()
        .patch(patch(patch_size))
        .min_width(min_width)
        .iters(max_iter)
        .patchmatch_iters(patchmatch_n_iter)
        .seed(seed)
        .seed_per_frame(seed_per_frame);
    let out = crate::pool::detach(py, || {
        if per_frame {
            wscg_video::per_frame_patchmatch(&v, &m, &cfg)
        } else {
            wscg_video::wexler_complete(&v, &m, &cfg).map(|c| c.video)
        }
    })
    .py_err()?;
    video_out(py, out)
}

/// `(ssim, psnr)` over the hole, or flicker (see `wscg.video`).
#[pyfunction]
fn measure(
    py: Python<'_>,
    a: PyReadonlyArrayDyn<u8>,
    b: Option<PyReadonlyArrayDyn<u8>>,
    mask: PyReadonlyArrayDyn<u8>,
    what: &str,
) -> PyResult<f64> {
    let a = video_in("a", &a)?;
    let m = mask_in(&mask, &a)?;
    let b = b.map(|b| video_in("b", &b)).transpose()?;
    match (what, b) {
        ("ssim", Some(b)) => crate::pool::detach(py, || metrics::ssim_masked(&a, &b, &m)).py_err(),
        ("psnr", Some(b)) => crate::pool::detach(py, || metrics::psnr_masked(&a, &b, &m)).py_err(),
        ("flicker", _) => crate::pool::detach(py, || metrics::flicker(&a, &m)).py_err(),
        _ => Err(value_error(format!("unknown measure {what:?}"))),
    }
}

/// Synthetic clips G1-G4 (see `wscg.video.make_clip`).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn make_clip<'py>(
    py: Python<'py>,
    kind: &str,
    n_frames: usize,
    height: usize,
    width: usize,
    radius: f64,
    speed: f64,
    step: f64,
    zoom: f64,
    hole: (usize, usize),
    period: f64,
    noise: f64,
    seed: u64,
) -> PyResult<(Arr<'py, u8>, Arr<'py, u8>, Arr<'py, u8>)> {
    if !matches!(kind, "sprite" | "pan" | "zoom" | "periodic") {
        return Err(value_error(format!(
            "`kind` {kind:?} is not a valid clip. Valid clips are 'sprite', 'pan', 'zoom', 'periodic'"
        )));
    }
    let clip = crate::pool::detach(py, || match kind {
        "sprite" => synth::sprite_clip(n_frames, height, width, radius, speed, noise, seed),
        "pan" => synth::pan_clip(n_frames, height, width, step, hole.0, hole.1, seed),
        "zoom" => synth::zoom_clip(n_frames, height, width, zoom, radius, speed, seed),
        _ => synth::periodic_clip(n_frames, height, width, period, hole.0),
    })
    .py_err_renamed(&[("frames, height, width", "n_frames, height, width")])?;
    let m = clip.hole.to_bytes();
    Ok((
        video_out(py, clip.clean)?,
        video_out(py, clip.observed)?,
        array(py, &[n_frames, height, width], m)?,
    ))
}

/// Fast-marching inpainting of one image (see `wscg.video.inpaint_telea`).
#[pyfunction]
fn inpaint_telea<'py>(
    py: Python<'py>,
    image: PyReadonlyArrayDyn<u8>,
    mask: PyReadonlyArrayDyn<u8>,
    radius: f32,
) -> PyResult<Arr<'py, u8>> {
    let shape = image.shape().to_vec();
    let (h, w, c) = crate::convert::image_dims("image", &shape)?;
    if mask.shape() != [h, w] {
        return Err(value_error(format!(
            "`mask` has shape {:?}, expected ({h}, {w})",
            mask.shape()
        )));
    }
    let data = values(&image);
    let hole: Vec<bool> = values(&mask).iter().map(|&v| v != 0).collect();
    let out = crate::pool::detach(py, || {
        wscg_video::telea::telea(
            ImageView::new(h, w, c, &data)?,
            ImageView::plane(h, w, &hole)?,
            radius,
        )
    })?
    .map_err(|e| match e.argument() {
        // The Python function names the hole `mask`.
        Some("hole") => value_error("`mask` covers the whole image: no known pixel to fill from"),
        _ => crate::errors::to_py(e),
    })?;
    array(py, &shape, out.into_data())
}

/// Frames of a folder (see `wscg.video.load_frames`).
#[pyfunction]
fn load_frames<'py>(py: Python<'py>, path: std::path::PathBuf) -> PyResult<Arr<'py, u8>> {
    let v = crate::pool::detach(py, || wscg_video::io::read_frames(&path)).py_err()?;
    video_out(py, v)
}

/// A mask image or folder (see `wscg.video.load_mask`).
#[pyfunction]
fn load_mask<'py>(
    py: Python<'py>,
    path: std::path::PathBuf,
    n_frames: usize,
    height: usize,
    width: usize,
) -> PyResult<Arr<'py, u8>> {
    let m = crate::pool::detach(py, || {
        wscg_video::io::read_mask(&path, n_frames, height, width)
    })
    .py_err_renamed(&[("frames", "n_frames")])?;
    array(py, &[n_frames, height, width], m.to_bytes())
}

/// Writes frames as PNG files (see `wscg.video.save_frames`).
#[pyfunction]
fn save_frames(
    py: Python<'_>,
    path: std::path::PathBuf,
    frames: PyReadonlyArrayDyn<u8>,
) -> PyResult<Vec<std::path::PathBuf>> {
    let v = video_in("frames", &frames)?;
    crate::pool::detach(py, || wscg_video::io::write_frames(&v, &path)).py_err()
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(complete_video, m)?)?;
    m.add_function(wrap_pyfunction!(wexler, m)?)?;
    m.add_function(wrap_pyfunction!(measure, m)?)?;
    m.add_function(wrap_pyfunction!(make_clip, m)?)?;
    m.add_function(wrap_pyfunction!(inpaint_telea, m)?)?;
    m.add_function(wrap_pyfunction!(load_frames, m)?)?;
    m.add_function(wrap_pyfunction!(load_mask, m)?)?;
    m.add_function(wrap_pyfunction!(save_frames, m)?)?;
    Ok(())
}
