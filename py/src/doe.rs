//! `wscg._native.doe`: bindings of `wscg-doe` (paper 07's study statistics). The documented
//! API is `python/wscg/doe.py`.

use nalgebra::DMatrix;
use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_doe::{AnovaEffect, CcdAlpha, CcdFace, RsmFit};

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

/// Central composite design, coded units, rows = runs (see `wscg.doe.ccd`).
#[pyfunction]
#[pyo3(signature = (k, face, alpha, center))]
fn ccd<'py>(
    py: Python<'py>,
    k: usize,
    face: &str,
    alpha: &str,
    center: (usize, usize),
) -> PyResult<Arr<'py, f64>> {
    let face = face.parse::<CcdFace>().py_err()?;
    let alpha = alpha.parse::<CcdAlpha>().py_err()?;
    let m = wscg_doe::ccd_blocks(k, face, alpha, center).py_err()?;
    dmat_out(py, &m)
}

/// Coded to physical units.
#[pyfunction]
fn decode<'py>(
    py: Python<'py>,
    coded: PyReadonlyArrayDyn<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
) -> PyResult<Arr<'py, f64>> {
    let m = wscg_doe::decode(&dmat("coded", &coded)?, &low, &high).py_err()?;
    dmat_out(py, &m)
}

/// Physical to coded units.
#[pyfunction]
fn encode<'py>(
    py: Python<'py>,
    physical: PyReadonlyArrayDyn<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
) -> PyResult<Arr<'py, f64>> {
    let m = wscg_doe::encode(&dmat("physical", &physical)?, &low, &high).py_err()?;
    dmat_out(py, &m)
}

/// Williams Latin square: presentation orders.
#[pyfunction]
fn williams(n: usize) -> PyResult<Vec<Vec<usize>>> {
    wscg_doe::williams_square(n).py_err()
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

/// Explained-variance ratios of the standardised panel (stimuli x subjects).
#[pyfunction]
fn panel_pca(scores: PyReadonlyArrayDyn<f64>) -> PyResult<Vec<f64>> {
    wscg_doe::panel_pca(&dmat("scores", &scores)?).py_err()
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
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
