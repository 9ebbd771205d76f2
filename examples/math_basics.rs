//! The shared math crate in a few lines: noise metrics, a Gaussian filter, an FFT and a
//! conjugate-gradient solve. Run with `cargo run --release --example math_basics`.

use num_complex::Complex;
use wscg::math::fft::{self, Direction, Norm};
use wscg::math::filter::{gaussian_filter, Border};
use wscg::math::image::Image;
use wscg::math::metrics::{psnr, ssim, SsimParams};
use wscg::math::rng;
use wscg::math::sparse::{pcg, CsrMatrix, InitialGuess, Jacobi, PcgParams};

fn main() -> wscg::math::Result<()> {
    // A smooth test image and a noisy copy (sigma = 0.05).
    let (h, w) = (256, 256);
    let clean = Image::from_fn(h, w, |y, x| {
        0.5 + 0.3 * ((x as f32) / 9.0).sin() * ((y as f32) / 13.0).cos()
    })?;
    let noise = rng::normal_vec(42, h * w, 0.0, 0.05)?;
    let noisy = Image::new(
        h,
        w,
        1,
        clean
            .data()
            .iter()
            .zip(&noise)
            .map(|(&c, &e)| c + e as f32)
            .collect(),
    )?;
    let denoised = gaussian_filter(&noisy, 1.5, 4.0, Border::Reflect)?;
    let p = SsimParams::default();
    println!(
        "noisy:    PSNR {:.2} dB (expected {:.2}), SSIM {:.4}",
        psnr(clean.data(), noisy.data(), 1.0)?,
        -20.0 * 0.05f64.log10(),
        ssim(&clean, &noisy, &p)?
    );
    println!(
        "denoised: PSNR {:.2} dB, SSIM {:.4}",
        psnr(clean.data(), denoised.data(), 1.0)?,
        ssim(&clean, &denoised, &p)?
    );

    // The spectrum's energy equals the image's (Parseval, with the unitary normalisation).
    let mut f: Vec<Complex<f64>> = clean
        .data()
        .iter()
        .map(|&v| Complex::new(v as f64, 0.0))
        .collect();
    fft::fft2(&mut f, h, w, Direction::Forward, Norm::Ortho)?;
    let e1: f64 = clean.data().iter().map(|&v| (v as f64).powi(2)).sum();
    let e2: f64 = f.iter().map(|c| c.norm_sqr()).sum();
    println!("Parseval: {e1:.6} = {e2:.6}");

    // Jacobi-preconditioned CG on a 3-D Poisson problem.
    let a = CsrMatrix::laplacian_3d(48, 48, 48)?;
    let b = vec![1.0; a.nrows()];
    let res = pcg(
        &a,
        &b,
        InitialGuess::Zero,
        &Jacobi::new(&a.diagonal())?,
        &PcgParams::default(),
    )?;
    println!(
        "PCG: {} iterations, relative residual {:.2e}, converged {}",
        res.iterations, res.relative_residual, res.converged
    );
    Ok(())
}
