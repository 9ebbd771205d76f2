//! `wscg._native.gait`, paper 17: bindings of `wscg_biometrics::gait` (Kinect gait cycles,
//! joint relative angles, pair relevance, the recognizer, the Ball and Preis baselines, the
//! synthetic walker and the cross-validation protocol) and of `wscg_biometrics::dtw` (DTW,
//! the DTW kernel Δ, dissimilarity matrices, 1-NN search, the UCR/UEA `.ts` reader).
//!
//! The documented API is `python/wscg/gait.py`. It passes C-contiguous float64 arrays, frames
//! of shape `(T, 25, 3)` and joint pairs as `(P, 2)` int64 joint indices; every function
//! checks shapes and values again, so a direct call cannot panic on bad arguments. The GIL
//! is released while Rust works.

use std::path::PathBuf;

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use wscg_biometrics::dtw::{self, ts_file, DtwParams, LocalCost, Multivariate};
use wscg_biometrics::gait::synth::{self, NoiseParams, SessionParams, SessionRanges};
use wscg_biometrics::gait::{
    self, CycleChoice, CycleParams, GaitCycle, GaitParams, GaitRecognizer, HistSpec, Joint,
    JointSet, JraSet, Pair, Protocol, SkeletonSeq, StartLeg, UpAxis, Vote, N_JOINTS,
};

use crate::convert::{array, mat_out, values, Arr};
use crate::errors::{value_error, IntoPy};

/// Largest number of synthetic walks of one call.
const MAX_WALKS: usize = 5_000;
/// Longest synthetic walk, seconds.
const MAX_WALK_S: f64 = 600.0;
/// Largest total number of synthetic frames of one call (about 1.2 GB with the noise-free
/// copies the generator keeps).
const MAX_FRAMES: f64 = 1e6;
/// Largest number of walks of [`evaluate_synthetic`] (its per-channel DTW cache holds
/// `n^2 x 276` distances).
const MAX_CV_WALKS: usize = 300;

// ------------------------------------------------------------------------------------------
// Conversions

/// A validated skeleton stream from a `(T, 25, 3)` (Kinect v2) or `(T, 20, 3)` (Kinect v1)
/// float64 array.
fn seq_in(
    py: Python<'_>,
    name: &str,
    a: &PyReadonlyArrayDyn<f64>,
    fps: f64,
) -> PyResult<SkeletonSeq> {
    let (t, j) = match *a.shape() {
        [t, j, 3] => (t, j),
        ref s => {
            return Err(value_error(format!(
                "`{name}` must be a (T, 25, 3) or (T, 20, 3) array (frames x 25 Kinect v2 or 20 \
                 Kinect v1 joints x xyz), got shape {s:?}"
            )))
        }
    };
    let v = values(a);
    crate::pool::detach(py, || SkeletonSeq::from_flat(fps, &v, t, j))?
        .map_err(|e| value_error(format!("`{name}`: {e}")))
}

/// `(T, J, 3)` array of a skeleton stream (`J` = 25, or 20 for Kinect v1).
fn seq_out<'py>(py: Python<'py>, s: &SkeletonSeq) -> PyResult<Arr<'py, f64>> {
    array(py, &[s.len(), s.joint_set.len(), 3], s.to_flat())
}

/// The joint set of `n_joints` (25 or 20).
fn joint_set_in(n_joints: usize) -> PyResult<JointSet> {
    JointSet::for_count(n_joints).map_err(|_| {
        value_error(format!(
            "`n_joints` must be 25 (Kinect v2) or 20 (Kinect v1), got {n_joints}"
        ))
    })
}

/// A 1-D float64 array as a vector.
fn vec1(name: &str, a: &PyReadonlyArrayDyn<f64>) -> PyResult<Vec<f64>> {
    if a.ndim() != 1 {
        return Err(value_error(format!(
            "`{name}` must be a 1-D sequence, got shape {:?}",
            a.shape()
        )));
    }
    Ok(values(a).into_owned())
}

/// A multichannel sample from a list of 1-D arrays.
fn sample_in(name: &str, v: &[PyReadonlyArrayDyn<f64>]) -> PyResult<Vec<Vec<f64>>> {
    v.iter()
        .enumerate()
        .map(|(k, a)| vec1(&format!("{name}[{k}]"), a))
        .collect()
}

/// A set of multichannel samples.
fn set_in(name: &str, v: &[Vec<PyReadonlyArrayDyn<f64>>]) -> PyResult<Vec<Vec<Vec<f64>>>> {
    v.iter()
        .enumerate()
        .map(|(i, s)| sample_in(&format!("{name}[{i}]"), s))
        .collect()
}

fn vec_out<'py>(py: Python<'py>, v: Vec<f64>) -> PyResult<Arr<'py, f64>> {
    array(py, &[v.len()], v)
}

fn idx_out<'py>(py: Python<'py>, v: impl IntoIterator<Item = usize>) -> PyResult<Arr<'py, i64>> {
    let v: Vec<i64> = v.into_iter().map(|i| i as i64).collect();
    array(py, &[v.len()], v)
}

/// `(P, 2)` int64 array of joint pairs.
fn pairs_out<'py>(py: Python<'py>, p: &[Pair]) -> PyResult<Arr<'py, i64>> {
    let v: Vec<i64> = p
        .iter()
        .flat_map(|&(a, b)| [a.index() as i64, b.index() as i64])
        .collect();
    array(py, &[p.len(), 2], v)
}

/// Joint pairs from a `(P, 2)` int64 array of joint indices.
fn pairs_in(a: &PyReadonlyArrayDyn<i64>) -> PyResult<Vec<Pair>> {
    match *a.shape() {
        [_, 2] => {}
        ref s => {
            return Err(value_error(format!(
                "`pairs` must be a (P, 2) array of joint indices, got shape {s:?}"
            )))
        }
    }
    let joint = |i: i64| {
        usize::try_from(i)
            .ok()
            .filter(|&i| i < N_JOINTS)
            .map(|i| Joint::ALL[i])
            .ok_or_else(|| {
                value_error(format!(
                    "`pairs` holds the joint index {i}, outside 0..{N_JOINTS}"
                ))
            })
    };
    values(a)
        .chunks_exact(2)
        .map(|c| Ok((joint(c[0])?, joint(c[1])?)))
        .collect()
}

fn joint_in(name: &str, s: &str) -> PyResult<Joint> {
    Joint::parse(s).map_err(|e| value_error(format!("`{name}`: {e}")))
}

/// The 25 x 25 relevance map as an array.
fn map_out<'py>(py: Python<'py>, m: &gait::JointMap) -> PyResult<Arr<'py, f64>> {
    array(
        py,
        &[N_JOINTS, N_JOINTS],
        m.iter().flatten().copied().collect(),
    )
}

/// A finite `(25, 25)` map from an array.
fn map_in(a: &PyReadonlyArrayDyn<f64>) -> PyResult<gait::JointMap> {
    if a.shape() != [N_JOINTS, N_JOINTS] {
        return Err(value_error(format!(
            "`relevance` must be a (25, 25) array, got shape {:?}",
            a.shape()
        )));
    }
    let v = values(a);
    if v.iter().any(|x| !x.is_finite()) {
        return Err(value_error("`relevance` contains NaN or infinity"));
    }
    Ok(std::array::from_fn(|i| {
        std::array::from_fn(|j| v[i * N_JOINTS + j])
    }))
}

fn hist(bin_deg: f64, lo_deg: f64, hi_deg: f64) -> PyResult<HistSpec> {
    let h = HistSpec {
        lo_deg,
        hi_deg,
        bin_deg,
    };
    h.validate().py_err()?;
    Ok(h)
}

fn dtw_params(cost: &str, window: Option<usize>, normalize: bool) -> PyResult<DtwParams> {
    Ok(DtwParams::default()
        .cost(LocalCost::parse(cost).py_err()?)
        .window(window)
        .normalize(normalize))
}

/// [`dtw_params`] for the multichannel functions, with the multivariate mode.
fn kernel_params(
    cost: &str,
    window: Option<usize>,
    normalize: bool,
    multivariate: &str,
) -> PyResult<DtwParams> {
    Ok(dtw_params(cost, window, normalize)?
        .multivariate(Multivariate::parse(multivariate).py_err()?))
}

fn start_leg_in(s: &str) -> PyResult<StartLeg> {
    match s {
        "left" => Ok(StartLeg::Left),
        "right" => Ok(StartLeg::Right),
        "any" => Ok(StartLeg::Any),
        other => Err(value_error(format!(
            "`start_leg` must be \"left\", \"right\" or \"any\", got {other:?}"
        ))),
    }
}

fn start_leg_name(s: StartLeg) -> &'static str {
    match s {
        StartLeg::Left => "left",
        StartLeg::Right => "right",
        StartLeg::Any => "any",
    }
}

/// `"estimate"`, `"y"` or a 3-vector.
fn up_in(up: &Bound<'_, PyAny>) -> PyResult<UpAxis> {
    if let Ok(s) = up.extract::<String>() {
        return match s.as_str() {
            "estimate" => Ok(UpAxis::Estimate),
            "y" => Ok(UpAxis::Y),
            other => Err(value_error(format!(
                "`up` must be \"estimate\", \"y\" or a 3-vector, got {other:?}"
            ))),
        };
    }
    let v: [f64; 3] = up
        .extract()
        .map_err(|_| value_error("`up` must be \"estimate\", \"y\" or a 3-vector of floats"))?;
    Ok(UpAxis::Vector(v))
}

/// The cycle of a walk: given `(start, mid, end)` frames, or detected with the default
/// parameters.
fn cycle_of(s: &SkeletonSeq, cycle: Option<(usize, usize, usize)>) -> wscg_math::Result<GaitCycle> {
    match cycle {
        Some((a, b, c)) => GaitCycle::from_frames(s, a, b, c),
        None => gait::detect_gait_cycle(s, &CycleParams::default()),
    }
}

// ------------------------------------------------------------------------------------------
// Joints and angles

/// All pairs of joints other than `reference` (276 for the 25 Kinect v2 joints), `(P, 2)`.
#[pyfunction]
#[pyo3(signature = (reference="SpineBase"))]
fn all_pairs<'py>(py: Python<'py>, reference: &str) -> PyResult<Arr<'py, i64>> {
    pairs_out(py, &gait::all_pairs(joint_in("reference", reference)?))
}

/// The index of a joint given by its Kinect v2 name (case-insensitive) or index as text.
#[pyfunction]
fn joint_index(name: &str) -> PyResult<usize> {
    Ok(joint_in("joint", name)?.index())
}

/// Joint relative angle (eq. 1), radians; `None` when undefined.
#[pyfunction]
fn jra(p1: [f64; 3], p2: [f64; 3], r: [f64; 3]) -> PyResult<Option<f64>> {
    if p1.iter().chain(&p2).chain(&r).any(|v| !v.is_finite()) {
        return Err(value_error(
            "`p1`, `p2` and `r` must hold finite coordinates",
        ));
    }
    Ok(gait::jra(p1, p2, r))
}

/// Gait cycle detection (section 3.1) as a dict.
#[pyfunction]
#[pyo3(signature = (frames, fps, smooth_window, min_step_s, min_prominence, up, choice, start_leg))]
#[allow(clippy::too_many_arguments)]
fn detect_cycle<'py>(
    py: Python<'py>,
    frames: PyReadonlyArrayDyn<'py, f64>,
    fps: f64,
    smooth_window: usize,
    min_step_s: f64,
    min_prominence: f64,
    up: &Bound<'py, PyAny>,
    choice: &str,
    start_leg: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let choice = match choice {
        "first" => CycleChoice::First,
        "most_regular" => CycleChoice::MostRegular,
        other => {
            return Err(value_error(format!(
                "`choice` must be \"first\" or \"most_regular\", got {other:?}"
            )))
        }
    };
    let p = CycleParams::default()
        .smooth_window(smooth_window)
        .min_step_s(min_step_s)
        .min_prominence(min_prominence)
        .up(up_in(up)?)
        .choice(choice)
        .start_leg(start_leg_in(start_leg)?);
    let s = seq_in(py, "frames", &frames, fps)?;
    let c = crate::pool::detach(py, || gait::detect_gait_cycle(&s, &p)).py_err()?;
    let d = PyDict::new(py);
    d.set_item("start", c.start)?;
    d.set_item("mid", c.mid)?;
    d.set_item("end", c.end)?;
    d.set_item("ankle_dist", vec_out(py, c.ankle_dist)?)?;
    d.set_item("minima", idx_out(py, c.minima)?)?;
    d.set_item("first_step", c.first_step.map(start_leg_name))?;
    Ok(d)
}

/// JRA sequences `(P, L)` of `pairs` (default: all 276) over a cycle (default: detected).
#[pyfunction]
#[pyo3(signature = (frames, fps, cycle=None, pairs=None, reference="SpineBase"))]
fn jra_sequences<'py>(
    py: Python<'py>,
    frames: PyReadonlyArrayDyn<'py, f64>,
    fps: f64,
    cycle: Option<(usize, usize, usize)>,
    pairs: Option<PyReadonlyArrayDyn<'py, i64>>,
    reference: &str,
) -> PyResult<(Arr<'py, f64>, (usize, usize, usize))> {
    let r = joint_in("reference", reference)?;
    let pairs = match pairs {
        Some(p) => pairs_in(&p)?,
        None => gait::all_pairs(r),
    };
    if pairs.is_empty() {
        return Err(value_error("`pairs` is empty"));
    }
    let s = seq_in(py, "frames", &frames, fps)?;
    let (set, c) = crate::pool::detach(py, || -> wscg_math::Result<_> {
        let c = cycle_of(&s, cycle)?;
        Ok((
            gait::jra_sequences(&s, &c, r, &pairs)?,
            (c.start, c.mid, c.end),
        ))
    })
    .py_err()?;
    let l = set.frames();
    let flat: Vec<f64> = set.seqs.into_iter().flatten().collect();
    Ok((array(py, &[pairs.len(), l], flat)?, c))
}

/// Relevance map (mean occupied bins) of `(276, L_i)` JRA sets in [`gait::all_pairs`] order.
#[pyfunction]
#[pyo3(signature = (samples, bin_deg, lo_deg, hi_deg, reference="SpineBase"))]
fn relevance_matrix<'py>(
    py: Python<'py>,
    samples: Vec<PyReadonlyArrayDyn<'py, f64>>,
    bin_deg: f64,
    lo_deg: f64,
    hi_deg: f64,
    reference: &str,
) -> PyResult<Arr<'py, f64>> {
    let h = hist(bin_deg, lo_deg, hi_deg)?;
    let r = joint_in("reference", reference)?;
    let pairs = gait::all_pairs(r);
    if samples.is_empty() {
        return Err(value_error("`samples` is empty"));
    }
    let sets = samples
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let (p, l) = match *a.shape() {
                [p, l] => (p, l),
                ref s => {
                    return Err(value_error(format!(
                        "`samples[{i}]` must be a 2-D (276, L) array, got shape {s:?}"
                    )))
                }
            };
            if p != pairs.len() || l == 0 {
                return Err(value_error(format!(
                    "`samples[{i}]` must have shape ({}, L) with L >= 1 (one row per pair of \
                     all_pairs), got ({p}, {l})",
                    pairs.len()
                )));
            }
            let v = values(a);
            if v.iter().any(|x| !x.is_finite()) {
                return Err(value_error(format!(
                    "`samples[{i}]` contains NaN or infinity"
                )));
            }
            Ok(JraSet {
                reference: r,
                pairs: pairs.clone(),
                seqs: v.chunks_exact(l).map(<[f64]>::to_vec).collect(),
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let refs: Vec<&JraSet> = sets.iter().collect();
    let m = crate::pool::detach(py, || gait::relevance_matrix(&refs, &h)).py_err()?;
    map_out(py, &m)
}

/// Number of non-empty histogram bins of angles in radians.
#[pyfunction]
fn occupied_bins(
    theta_rad: PyReadonlyArrayDyn<'_, f64>,
    bin_deg: f64,
    lo_deg: f64,
    hi_deg: f64,
) -> PyResult<usize> {
    let h = hist(bin_deg, lo_deg, hi_deg)?;
    let v = vec1("theta_rad", &theta_rad)?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(value_error("`theta_rad` contains NaN or infinity"));
    }
    Ok(gait::occupied_bins(&v, &h))
}

/// The pairs `i < j` with relevance at least `min_bins`, `(M, 2)`.
#[pyfunction]
fn select_pairs<'py>(
    py: Python<'py>,
    relevance: PyReadonlyArrayDyn<'py, f64>,
    min_bins: f64,
) -> PyResult<Arr<'py, i64>> {
    let m = map_in(&relevance)?;
    pairs_out(py, &gait::select_pairs(&m, min_bins).py_err()?)
}

// ------------------------------------------------------------------------------------------
// DTW

/// DTW distance (eq. 5).
#[pyfunction]
#[pyo3(signature = (a, b, cost="abs", window=None, normalize=false))]
fn dtw_distance(
    py: Python<'_>,
    a: PyReadonlyArrayDyn<'_, f64>,
    b: PyReadonlyArrayDyn<'_, f64>,
    cost: &str,
    window: Option<usize>,
    normalize: bool,
) -> PyResult<f64> {
    let p = dtw_params(cost, window, normalize)?;
    let (a, b) = (vec1("a", &a)?, vec1("b", &b)?);
    crate::pool::detach_serial(py, a.len().saturating_mul(b.len()), || dtw::dtw(&a, &b, &p))
        .py_err()
}

/// DTW distance and an optimal warp path `(L, 2)`.
#[pyfunction]
#[pyo3(signature = (a, b, cost="abs", window=None, normalize=false))]
fn dtw_path<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<'py, f64>,
    b: PyReadonlyArrayDyn<'py, f64>,
    cost: &str,
    window: Option<usize>,
    normalize: bool,
) -> PyResult<(f64, Arr<'py, i64>)> {
    let p = dtw_params(cost, window, normalize)?;
    let (a, b) = (vec1("a", &a)?, vec1("b", &b)?);
    let (d, path) = crate::pool::detach_serial(py, a.len().saturating_mul(b.len()), || {
        dtw::dtw_path(&a, &b, &p)
    })
    .py_err()?;
    let flat: Vec<i64> = path
        .iter()
        .flat_map(|&(i, j)| [i as i64, j as i64])
        .collect();
    Ok((d, array(py, &[path.len(), 2], flat)?))
}

/// The DTW kernel Δ (eq. 6) between two multichannel samples, or their dependent DTW.
#[pyfunction]
#[pyo3(signature = (a, b, cost="abs", window=None, normalize=false, multivariate="independent"))]
fn dtw_kernel(
    py: Python<'_>,
    a: Vec<PyReadonlyArrayDyn<'_, f64>>,
    b: Vec<PyReadonlyArrayDyn<'_, f64>>,
    cost: &str,
    window: Option<usize>,
    normalize: bool,
    multivariate: &str,
) -> PyResult<f64> {
    let p = kernel_params(cost, window, normalize, multivariate)?;
    let (a, b) = (sample_in("a", &a)?, sample_in("b", &b)?);
    crate::pool::detach(py, || dtw::dtw_kernel(&a, &b, &p)).py_err()
}

/// Δ between every query and gallery sample; the symmetric self matrix when `gallery` is
/// `None`.
#[pyfunction]
#[pyo3(signature = (queries, gallery=None, cost="abs", window=None, normalize=false, multivariate="independent"))]
fn dissimilarity_matrix<'py>(
    py: Python<'py>,
    queries: Vec<Vec<PyReadonlyArrayDyn<'py, f64>>>,
    gallery: Option<Vec<Vec<PyReadonlyArrayDyn<'py, f64>>>>,
    cost: &str,
    window: Option<usize>,
    normalize: bool,
    multivariate: &str,
) -> PyResult<Arr<'py, f64>> {
    let p = kernel_params(cost, window, normalize, multivariate)?;
    let q = set_in("queries", &queries)?;
    let m = match gallery {
        Some(g) => {
            let g = set_in("gallery", &g)?;
            crate::pool::detach(py, || dtw::dissimilarity_matrix(&q, &g, &p))?
        }
        None => crate::pool::detach(py, || dtw::self_dissimilarity(&q, &p))?,
    }
    .py_err()?;
    mat_out(py, &m)
}

/// The gallery sample nearest to `query` by Δ (ties: first index) and its Δ.
#[pyfunction]
#[pyo3(signature = (query, gallery, cost="abs", window=None, normalize=false, multivariate="independent"))]
fn nearest(
    py: Python<'_>,
    query: Vec<PyReadonlyArrayDyn<'_, f64>>,
    gallery: Vec<Vec<PyReadonlyArrayDyn<'_, f64>>>,
    cost: &str,
    window: Option<usize>,
    normalize: bool,
    multivariate: &str,
) -> PyResult<(usize, f64)> {
    let p = kernel_params(cost, window, normalize, multivariate)?;
    let q = sample_in("query", &query)?;
    let g = set_in("gallery", &gallery)?;
    crate::pool::detach(py, || dtw::nearest(&q, &g, &p)).py_err()
}

/// A UCR/UEA `.ts` file: `{problem, series (case -> dimension -> 1-D array), labels,
/// class_labels}`.
#[pyfunction]
fn load_ts(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let data = crate::pool::detach(py, || ts_file::read_ts(&path)).py_err()?;
    let series = PyList::empty(py);
    for case in data.series {
        let dims = PyList::empty(py);
        for dim in case {
            dims.append(vec_out(py, dim)?)?;
        }
        series.append(dims)?;
    }
    let d = PyDict::new(py);
    d.set_item("problem", data.problem)?;
    d.set_item("series", series)?;
    d.set_item("labels", data.labels)?;
    d.set_item("class_labels", data.class_labels)?;
    Ok(d)
}

// ------------------------------------------------------------------------------------------
// Files and baselines

/// A skeleton stream from a CSV (`frame, joint, x, y, z`), `.npy` or NTU RGB+D `.skeleton`
/// file, `(T, J, 3)`; `body`: an NTU body id (`None`: the most tracked).
#[pyfunction]
#[pyo3(signature = (path, fps, body, max_gap))]
fn load_skeleton(
    py: Python<'_>,
    path: PathBuf,
    fps: f64,
    body: Option<u64>,
    max_gap: usize,
) -> PyResult<Arr<'_, f64>> {
    let body = body.map_or(gait::BodyChoice::MostTracked, gait::BodyChoice::Id);
    let ntu = gait::NtuParams::default().body(body).max_gap(max_gap);
    let s = crate::pool::detach(py, || gait::read_skeleton_with(&path, fps, &ntu)).py_err()?;
    seq_out(py, &s)
}

/// The bodies of an NTU RGB+D file: `(id, frames present, tracked joints)`.
#[pyfunction]
fn load_ntu_bodies(py: Python<'_>, path: PathBuf) -> PyResult<Vec<(u64, usize, usize)>> {
    crate::pool::detach(py, || gait::ntu_bodies(&path)).py_err()
}

/// Writes a skeleton CSV.
#[pyfunction]
fn save_skeleton_csv(
    py: Python<'_>,
    path: PathBuf,
    frames: PyReadonlyArrayDyn<'_, f64>,
    fps: f64,
) -> PyResult<()> {
    let s = seq_in(py, "frames", &frames, fps)?;
    crate::pool::detach(py, || gait::write_skeleton_csv(&path, &s)).py_err()
}

/// Features of a walk over a cycle (default: detected) by one of the baselines' extractors.
fn baseline_features<'py>(
    py: Python<'py>,
    frames: PyReadonlyArrayDyn<'py, f64>,
    fps: f64,
    cycle: Option<(usize, usize, usize)>,
    extract: fn(&SkeletonSeq, &GaitCycle) -> wscg_math::Result<Vec<f64>>,
) -> PyResult<Arr<'py, f64>> {
    let s = seq_in(py, "frames", &frames, fps)?;
    let f = crate::pool::detach(py, || extract(&s, &cycle_of(&s, cycle)?)).py_err()?;
    vec_out(py, f)
}

/// Ball et al.'s 18 features over a cycle (default: detected).
#[pyfunction]
#[pyo3(signature = (frames, fps, cycle=None))]
fn ball_features<'py>(
    py: Python<'py>,
    frames: PyReadonlyArrayDyn<'py, f64>,
    fps: f64,
    cycle: Option<(usize, usize, usize)>,
) -> PyResult<Arr<'py, f64>> {
    baseline_features(py, frames, fps, cycle, |s, c| {
        Ok(gait::ball_features(s, c)?.to_vec())
    })
}

/// Preis et al.'s 13 features over a cycle (default: detected).
#[pyfunction]
#[pyo3(signature = (frames, fps, cycle=None))]
fn preis_features<'py>(
    py: Python<'py>,
    frames: PyReadonlyArrayDyn<'py, f64>,
    fps: f64,
    cycle: Option<(usize, usize, usize)>,
) -> PyResult<Arr<'py, f64>> {
    baseline_features(py, frames, fps, cycle, |s, c| {
        Ok(gait::preis_features(s, c)?.to_vec())
    })
}

// ------------------------------------------------------------------------------------------
// Recognizer

/// A fitted gait recognizer (labels are `u32` codes; the Python class maps them).
#[pyclass(module = "wscg._native.gait", name = "Recognizer", frozen)]
pub struct PyRecognizer {
    inner: GaitRecognizer,
}

#[pymethods]
impl PyRecognizer {
    /// Fits on whole walks: cycles, JRA sets, relevance on these walks, selected pairs.
    #[new]
    #[pyo3(signature = (walks, labels, fps, min_bins, vote, cost, window, bin_deg, start_leg))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        walks: Vec<PyReadonlyArrayDyn<'_, f64>>,
        labels: Vec<u32>,
        fps: f64,
        min_bins: f64,
        vote: &str,
        cost: &str,
        window: Option<usize>,
        bin_deg: f64,
        start_leg: &str,
    ) -> PyResult<Self> {
        if walks.is_empty() {
            return Err(value_error(
                "`walks` is empty: the gallery needs at least one walk",
            ));
        }
        if labels.len() != walks.len() {
            return Err(value_error(format!(
                "{} labels for {} walks",
                labels.len(),
                walks.len()
            )));
        }
        let p = GaitParams::default()
            .cycle(CycleParams::default().start_leg(start_leg_in(start_leg)?))
            .hist(hist(bin_deg, 0.0, 180.0)?)
            .min_bins(min_bins)
            .dtw(dtw_params(cost, window, false)?)
            .vote(Vote::parse(vote).py_err()?);
        let seqs = walks
            .iter()
            .enumerate()
            .map(|(i, w)| seq_in(py, &format!("walks[{i}]"), w, fps))
            .collect::<PyResult<Vec<_>>>()?;
        let inner = crate::pool::detach(py, || GaitRecognizer::fit(&seqs, &labels, &p)).py_err()?;
        Ok(Self { inner })
    }

    /// Selected pairs `(M, 2)`.
    fn pairs<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, i64>> {
        pairs_out(py, &self.inner.pairs)
    }

    /// Relevance map of the training walks `(25, 25)`.
    fn relevance<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        map_out(py, &self.inner.relevance)
    }

    /// Training label codes.
    fn labels(&self) -> Vec<u32> {
        self.inner.labels.clone()
    }

    /// The fitted recognizer as JSON.
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        crate::pool::detach(py, || self.inner.to_json()).py_err()
    }

    /// A recognizer from `to_json`.
    #[staticmethod]
    fn from_json(py: Python<'_>, s: &str) -> PyResult<Self> {
        Ok(Self {
            inner: crate::pool::detach(py, || GaitRecognizer::from_json(s)).py_err()?,
        })
    }

    /// `(label, training indices, their labels, their Δ, (start, mid, end))`, Δ ascending.
    #[allow(clippy::type_complexity)]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        frames: PyReadonlyArrayDyn<'py, f64>,
        fps: f64,
    ) -> PyResult<(
        u32,
        Arr<'py, i64>,
        Vec<u32>,
        Arr<'py, f64>,
        Option<(usize, usize, usize)>,
    )> {
        let s = seq_in(py, "frames", &frames, fps)?;
        let pr = crate::pool::detach(py, || self.inner.predict(&s)).py_err()?;
        let idx = idx_out(py, pr.ranked.iter().map(|r| r.0))?;
        let labels = pr.ranked.iter().map(|r| r.1).collect();
        let d = vec_out(py, pr.ranked.iter().map(|r| r.2).collect())?;
        Ok((
            pr.label,
            idx,
            labels,
            d,
            pr.cycle.map(|c| (c.start, c.mid, c.end)),
        ))
    }
}

// ------------------------------------------------------------------------------------------
// Synthetic walkers and the protocol

fn range2(name: &str, r: (f64, f64)) -> PyResult<[f64; 2]> {
    if !(r.0.is_finite() && r.1.is_finite() && r.0 <= r.1) {
        return Err(value_error(format!(
            "`{name}` must be a finite range (lo, hi) with lo <= hi, got {r:?}"
        )));
    }
    Ok([r.0, r.1])
}

/// `n_subjects x n_sessions` synthetic walks with ground truth, as a dict.
#[pyfunction]
#[pyo3(signature = (n_subjects, n_sessions, seed, heading_deg, speed, walk_s, sit_prob, noise, n_joints))]
#[allow(clippy::too_many_arguments)]
fn make_walkers<'py>(
    py: Python<'py>,
    n_subjects: usize,
    n_sessions: usize,
    seed: u64,
    heading_deg: (f64, f64),
    speed: (f64, f64),
    walk_s: (f64, f64),
    sit_prob: f64,
    noise: bool,
    n_joints: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let joint_set = joint_set_in(n_joints)?;
    let n = n_subjects.checked_mul(n_sessions);
    if n.is_none_or(|n| n == 0 || n > MAX_WALKS) {
        return Err(value_error(format!(
            "n_subjects * n_sessions must be in 1..={MAX_WALKS}, got {n_subjects} x {n_sessions}"
        )));
    }
    if !(0.0..=1.0).contains(&sit_prob) {
        return Err(value_error(format!(
            "`sit_prob` must be in [0, 1], got {sit_prob}"
        )));
    }
    let ranges = SessionRanges {
        heading_deg: range2("heading_deg", heading_deg)?,
        speed: range2("speed", speed)?,
        walk_s: range2("walk_s", walk_s)?,
        sit_prob,
        ..SessionRanges::default()
    };
    if ranges.speed[0] <= 0.0 || ranges.walk_s[0] <= 0.0 || ranges.walk_s[1] > MAX_WALK_S {
        return Err(value_error(format!(
            "`speed` must be positive and `walk_s` in (0, {MAX_WALK_S}] seconds"
        )));
    }
    let frames_max = n.unwrap_or(0) as f64 * (ranges.walk_s[1] + 1.0) * 30.0;
    if frames_max > MAX_FRAMES {
        return Err(value_error(format!(
            "{} walks of up to {} s exceed the size limit of {MAX_FRAMES} frames in total",
            n.unwrap_or(0),
            ranges.walk_s[1]
        )));
    }
    let set = crate::pool::detach(py, || {
        if noise {
            synth::walkers(n_subjects, n_sessions, &ranges, seed)
        } else {
            // The sessions `walkers` draws, without sensor noise.
            let subjects = synth::subjects(n_subjects, seed);
            let sessions: Vec<SessionParams> = (0..n_subjects * n_sessions)
                .map(|k| {
                    (SessionParams::draw(
                        &ranges,
                        seed.wrapping_mul(1_000_003).wrapping_add(k as u64),
                    ))
                    .noise(NoiseParams::none())
                })
                .collect();
            synth::walkers_with(&subjects, n_sessions, &sessions, seed)
        }
        .map(|set| match joint_set {
            JointSet::KinectV1 => set.to_kinect_v1(),
            JointSet::KinectV2 => set,
        })
    })
    .py_err()?;
    let frames = PyList::empty(py);
    for w in &set.walks {
        frames.append(seq_out(py, w)?)?;
    }
    let minima = PyList::empty(py);
    for t in &set.truth {
        minima.append(idx_out(py, t.minima.iter().copied())?)?;
    }
    let d = PyDict::new(py);
    d.set_item("frames", frames)?;
    d.set_item(
        "labels",
        idx_out(py, set.labels.iter().map(|&l| l as usize))?,
    )?;
    d.set_item("sessions", idx_out(py, set.session_index.iter().copied())?)?;
    d.set_item("minima", minima)?;
    d.set_item(
        "walk_frames",
        idx_out(py, set.truth.iter().map(|t| t.walk_frames))?,
    )?;
    d.set_item(
        "sit_tail",
        set.sessions.iter().map(|s| s.sit_tail).collect::<Vec<_>>(),
    )?;
    Ok(d)
}

/// The paper's cross-validation on synthetic walkers: the fields of `CvReport`.
#[pyfunction]
fn evaluate_synthetic(
    py: Python<'_>,
    n_subjects: usize,
    n_sessions: usize,
    seed: u64,
    n_joints: usize,
) -> PyResult<Bound<'_, PyDict>> {
    let joint_set = joint_set_in(n_joints)?;
    let n = n_subjects.checked_mul(n_sessions);
    if n_subjects < 2 || n_sessions < 2 || n.is_none_or(|n| n > MAX_CV_WALKS) {
        return Err(value_error(format!(
            "needs n_subjects >= 2, n_sessions >= 2 and at most {MAX_CV_WALKS} walks, got \
             {n_subjects} x {n_sessions}"
        )));
    }
    let r = crate::pool::detach(py, || -> wscg_math::Result<_> {
        let mut set = synth::walkers(n_subjects, n_sessions, &SessionRanges::default(), seed)?;
        if joint_set == JointSet::KinectV1 {
            set = set.to_kinect_v1();
        }
        let proto = Protocol::default();
        let prep = gait::prepare(&set.walks, &set.labels, &set.session_index, &proto.params)?;
        gait::cross_validate(&prep, None, &proto)
    })
    .py_err()?;
    let d = PyDict::new(py);
    d.set_item("decisions", r.decisions)?;
    d.set_item("jra_nearest", r.jra_nearest)?;
    d.set_item("jra_paper_vote", r.jra_paper_vote)?;
    d.set_item("jra_majority", r.jra_majority)?;
    d.set_item("jra_fixed", r.jra_fixed)?;
    d.set_item("jra_normalized", r.jra_normalized)?;
    d.set_item("jra_resampled", r.jra_resampled)?;
    d.set_item("raw_dtw", r.raw_dtw)?;
    d.set_item("ball_nn", r.ball_nn)?;
    d.set_item("preis_nb", r.preis_nb)?;
    d.set_item("preis_nn", r.preis_nn)?;
    d.set_item("chosen_t", r.chosen_t)?;
    let curve: Vec<f64> = r.curve.iter().flat_map(|&(t, a)| [t, a]).collect();
    d.set_item("curve", array(py, &[r.curve.len(), 2], curve)?)?;
    d.set_item("relevance", map_out(py, &r.relevance)?)?;
    Ok(d)
}

/// Registers the functions of `wscg._native.gait`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("JOINT_NAMES", gait::JOINT_NAMES.to_vec())?;
    m.add("KINECT_V1_NAMES", gait::KINECT_V1_NAMES.to_vec())?;
    m.add_class::<PyRecognizer>()?;
    m.add_function(wrap_pyfunction!(all_pairs, m)?)?;
    m.add_function(wrap_pyfunction!(joint_index, m)?)?;
    m.add_function(wrap_pyfunction!(jra, m)?)?;
    m.add_function(wrap_pyfunction!(detect_cycle, m)?)?;
    m.add_function(wrap_pyfunction!(jra_sequences, m)?)?;
    m.add_function(wrap_pyfunction!(relevance_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(occupied_bins, m)?)?;
    m.add_function(wrap_pyfunction!(select_pairs, m)?)?;
    m.add_function(wrap_pyfunction!(dtw_distance, m)?)?;
    m.add_function(wrap_pyfunction!(dtw_path, m)?)?;
    m.add_function(wrap_pyfunction!(dtw_kernel, m)?)?;
    m.add_function(wrap_pyfunction!(dissimilarity_matrix, m)?)?;
    m.add_function(wrap_pyfunction!(nearest, m)?)?;
    m.add_function(wrap_pyfunction!(load_ts, m)?)?;
    m.add_function(wrap_pyfunction!(load_skeleton, m)?)?;
    m.add_function(wrap_pyfunction!(load_ntu_bodies, m)?)?;
    m.add_function(wrap_pyfunction!(save_skeleton_csv, m)?)?;
    m.add_function(wrap_pyfunction!(ball_features, m)?)?;
    m.add_function(wrap_pyfunction!(preis_features, m)?)?;
    m.add_function(wrap_pyfunction!(make_walkers, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate_synthetic, m)?)?;
    Ok(())
}
