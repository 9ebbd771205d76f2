//! Repeated-measures analysis of variance and Fisher's least significant difference, as used in
//! paper 07 (§5.2–§6: "ANOVA repeated measure analysis on the global response", "the Least
//! Square Difference Test (LSD) show that with the stereoscopic condition the observers were
//! able to discriminate better the plates").
//!
//! # Two within-subject factors ([`rm_anova`])
//!
//! Every subject `s` (S of them) scores every stimulus `b` (B) under every condition `a` (A), one
//! score `y_sab` each. With means `m` (grand), `m_s`, `m_a`, `m_b`, `m_as`, `m_bs`, `m_ab`:
//!
//! ```text
//! SS_A   = S·B Σ_a (m_a − m)²                          df A−1
//! SS_B   = S·A Σ_b (m_b − m)²                          df B−1
//! SS_AB  = S Σ_ab (m_ab − m_a − m_b + m)²              df (A−1)(B−1)
//! SS_AxS = B Σ_as (m_as − m_a − m_s + m)²              df (A−1)(S−1)   error of A
//! SS_BxS = A Σ_bs (m_bs − m_b − m_s + m)²              df (B−1)(S−1)   error of B
//! SS_ABxS = Σ (y − m_ab − m_as − m_bs + m_a + m_b + m_s − m)²   df (A−1)(B−1)(S−1)  error of AB
//! F = (SS/df) / (SS_err/df_err),   p = P(F_{df, df_err} ≥ F)
//! ```
//!
//! Each effect is tested against its own effect-by-subject interaction, as statsmodels
//! `AnovaRM` and pingouin `rm_anova(within=[a, b])` do.
//!
//! # Greenhouse–Geisser correction
//!
//! For an effect with `d` degrees of freedom, let `Σ` be the sample covariance (divisor S − 1) of
//! the subjects' scores over the effect's cells (the condition means over stimuli for A, the
//! stimulus means over conditions for B, all A·B cells for the interaction) and `C` an
//! orthonormal contrast basis of the effect (`C = C_A ⊗ C_B` for the interaction). Then
//!
//! ```text
//! M = Cᵀ Σ C,   ε = min(1, tr(M)² / (d · tr(M²))),   ε = 1 when d = 1
//! p_GG = P(F_{max(1, ε·df), max(1, ε·df_err)} ≥ F)
//! ```
//!
//! (pingouin 0.7's definition, Greenhouse & Geisser 1959). `tr(M)` and `tr(M²)` do not depend
//! on the contrast basis, so they are computed here with the centring projector
//! `P = I − J/L` (`P_A ⊗ P_B` for the interaction) in place of `C Cᵀ`.
//!
//! # Fisher's LSD ([`lsd_pairs`])
//!
//! Within one condition (S subjects x N stimuli), the one-way repeated-measures error mean
//! square `MS_err = SS_{stimulus x subject} / ((N−1)(S−1))` gives
//! `LSD = t_{1−α/2, (N−1)(S−1)} · sqrt(2·MS_err / S)`; two stimuli are separated when their mean
//! scores differ by more than the LSD (paper: 78 pairs of 13 plates, 26 observers).

use nalgebra::DMatrix;
use wscg_math::error::ensure_finite;
use wscg_math::{Error, Result};

use crate::dist::{f_sf, t_quantile};

/// One tested effect of a repeated-measures ANOVA.
#[derive(Debug, Clone, PartialEq)]
pub struct AnovaEffect {
    /// `"condition"`, `"stimulus"` or `"condition:stimulus"` ([`rm_anova`]); `"effect"` for
    /// [`rm_anova_oneway`].
    pub name: String,
    /// Sum of squares of the effect.
    pub ss: f64,
    /// Degrees of freedom of the effect.
    pub df: usize,
    /// Mean square `ss / df`.
    pub ms: f64,
    /// F statistic `ms / ms_error`.
    pub f: f64,
    /// Uncorrected p-value `P(F_{df, df_error} ≥ f)`.
    pub p: f64,
    /// Sum of squares of the effect's error term (effect x subject interaction).
    pub ss_error: f64,
    /// Degrees of freedom of the error term.
    pub df_error: usize,
    /// Mean square of the error term.
    pub ms_error: f64,
    /// Partial eta squared `ss / (ss + ss_error)`.
    pub np2: f64,
    /// Greenhouse–Geisser epsilon (1 for an effect with one degree of freedom; NaN when the
    /// subjects' scores over the effect's cells do not vary).
    pub eps_gg: f64,
    /// p-value with Greenhouse–Geisser corrected degrees of freedom.
    pub p_gg: f64,
}

/// A two-way repeated-measures ANOVA table (condition x stimulus within subjects).
#[derive(Debug, Clone, PartialEq)]
pub struct AnovaTable {
    /// Number of subjects S.
    pub n_subjects: usize,
    /// Number of conditions A (paper 07: mono, stereo).
    pub n_conditions: usize,
    /// Number of stimuli B (paper 07: 13 plates).
    pub n_stimuli: usize,
    /// Effects in the order condition, stimulus, condition:stimulus.
    pub effects: Vec<AnovaEffect>,
    /// Between-subject sum of squares `A·B Σ_s (m_s − m)²` (df S − 1).
    pub ss_subject: f64,
    /// Total sum of squares `Σ (y − m)²` (df S·A·B − 1).
    pub ss_total: f64,
}

impl AnovaTable {
    /// The effect named `name` (`"condition"`, `"stimulus"` or `"condition:stimulus"`).
    pub fn effect(&self, name: &str) -> Option<&AnovaEffect> {
        self.effects.iter().find(|e| e.name == name)
    }
}

/// Two-way repeated-measures ANOVA with within-subject factors condition and stimulus.
///
/// * `scores`: `n_subjects · n_conditions · n_stimuli` values in C order, subject slowest:
///   `scores[(s · n_conditions + a) · n_stimuli + b]` is subject `s`, condition `a`, stimulus `b`
///   (the layout of a numpy array of shape `(S, A, B)`).
///
/// Needs S ≥ 2, A ≥ 2 and B ≥ 2 (complete data, one score per cell). When an error term is 0
/// the F statistic is ±∞ or NaN and so is its p-value.
///
/// # Errors
/// [`Error::InvalidArgument`] for a factor with fewer than two levels or fewer than two
/// subjects; [`Error::ShapeMismatch`] when `scores.len() != S·A·B`; [`Error::NonFinite`] for
/// NaN/∞ scores.
pub fn rm_anova(
    scores: &[f64],
    n_subjects: usize,
    n_conditions: usize,
    n_stimuli: usize,
) -> Result<AnovaTable> {
    let (ns, na, nb) = (n_subjects, n_conditions, n_stimuli);
    at_least_two("n_subjects", ns)?;
    at_least_two("n_conditions", na)?;
    at_least_two("n_stimuli", nb)?;
    let total = ns
        .checked_mul(na)
        .and_then(|v| v.checked_mul(nb))
        .ok_or_else(|| Error::LimitExceeded("S·A·B overflows".into()))?;
    if scores.len() != total {
        return Err(Error::ShapeMismatch(format!(
            "`scores` has {} values but {ns} subjects x {na} conditions x {nb} stimuli = {total}",
            scores.len()
        )));
    }
    ensure_finite("scores", scores)?;
    let y = |s: usize, a: usize, b: usize| scores[(s * na + a) * nb + b];
    let (fs, fa, fb) = (ns as f64, na as f64, nb as f64);

    let m = scores.iter().sum::<f64>() / total as f64;
    let mut m_s = vec![0.0; ns];
    let mut m_a = vec![0.0; na];
    let mut m_b = vec![0.0; nb];
    let mut m_as = vec![0.0; na * ns]; // [a * ns + s]
    let mut m_bs = vec![0.0; nb * ns]; // [b * ns + s]
    let mut m_ab = vec![0.0; na * nb]; // [a * nb + b]
    for s in 0..ns {
        for a in 0..na {
            for b in 0..nb {
                let v = y(s, a, b);
                m_s[s] += v / (fa * fb);
                m_a[a] += v / (fs * fb);
                m_b[b] += v / (fs * fa);
                m_as[a * ns + s] += v / fb;
                m_bs[b * ns + s] += v / fa;
                m_ab[a * nb + b] += v / fs;
            }
        }
    }
    let sq = |v: f64| v * v;
    let ss_total: f64 = scores.iter().map(|&v| sq(v - m)).sum();
    let ss_subject = fa * fb * m_s.iter().map(|&v| sq(v - m)).sum::<f64>();
    let ss_a = fs * fb * m_a.iter().map(|&v| sq(v - m)).sum::<f64>();
    let ss_b = fs * fa * m_b.iter().map(|&v| sq(v - m)).sum::<f64>();
    let mut ss_ab = 0.0;
    for a in 0..na {
        for b in 0..nb {
            ss_ab += sq(m_ab[a * nb + b] - m_a[a] - m_b[b] + m);
        }
    }
    ss_ab *= fs;
    let mut ss_as = 0.0;
    for a in 0..na {
        for s in 0..ns {
            ss_as += sq(m_as[a * ns + s] - m_a[a] - m_s[s] + m);
        }
    }
    ss_as *= fb;
    let mut ss_bs = 0.0;
    for b in 0..nb {
        for s in 0..ns {
            ss_bs += sq(m_bs[b * ns + s] - m_b[b] - m_s[s] + m);
        }
    }
    ss_bs *= fa;
    let mut ss_abs = 0.0;
    for s in 0..ns {
        for a in 0..na {
            for b in 0..nb {
                ss_abs += sq(
                    y(s, a, b) - m_ab[a * nb + b] - m_as[a * ns + s] - m_bs[b * ns + s]
                        + m_a[a]
                        + m_b[b]
                        + m_s[s]
                        - m,
                );
            }
        }
    }

    // Subject x cell matrices for the sphericity corrections.
    let cond_means = DMatrix::from_fn(ns, na, |s, a| m_as[a * ns + s]);
    let stim_means = DMatrix::from_fn(ns, nb, |s, b| m_bs[b * ns + s]);
    let cells = DMatrix::from_fn(ns, na * nb, |s, c| y(s, c / nb, c % nb));
    let eps_a = gg_epsilon(&cond_means, &[na]);
    let eps_b = gg_epsilon(&stim_means, &[nb]);
    let eps_ab = gg_epsilon(&cells, &[na, nb]);

    let effects = vec![
        effect("condition", ss_a, na - 1, ss_as, (na - 1) * (ns - 1), eps_a)?,
        effect("stimulus", ss_b, nb - 1, ss_bs, (nb - 1) * (ns - 1), eps_b)?,
        effect(
            "condition:stimulus",
            ss_ab,
            (na - 1) * (nb - 1),
            ss_abs,
            (na - 1) * (nb - 1) * (ns - 1),
            eps_ab,
        )?,
    ];
    Ok(AnovaTable {
        n_subjects: ns,
        n_conditions: na,
        n_stimuli: nb,
        effects,
        ss_subject,
        ss_total,
    })
}

/// One-way repeated-measures ANOVA: `scores` is subjects x levels (e.g. the 26 x 13 scores of
/// one viewing condition). The effect is tested against the level x subject interaction,
/// with the Greenhouse–Geisser correction (same as pingouin `rm_anova(within=...)`).
///
/// # Errors
/// [`Error::InvalidArgument`] for fewer than two subjects or levels; [`Error::NonFinite`] for
/// NaN/∞ scores.
pub fn rm_anova_oneway(scores: &DMatrix<f64>) -> Result<AnovaEffect> {
    let (ns, nl) = scores.shape();
    at_least_two("scores rows (subjects)", ns)?;
    at_least_two("scores columns (levels)", nl)?;
    ensure_finite("scores", scores.as_slice())?;
    let m = scores.mean();
    let m_s: Vec<f64> = scores.row_iter().map(|r| r.mean()).collect();
    let m_l: Vec<f64> = scores.column_iter().map(|c| c.mean()).collect();
    let ss = ns as f64 * m_l.iter().map(|v| (v - m) * (v - m)).sum::<f64>();
    let mut ss_err = 0.0;
    for s in 0..ns {
        for l in 0..nl {
            let r = scores[(s, l)] - m_s[s] - m_l[l] + m;
            ss_err += r * r;
        }
    }
    let eps = gg_epsilon(scores, &[nl]);
    effect("effect", ss, nl - 1, ss_err, (nl - 1) * (ns - 1), eps)
}

/// Result of Fisher's least significant difference test on one condition.
#[derive(Debug, Clone, PartialEq)]
pub struct LeastSignificantDifference {
    /// Significance level α of the two-sided comparisons.
    pub alpha: f64,
    /// Critical value `t_{1−α/2, df_error}`.
    pub t_crit: f64,
    /// Error mean square of the one-way repeated-measures ANOVA (stimulus x subject).
    pub ms_error: f64,
    /// Its degrees of freedom `(N − 1)(S − 1)`.
    pub df_error: usize,
    /// Least significant difference `t_crit · sqrt(2 · ms_error / S)`.
    pub lsd: f64,
    /// Mean score of each stimulus over subjects.
    pub means: Vec<f64>,
    /// Every pair `(i, j)`, `i < j`, lexicographic, with `|mean_i − mean_j| > lsd`.
    pub pairs: Vec<(usize, usize, bool)>,
    /// Number of separated pairs.
    pub n_separated: usize,
}

/// Fisher's LSD on the scores of one condition, `scores`: subjects x stimuli.
///
/// * `alpha`: two-sided significance level in (0, 1) (paper: 0.05, `t_{0.975}`).
///
/// # Errors
/// As [`rm_anova_oneway`], plus [`Error::InvalidArgument`] for `alpha` outside (0, 1).
pub fn lsd_pairs(scores: &DMatrix<f64>, alpha: f64) -> Result<LeastSignificantDifference> {
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(Error::invalid(
            "alpha",
            format!("must be a significance level in (0, 1), got {alpha}"),
        ));
    }
    let aov = rm_anova_oneway(scores)?;
    let ns = scores.nrows();
    let t_crit = t_quantile(1.0 - 0.5 * alpha, aov.df_error as f64)?;
    let lsd = t_crit * (2.0 * aov.ms_error / ns as f64).sqrt();
    let means: Vec<f64> = scores.column_iter().map(|c| c.mean()).collect();
    let mut pairs = Vec::new();
    for i in 0..means.len() {
        for j in i + 1..means.len() {
            pairs.push((i, j, (means[i] - means[j]).abs() > lsd));
        }
    }
    let n_separated = pairs.iter().filter(|p| p.2).count();
    Ok(LeastSignificantDifference {
        alpha,
        t_crit,
        ms_error: aov.ms_error,
        df_error: aov.df_error,
        lsd,
        means,
        pairs,
        n_separated,
    })
}

fn at_least_two(name: &'static str, v: usize) -> Result<()> {
    if v < 2 {
        Err(Error::invalid(
            name,
            format!("a repeated-measures ANOVA needs at least 2, got {v}"),
        ))
    } else {
        Ok(())
    }
}

fn effect(
    name: &str,
    ss: f64,
    df: usize,
    ss_error: f64,
    df_error: usize,
    eps_gg: f64,
) -> Result<AnovaEffect> {
    let ms = ss / df as f64;
    let ms_error = ss_error / df_error as f64;
    let f = ms / ms_error;
    let p = f_sf(f, df as f64, df_error as f64)?;
    let p_gg = if eps_gg.is_finite() {
        f_sf(
            f,
            (eps_gg * df as f64).max(1.0),
            (eps_gg * df_error as f64).max(1.0),
        )?
    } else {
        f64::NAN
    };
    Ok(AnovaEffect {
        name: name.to_string(),
        ss,
        df,
        ms,
        f,
        p,
        ss_error,
        df_error,
        ms_error,
        np2: ss / (ss + ss_error),
        eps_gg,
        p_gg,
    })
}

/// Greenhouse–Geisser ε of an effect from the subjects x cells matrix `y`, whose columns are
/// ordered as the factor levels in `levels` (one factor, or two with the second fastest).
fn gg_epsilon(y: &DMatrix<f64>, levels: &[usize]) -> f64 {
    let d: usize = levels.iter().map(|l| l - 1).product();
    if d <= 1 {
        return 1.0;
    }
    let (ns, nc) = y.shape();
    // Sample covariance of the columns (divisor S − 1).
    let mut centred = y.clone();
    for mut col in centred.column_iter_mut() {
        let mu = col.mean();
        col.add_scalar_mut(-mu);
    }
    let cov = centred.transpose() * &centred / (ns as f64 - 1.0);
    // Projector onto the effect's contrasts: P_L = I − J/L, Kronecker product over factors.
    let mut proj = DMatrix::<f64>::identity(1, 1);
    for &l in levels {
        let p_l = DMatrix::from_fn(l, l, |i, j| {
            (if i == j { 1.0 } else { 0.0 }) - 1.0 / l as f64
        });
        proj = proj.kronecker(&p_l);
    }
    debug_assert_eq!(proj.nrows(), nc);
    let m = &proj * cov * &proj;
    let tr = m.trace();
    let tr2 = m.component_mul(&m.transpose()).sum();
    (tr * tr / (d as f64 * tr2)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_of_squares_add_up() {
        let scores: Vec<f64> = (0..3 * 2 * 4)
            .map(|i| ((i * 37 % 11) as f64) * 0.7 + (i % 5) as f64)
            .collect();
        let t = rm_anova(&scores, 3, 2, 4).unwrap();
        let sum: f64 = t.ss_subject + t.effects.iter().map(|e| e.ss + e.ss_error).sum::<f64>();
        assert!((sum - t.ss_total).abs() < 1e-10 * t.ss_total);
        let df: usize = 2 + t.effects.iter().map(|e| e.df + e.df_error).sum::<usize>();
        assert_eq!(df, 3 * 2 * 4 - 1);
        // Two conditions: one degree of freedom, epsilon 1, corrected p = p.
        assert_eq!(t.effects[0].eps_gg, 1.0);
        assert_eq!(t.effects[0].p_gg, t.effects[0].p);
    }

    #[test]
    fn lsd_by_hand() {
        // 3 subjects x 3 stimuli. Means: stimuli (2, 5, 8), subjects (4, 5, 6), grand 5.
        // Residuals y − m_s − m_l + m:
        //   [1, 4, 7]  − [4] − [2, 5, 8] + 5 = [0, 0, 0]
        //   [3, 5, 7]  − [5] − [2, 5, 8] + 5 = [1, 0, −1]
        //   [2, 6, 10] − [6] − [2, 5, 8] + 5 = [−1, 0, 1]
        // SS_err = 4, df_err = 4, MS_err = 1; t_{0.975, 4} = 2.7764451051977987;
        // LSD = 2.776445 · sqrt(2/3) = 2.266958...; |2 − 5| = 3 > LSD, |2 − 8| = 6, |5 − 8| = 3.
        let s = DMatrix::from_row_slice(3, 3, &[1.0, 4.0, 7.0, 3.0, 5.0, 7.0, 2.0, 6.0, 10.0]);
        let r = lsd_pairs(&s, 0.05).unwrap();
        assert!((r.ms_error - 1.0).abs() < 1e-14);
        assert_eq!(r.df_error, 4);
        assert!((r.t_crit - 2.7764451051977987).abs() < 1e-12);
        let lsd = 2.7764451051977987 * (2.0f64 / 3.0).sqrt();
        assert!((r.lsd - lsd).abs() < 1e-12);
        assert_eq!(r.means, vec![2.0, 5.0, 8.0]);
        assert_eq!(r.pairs, vec![(0, 1, true), (0, 2, true), (1, 2, true)]);
        assert_eq!(r.n_separated, 3);
        // At alpha = 0.001, t_{0.9995, 4} = 8.610 gives LSD = 7.03 > 6: no pair separated.
        let r = lsd_pairs(&s, 0.001).unwrap();
        assert_eq!(r.n_separated, 0);
        assert!(lsd_pairs(&s, 0.0).is_err());
        assert!(lsd_pairs(&s, 1.5).is_err());
    }

    #[test]
    fn spherical_covariance_gives_epsilon_one_and_a_ridge_gives_less() {
        // Subject deviations ±c1, ±c2 (orthonormal contrasts of 3 levels): their covariance is
        // proportional to I − J/3, the sphericity ideal, so ε = 1. Subject offsets and level
        // effects do not change it.
        let r2 = 2f64.sqrt();
        let r6 = 6f64.sqrt();
        let c1 = [1.0 / r2, -1.0 / r2, 0.0];
        let c2 = [1.0 / r6, 1.0 / r6, -2.0 / r6];
        let dev = [c1, c1.map(|v| -v), c2, c2.map(|v| -v)];
        let level = [0.5, -1.0, 2.0];
        let y = DMatrix::from_fn(4, 3, |s, l| 10.0 + s as f64 + level[l] + dev[s][l]);
        let e = rm_anova_oneway(&y).unwrap();
        assert!((e.eps_gg - 1.0).abs() < 1e-12, "{}", e.eps_gg);
        // All deviation along c1 only: one nonzero eigenvalue of M, ε = 1/d = 1/2 (the lower
        // bound).
        let dev = [
            c1,
            c1.map(|v| -v),
            c1.map(|v| 2.0 * v),
            c1.map(|v| -2.0 * v),
        ];
        let y = DMatrix::from_fn(4, 3, |s, l| 10.0 + s as f64 + level[l] + dev[s][l]);
        let e = rm_anova_oneway(&y).unwrap();
        assert!((e.eps_gg - 0.5).abs() < 1e-12, "{}", e.eps_gg);
    }

    #[test]
    fn bad_layouts_are_errors() {
        let v = vec![1.0; 12];
        assert!(rm_anova(&v, 3, 2, 3).is_err());
        assert!(rm_anova(&v, 1, 2, 6).is_err());
        assert!(rm_anova(&v, 6, 1, 2).is_err());
        assert!(rm_anova(&v, 6, 2, 1).is_err());
        let mut w: Vec<f64> = (0..12).map(|i| i as f64).collect();
        w[5] = f64::NAN;
        assert!(matches!(
            rm_anova(&w, 3, 2, 2),
            Err(Error::NonFinite { index: 5, .. })
        ));
        assert!(rm_anova_oneway(&DMatrix::zeros(1, 4)).is_err());
    }
}
