//! Paper 12: shake a generated scene with the Ornstein-Uhlenbeck hand-shake model, render a
//! 5-frame burst densely, and restore the middle frame with every method of Table 1 (per
//! region Wiener, Richardson-Lucy, Krishnan-Fergus; multi-frame with 3 and 5 frames; one
//! global kernel). Prints PSNR / SSIM and the time of each (kernels and rectification included).
//!
//! `cargo run --release --example deblur_burst [width height seed]`

use std::time::Instant;

use wscg::deblur::metrics::quality;
use wscg::deblur::synth::{self, BlurRenderParams, Burst, ShakeParams};
use wscg::deblur::{
    deblur_frame, deblur_multiframe, GyroTrack, HyperLaplacianParams, Intrinsics, Method,
    MultiframeParams,
};
use wscg::math::progress::NoProgress;
use wscg::math::Image;

fn main() -> wscg::math::Result<()> {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let (w, h, seed) = (
        *args.first().unwrap_or(&480),
        *args.get(1).unwrap_or(&320),
        *args.get(2).unwrap_or(&1) as u64,
    );
    let sharp = synth::scene(h, w, seed)?;
    let burst = Burst::default();
    let t = Instant::now();
    let sb = synth::make_burst(
        &sharp,
        &burst,
        &ShakeParams::default(),
        2,
        0.002,
        &BlurRenderParams::default(),
        seed,
    )?;
    println!(
        "rendered 5 frames of {w}x{h} in {:.2} s",
        t.elapsed().as_secs_f64()
    );
    let track = GyroTrack::from_camera_rates(&sb.measured)?;
    let k = Intrinsics::centred(burst.f, w, h);
    let opts = MultiframeParams::default().t_delay(burst.t_delay);
    let report = |name: &str, img: &Image<f32>, secs: f64| -> wscg::math::Result<()> {
        let (p, s) = quality(img, &sb.sharp_display, 16)?;
        println!(
            "{name:<28} PSNR {p:6.2} dB  SSIM {s:.3}  {:8.1} ms",
            secs * 1e3
        );
        Ok(())
    };
    report("B (blurry input)", &sb.frames[2].image, 0.0)?;
    for (name, m) in [
        ("W (Wiener per region)", Method::Wiener { nsr: 0.03 }),
        (
            "RL (20 it per region)",
            Method::RichardsonLucy { iters: 20 },
        ),
        (
            "KS (Krishnan-Fergus)",
            Method::HyperLaplacian(HyperLaplacianParams::paper()),
        ),
        (
            "GU (one global kernel)",
            Method::GlobalUniform(HyperLaplacianParams::paper()),
        ),
    ] {
        let t = Instant::now();
        let (img, _) = deblur_frame(&sb.frames[2], &track, &k, &m, &opts)?;
        report(name, &img, t.elapsed().as_secs_f64())?;
    }
    for radius in [1, 2] {
        let t = Instant::now();
        let out = deblur_multiframe(
            &sb.frames,
            2,
            &track,
            &k,
            &opts.radius(Some(radius)),
            &NoProgress,
        )?;
        let secs = t.elapsed().as_secs_f64();
        report(&format!("KM ({} frames)", 2 * radius + 1), &out.image, secs)?;
        for warning in &out.warnings {
            println!("  warning: {warning}");
        }
    }
    Ok(())
}
