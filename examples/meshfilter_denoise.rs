//! Paper 04 in a few lines: add noise to a coloured cube, denoise it with JBMD, and compare
//! the error with the noisy input and with Laplacian smoothing.
//!
//! `cargo run --release --example meshfilter_denoise -- [out.ply]`

use wscg::meshfilter::metrics::{mean_error, mean_vertex_distance};
use wscg::meshfilter::smoothing::laplacian;
use wscg::meshfilter::synth::{add_noise, colored_cube, NOISE_SEED};
use wscg::meshfilter::{jbmd, JbmdParams};

fn main() -> wscg::math::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "denoised.ply".into());
    let clean = colored_cube(30)?;
    let mvd = mean_vertex_distance(&clean)?;
    let noisy = add_noise(&clean, 0.5 * mvd, false, NOISE_SEED)?;
    let params = JbmdParams::from_mvd(mvd).iterations(15);
    let denoised = jbmd(&noisy, &params)?;
    let smoothed = laplacian(&noisy, 0.5, 4)?;
    let me = |x: &[[f64; 3]]| mean_error(x, &clean.positions).map(|e| e / mvd);
    println!(
        "mean error (MVD): noisy {:.3}, JBMD {:.3}, Laplacian {:.3}",
        me(&noisy.positions)?,
        me(&denoised)?,
        me(&smoothed)?
    );
    let mut result = noisy.clone();
    result.positions = denoised;
    result.write(&out)?;
    println!("written to {out}");
    Ok(())
}
