//! Maps from oscillator states to source values (paper §2.2): `f_j: (x, y) → s_j`.
//!
//! The paper learns them by ε-SVR ([`SvrMap`]); [`FourierMap`] evaluates the learned Fourier
//! series at the state's angle and [`PhaseLut`] interpolates a table of it. The last two are
//! exact on the attractor (the LUT to its interpolation error) and much cheaper.

use crate::fourier::PeriodicSource;
use crate::hopf::phase;
use crate::svr::Svr;
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

/// Hyper-parameters of the SVR state maps (spec §2.4 defaults, on unit-RMS sources).
#[derive(Clone, Debug, PartialEq)]
pub struct SvrMapConfig {
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

impl Default for SvrMapConfig {
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

/// An ε-SVR learned from attractor states to source values.
#[derive(Clone, Debug, PartialEq)]
pub struct SvrMap {
    /// The regressor.
    pub svr: Svr,
}

impl SvrMap {
    /// Learns the map of `source` from `(r cos θ, r sin θ) → s(θ/2π)` on the configured rings.
    ///
    /// # Errors
    /// No phases or radii, non-positive radii, and the SVR's own errors.
    pub fn fit(source: &PeriodicSource, cfg: &SvrMapConfig) -> Result<Self> {
        if cfg.n_phases == 0 || cfg.radii.is_empty() {
            return Err(Error::Empty("svr map training set"));
        }
        if cfg.radii.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(Error::invalid("radii", "must be finite and > 0"));
        }
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
        Ok(Self {
            svr: Svr::fit(&x, &y, cfg.c, cfg.epsilon, cfg.gamma)?,
        })
    }
}

impl StateMap for SvrMap {
    fn eval(&self, xy: [f64; 2]) -> f64 {
        self.svr.predict(xy)
    }
}
