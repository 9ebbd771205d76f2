//! Criterion benchmarks of paper 06 (localized-search video completion). Workload names match
//! `benches/peers/06.py`, which times the Python binding against per-frame PatchMatch
//! (`pypatchmatch`) and OpenCV inpainting on an HD pan.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::video::synth::pan_clip;
use wscg::video::{
    complete_video, per_frame_patchmatch, wexler_complete, CompletionParams, WexlerParams,
};

fn bench_video(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper06");
    g.sample_size(10);
    // G2: a pan of 8 px/frame under a static logo (1.2 % of the pixels).
    let clip = pan_clip(16, 360, 640, 8.0, 45, 60, 3).unwrap();
    let mut cfg = CompletionParams::default();
    cfg.low.target_width = 320;
    g.bench_function("complete_video pan 640x360x16 (stage 1 at 320x180)", |b| {
        b.iter(|| black_box(complete_video(&clip.observed, &clip.hole, &cfg).unwrap()))
    });
    g.bench_function("wexler_complete pan 640x360x16", |b| {
        b.iter(|| {
            black_box(
                wexler_complete(&clip.observed, &clip.hole, &WexlerParams::default()).unwrap(),
            )
        })
    });
    let pf = WexlerParams::default().seed_per_frame(true);
    g.bench_function("per_frame_patchmatch pan 640x360x16", |b| {
        b.iter(|| black_box(per_frame_patchmatch(&clip.observed, &clip.hole, &pf).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench_video);
criterion_main!(benches);
