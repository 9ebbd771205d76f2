//! `wscg._native.doe`: bindings of `wscg-doe` (paper 07's study statistics).
//! `python/wscg/doe.py` documents the module, re-exports the design functions defined here
//! (arguments converted by [`crate::args`]) and builds the fits' result classes.

use nalgebra::DMatrix;
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_doe::{AnovaEffect, CcdAlpha, CcdFace, RsmFit};

use crate::args::{self, uint};
use crate::convert::{array, dims2, values, Arr};
use crate::errors::{value_error, IntoPy};

/// A 2-D float64 array as a nalgebra matrix.
fn dmat(name: &str, a: &PyReadonlyArrayDyn<f64>) -> PyResult<DMatrix<f64>> {
    let (r, c) = dims2(name, a)?;
    Ok(DMatrix::from_row_slice(r, c, &values(a)))
}

fn dmat_out<'py>(py: Python<'py>, m: &DMatrix<f64>) -> PyResult<Arr<'py, f64>> {
    let v: Vec<f64> = m
        .row_iter()
        .flat_map(|r| r.iter().copied().collect::<Vec<_>>())
        .collect();
    array(py, &[m.nrows(), m.ncols()], v)
}

/// `alpha` of [`ccd`]: a rule's name or an axial distance.
#[derive(FromPyObject)]
enum AxialDistance {
    Rule(String),
    Value(f64),
}

/// `center` of [`ccd`]: centre points of both blocks, or of the first.
#[derive(FromPyObject)]
enum CentrePoints {
    First(i128),
    Blocks((i128, i128)),
}

/// Central composite design in coded units, one row per run (pyDOE3's ``ccdesign``).
///
/// Parameters
/// ----------
/// k : int
///     Number of factors (>= 2).
/// face : {'circumscribed', 'inscribed', 'faced'} (or 'ccc', 'cci', 'ccf')
///     Where the axial points lie; inscribed designs scale everything into [-1, 1].
/// alpha : {'orthogonal', 'rotatable'} or float
///     Axial distance rule (pyDOE3's default is orthogonal).
/// center : int or (int, int)
///     Centre points in the factorial and axial blocks; an int puts them all in the first.
///
/// Returns
/// -------
/// (runs, k) float64 array: factorial block with its centre points, then axial block with its
/// centre points.
///
/// Examples
/// --------
/// >>> ccd(2, "inscribed", "rotatable", (3, 2)).shape   # the paper's 13 runs
/// (13, 2)
#[pyfunction]
#[pyo3(signature = (k, face="circumscribed", alpha=AxialDistance::Rule("orthogonal".into()),
                    center=CentrePoints::Blocks((4, 4))),
       text_signature = "(k, face='circumscribed', alpha='orthogonal', center=(4, 4))")]
fn ccd<'py>(
    py: Python<'py>,
    k: i128,
    face: &str,
    alpha: AxialDistance,
    center: CentrePoints,
) -> PyResult<Arr<'py, f64>> {
    let k = uint(py, "k", k, 0)?;
    let center = match center {
        CentrePoints::First(n) => (uint(py, "center", n, 0)?, 0),
        CentrePoints::Blocks((a, b)) => (uint(py, "center", a, 0)?, uint(py, "center", b, 0)?),
    };
    let face = face.parse::<CcdFace>().py_err()?;
    let alpha = match alpha {
        AxialDistance::Rule(name) => name.parse::<CcdAlpha>(),
        AxialDistance::Value(v) => v.to_string().parse::<CcdAlpha>(),
    }
    .py_err()?;
    let m = wscg_doe::ccd_blocks(k, face, alpha, center).py_err()?;
    dmat_out(py, &m)
}

/// The 2-D array argument `name` as a matrix.
fn dmat_arg(name: &str, a: &Bound<'_, PyAny>) -> PyResult<DMatrix<f64>> {
    dmat(name, &args::array(name, a)?)
}

/// Coded units [-1, 1] to physical units, per factor ``low`` ... ``high``.
#[pyfunction]
fn decode<'py>(
    py: Python<'py>,
    coded: &Bound<'py, PyAny>,
    low: Vec<f64>,
    high: Vec<f64>,
) -> PyResult<Arr<'py, f64>> {
    let m = wscg_doe::decode(&dmat_arg("coded", coded)?, &low, &high).py_err()?;
    dmat_out(py, &m)
}

/// Physical units to coded units [-1, 1].
#[pyfunction]
fn encode<'py>(
    py: Python<'py>,
    physical: &Bound<'py, PyAny>,
    low: Vec<f64>,
    high: Vec<f64>,
) -> PyResult<Arr<'py, f64>> {
    let m = wscg_doe::encode(&dmat_arg("physical", physical)?, &low, &high).py_err()?;
    dmat_out(py, &m)
}

/// Williams Latin square: presentation orders balanced for first-order carry-over.
///
/// ``n`` rows for even ``n``, ``2n`` rows for odd ``n`` (26 for the paper's 13 plates: one
/// order per observer); every row is a permutation of ``0 .. n-1``.
#[pyfunction]
fn williams(py: Python<'_>, n: i128) -> PyResult<Arr<'_, i64>> {
    let rows = wscg_doe::williams_square(uint(py, "n", n, 0)?).py_err()?;
    let width = rows.first().map_or(0, Vec::len);
    let data = rows.iter().flatten().map(|&v| v as i64).collect();
    array(py, &[rows.len(), width], data)
}

fn fit_dict<'py>(py: Python<'py>, f: &RsmFit) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("names", f.names.clone())?;
    d.set_item("coef", f.coef.clone())?;
    d.set_item("se", f.se.clone())?;
    d.set_item("t", f.t.clone())?;
    d.set_item("p", f.p.clone())?;
    d.set_item("r2", f.r2)?;
    d.set_item("r2_adj", f.r2_adj)?;
    d.set_item("r2_pred", f.r2_pred)?;
    d.set_item("press", f.press)?;
    d.set_item("sse", f.sse)?;
    d.set_item("sst", f.sst)?;
    d.set_item("df_resid", f.df_resid)?;
    d.set_item("sigma2", f.sigma2)?;
    d.set_item("leverage", f.leverage.clone())?;
    d.set_item("residuals", f.residuals.clone())?;
    d.set_item("fitted", f.fitted.clone())?;
    d.set_item("stationary", f.stationary.clone())?;
    d.set_item("y_stationary", f.y_stationary)?;
    d.set_item("canonical_eigs", f.canonical_eigs.clone())?;
    d.set_item("canonical_axes", dmat_out(py, &f.canonical_axes)?)?;
    Ok(d)
}

/// Second-order response surface on the runs `x` (runs x factors) and responses `y`.
#[pyfunction]
fn fit_rsm<'py>(
    py: Python<'py>,
    x: PyReadonlyArrayDyn<f64>,
    y: Vec<f64>,
    interaction: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let f = wscg_doe::fit_quadratic(&dmat("x", &x)?, &y, interaction).py_err()?;
    fit_dict(py, &f)
}

/// The same surface on every score (subjects x runs) with subjects as blocks.
#[pyfunction]
fn fit_rsm_blocked<'py>(
    py: Python<'py>,
    x: PyReadonlyArrayDyn<f64>,
    scores: PyReadonlyArrayDyn<f64>,
    interaction: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let f =
        wscg_doe::fit_quadratic_blocked(&dmat("x", &x)?, &dmat("scores", &scores)?, interaction)
            .py_err()?;
    fit_dict(py, &f)
}

fn effect_dict<'py>(py: Python<'py>, e: &AnovaEffect) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("ss", e.ss)?;
    d.set_item("df", e.df)?;
    d.set_item("ms", e.ms)?;
    d.set_item("F", e.f)?;
    d.set_item("p", e.p)?;
    d.set_item("ss_error", e.ss_error)?;
    d.set_item("df_error", e.df_error)?;
    d.set_item("ms_error", e.ms_error)?;
    d.set_item("np2", e.np2)?;
    d.set_item("eps_gg", e.eps_gg)?;
    d.set_item("p_gg", e.p_gg)?;
    Ok(d)
}

/// Two-way repeated-measures ANOVA on a (subjects, conditions, stimuli) array.
#[pyfunction]
fn rm_anova<'py>(py: Python<'py>, scores: PyReadonlyArrayDyn<f64>) -> PyResult<Bound<'py, PyDict>> {
    let [s, a, b] = *scores.shape() else {
        return Err(value_error(format!(
            "`scores` must be a 3-D (subjects, conditions, stimuli) array, got shape {:?}",
            scores.shape()
        )));
    };
    let t = wscg_doe::rm_anova(&values(&scores), s, a, b).py_err()?;
    let d = PyDict::new(py);
    for e in &t.effects {
        d.set_item(e.name.clone(), effect_dict(py, e)?)?;
    }
    d.set_item("ss_subject", t.ss_subject)?;
    d.set_item("ss_total", t.ss_total)?;
    Ok(d)
}

/// One-way repeated-measures ANOVA on a (subjects, levels) array.
#[pyfunction]
fn rm_anova_oneway<'py>(
    py: Python<'py>,
    scores: PyReadonlyArrayDyn<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let e = wscg_doe::rm_anova_oneway(&dmat("scores", &scores)?).py_err()?;
    effect_dict(py, &e)
}

/// Fisher's LSD on a (subjects, stimuli) array.
#[pyfunction]
fn lsd<'py>(
    py: Python<'py>,
    scores: PyReadonlyArrayDyn<f64>,
    alpha: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let r = wscg_doe::lsd_pairs(&dmat("scores", &scores)?, alpha).py_err()?;
    let d = PyDict::new(py);
    d.set_item("alpha", r.alpha)?;
    d.set_item("t_crit", r.t_crit)?;
    d.set_item("ms_error", r.ms_error)?;
    d.set_item("df_error", r.df_error)?;
    d.set_item("lsd", r.lsd)?;
    d.set_item("means", r.means)?;
    d.set_item("pairs", r.pairs)?;
    d.set_item("n_separated", r.n_separated)?;
    Ok(d)
}

/// Explained-variance ratios of the PCA of the panel (stimuli x subjects, subjects
/// standardised): the first above 0.8 means the observers agree (paper 07, section 5.1).
#[pyfunction]
fn panel_pca<'py>(py: Python<'py>, scores: &Bound<'py, PyAny>) -> PyResult<Arr<'py, f64>> {
    let ratios = wscg_doe::panel_pca(&dmat_arg("scores", scores)?).py_err()?;
    array(py, &[ratios.len()], ratios)
}

/// Registers the functions.
/// Reads a study's score table: `(subjects, conditions, scores (S, C, K))`.
#[pyfunction]
fn load_study(
    py: Python<'_>,
    path: std::path::PathBuf,
) -> PyResult<(Vec<String>, Vec<String>, Arr<'_, f64>)> {
    let st = crate::pool::detach(py, || wscg_doe::read_study(&path)).py_err()?;
    let shape = [st.subjects.len(), st.conditions.len(), st.stimuli];
    let scores = array(py, &shape, st.scores)?;
    Ok((st.subjects, st.conditions, scores))
}

/// Writes a study's score table from the names and the `(S, C, K)` scores.
#[pyfunction]
fn save_study(
    py: Python<'_>,
    path: std::path::PathBuf,
    subjects: Vec<String>,
    conditions: Vec<String>,
    scores: PyReadonlyArrayDyn<f64>,
) -> PyResult<()> {
    let stimuli = match *scores.shape() {
        [s, c, k] if s == subjects.len() && c == conditions.len() => k,
        ref sh => {
            return Err(value_error(format!(
                "`scores` must have shape ({}, {}, stimuli), got {sh:?}",
                subjects.len(),
                conditions.len()
            )))
        }
    };
    let st = wscg_doe::Study {
        subjects,
        conditions,
        stimuli,
        scores: values(&scores).into_owned(),
    };
    crate::pool::detach(py, || wscg_doe::write_study(&path, &st)).py_err()
}

/// Reads runs: `(x (n, k), y (n,))`.
#[pyfunction]
fn load_runs(py: Python<'_>, path: std::path::PathBuf) -> PyResult<(Arr<'_, f64>, Arr<'_, f64>)> {
    let (x, y) = crate::pool::detach(py, || wscg_doe::read_runs(&path)).py_err()?;
    let n = y.len();
    Ok((dmat_out(py, &x)?, array(py, &[n], y)?))
}

/// Writes runs `x (n, k)` and `y (n,)` with the header `x1,...,xk,y`.
#[pyfunction]
fn save_runs(
    py: Python<'_>,
    path: std::path::PathBuf,
    x: PyReadonlyArrayDyn<f64>,
    y: Vec<f64>,
) -> PyResult<()> {
    let x = dmat("x", &x)?;
    crate::pool::detach(py, || wscg_doe::write_runs(&path, &x, &y)).py_err()
}

/// Reads a design table (header, one row of factor levels per stimulus).
#[pyfunction]
fn load_design(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Arr<'_, f64>> {
    let m = crate::pool::detach(py, || wscg_doe::read_design(&path)).py_err()?;
    dmat_out(py, &m)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(load_study, m)?)?;
    m.add_function(wrap_pyfunction!(save_study, m)?)?;
    m.add_function(wrap_pyfunction!(load_runs, m)?)?;
    m.add_function(wrap_pyfunction!(save_runs, m)?)?;
    m.add_function(wrap_pyfunction!(load_design, m)?)?;
    m.add_function(wrap_pyfunction!(ccd, m)?)?;
    m.add_function(wrap_pyfunction!(decode, m)?)?;
    m.add_function(wrap_pyfunction!(encode, m)?)?;
    m.add_function(wrap_pyfunction!(williams, m)?)?;
    m.add_function(wrap_pyfunction!(fit_rsm, m)?)?;
    m.add_function(wrap_pyfunction!(fit_rsm_blocked, m)?)?;
    m.add_function(wrap_pyfunction!(rm_anova, m)?)?;
    m.add_function(wrap_pyfunction!(rm_anova_oneway, m)?)?;
    m.add_function(wrap_pyfunction!(lsd, m)?)?;
    m.add_function(wrap_pyfunction!(panel_pca, m)?)?;
    Ok(())
}
