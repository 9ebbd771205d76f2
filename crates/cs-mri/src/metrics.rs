//! Reconstruction metrics of paper 11, section 3.2.
//!
//! PSNR is computed on magnitude images, `20 log10(max|x_ref| / RMSE(|x|, |x_ref|))`, and the
//! relative l2 norm error RLNE (Qu et al. 2012) is `||x - x_ref|| / ||x_ref||`, on complex
//! values ([`rlne`]) or on magnitudes ([`rlne_magnitude`]). With magnitudes, every row of the
//! paper satisfies `PSNR + 20 log10(RLNE) = 20 log10(max|x_ref| sqrt(n) / ||x_ref||)`.

use num_complex::Complex64;
use wscg_math::{Error, Result};

fn check(reference: &[Complex64], x: &[Complex64]) -> Result<()> {
    if reference.is_empty() {
        return Err(Error::Empty("reference"));
    }
    if reference.len() != x.len() {
        return Err(Error::ShapeMismatch(format!(
            "reference has {} values, the image {}",
            reference.len(),
            x.len()
        )));
    }
    Ok(())
}

/// PSNR in dB of the magnitude of `x` against the magnitude of `reference`.
pub fn psnr(reference: &[Complex64], x: &[Complex64]) -> Result<f64> {
    check(reference, x)?;
    let peak = reference.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let mse = reference
        .iter()
        .zip(x)
        .map(|(a, b)| (a.norm() - b.norm()).powi(2))
        .sum::<f64>()
        / x.len() as f64;
    Ok(20.0 * peak.log10() - 10.0 * mse.log10())
}

/// RLNE `||x - x_ref|| / ||x_ref||` on complex values.
pub fn rlne(reference: &[Complex64], x: &[Complex64]) -> Result<f64> {
    check(reference, x)?;
    let num: f64 = reference
        .iter()
        .zip(x)
        .map(|(a, b)| (a - b).norm_sqr())
        .sum();
    let den: f64 = reference.iter().map(|a| a.norm_sqr()).sum();
    Ok((num / den).sqrt())
}

/// RLNE on magnitudes `|| |x| - |x_ref| || / ||x_ref||`.
pub fn rlne_magnitude(reference: &[Complex64], x: &[Complex64]) -> Result<f64> {
    check(reference, x)?;
    let num: f64 = reference
        .iter()
        .zip(x)
        .map(|(a, b)| (a.norm() - b.norm()).powi(2))
        .sum();
    let den: f64 = reference.iter().map(|a| a.norm_sqr()).sum();
    Ok((num / den).sqrt())
}

/// The constant of the metrics identity, `20 log10(max|x_ref| sqrt(n) / ||x_ref||)`.
pub fn identity_constant(reference: &[Complex64]) -> Result<f64> {
    if reference.is_empty() {
        return Err(Error::Empty("reference"));
    }
    let peak = reference.iter().map(|v| v.norm()).fold(0.0, f64::max);
    let norm: f64 = reference.iter().map(|a| a.norm_sqr()).sum::<f64>().sqrt();
    Ok(20.0 * (peak * (reference.len() as f64).sqrt() / norm).log10())
}
