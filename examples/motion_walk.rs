//! Paper 16 in a few lines: learn the step-wise action library (anechoic demixing with shared
//! delays) from the synthetic walker, let the predictive planner and the Hopf-oscillator
//! synthesizer walk to a drawer 3.2 m away and reach into it, and write the motion as BVH.
//!
//! `cargo run --release --example motion_walk -- [out.bvh]`

use std::time::Instant;

use wscg::motion::bvh::{motion_from_frames, write_bvh};
use wscg::motion::planner::Action;
use wscg::motion::stepwise::{fit_stepwise, StepwiseParams};
use wscg::motion::synthesizer::{planner_for, MapKind, Synthesizer, SynthesizerParams};
use wscg::motion::walker::{reach_walk, WalkerParams};

fn main() -> wscg::math::Result<()> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "walk.bvh".into());
    let goal = 3.2;
    let fps = 120.0;

    // 40 noisy trials of step, shortened step and reach from the synthetic walker.
    let (data, _) = reach_walk(&WalkerParams::default())?;
    let t0 = Instant::now();
    let lib = fit_stepwise(&data, &StepwiseParams::default())?;
    println!(
        "learned {} sources from {} trials in {:.2} s",
        lib.n_sources(),
        data.trials.len(),
        t0.elapsed().as_secs_f64()
    );
    for (a, name) in ["step", "short step", "reach"].iter().enumerate() {
        let f = &lib.actions[a];
        println!("  Q {name:<10} {:.4} ({} sources)", f.q, f.n_sources);
    }
    println!("  Q all actions {:.4}", lib.q_total);

    // Phase-table state maps (the fast path); the planner's step ranges are the training ones.
    let planner = planner_for(&lib);
    let mut syn = Synthesizer::new(
        lib,
        planner,
        SynthesizerParams::default().map(MapKind::Lut(1024)),
    )?;
    let t0 = Instant::now();
    let s = syn.run(goal, fps, &[], 60.0)?;
    let ms = 1e3 * t0.elapsed().as_secs_f64();
    let actions: Vec<String> = s
        .executed
        .iter()
        .map(|a| match a.action {
            Action::Reach => "reach".to_string(),
            other => format!("{other:?} {:.3} m", a.length),
        })
        .collect();
    let last = s.frames.last().map_or(0.0, |f| f.root_x);
    let seconds = s.frames.last().map_or(0.0, |f| f.time);
    println!(
        "goal {goal} m: {}; {} frames ({seconds:.2} s) synthesized in {ms:.1} ms",
        actions.join(", "),
        s.frames.len()
    );
    println!("final distance to the drawer {:.3} m", goal - last);

    let angles: Vec<Vec<f64>> = s.frames.iter().map(|f| f.angles.clone()).collect();
    let roots: Vec<f64> = s.frames.iter().map(|f| f.root_x).collect();
    write_bvh(&out, &motion_from_frames(angles, &roots, 1.0 / fps))?;
    println!("-> {out}");
    Ok(())
}
