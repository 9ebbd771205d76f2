//! `wscg._native.volseg`, paper 18: bindings of `wscg_volseg` (BoneSplit: random walks on a
//! bone-only graph, warm-started sessions, the geodesic nearest-seed baseline, the local grow
//! brush, small-island removal, the fractured-shell phantom and the multi-label Dice).
//!
//! The documented API is `python/wscg/volseg.py`. Volumes are C-contiguous numpy arrays
//! indexed `[z, y, x]` (float32 CT, uint16 labels, bool masks), which is the x-fastest layout
//! of `wscg_math::Volume`, so they are taken without reordering; spacing is `(dz, dy, dx)`
//! as in `wscg.math` and scikit-image. Parameters of the random walks travel as a dict whose
//! keys are the fields of `RandomWalkParams` (unknown keys are refused). Every function checks shapes
//! and values again, so a direct call cannot panic on bad arguments. The GIL is released
//! while Rust works.

use numpy::{Element, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_math::Volume;
use wscg_volseg::{
    dice_multilabel, fractured_shell_phantom, gaussian_smooth3, local_grow_edit,
    nearest_seed_labels, remove_small_components, BoneGraph, GrowWeights, IntensityNorm,
    PhantomParams, Precision, RandomWalkParams, RandomWalkSession, SolveReport, Solver,
};

use crate::convert::{array, choice, dict_item, set_fields, values, Arr};
use crate::errors::{value_error, IntoPy};

/// Most worker threads of one solve.
const MAX_THREADS: usize = 1024;
/// Most voxels of a phantom (512^3; the generator keeps about 40 bytes per voxel).
const MAX_PHANTOM_VOXELS: usize = 1 << 27;
/// Most fragments of a phantom (each voxel sorts the sites).
const MAX_FRAGMENTS: usize = 64;
/// Largest partial-volume blur of a phantom, voxels.
const MAX_BLUR: f64 = 16.0;
/// Most smoothing passes.
const MAX_PASSES: u32 = 100;
/// Largest solver state (five `n_nodes x K` vectors) plus requested probability volumes,
/// bytes (32 GiB): a label map with large label values would otherwise ask for more memory
/// than any machine has, and a failed allocation aborts the interpreter.
const MAX_SOLVER_BYTES: usize = 1 << 35;

// ------------------------------------------------------------------------------------------
// Conversions

/// `(nz, ny, nx)` of a 3-D array.
fn shape3(name: &str, shape: &[usize]) -> PyResult<[usize; 3]> {
    match *shape {
        [z, y, x] => Ok([z, y, x]),
        ref s => Err(value_error(format!(
            "`{name}` must be a 3-D array indexed [z, y, x], got shape {s:?}"
        ))),
    }
}

/// Python spacing `(dz, dy, dx)` as the volume's `[sx, sy, sz]`.
fn spacing_xyz(s: (f64, f64, f64)) -> [f64; 3] {
    [s.2, s.1, s.0]
}

/// A `[z, y, x]` array as a volume (C order is x fastest).
fn vol_in<T: Element + Copy>(
    name: &str,
    a: &PyReadonlyArrayDyn<'_, T>,
    spacing: (f64, f64, f64),
) -> PyResult<Volume<T>> {
    let [z, y, x] = shape3(name, a.shape())?;
    Volume::new([x, y, z], spacing_xyz(spacing), values(a).into_owned())
        .map_err(|e| value_error(format!("`{name}`: {e}")))
}

/// A volume as a new `[z, y, x]` array.
fn vol_out<T: Element>(py: Python<'_>, v: Volume<T>) -> PyResult<Arr<'_, T>> {
    let [x, y, z] = v.dims();
    array(py, &[z, y, x], v.into_data())
}

/// Errors unless `a` has the CT's shape.
fn same_shape_as_ct<T: Element>(
    name: &str,
    a: &PyReadonlyArrayDyn<'_, T>,
    ct: [usize; 3],
) -> PyResult<()> {
    if a.shape() == ct {
        Ok(())
    } else {
        Err(value_error(format!(
            "shape mismatch: `{name}` has shape {:?}, `ct` {ct:?}",
            a.shape()
        )))
    }
}

fn norm_in(name: &str, lo: Option<f64>, hi: Option<f64>) -> PyResult<IntensityNorm> {
    match name {
        "window" => {
            let d = RandomWalkParams::default();
            let (dlo, dhi) = match d.norm {
                IntensityNorm::Window { lo, hi } => (lo, hi),
                _ => (-1024.0, 3071.0),
            };
            Ok(IntensityNorm::Window {
                lo: lo.unwrap_or(dlo),
                hi: hi.unwrap_or(dhi),
            })
        }
        "minmax" => Ok(IntensityNorm::MinMax),
        "none" => Ok(IntensityNorm::None),
        other => Err(value_error(format!(
            "`norm` must be 'window', 'minmax' or 'none', got {other:?}"
        ))),
    }
}

/// Keys of a parameter dict.
const PARAM_KEYS: [&str; 15] = [
    "preset",
    "t_bone",
    "beta",
    "eps",
    "kappa",
    "tol",
    "max_iter",
    "norm",
    "window_lo",
    "window_hi",
    "spacing_in_weights",
    "solver",
    "precision",
    "jacobi",
    "n_threads",
];

/// Refuses keys of `d` outside `allowed`.
fn known_keys(d: &Bound<'_, PyDict>, allowed: &[&str], what: &str) -> PyResult<()> {
    for k in d.keys() {
        let k: String = k
            .extract()
            .map_err(|_| value_error(format!("{what} keys must be strings")))?;
        if !allowed.contains(&k.as_str()) {
            return Err(value_error(format!(
                "unknown {what} {k:?}; known: {}",
                allowed.join(", ")
            )));
        }
    }
    Ok(())
}

/// Random-walk parameters: those of the `preset` entry (`"default"`, the default, or
/// `"paper"`) overridden by the other entries of `d`, validated.
fn params_in(d: Option<&Bound<'_, PyDict>>) -> PyResult<RandomWalkParams> {
    let Some(d) = d else {
        return Ok(RandomWalkParams::default());
    };
    known_keys(d, &PARAM_KEYS, "parameter")?;
    let mut p = match dict_item::<String>(d, "preset")? {
        None => RandomWalkParams::default(),
        Some(s) => choice(
            "preset",
            &s,
            &[
                ("default", RandomWalkParams::default()),
                ("paper", RandomWalkParams::paper()),
            ],
        )?,
    };
    set_fields!(d, p; t_bone: f64, beta: f64, eps: f64, kappa: f64, tol: f64, max_iter: usize,
        spacing_in_weights: bool, jacobi: bool);
    let lo = dict_item::<f64>(d, "window_lo")?;
    let hi = dict_item::<f64>(d, "window_hi")?;
    if let Some(n) = dict_item::<String>(d, "norm")? {
        p.norm = norm_in(&n, lo, hi)?;
    } else if lo.is_some() || hi.is_some() {
        p.norm = norm_in("window", lo, hi)?;
    }
    if let Some(s) = dict_item::<String>(d, "solver")? {
        p.solver = choice(
            "solver",
            &s,
            &[("block", Solver::Block), ("per_label", Solver::PerLabel)],
        )?;
    }
    if let Some(s) = dict_item::<String>(d, "precision")? {
        p.precision = choice(
            "precision",
            &s,
            &[("f32", Precision::F32), ("f64", Precision::F64)],
        )?;
    }
    if let Some(t) = dict_item::<usize>(d, "n_threads")? {
        if t == 0 || t > MAX_THREADS {
            return Err(value_error(format!(
                "`n_threads` must be in 1..={MAX_THREADS} (or None for the wscg pool), got {t}"
            )));
        }
        p.threads = Some(t);
    }
    p.validate().py_err()?;
    Ok(p)
}

fn passes_in(name: &str, passes: u32) -> PyResult<u32> {
    if passes > MAX_PASSES {
        return Err(value_error(format!(
            "`{name}` must be in 0..={MAX_PASSES}, got {passes}"
        )));
    }
    Ok(passes)
}

/// The bone graph of `ct` (optionally smoothed first): thresholded at `p.t_bone`, or on the
/// voxels of `mask`.
fn graph_of(
    ct: &Volume<f32>,
    mask: Option<&[bool]>,
    passes: u32,
    p: &RandomWalkParams,
) -> wscg_math::Result<BoneGraph> {
    ct.ensure_finite("ct")?;
    let smoothed;
    let img = if passes > 0 {
        smoothed = gaussian_smooth3(ct, passes)?;
        &smoothed
    } else {
        ct
    };
    match mask {
        Some(m) => BoneGraph::from_mask(img, m, p),
        None => BoneGraph::build(img, p),
    }
}

/// A solve report as a dict.
fn report_out<'py>(
    py: Python<'py>,
    r: &SolveReport,
    s: &RandomWalkSession,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("iterations", r.iterations.clone())?;
    d.set_item("residuals", r.residuals.clone())?;
    d.set_item("converged", r.converged.clone())?;
    d.set_item("seconds", r.seconds.clone())?;
    d.set_item("unreached", r.unreached)?;
    d.set_item("n_labels", s.n_labels())?;
    d.set_item("n_nodes", s.graph().len())?;
    d.set_item(
        "n_seeds",
        s.node_seeds().iter().filter(|&&l| l != 0).count(),
    )?;
    Ok(d)
}

/// Errors when a solve of `s` (and `prob_voxels` voxels of probability volumes per label)
/// would need more than [`MAX_SOLVER_BYTES`].
fn check_memory(s: &RandomWalkSession, prob_voxels: usize) -> wscg_math::Result<()> {
    let k = s.n_labels();
    let lane = match s.params().precision {
        Precision::F32 => 4,
        Precision::F64 => 8,
    };
    let bytes = s
        .graph()
        .len()
        .saturating_mul(k)
        .saturating_mul(5 * lane)
        .saturating_add(prob_voxels.saturating_mul(k).saturating_mul(4));
    if bytes > MAX_SOLVER_BYTES {
        return Err(wscg_math::Error::LimitExceeded(format!(
            "{k} labels on {} bone voxels need about {} GiB (at most {} GiB); labels are \
             numbered 1..K, so use consecutive label values",
            s.graph().len(),
            bytes >> 30,
            MAX_SOLVER_BYTES >> 30
        )));
    }
    Ok(())
}

/// Probability volumes of labels `1..=k` stacked as `k x nz x ny x nx`.
fn all_probabilities(s: &RandomWalkSession, k: usize) -> wscg_math::Result<Vec<f32>> {
    let n: usize = s.graph().dims().iter().product();
    let mut out = Vec::with_capacity(k * n);
    for l in 1..=k {
        out.extend_from_slice(s.probabilities(l as u16)?.data());
    }
    Ok(out)
}

// ------------------------------------------------------------------------------------------
// Random walks

/// Random-walk labels (and optionally the K probability volumes) of `ct` from `seeds`, with
/// the solve report.
#[pyfunction]
#[pyo3(signature = (ct, seeds, spacing, n_smooth_passes, params, return_prob))]
#[allow(clippy::type_complexity)]
fn random_walker<'py>(
    py: Python<'py>,
    ct: PyReadonlyArrayDyn<'py, f32>,
    seeds: PyReadonlyArrayDyn<'py, u16>,
    spacing: (f64, f64, f64),
    n_smooth_passes: u32,
    params: Option<Bound<'py, PyDict>>,
    return_prob: bool,
) -> PyResult<(Arr<'py, u16>, Option<Arr<'py, f32>>, Bound<'py, PyDict>)> {
    let p = params_in(params.as_ref())?;
    let passes = passes_in("n_smooth_passes", n_smooth_passes)?;
    let shape = shape3("ct", ct.shape())?;
    same_shape_as_ct("seeds", &seeds, shape)?;
    let ct = vol_in("ct", &ct, spacing)?;
    let seeds = vol_in("seeds", &seeds, spacing)?;
    let (session, report, labels, probs) = crate::pool::detach(py, || -> wscg_math::Result<_> {
        let g = graph_of(&ct, None, passes, &p)?;
        let mut s = RandomWalkSession::new(g, p)?;
        s.set_seeds(&seeds)?;
        check_memory(&s, if return_prob { ct.len() } else { 0 })?;
        let r = s.solve(false)?;
        let labels = s.labels()?;
        let probs = if return_prob {
            Some(all_probabilities(&s, s.n_labels())?)
        } else {
            None
        };
        Ok((s, r, labels, probs))
    })
    .py_err()?;
    let report = report_out(py, &report, &session)?;
    let k = session.n_labels();
    let probs = match probs {
        Some(v) => Some(array(py, &[k, shape[0], shape[1], shape[2]], v)?),
        None => None,
    };
    Ok((vol_out(py, labels)?, probs, report))
}

/// An interactive random-walk segmentation: the bone graph, the seeds and the last solution.
#[pyclass(module = "wscg._native.volseg", name = "Session")]
pub struct PySession {
    inner: RandomWalkSession,
    /// `(nz, ny, nx)`.
    shape: [usize; 3],
    /// Number of labels of the last solve (0 before the first).
    solved_k: usize,
}

#[pymethods]
impl PySession {
    #[new]
    #[pyo3(signature = (ct, mask, spacing, n_smooth_passes, params))]
    fn new(
        py: Python<'_>,
        ct: PyReadonlyArrayDyn<'_, f32>,
        mask: Option<PyReadonlyArrayDyn<'_, bool>>,
        spacing: (f64, f64, f64),
        n_smooth_passes: u32,
        params: Option<Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let p = params_in(params.as_ref())?;
        let passes = passes_in("n_smooth_passes", n_smooth_passes)?;
        let shape = shape3("ct", ct.shape())?;
        let ct = vol_in("ct", &ct, spacing)?;
        let mask = match &mask {
            Some(m) => {
                same_shape_as_ct("mask", m, shape)?;
                Some(values(m).into_owned())
            }
            None => None,
        };
        let inner = crate::pool::detach(py, || {
            RandomWalkSession::new(graph_of(&ct, mask.as_deref(), passes, &p)?, p)
        })
        .py_err()?;
        Ok(Self {
            inner,
            shape,
            solved_k: 0,
        })
    }

    /// Replaces all seeds by the non-zero voxels of `seeds` on the graph; returns how many
    /// were placed.
    fn set_seeds(&mut self, py: Python<'_>, seeds: PyReadonlyArrayDyn<'_, u16>) -> PyResult<usize> {
        same_shape_as_ct("seeds", &seeds, self.shape)?;
        let sp = self.inner.graph().spacing();
        let seeds = vol_in("seeds", &seeds, (sp[2], sp[1], sp[0]))?;
        let s = &mut self.inner;
        crate::pool::detach(py, || s.set_seeds(&seeds)).py_err()
    }

    /// Adds seeds of `label` at `(N, 3)` voxel coordinates `(z, y, x)`; returns how many lie on
    /// the graph.
    fn add_seeds(&mut self, zyx: PyReadonlyArrayDyn<'_, i64>, label: u16) -> PyResult<usize> {
        let sh = zyx.shape();
        if sh.len() != 2 || sh[1] != 3 {
            return Err(value_error(format!(
                "`zyx` must be an (N, 3) array of voxel coordinates (z, y, x), got shape {sh:?}"
            )));
        }
        let [nz, ny, nx] = self.shape;
        let voxels = values(&zyx)
            .chunks_exact(3)
            .map(|c| {
                let inside = |v: i64, n: usize| v >= 0 && (v as u64) < n as u64;
                if inside(c[0], nz) && inside(c[1], ny) && inside(c[2], nx) {
                    let (z, y, x) = (c[0] as usize, c[1] as usize, c[2] as usize);
                    Ok(x + nx * (y + ny * z))
                } else {
                    Err(value_error(format!(
                        "`zyx` holds ({}, {}, {}), outside the volume of shape {:?}",
                        c[0], c[1], c[2], self.shape
                    )))
                }
            })
            .collect::<PyResult<Vec<usize>>>()?;
        self.inner.add_seeds(&voxels, label).py_err()
    }

    /// Solves the K systems (warm-started from the last solution when `warm_start`); returns
    /// the report.
    #[pyo3(signature = (warm_start=true))]
    fn solve<'py>(&mut self, py: Python<'py>, warm_start: bool) -> PyResult<Bound<'py, PyDict>> {
        let s = &mut self.inner;
        let r = crate::pool::detach(py, || {
            check_memory(s, 0)?;
            s.solve(warm_start)
        })
        .py_err()?;
        self.solved_k = self.inner.n_labels();
        report_out(py, &r, &self.inner)
    }

    /// Label volume `[z, y, x]` (uint16).
    fn labels<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, u16>> {
        let s = &self.inner;
        let v = crate::pool::detach(py, || s.labels()).py_err()?;
        vol_out(py, v)
    }

    /// Probability volume `[z, y, x]` (float32) of `label` from the last solve.
    fn probabilities<'py>(&self, py: Python<'py>, label: u16) -> PyResult<Arr<'py, f32>> {
        let s = &self.inner;
        let v = crate::pool::detach(py, || s.probabilities(label)).py_err()?;
        vol_out(py, v)
    }

    /// The K probability volumes of the last solve, `[K, z, y, x]`.
    fn all_probabilities<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f32>> {
        let (s, k) = (&self.inner, self.solved_k);
        if k == 0 {
            return Err(value_error("no probabilities before the first solve()"));
        }
        let [z, y, x] = self.shape;
        let voxels = z * y * x;
        if voxels.saturating_mul(k).saturating_mul(4) > MAX_SOLVER_BYTES {
            return Err(value_error(format!(
                "{k} probability volumes of {voxels} voxels exceed {} GiB",
                MAX_SOLVER_BYTES >> 30
            )));
        }
        let v = crate::pool::detach(py, || all_probabilities(s, k)).py_err()?;
        array(py, &[k, z, y, x], v)
    }

    /// Number of labels of the last solve (0 before the first).
    #[getter]
    fn solved_labels(&self) -> usize {
        self.solved_k
    }

    /// Seed volume `[z, y, x]` (uint16, seeds on the graph only).
    fn seeds<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, u16>> {
        let g = self.inner.graph();
        let mut out = vec![0u16; self.shape.iter().product()];
        for (i, &l) in self.inner.node_seeds().iter().enumerate() {
            out[g.voxel(i)] = l;
        }
        array(py, &self.shape, out)
    }

    /// Geodesic nearest-seed labels of the current seeds on this graph, `[z, y, x]`.
    fn nearest_seed<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, u16>> {
        let g = self.inner.graph();
        let seeds = self.inner.node_seeds();
        let labels = crate::pool::detach(py, || nearest_seed_labels(g, seeds))?;
        let mut out = vec![0u16; self.shape.iter().product()];
        for (i, l) in labels.into_iter().enumerate() {
            out[g.voxel(i)] = l;
        }
        array(py, &self.shape, out)
    }

    /// Number of graph nodes (bone voxels).
    #[getter]
    fn n_nodes(&self) -> usize {
        self.inner.graph().len()
    }

    /// Number of graph edges.
    #[getter]
    fn n_edges(&self) -> usize {
        self.inner.graph().edges()
    }

    /// Number of labels K (the largest seed label).
    #[getter]
    fn n_labels(&self) -> usize {
        self.inner.n_labels()
    }

    /// `(nz, ny, nx)`.
    #[getter]
    fn shape(&self) -> (usize, usize, usize) {
        (self.shape[0], self.shape[1], self.shape[2])
    }

    /// Approximate memory of the graph, bytes.
    #[getter]
    fn graph_bytes(&self) -> usize {
        self.inner.graph().memory_bytes()
    }

    /// Pickles as the session's state: graph, parameters, seeds and last solution.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::state::Reduced<'py>> {
        crate::state::reduce(py, "volseg", "_session_from_state", &self.inner)
    }
}

/// A session from the state that `Session.__reduce__` pickles.
#[pyfunction]
fn _session_from_state(py: Python<'_>, state: &[u8]) -> PyResult<PySession> {
    let inner: RandomWalkSession = crate::state::from_bytes(py, "random-walk session", state)?;
    let [nx, ny, nz] = inner.graph().dims();
    Ok(PySession {
        shape: [nz, ny, nx],
        solved_k: inner.solved_labels(),
        inner,
    })
}

// ------------------------------------------------------------------------------------------
// Baseline, metric, preprocessing

/// Geodesic nearest-seed labels (breadth-first inside the bone mask).
#[pyfunction]
#[pyo3(signature = (ct, seeds, params, mask=None))]
fn nearest_seed<'py>(
    py: Python<'py>,
    ct: PyReadonlyArrayDyn<'py, f32>,
    seeds: PyReadonlyArrayDyn<'py, u16>,
    params: Option<Bound<'py, PyDict>>,
    mask: Option<PyReadonlyArrayDyn<'py, bool>>,
) -> PyResult<Arr<'py, u16>> {
    let p = params_in(params.as_ref())?;
    let shape = shape3("ct", ct.shape())?;
    same_shape_as_ct("seeds", &seeds, shape)?;
    let mask = match &mask {
        Some(m) => {
            same_shape_as_ct("mask", m, shape)?;
            Some(values(m).into_owned())
        }
        None => None,
    };
    let ct = vol_in("ct", &ct, (1.0, 1.0, 1.0))?;
    let seeds = values(&seeds);
    let out = crate::pool::detach(py, || -> wscg_math::Result<Vec<u16>> {
        let g = graph_of(&ct, mask.as_deref(), 0, &p)?;
        let node_seeds: Vec<u16> = (0..g.len()).map(|i| seeds[g.voxel(i)]).collect();
        if node_seeds.iter().all(|&l| l == 0) {
            return Err(wscg_math::Error::invalid(
                "seeds",
                "no seed lies on a bone voxel; place at least one stroke on the bone",
            ));
        }
        let mut out = vec![0u16; ct.len()];
        for (i, l) in nearest_seed_labels(&g, &node_seeds).into_iter().enumerate() {
            out[g.voxel(i)] = l;
        }
        Ok(out)
    })
    .py_err()?;
    array(py, &shape, out)
}

/// Multi-label Dice (paper eq. 2).
#[pyfunction]
fn dice(a: PyReadonlyArrayDyn<'_, u16>, b: PyReadonlyArrayDyn<'_, u16>) -> PyResult<f64> {
    if a.shape() != b.shape() {
        return Err(value_error(format!(
            "shape mismatch: `a` has shape {:?}, `b` {:?}",
            a.shape(),
            b.shape()
        )));
    }
    dice_multilabel(&values(&a), &values(&b)).py_err()
}

/// `n_passes` rounds of the anisotropy-aware 3-tap Gaussian.
#[pyfunction]
fn smooth<'py>(
    py: Python<'py>,
    ct: PyReadonlyArrayDyn<'py, f32>,
    n_passes: u32,
    spacing: (f64, f64, f64),
) -> PyResult<Arr<'py, f32>> {
    let passes = passes_in("n_passes", n_passes)?;
    let ct = vol_in("ct", &ct, spacing)?;
    let v = crate::pool::detach(py, || gaussian_smooth3(&ct, passes)).py_err()?;
    vol_out(py, v)
}

// ------------------------------------------------------------------------------------------
// Editing

/// Grow-brush weights: defaults overridden by the entries of `d`.
fn grow_in(d: Option<&Bound<'_, PyDict>>) -> PyResult<GrowWeights> {
    let mut w = GrowWeights::default();
    let Some(d) = d else {
        return Ok(w);
    };
    known_keys(
        d,
        &[
            "ratio",
            "gradient",
            "distance",
            "gradient_scale",
            "tau",
            "max_sweeps",
        ],
        "grow weight",
    )?;
    set_fields!(d, w; ratio: f64, gradient: f64, distance: f64, gradient_scale: f64, tau: f64,
        max_sweeps: usize);
    let reals = [w.ratio, w.gradient, w.distance, w.gradient_scale, w.tau];
    if reals.iter().any(|v| !v.is_finite()) {
        return Err(value_error(
            "grow weights (ratio, gradient, distance, gradient_scale, tau) must be finite",
        ));
    }
    if w.gradient_scale <= 0.0 {
        return Err(value_error(format!(
            "`gradient_scale` must be > 0, got {}",
            w.gradient_scale
        )));
    }
    Ok(w)
}

/// The local grow brush on a copy of `labels`; returns the new labels and the count of
/// changed voxels.
#[pyfunction]
#[pyo3(signature = (labels, ct, center_zyx, radius, active, params, weights))]
#[allow(clippy::too_many_arguments)]
fn grow_edit<'py>(
    py: Python<'py>,
    labels: PyReadonlyArrayDyn<'py, u16>,
    ct: PyReadonlyArrayDyn<'py, f32>,
    center_zyx: (f64, f64, f64),
    radius: f64,
    active: u16,
    params: Option<Bound<'py, PyDict>>,
    weights: Option<Bound<'py, PyDict>>,
) -> PyResult<(Arr<'py, u16>, usize)> {
    let p = params_in(params.as_ref())?;
    let w = grow_in(weights.as_ref())?;
    let shape = shape3("ct", ct.shape())?;
    same_shape_as_ct("labels", &labels, shape)?;
    let ct = vol_in("ct", &ct, (1.0, 1.0, 1.0))?;
    let mut labels = vol_in("labels", &labels, (1.0, 1.0, 1.0))?;
    let center = [center_zyx.2, center_zyx.1, center_zyx.0];
    let n = crate::pool::detach(py, || {
        ct.ensure_finite("ct")?;
        local_grow_edit(&mut labels, &ct, &p, center, radius, active, &w)
    })
    .py_err()?;
    Ok((vol_out(py, labels)?, n))
}

/// Small-island removal on a copy of `labels`; returns the new labels and the count of
/// changed voxels.
#[pyfunction]
fn remove_small<'py>(
    py: Python<'py>,
    labels: PyReadonlyArrayDyn<'py, u16>,
    min_voxels: usize,
) -> PyResult<(Arr<'py, u16>, usize)> {
    let mut labels = vol_in("labels", &labels, (1.0, 1.0, 1.0))?;
    let n = crate::pool::detach(py, || remove_small_components(&mut labels, min_voxels))?;
    Ok((vol_out(py, labels)?, n))
}

// ------------------------------------------------------------------------------------------
// Phantom

/// Phantom configuration: `shape (nz, ny, nx)`, fragments, seed, and overrides.
fn phantom_cfg(
    shape: (usize, usize, usize),
    n_fragments: usize,
    seed: u64,
    d: Option<&Bound<'_, PyDict>>,
) -> PyResult<PhantomParams> {
    let voxels = shape
        .0
        .checked_mul(shape.1)
        .and_then(|v| v.checked_mul(shape.2));
    if !matches!(voxels, Some(v) if v <= MAX_PHANTOM_VOXELS) {
        return Err(value_error(format!(
            "`shape` {shape:?} has more than {MAX_PHANTOM_VOXELS} voxels (512^3)"
        )));
    }
    if !(2..=MAX_FRAGMENTS).contains(&n_fragments) {
        return Err(value_error(format!(
            "`n_fragments` must be in 2..={MAX_FRAGMENTS}, got {n_fragments}"
        )));
    }
    let mut c = PhantomParams::default()
        .dims([shape.2, shape.1, shape.0])
        .fragments(n_fragments)
        .seed(seed);
    let Some(d) = d else {
        return Ok(c);
    };
    known_keys(
        d,
        &[
            "shell",
            "bone_hu",
            "gap_hu",
            "gap_width",
            "blur_sigma",
            "noise_hu",
            "t_bone",
            "stroke_radius",
            "stroke_margin",
            "surface_strokes",
        ],
        "phantom option",
    )?;
    set_fields!(d, c; surface_strokes: bool);
    if let Some((a, b)) = dict_item::<(f64, f64)>(d, "shell")? {
        c.shell = [a, b];
    }
    macro_rules! set {
        ($field:ident) => {
            if let Some(v) = dict_item::<f64>(d, stringify!($field))? {
                if !v.is_finite() {
                    return Err(value_error(format!(
                        "`{}` must be finite, got {v}",
                        stringify!($field)
                    )));
                }
                c.$field = v;
            }
        };
    }
    set!(bone_hu);
    set!(gap_hu);
    set!(gap_width);
    set!(blur_sigma);
    set!(noise_hu);
    set!(t_bone);
    set!(stroke_radius);
    set!(stroke_margin);
    for (name, v, hi) in [
        ("gap_width", c.gap_width, f64::INFINITY),
        ("blur_sigma", c.blur_sigma, MAX_BLUR),
        ("noise_hu", c.noise_hu, f64::INFINITY),
        ("stroke_radius", c.stroke_radius, f64::INFINITY),
        ("stroke_margin", c.stroke_margin, f64::INFINITY),
    ] {
        if !(0.0..=hi).contains(&v) {
            return Err(value_error(format!(
                "`{name}` must be in [0, {hi}], got {v}"
            )));
        }
    }
    Ok(c)
}

/// The fractured-shell phantom: `(ct, truth, seeds, boundary_distance)`, all `[z, y, x]`.
#[pyfunction]
#[pyo3(signature = (shape, n_fragments, seed, options=None))]
#[allow(clippy::type_complexity)]
fn phantom<'py>(
    py: Python<'py>,
    shape: (usize, usize, usize),
    n_fragments: usize,
    seed: u64,
    options: Option<Bound<'py, PyDict>>,
) -> PyResult<(Arr<'py, f32>, Arr<'py, u16>, Arr<'py, u16>, Arr<'py, f32>)> {
    let c = phantom_cfg(shape, n_fragments, seed, options.as_ref())?;
    let ph = crate::pool::detach(py, || fractured_shell_phantom(&c)).py_err()?;
    let dims = [shape.0, shape.1, shape.2];
    let dist: Vec<f32> = ph.boundary_distance.iter().map(|&d| d as f32).collect();
    Ok((
        vol_out(py, ph.ct)?,
        vol_out(py, ph.truth)?,
        vol_out(py, ph.seeds)?,
        array(py, &dims, dist)?,
    ))
}

/// Registers the functions of `wscg._native.volseg`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySession>()?;
    m.add_function(wrap_pyfunction!(_session_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(random_walker, m)?)?;
    m.add_function(wrap_pyfunction!(nearest_seed, m)?)?;
    m.add_function(wrap_pyfunction!(dice, m)?)?;
    m.add_function(wrap_pyfunction!(smooth, m)?)?;
    m.add_function(wrap_pyfunction!(grow_edit, m)?)?;
    m.add_function(wrap_pyfunction!(remove_small, m)?)?;
    m.add_function(wrap_pyfunction!(phantom, m)?)?;
    Ok(())
}
