//! Locally weighted linear regression (Atkeson, Moore and Schaal 1997) of the mixing weights
//! against step parameters (paper §2.5).
//!
//! Inputs are standardised; a query `q*` weights training point `r` by
//! `κ_r = exp(−‖q_r − q*‖² / 2h²)`, solves the weighted least squares `[1, q_r − q*] β ≈ y_r`
//! with a small ridge on the slopes, and predicts `β₀`. The prediction is linear in the
//! training outputs (a linear smoother), so leave-one-out residuals have the closed form
//! `e_r / (1 − H_rr)`, which selects the bandwidth. `h = ∞` is global linear least squares.
//! Queries are clamped to the bounding box of the training inputs: with a dozen trials and
//! hundreds of outputs, extrapolation is not to be trusted.

use crate::linalg::solve_in_place;
use wscg_math::error::ensure_finite;
use wscg_math::{Error, Result};

/// Default ridge on the local slopes.
pub const DEFAULT_RIDGE: f64 = 1e-8;

/// A fitted LWLR model.
#[derive(Clone, Debug, PartialEq)]
pub struct Lwlr {
    /// Input dimension `d`.
    pub n_inputs: usize,
    /// Output dimension `P`.
    pub n_outputs: usize,
    /// Standardised training inputs, `R × d`.
    pub inputs: Vec<f64>,
    /// Training outputs, `R × P`.
    pub outputs: Vec<f64>,
    /// Input means.
    pub mean: Vec<f64>,
    /// Input standard deviations (1 for a constant input).
    pub scale: Vec<f64>,
    /// Bandwidth in standardised units (`f64::INFINITY` for global linear regression).
    pub bandwidth: f64,
    /// Ridge on the local slopes.
    pub ridge: f64,
}

/// The bandwidths tried by [`Lwlr::fit`] when none is given: 25 values from 0.15 to 10
/// (standardised units) and infinity.
pub fn default_bandwidths() -> Vec<f64> {
    let mut h: Vec<f64> = (0..25)
        .map(|i| 0.15 * (10.0f64 / 0.15).powf(i as f64 / 24.0))
        .collect();
    h.push(f64::INFINITY);
    h
}

impl Lwlr {
    /// Fits the model to `R` input rows (`R × d`) and output rows (`R × P`). With
    /// `bandwidth = None`, `h` minimises the leave-one-out error (outputs standardised) over
    /// [`default_bandwidths`].
    ///
    /// # Errors
    /// Shape mismatch, non-finite values, fewer than `d + 1` rows, a non-positive bandwidth or
    /// a negative ridge.
    pub fn fit(
        inputs: &[Vec<f64>],
        outputs: &[Vec<f64>],
        bandwidth: Option<f64>,
        ridge: f64,
    ) -> Result<Self> {
        let r = inputs.len();
        if r != outputs.len() {
            return Err(Error::ShapeMismatch(format!(
                "{r} input rows and {} output rows",
                outputs.len()
            )));
        }
        let d = inputs.first().map_or(0, |v| v.len());
        let p = outputs.first().map_or(0, |v| v.len());
        if d == 0 || p == 0 {
            return Err(Error::Empty("lwlr inputs/outputs"));
        }
        if r < d + 1 {
            return Err(Error::invalid(
                "trials",
                format!(
                    "LWLR with {d} inputs needs at least {} trials, got {r}",
                    d + 1
                ),
            ));
        }
        if inputs.iter().any(|v| v.len() != d) || outputs.iter().any(|v| v.len() != p) {
            return Err(Error::ShapeMismatch("rows of different lengths".into()));
        }
        let xin: Vec<f64> = inputs.iter().flatten().copied().collect();
        let yout: Vec<f64> = outputs.iter().flatten().copied().collect();
        ensure_finite("inputs", &xin)?;
        ensure_finite("outputs", &yout)?;
        if !(ridge.is_finite() && ridge >= 0.0) {
            return Err(Error::invalid(
                "ridge",
                format!("must be finite and >= 0, got {ridge}"),
            ));
        }
        let mean: Vec<f64> = (0..d)
            .map(|c| (0..r).map(|i| xin[i * d + c]).sum::<f64>() / r as f64)
            .collect();
        let scale: Vec<f64> = (0..d)
            .map(|c| {
                let v = (0..r)
                    .map(|i| (xin[i * d + c] - mean[c]).powi(2))
                    .sum::<f64>()
                    / r as f64;
                if v > 0.0 {
                    v.sqrt()
                } else {
                    1.0
                }
            })
            .collect();
        let std_in: Vec<f64> = (0..r * d)
            .map(|t| (xin[t] - mean[t % d]) / scale[t % d])
            .collect();
        let mut model = Self {
            n_inputs: d,
            n_outputs: p,
            inputs: std_in,
            outputs: yout,
            mean,
            scale,
            bandwidth: f64::INFINITY,
            ridge,
        };
        match bandwidth {
            Some(h) => {
                if h.is_nan() || h <= 0.0 {
                    return Err(Error::invalid("bandwidth", format!("must be > 0, got {h}")));
                }
                model.bandwidth = h;
            }
            None => {
                let mut best = (f64::INFINITY, f64::INFINITY);
                for h in default_bandwidths() {
                    model.bandwidth = h;
                    let e = model.loo_error(true)?;
                    if e < best.0 {
                        best = (e, h);
                    }
                }
                model.bandwidth = best.1;
            }
        }
        Ok(model)
    }

    fn n_rows(&self) -> usize {
        self.inputs.len() / self.n_inputs
    }

    /// Smoother weights `l_r(q)` for a standardised query: the prediction is `Σ_r l_r y_r`.
    fn smoother(&self, qs: &[f64]) -> Result<Vec<f64>> {
        let (d, r) = (self.n_inputs, self.n_rows());
        let m = d + 1;
        let kappa: Vec<f64> = (0..r)
            .map(|i| {
                if self.bandwidth.is_infinite() {
                    1.0
                } else {
                    let d2: f64 = (0..d)
                        .map(|c| (self.inputs[i * d + c] - qs[c]).powi(2))
                        .sum();
                    (-d2 / (2.0 * self.bandwidth * self.bandwidth)).exp()
                }
            })
            .collect();
        let mut a = vec![0.0; m * m];
        for (i, &k) in kappa.iter().enumerate() {
            let row: Vec<f64> = std::iter::once(1.0)
                .chain((0..d).map(|c| self.inputs[i * d + c] - qs[c]))
                .collect();
            for s in 0..m {
                for t in 0..m {
                    a[s * m + t] += k * row[s] * row[t];
                }
            }
        }
        let kmax = kappa.iter().fold(0.0f64, |x, &y| x.max(y));
        if kmax <= 0.0 {
            return Err(Error::Numerical(
                "LWLR query far outside the training inputs".into(),
            ));
        }
        for s in 1..m {
            a[s * m + s] += self.ridge;
        }
        let mut z = vec![0.0; m];
        z[0] = 1.0;
        solve_in_place(&mut a, &mut z, m, 0.0)?;
        Ok((0..r)
            .map(|i| {
                let dot: f64 = z[0]
                    + (0..d)
                        .map(|c| z[c + 1] * (self.inputs[i * d + c] - qs[c]))
                        .sum::<f64>();
                kappa[i] * dot
            })
            .collect())
    }

    fn standardize(&self, q: &[f64], clamp: bool) -> Vec<f64> {
        let (d, r) = (self.n_inputs, self.n_rows());
        (0..d)
            .map(|c| {
                let v = (q[c] - self.mean[c]) / self.scale[c];
                if clamp {
                    let lo = (0..r)
                        .map(|i| self.inputs[i * d + c])
                        .fold(f64::INFINITY, f64::min);
                    let hi = (0..r)
                        .map(|i| self.inputs[i * d + c])
                        .fold(f64::NEG_INFINITY, f64::max);
                    v.clamp(lo, hi)
                } else {
                    v
                }
            })
            .collect()
    }

    /// Prediction at `q` (raw input units), clamped to the training box.
    ///
    /// # Errors
    /// `q` of the wrong length or non-finite.
    pub fn predict(&self, q: &[f64]) -> Result<Vec<f64>> {
        self.predict_with(q, true)
    }

    /// Prediction at `q` with or without the clamp to the training box.
    ///
    /// # Errors
    /// As [`Lwlr::predict`].
    pub fn predict_with(&self, q: &[f64], clamp: bool) -> Result<Vec<f64>> {
        if q.len() != self.n_inputs {
            return Err(Error::ShapeMismatch(format!(
                "query of {} values for {} inputs",
                q.len(),
                self.n_inputs
            )));
        }
        ensure_finite("query", q)?;
        let l = self.smoother(&self.standardize(q, clamp))?;
        let p = self.n_outputs;
        let mut out = vec![0.0; p];
        for (i, li) in l.iter().enumerate() {
            for (o, y) in out.iter_mut().zip(&self.outputs[i * p..(i + 1) * p]) {
                *o += li * y;
            }
        }
        Ok(out)
    }

    /// Leave-one-out predictions at every training input (closed form `y − e/(1 − H_rr)`).
    ///
    /// # Errors
    /// A singular local system.
    pub fn loo_predictions(&self) -> Result<Vec<Vec<f64>>> {
        let (d, p, r) = (self.n_inputs, self.n_outputs, self.n_rows());
        (0..r)
            .map(|i| {
                let l = self.smoother(&self.inputs[i * d..(i + 1) * d])?;
                let h = l[i];
                let denom = 1.0 - h;
                if denom.abs() < 1e-12 {
                    return Err(Error::Numerical("leave-one-out leverage of 1".into()));
                }
                Ok((0..p)
                    .map(|o| {
                        let fit: f64 = (0..r).map(|t| l[t] * self.outputs[t * p + o]).sum();
                        let y = self.outputs[i * p + o];
                        y - (y - fit) / denom
                    })
                    .collect())
            })
            .collect()
    }

    /// Mean squared leave-one-out error, each output divided by its standard deviation when
    /// `standardized`.
    ///
    /// # Errors
    /// As [`Lwlr::loo_predictions`].
    pub fn loo_error(&self, standardized: bool) -> Result<f64> {
        let (p, r) = (self.n_outputs, self.n_rows());
        let pred = match self.loo_predictions() {
            Ok(v) => v,
            Err(_) => return Ok(f64::INFINITY),
        };
        let mut total = 0.0;
        #[allow(clippy::needless_range_loop)]
        for o in 0..p {
            let mean = (0..r).map(|i| self.outputs[i * p + o]).sum::<f64>() / r as f64;
            let var = (0..r)
                .map(|i| (self.outputs[i * p + o] - mean).powi(2))
                .sum::<f64>()
                / r as f64;
            let w = if standardized {
                if var > 0.0 {
                    1.0 / var
                } else {
                    0.0
                }
            } else {
                1.0
            };
            total += w
                * (0..r)
                    .map(|i| (pred[i][o] - self.outputs[i * p + o]).powi(2))
                    .sum::<f64>();
        }
        Ok(total / (r * p) as f64)
    }
}
