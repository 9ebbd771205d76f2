//! The multiscale pyramid of the sharp-frequency-localized contourlet (Lu & Do 2006): at each
//! level the spectrum is split by a separable low-pass window `L` with a raised-cosine
//! transition and its complement `H = sqrt(1 - L^2)`. The low-pass channel is band-limited
//! below `pi / D`, so it is downsampled by `D` without aliasing (its spectrum is cropped); the
//! high-pass channel keeps the level's resolution and goes to the directional filter bank.
//! Unlike the Laplacian pyramid of the original contourlet, nothing outside a band leaks
//! into it, which is what keeps the directional subbands sharply localized in frequency.
//!
//! With the unitary FFT the pyramid is a tight frame: `|L X|^2 + |H X|^2 = |X|^2`, and its
//! adjoint is its inverse.

use num_complex::Complex64;
use rayon::prelude::*;
use wscg_math::{Error, Result};

use crate::fourier::{signed_frequency, Fourier};

/// One level: cut-off `w` and half transition width `tbw` (fractions of the Nyquist
/// frequency) and the low-pass downsampling factor `d` (1 or 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelSpec {
    /// Cut-off (the window is 1/2 in energy there).
    pub w: f64,
    /// Half width of the transition band.
    pub tbw: f64,
    /// Low-pass downsampling factor.
    pub d: usize,
}

/// A planned level.
struct Level {
    /// Shape of the level's input (and high-pass output).
    shape: (usize, usize),
    /// Shape after downsampling the low-pass channel.
    low: (usize, usize),
    /// 1-D window along rows and columns (indexed by FFT index).
    win: [Vec<f64>; 2],
    fourier: Fourier,
}

/// The pyramid planned for one image shape. Levels run from the finest to the coarsest.
pub struct Pyramid {
    levels: Vec<Level>,
    coarse: Fourier,
}

/// The raised-cosine window value `sqrt(rcos)` at normalised frequency `nu` in `[0, 1]`.
fn window(nu: f64, w: f64, tbw: f64) -> f64 {
    if nu <= w - tbw {
        1.0
    } else if nu >= w + tbw {
        0.0
    } else {
        let t = (w + tbw - nu) / (2.0 * tbw);
        ((1.0 - (std::f64::consts::PI * t).cos()) / 2.0).sqrt()
    }
}

impl Pyramid {
    /// Plans the levels (finest first) for a `rows x cols` image. Errors: a low-pass band
    /// that would alias after downsampling, or a side that the downsampling does not divide.
    pub fn new(rows: usize, cols: usize, specs: &[LevelSpec]) -> Result<Self> {
        let mut shape = (rows, cols);
        let mut levels = Vec::with_capacity(specs.len());
        for s in specs {
            if !(s.d == 1 || s.d == 2) || s.tbw <= 0.0 || s.w - s.tbw <= 0.0 {
                return Err(Error::invalid("pyramid", format!("invalid level {s:?}")));
            }
            if s.w + s.tbw >= 1.0 / s.d as f64 {
                return Err(Error::invalid(
                    "pyramid",
                    format!("level {s:?}: the low-pass band reaches the new Nyquist frequency"),
                ));
            }
            if !shape.0.is_multiple_of(s.d)
                || !shape.1.is_multiple_of(s.d)
                || shape.0 < 4
                || shape.1 < 4
            {
                let halvings = specs.iter().filter(|s| s.d == 2).count() as u32;
                return Err(Error::invalid(
                    "shape",
                    format!(
                        "{rows} x {cols}: the pyramid halves the image {halvings} times, so \
                         both sides must be divisible by {}",
                        2usize.pow(halvings).max(4)
                    ),
                ));
            }
            let win = [shape.0, shape.1].map(|n| {
                (0..n)
                    .map(|i| {
                        let nu = signed_frequency(i, n).unsigned_abs() as f64 / (n as f64 / 2.0);
                        window(nu, s.w, s.tbw)
                    })
                    .collect::<Vec<_>>()
            });
            let low = (shape.0 / s.d, shape.1 / s.d);
            levels.push(Level {
                shape,
                low,
                win,
                fourier: Fourier::new(shape.0, shape.1)?,
            });
            shape = low;
        }
        Ok(Pyramid {
            levels,
            coarse: Fourier::new(shape.0, shape.1)?,
        })
    }

    /// Shapes of the high-pass images, finest first.
    pub fn highpass_shapes(&self) -> Vec<(usize, usize)> {
        self.levels.iter().map(|l| l.shape).collect()
    }

    /// Shape of the coarsest low-pass image.
    pub fn lowpass_shape(&self) -> (usize, usize) {
        self.coarse.shape()
    }

    /// Splits the unitary spectrum `xhat` of an image into the high-pass images (finest
    /// first) and the coarsest low-pass image, all in the spatial domain.
    pub fn forward_spectrum(&self, xhat: &[Complex64]) -> (Vec<Vec<Complex64>>, Vec<Complex64>) {
        let mut spec = xhat.to_vec();
        let mut highs = Vec::with_capacity(self.levels.len());
        for lv in &self.levels {
            let (r, c) = lv.shape;
            let mut hp = spec.clone();
            hp.par_chunks_mut(c).enumerate().for_each(|(i, row)| {
                for (j, v) in row.iter_mut().enumerate() {
                    let l = lv.win[0][i] * lv.win[1][j];
                    *v *= (1.0 - l * l).max(0.0).sqrt();
                }
            });
            lv.fourier.inverse(&mut hp);
            highs.push(hp);
            let (lr, lc) = lv.low;
            let mut low = vec![Complex64::new(0.0, 0.0); lr * lc];
            for (i, row) in low.chunks_mut(lc).enumerate() {
                let si = index_in(i, lr, r);
                for (j, v) in row.iter_mut().enumerate() {
                    let sj = index_in(j, lc, c);
                    *v = spec[si * c + sj] * (lv.win[0][si] * lv.win[1][sj]);
                }
            }
            spec = low;
        }
        self.coarse.inverse(&mut spec);
        (highs, spec)
    }

    /// The adjoint (and inverse): the unitary spectrum of the image whose pyramid is
    /// `(highs, low)`.
    pub fn backward_spectrum(&self, highs: &[Vec<Complex64>], low: &[Complex64]) -> Vec<Complex64> {
        let mut spec = low.to_vec();
        self.coarse.forward(&mut spec);
        for (lv, hp) in self.levels.iter().zip(highs).rev() {
            let (r, c) = lv.shape;
            let mut x = hp.clone();
            lv.fourier.forward(&mut x);
            x.par_chunks_mut(c).enumerate().for_each(|(i, row)| {
                for (j, v) in row.iter_mut().enumerate() {
                    let l = lv.win[0][i] * lv.win[1][j];
                    *v *= (1.0 - l * l).max(0.0).sqrt();
                }
            });
            let (lr, lc) = lv.low;
            for i in 0..lr {
                let si = index_in(i, lr, r);
                for j in 0..lc {
                    let sj = index_in(j, lc, c);
                    x[si * c + sj] += spec[i * lc + j] * (lv.win[0][si] * lv.win[1][sj]);
                }
            }
            spec = x;
        }
        spec
    }
}

/// The FFT index on an axis of length `big` with the same signed frequency as index `i` of
/// an axis of length `small`.
fn index_in(i: usize, small: usize, big: usize) -> usize {
    let k = signed_frequency(i, small);
    k.rem_euclid(big as i64) as usize
}

#[cfg(test)]
mod tests {
    use super::*;
    use wscg_math::rng;

    #[test]
    fn tight_frame_and_band_limits() {
        let specs = [
            LevelSpec {
                w: 0.5,
                tbw: 1.0 / 6.0,
                d: 1,
            },
            LevelSpec {
                w: 0.25,
                tbw: 1.0 / 12.0,
                d: 2,
            },
            LevelSpec {
                w: 1.0 / 3.0,
                tbw: 1.0 / 7.0,
                d: 2,
            },
        ];
        let (r, c) = (64, 96);
        let p = Pyramid::new(r, c, &specs).unwrap();
        assert_eq!(p.highpass_shapes(), vec![(64, 96), (64, 96), (32, 48)]);
        assert_eq!(p.lowpass_shape(), (16, 24));
        let x = rng::complex_normal_vec(3, r * c, 1.0).unwrap();
        let (h, l) = p.forward_spectrum(&x);
        let e: f64 = h.iter().flatten().chain(&l).map(|v| v.norm_sqr()).sum();
        let ex: f64 = x.iter().map(|v| v.norm_sqr()).sum();
        assert!((e - ex).abs() < 1e-11 * ex, "{e} vs {ex}");
        let y = p.backward_spectrum(&h, &l);
        let err = crate::sflct::max_diff(&x, &y);
        assert!(err < 1e-12, "{err}");
        assert!(Pyramid::new(
            64,
            64,
            &[LevelSpec {
                w: 0.45,
                tbw: 0.1,
                d: 2
            }]
        )
        .is_err());
    }
}
