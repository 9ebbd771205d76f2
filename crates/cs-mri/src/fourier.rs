//! The unitary 2-D DFT `F` of the measurement model `y = P F x` (paper 11, eq. 1).
//!
//! k-space arrays are un-shifted: the DC sample is at index (0, 0), as numpy's `fft2`
//! returns it; [`wscg_math::fft::fftshift`] centres them for display.

use num_complex::Complex64;
use wscg_math::fft::{Direction, Plan2};
use wscg_math::Result;

/// A planned unitary 2-D FFT of `rows x cols` images.
pub struct Fourier {
    rows: usize,
    cols: usize,
    plan: Plan2<f64>,
    scale: f64,
}

impl Fourier {
    /// Plans the transform. Errors: a zero dimension.
    pub fn new(rows: usize, cols: usize) -> Result<Self> {
        Ok(Fourier {
            rows,
            cols,
            plan: Plan2::new(rows, cols)?,
            scale: 1.0 / ((rows * cols) as f64).sqrt(),
        })
    }

    /// `(rows, cols)`.
    pub fn shape(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }

    /// In place `x <- F x` (unitary).
    pub fn forward(&self, x: &mut [Complex64]) {
        self.plan.process_par(x, Direction::Forward);
        x.iter_mut().for_each(|v| *v *= self.scale);
    }

    /// In place `x <- F^H x` (unitary).
    pub fn inverse(&self, x: &mut [Complex64]) {
        self.plan.process_par(x, Direction::Inverse);
        x.iter_mut().for_each(|v| *v *= self.scale);
    }
}

/// Signed frequency of FFT index `i` on an axis of length `n` (numpy's `fftfreq(n) * n`).
pub fn signed_frequency(i: usize, n: usize) -> i64 {
    if i < n.div_ceil(2) {
        i as i64
    } else {
        i as i64 - n as i64
    }
}
