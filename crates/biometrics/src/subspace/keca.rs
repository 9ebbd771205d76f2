//! KECA baseline (paper 01, section 2.3; Jenssen, "Kernel entropy component analysis",
//! IEEE TPAMI 32(5), 2010).
//!
//! The **uncentred** kernel `K = E D E'` (`N x N`) is decomposed; each eigenpair contributes
//! `psi_i = lambda_i (1' e_i)^2` to the Renyi entropy estimate `V = 1'K1 / N^2` (eq. 8, 9;
//! the paper's eq. 9 swaps the roles of lambda and alpha, we follow Jenssen). All `N`
//! eigenpairs are ranked by `psi` and the top `l` kept. Training embedding
//! `Phi_eca = D_l^{1/2} E_l'`; a new sample with kernel row `k_x` maps to
//! `D_l^{-1/2} E_l' k_x`.

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::{dense, Error, Result};

use super::kernel::{cross_kernel, Kernel, ResolvedKernel};
use super::kpca::{rows_matrix, sample_kernel, vectors_matrix};
use super::{check_components, check_query, order_desc, Projector};

/// A fitted KECA.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Keca {
    /// Training rows.
    pub train: Vec<Vec<f64>>,
    /// Kernel with resolved parameters.
    pub kernel: ResolvedKernel,
    /// Eigenvalues of the kept components, in entropy order.
    pub eigenvalues: Vec<f64>,
    /// Entropy terms `psi` of the kept components.
    pub entropy_terms: Vec<f64>,
    /// Eigenvectors (length `N`) of the kept components.
    pub eigenvectors: Vec<Vec<f64>>,
    /// `1' K 1`.
    pub kernel_sum: f64,
}

impl Keca {
    /// Fits KECA with `n_components` components (default: every component with a positive
    /// entropy term).
    ///
    /// Errors: bad data or kernel; more components than have a positive eigenvalue.
    pub fn fit(x: MatRef<'_, f64>, kernel: &Kernel, n_components: Option<usize>) -> Result<Self> {
        let sk = sample_kernel(x, kernel)?;
        let n = x.nrows();
        let e = dense::eigh(sk.k.as_ref())?;
        let (lambda, psi) = super::entropy_terms(&e);
        let lmax = lambda.iter().cloned().fold(0.0, f64::max);
        let order: Vec<usize> = order_desc(&psi, &lambda)
            .into_iter()
            .filter(|&i| lambda[i] > 1e-12 * lmax)
            .collect();
        if order.is_empty() {
            return Err(Error::invalid("x", "the kernel matrix is zero"));
        }
        let default_l = order.iter().filter(|&&i| psi[i] > 0.0).count().max(1);
        let l = match n_components {
            None => default_l,
            some => check_components(some, order.len())?,
        };
        let keep = &order[..l];
        let kernel_sum = (0..n)
            .map(|i| (0..n).map(|j| sk.k[(i, j)]).sum::<f64>())
            .sum();
        Ok(Self {
            train: sk.rows,
            kernel: sk.kernel,
            eigenvalues: keep.iter().map(|&i| lambda[i]).collect(),
            entropy_terms: keep.iter().map(|&i| psi[i]).collect(),
            eigenvectors: super::columns(e.vectors.as_ref(), keep),
            kernel_sum,
        })
    }

    /// The same model with its first `l` components (no refit).
    pub fn truncated(&self, l: usize) -> Result<Self> {
        let l = check_components(Some(l), self.eigenvalues.len())?;
        let mut m = self.clone();
        m.eigenvalues.truncate(l);
        m.eigenvectors.truncate(l);
        m.entropy_terms.truncate(l);
        Ok(m)
    }

    /// Training embedding `(D_l^{1/2} E_l')'` (`N x l`).
    pub fn embedding(&self) -> Mat<f64> {
        Mat::from_fn(self.train.len(), self.eigenvalues.len(), |i, j| {
            self.eigenvectors[j][i] * self.eigenvalues[j].sqrt()
        })
    }

    /// The Renyi entropy estimate `V = 1'K1 / N^2` (eq. 8).
    pub fn renyi_entropy_estimate(&self) -> f64 {
        let n = self.train.len() as f64;
        self.kernel_sum / (n * n)
    }
}

impl Projector for Keca {
    fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        check_query(x, self.train[0].len())?;
        let kq = cross_kernel(x, rows_matrix(&self.train).as_ref(), &self.kernel);
        let mut e = vectors_matrix(&self.eigenvectors);
        for (j, &l) in self.eigenvalues.iter().enumerate() {
            let s = 1.0 / l.sqrt();
            for i in 0..e.nrows() {
                e[(i, j)] *= s;
            }
        }
        Ok(kq * e)
    }
    fn n_components(&self) -> usize {
        self.eigenvalues.len()
    }
    fn input_dim(&self) -> usize {
        self.train[0].len()
    }
}
