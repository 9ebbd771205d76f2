//! Interpolation weights of the records (paper 08, section 4.3, eqs. 2-4, after Clarberg and
//! Akenine-Möller 2008) and the baseline's uniform weights (Georgiev et al. 2012).

use nalgebra::Vector3;
use wscg_math::{Error, Result};

/// How the nearest records' distributions are mixed at a shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Interp {
    /// Uniform average of the `M` nearest records (importance caching, Georgiev 2012).
    Uniform,
    /// The paper's similarity weights (eqs. 2-4) within a search radius, optionally blended
    /// with the uniform weights (a defensive mixture).
    Clarberg {
        /// `theta_max` (radians): at `d = d_max` a normal difference of `theta_max` zeroes the
        /// weight; pi / 6 in the paper.
        theta_max: f64,
        /// `lambda` of eq. (3); 5 in the paper.
        lambda: f64,
        /// The search radius `d_max` as a multiple of the median distance from a record to its
        /// `M`-th nearest other record (the paper does not give `d_max`); 2.
        dmax_factor: f64,
        /// Defensive share `c` in `[0, 1]`: the weights used are `(1 - c) w_k + c u_k`, `w_k`
        /// those of eqs. (2)-(4) and `u_k` the uniform weights of the `M` nearest records
        /// facing the same side (importance caching's). Eqs. (2)-(4) can put nearly all the
        /// weight on one record, whose distribution may give a VPL that the shading point
        /// sees (and another record sampled well) a tiny probability; the blend keeps every
        /// VPL's probability under the full, unoccluded and bounded strategies at least `c`
        /// times the uniform weights' one, so a sample's weight `I / p` is at most `1 / c`
        /// times the ablation's. The estimate stays unbiased: samples are divided by the
        /// blended probability. 0 is the paper's eqs. (2)-(4); 0.5 by default.
        defensive: f64,
    },
}

impl Default for Interp {
    fn default() -> Self {
        Self::Clarberg {
            theta_max: std::f64::consts::FRAC_PI_6,
            lambda: 5.0,
            dmax_factor: 2.0,
            defensive: DEFAULT_DEFENSIVE,
        }
    }
}

/// The default defensive share of [`Interp::Clarberg`].
pub const DEFAULT_DEFENSIVE: f64 = 0.5;

impl Interp {
    /// The paper's weights (eqs. 2-4 with its `theta_max = pi / 6`, `lambda = 5`), without
    /// the defensive blend.
    pub fn paper() -> Self {
        Self::default().with_defensive(0.0)
    }

    /// The same weights with defensive share `c` (no change to [`Interp::Uniform`]).
    pub fn with_defensive(self, c: f64) -> Self {
        match self {
            Interp::Clarberg {
                theta_max,
                lambda,
                dmax_factor,
                ..
            } => Interp::Clarberg {
                theta_max,
                lambda,
                dmax_factor,
                defensive: c,
            },
            Interp::Uniform => Interp::Uniform,
        }
    }

    /// Errors: `theta_max` outside (0, pi), a negative or non-finite `lambda`, a
    /// non-positive `dmax_factor`, `defensive` outside `[0, 1]`.
    pub fn validate(&self) -> Result<()> {
        if let Interp::Clarberg {
            theta_max,
            lambda,
            dmax_factor,
            defensive,
        } = *self
        {
            if !(0.0..=1.0).contains(&defensive) {
                return Err(Error::invalid(
                    "defensive",
                    format!("must lie in [0, 1], got {defensive}"),
                ));
            }
            if !(theta_max > 0.0 && theta_max < std::f64::consts::PI) {
                return Err(Error::invalid(
                    "theta_max",
                    format!("must lie in (0, pi), got {theta_max}"),
                ));
            }
            if !(lambda.is_finite() && lambda >= 0.0) {
                return Err(Error::invalid(
                    "lambda",
                    format!("must be finite and >= 0, got {lambda}"),
                ));
            }
            wscg_math::error::ensure_positive("dmax_factor", dmax_factor)?;
        }
        Ok(())
    }
}

/// Eq. (3): `w(d, theta) = (1 - theta / pi) (1 - d' / (1 + lambda d'))`, `d' = d / d_max`.
pub fn similarity(d_rel: f64, theta: f64, lambda: f64) -> f64 {
    (1.0 - theta / std::f64::consts::PI) * (1.0 - d_rel / (1.0 + lambda * d_rel))
}

/// Eq. (4): `max(0, (w - w0) / (1 - w0))` with `w0 = w(d_max, theta_max)`, in `[0, 1]`.
pub fn clipped_similarity(d_rel: f64, theta: f64, theta_max: f64, lambda: f64) -> f64 {
    let w0 = similarity(1.0, theta_max, lambda);
    ((similarity(d_rel, theta, lambda) - w0) / (1.0 - w0)).clamp(0.0, 1.0)
}

/// Eq. (2): the weight of a record at `p` with normal `n_c` for the shading point `x` with
/// normal `n`: `sqrt(1 - |n . v|)` (`v` the unit vector from `x` to `p`; 1 when they
/// coincide) times the clipped similarity of their distance and normal angle.
pub fn record_weight(
    x: [f64; 3],
    n: [f64; 3],
    p: [f64; 3],
    n_c: [f64; 3],
    d_max: f64,
    theta_max: f64,
    lambda: f64,
) -> f64 {
    let (n, n_c) = (Vector3::from(n), Vector3::from(n_c));
    let v = Vector3::from(p) - Vector3::from(x);
    let d = v.norm();
    let tangential = if d > 0.0 {
        (1.0 - (n.dot(&v) / d).abs()).max(0.0).sqrt()
    } else {
        1.0
    };
    let theta = n.dot(&n_c).clamp(-1.0, 1.0).acos();
    tangential * clipped_similarity(d / d_max, theta, theta_max, lambda)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn clipped_similarity_matches_hand_computed_values() {
        let w = |d: f64, t: f64| clipped_similarity(d, t, PI / 6.0, 5.0);
        assert!((similarity(1.0, PI / 6.0, 5.0) - 25.0 / 36.0).abs() < 1e-12);
        for (got, want) in [
            (w(0.0, 0.0), 1.0),
            (w(0.25, 0.0), 0.636364),
            (w(0.5, PI / 12.0), 0.298701),
            (w(1.0, 0.0), 0.454545),
            (w(0.0, PI / 6.0), 0.454545),
            (w(1.0, PI / 6.0), 0.0),
        ] {
            assert!((got - want).abs() < 1e-6, "{got} vs {want}");
        }
        for i in 0..=20 {
            for k in 0..=20 {
                let v = w(i as f64 / 10.0, k as f64 * PI / 20.0);
                assert!((0.0..=1.0).contains(&v));
            }
        }
        // In the plane of the shading point the first factor is 1; straight above it, 0.
        let (x, n) = ([0.0; 3], [0.0, 0.0, 1.0]);
        let side = record_weight(x, n, [0.25, 0.0, 0.0], n, 1.0, PI / 6.0, 5.0);
        assert!((side - 0.636364).abs() < 1e-6);
        let above = record_weight(x, n, [0.0, 0.0, 0.25], n, 1.0, PI / 6.0, 5.0);
        assert_eq!(above, 0.0);
        assert!(Interp::Clarberg {
            theta_max: 0.0,
            lambda: 5.0,
            dmax_factor: 2.0,
            defensive: 0.0
        }
        .validate()
        .is_err());
        assert!(Interp::Clarberg {
            theta_max: 0.5,
            lambda: -1.0,
            dmax_factor: 2.0,
            defensive: 0.0
        }
        .validate()
        .is_err());
        assert!(Interp::default().validate().is_ok());
        assert!(Interp::default().with_defensive(1.5).validate().is_err());
        assert!(Interp::default()
            .with_defensive(f64::NAN)
            .validate()
            .is_err());
        assert_eq!(
            Interp::paper(),
            Interp::Clarberg {
                theta_max: std::f64::consts::FRAC_PI_6,
                lambda: 5.0,
                dmax_factor: 2.0,
                defensive: 0.0
            }
        );
    }
}
