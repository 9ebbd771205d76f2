//! Temporal slow feature analysis (paper 05, section 2.1, eqs. 1-7; Wiskott and Sejnowski
//! 2002), the building block of the class-wise method.
//!
//! For a signal `x(t)` expanded to `z(t)`, find `y_j = w_j' (z - mu)` minimising the slowness
//! `Delta(y_j) = <(y_j(t+1) - y_j(t))^2>` (eq. 1) subject to zero mean, unit variance and
//! decorrelation (eqs. 2-4): the generalized problem `A w = lambda B w` with
//! `A = <z' z'^T>` (the difference signal, not centred) and `B` the covariance of `z`,
//! eigenvalues ascending; the delta value of `y_j` is `lambda_j`.
//!
//! The paper sphers `x` *before* the expansion (eq. 5) and then takes eigenvectors of the
//! expanded derivative's covariance (eq. 6); the expanded signal is then no longer white and
//! constraints 2-4 fail. As Wiskott and Sejnowski (and MDP's `SFA2Node`), the whitening
//! here is of the expanded signal, with a rank cut for directions of (numerically) zero
//! variance.

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::expansion::{expand_opt, QuadraticExpansion};
use super::scatter::{ClassMoments, Whitening};
use crate::subspace::{check_data, check_query};

/// A fitted temporal SFA.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TemporalSfa {
    /// The expansion applied before the linear SFA (`None`: linear SFA).
    pub expansion: Option<QuadraticExpansion>,
    /// Input dimension.
    pub input_dim: usize,
    /// Mean of the expanded signal.
    pub mean: Vec<f64>,
    /// `W` (`D x n_out`): output `j` is `W[:, j]' (z - mean)`.
    #[serde(with = "crate::subspace::serde_mat")]
    pub w: Mat<f64>,
    /// Delta values of the outputs, ascending.
    pub delta: Vec<f64>,
    /// Rank of the expanded covariance after the cut.
    pub rank: usize,
}

impl TemporalSfa {
    /// Fits `n_out` slow features to the time series `x` (`T x d`, one time step per row).
    ///
    /// Errors: fewer than 3 time steps, non-finite values, `n_out` outside `1..=rank`.
    pub fn fit(
        x: MatRef<'_, f64>,
        n_out: usize,
        expansion: Option<QuadraticExpansion>,
        rank_tol: f64,
    ) -> Result<Self> {
        check_data("x", x, 3)?;
        let t = x.nrows();
        let labels = vec![0u32; t];
        let mom = ClassMoments::accumulate(x, &labels, expansion);
        let white = Whitening::new(mom.total_covariance().as_ref(), rank_tol)?;
        // A = <dz dz'> over the T - 1 differences, block by block with one row of overlap.
        let dim = mom.dim();
        let mut a = Mat::<f64>::zeros(dim, dim);
        let step = super::expansion::CHUNK;
        let mut s = 0;
        while s + 1 < t {
            let end = (s + step + 1).min(t);
            let z = expand_opt(expansion, x.subrows(s, end - s));
            let mut dz = Mat::<f64>::zeros(z.nrows() - 1, dim);
            for j in 0..dim {
                let (src, dst) = (z.col(j), dz.col_mut(j));
                dst.iter_mut()
                    .enumerate()
                    .for_each(|(i, d)| *d = src[i + 1] - src[i]);
            }
            wscg_math::dense::gram_accumulate(&mut a, dz.as_ref(), 1.0);
            s = end - 1;
        }
        let a = a * faer::Scale(1.0 / (t - 1) as f64);
        let (delta, w) = white.smallest(white.project(a.as_ref()).as_ref(), n_out)?;
        Ok(Self {
            expansion,
            input_dim: x.ncols(),
            mean: mom.class_mean(0),
            w,
            delta,
            rank: white.rank,
        })
    }

    /// The slow features of the rows of `x` (`n x n_out`).
    ///
    /// Errors: wrong width, non-finite values.
    pub fn transform(&self, x: MatRef<'_, f64>) -> Result<Mat<f64>> {
        check_query(x, self.input_dim)?;
        let mut z = expand_opt(self.expansion, x);
        for j in 0..z.ncols() {
            let m = self.mean[j];
            z.col_mut(j).iter_mut().for_each(|v| *v -= m);
        }
        Ok(&z * &self.w)
    }

    /// Delta values (slowness) of the outputs, ascending.
    pub fn delta_values(&self) -> &[f64] {
        &self.delta
    }

    /// The model as JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::invalid("model", e.to_string()))
    }

    /// A model from [`Self::to_json`] output. Errors: not a model, or sizes that disagree
    /// (expanded dimension, mean, `W`, delta values).
    pub fn from_json(s: &str) -> Result<Self> {
        let m: Self = serde_json::from_str(s)
            .map_err(|e| Error::invalid("model", format!("not a temporal SFA model: {e}")))?;
        let dim = m.expansion.map_or(m.input_dim, |e| e.out_dim(m.input_dim));
        if m.mean.len() != dim || m.w.nrows() != dim || m.delta.len() != m.w.ncols() {
            return Err(Error::invalid(
                "model",
                format!(
                    "sizes disagree: expanded dimension {dim}, mean {}, W {} x {}, {} delta values",
                    m.mean.len(),
                    m.w.nrows(),
                    m.w.ncols(),
                    m.delta.len()
                ),
            ));
        }
        Ok(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wiskott_sejnowski_toy() {
        // The toy of Wiskott and Sejnowski (2002): x1 = sin t + cos^2(11 t), x2 = cos(11 t);
        // the slowest quadratic feature is sin t.
        let n = 5000;
        let ts: Vec<f64> = (0..n)
            .map(|i| 2.0 * std::f64::consts::PI * i as f64 / (n - 1) as f64)
            .collect();
        let x = Mat::from_fn(n, 2, |i, j| {
            let t = ts[i];
            if j == 0 {
                t.sin() + (11.0 * t).cos().powi(2)
            } else {
                (11.0 * t).cos()
            }
        });
        let sfa =
            TemporalSfa::fit(x.as_ref(), 3, Some(QuadraticExpansion::default()), 1e-10).unwrap();
        let y = sfa.transform(x.as_ref()).unwrap();
        let col = |j: usize| (0..n).map(|i| y[(i, j)]).collect::<Vec<f64>>();
        let y1 = col(0);
        let s: Vec<f64> = ts.iter().map(|t| t.sin()).collect();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let (my, ms) = (mean(&y1), mean(&s));
        let cov: f64 = y1.iter().zip(&s).map(|(a, b)| (a - my) * (b - ms)).sum();
        let vy: f64 = y1.iter().map(|a| (a - my).powi(2)).sum();
        let vs: f64 = s.iter().map(|b| (b - ms).powi(2)).sum();
        let corr = cov / (vy * vs).sqrt();
        assert!(corr.abs() >= 0.999, "{corr}");
        // Constraints 2-4 on the training signal.
        for a in 0..3 {
            let ca = col(a);
            assert!(mean(&ca).abs() < 1e-10);
            for b in 0..3 {
                let cb = col(b);
                let c: f64 = ca.iter().zip(&cb).map(|(p, q)| p * q).sum::<f64>() / n as f64;
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((c - want).abs() < 1e-8, "cov {a} {b} = {c}");
            }
        }
        assert!(sfa.delta_values().windows(2).all(|w| w[0] <= w[1]));
        assert!(TemporalSfa::fit(x.subrows(0, 2), 1, None, 1e-10).is_err());
        assert!(TemporalSfa::fit(x.as_ref(), 9, None, 1e-10).is_err());
        // JSON round trip: the same features to the bit.
        let back = TemporalSfa::from_json(&sfa.to_json().unwrap()).unwrap();
        let y2 = back.transform(x.as_ref()).unwrap();
        assert!((0..n).all(|i| (0..3).all(|j| y2[(i, j)].to_bits() == y[(i, j)].to_bits())));
        assert_eq!(back.delta_values(), sfa.delta_values());
        let mut bad = back.clone();
        bad.mean.pop();
        assert!(TemporalSfa::from_json(&bad.to_json().unwrap()).is_err());
        assert!(TemporalSfa::from_json("{}").is_err());
    }
}
