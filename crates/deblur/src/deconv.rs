//! Non-blind deconvolution of one periodic window with a uniform kernel: the hyper-Laplacian
//! solver of Krishnan & Fergus 2009 (paper eqs. 7-8), its multi-frame extension (eq. 9), and
//! the Wiener and Richardson-Lucy baselines of Table 1.

use std::sync::Arc;

use num_complex::Complex32;
use wscg_math::{Error, Image, Result};

use crate::spectral::{Grid, Scratch};
use crate::wstep::WStepTable;

wscg_math::params! {
    /// Parameters of the hyper-Laplacian solver (paper eqs. 7-8, Krishnan & Fergus 2009).
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct HyperLaplacianParams {
        /// Data weight `lambda` for intensities in `[0, 1]`. `None` (default): derived from
        /// the input's noise level, `0.3 / sigma^2` with `sigma` from
        /// [`crate::noise::estimate_noise`] (see [`crate::noise`]); `Some(2000.0)` is KF's
        /// demo value that the paper uses ([`HyperLaplacianParams::paper`]).
        pub lambda: Option<f32>,
        /// Gradient exponent `alpha` in `(0, 2]` (default 1/2, the paper's choice).
        pub alpha: f32,
        /// First penalty weight `beta_0` (default 1).
        pub beta0: f32,
        /// Factor between penalty weights (default `2 sqrt 2`).
        pub beta_rate: f32,
        /// Continuation stops once `beta >= beta_max` (default 256: six steps).
        pub beta_max: f32,
        /// Alternations of w- and I-steps per `beta` (default 1).
        pub inner: usize,
    }
}

impl Default for HyperLaplacianParams {
    fn default() -> Self {
        HyperLaplacianParams {
            lambda: None,
            alpha: 0.5,
            beta0: 1.0,
            beta_rate: 2.0 * std::f32::consts::SQRT_2,
            beta_max: 256.0,
            inner: 1,
        }
    }
}

impl HyperLaplacianParams {
    /// The paper's setting: the defaults with KF's fixed `lambda = 2000`.
    pub fn paper() -> Self {
        Self::default().lambda(Some(2000.0))
    }

    /// The data weight for the blurred input `image`: the fixed `lambda`, or the noise-aware
    /// one (`0.3 / sigma^2`, [`crate::noise`]) when it is `None`.
    ///
    /// Errors: as [`crate::noise::estimate_noise`] when `lambda` is `None`.
    pub fn lambda_for(&self, image: &Image<f32>) -> Result<f32> {
        match self.lambda {
            Some(l) => Ok(l),
            None => {
                let sigma = crate::noise::estimate_noise(image)?;
                let l = crate::noise::lambda_for_noise(sigma);
                log::debug!("noise estimate {sigma:.5}: lambda {l:.0}");
                Ok(l)
            }
        }
    }

    /// Errors: `lambda <= 0`, `alpha` outside `(0, 2]`, a `beta` schedule that does not grow,
    /// `inner == 0`, non-finite values.
    pub fn validate(&self) -> Result<()> {
        if let Some(l) = self.lambda.filter(|l| !(l.is_finite() && *l > 0.0)) {
            return Err(Error::invalid(
                "lambda",
                format!("must be finite and > 0, got {l}"),
            ));
        }
        if !(self.alpha > 0.0 && self.alpha <= 2.0) {
            return Err(Error::invalid(
                "alpha",
                format!("must lie in (0, 2], got {}", self.alpha),
            ));
        }
        if !(self.beta0.is_finite() && self.beta0 > 0.0) {
            return Err(Error::invalid(
                "beta0",
                format!("must be finite and > 0, got {}", self.beta0),
            ));
        }
        if !(self.beta_rate.is_finite() && self.beta_rate > 1.0) {
            return Err(Error::invalid(
                "beta_rate",
                format!(
                    "the beta schedule must grow: beta_rate must be finite and > 1, got {}",
                    self.beta_rate
                ),
            ));
        }
        if !self.beta_max.is_finite() {
            return Err(Error::invalid(
                "beta_max",
                format!("must be finite, got {}", self.beta_max),
            ));
        }
        if self.inner == 0 {
            return Err(Error::invalid("inner", "must be >= 1"));
        }
        if self.betas().len() > 64 {
            return Err(Error::invalid(
                "beta_max",
                "the continuation would take more than 64 steps",
            ));
        }
        Ok(())
    }

    /// The continuation `beta_0, beta_0 r, ...` while `< beta_max` (at least one step).
    pub fn betas(&self) -> Vec<f32> {
        let mut out = vec![self.beta0];
        let mut b = self.beta0 * self.beta_rate;
        while b < self.beta_max && out.len() <= 64 {
            out.push(b);
            b *= self.beta_rate;
        }
        out
    }

    /// The w-step tables of the continuation.
    pub(crate) fn luts(&self) -> Vec<Arc<WStepTable>> {
        self.betas()
            .iter()
            .map(|&b| WStepTable::shared(self.alpha as f64, b as f64))
            .collect()
    }
}

/// Reusable buffers of one worker thread.
#[derive(Default)]
pub(crate) struct Work {
    pub spec: Vec<Complex32>,
    pub aux: Vec<Complex32>,
    pub scratch: Scratch,
}

/// KF half-quadratic splitting on one periodic window (eq. 8): from `I = B`, for every `beta`
/// of the continuation, `inner` times: the w-step per pixel on the differences of `I`, then
/// the I-step in closed form in the Fourier domain,
/// `I^ = [F_x^* w_x^ + F_y^* w_y^ + (l/b) K^* B^ + (mu/b) P^] / [|F_x|^2 + |F_y|^2 + (l/b) |K|^2 + mu/b]`,
/// where `P` is the multi-frame prior `sum_j nu_j I_j` and `mu` its weight (eq. 9; none for
/// the single-frame solver) and `lambda` the data weight ([`HyperLaplacianParams::lambda_for`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn hyper_laplacian(
    grid: &Grid,
    b: &[f32],
    otf: &[Complex32],
    prior: Option<(&[f32], f32)>,
    lambda: f32,
    p: &HyperLaplacianParams,
    luts: &[Arc<WStepTable>],
    work: &mut Work,
) -> Vec<f32> {
    let (rows, cols, n) = (grid.rows, grid.cols, grid.len());
    // Constant parts of the I-step: lambda K^* B^ + mu P^ and lambda |K|^2 + mu.
    grid.forward(b, &mut work.spec, &mut work.scratch);
    let mut num0: Vec<Complex32> = work
        .spec
        .iter()
        .zip(otf)
        .map(|(s, k)| k.conj() * s * lambda)
        .collect();
    let mut den0: Vec<f32> = otf.iter().map(|k| k.norm_sqr() * lambda).collect();
    if let Some((pr, mu)) = prior.filter(|(_, mu)| *mu > 0.0) {
        grid.forward(pr, &mut work.aux, &mut work.scratch);
        num0.iter_mut()
            .zip(&work.aux)
            .for_each(|(n, ph)| *n += ph * mu);
        den0.iter_mut().for_each(|d| *d += mu);
    }
    let mut img = b.to_vec();
    let mut wx = vec![0f32; n];
    let mut wy = vec![0f32; n];
    let mut div = vec![0f32; n];
    for lut in luts {
        let inv_beta = 1.0 / lut.beta() as f32;
        for _ in 0..p.inner {
            // w-step on the circular differences I(i, j) - I(i, j-1) and I(i, j) - I(i-1, j).
            for i in 0..rows {
                let up = if i == 0 { rows - 1 } else { i - 1 };
                let (r, ru) = (&img[i * cols..][..cols], &img[up * cols..][..cols]);
                let (wxr, wyr) = (&mut wx[i * cols..][..cols], &mut wy[i * cols..][..cols]);
                wxr[0] = lut.eval(r[0] - r[cols - 1]);
                for j in 1..cols {
                    wxr[j] = lut.eval(r[j] - r[j - 1]);
                }
                for j in 0..cols {
                    wyr[j] = lut.eval(r[j] - ru[j]);
                }
            }
            // Adjoint differences: w(i, j) - w(i, j+1) and w(i, j) - w(i+1, j).
            for i in 0..rows {
                let down = if i + 1 == rows { 0 } else { i + 1 };
                let (wxr, wyr, wyd) = (
                    &wx[i * cols..][..cols],
                    &wy[i * cols..][..cols],
                    &wy[down * cols..][..cols],
                );
                let d = &mut div[i * cols..][..cols];
                for j in 0..cols - 1 {
                    d[j] = wxr[j] - wxr[j + 1] + wyr[j] - wyd[j];
                }
                d[cols - 1] = wxr[cols - 1] - wxr[0] + wyr[cols - 1] - wyd[cols - 1];
            }
            grid.forward(&div, &mut work.spec, &mut work.scratch);
            // I^ = [F^* w^ + (lambda K^* B^ + mu P^) / beta] / [|F|^2 + (lambda |K|^2 + mu) / beta]
            for (((s, n0), d0), g) in work.spec.iter_mut().zip(&num0).zip(&den0).zip(&grid.grad2) {
                *s = (*s + n0 * inv_beta) * (1.0 / (g + d0 * inv_beta));
            }
            grid.inverse_real(&mut work.spec, &mut img, &mut work.scratch);
        }
    }
    img
}

/// Wiener deconvolution of one window: `I^ = K^* B^ / (|K|^2 + nsr)`.
pub(crate) fn wiener(
    grid: &Grid,
    b: &[f32],
    otf: &[Complex32],
    nsr: f32,
    work: &mut Work,
) -> Vec<f32> {
    grid.forward(b, &mut work.spec, &mut work.scratch);
    work.spec
        .iter_mut()
        .zip(otf)
        .for_each(|(s, k)| *s = k.conj() * *s / (k.norm_sqr() + nsr));
    let mut out = vec![0f32; grid.len()];
    grid.inverse_real(&mut work.spec, &mut out, &mut work.scratch);
    out
}

/// Richardson-Lucy on one window: `I <- I . K^T (B / (K I))`, from `I = max(B, 0)`.
pub(crate) fn richardson_lucy(
    grid: &Grid,
    b: &[f32],
    otf: &[Complex32],
    iters: usize,
    work: &mut Work,
) -> Vec<f32> {
    let n = grid.len();
    let mut img: Vec<f32> = b.iter().map(|v| v.max(0.0)).collect();
    let mut ratio = vec![0f32; n];
    let mut corr = vec![0f32; n];
    for _ in 0..iters {
        // Stops early on a cancellation request, which the tiling reports.
        if wscg_math::cancel::requested() {
            break;
        }
        grid.convolve(
            &img,
            otf,
            false,
            &mut ratio,
            &mut work.spec,
            &mut work.scratch,
        );
        for (t, &bv) in ratio.iter_mut().zip(b) {
            *t = bv.max(0.0) / t.max(1e-12);
        }
        grid.convolve(
            &ratio,
            otf,
            true,
            &mut corr,
            &mut work.spec,
            &mut work.scratch,
        );
        img.iter_mut()
            .zip(&corr)
            .for_each(|(v, c)| *v *= c.max(0.0));
    }
    img
}
