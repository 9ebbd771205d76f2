//! Plain containers for multi-trial joint-angle data.

use wscg_math::error::{ensure_finite, ensure_nonempty};
use wscg_math::{Error, Result};

/// `R` trials × `I` channels × `N` samples, row-major (`data[(r·I + i)·N + n]`), the layout of a
/// numpy array of shape `(R, I, N)`. Each trial's action is time-normalised to one period.
#[derive(Clone, Debug, PartialEq)]
pub struct TrialSet {
    /// Number of trials `R`.
    pub n_trials: usize,
    /// Number of channels `I` (joint-angle components).
    pub n_channels: usize,
    /// Samples per period `N`.
    pub n_samples: usize,
    /// The values, `R·I·N` of them.
    pub data: Vec<f64>,
}

impl TrialSet {
    /// Checks the shape and that every value is finite.
    ///
    /// # Errors
    /// [`Error::Empty`] for a zero dimension, [`Error::ShapeMismatch`] when `data` has the
    /// wrong length, [`Error::NonFinite`] for NaN or infinity.
    pub fn new(
        n_trials: usize,
        n_channels: usize,
        n_samples: usize,
        data: Vec<f64>,
    ) -> Result<Self> {
        ensure_nonempty("trials", n_trials)?;
        ensure_nonempty("channels", n_channels)?;
        ensure_nonempty("samples", n_samples)?;
        if data.len() != n_trials * n_channels * n_samples {
            return Err(Error::ShapeMismatch(format!(
                "{} values for {n_trials} trials x {n_channels} channels x {n_samples} samples",
                data.len()
            )));
        }
        ensure_finite("trials", &data)?;
        Ok(Self {
            n_trials,
            n_channels,
            n_samples,
            data,
        })
    }

    /// Stacks per-trial `I × N` blocks, which must all have the same shape.
    ///
    /// # Errors
    /// As [`TrialSet::new`], and [`Error::ShapeMismatch`] naming the first trial whose length
    /// differs (trials of different sample counts).
    pub fn stack(trials: &[Vec<f64>], n_channels: usize, n_samples: usize) -> Result<Self> {
        ensure_nonempty("trials", trials.len())?;
        let len = n_channels * n_samples;
        let mut data = Vec::with_capacity(trials.len() * len);
        for (r, t) in trials.iter().enumerate() {
            if t.len() != len {
                return Err(Error::ShapeMismatch(format!(
                    "trial {r} has {} values, expected {n_channels} channels x {n_samples} samples",
                    t.len()
                )));
            }
            data.extend_from_slice(t);
        }
        Self::new(trials.len(), n_channels, n_samples, data)
    }

    /// Samples of channel `i` in trial `r`.
    pub fn row(&self, r: usize, i: usize) -> &[f64] {
        let n = self.n_samples;
        let o = (r * self.n_channels + i) * n;
        &self.data[o..o + n]
    }

    /// A zero-filled set of the same shape.
    pub fn zeros_like(&self) -> Self {
        Self {
            data: vec![0.0; self.data.len()],
            ..*self
        }
    }

    /// `‖X‖²_F`.
    pub fn energy(&self) -> f64 {
        self.data.iter().map(|v| v * v).sum()
    }
}

/// Approximation quality `Q = 1 − ‖X − X̂‖²_F / ‖X‖²_F` (paper Fig. 4).
///
/// # Errors
/// [`Error::ShapeMismatch`] for different shapes, [`Error::InvalidArgument`] when `X` is zero.
pub fn quality(x: &TrialSet, xhat: &TrialSet) -> Result<f64> {
    if (x.n_trials, x.n_channels, x.n_samples) != (xhat.n_trials, xhat.n_channels, xhat.n_samples) {
        return Err(Error::ShapeMismatch(format!(
            "data {}x{}x{} vs approximation {}x{}x{}",
            x.n_trials, x.n_channels, x.n_samples, xhat.n_trials, xhat.n_channels, xhat.n_samples
        )));
    }
    let total = x.energy();
    if total <= 0.0 {
        return Err(Error::invalid("x", "all values are zero; Q is undefined"));
    }
    let err: f64 = x
        .data
        .iter()
        .zip(&xhat.data)
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    Ok(1.0 - err / total)
}
