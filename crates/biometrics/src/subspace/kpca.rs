//! Kernel PCA baseline (paper 01, section 2.2; Schoelkopf, Smola and Mueller 1998).
//!
//! `K_ij = k(x_i, x_j)` (`N x N`) is centred, `Kc = H K H` with `H = I - 11'/N`, and
//! decomposed `Kc = E D E'`; the top `l` eigenpairs with `lambda > 1e-12 lambda_1` are kept.
//! Training embedding `Z = E_l D_l^{1/2}` (eq. 3). A new sample `x` with kernel row
//! `k_x = [k(x, x_i)]_i` is centred as
//! `k_x - mean(k_x) 1 - K 1/N + (1'K1/N^2) 1` and projected `z = D_l^{-1/2} E_l' k~_x`,
//! which is what scikit-learn's `KernelPCA.transform` computes.

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::{dense, Error, Result};

use super::kernel::{
    center_kernel, cross_kernel, kernel_from_gram, resolve, Kernel, ResolvedKernel,
};
use super::{check_components, check_data, check_query, from_columns, Projector};

/// Training rows, the resolved kernel and the uncentred kernel matrix of a sample-kernel
/// method (KPCA, KECA).
pub(crate) struct SampleKernel {
    pub rows: Vec<Vec<f64>>,
    pub kernel: ResolvedKernel,
    pub k: Mat<f64>,
}

/// Builds the `N x N` kernel of the rows of `x`, resolving data-dependent parameters
/// (median of the pairwise sample distances; `gamma = 1/d`).
pub(crate) fn sample_kernel(x: MatRef<'_, f64>, kernel: &Kernel) -> Result<SampleKernel> {
    check_data("x", x, 2)?;
    let g = x * x.transpose();
    let n = x.nrows();
    let g = Mat::from_fn(n, n, |i, j| 0.5 * (g[(i, j)] + g[(j, i)]));
    let kernel = resolve(kernel, g.as_ref(), x.ncols(), "samples")?;
    let k = kernel_from_gram(g.as_ref(), &kernel);
    let rows = (0..n)
        .map(|i| (0..x.ncols()).map(|j| x[(i, j)]).collect())
        .collect();
    Ok(SampleKernel { rows, kernel, k })
}

/// The training rows as an `N x d` matrix.
pub(crate) fn rows_matrix(rows: &[Vec<f64>]) -> Mat<f64> {
    let d = rows.first().map_or(0, |r| r.len());
    Mat::from_fn(rows.len(), d, |i, j| rows[i][j])
}

/// A fitted kernel PCA.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KernelPca {
    /// Training rows (needed for out-of-sample kernels).
    pub train: Vec<Vec<f64>>,
    /// Kernel with resolved parameters.
    pub kernel: ResolvedKernel,
    /// Column means of the uncentred training kernel, `K 1 / N`.
    pub k_col_means: Vec<f64>,
    /// `1' K 1 / N^2`.
    pub k_mean: f64,
    /// Eigenvalues of the centred kernel, kept components, descending.
    pub eigenvalues: Vec<f64>,
    /// Eigenvectors `e_i` (length `N`) of the kept components.
    pub eigenvectors: Vec<Vec<f64>>,
}

impl KernelPca {
    /// Fits KPCA with `n_components` components (default: every eigenvalue above
    /// `1e-12 lambda_1`).
    ///
    /// Errors: bad data or kernel, more components than the centred kernel's numerical rank.
    pub fn fit(x: MatRef<'_, f64>, kernel: &Kernel, n_components: Option<usize>) -> Result<Self> {
        let sk = sample_kernel(x, kernel)?;
        let n = x.nrows();
        let mut kc = sk.k;
        let (col_means, mean) = center_kernel(&mut kc);
        // With a requested l only the top l eigenpairs are computed (as scikit-learn's
        // "dense" solver does); otherwise all, to find the numerical rank.
        let e = match n_components {
            Some(l) if l >= 1 && l <= n => dense::eigh_largest(kc.as_ref(), l)?,
            _ => dense::eigh_largest(kc.as_ref(), n)?,
        };
        let lmax = e.values.first().copied().unwrap_or(0.0);
        let available = e
            .values
            .iter()
            .take_while(|&&v| v > 1e-12 * lmax && v > 0.0)
            .count();
        if available == 0 {
            return Err(Error::invalid(
                "x",
                "the centred kernel is zero (all samples identical)",
            ));
        }
        let l = check_components(n_components, available)?;
        let idx: Vec<usize> = (0..l).collect();
        Ok(Self {
            train: sk.rows,
            kernel: sk.kernel,
            k_col_means: col_means,
            k_mean: mean,
            eigenvalues: idx.iter().map(|&i| e.values[i]).collect(),
            eigenvectors: super::columns(e.vectors.as_ref(), &idx),
        })
    }

    /// The same model with its first `l` components (no refit).
    pub fn truncated(&self, l: usize) -> Result<Self> {
        let l = check_components(Some(l), self.eigenvalues.len())?;
        let mut m = self.clone();
        m.eigenvalues.truncate(l);
        m.eigenvectors.truncate(l);
        Ok(m)
    }

    /// Training embedding `E_l D_l^{1/2}` (`N x l`).
    pub fn embedding(&self) -> Mat<f64> {
        Mat::from_fn(self.train.len(), self.eigenvalues.len(), |i, j| {
            self.eigenvectors[j][i] * self.eigenvalues[j].sqrt()
        })
    }

    /// Centres rows of a cross kernel `k(q, x_i)` against the training kernel.
    fn center(&self, kq: &mut Mat<f64>) {
        let n = self.train.len();
        for i in 0..kq.nrows() {
            let row_mean = (0..n).map(|j| kq[(i, j)]).sum::<f64>() / n as f64;
            for j in 0..n {
                kq[(i, j)] += self.k_mean - row_mean - self.k_col_means[j];
            }
        }
    }
}

impl Projector for KernelPca {
    fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        let d = self.train[0].len();
        check_query(x, d)?;
        let mut kq = cross_kernel(x, rows_matrix(&self.train).as_ref(), &self.kernel);
        self.center(&mut kq);
        let n = self.train.len();
        let alphas = Mat::from_fn(n, self.eigenvalues.len(), |i, j| {
            self.eigenvectors[j][i] / self.eigenvalues[j].sqrt()
        });
        Ok(kq * alphas)
    }
    fn n_components(&self) -> usize {
        self.eigenvalues.len()
    }
    fn input_dim(&self) -> usize {
        self.train[0].len()
    }
}

/// `E_l` of a list of eigenvectors as an `N x l` matrix.
pub(crate) fn vectors_matrix(v: &[Vec<f64>]) -> Mat<f64> {
    from_columns(v.first().map_or(0, |c| c.len()), v)
}
