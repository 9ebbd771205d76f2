//! Undersampled k-space data: the measurements `y = P F x + noise` of paper 11, eq. 1.

use num_complex::Complex64;
use wscg_math::{Error, Result};

use crate::fourier::Fourier;

/// Measured k-space on a full `rows x cols` grid (un-shifted, DC at (0, 0), unitary FFT
/// scaling) and the sampling mask `P`. Values at unsampled positions are ignored.
#[derive(Clone, Debug, PartialEq)]
pub struct KSpace {
    rows: usize,
    cols: usize,
    data: Vec<Complex64>,
    mask: Vec<bool>,
    sampled: Vec<usize>,
}

impl KSpace {
    /// Validates and wraps k-space data and its mask (both row-major `rows x cols`).
    ///
    /// Errors: lengths that do not match `rows x cols`, an empty grid, a mask without a
    /// single sample, a non-finite sampled value.
    pub fn new(rows: usize, cols: usize, data: Vec<Complex64>, mask: Vec<bool>) -> Result<Self> {
        if rows == 0 || cols == 0 {
            return Err(Error::Empty("kspace"));
        }
        if data.len() != rows * cols {
            return Err(Error::ShapeMismatch(format!(
                "kspace has {} values, not {rows} x {cols}",
                data.len()
            )));
        }
        if mask.len() != rows * cols {
            return Err(Error::ShapeMismatch(format!(
                "the mask has {} values but the k-space is {rows} x {cols}",
                mask.len()
            )));
        }
        let sampled: Vec<usize> = (0..mask.len()).filter(|&k| mask[k]).collect();
        if sampled.is_empty() {
            return Err(Error::invalid("mask", "samples no k-space position"));
        }
        if let Some(&k) = sampled
            .iter()
            .find(|&&k| !(data[k].re.is_finite() && data[k].im.is_finite()))
        {
            return Err(Error::NonFinite {
                name: "kspace",
                index: k,
            });
        }
        let mut data = data;
        for (v, &m) in data.iter_mut().zip(&mask) {
            if !m {
                *v = Complex64::new(0.0, 0.0);
            }
        }
        Ok(KSpace {
            rows,
            cols,
            data,
            mask,
            sampled,
        })
    }

    /// Simulates measurements of an image: `y = P F x` with the unitary FFT.
    pub fn simulate(
        rows: usize,
        cols: usize,
        image: &[Complex64],
        mask: Vec<bool>,
    ) -> Result<Self> {
        if image.len() != rows * cols {
            return Err(Error::ShapeMismatch(format!(
                "the image has {} values, not {rows} x {cols}",
                image.len()
            )));
        }
        let mut data = image.to_vec();
        Fourier::new(rows, cols)?.forward(&mut data);
        KSpace::new(rows, cols, data, mask)
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// The data on the full grid (zeros where not sampled).
    pub fn data(&self) -> &[Complex64] {
        &self.data
    }

    /// The mask.
    pub fn mask(&self) -> &[bool] {
        &self.mask
    }

    /// Flat indices of the sampled positions, increasing.
    pub fn sampled(&self) -> &[usize] {
        &self.sampled
    }

    /// The sampled values `y`, in [`KSpace::sampled`] order.
    pub fn values(&self) -> Vec<Complex64> {
        self.sampled.iter().map(|&k| self.data[k]).collect()
    }

    /// Sampling rate `m / n`.
    pub fn rate(&self) -> f64 {
        self.sampled.len() as f64 / self.data.len() as f64
    }

    /// The zero-filled reconstruction `x0 = F^H P^T y` (paper 11, section 2.3 initialisation).
    pub fn zero_filled(&self) -> Vec<Complex64> {
        let mut x = self.data.clone();
        Fourier::new(self.rows, self.cols)
            .expect("non-empty grid")
            .inverse(&mut x);
        x
    }

    /// Adds complex white Gaussian noise of standard deviation `sigma` per real component to
    /// the sampled values (seeded).
    pub fn add_noise(&mut self, sigma: f64, seed: u64) -> Result<()> {
        if !(sigma >= 0.0 && sigma.is_finite()) {
            return Err(Error::invalid(
                "sigma",
                format!("{sigma} is not a finite value >= 0"),
            ));
        }
        let n = wscg_math::rng::normal_vec(
            seed,
            2 * self.sampled.len(),
            0.0,
            sigma.max(f64::MIN_POSITIVE),
        )?;
        for (i, &k) in self.sampled.iter().enumerate() {
            self.data[k] += Complex64::new(n[2 * i], n[2 * i + 1]);
        }
        Ok(())
    }

    /// `||F_u x - y||_2` for an image `x`.
    pub fn residual(&self, x: &[Complex64]) -> Result<f64> {
        if x.len() != self.data.len() {
            return Err(Error::ShapeMismatch(format!(
                "the image has {} values, not {} x {}",
                x.len(),
                self.rows,
                self.cols
            )));
        }
        let mut s = x.to_vec();
        Fourier::new(self.rows, self.cols)?.forward(&mut s);
        Ok(self
            .sampled
            .iter()
            .map(|&k| (s[k] - self.data[k]).norm_sqr())
            .sum::<f64>()
            .sqrt())
    }
}

/// The noise radius of the discrepancy principle (paper 11, section 2.2 after Afonso et al.
/// 2011): `eps = sigma sqrt(2m + 4 sqrt(m))`, the mean plus two standard deviations of the
/// norm of `m` complex Gaussian samples with standard deviation `sigma` per component.
pub fn noise_epsilon(sigma: f64, m: usize) -> f64 {
    let m = m as f64;
    sigma * (2.0 * m + 4.0 * m.sqrt()).sqrt()
}
