//! Multiscopic HDR (paper 13) on the layered five-camera scene: one HDR image per view with
//! the paper's method and the baselines, log2-radiance error against the ground truth.
//!
//! Run: `cargo run --release --example hdr_multiscopic`

use std::time::Instant;

use wscg::hdr::metrics::{evaluation_mask, rmse_log2, Region};
use wscg::hdr::synth::{layered_scene, SceneParams};
use wscg::hdr::{multiscopic_hdr, Align, MultiscopicParams, PatchMatchParams, Synthesis};
use wscg::math::progress::NoProgress;

fn main() -> wscg::math::Result<()> {
    let cfg = SceneParams::default();
    let scene = layered_scene(&cfg, 7)?;
    let n = scene.views.len();
    let max_disp = (cfg.layers.iter().map(|l| l.disparity).fold(0.0, f64::max) * (n - 1) as f64)
        .ceil() as i32
        + 2;
    println!(
        "{} views of {} x {}, exposures {:?} s, |disparity| <= {max_disp} px",
        n, cfg.height, cfg.width, cfg.times
    );
    let pm = PatchMatchParams::default().d_min(-max_disp).d_max(max_disp);
    let methods = [
        (
            "ours (epipolar + coherence, BDS)",
            Align::Ours,
            Synthesis::Bds,
            pm,
        ),
        (
            "ours without coherence",
            Align::Ours,
            Synthesis::Bds,
            pm.coherence(false),
        ),
        ("ours, direct warp", Align::Ours, Synthesis::Direct, pm),
        (
            "PatchMatch 2-D (Barnes 2009), BDS",
            Align::PatchMatch2d,
            Synthesis::Bds,
            pm,
        ),
        ("ZNCC stereo + warp", Align::Zncc, Synthesis::Direct, pm),
        ("no alignment", Align::None, Synthesis::Bds, pm),
    ];
    for (name, align, synthesis, pm) in methods {
        let p = MultiscopicParams::default()
            .pm(pm)
            .align(align)
            .synthesis(synthesis)
            .ordered(false);
        let t0 = Instant::now();
        let out = multiscopic_hdr(
            &scene.views,
            &scene.times,
            std::slice::from_ref(&scene.crf),
            &p,
            &NoProgress,
        )?;
        let dt = t0.elapsed().as_secs_f64();
        let errs: Vec<String> = (0..n)
            .map(|k| {
                let err = |region| {
                    let mask = evaluation_mask(&scene, k, region);
                    rmse_log2(&out.hdr[k], &scene.radiance[k], Some(&mask)).unwrap()
                };
                format!("{:.3}/{:.3}", err(Region::SeenByAll), err(Region::Occluded))
            })
            .collect();
        println!(
            "{name:<36} {dt:6.2} s  RMSE log2 per view: {}  fallback {:?}",
            errs.join(" "),
            out.fallback_pixels
        );
    }
    Ok(())
}
