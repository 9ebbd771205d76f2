//! Tail probabilities and quantiles of the Student-t and Fisher F distributions, shared by
//! paper 07's study analysis (t-tests of the response-surface coefficients, F-tests of the
//! repeated-measures ANOVA, Fisher's LSD) and paper 16's regression p-values (§2.1).
//!
//! Both tails are written through the regularised incomplete beta function `I_x(a, b)`
//! (`statrs::function::beta::beta_reg`), which keeps small p-values relatively accurate
//! instead of computing `1 - cdf`:
//!
//! ```text
//! P(|T_ν| > |t|)   = I_{ν/(ν+t²)}(ν/2, 1/2)
//! P(F_{d1,d2} > f) = I_{d2/(d2+d1 f)}(d2/2, d1/2)
//! ```

use crate::{Error, Result};
use statrs::function::beta::{beta_reg, inv_beta_reg};
use statrs::function::gamma::ln_gamma;

/// Two-sided p-value `P(|T_df| >= |t|)` of a Student-t statistic with `df` degrees of freedom.
///
/// Returns 0 for `t = ±∞` and NaN for a NaN `t` (as scipy's `2 * t.sf(|t|, df)` does).
///
/// # Errors
/// [`Error::InvalidArgument`] when `df` is not finite and > 0.
pub fn t_two_sided_p(t: f64, df: f64) -> Result<f64> {
    check_df("df", df)?;
    if t.is_nan() {
        return Ok(f64::NAN);
    }
    if t.is_infinite() {
        return Ok(0.0);
    }
    let x = df / (df + t * t);
    Ok(beta_reg(0.5 * df, 0.5, x.clamp(0.0, 1.0)))
}

/// Cumulative distribution `P(T_df <= t)` of Student's t.
///
/// # Errors
/// [`Error::InvalidArgument`] when `df` is not finite and > 0.
pub fn t_cdf(t: f64, df: f64) -> Result<f64> {
    let tail = 0.5 * t_two_sided_p(t, df)?;
    Ok(if t >= 0.0 { 1.0 - tail } else { tail })
}

/// Quantile `t` with `P(T_df <= t) = q` of Student's t (e.g. `t_quantile(0.975, df)` for the
/// two-sided 5 % critical value of Fisher's LSD).
///
/// A start from the inverse incomplete beta function (AS 109) is polished with Newton steps on
/// [`t_cdf`], so the result inverts `t_cdf` to machine precision.
///
/// # Errors
/// [`Error::InvalidArgument`] when `q` is not in (0, 1) or `df` is not finite and > 0.
pub fn t_quantile(q: f64, df: f64) -> Result<f64> {
    check_df("df", df)?;
    if !(q > 0.0 && q < 1.0) {
        return Err(Error::invalid(
            "q",
            format!("must be a probability in (0, 1), got {q}"),
        ));
    }
    if q == 0.5 {
        return Ok(0.0);
    }
    // Symmetry: solve for the upper tail probability p = min(q, 1 - q) and restore the sign.
    let p_low = q.min(1.0 - q);
    let y = inv_beta_reg(0.5 * df, 0.5, 2.0 * p_low);
    let mut t = if y > 0.0 {
        (df * (1.0 - y) / y).sqrt()
    } else {
        f64::MAX.sqrt()
    };
    // Newton on the upper tail g(t) = P(T > t) - p_low, g'(t) = -pdf(t).
    let ln_norm =
        ln_gamma(0.5 * (df + 1.0)) - ln_gamma(0.5 * df) - 0.5 * (df * std::f64::consts::PI).ln();
    for _ in 0..8 {
        let upper = 0.5 * t_two_sided_p(t, df)?;
        let pdf = (ln_norm - 0.5 * (df + 1.0) * (1.0 + t * t / df).ln()).exp();
        if pdf.is_nan() || pdf <= 0.0 {
            break;
        }
        let step = (upper - p_low) / pdf;
        t += step;
        if step.abs() <= 4.0 * f64::EPSILON * t.abs().max(1.0) {
            break;
        }
    }
    Ok(if q > 0.5 { t } else { -t })
}

/// Upper tail `P(F_{d1,d2} >= f)` of Fisher's F distribution (the p-value of an F-test).
///
/// Degrees of freedom may be fractional (Greenhouse–Geisser corrected tests). Returns 1 for
/// `f <= 0`, 0 for `f = +∞` and NaN for a NaN `f`.
///
/// # Errors
/// [`Error::InvalidArgument`] when `d1` or `d2` is not finite and > 0.
pub fn f_sf(f: f64, d1: f64, d2: f64) -> Result<f64> {
    check_df("d1", d1)?;
    check_df("d2", d2)?;
    if f.is_nan() {
        return Ok(f64::NAN);
    }
    if f <= 0.0 {
        return Ok(1.0);
    }
    if f.is_infinite() {
        return Ok(0.0);
    }
    let x = d2 / (d2 + d1 * f);
    Ok(beta_reg(0.5 * d2, 0.5 * d1, x.clamp(0.0, 1.0)))
}

fn check_df(name: &'static str, df: f64) -> Result<()> {
    if df.is_finite() && df > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            name,
            format!("degrees of freedom must be finite and > 0, got {df}"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_tail_matches_closed_forms() {
        // df = 1 is the Cauchy law: P(|T| > t) = 1 - 2 atan(t) / pi.
        for t in [0.0, 0.3, 1.0, 2.5, 40.0] {
            let want = 1.0 - 2.0 * f64::atan(t) / std::f64::consts::PI;
            assert!((t_two_sided_p(t, 1.0).unwrap() - want).abs() < 1e-14, "{t}");
        }
        // df = 2: P(|T| > t) = 1 - t / sqrt(2 + t^2).
        for t in [0.1f64, 1.0, 3.0, 10.0] {
            let want = 1.0 - t / (2.0 + t * t).sqrt();
            assert!(
                (t_two_sided_p(-t, 2.0).unwrap() - want).abs() < 1e-14,
                "{t}"
            );
        }
        assert_eq!(t_two_sided_p(f64::INFINITY, 5.0).unwrap(), 0.0);
        assert!(t_two_sided_p(f64::NAN, 5.0).unwrap().is_nan());
        assert!(t_two_sided_p(1.0, 0.0).is_err());
        assert!(t_two_sided_p(1.0, f64::NAN).is_err());
    }

    #[test]
    fn t_quantile_inverts_the_cdf() {
        // Tabulated two-sided 5 % critical values.
        let table = [
            // scipy.stats.t.ppf(0.975, df)
            (1.0, 12.706204736174694),
            (2.0, 4.302652729749462),
            (10.0, 2.228138851986274),
            (25.0, 2.0595385527532972),
        ];
        for (df, want) in table {
            let t = t_quantile(0.975, df).unwrap();
            assert!((t - want).abs() < 1e-10, "df {df}: {t} vs {want}");
            assert!((t_quantile(0.025, df).unwrap() + want).abs() < 1e-10);
        }
        for df in [1.5, 3.0, 7.0, 30.0, 300.0] {
            for q in [0.001, 0.2, 0.6, 0.99, 0.999_999] {
                let t = t_quantile(q, df).unwrap();
                assert!((t_cdf(t, df).unwrap() - q).abs() < 1e-13, "df {df} q {q}");
            }
        }
        assert!(t_quantile(1.0, 3.0).is_err());
        assert!(t_quantile(f64::NAN, 3.0).is_err());
    }

    #[test]
    fn f_tail_matches_closed_forms() {
        // F(2, d2): P(F > f) = (1 + 2 f / d2)^(-d2 / 2).
        for (f, d2) in [(0.5f64, 3.0f64), (2.0, 7.0), (9.0, 20.0), (1e3, 4.0)] {
            let want = (1.0 + 2.0 * f / d2).powf(-d2 / 2.0);
            let got = f_sf(f, 2.0, d2).unwrap();
            assert!(
                ((got - want) / want).abs() < 1e-12,
                "{f} {d2}: {got} vs {want}"
            );
        }
        // F(1, d) = T_d^2.
        for (t, d) in [(0.7, 4.0), (2.2, 11.0), (5.0, 30.0)] {
            let a = f_sf(t * t, 1.0, d).unwrap();
            let b = t_two_sided_p(t, d).unwrap();
            assert!((a - b).abs() < 1e-14);
        }
        assert_eq!(f_sf(0.0, 2.0, 3.0).unwrap(), 1.0);
        assert_eq!(f_sf(f64::INFINITY, 2.0, 3.0).unwrap(), 0.0);
        assert!(f_sf(1.0, -2.0, 3.0).is_err());
    }
}
