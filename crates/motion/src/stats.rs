//! The regression statistics of paper §2.1 (Fig. 2): least-squares line fits of step lengths
//! against the initial distance, with `R²` and the two-sided p-value of the slope.

use wscg_math::dist::t_two_sided_p;
use wscg_math::error::ensure_finite;
use wscg_math::{Error, Result};

/// A simple linear regression `y ≈ a + b x`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineFit {
    /// Intercept `a`.
    pub intercept: f64,
    /// Slope `b`.
    pub slope: f64,
    /// Coefficient of determination.
    pub r2: f64,
    /// Two-sided p-value of `H0: b = 0`.
    pub p_value: f64,
    /// Number of points.
    pub n: usize,
}

/// p-value of the slope of a simple regression with coefficient of determination `r2` on `n`
/// points: `t = sqrt(R² (n − 2) / (1 − R²))` on `n − 2` degrees of freedom.
///
/// # Errors
/// `n < 3` or `r2` outside `[0, 1]`.
pub fn regression_p_value(r2: f64, n: usize) -> Result<f64> {
    if n < 3 {
        return Err(Error::invalid(
            "n",
            format!("need at least 3 points, got {n}"),
        ));
    }
    if !(0.0..=1.0).contains(&r2) {
        return Err(Error::invalid("r2", format!("must be in [0, 1], got {r2}")));
    }
    if r2 >= 1.0 {
        return Ok(0.0);
    }
    let df = (n - 2) as f64;
    t_two_sided_p((r2 * df / (1.0 - r2)).sqrt(), df)
}

/// Least-squares line through `(x, y)` with its `R²` and slope p-value.
///
/// # Errors
/// Different lengths, fewer than 3 points, non-finite values, constant `x`.
pub fn fit_line(x: &[f64], y: &[f64]) -> Result<LineFit> {
    if x.len() != y.len() {
        return Err(Error::ShapeMismatch(format!(
            "{} x values and {} y values",
            x.len(),
            y.len()
        )));
    }
    ensure_finite("x", x)?;
    ensure_finite("y", y)?;
    let n = x.len();
    if n < 3 {
        return Err(Error::invalid(
            "x",
            format!("need at least 3 points, got {n}"),
        ));
    }
    let mx = x.iter().sum::<f64>() / n as f64;
    let my = y.iter().sum::<f64>() / n as f64;
    let sxx: f64 = x.iter().map(|v| (v - mx) * (v - mx)).sum();
    let syy: f64 = y.iter().map(|v| (v - my) * (v - my)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    if sxx <= 0.0 {
        return Err(Error::invalid("x", "all x values are equal"));
    }
    let slope = sxy / sxx;
    let r2 = if syy > 0.0 {
        (sxy * sxy / (sxx * syy)).clamp(0.0, 1.0)
    } else {
        1.0
    };
    Ok(LineFit {
        intercept: my - slope * mx,
        slope,
        r2,
        p_value: regression_p_value(r2, n)?,
        n,
    })
}
