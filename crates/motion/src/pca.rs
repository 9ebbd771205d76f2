//! The synchronous baseline of paper Fig. 4: PCA of the `(R·I) × N` signal matrix (each row a
//! channel of one trial, each column a time sample), `Q_PCA(J) = Σ_{l≤J} σ_l² / Σ_l σ_l²`.
//! This equals scikit-learn's `PCA(J).fit(X.T).explained_variance_ratio_.sum()`: rows are
//! centred over time first, as scikit-learn centres features.

use crate::data::TrialSet;
use faer::Mat;
use wscg_math::{Error, Result};

/// Cumulative explained-variance ratios `Q_PCA(1), Q_PCA(2), …` for every component count.
///
/// # Errors
/// Data whose rows are constant (zero variance).
pub fn pca_qualities(x: &TrialSet) -> Result<Vec<f64>> {
    let (rows, n) = (x.n_trials * x.n_channels, x.n_samples);
    let a = Mat::from_fn(rows, n, |ri, m| x.data[ri * n + m]);
    let means: Vec<f64> = (0..rows)
        .map(|ri| x.data[ri * n..(ri + 1) * n].iter().sum::<f64>() / n as f64)
        .collect();
    let centred = Mat::from_fn(rows, n, |ri, m| a[(ri, m)] - means[ri]);
    let d = wscg_math::dense::svd(centred.as_ref())?;
    let total: f64 = d.s.iter().map(|s| s * s).sum();
    if total <= 0.0 {
        return Err(Error::invalid(
            "x",
            "every channel is constant; PCA quality is undefined",
        ));
    }
    let mut acc = 0.0;
    Ok(d.s
        .iter()
        .map(|s| {
            acc += s * s;
            acc / total
        })
        .collect())
}

/// `Q_PCA(j)`, the fraction of variance of the `j` leading principal components.
///
/// # Errors
/// `j = 0` or more components than `min(R·I, N)`; constant data.
pub fn pca_quality(x: &TrialSet, j: usize) -> Result<f64> {
    let q = pca_qualities(x)?;
    if j == 0 || j > q.len() {
        return Err(Error::invalid(
            "j",
            format!("must be in 1..={}, got {j}", q.len()),
        ));
    }
    Ok(q[j - 1])
}
