//! Demo of the shared math crate: FFT, noise metrics against their analytic values, Gaussian
//! denoising, resizing, and the conjugate gradient on a 3-D Poisson problem with a known
//! solution. Everything is generated in code.

use std::f64::consts::PI;

use std::path::Path;

use num_complex::Complex;
use wscg_math::fft::{self, Direction, Norm};
use wscg_math::filter::{gaussian_filter, Border};
use wscg_math::image::Image;
use wscg_math::metrics::{psnr, ssim, SsimParams};
use wscg_math::progress::Progress;
use wscg_math::resize::{resize, Interpolation};
use wscg_math::sparse::{pcg, CsrMatrix, InitialGuess, Jacobi, PcgParams};
use wscg_math::{rng, Result, TriMesh, Volume};

use super::{Demo, Figure, Report, Row};

/// Registration of this demo.
pub const DEMO: Demo = Demo {
    name: "math",
    paper: "-",
    title: "Shared numerics: FFT, image metrics, filters, resizing, conjugate gradient",
    run,
};

/// Side of the generated test image.
const N: usize = 512;

/// A zone plate (local frequency rising linearly to Nyquist at the border of the inscribed
/// disc) over a soft background: every spatial frequency appears once, which makes FFT,
/// blur and resampling artefacts visible.
pub fn zone_plate(n: usize) -> Image {
    let c = n as f64 / 2.0;
    Image::from_fn(n, n, |y, x| {
        let (dy, dx) = (y as f64 + 0.5 - c, x as f64 + 0.5 - c);
        let r2 = dx * dx + dy * dy;
        let window = 0.5 * (1.0 + (PI * (r2.sqrt() / c).min(1.0)).cos());
        (0.5 + 0.4 * window * (PI * r2 / n as f64).cos()) as f32
    })
    .expect("non-empty image")
}

fn run(out: &Path, progress: &dyn Progress) -> Result<Report> {
    let mut rep = Report {
        summary: format!(
            "A {N}x{N} zone plate is transformed with the 2-D FFT, degraded with Gaussian noise \
             of known standard deviation (PSNR must match -20 log10 sigma), denoised with a \
             Gaussian filter and resized by area averaging; icosphere meshes and a sampled \
             distance field are checked against their analytic values, and a 64^3 Poisson \
             system with a manufactured solution is solved by Jacobi-preconditioned conjugate \
             gradient."
        ),
        ..Default::default()
    };
    progress.begin("math demo", 6);
    let img = zone_plate(N);
    img.save(out.join("zone_plate.png"))?;
    rep.figures.push(Figure {
        file: "zone_plate.png".into(),
        caption: format!("Generated {N}x{N} zone plate"),
    });
    progress.advance(1);

    // FFT and Parseval's identity.
    let mut spec: Vec<Complex<f64>> = img
        .data()
        .iter()
        .map(|&v| Complex::new(v as f64, 0.0))
        .collect();
    rep.time("fft2 512x512 (s)", || {
        fft::fft2(&mut spec, N, N, Direction::Forward, Norm::Backward)
    })?;
    let e_space: f64 = img.data().iter().map(|&v| (v as f64).powi(2)).sum();
    let e_freq: f64 = spec.iter().map(|c| c.norm_sqr()).sum::<f64>() / (N * N) as f64;
    rep.table.push(Row::new(
        "Parseval: sum|F|^2 / (N sum|x|^2)",
        format!("{:.12}", e_freq / e_space),
        "1",
        "exact identity of the DFT",
    ));
    let mag: Vec<f32> = fft::fftshift(&spec, &[N, N])?
        .iter()
        .map(|c| (1.0 + c.norm()).ln() as f32)
        .collect();
    let mx = mag.iter().cloned().fold(0.0f32, f32::max);
    let spectrum = Image::new(N, N, 1, mag.iter().map(|v| v / mx).collect())?;
    spectrum.save(out.join("spectrum.png"))?;
    rep.figures.push(Figure {
        file: "spectrum.png".into(),
        caption: "log(1 + |F|), centred (fftshift)".into(),
    });
    progress.advance(1);

    // Noise: PSNR against its expectation, SSIM, and Gaussian denoising.
    let params = SsimParams::default();
    let mut noisy_01 = None;
    for (k, sigma) in [0.01, 0.02, 0.05, 0.1].into_iter().enumerate() {
        let noise = rng::normal_vec(k as u64, N * N, 0.0, sigma)?;
        let data: Vec<f32> = img
            .data()
            .iter()
            .zip(&noise)
            .map(|(&v, &e)| v + e as f32)
            .collect();
        let noisy = Image::new(N, N, 1, data)?;
        let p = psnr(img.data(), noisy.data(), 1.0)?;
        let s = ssim(&img, &noisy, &params)?;
        rep.table.push(Row::new(
            format!("PSNR, Gaussian noise sigma = {sigma} (dB)"),
            format!("{p:.3}"),
            format!("{:.3}", -20.0 * sigma.log10()),
            format!("expectation -20 log10 sigma; SSIM = {s:.4}"),
        ));
        if sigma == 0.1 {
            noisy_01 = Some(noisy);
        }
    }
    let noisy = noisy_01.expect("sigma 0.1 is in the sweep");
    noisy
        .map(|v| v.clamp(0.0, 1.0))
        .save(out.join("noisy.png"))?;
    let den = rep.time("gaussian_filter sigma=1 512x512 (s)", || {
        gaussian_filter(&noisy, 1.0, 4.0, Border::Reflect)
    })?;
    den.map(|v| v.clamp(0.0, 1.0))
        .save(out.join("denoised.png"))?;
    rep.figures.push(Figure {
        file: "noisy.png".into(),
        caption: "Gaussian noise, sigma = 0.1".into(),
    });
    rep.figures.push(Figure {
        file: "denoised.png".into(),
        caption: "Gaussian filter, sigma = 1 pixel".into(),
    });
    rep.table.push(Row::new(
        "SSIM noisy -> Gaussian-filtered (sigma 0.1 noise)",
        format!(
            "{:.4} -> {:.4}",
            ssim(&img, &noisy, &params)?,
            ssim(&img, &den, &params)?
        ),
        "",
        "Wang et al. 2004 with an 11x11 Gaussian window, as scikit-image",
    ));
    progress.advance(1);

    // Area resizing preserves the mean exactly.
    let small = resize(&img, N / 4, N / 4, Interpolation::Area)?;
    small.save(out.join("area_128.png"))?;
    rep.figures.push(Figure {
        file: "area_128.png".into(),
        caption: "Area downscaling to 128x128 (no aliasing rings)".into(),
    });
    let mean = |d: &[f32]| d.iter().map(|&v| v as f64).sum::<f64>() / d.len() as f64;
    rep.table.push(Row::new(
        "mean after area resize - mean before",
        format!("{:.2e}", mean(small.data()) - mean(img.data())),
        "0",
        "area averaging conserves the integral",
    ));
    progress.advance(1);

    // PCG on the 3-D Poisson problem with a manufactured solution: b = A x_exact for a
    // random x_exact, so the error of the computed x is known exactly.
    let n = 64;
    let a = CsrMatrix::laplacian_3d(n, n, n)?;
    let u = rng::uniform_vec(11, n * n * n, -1.0, 1.0)?;
    let b = a.mul_vec(&u)?;
    let jac = Jacobi::new(&a.diagonal())?;
    let opts = PcgParams::default().tol(1e-10).max_iter(None);
    let res = rep.time("pcg Poisson 64^3 (s)", || {
        pcg(&a, &b, InitialGuess::Zero, &jac, &opts)
    })?;
    let err = res
        .x
        .iter()
        .zip(&u)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max);
    rep.table.push(Row::new(
        "PCG 64^3 Poisson: max |x - x_exact|",
        format!("{err:.2e} ({} iterations)", res.iterations),
        "0",
        "b = A x_exact, so the exact solution is known; tolerance 1e-10",
    ));
    progress.advance(1);

    // Meshes and volumes: icosphere area and volume converge to the sphere's; the gradient
    // of a sampled distance field has unit length.
    for k in [1u32, 3, 5] {
        let m = TriMesh::icosphere(k, 1.0)?;
        rep.table.push(Row::new(
            format!("icosphere level {k}: area / 4 pi, volume / (4/3 pi)"),
            format!(
                "{:.5}, {:.5}",
                m.total_area() / (4.0 * PI),
                m.signed_volume() / (4.0 / 3.0 * PI)
            ),
            "-> 1, 1",
            format!("{} faces, closed: {}", m.num_faces(), m.is_closed()),
        ));
    }
    let dist = Volume::from_fn([48, 40, 32], [0.5, 0.6, 0.8], |x, y, z| {
        let p = [
            x as f64 * 0.5 - 12.0,
            y as f64 * 0.6 - 12.0,
            z as f64 * 0.8 - 12.0,
        ];
        (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() as f32
    })?;
    let g = dist.gradient_trilinear([30.3, 27.1, 21.7]);
    rep.table.push(Row::new(
        "|grad| of a distance field, anisotropic voxels",
        format!(
            "{:.4}",
            g.iter().map(|v| (*v as f64).powi(2)).sum::<f64>().sqrt()
        ),
        "1",
        "central differences in physical units, trilinear blend",
    ));
    progress.advance(1);
    progress.finish();
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zone_plate_reaches_both_extremes_and_stays_in_range() {
        let z = zone_plate(64);
        let (lo, hi) = z
            .data()
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        assert!(lo >= 0.1 - 1e-6 && hi <= 0.9 + 1e-6);
        assert!(hi - lo > 0.7);
    }
}
