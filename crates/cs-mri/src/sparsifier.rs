//! Sparsifying transforms `Psi` of complex images (paper 11, eq. 2): the UDCT applied to the
//! real and imaginary parts separately (the paper's choice), an orthonormal Daubechies
//! wavelet applied the same way, and the identity.
//!
//! Every transform here except the SFLCT is a Parseval frame (`Psi^H Psi = I`), which
//! C-SALSA's closed-form x-update and the TV-of-synthesis prox rely on; the SFLCT (a frame
//! with bounds near 1) makes C-SALSA solve its x-update by preconditioned CG. Coefficients
//! live in a [`CoeffVec`]: real coefficients are shrunk one by one, complex ones by
//! magnitude.

use std::ops::Range;

use num_complex::Complex64;
use rayon::prelude::*;
use wscg_math::wavelet::{Daubechies, Wavelet2};
use wscg_math::{Error, Result};

use crate::fdct::{Fdct, FdctParams};
use crate::fourier::Fourier;
use crate::sflct::{Redundancy, Sflct, SflctParams};
use crate::udct::{Udct, UdctParams};

/// Coefficients of a [`Sparsifier`]: real ones and complex ones.
#[derive(Clone, Debug, PartialEq)]
pub struct CoeffVec {
    /// Real coefficients.
    pub real: Vec<f64>,
    /// Complex coefficients (thresholded by magnitude).
    pub complex: Vec<Complex64>,
}

impl CoeffVec {
    /// Zeros of the given sizes.
    pub fn zeros(real: usize, complex: usize) -> Self {
        CoeffVec {
            real: vec![0.0; real],
            complex: vec![Complex64::new(0.0, 0.0); complex],
        }
    }

    /// `self = a + b`, element-wise.
    pub fn set_sum(&mut self, a: &CoeffVec, b: &CoeffVec) {
        self.real
            .par_iter_mut()
            .zip(a.real.par_iter().zip(&b.real))
            .for_each(|(o, (x, y))| *o = x + y);
        self.complex
            .par_iter_mut()
            .zip(a.complex.par_iter().zip(&b.complex))
            .for_each(|(o, (x, y))| *o = x + y);
    }

    /// `self -= other`.
    pub fn sub_assign(&mut self, other: &CoeffVec) {
        self.real
            .par_iter_mut()
            .zip(&other.real)
            .for_each(|(a, b)| *a -= b);
        self.complex
            .par_iter_mut()
            .zip(&other.complex)
            .for_each(|(a, b)| *a -= b);
    }

    /// `self += other`.
    pub fn add_assign(&mut self, other: &CoeffVec) {
        self.real
            .par_iter_mut()
            .zip(&other.real)
            .for_each(|(a, b)| *a += b);
        self.complex
            .par_iter_mut()
            .zip(&other.complex)
            .for_each(|(a, b)| *a += b);
    }

    /// The l1 norm: `sum |real| + sum |complex|`.
    pub fn l1(&self) -> f64 {
        self.real.par_iter().map(|v| v.abs()).sum::<f64>()
            + self.complex.par_iter().map(|v| v.norm()).sum::<f64>()
    }

    /// Sum of squares of every real and imaginary part.
    pub fn energy(&self) -> f64 {
        self.real.par_iter().map(|v| v * v).sum::<f64>()
            + self.complex.par_iter().map(|v| v.norm_sqr()).sum::<f64>()
    }

    /// Real inner product.
    pub fn dot(&self, other: &CoeffVec) -> f64 {
        self.real
            .iter()
            .zip(&other.real)
            .map(|(a, b)| a * b)
            .sum::<f64>()
            + self
                .complex
                .iter()
                .zip(&other.complex)
                .map(|(a, b)| (a.conj() * b).re)
                .sum::<f64>()
    }
}

/// A real-linear transform of complex `rows x cols` images into coefficients.
pub trait Sparsifier: Send + Sync {
    /// A short name for reports ("udct", "db4", ...).
    fn name(&self) -> String;
    /// The image shape.
    fn shape(&self) -> (usize, usize);
    /// Whether `Psi^H Psi = I`.
    fn is_parseval(&self) -> bool;
    /// Numbers of real and complex coefficients.
    fn coeff_len(&self) -> (usize, usize);
    /// Ranges of [`CoeffVec::real`] holding low-pass (approximation) coefficients.
    fn lowpass_ranges(&self) -> Vec<Range<usize>>;
    /// Ranges of [`CoeffVec::complex`] holding low-pass coefficients (none by default).
    fn lowpass_complex_ranges(&self) -> Vec<Range<usize>> {
        Vec::new()
    }
    /// `Psi x` for an image `x`.
    fn analysis(&self, x: &[Complex64], out: &mut CoeffVec);
    /// `Psi^H c`.
    fn synthesis(&self, c: &CoeffVec, out: &mut [Complex64]);
    /// The unitary FFT of the image shape (shared with the solvers).
    fn fourier(&self) -> &Fourier;

    /// Zero coefficients.
    fn zeros(&self) -> CoeffVec {
        let (r, c) = self.coeff_len();
        CoeffVec::zeros(r, c)
    }

    /// `Psi x` given the unitary spectrum `F x` of the image.
    fn analysis_spectrum(&self, xhat: &[Complex64], out: &mut CoeffVec) {
        let mut x = xhat.to_vec();
        self.fourier().inverse(&mut x);
        self.analysis(&x, out);
    }

    /// The unitary spectrum `F Psi^H c`.
    fn synthesis_spectrum(&self, c: &CoeffVec, out: &mut [Complex64]) {
        self.synthesis(c, out);
        self.fourier().forward(out);
    }
}

/// The paper's prior: the UDCT of the real part and of the imaginary part, concatenated
/// (`Psi x = (U Re x, U Im x)`). Real coefficients: `[low-pass(Re), low-pass(Im)]`; complex:
/// `[bands(Re), bands(Im)]`. Works on spectra directly, so a C-SALSA iteration needs no full
/// size FFT.
pub struct UdctSparsifier {
    udct: Udct,
    fourier: Fourier,
}

impl UdctSparsifier {
    /// Plans the transform for `rows x cols` images.
    pub fn new(rows: usize, cols: usize, config: &UdctParams) -> Result<Self> {
        Ok(UdctSparsifier {
            udct: Udct::new(rows, cols, config)?,
            fourier: Fourier::new(rows, cols)?,
        })
    }

    /// The underlying transform.
    pub fn udct(&self) -> &Udct {
        &self.udct
    }
}

impl Sparsifier for UdctSparsifier {
    fn name(&self) -> String {
        "udct".into()
    }
    fn shape(&self) -> (usize, usize) {
        self.udct.shape()
    }
    fn is_parseval(&self) -> bool {
        self.udct.config().tight
    }
    fn coeff_len(&self) -> (usize, usize) {
        (
            2 * self.udct.zeros().lowpass.len(),
            2 * self.udct.band_coeff_len(),
        )
    }
    fn lowpass_ranges(&self) -> Vec<Range<usize>> {
        std::iter::once(0..self.coeff_len().0).collect()
    }
    fn fourier(&self) -> &Fourier {
        &self.fourier
    }

    fn analysis(&self, x: &[Complex64], out: &mut CoeffVec) {
        let mut s = x.to_vec();
        self.fourier.forward(&mut s);
        self.analysis_spectrum(&s, out);
    }

    fn synthesis(&self, c: &CoeffVec, out: &mut [Complex64]) {
        self.synthesis_spectrum(c, out);
        self.fourier.inverse(out);
    }

    fn analysis_spectrum(&self, xhat: &[Complex64], out: &mut CoeffVec) {
        let (rows, cols) = self.udct.shape();
        let scale = 1.0 / ((rows * cols) as f64).sqrt();
        let (nl, nb) = (out.real.len() / 2, out.complex.len() / 2);
        let (lr, li) = out.real.split_at_mut(nl);
        let (br, bi) = out.complex.split_at_mut(nb);
        self.udct.forward_pair(xhat, scale, [lr, li], [br, bi]);
    }

    fn synthesis_spectrum(&self, c: &CoeffVec, out: &mut [Complex64]) {
        let (rows, cols) = self.udct.shape();
        let (nl, nb) = (c.real.len() / 2, c.complex.len() / 2);
        self.udct.backward_pair(
            [&c.real[..nl], &c.real[nl..]],
            [&c.complex[..nb], &c.complex[nb..]],
            out,
        );
        let scale = 1.0 / ((rows * cols) as f64).sqrt();
        out.par_iter_mut().for_each(|v| *v *= scale);
    }
}

/// An orthonormal Daubechies wavelet (periodized) applied to the real and imaginary parts
/// separately: real coefficients `[W Re x, W Im x]` in the Mallat layout.
pub struct WaveletSparsifier {
    wavelet: Wavelet2,
    fourier: Fourier,
}

impl WaveletSparsifier {
    /// `db<order>` with `levels` levels for `rows x cols` images (the paper's baselines use
    /// db4 and 4 levels).
    pub fn new(rows: usize, cols: usize, order: usize, levels: usize) -> Result<Self> {
        Ok(WaveletSparsifier {
            wavelet: Wavelet2::new(rows, cols, Daubechies::new(order)?, levels)?,
            fourier: Fourier::new(rows, cols)?,
        })
    }

    /// The underlying transform.
    pub fn wavelet(&self) -> &Wavelet2 {
        &self.wavelet
    }
}

impl Sparsifier for WaveletSparsifier {
    fn name(&self) -> String {
        format!("db{}", self.wavelet.filter().order())
    }
    fn shape(&self) -> (usize, usize) {
        self.wavelet.shape()
    }
    fn is_parseval(&self) -> bool {
        true
    }
    fn coeff_len(&self) -> (usize, usize) {
        let (r, c) = self.wavelet.shape();
        (2 * r * c, 0)
    }
    fn lowpass_ranges(&self) -> Vec<Range<usize>> {
        let (r, c) = self.wavelet.shape();
        let (ar, ac) = (r >> self.wavelet.levels(), c >> self.wavelet.levels());
        (0..2)
            .flat_map(|p| (0..ar).map(move |i| p * r * c + i * c..p * r * c + i * c + ac))
            .collect()
    }
    fn fourier(&self) -> &Fourier {
        &self.fourier
    }

    fn analysis(&self, x: &[Complex64], out: &mut CoeffVec) {
        let n = x.len();
        let re: Vec<f64> = x.iter().map(|v| v.re).collect();
        let im: Vec<f64> = x.iter().map(|v| v.im).collect();
        let (a, b) = out.real.split_at_mut(n);
        rayon::join(
            || self.wavelet.forward(&re, a),
            || self.wavelet.forward(&im, b),
        );
    }

    fn synthesis(&self, c: &CoeffVec, out: &mut [Complex64]) {
        let n = out.len();
        let mut re = vec![0.0; n];
        let mut im = vec![0.0; n];
        rayon::join(
            || self.wavelet.inverse(&c.real[..n], &mut re),
            || self.wavelet.inverse(&c.real[n..], &mut im),
        );
        out.iter_mut()
            .zip(re.iter().zip(&im))
            .for_each(|(o, (&a, &b))| *o = Complex64::new(a, b));
    }
}

/// The wrapping FDCT (Candes et al. 2006) of the complex image, CurveLab's complex-valued
/// transform: complex coefficients `[coarse, wedges..., finest]`, the coarse block being the
/// low-pass. A Parseval frame that works on spectra directly, like [`UdctSparsifier`].
pub struct FdctSparsifier {
    fdct: Fdct,
    fourier: Fourier,
}

impl FdctSparsifier {
    /// Plans the transform for `rows x cols` images.
    pub fn new(rows: usize, cols: usize, config: &FdctParams) -> Result<Self> {
        Ok(FdctSparsifier {
            fdct: Fdct::new(rows, cols, config)?,
            fourier: Fourier::new(rows, cols)?,
        })
    }

    /// The underlying transform.
    pub fn fdct(&self) -> &Fdct {
        &self.fdct
    }
}

impl Sparsifier for FdctSparsifier {
    fn name(&self) -> String {
        "fdct".into()
    }
    fn shape(&self) -> (usize, usize) {
        self.fdct.shape()
    }
    fn is_parseval(&self) -> bool {
        true
    }
    fn coeff_len(&self) -> (usize, usize) {
        (0, self.fdct.coeff_len())
    }
    fn lowpass_ranges(&self) -> Vec<Range<usize>> {
        Vec::new()
    }
    fn lowpass_complex_ranges(&self) -> Vec<Range<usize>> {
        self.fdct
            .bands()
            .into_iter()
            .filter(|b| b.scale == 0)
            .map(|b| b.range)
            .collect()
    }
    fn fourier(&self) -> &Fourier {
        &self.fourier
    }

    fn analysis(&self, x: &[Complex64], out: &mut CoeffVec) {
        let mut s = x.to_vec();
        self.fourier.forward(&mut s);
        self.fdct.forward_spectrum(&s, &mut out.complex);
    }

    fn synthesis(&self, c: &CoeffVec, out: &mut [Complex64]) {
        self.fdct.backward_spectrum(&c.complex, out);
        self.fourier.inverse(out);
    }

    fn analysis_spectrum(&self, xhat: &[Complex64], out: &mut CoeffVec) {
        self.fdct.forward_spectrum(xhat, &mut out.complex);
    }

    fn synthesis_spectrum(&self, c: &CoeffVec, out: &mut [Complex64]) {
        self.fdct.backward_spectrum(&c.complex, out);
    }
}

/// The sharp-frequency-localized contourlet ([`Sflct`], Lu & Do 2006) of the real and
/// imaginary parts, the LRSFLCT / MRSFLCT priors of the paper's Tables 2 and 3: real
/// coefficients `[S Re x, S Im x]`, the low-pass band of each half unshrunk on request. Not a
/// Parseval frame (the PKVA ladder filter bank is only nearly orthogonal).
pub struct SflctSparsifier {
    sflct: Sflct,
}

impl SflctSparsifier {
    /// Plans the transform for `rows x cols` images.
    pub fn new(rows: usize, cols: usize, config: &SflctParams) -> Result<Self> {
        Ok(SflctSparsifier {
            sflct: Sflct::new(rows, cols, config)?,
        })
    }

    /// The underlying transform.
    pub fn sflct(&self) -> &Sflct {
        &self.sflct
    }
}

impl Sparsifier for SflctSparsifier {
    fn name(&self) -> String {
        match self.sflct.config().redundancy {
            Redundancy::Less => "lrsflct".into(),
            Redundancy::More => "mrsflct".into(),
        }
    }
    fn shape(&self) -> (usize, usize) {
        self.sflct.shape()
    }
    fn is_parseval(&self) -> bool {
        false
    }
    fn coeff_len(&self) -> (usize, usize) {
        (2 * self.sflct.coeff_len(), 0)
    }
    fn lowpass_ranges(&self) -> Vec<Range<usize>> {
        let m = self.sflct.coeff_len();
        let low = self.sflct.bands()[0].range.clone();
        vec![low.clone(), low.start + m..low.end + m]
    }
    fn fourier(&self) -> &Fourier {
        self.sflct.fourier()
    }

    fn analysis(&self, x: &[Complex64], out: &mut CoeffVec) {
        let mut s = x.to_vec();
        self.sflct.fourier().forward(&mut s);
        self.analysis_spectrum(&s, out);
    }

    fn synthesis(&self, c: &CoeffVec, out: &mut [Complex64]) {
        self.synthesis_spectrum(c, out);
        self.sflct.fourier().inverse(out);
    }

    fn analysis_spectrum(&self, xhat: &[Complex64], out: &mut CoeffVec) {
        // The SFLCT is real: the real and imaginary parts of the complex image's
        // coefficients are the transforms of its real and imaginary parts.
        let m = self.sflct.coeff_len();
        let mut c = vec![Complex64::new(0.0, 0.0); m];
        self.sflct.forward_spectrum(xhat, &mut c);
        let (re, im) = out.real.split_at_mut(m);
        re.par_iter_mut()
            .zip(im.par_iter_mut())
            .zip(&c)
            .for_each(|((a, b), v)| {
                *a = v.re;
                *b = v.im;
            });
    }

    fn synthesis_spectrum(&self, c: &CoeffVec, out: &mut [Complex64]) {
        let m = self.sflct.coeff_len();
        let z: Vec<Complex64> = c.real[..m]
            .par_iter()
            .zip(&c.real[m..])
            .map(|(&a, &b)| Complex64::new(a, b))
            .collect();
        self.sflct.backward_spectrum(&z, out, true);
    }
}

/// The identity: the image's own pixels, shrunk by magnitude (for images sparse in space).
pub struct IdentitySparsifier {
    fourier: Fourier,
}

impl IdentitySparsifier {
    /// For `rows x cols` images.
    pub fn new(rows: usize, cols: usize) -> Result<Self> {
        Ok(IdentitySparsifier {
            fourier: Fourier::new(rows, cols)?,
        })
    }
}

impl Sparsifier for IdentitySparsifier {
    fn name(&self) -> String {
        "identity".into()
    }
    fn shape(&self) -> (usize, usize) {
        self.fourier.shape()
    }
    fn is_parseval(&self) -> bool {
        true
    }
    fn coeff_len(&self) -> (usize, usize) {
        let (r, c) = self.fourier.shape();
        (0, r * c)
    }
    fn lowpass_ranges(&self) -> Vec<Range<usize>> {
        Vec::new()
    }
    fn fourier(&self) -> &Fourier {
        &self.fourier
    }
    fn analysis(&self, x: &[Complex64], out: &mut CoeffVec) {
        out.complex.copy_from_slice(x);
    }
    fn synthesis(&self, c: &CoeffVec, out: &mut [Complex64]) {
        out.copy_from_slice(&c.complex);
    }
}

/// The C-SALSA `tau0` chosen for a named prior by grid search on the development image (the
/// phantom turned by 90 degrees with its own smooth phase and mask; the protocol is the test
/// `tune_on_development_image`): 0.01 for the UDCT and the LRSFLCT, 0.02 for the FDCT and the
/// MRSFLCT, 0.04 for wavelets and the identity.
pub fn tuned_tau0(prior: &str) -> f64 {
    match prior {
        "udct" | "lrsflct" => 0.01,
        "fdct" | "mrsflct" => 0.02,
        _ => 0.04,
    }
}

wscg_math::params! {
    /// Configuration of the priors [`by_name`] builds.
    #[derive(Clone, Debug, PartialEq)]
    pub struct PriorParams {
        /// The UDCT of `"udct"`.
        pub udct: UdctParams,
        /// The FDCT of `"fdct"`.
        pub fdct: FdctParams,
        /// Directional levels per scale (coarsest first) of `"lrsflct"` and `"mrsflct"`.
        pub sflct_levels: Vec<usize>,
        /// Levels of the `"db<N>"` wavelets (the paper's baselines: 4).
        pub levels: usize,
    }
}

impl Default for PriorParams {
    fn default() -> Self {
        PriorParams {
            udct: UdctParams::default(),
            fdct: FdctParams::default(),
            sflct_levels: SflctParams::default().dfb_levels,
            levels: 4,
        }
    }
}

impl PriorParams {
    /// Checks every prior's configuration, whichever [`by_name`] builds: the UDCT's and the
    /// FDCT's (see [`UdctParams::validate`] and [`FdctParams::validate`]), 1 to 6 SFLCT
    /// scales of at most 8 directional levels, at least one wavelet level.
    pub fn validate(&self) -> Result<()> {
        self.udct.validate()?;
        self.fdct.validate()?;
        crate::sflct::check_dfb_levels("sflct_levels", &self.sflct_levels)?;
        if self.levels == 0 {
            return Err(Error::invalid("levels", "must be at least 1"));
        }
        Ok(())
    }
}

/// The priors a user can name: `"udct"`, `"fdct"`, `"lrsflct"`, `"mrsflct"`, `"db1"` ...
/// `"db8"`, `"identity"`, configured by `config`.
pub fn by_name(
    name: &str,
    rows: usize,
    cols: usize,
    config: &PriorParams,
) -> Result<Box<dyn Sparsifier>> {
    config.validate()?;
    match name {
        "udct" => Ok(Box::new(UdctSparsifier::new(rows, cols, &config.udct)?)),
        "fdct" => Ok(Box::new(FdctSparsifier::new(rows, cols, &config.fdct)?)),
        "identity" => Ok(Box::new(IdentitySparsifier::new(rows, cols)?)),
        "lrsflct" | "mrsflct" => {
            let redundancy = if name == "lrsflct" {
                Redundancy::Less
            } else {
                Redundancy::More
            };
            let cfg = SflctParams {
                redundancy,
                dfb_levels: config.sflct_levels.clone(),
            };
            Ok(Box::new(SflctSparsifier::new(rows, cols, &cfg)?))
        }
        _ => {
            let order = name
                .strip_prefix("db")
                .and_then(|o| o.parse::<usize>().ok())
                .ok_or_else(|| {
                    Error::invalid(
                        "prior",
                        format!("{name:?} is not a valid prior. Valid priors are \"udct\", \"fdct\", \"lrsflct\", \"mrsflct\", \"db1\" ... \"db8\" and \"identity\""),
                    )
                })?;
            Ok(Box::new(WaveletSparsifier::new(
                rows,
                cols,
                order,
                config.levels,
            )?))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wscg_math::rng;

    fn random(n: usize, seed: u64) -> Vec<Complex64> {
        rng::complex_normal_vec(seed, n, 1.0).unwrap()
    }

    #[test]
    fn udct_pair_equals_two_real_transforms_and_is_parseval() {
        let (r, c) = (64, 96);
        for wedges in [vec![[6, 6]], vec![[3, 3], [6, 6]]] {
            let cfg = UdctParams {
                wedges,
                ..Default::default()
            };
            let psi = UdctSparsifier::new(r, c, &cfg).unwrap();
            let x = random(r * c, 4);
            let mut co = psi.zeros();
            psi.analysis(&x, &mut co);
            let re: Vec<f64> = x.iter().map(|v| v.re).collect();
            let im: Vec<f64> = x.iter().map(|v| v.im).collect();
            let (a, b) = (
                psi.udct().forward(&re).unwrap(),
                psi.udct().forward(&im).unwrap(),
            );
            let (nl, nb) = (a.lowpass.len(), a.bands.len());
            let close = |u: &[f64], v: &[f64]| u.iter().zip(v).all(|(p, q)| (p - q).abs() < 1e-12);
            let closec = |u: &[Complex64], v: &[Complex64]| {
                u.iter().zip(v).all(|(p, q)| (p - q).norm() < 1e-12)
            };
            assert!(close(&co.real[..nl], &a.lowpass) && close(&co.real[nl..], &b.lowpass));
            assert!(closec(&co.complex[..nb], &a.bands) && closec(&co.complex[nb..], &b.bands));
            let ex: f64 = x.iter().map(|v| v.norm_sqr()).sum();
            assert!((co.energy() - ex).abs() < 1e-12 * ex);
            // Synthesis is the inverse and the adjoint.
            let mut y = vec![Complex64::new(0.0, 0.0); r * c];
            psi.synthesis(&co, &mut y);
            assert!(y.iter().zip(&x).all(|(p, q)| (p - q).norm() < 1e-11));
            let mut d = psi.zeros();
            let z = random(d.real.len() + d.complex.len(), 9);
            for (v, w) in d.real.iter_mut().zip(&z) {
                *v = w.re;
            }
            d.complex.copy_from_slice(&z[d.real.len()..]);
            psi.synthesis(&d, &mut y);
            let lhs = co.dot(&d);
            let rhs: f64 = x.iter().zip(&y).map(|(p, q)| (p.conj() * q).re).sum();
            assert!(
                (lhs - rhs).abs() < 1e-10 * lhs.abs().max(1.0),
                "{lhs} vs {rhs}"
            );
        }
    }
}
