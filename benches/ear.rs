//! Criterion benchmarks of paper 14 (ear occlusion detection and index-based recognition),
//! specification section 5: one probe's pre-processing and occlusion detection, enrolment,
//! and identification against a gallery of 10,000 templates (block-major layout, all
//! threads) under the block-wise maximum and the whole-ear baseline. Peer: the NumPy +
//! OpenCV + PyWavelets pipeline of benches/peers/14.py.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::biometrics::ear::synth::{self, EarSynthParams, OcclusionKind};
use wscg::biometrics::ear::{
    baseline_params, enroll, make_baseline_probe, make_probe, scores, EarParams, EarTemplate,
    Gallery,
};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper14");
    let p = EarParams::default();
    let set = synth::generate(
        50,
        1,
        OcclusionKind::Colour {
            min_pct: 10.0,
            max_pct: 50.0,
        },
        14,
        &EarSynthParams::default(),
        &p,
    )
    .unwrap();
    let probe_img = &set.probes[0].image.rgb;
    g.bench_function("make_probe (resize, equalise, skin, closing, Haar)", |b| {
        b.iter(|| make_probe(black_box(probe_img), &p).unwrap())
    });
    g.bench_function("enroll", |b| {
        b.iter(|| enroll(black_box(&set.enrol[0]), &p).unwrap())
    });
    // 10,000 templates: the 50 enrolled ears, each perturbed per copy.
    let base: Vec<EarTemplate> = set.enrol.iter().map(|im| enroll(im, &p).unwrap()).collect();
    let n = 10_000;
    let mut flat = Vec::with_capacity(n * 2000);
    for k in 0..n {
        let t = base[k % base.len()].features();
        flat.extend(
            t.iter()
                .enumerate()
                .map(|(i, &v)| v + 0.01 * (((i * 31 + k * 17) % 13) as f32 - 6.0) / 6.0),
        );
    }
    let gallery = Gallery::from_features(&flat, n, 80, 25).unwrap();
    let probe = make_probe(probe_img, &p).unwrap();
    g.bench_function("identify vs 10k templates (block-wise max)", |b| {
        b.iter(|| scores(black_box(&probe), &gallery, &p).unwrap())
    });
    let bprobe = make_baseline_probe(probe_img, &p).unwrap();
    let bp = baseline_params(&p);
    g.bench_function("baseline vs 10k templates", |b| {
        b.iter(|| scores(black_box(&bprobe), &gallery, &bp).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
