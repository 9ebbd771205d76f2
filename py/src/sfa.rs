//! `wscg._native.biometrics` (paper 05 part): bindings of `wscg_biometrics::sfa`, class-wise
//! and full-data-set slow feature analysis, temporal SFA, k-NN and the confusion matrix.
//! The documented API is `python/wscg/biometrics.py` (`PerClassSFA`, `GlobalSFA`,
//! `TemporalSFA`, `KNN`).

use numpy::PyReadonlyArrayDyn;
use pyo3::prelude::*;
use wscg_biometrics::sfa::global::parse_rule;
use wscg_biometrics::sfa::{
    confusion_matrix as confusion, ClassObjective, ClassSfaParams, GlobalSfa, Knn, KnnTie,
    PerClassSfa, QuadraticExpansion, TemporalSfa,
};

use crate::args::uint;
use crate::convert::{array, labels_from, mat, mat_map, mat_out, row_blocks, Arr};
use crate::errors::{value_error, IntoPy, IntoPyRenamed, Renames};

fn expansion(degree: usize, include_linear: bool) -> PyResult<Option<QuadraticExpansion>> {
    match degree {
        1 => Ok(None),
        2 => Ok(Some(QuadraticExpansion { include_linear })),
        d => Err(value_error(format!("`degree` must be 1 or 2, got {d}"))),
    }
}

enum Fitted {
    PerClass(PerClassSfa),
    Global(GlobalSfa),
}

/// A fitted class-wise or full-data-set SFA classifier.
#[pyclass(module = "wscg._native.biometrics", name = "SfaModel", frozen)]
pub struct PySfa {
    inner: Fitted,
}

#[pymethods]
impl PySfa {
    /// `Var_C` (or the Gaussian score) per row and class, smaller is better.
    fn decision_scores<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Arr<'py, f64>> {
        mat_map(py, "x", &x, |x| match &self.inner {
            Fitted::PerClass(m) => m.decision_scores(x),
            Fitted::Global(m) => m.decision_scores(x),
        })
    }

    /// Predicted class codes.
    fn predict<'py>(&self, py: Python<'py>, x: PyReadonlyArrayDyn<f64>) -> PyResult<Arr<'py, i64>> {
        let p: Vec<i64> = row_blocks(py, "x", &x, |x| match &self.inner {
            Fitted::PerClass(m) => m.predict(x),
            Fitted::Global(m) => m.predict(x),
        })?
        .into_iter()
        .flatten()
        .map(i64::from)
        .collect();
        array(py, &[p.len()], p)
    }

    /// Centred responses of one class code (`n x m`), class-wise models only.
    fn responses<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArrayDyn<f64>,
        class_code: u32,
    ) -> PyResult<Arr<'py, f64>> {
        mat_map(py, "x", &x, |x| match &self.inner {
            Fitted::PerClass(m) => m.responses(x, class_code),
            Fitted::Global(m) => m.transform(x),
        })
    }

    /// Eigenvalues: per class (class-wise) or of the shared functions, and the rank.
    fn eigenvalues(&self) -> (Vec<Vec<f64>>, usize) {
        match &self.inner {
            Fitted::PerClass(m) => (m.lambdas.clone(), m.rank),
            Fitted::Global(m) => (vec![m.lambdas.clone()], m.w.nrows()),
        }
    }

    /// The model as JSON.
    fn to_json(&self) -> PyResult<String> {
        match &self.inner {
            Fitted::PerClass(m) => m.to_json().py_err(),
            Fitted::Global(m) => m.to_json().py_err(),
        }
    }

    /// A model from `to_json` (`global` for a full-data-set model).
    #[staticmethod]
    fn from_json(py: Python<'_>, s: &str, global: bool) -> PyResult<Self> {
        let inner = if global {
            Fitted::Global(crate::pool::detach(py, || GlobalSfa::from_json(s)).py_err()?)
        } else {
            Fitted::PerClass(crate::pool::detach(py, || PerClassSfa::from_json(s)).py_err()?)
        };
        Ok(Self { inner })
    }
}

/// Fits class-wise SFA (`rule` None) or full-data-set SFA with `rule`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn sfa_fit(
    py: Python<'_>,
    x: PyReadonlyArrayDyn<f64>,
    y: PyReadonlyArrayDyn<i64>,
    pca_n_components: i128,
    m: &Bound<'_, PyAny>,
    degree: i128,
    include_linear: bool,
    gamma: Option<f64>,
    shrinkage: f64,
    rank_tol: f64,
    rule: Option<&str>,
) -> PyResult<PySfa> {
    // GlobalSFA (the one with a rule) calls its output count `n_components`.
    let m_name = if rule.is_some() { "n_components" } else { "m" };
    let (pca_n_components, m, degree): (usize, usize, usize) = (
        uint(py, "pca_n_components", pca_n_components, 0)?,
        uint(py, m_name, crate::args::integer(m_name, m)?, 0)?,
        uint(py, "degree", degree, 0)?,
    );
    let x = mat("x", &x)?;
    let y = labels_from("y", &y)?;
    let cfg = ClassSfaParams::default()
        .pca_dims(pca_n_components)
        .expansion(expansion(degree, include_linear)?)
        .m_per_class(m)
        .objective(gamma.map_or(ClassObjective::WithinOnly, |gamma| {
            ClassObjective::WithinMinusOutOfClass { gamma }
        }))
        .shrinkage(shrinkage)
        .rank_tol(rank_tol);
    // The Python classes name the functions per class `m` (PerClassSFA) or `n_components`
    // (GlobalSFA).
    const PER_CLASS: &Renames = &[("pca_dims", "pca_n_components"), ("m_per_class", "m")];
    const GLOBAL: &Renames = &[
        ("pca_dims", "pca_n_components"),
        ("m_per_class", "n_components"),
    ];
    let inner = match rule {
        None => Fitted::PerClass(
            crate::pool::detach(py, || PerClassSfa::fit(x.as_ref(), &y, &cfg))
                .py_err_renamed(PER_CLASS)?,
        ),
        Some(r) => {
            let r = parse_rule(r).py_err()?;
            Fitted::Global(
                crate::pool::detach(py, || GlobalSfa::fit(x.as_ref(), &y, &cfg, r))
                    .py_err_renamed(GLOBAL)?,
            )
        }
    };
    Ok(PySfa { inner })
}

/// A fitted temporal SFA.
#[pyclass(module = "wscg._native.biometrics", name = "TemporalSfaModel", frozen)]
pub struct PyTemporal {
    inner: TemporalSfa,
}

#[pymethods]
impl PyTemporal {
    /// Slow features of the rows.
    fn transform<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Arr<'py, f64>> {
        mat_map(py, "x", &x, |x| self.inner.transform(x))
    }

    /// Delta values, ascending.
    fn delta_values(&self) -> Vec<f64> {
        self.inner.delta.clone()
    }

    /// Rank of the expanded covariance.
    fn rank(&self) -> usize {
        self.inner.rank
    }

    /// The model as JSON.
    fn to_json(&self) -> PyResult<String> {
        self.inner.to_json().py_err()
    }

    /// A model from `to_json`.
    #[staticmethod]
    fn from_json(py: Python<'_>, s: &str) -> PyResult<Self> {
        Ok(Self {
            inner: crate::pool::detach(py, || TemporalSfa::from_json(s)).py_err()?,
        })
    }
}

/// Fits temporal SFA to a time series (one step per row).
#[pyfunction]
fn temporal_sfa_fit(
    py: Python<'_>,
    x: PyReadonlyArrayDyn<f64>,
    n_components: i128,
    degree: i128,
    include_linear: bool,
    rank_tol: f64,
) -> PyResult<PyTemporal> {
    let (n_components, degree): (usize, usize) = (
        uint(py, "n_components", n_components, 0)?,
        uint(py, "degree", degree, 0)?,
    );
    let x = mat("x", &x)?;
    let e = expansion(degree, include_linear)?;
    let inner = crate::pool::detach(py, || {
        TemporalSfa::fit(x.as_ref(), n_components, e, rank_tol)
    })
    .py_err()?;
    Ok(PyTemporal { inner })
}

/// k-NN labels (codes) of `test` against `train`.
#[pyfunction]
fn knn_predict<'py>(
    py: Python<'py>,
    train: PyReadonlyArrayDyn<f64>,
    y: PyReadonlyArrayDyn<i64>,
    test: PyReadonlyArrayDyn<f64>,
    n_neighbors: i128,
    tie: &str,
) -> PyResult<Arr<'py, i64>> {
    let n_neighbors: usize = uint(py, "n_neighbors", n_neighbors, 0)?;
    let tie = match tie {
        "nearest" => KnnTie::Nearest,
        "smallest" => KnnTie::SmallestLabel,
        other => {
            return Err(value_error(format!(
                "`tie` must be 'nearest' or 'smallest', got {other:?}"
            )))
        }
    };
    let (train, test, y) = (
        mat("x", &train)?,
        mat("x_test", &test)?,
        labels_from("y", &y)?,
    );
    let p = crate::pool::detach(py, || {
        Knn::fit(train.as_ref(), &y, n_neighbors, tie).and_then(|m| m.predict(test.as_ref()))
    })
    .py_err_renamed(&[("k", "n_neighbors")])?;
    let n = p.len();
    array(py, &[n], p.into_iter().map(i64::from).collect())
}

/// Row-normalised confusion matrix (percent) of class codes `0..n_classes`.
#[pyfunction]
fn confusion_matrix<'py>(
    py: Python<'py>,
    y_true: PyReadonlyArrayDyn<i64>,
    y_pred: PyReadonlyArrayDyn<i64>,
    n_classes: u32,
) -> PyResult<Arr<'py, f64>> {
    let classes: Vec<u32> = (0..n_classes).collect();
    let (t, p) = (
        labels_from("y_true", &y_true)?,
        labels_from("y_pred", &y_pred)?,
    );
    let m = crate::pool::detach(py, || confusion(&t, &p, &classes)).py_err()?;
    mat_out(py, &m)
}

/// Registers the paper 05 functions into the biometrics submodule.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PySfa>()?;
    m.add_class::<PyTemporal>()?;
    m.add_function(wrap_pyfunction!(sfa_fit, m)?)?;
    m.add_function(wrap_pyfunction!(temporal_sfa_fit, m)?)?;
    m.add_function(wrap_pyfunction!(knn_predict, m)?)?;
    m.add_function(wrap_pyfunction!(confusion_matrix, m)?)?;
    Ok(())
}
