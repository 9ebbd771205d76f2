//! Panel agreement by principal component analysis (paper 07 §5.1: "A principal component
//! analysis (PCA) was applied in order to verify if the observers generally agree in their
//! evaluations. The first axis represents more than 80% in the two studies").
//!
//! The panel is the stimuli x subjects score matrix (13 x 26 per condition in the paper); each
//! subject is a variable. Subjects are standardised (columns centred and scaled to unit
//! variance), so the PCA is that of the subjects' correlation matrix, and the explained-variance
//! ratios are
//!
//! ```text
//! Z = (X − 1 μᵀ) diag(1/σ),   Z = U S Vᵀ,   ratio_i = s_i² / Σ_j s_j²
//! ```
//!
//! A first ratio near 1 means the subjects rank the stimuli alike (up to each subject's own offset
//! and scale), which justifies modelling the panel mean.

use nalgebra::DMatrix;
use wscg_math::error::ensure_finite;
use wscg_math::{Error, Result};

/// Explained-variance ratios (descending, summing to 1) of the PCA of the standardised
/// subjects, `min(stimuli, subjects)` of them (same as scikit-learn's
/// `PCA().fit(StandardScaler().fit_transform(scores)).explained_variance_ratio_`).
///
/// * `scores`: stimuli x subjects (rows are observations, columns are the subjects).
///
/// A subject whose scores are all equal has no variance to standardise; like scikit-learn's
/// `StandardScaler` its centred column (all zeros) is kept unscaled and contributes nothing.
///
/// # Errors
/// [`Error::InvalidArgument`] for fewer than 2 stimuli or when every subject is constant;
/// [`Error::Empty`] for no subjects; [`Error::NonFinite`] for NaN/∞ scores.
pub fn panel_pca(scores: &DMatrix<f64>) -> Result<Vec<f64>> {
    let (n, m) = scores.shape();
    if n < 2 {
        return Err(Error::invalid(
            "scores",
            format!("needs at least 2 stimuli (rows) to standardise the subjects, got {n}"),
        ));
    }
    if m == 0 {
        return Err(Error::Empty("scores (subjects)"));
    }
    ensure_finite("scores", scores.as_slice())?;
    let mut z = scores.clone();
    let mut n_varying = 0;
    for mut col in z.column_iter_mut() {
        let mu = col.mean();
        col.add_scalar_mut(-mu);
        let sd = (col.norm_squared() / n as f64).sqrt();
        if sd > 1e-13 * (1.0 + mu.abs()) {
            col /= sd;
            n_varying += 1;
        }
    }
    if n_varying == 0 {
        return Err(Error::invalid(
            "scores",
            "every subject gives the same score to all stimuli: no variance to analyse",
        ));
    }
    let s = z.singular_values();
    let mut ev: Vec<f64> = s.iter().map(|v| v * v).collect();
    ev.sort_by(|a, b| b.total_cmp(a));
    let total: f64 = ev.iter().sum();
    Ok(ev.into_iter().map(|v| v / total).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_independent_subjects_split_the_variance() {
        // Two orthogonal, equally scaled profiles: ratios (0.5, 0.5).
        let x = DMatrix::from_row_slice(4, 2, &[1.0, 1.0, -1.0, 1.0, 1.0, -1.0, -1.0, -1.0]);
        let r = panel_pca(&x).unwrap();
        assert_eq!(r.len(), 2);
        assert!((r[0] - 0.5).abs() < 1e-14 && (r[1] - 0.5).abs() < 1e-14);
    }

    #[test]
    fn constant_subjects_are_ignored_or_rejected() {
        let x = DMatrix::from_row_slice(3, 2, &[1.0, 4.0, 2.0, 4.0, 3.0, 4.0]);
        let r = panel_pca(&x).unwrap();
        assert!((r[0] - 1.0).abs() < 1e-14);
        assert!(panel_pca(&DMatrix::from_element(3, 2, 4.0)).is_err());
        assert!(panel_pca(&DMatrix::zeros(1, 3)).is_err());
        assert!(panel_pca(&DMatrix::zeros(3, 0)).is_err());
    }
}
