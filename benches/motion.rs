//! Criterion benchmarks of paper 16 (predictive human movement coordination), specification
//! section 5: one anechoic demixing fit on the noise-free action-1 periodic part of 10 trials
//! (J = 3, K = 8, one run of a fixed 100 sweeps, so time / 100 is the cost of one ALS
//! iteration); the full step-wise learning of 40 trials with the default configuration; and
//! 10 s of synthesis at 120 fps (1200 frames of all 51 channels) with phase-table (LUT) and
//! SVR state maps. Peers (scikit-learn's SVR for the same map evaluations, a numpy reference
//! of the same ALS, scikit-learn's PCA) are in benches/peers/16.py.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::motion::anechoic::{fit_anechoic, AnechoicParams};
use wscg::motion::map::SvrMapParams;
use wscg::motion::stepwise::{fit_stepwise, StepwiseParams};
use wscg::motion::synthesizer::{planner_for, MapKind, Synthesizer, SynthesizerParams};
use wscg::motion::walker::{reach_walk, WalkerParams};

/// Sweeps of the timed demixing run (`tol = 0`, so every run does exactly this many).
const SWEEPS: usize = 100;
const FPS: f64 = 120.0;
/// 10 s at 120 fps.
const FRAMES: usize = 1200;
/// A goal far enough that the walk is still going after 10 s.
const GOAL: f64 = 15.0;

/// `reset(GOAL)`, then 1200 steps of 1/120 s with a frame after each, written into one reused
/// frame as a real-time loop would; returns a checksum.
fn synth_10s(syn: &mut Synthesizer) -> f64 {
    syn.reset(GOAL).unwrap();
    let mut acc = 0.0;
    let mut f = syn.frame();
    for _ in 0..FRAMES {
        syn.step(1.0 / FPS).unwrap();
        syn.frame_into(&mut f);
        acc += f.angles[0] + f.root_x;
    }
    assert!(!syn.finished(), "the goal was reached within 10 s");
    acc
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper16");
    g.sample_size(10);

    let (_, truth) = reach_walk(&WalkerParams::default().n_trials(10).noise(0.0)).unwrap();
    let x = &truth.periodic[0];
    let cfg = AnechoicParams::default()
        .n_sources(3)
        .n_harmonics(8)
        .restarts(1)
        .max_iter(SWEEPS)
        .tol(0.0)
        // The ALS alone (the numpy reference of benches/peers/16.py has no delay search).
        .delay_search(0);
    g.bench_function(
        format!("fit_anechoic R=10 I=51 N=100 J=3 K=8, 1 run x {SWEEPS} sweeps"),
        |b| {
            b.iter(|| {
                let m = fit_anechoic(black_box(x), &cfg).unwrap();
                assert_eq!(m.q_history.len(), SWEEPS + 1);
                m
            })
        },
    );

    // The default fit: 10 runs (PCA start, the orbit-subspace start, 8 random ones), then
    // the per-channel delay search.
    let default = AnechoicParams::default().n_sources(3);
    g.bench_function(
        "fit_anechoic R=10 I=51 N=100 J=3, default config (10 restarts)",
        |b| b.iter(|| fit_anechoic(black_box(x), &default).unwrap()),
    );

    let (data, _) = reach_walk(&WalkerParams::default()).unwrap();
    g.bench_function("fit_stepwise 40 trials, default config", |b| {
        b.iter(|| fit_stepwise(black_box(&data), &StepwiseParams::default()).unwrap())
    });

    let lib = fit_stepwise(&data, &StepwiseParams::default()).unwrap();
    for (name, map) in [
        ("LUT 1024", MapKind::Lut(1024)),
        ("SVR", MapKind::Svr(SvrMapParams::default())),
    ] {
        let mut syn = Synthesizer::new(
            lib.clone(),
            planner_for(&lib),
            SynthesizerParams::default().map(map),
        )
        .unwrap();
        g.bench_function(format!("synthesis 10 s at 120 fps, {name} maps"), |b| {
            b.iter(|| synth_10s(black_box(&mut syn)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
