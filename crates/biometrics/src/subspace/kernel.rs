//! Kernel functions and Gram matrices shared by FDKECA, KPCA and KECA.
//!
//! Every kernel is evaluated from inner products: for vectors `a`, `b` with Gram entry
//! `g = a.b` and squared norms `|a|^2`, `|b|^2`,
//! - linear: `k = g`;
//! - polynomial: `k = (gamma g + coef0)^degree`;
//! - Gaussian: `k = exp(-(|a|^2 + |b|^2 - 2 g) / (2 sigma^2))` (eq. 2, 10 of the paper), the
//!   squared distance clamped at 0 against round-off.
//!
//! Parameters that depend on the data (`Sigma::Median`, `Gamma::InvDim`) are resolved once
//! on the training set into a [`ResolvedKernel`], which is then used for new samples.

use faer::{Mat, MatRef};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

/// How the polynomial kernel's `gamma` is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Gamma {
    /// A fixed value (> 0).
    Fixed(f64),
    /// `1 / L`, with `L` the length of the vectors compared (for FDKECA's feature vectors,
    /// `L = N`, so `gamma a.b` is a covariance).
    InvDim,
}

/// How the Gaussian kernel's `sigma` is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Sigma {
    /// A fixed value (> 0).
    Fixed(f64),
    /// `scale` times the median of the non-zero pairwise distances of the training vectors
    /// (the paper gives no value; distances between feature vectors grow like `sqrt(N)`, so a
    /// fixed sigma does not transfer between data sets).
    Median {
        /// Multiplier of the median distance (> 0).
        scale: f64,
    },
}

/// A kernel function.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Kernel {
    /// `k(a, b) = a.b`.
    Linear,
    /// `k(a, b) = (gamma a.b + coef0)^degree` (degree 2 in the paper's eigenface analysis).
    Polynomial {
        /// Degree (>= 1).
        degree: u32,
        /// Scale of the inner product.
        gamma: Gamma,
        /// Additive constant (>= 0).
        coef0: f64,
    },
    /// `k(a, b) = exp(-|a - b|^2 / (2 sigma^2))` (the recognition experiments).
    Gaussian {
        /// Bandwidth.
        sigma: Sigma,
    },
}

impl Default for Kernel {
    /// The Gaussian kernel with the median heuristic, as in the paper's experiments.
    fn default() -> Self {
        Kernel::Gaussian {
            sigma: Sigma::Median { scale: 1.0 },
        }
    }
}

/// A kernel whose data-dependent parameters are fixed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ResolvedKernel {
    /// `a.b`.
    Linear,
    /// `(gamma a.b + coef0)^degree`.
    Polynomial {
        /// Degree.
        degree: u32,
        /// Scale.
        gamma: f64,
        /// Constant.
        coef0: f64,
    },
    /// `exp(-|a - b|^2 / (2 sigma^2))`.
    Gaussian {
        /// Bandwidth.
        sigma: f64,
    },
}

impl ResolvedKernel {
    /// The Gaussian bandwidth, if this is a Gaussian kernel.
    pub fn sigma(&self) -> Option<f64> {
        match self {
            ResolvedKernel::Gaussian { sigma } => Some(*sigma),
            _ => None,
        }
    }

    /// Kernel value from an inner product `g` and the two squared norms.
    #[inline]
    pub fn eval(&self, g: f64, na: f64, nb: f64) -> f64 {
        match *self {
            ResolvedKernel::Linear => g,
            ResolvedKernel::Polynomial {
                degree,
                gamma,
                coef0,
            } => (gamma * g + coef0).powi(degree as i32),
            ResolvedKernel::Gaussian { sigma } => {
                let d2 = (na + nb - 2.0 * g).max(0.0);
                (-d2 / (2.0 * sigma * sigma)).exp()
            }
        }
    }
}

/// Checks a user-supplied kernel's fixed parameters.
pub fn validate(kernel: &Kernel) -> Result<()> {
    match *kernel {
        Kernel::Linear => Ok(()),
        Kernel::Polynomial {
            degree,
            gamma,
            coef0,
        } => {
            if degree == 0 {
                return Err(Error::invalid("degree", "must be >= 1"));
            }
            if let Gamma::Fixed(g) = gamma {
                wscg_math::error::ensure_positive("gamma", g)?;
            }
            if !(coef0.is_finite() && coef0 >= 0.0) {
                return Err(Error::invalid(
                    "coef0",
                    format!("must be finite and >= 0, got {coef0}"),
                ));
            }
            Ok(())
        }
        Kernel::Gaussian { sigma } => match sigma {
            Sigma::Fixed(s) => wscg_math::error::ensure_positive("sigma", s),
            Sigma::Median { scale } => wscg_math::error::ensure_positive("sigma_scale", scale),
        },
    }
}

/// Median of the non-zero pairwise distances `sqrt(n_i + n_j - 2 g_ij)`, `i < j`, from a
/// Gram matrix (the mean of the two middle values for an even count, as `numpy.median`).
/// Errors for fewer than two vectors, and when every distance is zero ("all vectors
/// identical").
pub fn median_distance(gram: MatRef<'_, f64>, what: &str) -> Result<f64> {
    let n = gram.nrows();
    if n < 2 {
        return Err(Error::invalid(
            "x",
            format!(
                "n_{what} = {n}: the median heuristic needs at least two {what} (a distance \
                 between them); pass a fixed sigma"
            ),
        ));
    }
    let mut d: Vec<f64> = (0..n)
        .into_par_iter()
        .flat_map_iter(|i| {
            (i + 1..n).map(move |j| (gram[(i, i)] + gram[(j, j)] - 2.0 * gram[(i, j)]).max(0.0))
        })
        .filter(|&v| v > 1e-24 * (1.0 + gram[(0, 0)].abs()))
        .map(f64::sqrt)
        .collect();
    if d.is_empty() {
        return Err(Error::invalid(
            "x",
            format!(
                "all {what} identical (every pairwise distance is 0), so the median \
                 heuristic gives sigma = 0; pass a fixed sigma or vary the data"
            ),
        ));
    }
    let (count, mid) = (d.len(), d.len() / 2);
    let (lower, m, _) = d.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    let m = *m;
    if count % 2 == 1 {
        return Ok(m);
    }
    let below = lower.iter().copied().fold(f64::MIN, f64::max);
    Ok(0.5 * (below + m))
}

/// Fixes the data-dependent parameters of `kernel` on the training Gram matrix `gram`
/// (inner products of the training vectors, each of length `vector_len`; `what` names the
/// vectors in errors, "features" or "samples").
pub fn resolve(
    kernel: &Kernel,
    gram: MatRef<'_, f64>,
    vector_len: usize,
    what: &str,
) -> Result<ResolvedKernel> {
    validate(kernel)?;
    Ok(match *kernel {
        Kernel::Linear => ResolvedKernel::Linear,
        Kernel::Polynomial {
            degree,
            gamma,
            coef0,
        } => ResolvedKernel::Polynomial {
            degree,
            gamma: match gamma {
                Gamma::Fixed(g) => g,
                Gamma::InvDim => 1.0 / vector_len.max(1) as f64,
            },
            coef0,
        },
        Kernel::Gaussian { sigma } => ResolvedKernel::Gaussian {
            sigma: match sigma {
                Sigma::Fixed(s) => s,
                Sigma::Median { scale } => scale * median_distance(gram, what)?,
            },
        },
    })
}

/// The kernel matrix `K_ij = k(v_i, v_j)` from the Gram matrix of the vectors `v_i`.
/// Double-centres the square symmetric kernel `k` in place, `K - 1K/N - K1/N + 1K1/N^2`
/// (scikit-learn's `KernelCenterer`), and returns its column means and overall mean, which
/// centre out-of-sample rows: `k_q - mean(k_q) - col_means + mean`.
pub(crate) fn center_kernel(k: &mut Mat<f64>) -> (Vec<f64>, f64) {
    let n = k.nrows();
    let col_means: Vec<f64> = (0..n)
        .map(|j| k.col_as_slice(j).iter().sum::<f64>() / n as f64)
        .collect();
    let mean = col_means.iter().sum::<f64>() / n as f64;
    for (j, cj) in col_means.iter().enumerate() {
        for (i, ci) in col_means.iter().enumerate() {
            k[(i, j)] += mean - ci - cj;
        }
    }
    (col_means, mean)
}

/// Kernel matrix `K_ij = k(x_i, x_j)` (`n x n`) from the Gram matrix `G = X X^T` of the
/// samples, so that the kernel is evaluated from inner products and squared norms (`G_ii`)
/// without touching the `d`-dimensional samples again.
pub fn kernel_from_gram(gram: MatRef<'_, f64>, k: &ResolvedKernel) -> Mat<f64> {
    let n = gram.nrows();
    let diag: Vec<f64> = (0..n).map(|i| gram[(i, i)]).collect();
    let mut out = Mat::<f64>::zeros(n, n);
    let cols: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|j| {
            (0..n)
                .map(|i| k.eval(gram[(i, j)], diag[i], diag[j]))
                .collect()
        })
        .collect();
    for (j, col) in cols.iter().enumerate() {
        for (i, &v) in col.iter().enumerate() {
            out[(i, j)] = v;
        }
    }
    out
}

/// Cross kernel `K_qi = k(q_q, x_i)` between the rows of `q` (`m x d`) and of `x` (`n x d`).
pub fn cross_kernel(q: MatRef<'_, f64>, x: MatRef<'_, f64>, k: &ResolvedKernel) -> Mat<f64> {
    let g = q * x.transpose();
    let nq: Vec<f64> = (0..q.nrows()).map(|i| row_norm2(q, i)).collect();
    let nx: Vec<f64> = (0..x.nrows()).map(|i| row_norm2(x, i)).collect();
    Mat::from_fn(q.nrows(), x.nrows(), |i, j| k.eval(g[(i, j)], nq[i], nx[j]))
}

/// Squared Euclidean norm of row `i`.
pub fn row_norm2(m: MatRef<'_, f64>, i: usize) -> f64 {
    (0..m.ncols()).map(|j| m[(i, j)] * m[(i, j)]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_match_their_definitions() {
        let x = Mat::from_fn(4, 3, |i, j| (i * 3 + j) as f64 * 0.1 - 0.4);
        let g = &x * x.transpose();
        let rbf = ResolvedKernel::Gaussian { sigma: 0.7 };
        let poly = ResolvedKernel::Polynomial {
            degree: 2,
            gamma: 0.5,
            coef0: 1.0,
        };
        let kr = kernel_from_gram(g.as_ref(), &rbf);
        let kp = kernel_from_gram(g.as_ref(), &poly);
        for i in 0..4 {
            for j in 0..4 {
                let d2: f64 = (0..3).map(|c| (x[(i, c)] - x[(j, c)]).powi(2)).sum();
                assert!((kr[(i, j)] - (-d2 / (2.0 * 0.49)).exp()).abs() < 1e-14);
                let dot: f64 = (0..3).map(|c| x[(i, c)] * x[(j, c)]).sum();
                assert!((kp[(i, j)] - (0.5 * dot + 1.0).powi(2)).abs() < 1e-14);
            }
        }
        let c = cross_kernel(x.as_ref(), x.as_ref(), &rbf);
        assert!((0..4).all(|i| (0..4).all(|j| (c[(i, j)] - kr[(i, j)]).abs() < 1e-14)));
    }

    #[test]
    fn median_heuristic_and_validation() {
        // Points 0, 1, 3 on a line: distances 1, 2, 3 -> median 2.
        let x = Mat::from_fn(3, 1, |i, _| [0.0, 1.0, 3.0][i]);
        let g = &x * x.transpose();
        assert!((median_distance(g.as_ref(), "samples").unwrap() - 2.0).abs() < 1e-12);
        // Points 0, 1, 3, 7: distances 1, 2, 3, 4, 6, 7 -> median (3 + 4) / 2.
        let x4 = Mat::from_fn(4, 1, |i, _| [0.0, 1.0, 3.0, 7.0][i]);
        let g4 = &x4 * x4.transpose();
        assert!((median_distance(g4.as_ref(), "samples").unwrap() - 3.5).abs() < 1e-12);
        let same = Mat::from_fn(3, 2, |_, j| j as f64);
        let gs = &same * same.transpose();
        assert!(median_distance(gs.as_ref(), "samples").is_err());
        // One vector has no distance: the error says how many there are.
        let one = Mat::from_fn(1, 1, |_, _| 2.0);
        let e = median_distance(one.as_ref(), "features").unwrap_err();
        assert!(e.to_string().contains("n_features = 1"), "{e}");
        assert!(validate(&Kernel::Gaussian {
            sigma: Sigma::Fixed(0.0)
        })
        .is_err());
        assert!(validate(&Kernel::Gaussian {
            sigma: Sigma::Fixed(f64::NAN)
        })
        .is_err());
        assert!(validate(&Kernel::Polynomial {
            degree: 0,
            gamma: Gamma::InvDim,
            coef0: 1.0
        })
        .is_err());
        assert!(validate(&Kernel::Polynomial {
            degree: 2,
            gamma: Gamma::Fixed(-1.0),
            coef0: 1.0
        })
        .is_err());
        let r = resolve(
            &Kernel::Polynomial {
                degree: 2,
                gamma: Gamma::InvDim,
                coef0: 1.0,
            },
            g.as_ref(),
            8,
            "samples",
        )
        .unwrap();
        assert_eq!(
            r,
            ResolvedKernel::Polynomial {
                degree: 2,
                gamma: 0.125,
                coef0: 1.0
            }
        );
    }
}
