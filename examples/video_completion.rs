//! Paper 06 on synthetic clips with ground truth: completes a panning clip (G2), a static
//! scene with a moving object (G1) and a periodic texture (G4), and prints SSIM and PSNR in the
//! hole for the method, its ablations and the baselines, with timings.
//!
//! Run: `cargo run --release --example video_completion [SCALE]` (SCALE multiplies the frame
//! size; 1 gives 320 x 180).

use std::time::Instant;

use wscg::video::metrics::{flicker, psnr_masked, ssim_masked};
use wscg::video::synth::{pan_clip, periodic_clip, sprite_clip, Clip};
use wscg::video::{
    complete_video, per_frame_patchmatch, wexler_complete, CompletionParams, Video, WexlerParams,
};

fn report(name: &str, clip: &Clip, v: &Video, secs: f64) -> wscg::math::Result<()> {
    println!(
        "  {name:<28} SSIM_hole {:.4}  PSNR_hole {:6.2} dB  flicker {:6.2}  {secs:7.2} s",
        ssim_masked(v, &clip.clean, &clip.hole)?,
        psnr_masked(v, &clip.clean, &clip.hole)?,
        flicker(v, &clip.hole)?,
    );
    Ok(())
}

fn run(name: &str, clip: &Clip, baselines: bool) -> wscg::math::Result<()> {
    println!(
        "{name}: {} frames of {} x {}, {} hole pixels",
        clip.observed.frames,
        clip.observed.width,
        clip.observed.height,
        clip.hole.count()
    );
    let t = Instant::now();
    let out = complete_video(&clip.observed, &clip.hole, &CompletionParams::default())?;
    report(
        "localized search (paper)",
        clip,
        &out.video,
        t.elapsed().as_secs_f64(),
    )?;
    println!(
        "    stats: working {:?}, stage seconds {:?}",
        out.stats.working_size, out.stats.seconds
    );
    let t = Instant::now();
    let cfg = CompletionParams::default().refine(None);
    let out = complete_video(&clip.observed, &clip.hole, &cfg)?;
    report(
        "without refinement",
        clip,
        &out.video,
        t.elapsed().as_secs_f64(),
    )?;
    if baselines {
        let t = Instant::now();
        let w = wexler_complete(&clip.observed, &clip.hole, &WexlerParams::default())?;
        report(
            "Wexler et al. 2007",
            clip,
            &w.video,
            t.elapsed().as_secs_f64(),
        )?;
        let t = Instant::now();
        let p = per_frame_patchmatch(&clip.observed, &clip.hole, &WexlerParams::default())?;
        report("per-frame PatchMatch", clip, &p, t.elapsed().as_secs_f64())?;
    }
    Ok(())
}

fn main() -> wscg::math::Result<()> {
    let scale: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let (h, w) = (180 * scale, 320 * scale);
    run(
        "G2 pan 8 px/frame",
        &pan_clip(20, h, w, 8.0, 30 * scale, 40 * scale, 1)?,
        true,
    )?;
    run(
        "G1 moving disc",
        &sprite_clip(20, h, w, 25.0 * scale as f64, 8.0 * scale as f64, 0.0, 2)?,
        true,
    )?;
    run(
        "G4 periodic",
        &periodic_clip(10, h, w, 24.0, 30 * scale)?,
        true,
    )?;
    Ok(())
}
