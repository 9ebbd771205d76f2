//! `wscg._native.motion`, paper 16: bindings of `wscg_motion` (anechoic demixing with shared
//! delays, the PCA baseline, step-wise learning of the walk-and-reach actions, predictive step
//! planning, online synthesis with Hopf oscillators, BVH files, the regression statistics and
//! the ε-SVR).
//!
//! `pca_qualities`, `pca_quality`, `quality`, `save_bvh`, `forward_kinematics` and
//! `regression_p_value` are `wscg.motion`'s functions themselves, re-exported by
//! `python/wscg/motion.py` (which holds the module's documentation), their arguments converted
//! by [`crate::args`]; the others return the dicts from which the Python layer builds its
//! result classes and estimators, and take C-contiguous float64 arrays and plain numbers.
//! Every function checks shapes and values, so a direct call cannot panic on bad arguments.
//! The GIL is released while Rust works.

use std::f64::consts::TAU;

use num_complex::Complex64;
use numpy::{PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use wscg_math::Error;
use wscg_motion::anechoic::{fit_anechoic as fit_anechoic_rs, AnechoicParams, DelayMode, Init};
use wscg_motion::bvh::{self, BvhMotion, JointMap, RetargetParams};
use wscg_motion::bvh_file;
use wscg_motion::data::{quality as quality_rs, TrialSet};
use wscg_motion::dataset::{Dataset, TrialAction};
use wscg_motion::hopf::StarNetwork;
use wscg_motion::map::{SvrMapParams, MAX_LUT_SIZE};
use wscg_motion::pca::pca_qualities as pca_qualities_rs;
use wscg_motion::planner::{Action, Plan, Planner};
use wscg_motion::skeleton::{bones as bones_rs, forward_kinematics as fk_rs, JOINTS, N_CHANNELS};
use wscg_motion::stats::{fit_line as fit_line_rs, regression_p_value as p_value_rs};
use wscg_motion::stepwise::{fit_stepwise as fit_stepwise_rs, ActionLibrary, StepwiseParams};
use wscg_motion::svr::Svr;
use wscg_motion::synthesizer::{planner_for, MapKind, Synthesizer, SynthesizerParams};
use wscg_motion::walker::{reach_walk, WalkerParams};

use crate::args::{self, positive, uint};
use crate::convert::{array, values, vector, Arr};
use crate::errors::{value_error, IntoPy};

/// Largest number of values a generated or simulated array may hold (400 MB of float64).
const MAX_VALUES: usize = 50_000_000;
/// Largest number of frames of one synthesis (`fps * max_seconds`).
const MAX_FRAMES: f64 = 1_000_000.0;
/// Largest number of demixing restarts.
const MAX_RESTARTS: usize = 10_000;

/// Errors unless every value is finite.
fn check_finite(name: &str, v: &[f64]) -> PyResult<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(value_error(format!(
            "`{name}` contains a non-finite value (NaN or infinity) at flat index {i}"
        ))),
    }
}

/// A trial set from an `(R, I, N)` array, or `(R, N)` read as `I = 1`.
fn trials_in(name: &str, a: &PyReadonlyArrayDyn<f64>) -> PyResult<TrialSet> {
    let (r, i, n) = match *a.shape() {
        [r, i, n] => (r, i, n),
        [r, n] => (r, 1, n),
        ref s => {
            return Err(value_error(format!(
                "`{name}` must be an (R, I, N) array of trials x channels x samples \
                 (or (rows, N)), got shape {s:?}"
            )))
        }
    };
    let v = values(a);
    check_finite(name, &v)?;
    TrialSet::new(r, i, n, v.into_owned()).py_err()
}

/// `(R, I, N)` array of a trial set.
fn trials_out<'py>(py: Python<'py>, t: &TrialSet) -> PyResult<Arr<'py, f64>> {
    array(py, &[t.n_trials, t.n_channels, t.n_samples], t.data.clone())
}

fn action_name(a: Action) -> &'static str {
    match a {
        Action::Step => "step",
        Action::ShortStep => "short_step",
        Action::Reach => "reach",
    }
}

// ------------------------------------------------------------------------------------------
// Synthetic data

/// A dataset as the dict of arrays of `MotionDataset` (`root` `None` when the actions have
/// no root curves).
fn dataset_out<'py>(py: Python<'py>, data: &Dataset) -> PyResult<Bound<'py, PyDict>> {
    let (r_n, i_n, n) = (data.trials.len(), data.n_channels, data.n_samples);
    let actions = || data.trials.iter().flat_map(|t| t.iter());
    let angles: Vec<f64> = actions().flat_map(|a| a.angles.iter().copied()).collect();
    let steps: Vec<f64> = actions().map(|a| a.step_length).collect();
    let durations: Vec<f64> = actions().map(|a| a.duration).collect();
    let d = PyDict::new(py);
    d.set_item("angles", array(py, &[r_n, 3, i_n, n], angles)?)?;
    d.set_item("step_length", array(py, &[r_n, 3], steps)?)?;
    d.set_item("duration", array(py, &[r_n, 3], durations)?)?;
    if actions().all(|a| a.root.len() == n) {
        let root: Vec<f64> = actions().flat_map(|a| a.root.iter().copied()).collect();
        d.set_item("root", array(py, &[r_n, 3, n], root)?)?;
    } else {
        d.set_item("root", py.None())?;
    }
    d.set_item("distances", vector(py, data.distances.to_vec())?)?;
    Ok(d)
}

/// Reads a training folder (`angles.npy`, `root.npy`, `steps.csv`) as a dict of arrays.
#[pyfunction]
fn load_dataset<'py>(py: Python<'py>, path: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    let path = args::path("path", path)?;
    let data = crate::pool::detach(py, || wscg_motion::read_dataset(&path)).py_err()?;
    dataset_out(py, &data)
}

/// Writes a dataset's arrays as a training folder.
#[pyfunction]
#[pyo3(signature = (path, angles, step_length, duration, root=None))]
fn save_dataset(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    angles: &Bound<'_, PyAny>,
    step_length: &Bound<'_, PyAny>,
    duration: &Bound<'_, PyAny>,
    root: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let path = args::path("path", path)?;
    let angles = args::array::<f64>("angles", angles)?;
    let step_length = args::array::<f64>("step_length", step_length)?;
    let duration = args::array::<f64>("duration", duration)?;
    let root = root
        .filter(|r| !r.is_none())
        .map(|r| args::array::<f64>("root", r))
        .transpose()?;
    let data = dataset_in(&angles, &step_length, &duration, root.as_ref(), None)?;
    crate::pool::detach(py, || wscg_motion::write_dataset(&path, &data)).py_err()
}

/// The synthetic walk-and-reach training set and its ground truth as a dict of arrays.
#[pyfunction]
#[pyo3(signature = (n_trials, seed, noise, human_like, n_samples, model_seed))]
fn make_synthetic_dataset<'py>(
    py: Python<'py>,
    n_trials: i128,
    seed: i128,
    noise: f64,
    human_like: bool,
    n_samples: i128,
    model_seed: i128,
) -> PyResult<Bound<'py, PyDict>> {
    let n_trials: usize = uint(py, "n_trials", n_trials, 1)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let noise = args::number("noise", noise)?;
    let n_samples: usize = uint(py, "n_samples", n_samples, 8)?;
    let model_seed: u64 = uint(py, "model_seed", model_seed, 0)?;
    let total = n_trials
        .checked_mul(n_samples)
        .and_then(|v| v.checked_mul(6 * N_CHANNELS));
    if total.is_none_or(|t| t > MAX_VALUES) {
        return Err(value_error(format!(
            "{n_trials} trials of {n_samples} samples exceed the size limit \
             (n_trials * n_samples <= {})",
            MAX_VALUES / (6 * N_CHANNELS)
        )));
    }
    let cfg = WalkerParams::default()
        .n_trials(n_trials)
        .n_samples(n_samples)
        .noise(noise)
        .seed(seed)
        .model_seed(model_seed)
        .human_like(human_like);
    let (data, truth) = crate::pool::detach(py, || reach_walk(&cfg)).py_err()?;
    let (r_n, i_n, n) = (data.trials.len(), data.n_channels, data.n_samples);
    let d = dataset_out(py, &data)?;

    let j_n = truth.sources.len();
    let t = PyDict::new(py);
    let periodic: Vec<f64> = truth
        .periodic
        .iter()
        .flat_map(|p| p.data.iter().copied())
        .collect();
    t.set_item("periodic", array(py, &[3, r_n, i_n, n], periodic)?)?;
    t.set_item("delays", array(py, &[i_n, j_n], truth.delays.clone())?)?;
    t.set_item(
        "weights",
        array(py, &[3, r_n, i_n, j_n], truth.weights.concat())?,
    )?;
    t.set_item("means", array(py, &[3, r_n, i_n], truth.means.concat())?)?;
    t.set_item("w0", array(py, &[3, r_n, i_n], truth.w0.concat())?)?;
    let sources: Vec<f64> = truth
        .sources
        .iter()
        .flat_map(|s| s.sample(n, 0.0))
        .collect();
    t.set_item("sources", array(py, &[j_n, n], sources)?)?;
    let k = truth.sources.first().map_or(0, |s| s.n_harmonics());
    let coeffs: Vec<Complex64> = truth
        .sources
        .iter()
        .flat_map(|s| s.coeffs.iter().copied())
        .collect();
    t.set_item("source_coeffs", array(py, &[j_n, k], coeffs)?)?;
    d.set_item("truth", t)?;
    Ok(d)
}

// ------------------------------------------------------------------------------------------
// Demixing and PCA

fn delay_mode(s: &str) -> PyResult<DelayMode> {
    match s {
        "shared" => Ok(DelayMode::Shared),
        "per_trial" => Ok(DelayMode::PerTrial),
        "zero" => Ok(DelayMode::Zero),
        other => Err(value_error(format!(
            "`delays` must be 'shared', 'per_trial' or 'zero', got {other:?}"
        ))),
    }
}

fn init_from(s: &str) -> PyResult<Init> {
    match s {
        "pca" => Ok(Init::Pca),
        "random" => Ok(Init::Random),
        "greedy" => Ok(Init::Greedy),
        "orbit" => Ok(Init::Orbit),
        other => Err(value_error(format!(
            "`init` must be 'pca', 'random', 'greedy' or 'orbit', got {other:?}"
        ))),
    }
}

/// The restart count `n`, in `1..=MAX_RESTARTS`.
fn restarts(py: Python<'_>, n: i128) -> PyResult<usize> {
    let n = uint(py, "n_restarts", n, 1usize)?;
    if n > MAX_RESTARTS {
        return Err(value_error(format!(
            "`n_restarts` must be <= {MAX_RESTARTS}, got {n}"
        )));
    }
    Ok(n)
}

/// Anechoic demixing of `x` (`R x I x N`): quality, sources, delays, weights, reconstruction.
#[pyfunction]
#[pyo3(signature = (x, n_sources, delays, n_harmonics, n_restarts, max_iter, tol, seed, init, delay_search))]
#[allow(clippy::too_many_arguments)]
fn fit_anechoic<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    n_sources: i128,
    delays: &str,
    n_harmonics: i128,
    n_restarts: i128,
    max_iter: i128,
    tol: f64,
    seed: i128,
    init: &str,
    delay_search: i128,
) -> PyResult<Bound<'py, PyDict>> {
    let x = args::array::<f64>("X", x)?;
    if x.shape().len() != 3 {
        return Err(value_error(format!(
            "`X` must be an (R, I, N) array of trials x channels x samples, got shape {}",
            args::shape_repr(x.shape())
        )));
    }
    let set = trials_in("X", &x)?;
    let cfg = AnechoicParams::default()
        .n_sources(uint(py, "n_sources", n_sources, 1)?)
        .n_harmonics(uint(py, "n_harmonics", n_harmonics, 1)?)
        .delays(delay_mode(delays)?)
        .max_iter(uint(py, "max_iter", max_iter, 1)?)
        .tol(tol)
        .restarts(restarts(py, n_restarts)?)
        .init(init_from(init)?)
        .seed(uint(py, "seed", seed, 0)?)
        .delay_search(uint(py, "delay_search", delay_search, 0)?);
    let (model, recon) = crate::pool::detach(py, || {
        let m = fit_anechoic_rs(&set, &cfg)?;
        let r = m.reconstruct();
        Ok::<_, Error>((m, r))
    })
    .py_err()?;
    let (r_n, i_n, n, j_n) = (
        model.n_trials,
        model.n_channels,
        model.n_samples,
        model.n_sources(),
    );
    let d = PyDict::new(py);
    d.set_item("q", model.q)?;
    d.set_item("q_history", vector(py, model.q_history.to_vec())?)?;
    let sources: Vec<f64> = model
        .sources
        .iter()
        .flat_map(|s| s.sample(n, 0.0))
        .collect();
    d.set_item("sources", array(py, &[j_n, n], sources)?)?;
    let coeffs: Vec<Complex64> = model
        .sources
        .iter()
        .flat_map(|s| s.coeffs.iter().copied())
        .collect();
    d.set_item(
        "source_coeffs",
        array(py, &[j_n, model.sources[0].n_harmonics()], coeffs)?,
    )?;
    let dshape: Vec<usize> = if model.delay_mode == DelayMode::PerTrial {
        vec![r_n, i_n, j_n]
    } else {
        vec![i_n, j_n]
    };
    d.set_item("delays", array(py, &dshape, model.delays.clone())?)?;
    d.set_item(
        "weights",
        array(py, &[r_n, i_n, j_n], model.weights.clone())?,
    )?;
    d.set_item("reconstruction", trials_out(py, &recon)?)?;
    Ok(d)
}

/// The trial set of the argument `name` (any real array-like, `(R, I, N)` or `(rows, N)`).
fn trials_arg(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<TrialSet> {
    trials_in(name, &args::array::<f64>(name, obj)?)
}

/// Cumulative explained-variance ratios ``Q_PCA(1), Q_PCA(2), ...`` (paper Fig. 4).
///
/// PCA of the ``(R * I) x N`` signal matrix: each row a channel of one trial, each column a
/// time sample, rows centred over time. ``Q_PCA(J)`` equals scikit-learn's
/// ``PCA(J).fit(X.reshape(-1, N).T).explained_variance_ratio_.sum()``.
///
/// Parameters
/// ----------
/// X : array_like, shape (R, I, N) or (rows, N)
///
/// Returns
/// -------
/// ndarray, shape (min(R * I, N),)
#[pyfunction]
#[allow(non_snake_case)]
fn pca_qualities<'py>(py: Python<'py>, X: &Bound<'py, PyAny>) -> PyResult<Arr<'py, f64>> {
    let set = trials_arg("X", X)?;
    let q = crate::pool::detach(py, || pca_qualities_rs(&set)).py_err()?;
    vector(py, q.to_vec())
}

/// ``Q_PCA(j)``: the fraction of variance of the ``j`` leading principal components of
/// the ``(R * I) x N`` signal matrix (see :func:`pca_qualities`).
///
/// Parameters
/// ----------
/// X : array_like, shape (R, I, N) or (rows, N)
/// j : int
///     Number of components, ``1 <= j <= min(R * I, N)``.
#[pyfunction]
#[allow(non_snake_case)]
fn pca_quality(py: Python<'_>, X: &Bound<'_, PyAny>, j: i128) -> PyResult<f64> {
    let set = trials_arg("X", X)?;
    let j: usize = uint(py, "j", j, 1)?;
    let q = crate::pool::detach(py, || pca_qualities_rs(&set)).py_err()?;
    if j == 0 || j > q.len() {
        return Err(value_error(format!(
            "`j` must be in 1..={}, got {j}",
            q.len()
        )));
    }
    Ok(q[j - 1])
}

/// Approximation quality ``Q = 1 - ||X - Xhat||_F^2 / ||X||_F^2`` (paper Fig. 4).
///
/// Parameters
/// ----------
/// X, Xhat : array_like
///     Arrays of the same shape; ``X`` not all zero.
#[pyfunction]
#[allow(non_snake_case)]
fn quality(py: Python<'_>, X: &Bound<'_, PyAny>, Xhat: &Bound<'_, PyAny>) -> PyResult<f64> {
    let x = args::array::<f64>("X", X)?;
    let xhat = args::array::<f64>("Xhat", Xhat)?;
    if x.shape() != xhat.shape() {
        return Err(value_error(format!(
            "shape mismatch: `X` has shape {:?}, `Xhat` {:?}",
            x.shape(),
            xhat.shape()
        )));
    }
    let (a, b) = (values(&x), values(&xhat));
    check_finite("X", &a)?;
    check_finite("Xhat", &b)?;
    let n = a.len();
    let xs = TrialSet::new(1, 1, n, a.into_owned()).py_err()?;
    let ys = TrialSet::new(1, 1, n, b.into_owned()).py_err()?;
    crate::pool::detach(py, || quality_rs(&xs, &ys)).py_err()
}

// ------------------------------------------------------------------------------------------
// Step-wise learning

/// The dataset of the arrays of `make_synthetic_dataset` (`root` and `distances` optional).
fn dataset_in(
    angles: &PyReadonlyArrayDyn<f64>,
    step_length: &PyReadonlyArrayDyn<f64>,
    duration: &PyReadonlyArrayDyn<f64>,
    root: Option<&PyReadonlyArrayDyn<f64>>,
    distances: Option<&PyReadonlyArrayDyn<f64>>,
) -> PyResult<Dataset> {
    let (r_n, i_n, n) = match *angles.shape() {
        [r, 3, i, n] => (r, i, n),
        ref s => {
            return Err(value_error(format!(
                "`angles` must be an (R, 3, I, N) array (trials x actions x channels x \
                 samples), got shape {s:?}"
            )))
        }
    };
    for (name, a) in [("step_length", step_length), ("duration", duration)] {
        if a.shape() != [r_n, 3] {
            return Err(value_error(format!(
                "`{name}` must have shape ({r_n}, 3), got {:?}",
                a.shape()
            )));
        }
    }
    let av = values(angles);
    check_finite("angles", &av)?;
    let (sv, dv) = (values(step_length), values(duration));
    check_finite("step_length", &sv)?;
    check_finite("duration", &dv)?;
    let rv = match root {
        Some(r) => {
            if r.shape() != [r_n, 3, n] {
                return Err(value_error(format!(
                    "`root` must have shape ({r_n}, 3, {n}), got {:?}",
                    r.shape()
                )));
            }
            let v = values(r).into_owned();
            check_finite("root", &v)?;
            Some(v)
        }
        None => None,
    };
    let distances = match distances {
        Some(d) => {
            let v = values(d).into_owned();
            check_finite("distances", &v)?;
            v
        }
        None => Vec::new(),
    };
    let len = i_n * n;
    let mut trials = Vec::with_capacity(r_n);
    for r in 0..r_n {
        let act = |a: usize| TrialAction {
            angles: av[(r * 3 + a) * len..(r * 3 + a + 1) * len].to_vec(),
            step_length: sv[r * 3 + a],
            duration: dv[r * 3 + a],
            root: rv.as_ref().map_or_else(Vec::new, |v| {
                v[(r * 3 + a) * n..(r * 3 + a + 1) * n].to_vec()
            }),
        };
        trials.push([act(0), act(1), act(2)]);
    }
    let data = Dataset {
        n_channels: i_n,
        n_samples: n,
        trials,
        distances,
    };
    data.validate().py_err()?;
    Ok(data)
}

/// What `fit_stepwise` learns: sources, shared delays and per-trial weights of the three
/// actions.
#[pyclass(module = "wscg._native.motion", name = "Library", frozen)]
pub struct PyLibrary {
    inner: ActionLibrary,
}

#[pymethods]
impl PyLibrary {
    /// `Q` over all three actions.
    #[getter]
    fn q_total(&self) -> f64 {
        self.inner.q_total
    }

    /// `Q` of each action.
    #[getter]
    fn q_actions(&self) -> Vec<f64> {
        self.inner.actions.iter().map(|a| a.q).collect()
    }

    /// `Q` of action 2 with the first sources only.
    #[getter]
    fn q_second_before_extra(&self) -> f64 {
        self.inner.q_second_before_extra
    }

    /// Number of periodic sources `J`.
    #[getter]
    fn n_sources(&self) -> usize {
        self.inner.n_sources()
    }

    /// Channels `I`.
    #[getter]
    fn n_channels(&self) -> usize {
        self.inner.n_channels
    }

    /// Samples per action `N`.
    #[getter]
    fn n_samples(&self) -> usize {
        self.inner.n_samples
    }

    /// The sources sampled over one period, `(J, N)`.
    #[getter]
    fn sources<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        let n = self.inner.n_samples;
        let v: Vec<f64> = self
            .inner
            .sources
            .iter()
            .flat_map(|s| s.sample(n, 0.0))
            .collect();
        array(py, &[self.inner.n_sources(), n], v)
    }

    /// Shared delays `(I, J)` in periods.
    #[getter]
    fn delays<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        array(
            py,
            &[self.inner.n_channels, self.inner.n_sources()],
            self.inner.delays.clone(),
        )
    }

    /// Normalised pelvis progress over an action at `u = m / N`, `m = 0..=N`.
    #[getter]
    fn progress<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        vector(py, self.inner.progress.to_vec())
    }

    /// `(step parameter, duration)` of every trial for action `a`, as an `(R, 2)` array.
    fn params<'py>(&self, py: Python<'py>, a: usize) -> PyResult<Arr<'py, f64>> {
        let p = self
            .inner
            .params
            .get(a)
            .ok_or_else(|| value_error(format!("`action` must be 0, 1 or 2, got {a}")))?;
        array(
            py,
            &[p.len(), 2],
            p.iter().flat_map(|&(x, y)| [x, y]).collect(),
        )
    }

    /// The fit of action `a` as a `wscg.motion.ActionFit`: means and non-periodic weights
    /// `(R, I)`, weights `(R, I, J)`, `q` and the number of sources it uses.
    fn action_fit<'py>(&self, py: Python<'py>, a: usize) -> PyResult<Bound<'py, PyAny>> {
        let f = self
            .inner
            .actions
            .get(a)
            .ok_or_else(|| value_error(format!("`action` must be 0, 1 or 2, got {a}")))?;
        let (i_n, j_n) = (self.inner.n_channels, self.inner.n_sources());
        let r_n = f.means.len() / i_n.max(1);
        let d = PyDict::new(py);
        d.set_item("means", array(py, &[r_n, i_n], f.means.clone())?)?;
        d.set_item("w0", array(py, &[r_n, i_n], f.w0.clone())?)?;
        d.set_item("weights", array(py, &[r_n, i_n, j_n], f.weights.clone())?)?;
        d.set_item("q", f.q)?;
        d.set_item("n_sources", f.n_sources)?;
        py.import("wscg.motion")?
            .getattr("ActionFit")?
            .call((), Some(&d))
    }

    /// The library as JSON (floats round-trip exactly).
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        crate::pool::detach(py, || self.inner.to_json()).py_err()
    }

    /// A library from `to_json`.
    #[staticmethod]
    fn from_json(py: Python<'_>, s: &str) -> PyResult<Self> {
        Ok(Self {
            inner: crate::pool::detach(py, || ActionLibrary::from_json(s)).py_err()?,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Library(n_sources={}, n_channels={}, n_samples={}, q_total={:.6})",
            self.inner.n_sources(),
            self.inner.n_channels,
            self.inner.n_samples,
            self.inner.q_total
        )
    }
}

/// Step-wise learning of the three actions from a dataset's arrays.
#[pyfunction]
#[pyo3(signature = (angles, step_length, duration, root, distances, n_sources_first,
                    n_sources_extra, n_harmonics, n_restarts, max_iter, tol, seed, delay_search))]
#[allow(clippy::too_many_arguments)]
fn fit_stepwise<'py>(
    py: Python<'py>,
    angles: &Bound<'py, PyAny>,
    step_length: &Bound<'py, PyAny>,
    duration: &Bound<'py, PyAny>,
    root: Option<&Bound<'py, PyAny>>,
    distances: Option<&Bound<'py, PyAny>>,
    n_sources_first: i128,
    n_sources_extra: i128,
    n_harmonics: i128,
    n_restarts: i128,
    max_iter: i128,
    tol: f64,
    seed: i128,
    delay_search: i128,
) -> PyResult<PyLibrary> {
    let optional = |name: &str, a: Option<&Bound<'py, PyAny>>| {
        a.filter(|a| !a.is_none())
            .map(|a| args::array::<f64>(name, a))
            .transpose()
    };
    let (root, distances) = (optional("root", root)?, optional("distances", distances)?);
    let data = dataset_in(
        &args::array("angles", angles)?,
        &args::array("step_length", step_length)?,
        &args::array("duration", duration)?,
        root.as_ref(),
        distances.as_ref(),
    )?;
    let cfg = StepwiseParams::default()
        .n_sources_first(uint(py, "n_sources_first", n_sources_first, 1)?)
        .n_sources_extra(uint(py, "n_sources_extra", n_sources_extra, 0)?)
        .demix(
            AnechoicParams::default()
                .n_harmonics(uint(py, "n_harmonics", n_harmonics, 1)?)
                .restarts(restarts(py, n_restarts)?)
                .max_iter(uint(py, "max_iter", max_iter, 1)?)
                .tol(tol)
                .seed(uint(py, "seed", seed, 0)?)
                .delay_search(uint(py, "delay_search", delay_search, 0)?),
        );
    let inner = crate::pool::detach(py, || fit_stepwise_rs(&data, &cfg)).py_err()?;
    Ok(PyLibrary { inner })
}

// ------------------------------------------------------------------------------------------
// Planning and synthesis

fn range_in(name: &str, r: (f64, f64)) -> PyResult<(f64, f64)> {
    if r.0.is_finite() && r.1.is_finite() && r.0 > 0.0 && r.1 >= r.0 {
        Ok(r)
    } else {
        Err(value_error(format!(
            "`{name}` must satisfy 0 < lo <= hi, got ({}, {})",
            r.0, r.1
        )))
    }
}

fn plan_out<'py>(py: Python<'py>, plan: &Plan) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let acts: Vec<(&str, f64)> = plan
        .actions
        .iter()
        .map(|a| (action_name(a.action), a.length))
        .collect();
    d.set_item("actions", PyList::new(py, acts)?)?;
    d.set_item("too_short", plan.too_short)?;
    d.set_item("violation", plan.violation)?;
    d.set_item("n_steps", plan.n_steps())?;
    d.set_item("distance", plan.distance())?;
    Ok(d)
}

/// The predictive planner's split of the goal distance `d` into steps and the reach.
#[pyfunction]
#[pyo3(signature = (d, comfort, gamma, range1, range2, human_like, max_steps))]
#[allow(clippy::too_many_arguments)]
fn plan_steps<'py>(
    py: Python<'py>,
    d: f64,
    comfort: f64,
    gamma: f64,
    range1: &Bound<'py, PyAny>,
    range2: &Bound<'py, PyAny>,
    human_like: Option<f64>,
    max_steps: i128,
) -> PyResult<Bound<'py, PyDict>> {
    let planner = Planner {
        comfort,
        gamma,
        range1: range_in("range1", args::pair("range1", range1)?)?,
        range2: range_in("range2", args::pair("range2", range2)?)?,
        human_like,
        max_steps: uint(py, "max_steps", max_steps, 1)?,
    };
    let plan = crate::pool::detach(py, || planner.plan(d)).py_err()?;
    plan_out(py, &plan)
}

/// The online synthesizer of a learned library.
#[pyclass(module = "wscg._native.motion", name = "Synthesizer")]
pub struct PySynthesizer {
    inner: Synthesizer,
}

#[pymethods]
impl PySynthesizer {
    #[new]
    #[pyo3(signature = (lib, comfort, gamma, map, beta, coupling, lut_size, bandwidth,
                        human_like, svr_c, svr_epsilon, svr_gamma))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        lib: &PyLibrary,
        comfort: f64,
        gamma: f64,
        map: &str,
        beta: f64,
        coupling: f64,
        lut_size: i128,
        bandwidth: Option<f64>,
        human_like: Option<f64>,
        svr_c: f64,
        svr_epsilon: f64,
        svr_gamma: f64,
    ) -> PyResult<Self> {
        let map = match map {
            "lut" => {
                let lut_size = uint(py, "lut_size", lut_size, 0usize)?;
                if !(4..=MAX_LUT_SIZE).contains(&lut_size) {
                    return Err(value_error(format!(
                        "`lut_size` must be in 4..={MAX_LUT_SIZE}, got {lut_size}"
                    )));
                }
                MapKind::Lut(lut_size)
            }
            "fourier" => MapKind::Fourier,
            "svr" => MapKind::Svr(
                SvrMapParams::default()
                    .c(svr_c)
                    .epsilon(svr_epsilon)
                    .gamma(svr_gamma),
            ),
            other => {
                return Err(value_error(format!(
                    "`map` must be 'lut', 'fourier' or 'svr', got {other:?}"
                )))
            }
        };
        if let Some(b) = bandwidth {
            positive("bandwidth", b)?;
        }
        let planner = Planner {
            comfort,
            gamma,
            human_like,
            ..planner_for(&lib.inner)
        };
        let cfg = SynthesizerParams::default()
            .beta(beta)
            .coupling(coupling)
            .map(map)
            .bandwidth(bandwidth);
        let lib = lib.inner.clone();
        let inner = crate::pool::detach(py, || Synthesizer::new(lib, planner, cfg)).py_err()?;
        Ok(Self { inner })
    }

    /// The planner's parameters: comfort, gamma, range1, range2, human_like.
    #[getter]
    fn planner<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = self.inner.planner();
        let d = PyDict::new(py);
        d.set_item("comfort", p.comfort)?;
        d.set_item("gamma", p.gamma)?;
        d.set_item("range1", p.range1)?;
        d.set_item("range2", p.range2)?;
        d.set_item("human_like", p.human_like)?;
        Ok(d)
    }

    /// The plan of the synthesizer's planner for a goal at distance `d`.
    fn plan<'py>(&self, py: Python<'py>, d: f64) -> PyResult<Bound<'py, PyDict>> {
        let planner = self.inner.planner();
        let plan = crate::pool::detach(py, || planner.plan(d)).py_err()?;
        plan_out(py, &plan)
    }

    /// Synthesizes a whole walk-and-reach sequence towards `goal`.
    #[pyo3(signature = (goal, fps, goal_changes, max_seconds))]
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        goal: f64,
        fps: f64,
        goal_changes: &Bound<'py, PyAny>,
        max_seconds: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let goal_changes = goal_changes
            .try_iter()
            .map_err(|_| value_error("`goal_changes` must hold (time, distance) pairs"))?
            .map(|c| args::pair("goal_changes", &c?))
            .collect::<PyResult<Vec<_>>>()?;
        positive("fps", fps)?;
        positive("max_seconds", max_seconds)?;
        if fps * max_seconds > MAX_FRAMES {
            return Err(value_error(format!(
                "fps * max_seconds must be <= {MAX_FRAMES}, got {}",
                fps * max_seconds
            )));
        }
        let syn = &mut self.inner;
        let out =
            crate::pool::detach(py, || syn.run(goal, fps, &goal_changes, max_seconds)).py_err()?;
        let t_n = out.frames.len();
        let i_n = out.frames.first().map_or(0, |f| f.angles.len());
        let mut angles = Vec::with_capacity(t_n * i_n);
        for f in &out.frames {
            angles.extend_from_slice(&f.angles);
        }
        let col = |g: fn(&wscg_motion::synthesizer::Frame) -> f64| -> Vec<f64> {
            out.frames.iter().map(g).collect()
        };
        let d = PyDict::new(py);
        d.set_item("angles", array(py, &[t_n, i_n], angles)?)?;
        d.set_item("root_x", array(py, &[t_n], col(|f| f.root_x))?)?;
        d.set_item("time", array(py, &[t_n], col(|f| f.time))?)?;
        d.set_item("phase", array(py, &[t_n], col(|f| f.phase))?)?;
        let codes: Vec<i64> = out.frames.iter().map(|f| f.action.index() as i64).collect();
        d.set_item("action", array(py, &[t_n], codes)?)?;
        let executed: Vec<(&str, f64)> = out
            .executed
            .iter()
            .map(|a| (action_name(a.action), a.length))
            .collect();
        d.set_item("executed", PyList::new(py, executed)?)?;
        d.set_item(
            "transitions",
            array(py, &[out.transitions.len(), i_n], out.transitions.concat())?,
        )?;
        d.set_item("too_short", out.too_short)?;
        d.set_item("goal", goal)?;
        Ok(d)
    }
}

// ------------------------------------------------------------------------------------------
// Skeleton and BVH

/// `(T, 51)` frames of an angle array (a single frame of 51 values is accepted).
fn frames_in(name: &str, a: &PyReadonlyArrayDyn<f64>) -> PyResult<Vec<Vec<f64>>> {
    let ok = match *a.shape() {
        [t, c] => t > 0 && c == N_CHANNELS,
        _ => false,
    };
    if !ok {
        return Err(value_error(format!(
            "`{name}` must be a (T, {N_CHANNELS}) array of exponential-map channels with T >= 1, \
             got shape {:?}",
            a.shape()
        )));
    }
    let v = values(a);
    check_finite(name, &v)?;
    Ok(v.chunks_exact(N_CHANNELS).map(<[f64]>::to_vec).collect())
}

/// Pelvis positions from `(T,)` forward positions (hips at the rest height) or `(T, 3)`
/// positions, in metres.
fn root_in(a: &PyReadonlyArrayDyn<f64>, t_n: usize) -> PyResult<Vec<[f64; 3]>> {
    let v = values(a);
    check_finite("root", &v)?;
    match *a.shape() {
        [t] if t == t_n => Ok(bvh::motion_from_frames(Vec::new(), &v, 1.0).root),
        [t, 3] if t == t_n => Ok(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()),
        ref s => Err(value_error(format!(
            "`root` must have shape ({t_n},) (forward positions) or ({t_n}, 3), got {s:?}"
        ))),
    }
}

/// Frames of exponential-map channels and their pelvis positions.
type Frames = (Vec<Vec<f64>>, Vec<[f64; 3]>);

/// The frames of the `angles` `(T, 51)` (one frame: `(51,)`) and `root` `(T,)` or `(T, 3)`
/// (one frame: a number) arguments, any real array-likes.
fn frames_arg(angles: &Bound<'_, PyAny>, root: &Bound<'_, PyAny>) -> PyResult<Frames> {
    let mut a = args::array::<f64>("angles", angles)?;
    if a.ndim() == 1 {
        a = a.reshape(vec![1, a.len()])?.readonly();
    }
    let mut r = args::array::<f64>("root", root)?;
    if r.ndim() == 0 {
        r = r.reshape(vec![1usize])?.readonly();
    }
    let frames = frames_in("angles", &a)?;
    let root = root_in(&r, frames.len())?;
    Ok((frames, root))
}

/// Writes frames of the 17-joint skeleton as a BVH file.
///
/// Rotations become ``Zrotation Xrotation Yrotation`` Euler angles in degrees; positions
/// are in centimetres; the pelvis walks along +z.
///
/// Parameters
/// ----------
/// path : str or PathLike
/// angles : array_like, shape (T, 51)
///     Exponential-map channels per frame.
/// root : array_like, shape (T,) or (T, 3)
///     Pelvis forward position in metres (hips at the rest height), or full positions (as
///     :func:`forward_kinematics` takes them).
/// fps : float
///     Frame rate (> 0).
#[pyfunction]
#[pyo3(signature = (path, angles, root, fps=120.0))]
fn save_bvh(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    angles: &Bound<'_, PyAny>,
    root: &Bound<'_, PyAny>,
    fps: f64,
) -> PyResult<()> {
    let path = args::path("path", path)?;
    let (frames, root) = frames_arg(angles, root)?;
    positive("fps", fps)?;
    let motion = BvhMotion {
        frame_time: 1.0 / fps,
        angles: frames,
        root,
    };
    crate::pool::detach(py, || bvh::write_bvh(&path, &motion)).py_err()
}

/// Reads a BVH file of any skeleton onto the 17-joint skeleton. `joint_map`: `("auto", "")`,
/// `("builtin", name)`, `("json", text)` or `("file", path)`.
#[pyfunction]
fn load_bvh<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    joint_map: (String, String),
    units_per_metre: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let path = args::path("path", path)?;
    let units_per_metre = args::number("units_per_metre", units_per_metre)?;
    let map = match joint_map.0.as_str() {
        "builtin" => Some(JointMap::builtin(&joint_map.1)),
        "json" => Some(JointMap::from_json(&joint_map.1)),
        "file" => Some(JointMap::read_json(&joint_map.1)),
        _ => None,
    }
    .transpose()
    .py_err()?;
    let p = RetargetParams::default()
        .joint_map(map)
        .units_per_metre(units_per_metre);
    let m = crate::pool::detach(py, || bvh::read_bvh_with(&path, &p)).py_err()?;
    let t_n = m.angles.len();
    let d = PyDict::new(py);
    d.set_item("angles", array(py, &[t_n, N_CHANNELS], m.angles.concat())?)?;
    d.set_item(
        "root",
        array(py, &[t_n, 3], m.root.iter().flatten().copied().collect())?,
    )?;
    d.set_item("frame_time", m.frame_time)?;
    Ok(d)
}

/// The hierarchy and motion of a BVH file of any skeleton, with the world joint positions of
/// every frame (forward kinematics, file units).
#[pyfunction]
fn load_bvh_skeleton<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let path = args::path("path", path)?;
    let (f, pos) = crate::pool::detach(py, || {
        bvh_file::read_bvh_file(&path).map(|f| {
            let pos = bvh_file::bvh_forward_kinematics(&f);
            (f, pos)
        })
    })
    .py_err()?;
    let (t_n, j_n, c_n) = (f.frames.len(), f.joints.len(), f.n_channels());
    let d = PyDict::new(py);
    d.set_item(
        "names",
        f.joints.iter().map(|j| j.name.clone()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "parents",
        f.joints
            .iter()
            .map(|j| j.parent.map_or(-1, |p| p as i64))
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "offsets",
        array(
            py,
            &[j_n, 3],
            f.joints.iter().flat_map(|j| j.offset).collect(),
        )?,
    )?;
    d.set_item(
        "channels",
        f.joints
            .iter()
            .map(|j| j.channels.iter().map(|c| c.name()).collect::<Vec<_>>())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "end_sites",
        f.joints
            .iter()
            .map(|j| j.end_sites.iter().map(|e| e.to_vec()).collect::<Vec<_>>())
            .collect::<Vec<_>>(),
    )?;
    d.set_item("motion", array(py, &[t_n, c_n], f.frames.concat())?)?;
    d.set_item(
        "positions",
        array(
            py,
            &[t_n, j_n, 3],
            pos.iter().flatten().flatten().copied().collect(),
        )?,
    )?;
    d.set_item("frame_time", f.frame_time)?;
    Ok(d)
}

/// World positions of the 17 joints and the 5 end sites, ``(T, 22, 3)`` metres.
///
/// Parameters
/// ----------
/// angles : array_like, shape (T, 51)
/// root : array_like, shape (T,) or (T, 3)
///     Pelvis forward position (hips at the rest height) or full positions.
#[pyfunction]
fn forward_kinematics<'py>(
    py: Python<'py>,
    angles: &Bound<'py, PyAny>,
    root: &Bound<'py, PyAny>,
) -> PyResult<Arr<'py, f64>> {
    let (frames, root) = frames_arg(angles, root)?;
    let pts: Vec<Vec<[f64; 3]>> = crate::pool::detach(py, || {
        frames
            .iter()
            .zip(&root)
            .map(|(a, r)| fk_rs(a, *r))
            .collect()
    })?;
    let p_n = pts.first().map_or(0, Vec::len);
    let flat: Vec<f64> = pts.iter().flatten().flatten().copied().collect();
    array(py, &[pts.len(), p_n, 3], flat)
}

/// The skeleton: joint names, parent indices (-1 for the root), rest offsets `(17, 3)` and
/// bones `(B, 2)` as index pairs into `forward_kinematics`'s points.
#[pyfunction]
fn skeleton<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let names: Vec<&str> = JOINTS.iter().map(|j| j.0).collect();
    let parents: Vec<i64> = JOINTS
        .iter()
        .map(|j| j.1.map_or(-1, |p| p as i64))
        .collect();
    let offsets: Vec<f64> = JOINTS.iter().flat_map(|j| j.2).collect();
    let b = bones_rs();
    d.set_item("names", PyList::new(py, names)?)?;
    d.set_item("parents", array(py, &[parents.len()], parents)?)?;
    d.set_item("offsets", array(py, &[JOINTS.len(), 3], offsets)?)?;
    d.set_item(
        "bones",
        array(
            py,
            &[b.len(), 2],
            b.iter().flat_map(|&(a, c)| [a as i64, c as i64]).collect(),
        )?,
    )?;
    Ok(d)
}

// ------------------------------------------------------------------------------------------
// Statistics, SVR, oscillators

/// Two-sided p-value of the slope of a simple regression with ``R^2 = r2`` on ``n``
/// points: ``t = sqrt(R^2 (n - 2) / (1 - R^2))`` on ``n - 2`` degrees of freedom.
///
/// Parameters
/// ----------
/// r2 : float
///     In ``[0, 1]``.
/// n : int
///     At least 3.
#[pyfunction]
fn regression_p_value(py: Python<'_>, r2: f64, n: i128) -> PyResult<f64> {
    let r2 = args::number("r2", r2)?;
    let n: usize = uint(py, "n", n, 0)?;
    p_value_rs(r2, n).py_err()
}

/// Least-squares line `y = a + b x` with `R^2` and the slope's p-value.
#[pyfunction]
fn fit_line<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let (x, y) = (args::array::<f64>("x", x)?, args::array::<f64>("y", y)?);
    if x.shape().len() != 1 || y.shape().len() != 1 {
        return Err(value_error(format!(
            "`x` and `y` must be 1-D, got shapes {:?} and {:?}",
            x.shape(),
            y.shape()
        )));
    }
    let f = fit_line_rs(&values(&x), &values(&y)).py_err()?;
    let d = PyDict::new(py);
    d.set_item("intercept", f.intercept)?;
    d.set_item("slope", f.slope)?;
    d.set_item("r2", f.r2)?;
    d.set_item("p_value", f.p_value)?;
    d.set_item("n", f.n)?;
    Ok(d)
}

fn points2(name: &str, a: &PyReadonlyArrayDyn<f64>) -> PyResult<Vec<[f64; 2]>> {
    match *a.shape() {
        [_, 2] => {
            let v = values(a);
            check_finite(name, &v)?;
            Ok(v.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
        }
        ref s => Err(value_error(format!(
            "`{name}` must be an (n, 2) array, got shape {s:?}"
        ))),
    }
}

/// Trains the RBF ε-SVR on `(x_train, y_train)` and predicts `x_test`; also returns the
/// number of support vectors, the offset and the SMO iterations.
#[pyfunction]
#[pyo3(signature = (x_train, y_train, x_test, c, epsilon, gamma, tol))]
#[allow(clippy::too_many_arguments)]
fn svr_fit_predict<'py>(
    py: Python<'py>,
    x_train: &Bound<'py, PyAny>,
    y_train: &Bound<'py, PyAny>,
    x_test: &Bound<'py, PyAny>,
    c: f64,
    epsilon: f64,
    gamma: f64,
    tol: f64,
) -> PyResult<(Arr<'py, f64>, usize, f64, usize)> {
    let x_train = args::array::<f64>("x_train", x_train)?;
    let y_train = args::array::<f64>("y_train", y_train)?;
    let x_test = args::array::<f64>("x_test", x_test)?;
    let c = args::number("C", c)?;
    let epsilon = args::number("epsilon", epsilon)?;
    let gamma = args::number("gamma", gamma)?;
    let tol = args::number("tol", tol)?;
    let xt = points2("x_train", &x_train)?;
    let xq = points2("x_test", &x_test)?;
    if y_train.shape() != [xt.len()] {
        return Err(value_error(format!(
            "`y_train` must have shape ({},), got {:?}",
            xt.len(),
            y_train.shape()
        )));
    }
    let y = values(&y_train).into_owned();
    let (svr, pred) = crate::pool::detach(py, || {
        let svr = Svr::fit_tol(&xt, &y, c, epsilon, gamma, tol)?;
        let fast = svr.expansion();
        let pred: Vec<f64> = xq.iter().map(|&p| fast.eval(p)).collect();
        Ok::<_, Error>((svr, pred))
    })
    .py_err()?;
    Ok((
        vector(py, pred.to_vec())?,
        svr.n_support(),
        svr.rho,
        svr.iterations,
    ))
}

/// Integrates a Hopf star network (one leader, followers coupled to it) with RK4.
#[pyfunction]
#[pyo3(signature = (duration, dt, omega, coupling, leader, followers))]
fn hopf_simulate<'py>(
    py: Python<'py>,
    duration: f64,
    dt: f64,
    omega: f64,
    coupling: f64,
    leader: &Bound<'py, PyAny>,
    followers: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let leader = args::pair("leader", leader)?;
    let followers = args::array::<f64>("followers", followers)?;
    positive("duration", duration)?;
    positive("dt", dt)?;
    let fs = match *followers.shape() {
        _ if followers.len() == 0 => Vec::new(),
        [_, 2] => {
            let v = values(&followers);
            check_finite("followers", &v)?;
            v.chunks_exact(2).map(|c| [c[0], c[1]]).collect::<Vec<_>>()
        }
        ref s => {
            return Err(value_error(format!(
                "`followers` must be an (F, 2) array of states, got shape {s:?}"
            )))
        }
    };
    check_finite("leader", &[leader.0, leader.1])?;
    let steps = (duration / dt).round();
    let per = 2 * (fs.len() + 1) + 1;
    if steps < 1.0 || (steps + 1.0) * per as f64 > MAX_VALUES as f64 {
        return Err(value_error(format!(
            "duration / dt = {steps} steps (x {per} values) is outside 1..={}",
            MAX_VALUES / per - 1
        )));
    }
    let steps = steps as usize;
    let mut net = StarNetwork::new(omega, coupling, fs.len()).py_err()?;
    net.leader = [leader.0, leader.1];
    net.followers = fs;
    let f_n = net.followers.len();
    let (lead, fol) = crate::pool::detach(py, || {
        let mut lead = Vec::with_capacity(2 * (steps + 1));
        let mut fol = Vec::with_capacity(2 * f_n * (steps + 1));
        lead.extend(net.leader);
        fol.extend(net.followers.iter().flatten().copied());
        for _ in 0..steps {
            net.step_rk4(dt)?;
            lead.extend(net.leader);
            fol.extend(net.followers.iter().flatten().copied());
        }
        Ok::<_, Error>((lead, fol))
    })
    .py_err()?;
    let d = PyDict::new(py);
    let time: Vec<f64> = (0..=steps).map(|s| s as f64 * dt).collect();
    d.set_item("time", vector(py, time.to_vec())?)?;
    let phase: Vec<f64> = lead
        .chunks_exact(2)
        .map(|c| c[1].atan2(c[0]).rem_euclid(TAU))
        .collect();
    d.set_item("leader_phase", vector(py, phase.to_vec())?)?;
    d.set_item("leader", array(py, &[steps + 1, 2], lead)?)?;
    d.set_item("followers", array(py, &[steps + 1, f_n, 2], fol)?)?;
    Ok(d)
}

/// Registers the submodule's functions and classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyLibrary>()?;
    m.add_class::<PySynthesizer>()?;
    m.add_function(wrap_pyfunction!(make_synthetic_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(fit_anechoic, m)?)?;
    m.add_function(wrap_pyfunction!(pca_qualities, m)?)?;
    m.add_function(wrap_pyfunction!(pca_quality, m)?)?;
    m.add_function(wrap_pyfunction!(quality, m)?)?;
    m.add_function(wrap_pyfunction!(fit_stepwise, m)?)?;
    m.add_function(wrap_pyfunction!(plan_steps, m)?)?;
    m.add_function(wrap_pyfunction!(save_bvh, m)?)?;
    m.add_function(wrap_pyfunction!(load_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(save_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(load_bvh, m)?)?;
    m.add_function(wrap_pyfunction!(load_bvh_skeleton, m)?)?;
    m.add_function(wrap_pyfunction!(forward_kinematics, m)?)?;
    m.add_function(wrap_pyfunction!(skeleton, m)?)?;
    m.add_function(wrap_pyfunction!(regression_p_value, m)?)?;
    m.add_function(wrap_pyfunction!(fit_line, m)?)?;
    m.add_function(wrap_pyfunction!(svr_fit_predict, m)?)?;
    m.add_function(wrap_pyfunction!(hopf_simulate, m)?)?;
    Ok(())
}
