//! Second-order response surfaces fitted by ordinary least squares, with the adequacy measures
//! and the canonical analysis of paper 07 (§5.2, Tables 2 and 3, Fig. 5a–b).
//!
//! Model, for `k` coded factors `x_1 … x_k` (paper: x1 = flake radius, x2 = flake density):
//!
//! ```text
//! y = b0 + Σ_i b_i x_i + Σ_i b_ii x_i² [+ Σ_{i<j} b_ij x_i x_j] + e
//! ```
//!
//! Term order (and [`RsmFit::names`]): `b0`, the linear terms `b1 … bk`, the pure quadratic
//! terms `b11 … bkk`, then, when `interaction` is set, the cross terms `b12, b13, …, b1k, b23, …`
//! (i < j, lexicographic). Indices are 1-based like the paper's; for k ≥ 10 the two indices of a
//! second-order term are separated by an underscore (`b3_12`). The paper's Table 2 model is the
//! two-factor model without interaction: `b0, b1, b2, b11, b22`.
//!
//! Fit (design matrix `X`, `n` runs x `p` terms, thin SVD `X = U S Vᵀ`):
//!
//! ```text
//! b      = V S⁻¹ Uᵀ y                     SSE = Σ e_i²,  e = y − X b
//! σ²     = SSE / (n − p)                  SST = Σ (y_i − ȳ)²
//! Cov(b) = σ² (XᵀX)⁻¹ = σ² V S⁻² Vᵀ       se_j = sqrt(Cov_jj),  t_j = b_j / se_j
//! p_j    = P(|T_{n−p}| ≥ |t_j|)           (two-sided)
//! R²     = 1 − SSE/SST                    R²_adj = 1 − (1 − R²)(n − 1)/(n − p)
//! h_ii   = Σ_j U_ij²  (leverages)         PRESS = Σ (e_i / (1 − h_ii))²
//! R²_pred = 1 − PRESS/SST
//! ```
//!
//! PRESS is the sum of squared leave-one-out prediction errors; the closed form above equals a
//! refit loop without refitting. Canonical analysis: with `b = (b1 … bk)` and the symmetric
//! matrix `B` (`B_ii = b_ii`, `B_ij = B_ji = b_ij / 2`, zero off the diagonal without
//! interaction), the stationary point is `x_s = −½ B⁻¹ b` and the eigenvalues of `B` classify it
//! (all > 0: minimum, all < 0: maximum, mixed: saddle). For paper 07's 0 (identical) … 10
//! (different) similarity score a minimum is the best-matching microstructure.
//!
//! The paper fits the panel means (13 values per condition); its significance column is not
//! reproducible from 13 means, so [`fit_quadratic_blocked`] offers the fit on all individual
//! scores with the subject as a blocking factor too (the paper's section 5.2 does not say which
//! data its p-values come from, so both fits are offered).

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use wscg_math::error::ensure_finite;
use wscg_math::{Error, Result};

use crate::dist::t_two_sided_p;

/// Singular values below `RCOND · s_max` make a design singular (rank-deficient).
pub const RCOND: f64 = 1e-10;

/// A fitted second-order response surface: coefficients with their tests, adequacy measures
/// (paper 07 Tables 2 and 3) and the canonical analysis of the fitted quadric.
#[derive(Debug, Clone, PartialEq)]
pub struct RsmFit {
    /// Number of factors `k`.
    pub k: usize,
    /// Whether the cross terms `b_ij x_i x_j` are in the model.
    pub interaction: bool,
    /// Number of subjects of a blocked fit ([`fit_quadratic_blocked`]); 1 for [`fit_quadratic`].
    pub n_blocks: usize,
    /// Coefficients in the documented term order; a blocked fit appends the `n_blocks − 1`
    /// subject effects (`subject0`, …).
    pub coef: Vec<f64>,
    /// Term names, same order as `coef` (`b0`, `b1`, `b2`, `b11`, `b22`, `b12`, …).
    pub names: Vec<String>,
    /// Standard errors `sqrt(σ² (XᵀX)⁻¹_jj)`.
    pub se: Vec<f64>,
    /// t statistics `coef / se` (±∞ or NaN when the fit is exact, `sse = 0`).
    pub t: Vec<f64>,
    /// Two-sided p-values of the t statistics with `df_resid` degrees of freedom.
    pub p: Vec<f64>,
    /// Coefficient of determination `1 − SSE/SST`.
    pub r2: f64,
    /// Adjusted R²: `1 − (1 − R²)(n − 1)/df_resid`.
    pub r2_adj: f64,
    /// Predicted R² (cross-validated): `1 − PRESS/SST`; −∞ when a run has leverage 1.
    pub r2_pred: f64,
    /// Predicted residual sum of squares `Σ (e_i/(1 − h_ii))²`; +∞ when a run has leverage 1.
    pub press: f64,
    /// Residual sum of squares.
    pub sse: f64,
    /// Total (centred) sum of squares of the responses.
    pub sst: f64,
    /// Residual degrees of freedom `n − p` (p counts the block columns of a blocked fit).
    pub df_resid: usize,
    /// Residual variance estimate `SSE / df_resid`.
    pub sigma2: f64,
    /// Leverages `h_ii` (diagonal of the hat matrix), one per observation.
    pub leverage: Vec<f64>,
    /// Residuals `y − ŷ`, one per observation.
    pub residuals: Vec<f64>,
    /// Fitted values `ŷ`, one per observation.
    pub fitted: Vec<f64>,
    /// Stationary point `x_s = −½ B⁻¹ b` in coded units, `None` when `B` is (numerically)
    /// singular.
    pub stationary: Option<Vec<f64>>,
    /// Predicted response at the stationary point, `b0 + ½ x_sᵀ b` (population average for a
    /// blocked fit).
    pub y_stationary: Option<f64>,
    /// Eigenvalues of `B`, ascending.
    pub canonical_eigs: Vec<f64>,
    /// Unit eigenvectors of `B` (columns, same order as `canonical_eigs`): the canonical axes.
    pub canonical_axes: DMatrix<f64>,
}

impl RsmFit {
    /// Coefficient by term name (e.g. `"b11"`).
    pub fn coef_of(&self, name: &str) -> Option<f64> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.coef[i])
    }

    /// The symmetric second-order matrix `B` (`B_ii = b_ii`, `B_ij = b_ij / 2`).
    pub fn b_matrix(&self) -> DMatrix<f64> {
        second_order_matrix(&self.coef, self.k, self.interaction)
    }
}

/// Number of model terms `p = 1 + 2k (+ k(k−1)/2 with interaction)`.
pub fn n_terms(k: usize, interaction: bool) -> usize {
    1 + 2 * k
        + if interaction {
            k * (k.saturating_sub(1)) / 2
        } else {
            0
        }
}

/// Term names in the documented order (`b0`, `b1`, …, `b11`, …, `b12`, …).
pub fn term_names(k: usize, interaction: bool) -> Vec<String> {
    let pair = |i: usize, j: usize| {
        if k < 10 {
            format!("b{}{}", i + 1, j + 1)
        } else {
            format!("b{}_{}", i + 1, j + 1)
        }
    };
    let mut names = vec!["b0".to_string()];
    names.extend((0..k).map(|i| format!("b{}", i + 1)));
    names.extend((0..k).map(|i| pair(i, i)));
    if interaction {
        for i in 0..k {
            for j in i + 1..k {
                names.push(pair(i, j));
            }
        }
    }
    names
}

/// Model matrix of the second-order model: one row per run, columns in the documented term
/// order (`1, x_1 … x_k, x_1² … x_k², x_1x_2 …`).
///
/// # Errors
/// [`Error::Empty`] for no runs or no factors; [`Error::NonFinite`] for NaN/∞ in `x`;
/// [`Error::InvalidArgument`] naming `x` when a model entry (a value, square or cross
/// product) exceeds 1e150 in magnitude, beyond what a least-squares fit sums without overflow.
pub fn quadratic_design(x: &DMatrix<f64>, interaction: bool) -> Result<DMatrix<f64>> {
    if x.nrows() == 0 {
        return Err(Error::Empty("x (runs)"));
    }
    if x.ncols() == 0 {
        return Err(Error::Empty("x (factors)"));
    }
    ensure_finite("x", x.as_slice())?;
    let design = design_unchecked(x, interaction);
    // The least-squares fit sums squares of the model columns: entries above 1e150 (factor
    // values above about 1e75) would overflow to infinity there, and the SVD never converges
    // on infinities.
    if let Some(v) = design
        .iter()
        .find(|v| v.is_nan() || v.abs() > MAX_MODEL_ENTRY)
    {
        return Err(Error::invalid(
            "x",
            format!(
                "a squared or cross term is {v:e}, beyond the {MAX_MODEL_ENTRY:e} a least-squares \
                 fit can sum without overflow; code the factors (for example to [-1, 1])"
            ),
        ));
    }
    Ok(design)
}

/// Largest magnitude of a model-matrix entry (a factor value, its square or a cross product).
const MAX_MODEL_ENTRY: f64 = 1e150;

fn design_unchecked(x: &DMatrix<f64>, interaction: bool) -> DMatrix<f64> {
    let (n, k) = x.shape();
    let p = n_terms(k, interaction);
    DMatrix::from_fn(n, p, |r, c| {
        if c == 0 {
            1.0
        } else if c <= k {
            x[(r, c - 1)]
        } else if c <= 2 * k {
            let i = c - k - 1;
            x[(r, i)] * x[(r, i)]
        } else {
            let (i, j) = cross_pair(k, c - 2 * k - 1);
            x[(r, i)] * x[(r, j)]
        }
    })
}

/// The `m`-th (0-based) pair `(i, j)`, `i < j`, in lexicographic order.
fn cross_pair(k: usize, mut m: usize) -> (usize, usize) {
    for i in 0..k {
        let row = k - 1 - i;
        if m < row {
            return (i, i + 1 + m);
        }
        m -= row;
    }
    unreachable!("cross term index beyond k(k-1)/2")
}

fn second_order_matrix(coef: &[f64], k: usize, interaction: bool) -> DMatrix<f64> {
    let mut b = DMatrix::<f64>::zeros(k, k);
    for i in 0..k {
        b[(i, i)] = coef[1 + k + i];
    }
    if interaction {
        let mut c = 1 + 2 * k;
        for i in 0..k {
            for j in i + 1..k {
                b[(i, j)] = 0.5 * coef[c];
                b[(j, i)] = 0.5 * coef[c];
                c += 1;
            }
        }
    }
    b
}

/// Fits the second-order model to `y` over the coded runs `x` (paper 07 §5.2: the panel means of
/// one condition over the 13 CCI runs).
///
/// * `x`: runs x k coded factor levels (e.g. from [`crate::ccd::ccd`]).
/// * `y`: one response per run.
/// * `interaction`: include the cross terms `b_ij x_i x_j` (the paper reports none).
///
/// Needs more runs than terms (at least one residual degree of freedom, for σ², the t-tests and
/// PRESS).
///
/// # Errors
/// [`Error::ShapeMismatch`] when `y.len() != x.nrows()`; [`Error::Empty`] for no runs or
/// factors; [`Error::NonFinite`] for NaN/∞ in `x` or `y`; [`Error::InvalidArgument`] when there
/// are not more runs than terms, when the design is singular (rank-deficient, e.g. all runs
/// identical or a factor held constant), or when all responses are equal (SST = 0).
pub fn fit_quadratic(x: &DMatrix<f64>, y: &[f64], interaction: bool) -> Result<RsmFit> {
    let design = quadratic_design(x, interaction)?;
    check_response(y, x.nrows())?;
    let names = term_names(x.ncols(), interaction);
    ols(&design, y, names, x.ncols(), interaction, 1)
}

/// Fits the second-order model to every individual score, with the subject as a blocking factor
/// (the paper's significance levels, section 5.2, Table 2, look like they come from the 338
/// individual scores rather than the 13 panel means; with [`fit_quadratic`] both fits are on
/// offer).
///
/// * `x`: stimuli x k coded runs (the design; one row per stimulus).
/// * `scores`: subjects x stimuli responses (row `s`, column `i`: subject `s`, stimulus `i`).
///
/// Observations are stacked subject-major (observation `s · n_stimuli + i`), which is the order
/// of [`RsmFit::leverage`], [`RsmFit::residuals`] and [`RsmFit::fitted`]. The model matrix is the
/// second-order model followed by `S − 1` sum-coded (effect-coded) subject columns: column `s`
/// is +1 for subject `s`, −1 for the last subject, 0 otherwise, named `subject0`, `subject1`, ….
/// With this coding and a complete layout the model coefficients equal those of
/// [`fit_quadratic`] on the panel means (the subject columns are orthogonal to the model columns)
/// while the residual variance, degrees of freedom `S·N − p − (S − 1)`, standard errors and
/// p-values come from all observations. R², PRESS and leverages are those of the
/// observation-level regression (subject effects included).
///
/// # Errors
/// As [`fit_quadratic`], plus [`Error::ShapeMismatch`] when `scores.ncols() != x.nrows()` and
/// [`Error::Empty`] for no subjects.
pub fn fit_quadratic_blocked(
    x: &DMatrix<f64>,
    scores: &DMatrix<f64>,
    interaction: bool,
) -> Result<RsmFit> {
    let base = quadratic_design(x, interaction)?;
    let (n_sub, n_stim) = scores.shape();
    if n_sub == 0 {
        return Err(Error::Empty("scores (subjects)"));
    }
    if n_stim != x.nrows() {
        return Err(Error::ShapeMismatch(format!(
            "`scores` has {n_stim} columns (stimuli) but `x` has {} rows (runs)",
            x.nrows()
        )));
    }
    ensure_finite("scores", scores.as_slice())?;
    let p0 = base.ncols();
    let n_obs = n_sub * n_stim;
    let p = p0 + n_sub - 1;
    let mut design = DMatrix::<f64>::zeros(n_obs, p);
    let mut y = Vec::with_capacity(n_obs);
    for s in 0..n_sub {
        for i in 0..n_stim {
            let r = s * n_stim + i;
            for c in 0..p0 {
                design[(r, c)] = base[(i, c)];
            }
            for b in 0..n_sub - 1 {
                design[(r, p0 + b)] = if s == b {
                    1.0
                } else if s == n_sub - 1 {
                    -1.0
                } else {
                    0.0
                };
            }
            y.push(scores[(s, i)]);
        }
    }
    check_response(&y, n_obs)?;
    let mut names = term_names(x.ncols(), interaction);
    names.extend((0..n_sub - 1).map(|s| format!("subject{s}")));
    ols(&design, &y, names, x.ncols(), interaction, n_sub)
}

/// Predicted responses of a fitted surface at coded points `x` (points x k). For a blocked fit
/// this is the population-average surface (subject effects sum to zero).
///
/// # Errors
/// [`Error::ShapeMismatch`] when `x.ncols() != fit.k`; [`Error::NonFinite`] for NaN/∞ in `x`.
pub fn predict(fit: &RsmFit, x: &DMatrix<f64>) -> Result<Vec<f64>> {
    if x.ncols() != fit.k {
        return Err(Error::ShapeMismatch(format!(
            "`x` has {} columns but the surface was fitted on {} factors",
            x.ncols(),
            fit.k
        )));
    }
    ensure_finite("x", x.as_slice())?;
    let p = n_terms(fit.k, fit.interaction);
    if fit.coef.len() < p {
        return Err(Error::ShapeMismatch(format!(
            "the fit holds {} coefficients, fewer than the {p} terms of its model",
            fit.coef.len()
        )));
    }
    let d = design_unchecked(x, fit.interaction);
    let b = DVector::from_column_slice(&fit.coef[..p]);
    Ok((d * b).iter().copied().collect())
}

fn check_response(y: &[f64], n: usize) -> Result<()> {
    if y.len() != n {
        return Err(Error::ShapeMismatch(format!(
            "`y` has {} responses but the design has {n} runs",
            y.len()
        )));
    }
    ensure_finite("y", y)
}

fn ols(
    design: &DMatrix<f64>,
    y: &[f64],
    names: Vec<String>,
    k: usize,
    interaction: bool,
    n_blocks: usize,
) -> Result<RsmFit> {
    let (n, p) = design.shape();
    if n <= p {
        return Err(Error::invalid(
            "x",
            format!(
                "the model has {p} terms and needs more runs than terms (at least {}), got {n}",
                p + 1
            ),
        ));
    }
    let yv = DVector::from_column_slice(y);
    let mean = yv.mean();
    let sst: f64 = yv.iter().map(|v| (v - mean) * (v - mean)).sum();
    // Equal responses up to rounding (deviations of a few ulps of the largest |y|).
    let y_max = yv.amax();
    if sst <= n as f64 * (16.0 * f64::EPSILON * y_max).powi(2) {
        return Err(Error::invalid(
            "y",
            "all responses are equal (total sum of squares 0): R² and the t-tests are undefined",
        ));
    }

    // A bounded number of sweeps: an SVD that does not converge is an error, never a hang.
    let svd = design
        .clone()
        .try_svd(true, true, f64::EPSILON, 10_000)
        .ok_or_else(|| Error::Numerical("the SVD of the design matrix did not converge".into()))?;
    let (u, v_t) = match (svd.u, svd.v_t) {
        (Some(u), Some(v_t)) => (u, v_t),
        _ => return Err(Error::Numerical("SVD of the design matrix failed".into())),
    };
    let s = svd.singular_values;
    let s_max = s.max();
    let rank = s.iter().filter(|&&v| v > RCOND * s_max).count();
    if s_max.is_nan() || s_max <= 0.0 || rank < p {
        return Err(Error::invalid(
            "x",
            format!(
                "the design is singular: its {p}-term model matrix has rank {rank} \
                 (identical runs, a constant factor or too few distinct levels per factor)"
            ),
        ));
    }
    // b = V S⁻¹ Uᵀ y ; Cov factor (XᵀX)⁻¹ = V S⁻² Vᵀ.
    let uty = u.transpose() * &yv;
    let w = DVector::from_fn(p, |j, _| uty[j] / s[j]);
    let coef = v_t.transpose() * w;
    let fitted = design * &coef;
    let resid = &yv - &fitted;
    let sse = resid.norm_squared();
    let df_resid = n - p;
    let sigma2 = sse / df_resid as f64;
    let mut xtx_inv_diag = vec![0.0; p];
    for (j, d) in xtx_inv_diag.iter_mut().enumerate() {
        *d = (0..p).map(|m| (v_t[(m, j)] / s[m]).powi(2)).sum();
    }
    let se: Vec<f64> = xtx_inv_diag.iter().map(|d| (sigma2 * d).sqrt()).collect();
    let t: Vec<f64> = coef.iter().zip(&se).map(|(b, e)| b / e).collect();
    let p_vals = t
        .iter()
        .map(|&tv| t_two_sided_p(tv, df_resid as f64))
        .collect::<Result<Vec<f64>>>()?;
    let leverage: Vec<f64> = (0..n)
        .map(|i| (0..p).map(|j| u[(i, j)] * u[(i, j)]).sum())
        .collect();
    let press = if leverage.iter().any(|&h| 1.0 - h <= 1e-12) {
        f64::INFINITY
    } else {
        resid
            .iter()
            .zip(&leverage)
            .map(|(e, h)| (e / (1.0 - h)).powi(2))
            .sum()
    };
    let r2 = 1.0 - sse / sst;
    let r2_adj = 1.0 - (1.0 - r2) * (n - 1) as f64 / df_resid as f64;
    let r2_pred = 1.0 - press / sst;

    let coef: Vec<f64> = coef.iter().copied().collect();
    let bmat = second_order_matrix(&coef, k, interaction);
    let eig = SymmetricEigen::new(bmat);
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let canonical_eigs: Vec<f64> = order.iter().map(|&i| eig.eigenvalues[i]).collect();
    let canonical_axes = DMatrix::from_fn(k, k, |r, c| eig.eigenvectors[(r, order[c])]);
    let lin = DVector::from_column_slice(&coef[1..=k]);
    let lam_max = canonical_eigs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let singular = lam_max == 0.0 || canonical_eigs.iter().any(|v| v.abs() <= 1e-12 * lam_max);
    let stationary = if singular {
        None
    } else {
        // x_s = −½ B⁻¹ b = −½ Σ_i (v_iᵀ b / λ_i) v_i.
        let mut xs = DVector::<f64>::zeros(k);
        for (c, lam) in canonical_eigs.iter().enumerate() {
            let v = canonical_axes.column(c);
            xs += v * (-0.5 * v.dot(&lin) / lam);
        }
        Some(xs.iter().copied().collect::<Vec<f64>>())
    };
    let y_stationary = stationary
        .as_ref()
        .map(|xs| coef[0] + 0.5 * xs.iter().zip(lin.iter()).map(|(a, b)| a * b).sum::<f64>());

    Ok(RsmFit {
        k,
        interaction,
        n_blocks,
        coef,
        names,
        se,
        t,
        p: p_vals,
        r2,
        r2_adj,
        r2_pred,
        press,
        sse,
        sst,
        df_resid,
        sigma2,
        leverage,
        residuals: resid.iter().copied().collect(),
        fitted: fitted.iter().copied().collect(),
        stationary,
        y_stationary,
        canonical_eigs,
        canonical_axes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_columns_follow_the_documented_order() {
        assert_eq!(term_names(2, false), ["b0", "b1", "b2", "b11", "b22"]);
        assert_eq!(
            term_names(3, true),
            ["b0", "b1", "b2", "b3", "b11", "b22", "b33", "b12", "b13", "b23"]
        );
        assert_eq!(term_names(10, false)[11], "b1_1");
        assert_eq!(n_terms(3, true), 10);
        let x = DMatrix::from_row_slice(1, 3, &[2.0, 3.0, 5.0]);
        let d = quadratic_design(&x, true).unwrap();
        let want = [1.0, 2.0, 3.0, 5.0, 4.0, 9.0, 25.0, 6.0, 10.0, 15.0];
        assert_eq!(d.as_slice(), &want);
    }

    #[test]
    fn values_whose_squares_overflow_are_refused() {
        // A 3x3 grid with one value of 1e155: its square is infinite, which made the SVD loop
        // forever; refused by name before any fit.
        let mut pts = Vec::new();
        for a in [-1.0, 0.0, 1.0] {
            for b in [-1.0, 0.0, 1.0] {
                pts.extend_from_slice(&[a, b]);
            }
        }
        pts[0] = 1e155;
        let x = DMatrix::from_row_slice(9, 2, &pts);
        let y: Vec<f64> = (0..9).map(|i| i as f64).collect();
        let e = fit_quadratic(&x, &y, true).unwrap_err();
        assert_eq!(e.argument(), Some("x"), "{e}");
        // Below the bound the fit runs (this design is then too ill-conditioned to be of full
        // rank, which is its own error).
        pts[0] = 1e74;
        let x = DMatrix::from_row_slice(9, 2, &pts);
        if let Err(e) = fit_quadratic(&x, &y, true) {
            assert!(!e.to_string().contains("overflow"), "{e}");
        }
    }

    #[test]
    fn stationary_point_of_a_known_bowl() {
        // y = 1 + (x1 − 0.2)² + 2 (x2 + 0.1)² + 0.5 (x1 − 0.2)(x2 + 0.1), on a 3x3 grid.
        let mut pts = Vec::new();
        let mut y = Vec::new();
        for a in [-1.0, 0.0, 1.0] {
            for b in [-1.0, 0.0, 1.0] {
                pts.extend_from_slice(&[a, b]);
                let (u, v): (f64, f64) = (a - 0.2, b + 0.1);
                y.push(1.0 + u * u + 2.0 * v * v + 0.5 * u * v);
            }
        }
        let x = DMatrix::from_row_slice(9, 2, &pts);
        let fit = fit_quadratic(&x, &y, true).unwrap();
        let xs = fit.stationary.clone().unwrap();
        assert!(
            (xs[0] - 0.2).abs() < 1e-12 && (xs[1] + 0.1).abs() < 1e-12,
            "{xs:?}"
        );
        assert!((fit.y_stationary.unwrap() - 1.0).abs() < 1e-12);
        // B = [[1, 0.25], [0.25, 2]]: eigenvalues 1.5 ∓ sqrt(0.25 + 0.0625).
        let d = (0.25f64 + 0.0625).sqrt();
        assert!((fit.canonical_eigs[0] - (1.5 - d)).abs() < 1e-12);
        assert!((fit.canonical_eigs[1] - (1.5 + d)).abs() < 1e-12);
        let pred = predict(&fit, &DMatrix::from_row_slice(1, 2, &[0.2, -0.1])).unwrap();
        assert!((pred[0] - 1.0).abs() < 1e-12);
        assert!(predict(&fit, &DMatrix::zeros(1, 3)).is_err());
    }

    #[test]
    fn a_flat_direction_has_no_stationary_point() {
        // y = 1 + x1² + 0.5 x2: B = diag(1, 0) is singular, the surface is a ridge.
        let mut pts = Vec::new();
        let mut y = Vec::new();
        for a in [-1.0, 0.0, 1.0] {
            for b in [-1.0, 0.0, 1.0] {
                pts.extend_from_slice(&[a, b]);
                y.push(1.0 + a * a + 0.5 * b);
            }
        }
        let x = DMatrix::from_row_slice(9, 2, &pts);
        let fit = fit_quadratic(&x, &y, false).unwrap();
        assert!(fit.stationary.is_none());
        assert!(fit.y_stationary.is_none());
        assert!(fit.canonical_eigs[0].abs() < 1e-12);
        assert!((fit.canonical_eigs[1] - 1.0).abs() < 1e-12);
        assert!((fit.coef_of("b2").unwrap() - 0.5).abs() < 1e-12);
    }
}
