//! The sharp-frequency-localized contourlet transform (SFLCT; Lu & Do, "A new contourlet
//! transform with sharp frequency localization", ICIP 2006), the LRSFLCT and MRSFLCT priors
//! of paper 11's Tables 2 and 3.
//!
//! A frequency-domain multiscale [`pyramid`] replaces the Laplacian pyramid of the original
//! contourlet, and a ladder [`dfb`] splits each high-pass image into `2^n` directional
//! subbands. Two redundancies, as in Lu & Do's toolbox:
//! - [`Redundancy::Less`] (LRSFLCT): every low-pass channel is downsampled by 2 (cut-off
//!   `pi/3`, transition `pi/7`); about 4/3 coefficients per pixel.
//! - [`Redundancy::More`] (MRSFLCT): the finest level's low-pass is not downsampled (cut-off
//!   `pi/2`, transition `pi/6`), the coarser ones are (`pi/4`, `pi/12`); about 7/3.
//!
//! The pyramid is a tight frame and the PKVA ladder DFB is nearly orthogonal, so the SFLCT is
//! a frame with bounds close to (but not exactly) 1: [`Sflct::inverse`] reconstructs exactly,
//! [`Sflct::adjoint`] is the transpose used by solvers.

pub mod dfb;
pub mod pyramid;

use num_complex::Complex64;
use wscg_math::{Error, Result};

use crate::fourier::Fourier;
use dfb::DirectionalFilterBank;
use pyramid::{LevelSpec, Pyramid};

/// Low (LRSFLCT) or more (MRSFLCT) redundancy.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Redundancy {
    /// About 1.33 coefficients per pixel.
    Less,
    /// About 2.33 coefficients per pixel.
    More,
}

impl Redundancy {
    /// `"less"` or `"more"`.
    pub fn by_name(name: &str) -> Result<Self> {
        match name {
            "less" | "lr" => Ok(Redundancy::Less),
            "more" | "mr" => Ok(Redundancy::More),
            _ => Err(Error::invalid(
                "redundancy",
                format!("{name:?} is not a valid redundancy; use \"less\" or \"more\""),
            )),
        }
    }
}

wscg_math::params! {
    /// SFLCT configuration.
    #[derive(Clone, Debug, PartialEq)]
    pub struct SflctParams {
        /// Pyramid redundancy.
        pub redundancy: Redundancy,
        /// Directional levels per scale, coarsest first (`n` gives `2^n` directions); the number
        /// of entries is the number of scales.
        pub dfb_levels: Vec<usize>,
    }
}

impl Default for SflctParams {
    /// Three scales with 8, 8 and 16 directions (coarse to fine), less redundant.
    fn default() -> Self {
        SflctParams {
            redundancy: Redundancy::Less,
            dfb_levels: vec![3, 3, 4],
        }
    }
}

impl SflctParams {
    /// Checks the directional levels: 1 to 6 scales of at most 8 levels each (whether the
    /// image sides are divisible by what the pyramid and the filter banks need is checked by
    /// [`Sflct::new`]).
    pub fn validate(&self) -> Result<()> {
        check_dfb_levels("dfb_levels", &self.dfb_levels)
    }
}

/// Checks a list of directional levels per scale (`name` is the parameter holding it).
pub(crate) fn check_dfb_levels(name: &'static str, levels: &[usize]) -> Result<()> {
    let scales = levels.len();
    if scales == 0 || scales > 6 {
        return Err(Error::invalid(
            name,
            format!("{scales} scales requested; use 1 to 6"),
        ));
    }
    if let Some(l) = levels.iter().find(|&&l| l > 8) {
        return Err(Error::invalid(
            name,
            format!("{l} directional levels requested; at most 8 are supported"),
        ));
    }
    Ok(())
}

/// One subband: its scale (0 = the low-pass, then coarse to fine), direction index within
/// the scale, shape and coefficient range.
#[derive(Clone, Debug, PartialEq)]
pub struct SflctBand {
    /// 0 for the low-pass band, `1..=scales` for the directional scales (coarse to fine).
    pub scale: usize,
    /// Direction index within the scale.
    pub direction: usize,
    /// Rows and columns of the band.
    pub shape: (usize, usize),
    /// Position in the coefficient vector.
    pub range: std::ops::Range<usize>,
}

/// A planned SFLCT for one image shape.
pub struct Sflct {
    shape: (usize, usize),
    config: SflctParams,
    pyramid: Pyramid,
    /// DFBs of the high-pass images, finest first (as the pyramid's levels).
    dfbs: Vec<DirectionalFilterBank>,
    bands: Vec<SflctBand>,
    fourier: Fourier,
}

impl Sflct {
    /// Plans the transform. Errors: no scale, too many directional levels, or sides the
    /// downsampling and the DFBs do not divide.
    pub fn new(rows: usize, cols: usize, config: &SflctParams) -> Result<Self> {
        config.validate()?;
        // The transform holds a few complex planes of rows x cols per scale and direction;
        // refuse a shape whose single plane cannot fit.
        wscg_math::alloc::ensure_shape::<[f64; 2]>("shape", &[rows, cols])?;
        let scales = config.dfb_levels.len();
        let specs: Vec<LevelSpec> = (0..scales)
            .map(|k| match (config.redundancy, k) {
                (Redundancy::More, 0) => LevelSpec {
                    w: 0.5,
                    tbw: 1.0 / 6.0,
                    d: 1,
                },
                (Redundancy::More, _) => LevelSpec {
                    w: 0.25,
                    tbw: 1.0 / 12.0,
                    d: 2,
                },
                (Redundancy::Less, _) => LevelSpec {
                    w: 1.0 / 3.0,
                    tbw: 1.0 / 7.0,
                    d: 2,
                },
            })
            .collect();
        let pyramid = Pyramid::new(rows, cols, &specs)?;
        let shapes = pyramid.highpass_shapes();
        let mut dfbs = Vec::with_capacity(scales);
        for (k, &(r, c)) in shapes.iter().enumerate() {
            // Finest first: the last entry of the coarse-to-fine list.
            dfbs.push(DirectionalFilterBank::new(
                r,
                c,
                config.dfb_levels[scales - 1 - k],
            )?);
        }
        let mut bands = Vec::new();
        let (lr, lc) = pyramid.lowpass_shape();
        bands.push(SflctBand {
            scale: 0,
            direction: 0,
            shape: (lr, lc),
            range: 0..lr * lc,
        });
        let mut off = lr * lc;
        for (s, d) in dfbs.iter().rev().enumerate() {
            for (k, sh) in d.band_shapes().into_iter().enumerate() {
                bands.push(SflctBand {
                    scale: s + 1,
                    direction: k,
                    shape: sh,
                    range: off..off + sh.0 * sh.1,
                });
                off += sh.0 * sh.1;
            }
        }
        Ok(Sflct {
            shape: (rows, cols),
            config: config.clone(),
            pyramid,
            dfbs,
            bands,
            fourier: Fourier::new(rows, cols)?,
        })
    }

    /// Image shape.
    pub fn shape(&self) -> (usize, usize) {
        self.shape
    }

    /// The configuration.
    pub fn config(&self) -> &SflctParams {
        &self.config
    }

    /// The subbands: the low-pass first, then each scale (coarse to fine) in directional
    /// order.
    pub fn bands(&self) -> &[SflctBand] {
        &self.bands
    }

    /// Total number of coefficients.
    pub fn coeff_len(&self) -> usize {
        self.bands.last().map_or(0, |b| b.range.end)
    }

    /// Coefficients per pixel.
    pub fn redundancy(&self) -> f64 {
        self.coeff_len() as f64 / (self.shape.0 * self.shape.1) as f64
    }

    fn check(&self, what: &'static str, got: usize, want: usize) -> Result<()> {
        if got != want {
            return Err(Error::invalid(
                what,
                format!("has {got} values; the transform needs {want}"),
            ));
        }
        Ok(())
    }

    /// The SFLCT of an image (row-major, complex; a real image gives real coefficients).
    pub fn forward(&self, x: &[Complex64]) -> Result<Vec<Complex64>> {
        self.check("image", x.len(), self.shape.0 * self.shape.1)?;
        let mut s = x.to_vec();
        self.fourier.forward(&mut s);
        let mut out = vec![Complex64::new(0.0, 0.0); self.coeff_len()];
        self.forward_spectrum(&s, &mut out);
        Ok(out)
    }

    /// Exact reconstruction from coefficients.
    pub fn inverse(&self, c: &[Complex64]) -> Result<Vec<Complex64>> {
        self.check("coefficients", c.len(), self.coeff_len())?;
        let mut x = vec![Complex64::new(0.0, 0.0); self.shape.0 * self.shape.1];
        self.backward_spectrum(c, &mut x, false);
        self.fourier.inverse(&mut x);
        Ok(x)
    }

    /// The adjoint `Psi^H c`.
    pub fn adjoint(&self, c: &[Complex64]) -> Result<Vec<Complex64>> {
        self.check("coefficients", c.len(), self.coeff_len())?;
        let mut x = vec![Complex64::new(0.0, 0.0); self.shape.0 * self.shape.1];
        self.backward_spectrum(c, &mut x, true);
        self.fourier.inverse(&mut x);
        Ok(x)
    }

    /// [`Sflct::forward`] from the image's unitary spectrum (no length checks).
    pub fn forward_spectrum(&self, xhat: &[Complex64], out: &mut [Complex64]) {
        let (highs, low) = self.pyramid.forward_spectrum(xhat);
        let (lowpass, mut rest) = out.split_at_mut(self.bands[0].range.end);
        lowpass.copy_from_slice(&low);
        // Coefficients run coarse to fine; the pyramid's levels (and `dfbs`) fine to coarse.
        rayon::scope(|sc| {
            for (d, h) in self.dfbs.iter().zip(&highs).rev() {
                let (slot, tail) = std::mem::take(&mut rest).split_at_mut(h.len());
                rest = tail;
                sc.spawn(move |_| d.forward(h, slot));
            }
        });
    }

    /// The spectrum of [`Sflct::inverse`] (`adjoint = false`) or [`Sflct::adjoint`].
    pub fn backward_spectrum(&self, c: &[Complex64], out: &mut [Complex64], adjoint: bool) {
        let (low, mut rest) = c.split_at(self.bands[0].range.end);
        let mut highs: Vec<Vec<Complex64>> = self
            .dfbs
            .iter()
            .map(|d| vec![Complex64::new(0.0, 0.0); d.shape().0 * d.shape().1])
            .collect();
        rayon::scope(|sc| {
            for (d, h) in self.dfbs.iter().zip(highs.iter_mut()).rev() {
                let (src, tail) = rest.split_at(h.len());
                rest = tail;
                sc.spawn(move |_| {
                    if adjoint {
                        d.adjoint(src, h)
                    } else {
                        d.inverse(src, h)
                    }
                });
            }
        });
        out.copy_from_slice(&self.pyramid.backward_spectrum(&highs, low));
    }

    /// The unitary FFT of the image shape.
    pub fn fourier(&self) -> &Fourier {
        &self.fourier
    }
}

/// Largest distance between corresponding samples (test helper of the SFLCT modules).
#[cfg(test)]
pub(crate) fn max_diff(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).norm())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use wscg_math::rng;

    #[test]
    fn redundancies_and_exact_reconstruction() {
        for (red, want) in [(Redundancy::Less, 1.33), (Redundancy::More, 2.31)] {
            let cfg = SflctParams {
                redundancy: red,
                dfb_levels: vec![2, 3, 3],
            };
            let t = Sflct::new(128, 128, &cfg).unwrap();
            assert!((t.redundancy() - want).abs() < 0.01, "{}", t.redundancy());
            let x = rng::complex_normal_vec(5, 128 * 128, 1.0).unwrap();
            let c = t.forward(&x).unwrap();
            let y = t.inverse(&c).unwrap();
            let err = max_diff(&x, &y);
            assert!(err < 1e-11, "{err}");
            let g = rng::complex_normal_vec(6, c.len(), 1.0).unwrap();
            let z = t.adjoint(&g).unwrap();
            let lhs: Complex64 = c.iter().zip(&g).map(|(a, b)| a.conj() * b).sum();
            let rhs: Complex64 = x.iter().zip(&z).map(|(a, b)| a.conj() * b).sum();
            assert!((lhs - rhs).norm() < 1e-9 * lhs.norm(), "{lhs} {rhs}");
        }
    }
}
