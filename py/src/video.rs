//! `wscg.video`'s functions (paper 06, localized-search HD video completion): bindings of
//! `wscg-video`. Those whose Python layer would only convert and check their arguments are
//! called directly, re-exported by `python/wscg/video.py` (which holds the module's
//! documentation); `complete_video` returns the dict from which the Python layer builds its
//! `CompletionStats`. Frames are uint8 arrays taken as they are (another dtype is refused,
//! not cast), masks bool or uint8; counts and seeds are Python ints checked by
//! [`crate::args`].

use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_video::metrics;
use wscg_video::synth;
use wscg_video::{
    CompletionParams, InitMethod, LocalSearchParams, LowResParams, Mask3, PatchSize, RefineParams,
    SearchMethod, UpscaleStep, Video, WexlerParams,
};

use wscg_math::ImageView;

use crate::args::{self, uint};
use crate::convert::{array, values, Arr};
use crate::errors::{value_error, IntoPy, IntoPyRenamed};

/// A video argument: `(F, H, W, C)` (C = 1 or 3) or `(F, H, W)` uint8 frames, and their
/// shape (that of the output).
fn video_in(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(Video, Vec<usize>)> {
    let a = args::u8s(name, obj)?;
    let (f, h, w, c) = match *a.shape() {
        [f, h, w] => (f, h, w, 1),
        [f, h, w, c] => (f, h, w, c),
        ref s => {
            return Err(value_error(format!(
                "`{name}` must have shape (F, H, W, C) or (F, H, W), got {s:?}"
            )))
        }
    };
    let v = Video::new(f, h, w, c, values(&a).into_owned()).py_err()?;
    Ok((v, a.shape().to_vec()))
}

/// The `mask` argument of the video `v`: a bool or uint8 array (non-zero = hole) of shape
/// `(F, H, W)`, or one `(H, W)` mask for every frame.
fn mask_in(obj: &Bound<'_, PyAny>, v: &Video) -> PyResult<Mask3> {
    let a = args::asarray("mask", obj)?;
    let bytes: Vec<u8> = if let Ok(m) = a.cast::<PyArrayDyn<u8>>() {
        values(&m.readonly()).into_owned()
    } else if let Ok(m) = a.cast::<PyArrayDyn<bool>>() {
        values(&m.readonly()).iter().map(|&b| u8::from(b)).collect()
    } else {
        return Err(value_error(format!(
            "`mask` must be a bool or uint8 array, got dtype {}",
            a.dtype()
        )));
    };
    let (f, h, w) = (v.frames, v.height, v.width);
    let bytes = match *a.shape() {
        [mh, mw] if (mh, mw) == (h, w) => bytes.repeat(f),
        [mf, mh, mw] if (mf, mh, mw) == (f, h, w) => bytes,
        ref s => {
            return Err(value_error(format!(
                "`mask` has shape {s:?}, expected ({f}, {h}, {w}) (F, H, W) or one (H, W) \
                 mask for every frame"
            )))
        }
    };
    Mask3::from_bytes(f, h, w, &bytes).py_err()
}

/// The frames `v` as an array of `shape` (that of the input).
fn video_out<'py>(py: Python<'py>, v: Video, shape: &[usize]) -> PyResult<Arr<'py, u8>> {
    array(py, shape, v.data)
}

/// Per-level iteration caps: a non-empty sequence of counts.
fn sweeps(py: Python<'_>, name: &str, v: &[i128]) -> PyResult<Vec<usize>> {
    if v.is_empty() {
        return Err(value_error(format!(
            "`{name}` needs the iteration count of at least one level"
        )));
    }
    args::uints(py, name, v.iter().copied())
}

/// The space-time patch `(px, py, pt)`.
fn patch(py: Python<'_>, p: &[i128]) -> PyResult<PatchSize> {
    match *args::uints(py, "patch", p.iter().copied())? {
        [px, y, pt] => Ok(PatchSize { px, py: y, pt }),
        _ => Err(value_error(format!(
            "`patch` must be (px, py, pt), got {p:?}"
        ))),
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

/// One temporal radius for every stage-3 iteration, or one per iteration.
#[derive(FromPyObject)]
enum Radii {
    One(i128),
    Each(Vec<i128>),
}

/// Localized-search video completion (see `wscg.video.complete_video`, which builds the
/// `CompletionStats` from the dict).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn complete_video<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    patch_size: Vec<i128>,
    lowres_width: i128,
    n_levels: Option<i128>,
    lowres_max_iter: Vec<i128>,
    init: &str,
    search: &str,
    patchmatch_n_iter: i128,
    seed: i128,
    onion_order: bool,
    causal_first_sweep: bool,
    refine_max_iter: i128,
    windows: Vec<i128>,
    fine_max_iter: i128,
    min_energy_drop: f64,
    temporal_radius: Radii,
    max_candidates: i128,
    propagate: bool,
    temporal_candidates: bool,
    hypotheses: i128,
    scan_propagation: bool,
    step: &str,
    global_fine_search: bool,
    return_matches: bool,
) -> PyResult<Completed<'py>> {
    let fine_max_iter: usize = uint(py, "fine_max_iter", fine_max_iter, 0)?;
    let hypotheses: usize = uint(py, "hypotheses", hypotheses, 0)?;
    let temporal_radius = match temporal_radius {
        Radii::One(r) => vec![r],
        Radii::Each(r) => r,
    };
    let temporal_radius = args::uints(py, "temporal_radius", temporal_radius.iter().copied())?;
    let max_candidates: usize = uint(py, "max_candidates", max_candidates, 0)?;
    let lowres_max_iter = sweeps(py, "lowres_max_iter", &lowres_max_iter)?;
    let (mut v, shape) = video_in("frames", frames)?;
    let m = mask_in(mask, &v)?;
    let patch_size = patch(py, &patch_size)?;
    let lowres_width: usize = uint(py, "lowres_width", lowres_width, 0)?;
    let n_levels: Option<usize> = n_levels.map(|n| uint(py, "n_levels", n, 0)).transpose()?;
    let patchmatch_n_iter: usize = uint(py, "patchmatch_n_iter", patchmatch_n_iter, 0)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let refine_max_iter: usize = uint(py, "refine_max_iter", refine_max_iter, 0)?;
    let windows = args::uints(py, "windows", windows.iter().copied())?;
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
                .patch(patch_size)
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
                .temporal_candidates(temporal_candidates)
                .hypotheses(hypotheses)
                .scan_propagation(scan_propagation),
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
    Ok((video_out(py, v, &shape)?, dense, stats))
}

/// Wexler et al. 2007 completion, or per-frame PatchMatch inpainting with `per_frame`.
#[allow(clippy::too_many_arguments)]
fn wexler<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    patch_size: PatchSize,
    min_width: i128,
    max_iter: &[i128],
    patchmatch_n_iter: i128,
    seed: i128,
    per_frame: bool,
    seed_per_frame: bool,
) -> PyResult<Arr<'py, u8>> {
    let (v, shape) = video_in("frames", frames)?;
    let m = mask_in(mask, &v)?;
    let cfg = WexlerParams::default()
        .patch(patch_size)
        .min_width(uint(py, "min_width", min_width, 0)?)
        .iters(sweeps(py, "max_iter", max_iter)?)
        .patchmatch_iters(uint(py, "patchmatch_n_iter", patchmatch_n_iter, 0)?)
        .seed(uint(py, "seed", seed, 0)?)
        .seed_per_frame(seed_per_frame);
    let out = crate::pool::detach(py, || {
        if per_frame {
            wscg_video::per_frame_patchmatch(&v, &m, &cfg)
        } else {
            wscg_video::wexler_complete(&v, &m, &cfg).map(|c| c.video)
        }
    })
    .py_err()?;
    video_out(py, out, &shape)
}

/// Wexler et al. 2007 space-time completion (the paper's baseline): random start,
/// PatchMatch (``patchmatch_n_iter`` iterations; 0 = exact) global search at every pyramid
/// level up to full resolution, and voting ``w = exp(-D / (2 sigma^2)) * 1.3^-dist(p, E)``
/// of all patches covering a pixel, at most ``max_iter[k]`` search-and-vote iterations at
/// level ``k`` (coarsest first, the last value repeats; a level stops when the vote changes
/// nothing). Slow at HD (the paper reports an hour per iteration).
#[pyfunction]
#[pyo3(signature = (frames, mask, patch=vec![5, 5, 5], min_width=64, max_iter=vec![10, 5, 3],
                    patchmatch_n_iter=4, seed=0),
       text_signature = "(frames, mask, patch=(5, 5, 5), min_width=64, max_iter=(10, 5, 3), \
                         patchmatch_n_iter=4, seed=0)")]
#[allow(clippy::too_many_arguments)]
fn wexler_complete<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    patch: Vec<i128>,
    min_width: i128,
    max_iter: Vec<i128>,
    patchmatch_n_iter: i128,
    seed: i128,
) -> PyResult<Arr<'py, u8>> {
    let p = self::patch(py, &patch)?;
    wexler(
        py,
        frames,
        mask,
        p,
        min_width,
        &max_iter,
        patchmatch_n_iter,
        seed,
        false,
        false,
    )
}

/// Image PatchMatch inpainting of every frame separately (``(px, py)`` patches, Wexler
/// voting; ``max_iter`` and ``patchmatch_n_iter`` as in :func:`wexler_complete`): what an
/// image tool applied frame by frame gives. ``seed_per_frame`` seeds frame ``t`` with
/// ``seed + t``, as separate runs would be.
#[pyfunction]
#[pyo3(signature = (frames, mask, patch=vec![5, 5], min_width=64, max_iter=vec![10, 5, 3],
                    patchmatch_n_iter=4, seed=0, seed_per_frame=true),
       text_signature = "(frames, mask, patch=(5, 5), min_width=64, max_iter=(10, 5, 3), \
                         patchmatch_n_iter=4, seed=0, seed_per_frame=True)")]
#[allow(clippy::too_many_arguments)]
fn per_frame_patchmatch<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    patch: Vec<i128>,
    min_width: i128,
    max_iter: Vec<i128>,
    patchmatch_n_iter: i128,
    seed: i128,
    seed_per_frame: bool,
) -> PyResult<Arr<'py, u8>> {
    let p = match *args::uints(py, "patch", patch.iter().copied())? {
        [px, y] => PatchSize { px, py: y, pt: 1 },
        _ => {
            return Err(value_error(format!(
                "`patch` must be (px, py), got {patch:?}"
            )))
        }
    };
    wexler(
        py,
        frames,
        mask,
        p,
        min_width,
        &max_iter,
        patchmatch_n_iter,
        seed,
        true,
        seed_per_frame,
    )
}

/// The frames `a` and `b` to compare and the hole `mask` of `a`.
fn measured(
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    mask: &Bound<'_, PyAny>,
) -> PyResult<(Video, Video, Mask3)> {
    let (a, _) = video_in("a", a)?;
    let (b, _) = video_in("b", b)?;
    let m = mask_in(mask, &a)?;
    Ok((a, b, m))
}

/// Mean SSIM over the hole pixels (Gaussian window sigma 1.5, K1 = 0.01, K2 = 0.03, data
/// range 255; per-channel maps averaged), counting hole pixels at least 5 pixels from the
/// frame border as scikit-image does; with an all-true mask it equals
/// ``skimage.metrics.structural_similarity(a, b, gaussian_weights=True, sigma=1.5,
/// use_sample_covariance=False, data_range=255, channel_axis=-1)`` per frame.
#[pyfunction]
fn ssim_masked(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    mask: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    let (a, b, m) = measured(a, b, mask)?;
    crate::pool::detach(py, || metrics::ssim_masked(&a, &b, &m)).py_err()
}

/// PSNR (dB, data range 255) over the hole pixels; ``inf`` when they are equal.
#[pyfunction]
fn psnr_masked(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    mask: &Bound<'_, PyAny>,
) -> PyResult<f64> {
    let (a, b, m) = measured(a, b, mask)?;
    crate::pool::detach(py, || metrics::psnr_masked(&a, &b, &m)).py_err()
}

/// Mean absolute frame-to-frame change (grey levels) over the pixel positions in the
/// hole at ``t`` or ``t + 1``: 0 for a static completion of a static scene.
#[pyfunction]
fn flicker(py: Python<'_>, frames: &Bound<'_, PyAny>, mask: &Bound<'_, PyAny>) -> PyResult<f64> {
    let (v, _) = video_in("frames", frames)?;
    let m = mask_in(mask, &v)?;
    crate::pool::detach(py, || metrics::flicker(&v, &m)).py_err()
}

/// A synthetic clip of ``n_frames`` frames of ``height x width`` with exact ground truth:
/// returns ``(clean, observed, mask)``.
///
/// ``kind``: ``'sprite'`` (static camera, an opaque disc of ``radius`` moving ``speed``
/// px/frame, Gaussian ``noise``), ``'pan'`` (camera panning ``step`` px/frame under a static
/// ``hole = (h, w)`` logo), ``'zoom'`` (zoom by ``zoom`` per frame, disc hole of ``radius``
/// moving ``speed`` px/frame), ``'periodic'`` (stripes of ``period`` px over bricks, a
/// static square hole of side ``hole[0]`` hidden in every frame). **Synthetic data.**
#[pyfunction]
#[pyo3(signature = (kind, n_frames=20, height=180, width=320, radius=25.0, speed=8.0, step=8.0,
                    zoom=1.003, hole=vec![30, 40], period=24.0, noise=0.0, seed=0),
       text_signature = "(kind, n_frames=20, height=180, width=320, radius=25.0, speed=8.0, \
                         step=8.0, zoom=1.003, hole=(30, 40), period=24.0, noise=0.0, seed=0)")]
#[allow(clippy::too_many_arguments)]
fn make_clip<'py>(
    py: Python<'py>,
    kind: &str,
    n_frames: i128,
    height: i128,
    width: i128,
    radius: f64,
    speed: f64,
    step: f64,
    zoom: f64,
    hole: Vec<i128>,
    period: f64,
    noise: f64,
    seed: i128,
) -> PyResult<(Arr<'py, u8>, Arr<'py, u8>, Arr<'py, u8>)> {
    let n_frames: usize = uint(py, "n_frames", n_frames, 0)?;
    let height: usize = uint(py, "height", height, 0)?;
    let width: usize = uint(py, "width", width, 0)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let hole = args::uints(py, "hole", hole.iter().copied())?;
    let (Some(&hole_h), Some(&hole_w)) = (hole.first(), hole.last()) else {
        return Err(value_error("`hole` must be (h, w), got ()"));
    };
    for (name, v) in [
        ("radius", radius),
        ("speed", speed),
        ("step", step),
        ("zoom", zoom),
        ("period", period),
        ("noise", noise),
    ] {
        args::number(name, v)?;
    }
    if !matches!(kind, "sprite" | "pan" | "zoom" | "periodic") {
        return Err(value_error(format!(
            "`kind` {kind:?} is not a valid clip. Valid clips are 'sprite', 'pan', 'zoom', 'periodic'"
        )));
    }
    let clip = crate::pool::detach(py, || match kind {
        "sprite" => synth::sprite_clip(n_frames, height, width, radius, speed, noise, seed),
        "pan" => synth::pan_clip(n_frames, height, width, step, hole_h, hole_w, seed),
        "zoom" => synth::zoom_clip(n_frames, height, width, zoom, radius, speed, seed),
        _ => synth::periodic_clip(n_frames, height, width, period, hole_h),
    })
    .py_err_renamed(&[("frames, height, width", "n_frames, height, width")])?;
    let m = clip.hole.to_bytes();
    let shape = |v: &Video| [v.frames, v.height, v.width, v.channels];
    let (clean, observed) = (shape(&clip.clean), shape(&clip.observed));
    Ok((
        video_out(py, clip.clean, &clean)?,
        video_out(py, clip.observed, &observed)?,
        array(py, &[n_frames, height, width], m)?,
    ))
}

/// Fast-marching inpainting of one image (Telea 2004; one of stage 1's initialisations):
/// the hole is filled inwards in order of its distance to the known pixels, each pixel from
/// the first-order extrapolations of the known pixels within ``radius``. ``image``:
/// ``(H, W, C)`` or ``(H, W)`` uint8; ``mask``: ``(H, W)``, non-zero = hole. Compare
/// ``cv2.inpaint(image, mask, radius, cv2.INPAINT_TELEA)``.
#[pyfunction]
#[pyo3(signature = (image, mask, radius=5.0))]
fn inpaint_telea<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    radius: f64,
) -> PyResult<Arr<'py, u8>> {
    let image = args::u8s("image", image)?;
    let shape = image.shape().to_vec();
    let (h, w, c) = crate::convert::image_dims("image", &shape)?;
    let mask = args::array::<f64>("mask", mask)?;
    if mask.shape() != [h, w] {
        return Err(value_error(format!(
            "`mask` has shape {:?}, expected ({h}, {w})",
            mask.shape()
        )));
    }
    let radius = args::number("radius", radius)? as f32;
    let data = values(&image);
    let hole: Vec<bool> = values(&mask).iter().map(|&v| v != 0.0).collect();
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

/// The PNG/JPEG files of a folder, in name order, as an ``(F, H, W, 3)`` uint8 array
/// (``OSError`` for unreadable files or frames of different sizes).
#[pyfunction]
fn load_frames<'py>(py: Python<'py>, path: &Bound<'py, PyAny>) -> PyResult<Arr<'py, u8>> {
    let path = args::path("path", path)?;
    let v = crate::pool::detach(py, || wscg_video::io::read_frames(&path)).py_err()?;
    let shape = [v.frames, v.height, v.width, v.channels];
    video_out(py, v, &shape)
}

/// A hole mask from one image (used for every frame) or a folder of one image per frame;
/// a pixel is in the hole when any channel is non-zero. Returns ``(n_frames, height,
/// width)`` bool.
#[pyfunction]
fn load_mask<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    n_frames: i128,
    height: i128,
    width: i128,
) -> PyResult<Arr<'py, bool>> {
    let path = args::path("path", path)?;
    let n_frames: usize = uint(py, "n_frames", n_frames, 0)?;
    let height: usize = uint(py, "height", height, 0)?;
    let width: usize = uint(py, "width", width, 0)?;
    let m = crate::pool::detach(py, || {
        wscg_video::io::read_mask(&path, n_frames, height, width)
    })
    .py_err_renamed(&[("frames", "n_frames")])?;
    let hole = m.to_bytes().iter().map(|&b| b != 0).collect();
    array(py, &[n_frames, height, width], hole)
}

/// Writes ``frame_00000.png``, ... into the folder ``path`` (created if missing); returns
/// the file paths.
#[pyfunction]
fn save_frames(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    frames: &Bound<'_, PyAny>,
) -> PyResult<Vec<String>> {
    let path = args::path("path", path)?;
    let (v, _) = video_in("frames", frames)?;
    let files = crate::pool::detach(py, || wscg_video::io::write_frames(&v, &path)).py_err()?;
    Ok(files
        .into_iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect())
}

/// Registers the submodule's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(complete_video, m)?)?;
    m.add_function(wrap_pyfunction!(wexler_complete, m)?)?;
    m.add_function(wrap_pyfunction!(per_frame_patchmatch, m)?)?;
    m.add_function(wrap_pyfunction!(ssim_masked, m)?)?;
    m.add_function(wrap_pyfunction!(psnr_masked, m)?)?;
    m.add_function(wrap_pyfunction!(flicker, m)?)?;
    m.add_function(wrap_pyfunction!(make_clip, m)?)?;
    m.add_function(wrap_pyfunction!(inpaint_telea, m)?)?;
    m.add_function(wrap_pyfunction!(load_frames, m)?)?;
    m.add_function(wrap_pyfunction!(load_mask, m)?)?;
    m.add_function(wrap_pyfunction!(save_frames, m)?)?;
    Ok(())
}
