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
use crate::filter::{gaussian_kernel, Border};
use crate::image::Image;
use crate::view::ImageView;

/// Errors unless `a` and `b` have the same, non-zero length (`what` names them).
fn check_lengths(what: &'static str, a: usize, b: usize) -> Result<()> {
    if a != b {
        return Err(Error::ShapeMismatch(format!(
            "{what} have {a} and {b} elements"
        )));
    }
    if a == 0 {
        return Err(Error::Empty(what));
    }
    Ok(())
}

fn check_pair<T: Copy + Into<f64>>(a: &[T], b: &[T]) -> Result<()> {
    check_lengths("inputs", a.len(), b.len())?;
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

crate::params! {
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

impl SsimParams {
    /// Checks the ranges: `data_range`, `sigma`, `truncate`, `k1` and `k2` finite and > 0.
    pub fn validate(&self) -> Result<()> {
        ensure_positive("data_range", self.data_range)?;
        ensure_positive("sigma", self.sigma)?;
        ensure_positive("truncate", self.truncate)?;
        ensure_positive("k1", self.k1)?;
        ensure_positive("k2", self.k2)
    }
}

/// Per-thread row buffers of the streaming SSIM.
struct RowBufs {
    /// Vertically filtered moments of one row: mean a, mean b, a^2, b^2, ab.
    v: [Vec<f64>; 5],
    /// The same after the horizontal pass.
    hz: [Vec<f64>; 5],
    /// A row padded by the kernel radius on both sides.
    pad: Vec<f64>,
}

impl RowBufs {
    fn new(w: usize, r: usize) -> Self {
        Self {
            v: std::array::from_fn(|_| vec![0.0; w]),
            hz: std::array::from_fn(|_| vec![0.0; w]),
            pad: vec![0.0; w + 2 * r],
        }
    }
}

/// Validated inputs of the SSIM kernels: the window and the stabilising constants.
struct SsimSetup<'a> {
    a: &'a [f64],
    b: &'a [f64],
    h: usize,
    w: usize,
    k: Vec<f64>,
    c1: f64,
    c2: f64,
}

fn ssim_setup<'a>(
    a: ImageView<'a, f64>,
    b: ImageView<'a, f64>,
    p: &SsimParams,
) -> Result<SsimSetup<'a>> {
    p.validate()?;
    a.ensure_plane("a")?;
    a.ensure_same_shape(&b, "b")?;
    check_pair(a.data(), b.data())?;
    Ok(SsimSetup {
        a: a.data(),
        b: b.data(),
        h: a.height(),
        w: a.width(),
        k: gaussian_kernel(p.sigma, p.truncate)?,
        c1: (p.k1 * p.data_range).powi(2),
        c2: (p.k2 * p.data_range).powi(2),
    })
}

/// SSIM (eq. 13 of Wang et al. 2004) of every pixel of row `y`, written to `out`.
///
/// The local moments are Gaussian-filtered on the fly, row by row, so no full-size
/// intermediate planes are allocated: the five moments of the rows under the window are
/// accumulated vertically, then filtered horizontally (`reflect` borders throughout).
fn ssim_row(s: &SsimSetup, y: usize, buf: &mut RowBufs, out: &mut [f64]) {
    let (a, b, h, w) = (s.a, s.b, s.h, s.w);
    let r = s.k.len() / 2;
    for v in buf.v.iter_mut() {
        v.fill(0.0);
    }
    for (j, &kj) in s.k.iter().enumerate() {
        let sy = Border::Reflect
            .map(y as isize + j as isize - r as isize, h)
            .expect("reflect maps every index");
        let ra = &a[sy * w..sy * w + w];
        let rb = &b[sy * w..sy * w + w];
        let [v0, v1, v2, v3, v4] = &mut buf.v;
        for x in 0..w {
            let (p, q) = (ra[x], rb[x]);
            v0[x] += kj * p;
            v1[x] += kj * q;
            v2[x] += kj * p * p;
            v3[x] += kj * q * q;
            v4[x] += kj * p * q;
        }
    }
    for (v, hz) in buf.v.iter().zip(buf.hz.iter_mut()) {
        for (i, p) in buf.pad.iter_mut().enumerate() {
            *p = v[Border::Reflect
                .map(i as isize - r as isize, w)
                .expect("reflect maps every index")];
        }
        hz.fill(0.0);
        for (j, &kj) in s.k.iter().enumerate() {
            hz.iter_mut()
                .zip(&buf.pad[j..j + w])
                .for_each(|(o, &v)| *o += kj * v);
        }
    }
    let [ux, uy, uxx, uyy, uxy] = &buf.hz;
    for x in 0..w {
        let (mx, my) = (ux[x], uy[x]);
        let vx = uxx[x] - mx * mx;
        let vy = uyy[x] - my * my;
        let vxy = uxy[x] - mx * my;
        out[x] = ((2.0 * mx * my + s.c1) * (2.0 * vxy + s.c2))
            / ((mx * mx + my * my + s.c1) * (vx + vy + s.c2));
    }
}

/// SSIM map of two single-channel images of one shape (eq. 13 of Wang et al. 2004 at every
/// pixel), uncropped.
///
/// Errors: more than one channel, different shapes, non-finite values, bad parameters.
pub fn ssim_map_plane(
    a: ImageView<'_, f64>,
    b: ImageView<'_, f64>,
    p: &SsimParams,
) -> Result<Image<f64>> {
    let s = ssim_setup(a, b, p)?;
    let (h, w) = (s.h, s.w);
    let r = s.k.len() / 2;
    let mut map = vec![0.0; h * w];
    map.par_chunks_mut(w).enumerate().for_each_init(
        || RowBufs::new(w, r),
        |buf, (y, out)| ssim_row(&s, y, buf, out),
    );
    Image::new(h, w, 1, map)
}

/// Mean SSIM of two single-channel images of one shape over the map cropped by the window
/// radius (scikit-image's averaging), without storing the map.
///
/// Errors: as [`ssim_map_plane`]; images smaller than the window.
pub fn ssim_plane(a: ImageView<'_, f64>, b: ImageView<'_, f64>, p: &SsimParams) -> Result<f64> {
    let s = ssim_setup(a, b, p)?;
    let (h, w) = (s.h, s.w);
    let r = s.k.len() / 2;
    if h <= 2 * r || w <= 2 * r {
        return Err(Error::invalid(
            "a, b",
            format!(
                "images of {h}x{w} are smaller than the {0}x{0} SSIM window",
                2 * r + 1
            ),
        ));
    }
    let total: f64 = (r..h - r)
        .into_par_iter()
        .map_init(
            || (RowBufs::new(w, r), vec![0.0; w]),
            |(buf, out), y| {
                ssim_row(&s, y, buf, out);
                out[r..w - r].iter().sum::<f64>()
            },
        )
        .sum();
    Ok(total / ((h - 2 * r) * (w - 2 * r)) as f64)
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
    let mut total = 0.0;
    for ch in 0..c {
        let (pa, pb) = (a.plane_f64(ch), b.plane_f64(ch));
        total += ssim_plane(
            ImageView::plane(h, w, &pa)?,
            ImageView::plane(h, w, &pb)?,
            p,
        )?;
    }
    Ok(total / c as f64)
}

/// Dice coefficient `2 |A ∩ B| / (|A| + |B|)` of two boolean masks of equal length.
/// Two empty masks give 1 (perfect agreement).
///
/// Errors: different lengths or zero length.
pub fn dice(a: &[bool], b: &[bool]) -> Result<f64> {
    check_lengths("masks", a.len(), b.len())?;
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
    fn streaming_map_equals_filtering_full_planes() {
        use crate::filter::separable_plane;
        let (c, n) = noisy(9, 0.1);
        let (h, w) = (64, 80);
        let a: Vec<f64> = c.data().iter().map(|&v| v as f64).collect();
        let b: Vec<f64> = n.data().iter().map(|&v| v as f64).collect();
        let p = SsimParams::default();
        let k = gaussian_kernel(p.sigma, p.truncate).unwrap();
        let f = |v: &[f64]| {
            separable_plane(ImageView::plane(h, w, v).unwrap(), &k, &k, Border::Reflect)
                .unwrap()
                .into_data()
        };
        let prod = |g: &dyn Fn(f64, f64) -> f64| -> Vec<f64> {
            a.iter().zip(&b).map(|(&x, &y)| g(x, y)).collect()
        };
        let (ux, uy) = (f(&a), f(&b));
        let (uxx, uyy, uxy) = (
            f(&prod(&|x, _| x * x)),
            f(&prod(&|_, y| y * y)),
            f(&prod(&|x, y| x * y)),
        );
        let (va, vb) = (
            ImageView::plane(h, w, &a).unwrap(),
            ImageView::plane(h, w, &b).unwrap(),
        );
        let map = ssim_map_plane(va, vb, &p).unwrap().into_data();
        let (c1, c2) = (1e-4, 9e-4);
        for i in 0..h * w {
            let (vx, vy, vxy) = (
                uxx[i] - ux[i] * ux[i],
                uyy[i] - uy[i] * uy[i],
                uxy[i] - ux[i] * uy[i],
            );
            let e = ((2.0 * ux[i] * uy[i] + c1) * (2.0 * vxy + c2))
                / ((ux[i] * ux[i] + uy[i] * uy[i] + c1) * (vx + vy + c2));
            assert!((map[i] - e).abs() < 1e-10, "pixel {i}");
        }
        let mut s = 0.0;
        for y in 5..h - 5 {
            for x in 5..w - 5 {
                s += map[y * w + x];
            }
        }
        let mean = s / ((h - 10) * (w - 10)) as f64;
        assert!((ssim_plane(va, vb, &p).unwrap() - mean).abs() < 1e-12);
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
