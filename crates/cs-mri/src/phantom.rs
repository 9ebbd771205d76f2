//! Test images with exact ground truth (paper 11, section 3 stand-ins; the paper's own data
//! are not available offline).
//!
//! - [`shepp_logan_kspace`]: the modified Shepp-Logan phantom (Toft) sampled analytically in
//!   k-space, so that reconstructions are not judged against the raster they were simulated
//!   from (no "inverse crime"); [`shepp_logan_reference`] is the inverse FFT of the full
//!   analytic k-space, the reference image as in MRI practice.
//! - [`with_smooth_phase`]: a magnitude image times a smooth quadratic phase, a complex
//!   "T2w-like" image that exercises the real/imaginary split of the prior.
//! - [`diamond_lattice`]: a disk filled with a rhombic lattice, the directional texture of
//!   the paper's water phantom.

use std::f64::consts::PI;

use num_complex::Complex64;
use rand::Rng;
use wscg_math::{Error, Image, ImageView, Result};

use crate::fourier::{signed_frequency, Fourier};

/// Modified Shepp-Logan ellipses (Toft): intensity, semi-axes a (x) and b (y), centre, angle
/// in degrees, on the field of view [-1, 1]^2 with y up.
pub const SHEPP_LOGAN: [[f64; 6]; 10] = [
    [1.0, 0.69, 0.92, 0.0, 0.0, 0.0],
    [-0.8, 0.6624, 0.874, 0.0, -0.0184, 0.0],
    [-0.2, 0.11, 0.31, 0.22, 0.0, -18.0],
    [-0.2, 0.16, 0.41, -0.22, 0.0, 18.0],
    [0.1, 0.21, 0.25, 0.0, 0.35, 0.0],
    [0.1, 0.046, 0.046, 0.0, 0.1, 0.0],
    [0.1, 0.046, 0.046, 0.0, -0.1, 0.0],
    [0.1, 0.046, 0.023, -0.08, -0.605, 0.0],
    [0.1, 0.023, 0.023, 0.0, -0.606, 0.0],
    [0.1, 0.023, 0.046, 0.06, -0.605, 0.0],
];

fn check_size(n: usize) -> Result<()> {
    if n < 4 || !n.is_multiple_of(2) || n > 1 << 14 {
        return Err(Error::invalid(
            "n",
            format!("{n} must be even, at least 4 and at most 16384"),
        ));
    }
    Ok(())
}

/// Fourier transform of the ellipse table at spatial frequency `(kx, ky)` (cycles per unit):
/// `sum rho a b e^{-2 pi i k.c} J1(2 pi q) / q`, `q = |diag(a, b) R^T k|` (limit `pi` at 0).
/// Rows of the image run downward, so the table's y is mirrored.
fn ellipses_ft(kx: f64, ky: f64) -> Complex64 {
    let mut sum = Complex64::new(0.0, 0.0);
    for e in SHEPP_LOGAN {
        let [rho, a, b, x0, y0, deg] = e;
        let (y0, th) = (-y0, -deg.to_radians());
        let (s, c) = th.sin_cos();
        let u = a * (kx * c + ky * s);
        let v = b * (-kx * s + ky * c);
        let q = (u * u + v * v).sqrt();
        let disk = if q < 1e-12 {
            PI
        } else {
            libm::j1(2.0 * PI * q) / q
        };
        let phase = -2.0 * PI * (kx * x0 + ky * y0);
        sum += Complex64::from_polar(rho * a * b * disk, phase);
    }
    sum
}

/// The analytic k-space of the modified Shepp-Logan phantom on an `n x n` grid: un-shifted
/// (DC at index 0), scaled like the unitary FFT of the phantom rasterised on pixel corners
/// `-1 + 2 i / n` (so its DC equals the raster's sum divided by `n`).
pub fn shepp_logan_kspace(n: usize) -> Result<Vec<Complex64>> {
    check_size(n)?;
    let scale = n as f64 / 4.0;
    let mut out = vec![Complex64::new(0.0, 0.0); n * n];
    for (k, o) in out.iter_mut().enumerate() {
        let (m0, m1) = (
            signed_frequency(k / n, n) as f64,
            signed_frequency(k % n, n) as f64,
        );
        let sign = if (m0 + m1).rem_euclid(2.0) == 0.0 {
            1.0
        } else {
            -1.0
        };
        *o = ellipses_ft(m1 / 2.0, m0 / 2.0) * (scale * sign);
    }
    Ok(out)
}

/// The reference image: the unitary inverse FFT of [`shepp_logan_kspace`].
pub fn shepp_logan_reference(n: usize) -> Result<Vec<Complex64>> {
    let mut x = shepp_logan_kspace(n)?;
    Fourier::new(n, n)?.inverse(&mut x);
    Ok(x)
}

/// The phantom rasterised at pixel corners `-1 + 2 i / n` (for display and for users who
/// want an image to simulate from).
pub fn shepp_logan_image(n: usize) -> Result<Vec<f64>> {
    check_size(n)?;
    let mut out = vec![0.0; n * n];
    for (k, o) in out.iter_mut().enumerate() {
        let (y, x) = (
            -1.0 + 2.0 * (k / n) as f64 / n as f64,
            -1.0 + 2.0 * (k % n) as f64 / n as f64,
        );
        for e in SHEPP_LOGAN {
            let [rho, a, b, x0, y0, deg] = e;
            let (y0, th) = (-y0, -deg.to_radians());
            let (s, c) = th.sin_cos();
            let (dx, dy) = (x - x0, y - y0);
            let u = (dx * c + dy * s) / a;
            let v = (-dx * s + dy * c) / b;
            if u * u + v * v <= 1.0 {
                *o += rho;
            }
        }
    }
    Ok(out)
}

/// `magnitude * exp(i phi)` with a smooth random quadratic phase `phi` whose peak-to-peak
/// value over the image is `2 pi` (seeded): a complex image of the shape of `magnitude`.
///
/// Errors: `magnitude` with more than one channel.
pub fn with_smooth_phase(magnitude: ImageView<'_, f64>, seed: u64) -> Result<Image<Complex64>> {
    magnitude.ensure_plane("magnitude")?;
    let (rows, cols) = (magnitude.height(), magnitude.width());
    let mut r = wscg_math::rng::seeded(seed);
    let c: [f64; 5] = std::array::from_fn(|_| r.random_range(-1.0..1.0));
    let raw: Vec<f64> = (0..rows * cols)
        .map(|k| {
            let y = 2.0 * (k / cols) as f64 / rows as f64 - 1.0;
            let x = 2.0 * (k % cols) as f64 / cols as f64 - 1.0;
            c[0] * x + c[1] * y + c[2] * x * x + c[3] * y * y + c[4] * x * y
        })
        .collect();
    let (lo, hi) = raw
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let span = (hi - lo).max(1e-12);
    let data = magnitude
        .data()
        .iter()
        .zip(&raw)
        .map(|(&m, &p)| Complex64::from_polar(m, 2.0 * PI * (p - lo) / span - PI))
        .collect();
    Image::new(rows, cols, 1, data)
}

/// A disk of radius 0.8 (field of view [-1, 1]^2) filled with the rhombic lattice
/// `|cos(pi (x + y) / p)| + |cos(pi (x - y) / p)| > 1.2` (`x, y` and the period `p` in
/// pixels; 1 on the lattice, 0.3 elsewhere inside the disk): the directional texture of
/// the paper's water phantom.
pub fn diamond_lattice(n: usize, period: f64) -> Result<Vec<f64>> {
    check_size(n)?;
    if !(period >= 2.0 && period.is_finite()) {
        return Err(Error::invalid(
            "period",
            format!("{period} must be at least 2 pixels"),
        ));
    }
    let h = n as f64 / 2.0;
    Ok((0..n * n)
        .map(|k| {
            let (i, j) = ((k / n) as f64, (k % n) as f64);
            let (u, v) = ((j - h) / h, (i - h) / h);
            if u * u + v * v > 0.64 {
                return 0.0;
            }
            let a = (PI * (i + j) / period).cos().abs() + (PI * (i - j) / period).cos().abs();
            if a > 1.2 {
                1.0
            } else {
                0.3
            }
        })
        .collect())
}
