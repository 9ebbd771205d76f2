//! Maps from oscillator states to source values (paper §2.2): `f_j: (x, y) → s_j`.
//!
//! The paper learns them by ε-SVR ([`SvrMap`]); [`FourierMap`] evaluates the learned Fourier
//! series at the state's angle and [`PhaseLut`] interpolates a table of it. The last two are
//! exact on the attractor (the LUT to its interpolation error) and much cheaper.

use crate::fourier::PeriodicSource;
use crate::hopf::phase;
use crate::svr::{RbfExpansion, Svr};
use rayon::prelude::*;
use std::f64::consts::TAU;
use wscg_math::{Error, Result};

/// A map from an oscillator state to a source value.
pub trait StateMap: Send + Sync {
    /// `f(x, y)`.
    fn eval(&self, xy: [f64; 2]) -> f64;
    /// `f` at the attractor point of angle `θ` (radians); maps that only use the angle
    /// override this to skip the trigonometry.
    fn eval_angle(&self, theta: f64) -> f64 {
        let (s, c) = theta.sin_cos();
        self.eval([c, s])
    }
    /// Whether the map depends on the state through its angle only.
    fn angle_only(&self) -> bool {
        false
    }
}

/// The source's Fourier series at the angle `atan2(y, x)`.
#[derive(Clone, Debug, PartialEq)]
pub struct FourierMap {
    /// The source.
    pub source: PeriodicSource,
}

impl StateMap for FourierMap {
    fn eval(&self, xy: [f64; 2]) -> f64 {
        self.source.eval_angle(phase(xy))
    }
    fn eval_angle(&self, theta: f64) -> f64 {
        self.source.eval_angle(theta)
    }
    fn angle_only(&self) -> bool {
        true
    }
}

/// A table of the source over one period, linearly interpolated in the angle.
#[derive(Clone, Debug, PartialEq)]
pub struct PhaseLut {
    /// `table[m] = s(m / M)`.
    pub table: Vec<f64>,
}

impl PhaseLut {
    /// Tabulates `source` at `size` phases.
    ///
    /// # Errors
    /// `size < 4`.
    pub fn new(source: &PeriodicSource, size: usize) -> Result<Self> {
        if size < 4 {
            return Err(Error::invalid(
                "lut_size",
                format!("must be >= 4, got {size}"),
            ));
        }
        Ok(Self {
            table: source.sample(size, 0.0),
        })
    }
}

impl StateMap for PhaseLut {
    fn eval(&self, xy: [f64; 2]) -> f64 {
        self.eval_angle(phase(xy))
    }
    fn eval_angle(&self, theta: f64) -> f64 {
        lut_interp(
            &self.table,
            theta.rem_euclid(TAU) / TAU * self.table.len() as f64,
        )
    }
    fn angle_only(&self) -> bool {
        true
    }
}

/// A periodic table read at the fractional index `u ∈ [0, M)`, linearly interpolated (the
/// last entry wraps to the first).
#[inline]
pub fn lut_interp(table: &[f64], u: f64) -> f64 {
    let m = table.len();
    let i0 = (u as usize).min(m - 1);
    let f = u - i0 as f64;
    let i1 = if i0 + 1 == m { 0 } else { i0 + 1 };
    table[i0] + (table[i1] - table[i0]) * f
}

/// Largest phase table size accepted by [`DelayedLuts`] (memory grows as `I · J · M`).
pub const MAX_LUT_SIZE: usize = 1 << 16;

/// Phase tables of every delayed source `s_j(t − τ_ij)`: the synthesizer's fast state maps.
///
/// A [`PhaseLut`] per source is read at `θ_j/2π − τ_ij`, a different place for every channel.
/// Tabulating each `(i, j)` pair with its delay already applied (sampled exactly from the
/// Fourier series, so the only error is the linear interpolation) makes the read position
/// depend on the follower phase `θ_j` only: one index and one weight per source and frame,
/// then a contiguous interpolation of two rows of `I` values.
#[derive(Clone, Debug, PartialEq)]
pub struct DelayedLuts {
    size: usize,
    n_channels: usize,
    n_sources: usize,
    /// `[m][j][i] = s_j(m/M − τ_ij)` for `m = 0..=M` (row `M` repeats row 0): the rows a frame
    /// reads are adjacent in memory while the followers are in phase.
    data: Vec<f64>,
}

impl DelayedLuts {
    /// Tabulates `s_j(m/M − τ_ij)` for `delays` `I × J` (periods, row-major) at `size` phases.
    ///
    /// # Errors
    /// `size` outside `4..=MAX_LUT_SIZE`, no sources, or `delays.len()` not a multiple of the
    /// number of sources.
    pub fn new(sources: &[PeriodicSource], delays: &[f64], size: usize) -> Result<Self> {
        if !(4..=MAX_LUT_SIZE).contains(&size) {
            return Err(Error::invalid(
                "lut_size",
                format!("must be in 4..={MAX_LUT_SIZE}, got {size}"),
            ));
        }
        let j_n = sources.len();
        if j_n == 0 || !delays.len().is_multiple_of(j_n) {
            return Err(Error::invalid(
                "delays",
                format!("{} delays do not form rows of {j_n} sources", delays.len()),
            ));
        }
        let i_n = delays.len() / j_n;
        // Sample every delayed series (`[i][j][m]`), then transpose to `[m][j][i]`.
        let samples: Vec<Vec<f64>> = (0..i_n * j_n)
            .into_par_iter()
            .map(|ij| sources[ij % j_n].sample(size, delays[ij]))
            .collect();
        let mut data = vec![0.0; (size + 1) * j_n * i_n];
        data.par_chunks_mut((j_n * i_n).max(1))
            .enumerate()
            .for_each(|(m, row)| {
                for (ij, s) in samples.iter().enumerate() {
                    row[(ij % j_n) * i_n + ij / j_n] = s[m % size];
                }
            });
        Ok(Self {
            size,
            n_channels: i_n,
            n_sources: j_n,
            data,
        })
    }

    /// `out[j·I + i] = s_j(θ_j/2π − τ_ij)` (source-major) from the follower angles `thetas`
    /// (radians, any range; one per source), linearly interpolated between table rows.
    ///
    /// # Panics
    /// If `thetas.len() != J` or `out.len() != I · J`.
    pub fn eval(&self, thetas: &[f64], out: &mut [f64]) {
        let (i_n, j_n, m) = (self.n_channels, self.n_sources, self.size);
        assert!(thetas.len() == j_n && out.len() == i_n * j_n);
        for (j, &theta) in thetas.iter().enumerate() {
            let wrapped = if (0.0..TAU).contains(&theta) {
                theta
            } else {
                theta.rem_euclid(TAU)
            };
            let u = wrapped / TAU * m as f64;
            let k = (u as usize).min(m - 1);
            let f = u - k as f64;
            let r0 = &self.data[(k * j_n + j) * i_n..][..i_n];
            let r1 = &self.data[((k + 1) * j_n + j) * i_n..][..i_n];
            for ((o, &a), &b) in out[j * i_n..][..i_n].iter_mut().zip(r0).zip(r1) {
                *o = a + (b - a) * f;
            }
        }
    }
}

wscg_math::params! {
    /// Hyper-parameters of the SVR state maps. The paper (§2.2) gives none; the defaults are ours,
    /// for unit-RMS sources.
    #[derive(Clone, Debug, PartialEq)]
    pub struct SvrMapParams {
        /// Box constraint `C`.
        pub c: f64,
        /// Tube width `ε`.
        pub epsilon: f64,
        /// RBF `γ`.
        pub gamma: f64,
        /// Training phases per period.
        pub n_phases: usize,
        /// Radii of the training rings (1 is the attractor; the others keep transients sane).
        pub radii: Vec<f64>,
    }
}

impl Default for SvrMapParams {
    fn default() -> Self {
        Self {
            c: 10.0,
            epsilon: 0.01,
            gamma: 2.0,
            n_phases: 200,
            radii: vec![0.9, 1.0, 1.1],
        }
    }
}

impl SvrMapParams {
    /// Errors: a non-positive or non-finite `c` or `gamma`, a negative or non-finite
    /// `epsilon`, `n_phases == 0`, no radii or a non-positive or non-finite radius.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("c", self.c), ("gamma", self.gamma)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and > 0, got {v}"),
                ));
            }
        }
        if !(self.epsilon.is_finite() && self.epsilon >= 0.0) {
            return Err(Error::invalid(
                "epsilon",
                format!("must be finite and >= 0, got {}", self.epsilon),
            ));
        }
        if self.n_phases == 0 {
            return Err(Error::invalid("n_phases", "must be >= 1, got 0"));
        }
        if self.radii.is_empty() {
            return Err(Error::invalid("radii", "needs at least one training ring"));
        }
        if self.radii.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(Error::invalid("radii", "must be finite and > 0"));
        }
        Ok(())
    }
}

/// An ε-SVR learned from attractor states to source values.
#[derive(Clone, Debug, PartialEq)]
pub struct SvrMap {
    /// The regressor.
    pub svr: Svr,
    /// Its expansion, which the map evaluates.
    fast: RbfExpansion,
}

impl SvrMap {
    /// Learns the map of `source` from `(r cos θ, r sin θ) → s(θ/2π)` on the configured rings.
    ///
    /// # Errors
    /// Invalid parameters (see [`SvrMapParams::validate`]) and the SVR's own errors.
    pub fn fit(source: &PeriodicSource, cfg: &SvrMapParams) -> Result<Self> {
        cfg.validate()?;
        let mut x = Vec::with_capacity(cfg.n_phases * cfg.radii.len());
        let mut y = Vec::with_capacity(x.capacity());
        for m in 0..cfg.n_phases {
            let t = m as f64 / cfg.n_phases as f64;
            let v = source.eval(t, 0.0);
            let (s, c) = (TAU * t).sin_cos();
            for r in &cfg.radii {
                x.push([r * c, r * s]);
                y.push(v);
            }
        }
        let svr = Svr::fit(&x, &y, cfg.c, cfg.epsilon, cfg.gamma)?;
        Ok(Self {
            fast: svr.expansion(),
            svr,
        })
    }
}

impl StateMap for SvrMap {
    fn eval(&self, xy: [f64; 2]) -> f64 {
        self.fast.eval(xy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    fn sources() -> Vec<PeriodicSource> {
        vec![
            PeriodicSource::new(vec![Complex64::new(0.4, -0.1), Complex64::new(0.0, 0.2)]),
            PeriodicSource::new(vec![Complex64::new(-0.3, 0.3), Complex64::new(0.1, 0.0)]),
        ]
    }

    #[test]
    fn delayed_tables_read_the_delayed_fourier_series() {
        let src = sources();
        // I = 3 channels × J = 2 sources, delays in periods (negative and > 1 included).
        let delays = [0.0, 0.25, -0.1, 0.6, 1.3, 0.999];
        let m = 512;
        let luts = DelayedLuts::new(&src, &delays, m).unwrap();
        // Linear interpolation on M phases errs by at most max|s''| / (8 M²), and
        // |s''| <= Σ_k 2 |c_k| (2πk)².
        let bound: Vec<f64> = src
            .iter()
            .map(|s| {
                let d2: f64 = (s.coeffs.iter().enumerate())
                    .map(|(k, c)| 2.0 * c.norm() * (TAU * (k + 1) as f64).powi(2))
                    .sum();
                d2 / (8.0 * (m * m) as f64)
            })
            .collect();
        let mut out = [0.0; 6];
        for step in 0..97 {
            let thetas = [0.37 * step as f64 - 5.0, 1.1 - 0.29 * step as f64];
            luts.eval(&thetas, &mut out);
            for i in 0..3 {
                for j in 0..2 {
                    let want = src[j].eval(thetas[j] / TAU, delays[i * 2 + j]);
                    let err = (out[j * 3 + i] - want).abs();
                    assert!(err <= bound[j], "channel {i} source {j}: error {err}");
                }
            }
        }
        // On a table node the value is the exact sample.
        luts.eval(&[TAU * 5.0 / m as f64, 0.0], &mut out);
        assert!((out[2] - src[0].eval(5.0 / m as f64, 1.3)).abs() < 1e-14);
    }

    #[test]
    fn delayed_tables_reject_bad_sizes() {
        let src = sources();
        assert!(DelayedLuts::new(&src, &[0.0; 4], 3).is_err());
        assert!(DelayedLuts::new(&src, &[0.0; 4], MAX_LUT_SIZE + 1).is_err());
        assert!(DelayedLuts::new(&src, &[0.0; 5], 64).is_err());
        assert!(DelayedLuts::new(&[], &[], 64).is_err());
    }
}
