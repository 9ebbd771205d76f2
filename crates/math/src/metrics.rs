//! Image and segmentation metrics: MSE, RMSE, PSNR, SSIM and Dice.
//!
//! SSIM is the structural similarity of Wang, Bovik, Sheikh and Simoncelli, "Image quality
//! assessment: from error visibility to structural similarity", IEEE TIP 13(4), 2004,
//! doi:10.1109/TIP.2003.819861, eq. (13), with a Gaussian window (sigma 1.5, 11 x 11) and the
//! constants K1 = 0.01, K2 = 0.03. It is computed exactly as scikit-image's
//! `structural_similarity(a, b, data_range=R, gaussian_weights=True, sigma=1.5,
//! use_sample_covariance=False)`: local moments by Gaussian filtering with `reflect` borders,
//! the SSIM map cropped by the window radius before averaging, multi-channel images averaged
//! over channels.

use rayon::prelude::*;

use crate::error::{ensure_finite, ensure_positive, Error, Result};
use crate::filter::{gaussian_kernel, separable_plane, Border};
use crate::image::Image;

fn check_pair<T: Copy + Into<f64>>(a: &[T], b: &[T]) -> Result<()> {
    if a.len() != b.len() {
        return Err(Error::ShapeMismatch(format!(
            "inputs have {} and {} values",
            a.len(),
            b.len()
        )));
    }
    if a.is_empty() {
        return Err(Error::Empty("input"));
    }
    ensure_finite("a", a)?;
    ensure_finite("b", b)
}

/// Mean squared error `mean((a - b)^2)` of two equally long arrays.
///
/// Errors: different lengths, empty, non-finite values.
pub fn mse<T: Copy + Into<f64> + Sync>(a: &[T], b: &[T]) -> Result<f64> {
    check_pair(a, b)?;
    let s: f64 = a
        .par_iter()
        .zip(b)
        .map(|(&x, &y)| {
            let d = x.into() - y.into();
            d * d
        })
        .sum();
    Ok(s / a.len() as f64)
}

/// Root mean squared error `sqrt(mse(a, b))`.
pub fn rmse<T: Copy + Into<f64> + Sync>(a: &[T], b: &[T]) -> Result<f64> {
    mse(a, b).map(f64::sqrt)
}

/// Peak signal-to-noise ratio `10 log10(R^2 / mse)` in dB, `R = data_range` (1 for images in
/// `[0, 1]`, 255 for 8-bit). Identical inputs give `f64::INFINITY`.
///
/// Errors: as [`mse`], and `data_range` not > 0.
pub fn psnr<T: Copy + Into<f64> + Sync>(a: &[T], b: &[T], data_range: f64) -> Result<f64> {
    ensure_positive("data_range", data_range)?;
    let m = mse(a, b)?;
    Ok(if m == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (data_range * data_range / m).log10()
    })
}

/// Parameters of [`ssim`] (defaults: Wang et al. 2004 with a Gaussian window).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SsimParams {
    /// Dynamic range `R` of the data (1 for `[0, 1]` images).
    pub data_range: f64,
    /// Standard deviation of the Gaussian window (1.5).
    pub sigma: f64,
    /// Window radius in standard deviations (3.5, giving an 11 x 11 window at sigma 1.5).
    pub truncate: f64,
    /// `K1` (0.01).
    pub k1: f64,
    /// `K2` (0.03).
    pub k2: f64,
}

impl Default for SsimParams {
    fn default() -> Self {
        Self {
            data_range: 1.0,
            sigma: 1.5,
            truncate: 3.5,
            k1: 0.01,
            k2: 0.03,
        }
    }
}

/// SSIM map of two `h x w` planes (eq. 13 of Wang et al. 2004 at every pixel), uncropped.
pub fn ssim_map_plane(
    a: &[f64],
    b: &[f64],
    h: usize,
    w: usize,
    p: &SsimParams,
) -> Result<Vec<f64>> {
    check_pair(a, b)?;
    if a.len() != h * w {
        return Err(Error::ShapeMismatch(format!(
            "plane has {} values, expected {h}x{w}",
            a.len()
        )));
    }
    ensure_positive("data_range", p.data_range)?;
    ensure_positive("k1", p.k1)?;
    ensure_positive("k2", p.k2)?;
    let k = gaussian_kernel(p.sigma, p.truncate)?;
    let filt = |v: &[f64]| separable_plane(v, h, w, &k, &k, Border::Reflect);
    let prod = |f: &(dyn Fn(f64, f64) -> f64 + Sync)| -> Vec<f64> {
        a.par_iter().zip(b).map(|(&x, &y)| f(x, y)).collect()
    };
    let ux = filt(a)?;
    let uy = filt(b)?;
    let uxx = filt(&prod(&|x, _| x * x))?;
    let uyy = filt(&prod(&|_, y| y * y))?;
    let uxy = filt(&prod(&|x, y| x * y))?;
    let c1 = (p.k1 * p.data_range).powi(2);
    let c2 = (p.k2 * p.data_range).powi(2);
    Ok((0..h * w)
        .into_par_iter()
        .map(|i| {
            let (mx, my) = (ux[i], uy[i]);
            let vx = uxx[i] - mx * mx;
            let vy = uyy[i] - my * my;
            let vxy = uxy[i] - mx * my;
            ((2.0 * mx * my + c1) * (2.0 * vxy + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
        })
        .collect())
}

/// Mean SSIM of two images of equal shape (channels averaged), as scikit-image's
/// `structural_similarity(..., gaussian_weights=True, use_sample_covariance=False,
/// channel_axis=-1)`.
///
/// Errors: shape mismatch, non-finite pixels, images smaller than the 11 x 11 window (a
/// window of `2 * int(truncate * sigma + 0.5) + 1` in general), bad parameters.
pub fn ssim(a: &Image<f32>, b: &Image<f32>, p: &SsimParams) -> Result<f64> {
    a.ensure_same_shape(b)?;
    let (h, w, c) = a.shape();
    let radius = (p.truncate * p.sigma + 0.5) as usize;
    let win = 2 * radius + 1;
    if h < win || w < win {
        return Err(Error::invalid(
            "a, b",
            format!("images of {h}x{w} are smaller than the {win}x{win} SSIM window"),
        ));
    }
    let mut total = 0.0;
    for ch in 0..c {
        let pa: Vec<f64> = a
            .data()
            .iter()
            .skip(ch)
            .step_by(c)
            .map(|&v| v as f64)
            .collect();
        let pb: Vec<f64> = b
            .data()
            .iter()
            .skip(ch)
            .step_by(c)
            .map(|&v| v as f64)
            .collect();
        let map = ssim_map_plane(&pa, &pb, h, w, p)?;
        let (mut s, mut n) = (0.0, 0usize);
        for y in radius..h - radius {
            s += map[y * w + radius..y * w + w - radius].iter().sum::<f64>();
            n += w - 2 * radius;
        }
        total += s / n as f64;
    }
    Ok(total / c as f64)
}

/// Dice coefficient `2 |A ∩ B| / (|A| + |B|)` of two boolean masks of equal length.
/// Two empty masks give 1 (perfect agreement).
///
/// Errors: different lengths or zero length.
pub fn dice(a: &[bool], b: &[bool]) -> Result<f64> {
    if a.len() != b.len() {
        return Err(Error::ShapeMismatch(format!(
            "masks have {} and {} elements",
            a.len(),
            b.len()
        )));
    }
    if a.is_empty() {
        return Err(Error::Empty("mask"));
    }
    let (inter, na, nb) = a
        .par_iter()
        .zip(b)
        .map(|(&x, &y)| ((x && y) as usize, x as usize, y as usize))
        .reduce(|| (0, 0, 0), |p, q| (p.0 + q.0, p.1 + q.1, p.2 + q.2));
    Ok(if na + nb == 0 {
        1.0
    } else {
        2.0 * inter as f64 / (na + nb) as f64
    })
}

/// Dice coefficient of label `label` in two label maps.
pub fn dice_label(a: &[u32], b: &[u32], label: u32) -> Result<f64> {
    let ma: Vec<bool> = a.iter().map(|&v| v == label).collect();
    let mb: Vec<bool> = b.iter().map(|&v| v == label).collect();
    dice(&ma, &mb)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng;

    fn noisy(seed: u64, sigma: f64) -> (Image, Image) {
        let clean = Image::from_fn(64, 80, |y, x| {
            0.5 + 0.4 * ((x as f32) / 7.0).sin() * ((y as f32) / 5.0).cos()
        })
        .unwrap();
        let n = rng::normal_vec(seed, 64 * 80, 0.0, sigma).unwrap();
        let d: Vec<f32> = clean
            .data()
            .iter()
            .zip(&n)
            .map(|(&c, &e)| c + e as f32)
            .collect();
        let noisy = Image::new(64, 80, 1, d).unwrap();
        (clean, noisy)
    }

    #[test]
    fn psnr_of_gaussian_noise_matches_the_analytic_value() {
        // E[mse] = sigma^2, so PSNR = -20 log10(sigma) for R = 1.
        // With n samples the MSE has relative standard deviation sqrt(2/n): for n = 2^18 the
        // PSNR is within 0.012 dB of the expectation at one standard deviation.
        let n = 1 << 18;
        let c = vec![0.5f64; n];
        let noise = rng::normal_vec(4, n, 0.0, 0.05).unwrap();
        let d: Vec<f64> = c.iter().zip(&noise).map(|(a, e)| a + e).collect();
        let p = psnr(&c, &d, 1.0).unwrap();
        assert!((p - 26.0206).abs() < 0.05, "{p}");
        assert_eq!(psnr(&c, &c, 1.0).unwrap(), f64::INFINITY);
        let r = rmse(&[0.0f64, 0.0], &[3.0, 4.0]).unwrap();
        assert!((r - 12.5f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn ssim_properties() {
        let (c, n) = noisy(5, 0.1);
        let p = SsimParams::default();
        assert!((ssim(&c, &c, &p).unwrap() - 1.0).abs() < 1e-12);
        let s = ssim(&c, &n, &p).unwrap();
        let s2 = ssim(&n, &c, &p).unwrap();
        assert!((s - s2).abs() < 1e-12, "symmetric");
        assert!(s < 0.8 && s > 0.0, "{s}");
        let (_, n_small) = noisy(5, 0.02);
        assert!(
            ssim(&c, &n_small, &p).unwrap() > s,
            "less noise, higher SSIM"
        );
        // A constant shift only changes the luminance term: for mean-free structure with
        // shift d on plane mean mu: l = (2 mu (mu+d) + C1)/(mu^2 + (mu+d)^2 + C1) everywhere.
        let flat = Image::filled(20, 20, 1, 0.5f32).unwrap();
        let shifted = flat.map(|v| v + 0.1);
        let c1 = 1e-4;
        let expect = (2.0 * 0.5 * 0.6 + c1) / (0.25 + 0.36 + c1);
        assert!((ssim(&flat, &shifted, &p).unwrap() - expect).abs() < 1e-6);
    }

    #[test]
    fn ssim_rejects_bad_input() {
        let (c, _) = noisy(1, 0.1);
        let small = Image::filled(8, 8, 1, 0.0f32).unwrap();
        assert!(ssim(&small, &small, &SsimParams::default()).is_err());
        let other = Image::filled(64, 81, 1, 0.0f32).unwrap();
        assert!(matches!(
            ssim(&c, &other, &SsimParams::default()),
            Err(Error::ShapeMismatch(_))
        ));
        let bad = SsimParams {
            data_range: 0.0,
            ..Default::default()
        };
        assert!(ssim(&c, &c, &bad).is_err());
        let mut nan = c.clone();
        nan.set(3, 3, 0, f32::NAN);
        assert!(ssim(&c, &nan, &SsimParams::default()).is_err());
        assert!(mse::<f64>(&[], &[]).is_err());
        assert!(psnr(&[1.0f32], &[1.0, 2.0], 1.0).is_err());
    }

    #[test]
    fn dice_counts_overlap() {
        let a = [true, true, false, false];
        let b = [true, false, true, false];
        assert!((dice(&a, &b).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(dice(&[false; 3], &[false; 3]).unwrap(), 1.0);
        assert_eq!(dice(&a, &a).unwrap(), 1.0);
        assert!(dice(&a, &b[..3]).is_err());
        assert!((dice_label(&[1, 2, 2], &[2, 2, 1], 2).unwrap() - 0.5).abs() < 1e-12);
    }
}
