//! Paper 01: FDKECA and the subspace baselines it is compared with.
//!
//! - [`Fdkeca`]: the paper's method (section 3): a `d x d` kernel between pixel columns,
//!   eigenvectors ordered by their Renyi-entropy contribution, a linear projection.
//! - [`Pca`] (section 2.1), [`KernelPca`] (section 2.2, Schoelkopf et al. 1998) and
//!   [`Keca`] (section 2.3, Jenssen 2010): the baselines of Table 1 and Fig. 7.
//! - [`classify`]: the supervised "spectral clustering" pipeline of section 5 (project, then
//!   nearest neighbour), the accuracy-versus-dimension protocol of section 6 and a validated
//!   variant that chooses the dimension by cross-validation on the training set.
//!
//! All models take data with one sample per row (`n x d`).

use faer::{Mat, MatRef};
use wscg_math::{Error, Result};

pub mod classify;
pub mod fdkeca;
pub mod keca;
pub mod kernel;
pub mod kpca;
pub mod model;
pub mod pca;
pub mod protocol;
pub mod recognizer;
pub mod serde_mat;

pub use classify::{
    accuracy, accuracy_curve, best_dimension, nearest_neighbours, nn_classify, select_dimension_cv,
    Metric, Neighbour, SubspaceClassifier,
};
pub use fdkeca::{Fdkeca, FdkecaParams, Ordering};
pub use keca::Keca;
pub use kernel::{Gamma, Kernel, ResolvedKernel, Sigma};
pub use kpca::KernelPca;
pub use model::{Method, Model};
pub use pca::Pca;
pub use protocol::{evaluate, ProtocolParams, ProtocolResult};
pub use recognizer::{Identification, Recognizer};

/// A fitted linear or kernel projection `R^d -> R^l`.
pub trait Projector: Sync {
    /// Projects the rows of `x` (`m x d`) to `m x l`.
    fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>>;
    /// Number of output components `l`.
    fn n_components(&self) -> usize;
    /// Input dimension `d`.
    fn input_dim(&self) -> usize;
}

/// Validates a data matrix: finite, at least `min_rows` rows and one column.
pub fn check_data(name: &'static str, x: MatRef<'_, f64>, min_rows: usize) -> Result<()> {
    if x.ncols() == 0 {
        return Err(Error::invalid(name, "has no columns (d = 0)"));
    }
    if x.nrows() < min_rows {
        return Err(Error::invalid(
            name,
            format!(
                "needs at least {min_rows} rows (samples), got {}",
                x.nrows()
            ),
        ));
    }
    wscg_math::dense::check_matrix(name, x)
}

/// Checks that query rows have the training dimension `d` and are finite.
pub fn check_query(x: MatRef<'_, f64>, d: usize) -> Result<()> {
    if x.ncols() != d {
        return Err(Error::ShapeMismatch(format!(
            "x has {} columns but the model was fitted on d = {d}",
            x.ncols()
        )));
    }
    if x.nrows() == 0 {
        return Ok(());
    }
    wscg_math::dense::check_matrix("x", x)
}

/// Column means of `x`.
pub fn column_means(x: MatRef<'_, f64>) -> Vec<f64> {
    use rayon::prelude::*;
    let n = x.nrows() as f64;
    (0..x.ncols())
        .into_par_iter()
        .map(|j| x.col(j).iter().sum::<f64>() / n)
        .collect()
}

/// `x - 1 mean'`.
pub fn subtract_mean(x: MatRef<'_, f64>, mean: &[f64]) -> Mat<f64> {
    use rayon::prelude::*;
    let mut out = Mat::<f64>::zeros(x.nrows(), x.ncols());
    out.par_col_iter_mut().enumerate().for_each(|(j, c)| {
        for (o, v) in c.iter_mut().zip(x.col(j).iter()) {
            *o = v - mean[j];
        }
    });
    out
}

/// Checks a requested number of components against what is available.
pub fn check_components(requested: Option<usize>, available: usize) -> Result<usize> {
    match requested {
        None => Ok(available),
        Some(0) => Err(Error::invalid("n_components", "must be >= 1")),
        Some(l) if l > available => Err(Error::invalid(
            "n_components",
            format!("{l} requested but only {available} components are available"),
        )),
        Some(l) => Ok(l),
    }
}

/// The rows `idx` of `x`, in that order (a train/test split, a cross-validation fold).
pub fn select_rows(x: MatRef<'_, f64>, idx: &[usize]) -> Mat<f64> {
    Mat::from_fn(idx.len(), x.ncols(), |i, j| x[(idx[i], j)])
}

/// Columns of `m` as vectors.
pub fn columns(m: MatRef<'_, f64>, idx: &[usize]) -> Vec<Vec<f64>> {
    idx.iter()
        .map(|&j| (0..m.nrows()).map(|i| m[(i, j)]).collect())
        .collect()
}

/// A `rows x cols` matrix whose columns are `cols_data` (each of length `rows`).
pub fn from_columns(rows: usize, cols_data: &[Vec<f64>]) -> Mat<f64> {
    Mat::from_fn(rows, cols_data.len(), |i, j| cols_data[j][i])
}

/// Indices sorted by `key` descending, ties broken by `tie` descending, then by index.
pub fn order_desc(key: &[f64], tie: &[f64]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..key.len()).collect();
    idx.sort_by(|&a, &b| {
        key[b]
            .total_cmp(&key[a])
            .then(tie[b].total_cmp(&tie[a]))
            .then(a.cmp(&b))
    });
    idx
}

/// Pre-image of projected rows under orthonormal axes: `x = mean + sum_j y_j s_j a_j`, with
/// `s_j = scale[j]` (1 when `scale` is `None`). Errors when `y` is not `m x axes.len()`.
pub fn reconstruct(
    mean: &[f64],
    axes: &[Vec<f64>],
    scale: Option<&[f64]>,
    y: MatRef<'_, f64>,
) -> Result<Mat<f64>> {
    if y.ncols() != axes.len() {
        return Err(Error::ShapeMismatch(format!(
            "y has {} columns but the model has {} components",
            y.ncols(),
            axes.len()
        )));
    }
    wscg_math::dense::check_matrix("y", y)?;
    let d = mean.len();
    let a = Mat::from_fn(axes.len(), d, |j, t| {
        axes[j][t] * scale.map_or(1.0, |s| s[j])
    });
    let mut x = y * a;
    for i in 0..x.nrows() {
        for (t, m) in mean.iter().enumerate() {
            x[(i, t)] += m;
        }
    }
    Ok(x)
}

/// Eigenvalues clipped at 0 and the Renyi-entropy terms `psi_i = lambda_i (1' e_i)^2` of a
/// symmetric eigendecomposition (eq. 9; KECA over samples, FDKECA over features).
pub fn entropy_terms(e: &wscg_math::dense::SymEigen) -> (Vec<f64>, Vec<f64>) {
    let n = e.vectors.nrows();
    let lambda: Vec<f64> = e.values.iter().map(|&v| v.max(0.0)).collect();
    let psi = (0..e.vectors.ncols())
        .map(|i| {
            let s: f64 = (0..n).map(|r| e.vectors[(r, i)]).sum();
            lambda[i] * s * s
        })
        .collect();
    (lambda, psi)
}
