//! `wscg._native.volseg`, paper 18: bindings of `wscg_volseg` (BoneSplit: random walks on a
//! bone-only graph, warm-started sessions, the geodesic nearest-seed baseline, the local grow
//! brush, small-island removal, the fractured-shell phantom and the multi-label Dice).
//!
//! `nearest_seed`, `dice`, `bone_mask`, `smooth`, `local_grow_edit` and
//! `remove_small_components` are the public functions of `wscg.volseg`;
//! `random_walker_bone` and `RandomWalkerSession` (`python/wscg/volseg.py`) keep a Python
//! layer for the label bookkeeping, the warnings and `SolveReport`, their arguments checked
//! here by the same conversions (`ct_arg`, `labels_arg`, `mask_arg`, `spacing_arg`,
//! `params_arg`), with the messages of py/API.md. Volumes are numpy arrays indexed
//! `[z, y, x]` (CT as float32, labels as uint16, masks as bool), which is the x-fastest
//! layout of `wscg_math::Volume`, so they are taken without reordering; spacing is
//! `(dz, dy, dx)` as in `wscg.math` and scikit-image. The GIL is released while Rust works.

use numpy::{Element, PyArrayDescrMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use wscg_math::Volume;
use wscg_volseg::{
    dice_multilabel, fractured_shell_phantom, gaussian_smooth3, local_grow_edit,
    nearest_seed_labels, remove_small_components, BoneGraph, GrowWeights, IntensityNorm,
    PhantomParams, Precision, RandomWalkParams, RandomWalkSession, SolveReport, Solver,
};

use crate::args;
use crate::convert::{array, choice, values, Arr};
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
/// Largest seed label (65535 is kept free: the session numbers labels `1..K` below it).
const MAX_LABEL: u16 = 65534;
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

/// A `[z, y, x]` array as a volume (C order is x fastest).
fn vol_in<T: Element + Copy>(
    name: &str,
    a: &PyReadonlyArrayDyn<'_, T>,
    spacing: [f64; 3],
) -> PyResult<Volume<T>> {
    let [z, y, x] = shape3(name, a.shape())?;
    Volume::new([x, y, z], args::xyz(spacing), values(a).into_owned())
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

/// The CT argument `ct`: any real (integer or float) array-like, 3-D `[z, y, x]`, as float32
/// (NaN and infinities are refused where the volume is used, with the flat index).
fn ct_arg<'py>(obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArrayDyn<'py, f32>> {
    let a = args::real_array("ct", obj)?;
    shape3("ct", a.shape())?;
    // A float64 value beyond float32's range becomes an infinity, refused with its index
    // where the volume is used; numpy's overflow warning would only repeat that.
    let py = obj.py();
    let kw = pyo3::types::PyDict::new(py);
    kw.set_item("over", "ignore")?;
    kw.set_item("invalid", "ignore")?;
    let quiet = py.import("numpy")?.call_method("errstate", (), Some(&kw))?;
    quiet.call_method0("__enter__")?;
    let out = args::array("ct", &a);
    quiet.call_method1("__exit__", (py.None(), py.None(), py.None()))?;
    out
}

/// A label argument `name` as uint16: integer or boolean data, or floats holding whole
/// numbers, with values in `0..=hi` (0 = no label); 3-D with the CT's shape `ct` when given
/// (`three_d`: 3-D of any shape).
fn labels_arg<'py>(
    name: &str,
    obj: &Bound<'py, PyAny>,
    ct: Option<[usize; 3]>,
    three_d: bool,
    hi: u16,
) -> PyResult<PyReadonlyArrayDyn<'py, u16>> {
    let a = args::asarray(name, obj)?;
    let np = obj.py().import("numpy")?;
    let dtype = a.dtype();
    match dtype.kind() {
        b'b' | b'i' | b'u' => {}
        b'f' => {
            let whole = a.len() == 0
                || (np
                    .call_method1("isfinite", (&a,))?
                    .call_method0("all")?
                    .is_truthy()?
                    && np
                        .call_method1("array_equal", (&a, np.call_method1("round", (&a,))?))?
                        .is_truthy()?);
            if !whole {
                return Err(value_error(format!(
                    "`{name}` must hold whole-number labels, got non-integral values"
                )));
            }
        }
        _ => {
            return Err(value_error(format!(
                "`{name}` must be an integer label array, got dtype {dtype}"
            )))
        }
    }
    if (three_d || ct.is_some()) && a.ndim() != 3 {
        return Err(value_error(format!(
            "`{name}` must be a 3-D array indexed [z, y, x], got shape {}",
            args::shape_repr(a.shape())
        )));
    }
    if let Some(ct) = ct {
        if a.shape() != ct {
            return Err(value_error(format!(
                "shape mismatch: `{name}` has shape {}, `ct` {}",
                args::shape_repr(a.shape()),
                args::shape_repr(&ct)
            )));
        }
    }
    if a.len() > 0 && dtype.kind() != b'b' {
        let (lo, top) = (a.call_method0("min")?, a.call_method0("max")?);
        if lo.lt(0)? || top.gt(hi)? {
            return Err(value_error(format!(
                "`{name}` must hold labels in 0..{hi} (0 = none), got values in [{}, {}]",
                lo.str()?,
                top.str()?
            )));
        }
    }
    args::array(name, &a)
}

/// The optional `mask` argument: boolean or integer data (non-zero = graph node) of the
/// CT's shape `ct`.
fn mask_arg(obj: Option<&Bound<'_, PyAny>>, ct: [usize; 3]) -> PyResult<Option<Vec<bool>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let a = args::asarray("mask", obj)?;
    let dtype = a.dtype();
    if !matches!(dtype.kind(), b'b' | b'i' | b'u') {
        return Err(value_error(format!(
            "`mask` must be a boolean array, got dtype {dtype}"
        )));
    }
    if a.shape() != ct {
        return Err(value_error(format!(
            "shape mismatch: `mask` has shape {}, `ct` {}",
            args::shape_repr(a.shape()),
            args::shape_repr(&ct)
        )));
    }
    Ok(Some(values(&args::array::<bool>("mask", &a)?).into_owned()))
}

/// The `spacing` argument `(dz, dy, dx)` (3 finite numbers > 0; `None`: unit spacing).
fn spacing_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<[f64; 3]> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok([1.0; 3]);
    };
    let [dz, dy, dx] = args::triple("spacing", obj)?;
    if [dz, dy, dx].iter().all(|d| d.is_finite() && *d > 0.0) {
        Ok([dz, dy, dx])
    } else {
        Err(value_error(format!(
            "`spacing` must be finite and > 0, got ({dz}, {dy}, {dx})"
        )))
    }
}

/// The `t_bone` argument (HU, finite).
fn t_bone_arg(t: f64) -> PyResult<f64> {
    if t.is_finite() {
        Ok(t)
    } else {
        Err(value_error(format!("`t_bone` must be finite, got {t}")))
    }
}

/// The `norm` argument: `"window"` (the default window), `("window", lo, hi)`, `"minmax"`
/// or `"none"`.
#[derive(FromPyObject)]
enum NormArg {
    Name(String),
    Window(String, f64, f64),
}

/// The intensity map of `norm` (`None`: the default window).
fn norm_arg(norm: Option<&NormArg>) -> PyResult<IntensityNorm> {
    let default = RandomWalkParams::default().norm;
    match norm {
        None => Ok(default),
        Some(NormArg::Name(n)) => choice(
            "norm",
            n,
            &[
                ("window", default),
                ("minmax", IntensityNorm::MinMax),
                ("none", IntensityNorm::None),
            ],
        ),
        Some(&NormArg::Window(ref n, lo, hi)) if n == "window" => {
            if lo.is_finite() && hi.is_finite() && hi > lo {
                Ok(IntensityNorm::Window { lo, hi })
            } else {
                Err(value_error(format!(
                    "`norm` window needs finite lo < hi, got ({lo}, {hi})"
                )))
            }
        }
        Some(NormArg::Window(n, ..)) => Err(value_error(format!(
            "`norm` must be 'window', ('window', lo, hi), 'minmax' or 'none', got a tuple \
             starting with {n:?}"
        ))),
    }
}

/// The random-walk parameters of the keyword arguments of `random_walker_bone` and
/// `RandomWalkerSession` (paper 18 section 2.4): those of `preset`, overridden by `beta`,
/// `eps` and `kappa` when given, each checked and named.
#[allow(clippy::too_many_arguments)]
fn params_arg(
    py: Python<'_>,
    t_bone: f64,
    beta: Option<f64>,
    eps: Option<f64>,
    kappa: Option<f64>,
    preset: &str,
    tol: f64,
    max_iter: i128,
    norm: Option<&NormArg>,
    spacing_in_weights: bool,
    solver: &str,
    precision: &str,
    jacobi: bool,
    n_threads: Option<i128>,
) -> PyResult<RandomWalkParams> {
    let mut p = choice(
        "preset",
        preset,
        &[
            ("default", RandomWalkParams::default()),
            ("paper", RandomWalkParams::paper()),
        ],
    )?;
    p.t_bone = t_bone_arg(t_bone)?;
    for (name, v, field) in [
        ("beta", beta, &mut p.beta),
        ("eps", eps, &mut p.eps),
        ("kappa", kappa, &mut p.kappa),
    ] {
        if let Some(v) = v {
            if !v.is_finite() {
                return Err(value_error(format!("`{name}` must be finite, got {v}")));
            }
            if v < 0.0 {
                return Err(value_error(format!("`{name}` must be >= 0, got {v}")));
            }
            *field = v;
        }
    }
    if !(tol.is_finite() && tol > 0.0) {
        return Err(value_error(format!(
            "`tol` must be finite and > 0, got {tol}"
        )));
    }
    p.tol = tol;
    p.max_iter = args::uint(py, "max_iter", max_iter, 1)?;
    p.norm = norm_arg(norm)?;
    p.spacing_in_weights = spacing_in_weights;
    p.solver = choice(
        "solver",
        solver,
        &[("block", Solver::Block), ("per_label", Solver::PerLabel)],
    )?;
    p.precision = choice(
        "precision",
        precision,
        &[("f32", Precision::F32), ("f64", Precision::F64)],
    )?;
    p.jacobi = jacobi;
    if let Some(t) = n_threads {
        let t = args::uint(py, "n_threads", t, 1)?;
        if t > MAX_THREADS {
            return Err(value_error(format!(
                "`n_threads` must be in 1..={MAX_THREADS} (or None for the wscg pool), got {t}"
            )));
        }
        p.threads = Some(t);
    }
    p.validate().py_err()?;
    Ok(p)
}

/// A count of smoothing passes `name` (0..=100).
fn passes_arg(py: Python<'_>, name: &str, passes: i128) -> PyResult<u32> {
    let passes = args::uint(py, name, passes, 0)?;
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
/// the solve report, for `wscg.volseg.random_walker_bone` (paper 18 section 2.4), which adds
/// the warnings and the `SolveReport`. The seed labels are numbered `1..K` in ascending order
/// for the solve and mapped back; the report lists them (`labels`) and counts the non-zero
/// seed voxels given (`n_seed_voxels`, on the graph or not).
#[pyfunction]
#[pyo3(signature = (ct, seeds, *, t_bone, beta, eps, kappa, preset, tol, max_iter, spacing,
                    n_smooth_passes, norm, spacing_in_weights, solver, precision, jacobi,
                    n_threads, return_prob))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn random_walker<'py>(
    py: Python<'py>,
    ct: &Bound<'py, PyAny>,
    seeds: &Bound<'py, PyAny>,
    t_bone: f64,
    beta: Option<f64>,
    eps: Option<f64>,
    kappa: Option<f64>,
    preset: &str,
    tol: f64,
    max_iter: i128,
    spacing: &Bound<'py, PyAny>,
    n_smooth_passes: i128,
    norm: NormArg,
    spacing_in_weights: bool,
    solver: &str,
    precision: &str,
    jacobi: bool,
    n_threads: Option<i128>,
    return_prob: bool,
) -> PyResult<(Arr<'py, u16>, Option<Arr<'py, f32>>, Bound<'py, PyDict>)> {
    let ct = ct_arg(ct)?;
    let shape = shape3("ct", ct.shape())?;
    let seeds = labels_arg("seeds", seeds, Some(shape), true, MAX_LABEL)?;
    let p = params_arg(
        py,
        t_bone,
        beta,
        eps,
        kappa,
        preset,
        tol,
        max_iter,
        Some(&norm),
        spacing_in_weights,
        solver,
        precision,
        jacobi,
        n_threads,
    )?;
    let spacing = spacing_arg(Some(spacing))?;
    let passes = passes_arg(py, "n_smooth_passes", n_smooth_passes)?;
    let ct = vol_in("ct", &ct, spacing)?;
    // The labels present, ascending, and their numbers 1..K.
    let mut present = vec![false; usize::from(u16::MAX) + 1];
    let mut n_seed_voxels = 0usize;
    for &l in values(&seeds).iter() {
        present[usize::from(l)] = true;
        n_seed_voxels += usize::from(l != 0);
    }
    let user: Vec<u16> = (1..=MAX_LABEL)
        .filter(|&l| present[usize::from(l)])
        .collect();
    let mut internal = vec![0u16; present.len()];
    for (i, &u) in user.iter().enumerate() {
        internal[usize::from(u)] = i as u16 + 1;
    }
    let compact: Vec<u16> = values(&seeds)
        .iter()
        .map(|&l| internal[usize::from(l)])
        .collect();
    let seeds = Volume::new(ct.dims(), ct.spacing(), compact).py_err()?;
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
    report.set_item("labels", &user[..k])?;
    report.set_item("n_seed_voxels", n_seed_voxels)?;
    let probs = match probs {
        Some(v) => Some(array(py, &[k, shape[0], shape[1], shape[2]], v)?),
        None => None,
    };
    let labels: Vec<u16> = labels
        .into_data()
        .into_iter()
        .map(|l| if l == 0 { 0 } else { user[usize::from(l) - 1] })
        .collect();
    Ok((array(py, &shape, labels)?, probs, report))
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
    #[pyo3(signature = (ct, mask, *, t_bone, beta, eps, kappa, preset, tol, max_iter, spacing,
                        n_smooth_passes, norm, spacing_in_weights, solver, precision, jacobi,
                        n_threads))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        ct: &Bound<'_, PyAny>,
        mask: Option<&Bound<'_, PyAny>>,
        t_bone: f64,
        beta: Option<f64>,
        eps: Option<f64>,
        kappa: Option<f64>,
        preset: &str,
        tol: f64,
        max_iter: i128,
        spacing: &Bound<'_, PyAny>,
        n_smooth_passes: i128,
        norm: NormArg,
        spacing_in_weights: bool,
        solver: &str,
        precision: &str,
        jacobi: bool,
        n_threads: Option<i128>,
    ) -> PyResult<Self> {
        let ct = ct_arg(ct)?;
        let shape = shape3("ct", ct.shape())?;
        let p = params_arg(
            py,
            t_bone,
            beta,
            eps,
            kappa,
            preset,
            tol,
            max_iter,
            Some(&norm),
            spacing_in_weights,
            solver,
            precision,
            jacobi,
            n_threads,
        )?;
        let mask = mask_arg(mask, shape)?;
        let spacing = spacing_arg(Some(spacing))?;
        let passes = passes_arg(py, "n_smooth_passes", n_smooth_passes)?;
        let ct = vol_in("ct", &ct, spacing)?;
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

    /// The seed argument `seeds` of `RandomWalkerSession.set_seeds` as uint16 (labels in
    /// `0..=65534`, the session's shape), for the label bookkeeping of the Python class.
    fn check_seeds<'py>(&self, seeds: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let a = labels_arg("seeds", seeds, Some(self.shape), true, MAX_LABEL)?;
        Ok(a.as_any().clone())
    }

    /// Replaces all seeds by the non-zero voxels of `seeds` on the graph; returns how many
    /// were placed.
    fn set_seeds(&mut self, py: Python<'_>, seeds: PyReadonlyArrayDyn<'_, u16>) -> PyResult<usize> {
        same_shape_as_ct("seeds", &seeds, self.shape)?;
        let sp = self.inner.graph().spacing();
        // The graph's spacing is [x, y, z]: reversed, the (dz, dy, dx) vol_in takes.
        let seeds = vol_in("seeds", &seeds, args::xyz(sp))?;
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

/// Geodesic nearest-seed labelling, a baseline (not in the paper) random walks must beat.
///
/// Breadth-first search inside the bone mask from all seeds at once (unweighted
/// 6-neighbour steps): each bone voxel takes the label of the first seed front to reach it
/// (ties: lower voxel index).
///
/// Parameters
/// ----------
/// ct : (Z, Y, X) array
///     CT volume in HU.
/// seeds : (Z, Y, X) int array
///     Seed labels (0 = none).
/// t_bone : float, default 300
///     Bone threshold, HU.
/// mask : (Z, Y, X) bool array, optional
///     Bone mask used instead of ``ct >= t_bone``.
///
/// Returns
/// -------
/// labels : (Z, Y, X) uint16 array
///     0 on non-bone voxels and on bone no seed reaches.
///
/// Raises
/// ------
/// ValueError
///     Shape mismatch, NaN CT values, no seed on a bone voxel.
#[pyfunction]
#[pyo3(signature = (ct, seeds, t_bone=300.0, *, mask=None))]
fn nearest_seed<'py>(
    py: Python<'py>,
    ct: &Bound<'py, PyAny>,
    seeds: &Bound<'py, PyAny>,
    t_bone: f64,
    mask: Option<&Bound<'py, PyAny>>,
) -> PyResult<Arr<'py, u16>> {
    let ct = ct_arg(ct)?;
    let shape = shape3("ct", ct.shape())?;
    let seeds = labels_arg("seeds", seeds, Some(shape), true, MAX_LABEL)?;
    let mut p = RandomWalkParams::default();
    p.t_bone = t_bone_arg(t_bone)?;
    let mask = mask_arg(mask, shape)?;
    let ct = vol_in("ct", &ct, [1.0; 3])?;
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

/// Multi-label Dice similarity (paper eq. 2): ``2 |A n B| / (|A| + |B|)``, where
/// ``|A n B|`` counts the voxels with the same non-zero label in both and ``|A|`` the
/// non-zero voxels of ``A``; 1 when both are empty.
///
/// Parameters
/// ----------
/// a, b : arrays of the same shape
///     Label arrays (integers in 0..65535; 0 = background).
///
/// Returns
/// -------
/// float
#[pyfunction]
fn dice(a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<f64> {
    let a = labels_arg("a", a, None, false, u16::MAX)?;
    let b = labels_arg("b", b, None, false, u16::MAX)?;
    if a.shape() != b.shape() {
        return Err(value_error(format!(
            "shape mismatch: `a` has shape {}, `b` {}",
            args::shape_repr(a.shape()),
            args::shape_repr(b.shape())
        )));
    }
    dice_multilabel(&values(&a), &values(&b)).py_err()
}

/// The collective bone mask ``ct >= t_bone`` (paper section 2.1, after ``n_smooth_passes``
/// passes of :func:`smooth` with ``spacing`` ``(dz, dy, dx)``): the nodes of the graph
/// :func:`random_walker_bone` builds.
#[pyfunction]
#[pyo3(signature = (ct, t_bone=300.0, *, n_smooth_passes=0, spacing=None),
       text_signature = "(ct, t_bone=300.0, *, n_smooth_passes=0, spacing=(1.0, 1.0, 1.0))")]
fn bone_mask<'py>(
    py: Python<'py>,
    ct: &Bound<'py, PyAny>,
    t_bone: f64,
    n_smooth_passes: i128,
    spacing: Option<&Bound<'py, PyAny>>,
) -> PyResult<Arr<'py, bool>> {
    let ct = ct_arg(ct)?;
    let shape = shape3("ct", ct.shape())?;
    let t = t_bone_arg(t_bone)?;
    let passes = passes_arg(py, "n_smooth_passes", n_smooth_passes)?;
    let ct = vol_in("ct", &ct, spacing_arg(spacing)?)?;
    let mask = crate::pool::detach(py, || -> wscg_math::Result<Vec<bool>> {
        ct.ensure_finite("ct")?;
        let smoothed;
        let img = if passes > 0 {
            smoothed = gaussian_smooth3(&ct, passes)?;
            &smoothed
        } else {
            &ct
        };
        Ok(img.data().iter().map(|&v| f64::from(v) >= t).collect())
    })
    .py_err()?;
    array(py, &shape, mask)
}

/// Anisotropy-aware 3-tap Gaussian smoothing (paper section 2.1).
///
/// Along array axis ``a`` the standard deviation is ``0.6 * min(spacing) / spacing[a]``
/// voxels, i.e. ``0.6 * min(spacing)`` in world units on every axis (3 taps, replicated
/// border; an axis whose sigma falls below 0.3 voxel is left alone), applied ``n_passes``
/// times.
///
/// Parameters
/// ----------
/// ct : (Z, Y, X) array
///     CT volume (converted to float32; no NaN).
/// n_passes : int, default 1
///     Number of passes (0..100; 0 returns a float32 copy).
/// spacing : (dz, dy, dx), default (1, 1, 1)
///     Voxel spacing (finite, > 0), in array axis order.
///
/// Returns
/// -------
/// (Z, Y, X) float32 array
#[pyfunction]
#[pyo3(signature = (ct, n_passes=1, *, spacing=None),
       text_signature = "(ct, n_passes=1, *, spacing=(1.0, 1.0, 1.0))")]
fn smooth<'py>(
    py: Python<'py>,
    ct: &Bound<'py, PyAny>,
    n_passes: i128,
    spacing: Option<&Bound<'py, PyAny>>,
) -> PyResult<Arr<'py, f32>> {
    let ct = ct_arg(ct)?;
    let passes = passes_arg(py, "n_passes", n_passes)?;
    let ct = vol_in("ct", &ct, spacing_arg(spacing)?)?;
    let v = crate::pool::detach(py, || gaussian_smooth3(&ct, passes)).py_err()?;
    vol_out(py, v)
}

// ------------------------------------------------------------------------------------------
// Editing

/// The local 3-D grow brush (paper section 2.6, stage 3), on a copy of ``labels``.
///
/// Inside the ball of ``radius`` voxels around ``center_zyx``, a bone voxel ``p_j``
/// (``ct >= t_bone``) takes the ``active`` label from a 26-neighbour ``p_i`` carrying it
/// when ``W_ij = ratio * rho_j + gradient * (1 - min(1, |g_i - g_j| / gradient_scale)) +
/// distance * (1 - |p_j - c| / radius) > tau``, ``rho_j`` the fraction of ``p_j``'s 26
/// neighbours carrying the label and ``g`` the normalised intensity (``norm``). Sweeps
/// repeat until nothing changes or ``max_sweeps``. Voxels outside the ball or the bone
/// mask never change.
///
/// Parameters
/// ----------
/// labels : (Z, Y, X) int array
///     Current labels (0..65535); not modified.
/// ct : (Z, Y, X) array
///     CT volume in HU.
/// center_zyx : (z, y, x)
///     Brush centre, voxel coordinates.
/// radius : float
///     Brush radius, voxels (> 0).
/// active : int
///     Label to grow (1..65535).
/// t_bone : float, default 300
///     Bone threshold, HU.
/// norm : as in :func:`random_walker_bone`
/// ratio, gradient, distance, gradient_scale, tau, max_sweeps
///     Terms of ``W_ij`` (the paper names them without values; these defaults are ours).
///
/// Returns
/// -------
/// labels : (Z, Y, X) uint16 array
///     The edited copy.
/// n_changed : int
///     Number of voxels whose label changed.
#[pyfunction]
#[pyo3(name = "local_grow_edit",
       signature = (labels, ct, center_zyx, radius, active, t_bone=300.0, *, norm=None,
                    ratio=0.5, gradient=0.3, distance=0.2, gradient_scale=0.05, tau=0.5,
                    max_sweeps=10),
       text_signature = "(labels, ct, center_zyx, radius, active, t_bone=300.0, *, \
                         norm='window', ratio=0.5, gradient=0.3, distance=0.2, \
                         gradient_scale=0.05, tau=0.5, max_sweeps=10)")]
#[allow(clippy::too_many_arguments)]
fn local_grow_edit_py<'py>(
    py: Python<'py>,
    labels: &Bound<'py, PyAny>,
    ct: &Bound<'py, PyAny>,
    center_zyx: &Bound<'py, PyAny>,
    radius: f64,
    active: i128,
    t_bone: f64,
    norm: Option<NormArg>,
    ratio: f64,
    gradient: f64,
    distance: f64,
    gradient_scale: f64,
    tau: f64,
    max_sweeps: i128,
) -> PyResult<(Arr<'py, u16>, usize)> {
    let ct = ct_arg(ct)?;
    let shape = shape3("ct", ct.shape())?;
    let labels = labels_arg("labels", labels, Some(shape), true, u16::MAX)?;
    let [cz, cy, cx] = args::finite3("center_zyx", args::triple("center_zyx", center_zyx)?)?;
    if !(radius.is_finite() && radius > 0.0) {
        return Err(value_error(format!(
            "`radius` must be finite and > 0, got {radius}"
        )));
    }
    let active = args::uint(py, "active", active, 1u16)?;
    let mut p = RandomWalkParams::default();
    p.t_bone = t_bone_arg(t_bone)?;
    p.norm = norm_arg(norm.as_ref())?;
    let w = GrowWeights {
        ratio,
        gradient,
        distance,
        gradient_scale,
        tau,
        max_sweeps: args::uint(py, "max_sweeps", max_sweeps, 0)?,
    };
    for (name, v) in [
        ("ratio", ratio),
        ("gradient", gradient),
        ("distance", distance),
        ("gradient_scale", gradient_scale),
        ("tau", tau),
    ] {
        if !v.is_finite() {
            return Err(value_error(format!("`{name}` must be finite, got {v}")));
        }
    }
    if gradient_scale <= 0.0 {
        return Err(value_error(format!(
            "`gradient_scale` must be > 0, got {gradient_scale}"
        )));
    }
    let ct = vol_in("ct", &ct, [1.0; 3])?;
    let mut labels = vol_in("labels", &labels, [1.0; 3])?;
    let n = crate::pool::detach(py, || {
        ct.ensure_finite("ct")?;
        local_grow_edit(&mut labels, &ct, &p, [cx, cy, cz], radius, active, &w)
    })
    .py_err()?;
    Ok((vol_out(py, labels)?, n))
}

/// Relabels small label islands (an optional clean-up, not in the paper), on a copy.
///
/// Every 6-connected component of a non-zero label with fewer than ``min_voxels`` voxels
/// takes the most frequent other non-zero label among its 6-neighbours (ties: the lowest);
/// components without a labelled neighbour stay.
///
/// Parameters
/// ----------
/// labels : (Z, Y, X) int array
///     Labels (0..65535); not modified.
/// min_voxels : int
///     Smallest component kept (>= 0).
///
/// Returns
/// -------
/// labels : (Z, Y, X) uint16 array
/// n_changed : int
#[pyfunction]
#[pyo3(name = "remove_small_components")]
fn remove_small_components_py<'py>(
    py: Python<'py>,
    labels: &Bound<'py, PyAny>,
    min_voxels: i128,
) -> PyResult<(Arr<'py, u16>, usize)> {
    let labels = labels_arg("labels", labels, None, true, u16::MAX)?;
    let min_voxels = args::uint(py, "min_voxels", min_voxels, 0)?;
    let mut labels = vol_in("labels", &labels, [1.0; 3])?;
    let n = crate::pool::detach(py, || remove_small_components(&mut labels, min_voxels))?;
    Ok((vol_out(py, labels)?, n))
}

// ------------------------------------------------------------------------------------------
// Phantom

/// A CT phantom of a fractured bone shell with exact fragment labels and seed strokes
/// (a stand-in for the paper's clinical cases of section 3; no clinical CT is
/// redistributable).
///
/// An ellipsoidal shell (``shell`` radii as fractions of the half-size, ``bone_hu``) split
/// into ``n_fragments`` pieces by the spherical Voronoi cells of random directions; fracture
/// gaps of ``gap_hu`` (above the 300 HU threshold, so the thresholded bone stays in one
/// piece); soft tissue (40 HU) inside, air (-1000 HU) outside; Gaussian partial-volume blur,
/// CT noise, rounding to integers. Seeds: one stroke per fragment, a ball around a random
/// mid-shell point away from its boundary (not at the Voronoi site, so nearest-seed
/// labelling does not reproduce the truth by construction), or a patch of its outer surface.
///
/// Parameters
/// ----------
/// shape : (Z, Y, X), default (128, 128, 128)
///     Volume shape, each side >= 16, at most 512^3 voxels.
/// n_fragments : int, default 6
///     Number of fragments K (2..64).
/// seed : int, default 0
///     Seed of the sites, strokes and noise (same seed, same phantom).
/// return_distance : bool, default False
///     Also return the arc distance (voxels) of every voxel from the nearest fracture
///     boundary, float32.
/// shell : (inner, outer), default (0.60, 0.68)
///     Radii of the shell as fractions of the half-size of each axis (``0 < inner < outer
///     < 0.9``).
/// bone_hu : float, default 1200
///     CT value of the bone, HU.
/// gap_hu : float, default 450
///     CT value inside the fracture gaps, HU.
/// gap_width : float, default 0.75
///     Width of the fracture gaps, voxels (>= 0).
/// blur_sigma : float, default 0.8
///     Partial-volume blur, voxels (0..16).
/// noise_hu : float, default 30
///     Standard deviation of the CT noise, HU (>= 0).
/// t_bone : float, default 300
///     Threshold of the ``truth`` labels and of the seed voxels, HU.
/// stroke_radius : float, default 2
///     Radius of each seed stroke, voxels (>= 0).
/// stroke_margin : float, default 4
///     Least distance of a stroke from its fragment's boundary, voxels (>= 0).
/// surface_strokes : bool, default False
///     Paint the strokes on the outer surface, as with the paper's 3-D brush (the bone
///     voxels with a non-bone 6-neighbour within 3 voxels of a point of the outer surface).
///
/// Returns
/// -------
/// ct : (Z, Y, X) float32 array
///     HU.
/// truth : (Z, Y, X) uint16 array
///     Fragment label ``1..K`` of every voxel with ``ct >= t_bone``, 0 elsewhere.
/// seeds : (Z, Y, X) uint16 array
///     Seed strokes (on bone voxels).
/// distance : (Z, Y, X) float32 array
///     Only with ``return_distance``.
#[pyfunction]
#[pyo3(signature = (shape=vec![128, 128, 128], n_fragments=6, seed=0, *, return_distance=false,
                    shell=[0.60, 0.68], bone_hu=1200.0, gap_hu=450.0, gap_width=0.75,
                    blur_sigma=0.8, noise_hu=30.0, t_bone=300.0, stroke_radius=2.0,
                    stroke_margin=4.0, surface_strokes=false),
       text_signature = "(shape=(128, 128, 128), n_fragments=6, seed=0, *, \
                         return_distance=False, shell=(0.6, 0.68), bone_hu=1200.0, \
                         gap_hu=450.0, gap_width=0.75, blur_sigma=0.8, noise_hu=30.0, \
                         t_bone=300.0, stroke_radius=2.0, stroke_margin=4.0, \
                         surface_strokes=False)")]
#[allow(clippy::too_many_arguments)]
fn make_fractured_shell_phantom<'py>(
    py: Python<'py>,
    shape: Vec<i128>,
    n_fragments: i128,
    seed: i128,
    return_distance: bool,
    shell: [f64; 2],
    bone_hu: f64,
    gap_hu: f64,
    gap_width: f64,
    blur_sigma: f64,
    noise_hu: f64,
    t_bone: f64,
    stroke_radius: f64,
    stroke_margin: f64,
    surface_strokes: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    let [z, y, x] = shape[..] else {
        return Err(value_error(format!(
            "`shape` must be 3 integers (Z, Y, X), got {shape:?}"
        )));
    };
    let dims = [
        args::uint(py, "shape", z, 16usize)?,
        args::uint(py, "shape", y, 16usize)?,
        args::uint(py, "shape", x, 16usize)?,
    ];
    let voxels = dims[0]
        .checked_mul(dims[1])
        .and_then(|v| v.checked_mul(dims[2]));
    if !matches!(voxels, Some(v) if v <= MAX_PHANTOM_VOXELS) {
        return Err(value_error(format!(
            "`shape` {} has more than {MAX_PHANTOM_VOXELS} voxels (512^3)",
            args::shape_repr(&dims)
        )));
    }
    let n_fragments = args::uint(py, "n_fragments", n_fragments, 2usize)?;
    if n_fragments > MAX_FRAGMENTS {
        return Err(value_error(format!(
            "`n_fragments` must be in 2..={MAX_FRAGMENTS}, got {n_fragments}"
        )));
    }
    let mut c = PhantomParams::default()
        .dims([dims[2], dims[1], dims[0]])
        .fragments(n_fragments)
        .seed(args::uint(py, "seed", seed, 0u64)?);
    c.shell = shell;
    c.surface_strokes = surface_strokes;
    for (name, v, hi, field) in [
        ("bone_hu", bone_hu, None, &mut c.bone_hu),
        ("gap_hu", gap_hu, None, &mut c.gap_hu),
        (
            "gap_width",
            gap_width,
            Some(f64::INFINITY),
            &mut c.gap_width,
        ),
        ("blur_sigma", blur_sigma, Some(MAX_BLUR), &mut c.blur_sigma),
        ("noise_hu", noise_hu, Some(f64::INFINITY), &mut c.noise_hu),
        ("t_bone", t_bone, None, &mut c.t_bone),
        (
            "stroke_radius",
            stroke_radius,
            Some(f64::INFINITY),
            &mut c.stroke_radius,
        ),
        (
            "stroke_margin",
            stroke_margin,
            Some(f64::INFINITY),
            &mut c.stroke_margin,
        ),
    ] {
        if !v.is_finite() {
            return Err(value_error(format!("`{name}` must be finite, got {v}")));
        }
        if let Some(hi) = hi {
            if !(0.0..=hi).contains(&v) {
                return Err(value_error(format!(
                    "`{name}` must be in [0, {hi}], got {v}"
                )));
            }
        }
        *field = v;
    }
    let ph = crate::pool::detach(py, || fractured_shell_phantom(&c)).py_err()?;
    let mut out = vec![
        vol_out(py, ph.ct)?.into_any(),
        vol_out(py, ph.truth)?.into_any(),
        vol_out(py, ph.seeds)?.into_any(),
    ];
    if return_distance {
        let dist: Vec<f32> = ph.boundary_distance.iter().map(|&d| d as f32).collect();
        out.push(array(py, &dims, dist)?.into_any());
    }
    PyTuple::new(py, out)
}

/// Registers the functions of `wscg._native.volseg`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySession>()?;
    m.add_function(wrap_pyfunction!(_session_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(random_walker, m)?)?;
    m.add_function(wrap_pyfunction!(nearest_seed, m)?)?;
    m.add_function(wrap_pyfunction!(dice, m)?)?;
    m.add_function(wrap_pyfunction!(smooth, m)?)?;
    m.add_function(wrap_pyfunction!(bone_mask, m)?)?;
    m.add_function(wrap_pyfunction!(local_grow_edit_py, m)?)?;
    m.add_function(wrap_pyfunction!(remove_small_components_py, m)?)?;
    m.add_function(wrap_pyfunction!(make_fractured_shell_phantom, m)?)?;
    Ok(())
}
