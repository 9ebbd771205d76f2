//! Noise level of a blurred input and the noise-aware data weight of the Krishnan-Fergus
//! solver (paper eqs. 7-8).
//!
//! **Estimator** (Donoho and Johnstone 1994, Donoho 1995): the median absolute value of the
//! finest diagonal Haar wavelet coefficients, `HH = (a - b - c + d) / 2` over disjoint 2 x 2
//! blocks, divided by 0.6745 (the median of `|N(0, 1)|`). The Haar `HH` filter has unit norm,
//! so on white Gaussian noise of deviation `sigma` its coefficients have deviation `sigma`; a
//! blurred photograph has almost no signal in that subband, and the median ignores the few
//! edges that leak into it. It was preferred to Immerkaer's Laplacian-based estimator
//! (1996), whose mean absolute response counts every edge of the image: on a blurred input
//! both are cheap, but the median is the robust one. Cost: one pass over the image and a
//! linear-time selection of the median (about 1 ms for a 512 x 512 image).
//!
//! **Rule**: KF's `lambda` weighs the data term `lambda/2 ||k * I - B||^2` against the prior
//! `sum |grad I|^alpha`; read as a MAP estimate under Gaussian noise, the data term is
//! `||k * I - B||^2 / (2 sigma^2)`, so `lambda = c / sigma^2`: more noise, smaller `lambda`,
//! more regularisation. `c = 0.3` was fitted on one photograph (scikit-image's `camera`, an
//! 11-pixel box blur and a gyro-rendered shake kernel, sigma 0.002-0.02; the PSNR is within
//! 0.3 dB of the best `c` at every level, `benches/peers/_12_lam.py`) and checked on others
//! (`BENCHMARKS.md`). The estimate is floored at [`MIN_SIGMA`] so a noise-free input does not
//! get an unbounded weight.

use wscg_math::{Error, Image, Result};

/// `c` of the rule `lambda = c / sigma^2`.
pub const LAMBDA_PER_INVERSE_VARIANCE: f32 = 0.3;

/// Floor of the noise estimate used by the rule (an 8-bit image's quantisation noise is
/// `1 / (255 sqrt 12) = 0.0011`): `lambda` is at most `0.3 / 1e-6 = 300 000`.
pub const MIN_SIGMA: f32 = 1e-3;

/// Standard deviation of white Gaussian noise in a single-channel image, from the median
/// absolute finest diagonal Haar coefficient divided by 0.6745 (see the module
/// documentation). An odd last row or column is left out.
///
/// Errors: a multi-channel image, or one smaller than 2 x 2; a non-finite value.
pub fn estimate_noise(image: &Image<f32>) -> Result<f32> {
    if image.channels() != 1 {
        return Err(Error::invalid(
            "image",
            format!(
                "expected a single-channel (grayscale) image, got {} channels",
                image.channels()
            ),
        ));
    }
    let (h, w) = (image.height(), image.width());
    if h < 2 || w < 2 {
        return Err(Error::invalid(
            "image",
            format!("the noise estimate needs at least 2 x 2 pixels, got {h} x {w}"),
        ));
    }
    image.ensure_finite("image")?;
    let d = image.data();
    let mut hh = Vec::with_capacity((h / 2) * (w / 2));
    for r in (0..h - 1).step_by(2) {
        let (top, bottom) = (&d[r * w..][..w], &d[(r + 1) * w..][..w]);
        for c in (0..w - 1).step_by(2) {
            hh.push(((top[c] - top[c + 1] - bottom[c] + bottom[c + 1]) * 0.5).abs());
        }
    }
    let mid = hh.len() / 2;
    let (_, median, _) = hh.select_nth_unstable_by(mid, f32::total_cmp);
    Ok(*median / 0.6745)
}

/// The data weight for noise of deviation `sigma`: `0.3 / max(sigma, 1e-3)^2` (see the module
/// documentation).
pub fn lambda_for_noise(sigma: f32) -> f32 {
    let s = sigma.max(MIN_SIGMA);
    LAMBDA_PER_INVERSE_VARIANCE / (s * s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::{Distribution, Normal};

    #[test]
    fn recovers_white_noise() {
        let mut r = wscg_math::rng::seeded(5);
        let n = Normal::new(0.0f32, 0.01).unwrap();
        // A smooth ramp plus noise: the ramp has no diagonal detail.
        let data: Vec<f32> = (0..256 * 256)
            .map(|i| 0.3 + 0.001 * (i % 256) as f32 + n.sample(&mut r))
            .collect();
        let s = estimate_noise(&Image::new(256, 256, 1, data).unwrap()).unwrap();
        assert!((s - 0.01).abs() < 0.0005, "{s}");
        assert_eq!(lambda_for_noise(0.01), 0.3 / (0.01 * 0.01));
        assert_eq!(lambda_for_noise(0.0), 0.3 / (MIN_SIGMA * MIN_SIGMA));
        assert!(estimate_noise(&Image::new(1, 4, 1, vec![0.0; 4]).unwrap()).is_err());
    }
}
