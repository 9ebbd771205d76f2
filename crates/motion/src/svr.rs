//! ε-support vector regression with an RBF kernel, trained by sequential minimal optimisation
//! with the second-order working-set selection of Fan, Chen and Lin (2005), as in LIBSVM (the
//! library the paper uses to map oscillator states onto sources, §2.2).
//!
//! Dual problem (LIBSVM's formulation with `2l` variables):
//! `min ½ αᵀQα + pᵀα` s.t. `yᵀα = 0`, `0 ≤ α ≤ C`, with `y = (+1…, −1…)`,
//! `p = (ε − z, ε + z)`, `Q_st = y_s y_t K(x_s, x_t)`; the regressor is
//! `f(x) = Σ_i (α_i − α_{i+l}) K(x_i, x) − ρ`.

use wscg_math::error::ensure_finite;
use wscg_math::{Error, Result};

/// Largest training set (the kernel matrix is kept in memory).
pub const MAX_TRAINING: usize = 4000;

/// A trained RBF ε-SVR on 2-D inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Svr {
    /// Support vectors.
    pub support: Vec<[f64; 2]>,
    /// Their coefficients `α_i − α_{i+l}`.
    pub coef: Vec<f64>,
    /// Offset: `f(x) = Σ coef K − rho`.
    pub rho: f64,
    /// RBF parameter: `K(a, b) = exp(−γ ‖a − b‖²)`.
    pub gamma: f64,
    /// SMO iterations used.
    pub iterations: usize,
}

fn rbf(a: [f64; 2], b: [f64; 2], gamma: f64) -> f64 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    (-gamma * (dx * dx + dy * dy)).exp()
}

impl Svr {
    /// Trains on `x` → `y` with box constraint `c`, tube width `eps` and RBF `gamma`
    /// (stopping tolerance 1e-3, LIBSVM's default).
    ///
    /// # Errors
    /// Empty or mismatched data, non-finite values, more than [`MAX_TRAINING`] samples,
    /// non-positive `c` or `gamma`, negative `eps`.
    pub fn fit(x: &[[f64; 2]], y: &[f64], c: f64, eps: f64, gamma: f64) -> Result<Self> {
        Self::fit_tol(x, y, c, eps, gamma, 1e-3)
    }

    /// [`Svr::fit`] with an explicit stopping tolerance on the maximal KKT violation.
    ///
    /// # Errors
    /// As [`Svr::fit`], and a non-positive `tol`.
    pub fn fit_tol(
        x: &[[f64; 2]],
        y: &[f64],
        c: f64,
        eps: f64,
        gamma: f64,
        tol: f64,
    ) -> Result<Self> {
        let l = x.len();
        if l == 0 {
            return Err(Error::Empty("svr training set"));
        }
        if y.len() != l {
            return Err(Error::ShapeMismatch(format!(
                "{l} inputs and {} targets",
                y.len()
            )));
        }
        if l > MAX_TRAINING {
            return Err(Error::LimitExceeded(format!(
                "{l} SVR training samples (max {MAX_TRAINING})"
            )));
        }
        let flat: Vec<f64> = x.iter().flatten().copied().collect();
        ensure_finite("x", &flat)?;
        ensure_finite("y", y)?;
        for (name, v) in [("C", c), ("gamma", gamma), ("tol", tol)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and > 0, got {v}"),
                ));
            }
        }
        if !(eps.is_finite() && eps >= 0.0) {
            return Err(Error::invalid(
                "epsilon",
                format!("must be finite and >= 0, got {eps}"),
            ));
        }
        let kmat: Vec<f64> = (0..l * l).map(|t| rbf(x[t / l], x[t % l], gamma)).collect();
        let n = 2 * l;
        let sign = |t: usize| if t < l { 1.0 } else { -1.0 };
        let kk = |s: usize, t: usize| kmat[(s % l) * l + (t % l)];
        let mut alpha = vec![0.0; n];
        let mut grad: Vec<f64> = (0..n)
            .map(|t| if t < l { eps - y[t] } else { eps + y[t - l] })
            .collect();
        let max_iter = (100 * n).max(10_000_000);
        let mut iter = 0;
        while iter < max_iter {
            // Working set selection 2 (Fan, Chen and Lin 2005).
            let mut gmax = f64::NEG_INFINITY;
            let mut i_sel = usize::MAX;
            for t in 0..n {
                let yt = sign(t);
                if yt > 0.0 {
                    if alpha[t] < c && -grad[t] >= gmax {
                        gmax = -grad[t];
                        i_sel = t;
                    }
                } else if alpha[t] > 0.0 && grad[t] >= gmax {
                    gmax = grad[t];
                    i_sel = t;
                }
            }
            if i_sel == usize::MAX {
                break;
            }
            let i = i_sel;
            let yi = sign(i);
            let mut gmax2 = f64::NEG_INFINITY;
            let mut j_sel = usize::MAX;
            let mut obj_min = f64::INFINITY;
            for t in 0..n {
                let yt = sign(t);
                let qit = yi * yt * kk(i, t);
                if yt > 0.0 {
                    if alpha[t] > 0.0 {
                        let gd = gmax + grad[t];
                        gmax2 = gmax2.max(grad[t]);
                        if gd > 0.0 {
                            let quad = (kk(i, i) + kk(t, t) - 2.0 * yi * qit).max(1e-12);
                            let obj = -(gd * gd) / quad;
                            if obj <= obj_min {
                                obj_min = obj;
                                j_sel = t;
                            }
                        }
                    }
                } else if alpha[t] < c {
                    let gd = gmax - grad[t];
                    gmax2 = gmax2.max(-grad[t]);
                    if gd > 0.0 {
                        let quad = (kk(i, i) + kk(t, t) + 2.0 * yi * qit).max(1e-12);
                        let obj = -(gd * gd) / quad;
                        if obj <= obj_min {
                            obj_min = obj;
                            j_sel = t;
                        }
                    }
                }
            }
            if gmax + gmax2 < tol || j_sel == usize::MAX {
                break;
            }
            let j = j_sel;
            let yj = sign(j);
            let qij = yi * yj * kk(i, j);
            let (old_i, old_j) = (alpha[i], alpha[j]);
            if yi != yj {
                let quad = (kk(i, i) + kk(j, j) + 2.0 * qij).max(1e-12);
                let delta = (-grad[i] - grad[j]) / quad;
                let diff = alpha[i] - alpha[j];
                alpha[i] += delta;
                alpha[j] += delta;
                if diff > 0.0 {
                    if alpha[j] < 0.0 {
                        alpha[j] = 0.0;
                        alpha[i] = diff;
                    }
                } else if alpha[i] < 0.0 {
                    alpha[i] = 0.0;
                    alpha[j] = -diff;
                }
                if diff > 0.0 {
                    if alpha[i] > c {
                        alpha[i] = c;
                        alpha[j] = c - diff;
                    }
                } else if alpha[j] > c {
                    alpha[j] = c;
                    alpha[i] = c + diff;
                }
            } else {
                let quad = (kk(i, i) + kk(j, j) - 2.0 * qij).max(1e-12);
                let delta = (grad[i] - grad[j]) / quad;
                let sum = alpha[i] + alpha[j];
                alpha[i] -= delta;
                alpha[j] += delta;
                if sum > c {
                    if alpha[i] > c {
                        alpha[i] = c;
                        alpha[j] = sum - c;
                    }
                } else if alpha[j] < 0.0 {
                    alpha[j] = 0.0;
                    alpha[i] = sum;
                }
                if sum > c {
                    if alpha[j] > c {
                        alpha[j] = c;
                        alpha[i] = sum - c;
                    }
                } else if alpha[i] < 0.0 {
                    alpha[i] = 0.0;
                    alpha[j] = sum;
                }
            }
            let (di, dj) = (alpha[i] - old_i, alpha[j] - old_j);
            for (t, g) in grad.iter_mut().enumerate() {
                let yt = sign(t);
                *g += yt * (yi * kk(t, i) * di + yj * kk(t, j) * dj);
            }
            iter += 1;
        }
        // ρ from the free variables (or the middle of the feasible interval).
        let (mut ub, mut lb, mut sum_free, mut n_free) =
            (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
        for t in 0..n {
            let yg = sign(t) * grad[t];
            if alpha[t] >= c {
                if sign(t) < 0.0 {
                    ub = ub.min(yg);
                } else {
                    lb = lb.max(yg);
                }
            } else if alpha[t] <= 0.0 {
                if sign(t) > 0.0 {
                    ub = ub.min(yg);
                } else {
                    lb = lb.max(yg);
                }
            } else {
                n_free += 1;
                sum_free += yg;
            }
        }
        let rho = if n_free > 0 {
            sum_free / n_free as f64
        } else {
            0.5 * (ub + lb)
        };
        let mut support = Vec::new();
        let mut coef = Vec::new();
        for t in 0..l {
            let cf = alpha[t] - alpha[t + l];
            if cf != 0.0 {
                support.push(x[t]);
                coef.push(cf);
            }
        }
        Ok(Self {
            support,
            coef,
            rho,
            gamma,
            iterations: iter,
        })
    }

    /// `f(x)`.
    pub fn predict(&self, x: [f64; 2]) -> f64 {
        let mut acc = -self.rho;
        for (sv, c) in self.support.iter().zip(&self.coef) {
            acc += c * rbf(*sv, x, self.gamma);
        }
        acc
    }

    /// Number of support vectors.
    pub fn n_support(&self) -> usize {
        self.support.len()
    }
}
