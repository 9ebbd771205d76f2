//! `wscg._native.gait`, paper 17: bindings of `wscg_biometrics::gait` (Kinect gait cycles,
//! joint relative angles, pair relevance, the recognizer, the Ball and Preis baselines, the
//! synthetic walker and the cross-validation protocol) and of `wscg_biometrics::dtw` (DTW,
//! the DTW kernel Δ, dissimilarity matrices, 1-NN search, the UCR/UEA `.ts` reader).
//!
//! The joint and angle functions, the DTW functions, the skeleton files and the baselines'
//! features are `wscg.gait`'s functions themselves, re-exported by `python/wscg/gait.py`
//! (which holds the module's documentation), their arguments converted here and by
//! [`crate::args`]: frames, sequences and samples as any real array-likes, joints by name or
//! index, cycles as `(start, mid, end)` or a `CycleDetails`. `detect_cycle`, the recognizer
//! and the synthetic walkers return the values from which the Python layer builds its result
//! classes and estimator, and take C-contiguous float64 arrays and plain numbers. Every
//! function checks shapes and values, so a direct call cannot panic on bad arguments. The GIL
//! is released while Rust works.

use std::path::PathBuf;

use numpy::{PyArrayDescrMethods, PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use wscg_biometrics::dtw::{self, ts_file, DtwParams, LocalCost, Multivariate};
use wscg_biometrics::gait::synth::{self, NoiseParams, SessionParams, SessionRanges};
use wscg_biometrics::gait::{
    self, CycleChoice, CycleParams, GaitCycle, GaitParams, GaitRecognizer, HistSpec, Joint,
    JointSet, JraSet, Pair, Protocol, SkeletonSeq, StartLeg, UpAxis, Vote, N_JOINTS,
};

use crate::args::{self, uint};
use crate::convert::{array, choice, index_vector, mat_out, values, vector, Arr};
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
        [t, j @ (25 | 20), 3] => (t, j),
        ref s => {
            return Err(value_error(format!(
                "`{name}` must have shape (T, 25, 3) or (T, 20, 3): T frames x the 25 joints \
                 of a Kinect v2 skeleton (or the 20 of Kinect v1, in the v1 SDK's order) x \
                 (x, y, z), got shape {s:?}"
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
    Ok(UpAxis::Vector(args::finite3(
        "up",
        args::triple("up", up)?,
    )?))
}

/// The cycle of a walk: given `(start, mid, end)` frames, or detected with the default
/// parameters.
fn cycle_of(s: &SkeletonSeq, cycle: Option<(usize, usize, usize)>) -> wscg_math::Result<GaitCycle> {
    match cycle {
        Some((a, b, c)) => GaitCycle::from_frames(s, a, b, c),
        None => gait::detect_gait_cycle(s, &CycleParams::default()),
    }
}

/// `fps`, or a `ValueError` unless it is finite and > 0.
fn fps_arg(fps: f64) -> PyResult<f64> {
    if fps.is_finite() && fps > 0.0 {
        Ok(fps)
    } else {
        Err(value_error(format!(
            "`fps` must be a finite number > 0, got {fps}"
        )))
    }
}

/// The walk of the `frames` argument (any real array-like, `(T, 25, 3)` or `(T, 20, 3)`)
/// at `fps` frames per second.
fn frames_arg(py: Python<'_>, frames: &Bound<'_, PyAny>, fps: f64) -> PyResult<SkeletonSeq> {
    walk_arg(py, "frames", frames, fps)
}

/// The walk of the argument `name`, as [`frames_arg`].
fn walk_arg(
    py: Python<'_>,
    name: &str,
    frames: &Bound<'_, PyAny>,
    fps: f64,
) -> PyResult<SkeletonSeq> {
    let a = args::array::<f64>(name, frames)?;
    let fps = fps_arg(fps)?;
    seq_in(py, name, &a, fps)
}

/// The 1-D sequence argument `name` (any real array-like).
fn seq_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    vec1(name, &args::array::<f64>(name, obj)?)
}

/// The multichannel sample argument `name`: a 2-D `(channels, time)` array, a 1-D array (one
/// channel) or a sequence of 1-D sequences (lengths may differ).
fn sample_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<f64>>> {
    let numeric_array = obj
        .cast::<PyUntypedArray>()
        .is_ok_and(|a| a.dtype().kind() != b'O');
    let out: Vec<Vec<f64>> = if numeric_array {
        let a = args::array::<f64>(name, obj)?;
        let v = values(&a);
        match *a.shape() {
            [_] => vec![v.into_owned()],
            [r, n] => (0..r).map(|i| v[i * n..(i + 1) * n].to_vec()).collect(),
            ref s => {
                return Err(value_error(format!(
                    "`{name}` must be a 2-D (channels, time) array or a list of 1-D sequences, \
                     got shape {s:?}"
                )))
            }
        }
    } else {
        obj.try_iter()
            .map_err(|_| {
                value_error(format!(
                    "`{name}` must be a list of 1-D sequences or a 2-D array, got {}",
                    args::type_name(obj)
                ))
            })?
            .enumerate()
            .map(|(k, c)| seq_arg(&format!("{name}[{k}]"), &c?))
            .collect::<PyResult<_>>()?
    };
    if out.is_empty() {
        return Err(value_error(format!("`{name}` has no channels")));
    }
    Ok(out)
}

/// The argument `name` holding samples ([`sample_arg`]): a sequence of them, or a 3-D array
/// `(n, channels, time)`.
fn samples_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<Vec<f64>>>> {
    let out: Vec<_> = obj
        .try_iter()
        .map_err(|_| {
            value_error(format!(
                "`{name}` must be a list of samples, got {}",
                args::type_name(obj)
            ))
        })?
        .enumerate()
        .map(|(i, s)| sample_arg(&format!("{name}[{i}]"), &s?))
        .collect::<PyResult<_>>()?;
    if out.is_empty() {
        return Err(value_error(format!(
            "`{name}` is empty: at least one sample is needed"
        )));
    }
    Ok(out)
}

/// A joint argument (`reference`, a joint of `pairs`): a Kinect v2 joint name
/// (case-insensitive) or index 0..24.
enum JointRef {
    Name(String),
    Index(i128),
}

impl<'a, 'py> FromPyObject<'a, 'py> for JointRef {
    type Error = PyErr;

    /// A `str` or an integer; anything else is a `ValueError` naming `reference`, the
    /// argument of this type (the joints of `pairs` go through [`joint_arg`]).
    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(s) = obj.extract::<String>() {
            return Ok(JointRef::Name(s));
        }
        match obj.extract::<i128>() {
            Ok(i) => Ok(JointRef::Index(i)),
            Err(_) => Err(value_error(format!(
                "`reference` must be a joint name or index, got {}",
                obj.repr()?
            ))),
        }
    }
}

impl JointRef {
    /// The reference joint's default, `"SpineBase"`.
    fn spine_base() -> Self {
        JointRef::Name(String::from("SpineBase"))
    }

    /// The joint, or a `ValueError` naming the argument `name`.
    fn joint(&self, name: &str) -> PyResult<Joint> {
        match self {
            JointRef::Name(s) => joint_in(name, s),
            JointRef::Index(i) => usize::try_from(*i)
                .ok()
                .filter(|&i| i < N_JOINTS)
                .map(|i| Joint::ALL[i])
                .ok_or_else(|| {
                    value_error(format!(
                        "`{name}` must be a joint index in 0..{}, got {i}",
                        N_JOINTS - 1
                    ))
                }),
        }
    }
}

/// The joint `obj` of the argument `name` (a [`JointRef`]).
fn joint_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Joint> {
    match obj.extract::<JointRef>() {
        Ok(r) => r.joint(name),
        Err(_) => Err(value_error(format!(
            "`{name}` must be a joint name or index, got {}",
            obj.repr()?
        ))),
    }
}

/// The `pairs` argument: `None`, a `(P, 2)` integer array of joint indices, or a list of
/// `(joint, joint)` pairs of names or indices; not empty.
fn pairs_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<Pair>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let integral =
        args::asarray("pairs", obj).is_ok_and(|a| matches!(a.dtype().kind(), b'i' | b'u'));
    let not_pairs =
        || value_error("`pairs` must be a (P, 2) int array or a list of (joint, joint) tuples");
    let pairs: Vec<Pair> = if integral {
        pairs_in(&args::array::<i64>("pairs", obj)?)?
    } else {
        obj.try_iter()
            .map_err(|_| not_pairs())?
            .map(|p| {
                let row: Vec<Bound<'_, PyAny>> = p?
                    .try_iter()
                    .map_err(|_| not_pairs())?
                    .collect::<PyResult<_>>()?;
                match row.as_slice() {
                    [a, b] => Ok((joint_arg("pairs", a)?, joint_arg("pairs", b)?)),
                    _ => Err(value_error(
                        "`pairs` must hold (joint, joint) tuples of two joints",
                    )),
                }
            })
            .collect::<PyResult<_>>()?
    };
    if pairs.is_empty() {
        return Err(value_error(
            "`pairs` is empty: give at least one joint pair",
        ));
    }
    Ok(Some(pairs))
}

/// The `cycle` argument: `None`, `(start, mid, end)` frames, a `CycleDetails` (its
/// `cycle`) or a mapping with `start`, `mid` and `end`.
fn cycle_arg(
    py: Python<'_>,
    obj: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<(usize, usize, usize)>> {
    let Some(c) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let bad = || {
        let r = c.repr().map_or_else(|_| "?".to_owned(), |r| r.to_string());
        value_error(format!("`cycle` must be (start, mid, end) frames, got {r}"))
    };
    let items: Vec<Bound<'_, PyAny>> = if let Ok(d) = c.cast::<PyDict>() {
        ["start", "mid", "end"]
            .iter()
            .map(|k| d.get_item(k)?.ok_or_else(bad))
            .collect::<PyResult<_>>()?
    } else {
        let c = if c.hasattr("cycle")? {
            c.getattr("cycle")?
        } else {
            c.clone()
        };
        c.try_iter().map_err(|_| bad())?.collect::<PyResult<_>>()?
    };
    let [a, b, e] = items.as_slice() else {
        return Err(bad());
    };
    let frame = |v: &Bound<'_, PyAny>| -> PyResult<usize> {
        uint(py, "cycle", v.extract::<i128>().map_err(|_| bad())?, 0)
    };
    Ok(Some((frame(a)?, frame(b)?, frame(e)?)))
}

/// The DTW settings of the `cost`, `window` and `normalize` arguments.
fn dtw_args(
    py: Python<'_>,
    cost: &str,
    window: Option<i128>,
    normalize: bool,
) -> PyResult<DtwParams> {
    let cost = choice(
        "cost",
        cost,
        &[("abs", LocalCost::Abs), ("squared", LocalCost::Squared)],
    )?;
    let window = window.map(|w| uint(py, "window", w, 0)).transpose()?;
    Ok(DtwParams::default()
        .cost(cost)
        .window(window)
        .normalize(normalize))
}

/// [`dtw_args`] for the multichannel functions, with the `multivariate` mode.
fn kernel_args(
    py: Python<'_>,
    cost: &str,
    window: Option<i128>,
    normalize: bool,
    multivariate: &str,
) -> PyResult<DtwParams> {
    let m = choice(
        "multivariate",
        multivariate,
        &[
            ("independent", Multivariate::Independent),
            ("dependent", Multivariate::Dependent),
        ],
    )?;
    Ok(dtw_args(py, cost, window, normalize)?.multivariate(m))
}

// ------------------------------------------------------------------------------------------
// Joints and angles

/// All joint pairs ``(p1, p2)``, ``p1 < p2``, of the joints other than ``reference``.
///
/// Parameters
/// ----------
/// reference : str or int, default "SpineBase"
///     Reference joint (name from :data:`JOINT_NAMES` or index).
///
/// Returns
/// -------
/// pairs : ndarray of int64, shape (276, 2)
///     Joint indices, lexicographic order. This is the row order of :func:`jra_sequences`
///     with ``pairs=None`` and of the samples of :func:`relevance_matrix`.
///
/// Notes
/// -----
/// The paper counts C(25, 2) = 300 pairs; the 24 pairs containing the reference joint
/// have no joint relative angle, leaving C(24, 2) = 276.
#[pyfunction]
#[pyo3(signature = (reference=JointRef::spine_base()), text_signature = "(reference='SpineBase')")]
fn all_pairs(py: Python<'_>, reference: JointRef) -> PyResult<Arr<'_, i64>> {
    pairs_out(py, &gait::all_pairs(reference.joint("reference")?))
}

/// The index of a joint given by its Kinect v2 name (case-insensitive) or index as text.
#[pyfunction]
fn joint_index(name: &str) -> PyResult<usize> {
    Ok(joint_in("joint", name)?.index())
}

/// Joint relative angle of joints ``p1`` and ``p2`` at the reference joint ``r`` (eq. 1).
///
/// Parameters
/// ----------
/// p1, p2, r : array_like, shape (3,)
///     Joint positions.
///
/// Returns
/// -------
/// theta : float
///     ``arccos(v1 . v2 / (|v1| |v2|))`` with ``v1 = r - p1``, ``v2 = p2 - r``, radians in
///     ``[0, pi]`` (equal to ``pi`` minus the angle ``p1-r-p2``).
///
/// Raises
/// ------
/// ValueError
///     When the angle is undefined: ``p1`` or ``p2`` lies within 1e-9 of ``r``.
///
/// Notes
/// -----
/// Computed as ``atan2(|v1 x v2|, v1 . v2)``, the same angle but accurate near 0 and pi.
#[pyfunction]
fn jra(p1: &Bound<'_, PyAny>, p2: &Bound<'_, PyAny>, r: &Bound<'_, PyAny>) -> PyResult<f64> {
    let point = |name: &str, p: &Bound<'_, PyAny>| args::finite3(name, args::triple(name, p)?);
    let (p1, p2, r) = (point("p1", p1)?, point("p2", p2)?, point("r", r)?);
    gait::jra(p1, p2, r).ok_or_else(|| {
        value_error(
            "the joint relative angle is undefined: `p1` or `p2` coincides with the reference \
             joint `r` (within 1e-9)",
        )
    })
}

/// Gait cycle detection (section 3.1) as a dict.
#[pyfunction]
#[pyo3(signature = (frames, fps, smooth_window, min_step_s, min_prominence, up, choice, start_leg))]
#[allow(clippy::too_many_arguments)]
fn detect_cycle<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    fps: f64,
    smooth_window: i128,
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
        .smooth_window(uint(py, "smooth_window", smooth_window, 1)?)
        .min_step_s(min_step_s)
        .min_prominence(min_prominence)
        .up(up_in(up)?)
        .choice(choice)
        .start_leg(start_leg_in(start_leg)?);
    let s = frames_arg(py, frames, fps)?;
    let c = crate::pool::detach(py, || gait::detect_gait_cycle(&s, &p)).py_err()?;
    let d = PyDict::new(py);
    d.set_item("start", c.start)?;
    d.set_item("mid", c.mid)?;
    d.set_item("end", c.end)?;
    d.set_item("ankle_dist", vector(py, c.ankle_dist)?)?;
    d.set_item("minima", index_vector(py, c.minima)?)?;
    d.set_item("first_step", c.first_step.map(start_leg_name))?;
    Ok(d)
}

/// Joint relative angle sequences of a walk over one gait cycle (section 3.2).
///
/// Parameters
/// ----------
/// frames : array_like, shape (T, 25, 3)
///     The walk.
/// cycle : (start, mid, end) or CycleDetails, optional
///     The cycle's frames (e.g. from :func:`detect_cycle`); default: detected with the
///     default parameters.
/// pairs : array_like of int, shape (P, 2), or list of (name, name), optional
///     Joint pairs; default: all 276 pairs of :func:`all_pairs`.
/// reference : str or int, default "SpineBase"
///     Reference joint.
/// fps : float, default 30.0
///     Frame rate (used by the cycle detection).
///
/// Returns
/// -------
/// theta : ndarray, shape (P, L)
///     ``theta[k, t]``: angle of pair ``k`` in frame ``start + t``, radians;
///     ``L = end - start + 1``.
///
/// Raises
/// ------
/// ValueError
///     A pair containing the reference joint or one joint twice, a cycle outside the walk,
///     a walk without a full gait cycle, bad frames.
#[pyfunction]
#[pyo3(signature = (frames, cycle=None, pairs=None, reference=JointRef::spine_base(), fps=30.0),
       text_signature = "(frames, cycle=None, pairs=None, reference='SpineBase', fps=30.0)")]
fn jra_sequences<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    cycle: Option<&Bound<'py, PyAny>>,
    pairs: Option<&Bound<'py, PyAny>>,
    reference: JointRef,
    fps: f64,
) -> PyResult<Arr<'py, f64>> {
    let s = frames_arg(py, frames, fps)?;
    let cycle = cycle_arg(py, cycle)?;
    let pairs = pairs_arg(pairs)?;
    let r = reference.joint("reference")?;
    let pairs = pairs.unwrap_or_else(|| gait::all_pairs(r));
    let set = crate::pool::detach(py, || -> wscg_math::Result<_> {
        gait::jra_sequences(&s, &cycle_of(&s, cycle)?, r, &pairs)
    })
    .py_err()?;
    let l = set.frames();
    let flat: Vec<f64> = set.seqs.into_iter().flatten().collect();
    array(py, &[pairs.len(), l], flat)
}

/// The relevance map (Fig. 8): mean number of occupied bins of every joint pair.
///
/// Parameters
/// ----------
/// samples : sequence of array_like, each of shape (276, L_i)
///     JRA sets of walks (:func:`jra_sequences` with ``pairs=None``), rows in
///     :func:`all_pairs` order; cycle lengths may differ.
/// bin_deg, lo_deg, hi_deg : float
///     Histogram layout, degrees.
/// reference : str or int, default "SpineBase"
///     The reference joint the sets were computed with.
///
/// Returns
/// -------
/// R : ndarray, shape (25, 25)
///     Symmetric; zero on the diagonal and in the reference joint's row and column.
#[pyfunction]
#[pyo3(signature = (samples, bin_deg=1.0, lo_deg=0.0, hi_deg=180.0, reference=JointRef::spine_base()),
       text_signature = "(samples, bin_deg=1.0, lo_deg=0.0, hi_deg=180.0, reference='SpineBase')")]
fn relevance_matrix<'py>(
    py: Python<'py>,
    samples: &Bound<'py, PyAny>,
    bin_deg: f64,
    lo_deg: f64,
    hi_deg: f64,
    reference: JointRef,
) -> PyResult<Arr<'py, f64>> {
    let samples = samples
        .try_iter()
        .map_err(|_| value_error("`samples` must be a list of (276, L) arrays"))?
        .enumerate()
        .map(|(i, s)| args::array::<f64>(&format!("samples[{i}]"), &s?))
        .collect::<PyResult<Vec<_>>>()?;
    if samples.is_empty() {
        return Err(value_error(
            "`samples` is empty: at least one JRA set is needed",
        ));
    }
    let h = hist(bin_deg, lo_deg, hi_deg)?;
    let r = reference.joint("reference")?;
    let pairs = gait::all_pairs(r);
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

/// Number of non-empty histogram bins of a JRA sequence: a pair's relevance (section
/// 3.3).
///
/// Parameters
/// ----------
/// theta_rad : array_like, shape (L,)
///     Angles, radians (converted to degrees; values outside the range count in the edge
///     bins).
/// bin_deg, lo_deg, hi_deg : float
///     Bin width and range, degrees (the paper does not give them; 1-degree bins on
///     ``[0, 180]`` match its "2 or 3 bins" for narrow pairs and ``t = 20``).
///
/// Returns
/// -------
/// int
#[pyfunction]
#[pyo3(signature = (theta_rad, bin_deg=1.0, lo_deg=0.0, hi_deg=180.0))]
fn occupied_bins(
    theta_rad: &Bound<'_, PyAny>,
    bin_deg: f64,
    lo_deg: f64,
    hi_deg: f64,
) -> PyResult<usize> {
    let v = seq_arg("theta_rad", theta_rad)?;
    let h = hist(bin_deg, lo_deg, hi_deg)?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(value_error("`theta_rad` contains NaN or infinity"));
    }
    Ok(gait::occupied_bins(&v, &h))
}

/// The relevant pairs (Fig. 10): ``i < j`` with ``R[i, j] >= min_bins``.
///
/// Parameters
/// ----------
/// relevance : array_like, shape (25, 25)
///     A relevance map (:func:`relevance_matrix`).
/// min_bins : float, default 20.0
///     The threshold ``t`` (the paper's best: 20 bins).
///
/// Returns
/// -------
/// pairs : ndarray of int64, shape (M, 2)
///
/// Raises
/// ------
/// ValueError
///     When no pair reaches the threshold (the message gives the largest relevance).
#[pyfunction]
#[pyo3(signature = (relevance, min_bins=20.0))]
fn select_pairs<'py>(
    py: Python<'py>,
    relevance: &Bound<'py, PyAny>,
    min_bins: f64,
) -> PyResult<Arr<'py, i64>> {
    let m = map_in(&args::array::<f64>("relevance", relevance)?)?;
    let min_bins = args::number("min_bins", min_bins)?;
    pairs_out(py, &gait::select_pairs(&m, min_bins).py_err()?)
}

// ------------------------------------------------------------------------------------------
// DTW

/// Dynamic time warping distance between two scalar sequences (eq. 5).
///
/// Parameters
/// ----------
/// a, b : array_like, shapes (n,) and (m,)
///     Non-empty finite sequences; lengths may differ.
/// cost : {"abs", "squared"}, default "abs"
///     Local cost ``|a_i - b_j|`` (the paper's) or ``(a_i - b_j)**2`` (the UCR/UEA
///     archive's; dtaidistance returns the square root of this distance).
/// window : int, optional
///     Sakoe-Chiba band half-width ``r``: cell ``(i, j)`` is allowed when
///     ``|j - i (m-1)/(n-1)| <= r``; for equal lengths exactly ``|i - j| <= r``
///     (``window=0`` is the lock-step, Euclidean-style sum); for different lengths ``r`` is
///     raised to ``ceil((m-1)/(n-1))`` so that a path exists. Default: the full grid.
///     dtaidistance's ``window=w`` on equal lengths is ``|i - j| < w``, i.e. our
///     ``window=w - 1``.
/// normalize : bool, default False
///     Divide by ``n + m`` (not in the paper).
///
/// Returns
/// -------
/// float
///     ``D(n, m)`` of ``D(i, j) = c(a_i, b_j) + min(D(i-1, j), D(i, j-1), D(i-1, j-1))``,
///     ``D(0, 0) = 0``: the raw sum of local costs along the best warp path.
#[pyfunction]
#[pyo3(name = "dtw", signature = (a, b, cost="abs", window=None, normalize=false))]
fn dtw_distance(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    cost: &str,
    window: Option<i128>,
    normalize: bool,
) -> PyResult<f64> {
    let (a, b) = (seq_arg("a", a)?, seq_arg("b", b)?);
    let p = dtw_args(py, cost, window, normalize)?;
    crate::pool::detach_serial(py, a.len().saturating_mul(b.len()), || dtw::dtw(&a, &b, &p))
        .py_err()
}

/// DTW distance and an optimal warp path.
///
/// Parameters
/// ----------
/// a, b, cost, window, normalize
///     As in :func:`dtw`.
///
/// Returns
/// -------
/// distance : float
///     Equal to :func:`dtw`.
/// path : ndarray of int64, shape (L, 2)
///     0-based index pairs from ``(0, 0)`` to ``(n-1, m-1)``, steps ``(1, 0)``, ``(0, 1)``
///     or ``(1, 1)``; ties prefer the diagonal step. ``max(n, m) <= L <= n + m - 1``.
#[pyfunction]
#[pyo3(signature = (a, b, cost="abs", window=None, normalize=false))]
fn dtw_path<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    cost: &str,
    window: Option<i128>,
    normalize: bool,
) -> PyResult<(f64, Arr<'py, i64>)> {
    let (a, b) = (seq_arg("a", a)?, seq_arg("b", b)?);
    let p = dtw_args(py, cost, window, normalize)?;
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

/// The DTW kernel of eq. 6 between two multichannel samples (or their dependent DTW).
///
/// Parameters
/// ----------
/// A, B : sequence of 1-D array_like, or 2-D array_like (channels, time)
///     Two samples with the same number of channels (e.g. the selected JRA sequences of
///     two walks); channel lengths may differ between and within samples
///     (``multivariate="independent"``) or between samples only (``"dependent"``).
/// cost, window, normalize
///     As in :func:`dtw`.
/// multivariate : {"independent", "dependent"}, default "independent"
///     ``"independent"`` (DTW_I, the paper's eq. 6): each channel warps on its own and
///     the channel distances are summed. ``"dependent"`` (DTW_D, the usual 1-NN baseline
///     of the UEA multivariate archive): one warp path for all channels, the local cost
///     between whole frames, ``||A[:, i] - B[:, j]||`` (``cost="abs"``) or its square
///     (``cost="squared"``; dtaidistance's ``dtw_ndim.distance`` is the square root of
///     this). Both cost ``O(n m channels)`` per pair; the independent one can follow each
///     channel's own best alignment, the dependent one keeps the channels in step (and
///     needs every channel of a sample to have one length). A keyword here rather than a
///     separate function because it is a setting of the same Delta, which
///     :func:`dissimilarity_matrix` and :func:`nearest` take too.
///
/// Returns
/// -------
/// float
///     ``Delta(A, B) = sum_k DTW(A[k], B[k])`` (independent; a dissimilarity, not a
///     positive-definite kernel despite the paper's name) or the dependent DTW.
#[pyfunction]
#[pyo3(signature = (A, B, cost="abs", window=None, normalize=false, multivariate="independent"))]
#[allow(non_snake_case)]
fn dtw_kernel(
    py: Python<'_>,
    A: &Bound<'_, PyAny>,
    B: &Bound<'_, PyAny>,
    cost: &str,
    window: Option<i128>,
    normalize: bool,
    multivariate: &str,
) -> PyResult<f64> {
    let (a, b) = (sample_arg("A", A)?, sample_arg("B", B)?);
    let p = kernel_args(py, cost, window, normalize, multivariate)?;
    crate::pool::detach(py, || dtw::dtw_kernel(&a, &b, &p)).py_err()
}

/// ``Delta`` between every sample of ``As`` (rows) and of ``Bs`` (columns), in parallel.
///
/// Parameters
/// ----------
/// As : sequence of samples
///     Each a list of 1-D sequences or a 2-D ``(channels, time)`` array, all with the same
///     channel count (a 3-D array ``(n, channels, time)`` also works).
/// Bs : sequence of samples, optional
///     Default: ``As`` itself; the matrix is then computed once per unordered pair
///     (symmetric, zero diagonal).
/// cost, window, normalize
///     As in :func:`dtw`.
/// multivariate : {"independent", "dependent"}, default "independent"
///     As in :func:`dtw_kernel`.
///
/// Returns
/// -------
/// D : ndarray, shape (n, m)
#[pyfunction]
#[pyo3(signature = (As, Bs=None, cost="abs", window=None, normalize=false, multivariate="independent"))]
#[allow(non_snake_case)]
fn dissimilarity_matrix<'py>(
    py: Python<'py>,
    As: &Bound<'py, PyAny>,
    Bs: Option<&Bound<'py, PyAny>>,
    cost: &str,
    window: Option<i128>,
    normalize: bool,
    multivariate: &str,
) -> PyResult<Arr<'py, f64>> {
    let q = samples_arg("As", As)?;
    let g = Bs
        .filter(|b| !b.is_none())
        .map(|b| samples_arg("Bs", b))
        .transpose()?;
    let p = kernel_args(py, cost, window, normalize, multivariate)?;
    let m = match g {
        Some(g) => crate::pool::detach(py, || dtw::dissimilarity_matrix(&q, &g, &p))?,
        None => crate::pool::detach(py, || dtw::self_dissimilarity(&q, &p))?,
    }
    .py_err()?;
    mat_out(py, &m)
}

/// The gallery sample nearest to ``query`` by ``Delta`` (1-NN with exact early
/// abandoning).
///
/// Parameters
/// ----------
/// query : sample
///     A list of 1-D sequences or a 2-D ``(channels, time)`` array.
/// gallery : sequence of samples
///     With the query's channel count.
/// cost, window, normalize
///     As in :func:`dtw`.
/// multivariate : {"independent", "dependent"}, default "independent"
///     As in :func:`dtw_kernel`.
///
/// Returns
/// -------
/// (index, delta) : (int, float)
///     Ties go to the first index.
#[pyfunction]
#[pyo3(signature = (query, gallery, cost="abs", window=None, normalize=false, multivariate="independent"))]
fn nearest(
    py: Python<'_>,
    query: &Bound<'_, PyAny>,
    gallery: &Bound<'_, PyAny>,
    cost: &str,
    window: Option<i128>,
    normalize: bool,
    multivariate: &str,
) -> PyResult<(usize, f64)> {
    let q = sample_arg("query", query)?;
    let g = samples_arg("gallery", gallery)?;
    let p = kernel_args(py, cost, window, normalize, multivariate)?;
    crate::pool::detach(py, || dtw::nearest(&q, &g, &p)).py_err()
}

/// Reads a UCR/UEA archive ``.ts`` file (as shipped inside the sktime wheel).
///
/// Parameters
/// ----------
/// path : str or path-like
///
/// Returns
/// -------
/// cases : list of list of ndarray
///     ``cases[i][d]``: dimension ``d`` of case ``i`` (a missing value ``?`` reads as NaN;
///     lengths may differ between cases).
/// labels : list of str
///     Class label of each case, as written in the file.
///
/// Raises
/// ------
/// OSError
///     Unreadable or malformed file.
#[pyfunction]
fn load_ts<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
) -> PyResult<(Bound<'py, PyList>, Vec<String>)> {
    let path = args::path("path", path)?;
    let data = crate::pool::detach(py, || ts_file::read_ts(&path)).py_err()?;
    let series = PyList::empty(py);
    for case in data.series {
        let dims = PyList::empty(py);
        for dim in case {
            dims.append(vector(py, dim)?)?;
        }
        series.append(dims)?;
    }
    Ok((series, data.labels))
}

// ------------------------------------------------------------------------------------------
// Files and baselines

/// Reads a skeleton stream: ``.npy`` (shape ``(T, 25, 3)`` or ``(T, 20, 3)``), an NTU
/// RGB+D ``.skeleton`` file, or CSV rows ``frame, joint, x, y, z``.
///
/// CSV joints are Kinect v2 or Kinect v1 SDK names (``SpineBase``, ``HipCenter``,
/// ``ShoulderCenter``, ...) or indices; a file naming no Neck, HandTip or Thumb joint (and
/// with indices below 20) is a Kinect v1 stream of 20 joints, returned in the v1 SDK's
/// order (:data:`KINECT_V1_NAMES`). Optional header; ``#`` comments.
///
/// NTU RGB+D files hold several bodies per frame: ``body`` picks one by its ``bodyID``
/// (``None``: the body with the most tracked joints over the file). Frames before its first
/// and after its last appearance are dropped; interior absences of at most ``max_gap``
/// frames are interpolated linearly.
///
/// Parameters
/// ----------
/// path : str or path-like
/// fps : float, default 30.0
///     Frame rate (validated).
/// body : int, optional
///     NTU body id (see :func:`load_ntu_bodies`).
/// max_gap : int, default 10
///     Longest NTU absence interpolated, frames.
///
/// Returns
/// -------
/// frames : ndarray, shape (T, 25, 3) or (T, 20, 3)
///
/// Raises
/// ------
/// OSError
///     Unreadable or malformed file (a frame missing a joint, a bad number, an NTU header
///     that does not match the values, no body with the id, a longer absence).
/// ValueError
///     NaN coordinates, fewer than 3 frames, ``fps <= 0``, a wrong ``.npy`` shape.
#[pyfunction]
#[pyo3(signature = (path, fps=30.0, body=None, max_gap=10))]
fn load_skeleton<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    fps: f64,
    body: Option<i128>,
    max_gap: i128,
) -> PyResult<Arr<'py, f64>> {
    let path = args::path("path", path)?;
    let fps = fps_arg(fps)?;
    let body = match body {
        Some(b) => gait::BodyChoice::Id(uint(py, "body", b, 0)?),
        None => gait::BodyChoice::MostTracked,
    };
    let ntu = gait::NtuParams::default()
        .body(body)
        .max_gap(uint(py, "max_gap", max_gap, 0)?);
    let s = crate::pool::detach(py, || gait::read_skeleton_with(&path, fps, &ntu)).py_err()?;
    seq_out(py, &s)
}

/// The bodies of an NTU RGB+D file: `(id, frames present, tracked joints)`.
#[pyfunction]
fn load_ntu_bodies(py: Python<'_>, path: PathBuf) -> PyResult<Vec<(u64, usize, usize)>> {
    crate::pool::detach(py, || gait::ntu_bodies(&path)).py_err()
}

/// Writes a skeleton CSV (header ``frame,joint,x,y,z``, joints by name, 6 decimals).
///
/// Parameters
/// ----------
/// path : str or path-like
/// frames : array_like, shape (T, 25, 3)
/// fps : float, default 30.0
///     Only validated (CSV files carry no frame rate).
#[pyfunction]
#[pyo3(signature = (path, frames, fps=30.0))]
fn save_skeleton_csv(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    frames: &Bound<'_, PyAny>,
    fps: f64,
) -> PyResult<()> {
    let path = args::path("path", path)?;
    let s = frames_arg(py, frames, fps)?;
    crate::pool::detach(py, || gait::write_skeleton_csv(&path, &s)).py_err()
}

/// Features of a walk over a cycle (default: detected) by one of the baselines' extractors.
fn baseline_features<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    cycle: Option<&Bound<'py, PyAny>>,
    fps: f64,
    extract: fn(&SkeletonSeq, &GaitCycle) -> wscg_math::Result<Vec<f64>>,
) -> PyResult<Arr<'py, f64>> {
    let s = frames_arg(py, frames, fps)?;
    let cycle = cycle_arg(py, cycle)?;
    let f = crate::pool::detach(py, || extract(&s, &cycle_of(&s, cycle)?)).py_err()?;
    vector(py, f)
}

/// Ball et al.'s 18 gait features (baseline of Table 1).
///
/// Parameters
/// ----------
/// frames : array_like, shape (T, 25, 3)
/// cycle : (start, mid, end), optional
///     Default: detected.
/// fps : float, default 30.0
///
/// Returns
/// -------
/// ndarray, shape (18,)
///     ``[mean, std, max]`` over the cycle of the angles hip L, hip R, knee L, knee R,
///     ankle L, ankle R (radians), angle-major.
///
/// Notes
/// -----
/// Hip: between the trunk (SpineMid - SpineBase) and the thigh (Knee - Hip); knee: at the
/// knee between hip and ankle; ankle: at the ankle between knee and foot. The definitions
/// are our reading of the 2-page paper.
///
/// References
/// ----------
/// A. Ball, D. Rye, F. Ramos and M. Velonaki, "Unsupervised clustering of people from
/// 'skeleton' data", HRI 2012.
#[pyfunction]
#[pyo3(signature = (frames, cycle=None, fps=30.0))]
fn ball_features<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    cycle: Option<&Bound<'py, PyAny>>,
    fps: f64,
) -> PyResult<Arr<'py, f64>> {
    baseline_features(py, frames, cycle, fps, |s, c| {
        Ok(gait::ball_features(s, c)?.to_vec())
    })
}

/// Preis et al.'s 13 anthropometric and step features (baseline of Table 1).
///
/// Parameters
/// ----------
/// frames : array_like, shape (T, 25, 3)
/// cycle : (start, mid, end), optional
///     Default: detected.
/// fps : float, default 30.0
///
/// Returns
/// -------
/// ndarray, shape (13,)
///     ``[height, leg length, torso, lower leg L, lower leg R, thigh L, thigh R, upper arm
///     L, upper arm R, forearm L, forearm R, step length, speed]`` in metres and m/s; bone
///     lengths are per-frame medians over the cycle.
///
/// References
/// ----------
/// J. Preis, M. Kessel, M. Werner and C. Linnhoff-Popien, "Gait recognition with Kinect",
/// Workshop on Kinect in Pervasive Computing, 2012.
#[pyfunction]
#[pyo3(signature = (frames, cycle=None, fps=30.0))]
fn preis_features<'py>(
    py: Python<'py>,
    frames: &Bound<'py, PyAny>,
    cycle: Option<&Bound<'py, PyAny>>,
    fps: f64,
) -> PyResult<Arr<'py, f64>> {
    baseline_features(py, frames, cycle, fps, |s, c| {
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
        walks: Vec<Bound<'_, PyAny>>,
        labels: Vec<u32>,
        fps: f64,
        min_bins: f64,
        vote: &str,
        cost: &str,
        window: Option<i128>,
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
            .dtw(dtw_args(py, cost, window, false)?)
            .vote(Vote::parse(vote).py_err()?);
        let seqs = walks
            .iter()
            .enumerate()
            .map(|(i, w)| walk_arg(py, &format!("X[{i}]"), w, fps))
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
    #[pyo3(signature = (frames, fps, name = "frames"))]
    #[allow(clippy::type_complexity)]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        frames: &Bound<'py, PyAny>,
        fps: f64,
        name: &str,
    ) -> PyResult<(
        u32,
        Arr<'py, i64>,
        Vec<u32>,
        Arr<'py, f64>,
        Option<(usize, usize, usize)>,
    )> {
        let s = walk_arg(py, name, frames, fps)?;
        let pr = crate::pool::detach(py, || self.inner.predict(&s)).py_err()?;
        let idx = index_vector(py, pr.ranked.iter().map(|r| r.0))?;
        let labels = pr.ranked.iter().map(|r| r.1).collect();
        let d = vector(py, pr.ranked.iter().map(|r| r.2).collect())?;
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

fn range2(name: &str, r: &Bound<'_, PyAny>) -> PyResult<[f64; 2]> {
    let r = args::pair(name, r)?;
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
    n_subjects: i128,
    n_sessions: i128,
    seed: i128,
    heading_deg: &Bound<'py, PyAny>,
    speed: &Bound<'py, PyAny>,
    walk_s: &Bound<'py, PyAny>,
    sit_prob: f64,
    noise: bool,
    n_joints: i128,
) -> PyResult<Bound<'py, PyDict>> {
    let joint_set = joint_set_in(uint(py, "n_joints", n_joints, 0)?)?;
    let n_subjects: usize = uint(py, "n_subjects", n_subjects, 1)?;
    let n_sessions: usize = uint(py, "n_sessions", n_sessions, 1)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
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
        minima.append(index_vector(py, t.minima.iter().copied())?)?;
    }
    let d = PyDict::new(py);
    d.set_item("frames", frames)?;
    d.set_item(
        "labels",
        index_vector(py, set.labels.iter().map(|&l| l as usize))?,
    )?;
    d.set_item(
        "sessions",
        index_vector(py, set.session_index.iter().copied())?,
    )?;
    d.set_item("minima", minima)?;
    d.set_item(
        "walk_frames",
        index_vector(py, set.truth.iter().map(|t| t.walk_frames))?,
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
    n_subjects: i128,
    n_sessions: i128,
    seed: i128,
    n_joints: i128,
) -> PyResult<Bound<'_, PyDict>> {
    let joint_set = joint_set_in(uint(py, "n_joints", n_joints, 0)?)?;
    let n_subjects: usize = uint(py, "n_subjects", n_subjects, 2)?;
    let n_sessions: usize = uint(py, "n_sessions", n_sessions, 2)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
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
