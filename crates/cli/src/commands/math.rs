//! `wscg math ...`: the shared numerics on the user's image files.

use std::path::PathBuf;

use clap::{Subcommand, ValueEnum};
use num_complex::Complex;
use wscg_math::fft::{self, Direction, Norm};
use wscg_math::filter::{gaussian_filter, Border};
use wscg_math::image::Image;
use wscg_math::metrics::{mse, psnr, ssim, SsimParams};
use wscg_math::resize::{resize, Interpolation};
use wscg_math::Result;

#[derive(Subcommand, Debug)]
pub enum MathCommand {
    /// MSE, RMSE, PSNR and SSIM of TEST against REFERENCE (same size; values in [0, 1] for
    /// 8/16-bit files).
    Metrics {
        reference: PathBuf,
        test: PathBuf,
        /// Dynamic range of the data.
        #[arg(long, default_value_t = 1.0)]
        data_range: f64,
    },
    /// Gaussian blur of every channel.
    Blur {
        input: PathBuf,
        output: PathBuf,
        /// Standard deviation in pixels.
        #[arg(long)]
        sigma: f64,
        /// Border handling.
        #[arg(long, value_enum, default_value_t = Mode::Reflect)]
        mode: Mode,
    },
    /// Resize to HEIGHT x WIDTH.
    Resize {
        input: PathBuf,
        output: PathBuf,
        #[arg(long)]
        height: usize,
        #[arg(long)]
        width: usize,
        #[arg(long, value_enum, default_value_t = Method::Area)]
        method: Method,
    },
    /// Centred log-magnitude spectrum log(1 + |FFT|) of the luminance, scaled to [0, 1].
    Spectrum { input: PathBuf, output: PathBuf },
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Mode {
    Reflect,
    Mirror,
    Nearest,
    Wrap,
    Constant,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Method {
    Area,
    Bilinear,
}

pub fn run(cmd: MathCommand) -> Result<()> {
    match cmd {
        MathCommand::Metrics {
            reference,
            test,
            data_range,
        } => {
            let a = Image::load(&reference)?;
            let b = Image::load(&test)?;
            a.ensure_same_shape(&b)?;
            let m = mse(a.data(), b.data())?;
            let p = psnr(a.data(), b.data(), data_range)?;
            let s = ssim(&a, &b, &SsimParams::default().data_range(data_range))?;
            println!(
                "mse  {m:.6e}\nrmse {:.6e}\npsnr {p:.4} dB\nssim {s:.6}",
                m.sqrt()
            );
            Ok(())
        }
        MathCommand::Blur {
            input,
            output,
            sigma,
            mode,
        } => {
            crate::commands::overwrite::check_file("output", &output, [&input])?;
            let border = match mode {
                Mode::Reflect => Border::Reflect,
                Mode::Mirror => Border::Mirror,
                Mode::Nearest => Border::Nearest,
                Mode::Wrap => Border::Wrap,
                Mode::Constant => Border::Constant(0.0),
            };
            let img = Image::load(&input)?;
            gaussian_filter(&img, sigma, 4.0, border)?.save(&output)
        }
        MathCommand::Resize {
            input,
            output,
            height,
            width,
            method,
        } => {
            crate::commands::overwrite::check_file("output", &output, [&input])?;
            let m = match method {
                Method::Area => Interpolation::Area,
                Method::Bilinear => Interpolation::Bilinear,
            };
            resize(&Image::load(&input)?, height, width, m)?.save(&output)
        }
        MathCommand::Spectrum { input, output } => {
            crate::commands::overwrite::check_file("output", &output, [&input])?;
            let g = Image::load(&input)?.to_gray();
            let (h, w, _) = g.shape();
            let mut c: Vec<Complex<f64>> = g
                .data()
                .iter()
                .map(|&v| Complex::new(v as f64, 0.0))
                .collect();
            fft::fft2(&mut c, h, w, Direction::Forward, Norm::Backward)?;
            let mag: Vec<f32> = fft::fftshift(&c, &[h, w])?
                .iter()
                .map(|v| (1.0 + v.norm()).ln() as f32)
                .collect();
            let mx = mag.iter().cloned().fold(f32::MIN_POSITIVE, f32::max);
            Image::new(h, w, 1, mag.iter().map(|v| v / mx).collect())?.save(&output)
        }
    }
}
