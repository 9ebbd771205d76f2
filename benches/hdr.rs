//! Criterion benchmarks of paper 13 (multiscopic HDR), specification section 5, on a
//! generated three-camera scene at the paper's Aloe resolution 1282 x 1110: one field with
//! the paper's matcher (2 and 3 iterations, on one thread as the specification's target
//! asks and on every core) and with original 2-D PatchMatch, BDS voting of one source, the
//! merge of 5 aligned exposures (peer: OpenCV `MergeDebevec`, benches/peers/13.py) and the
//! end-to-end multiscopic run of 3 views (paper: 103 s).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::hdr::synth::{encode, layered_scene, SceneParams};
use wscg::hdr::{
    merge_stack, multiscopic_hdr, patchmatch, to_radiance, to_samples, vote_bds, MultiscopicParams,
    PatchMatchParams,
};
use wscg::math::progress::NoProgress;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper13");
    g.sample_size(10);
    let cfg = SceneParams::default()
        .height(1110)
        .width(1282)
        .times(vec![0.005, 0.04, 0.3]);
    let sc = layered_scene(&cfg, 1).unwrap();
    let a = to_radiance(&sc.views[0], &sc.crf, sc.times[0]).unwrap();
    let b = to_radiance(&sc.views[1], &sc.crf, sc.times[1]).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let max_d = 70;
    for iters in [2, 3] {
        let p = PatchMatchParams::default()
            .iters(iters)
            .d_min(-max_d)
            .d_max(max_d);
        g.bench_function(
            format!("patchmatch 1282x1110, {iters} it, 1 thread"),
            |bch| bch.iter(|| one.install(|| black_box(patchmatch(&a, &b, &p).unwrap()))),
        );
        // The rows of a sweep as a pipeline on every core (the same field).
        g.bench_function(
            format!("patchmatch 1282x1110, {iters} it, all threads"),
            |bch| bch.iter(|| black_box(patchmatch(&a, &b, &p).unwrap())),
        );
    }
    g.bench_function("patchmatch_2d 1282x1110, 2 it, 1 thread", |bch| {
        bch.iter(|| {
            one.install(|| {
                black_box(patchmatch(&a, &b, &PatchMatchParams::barnes(7, 2, 0)).unwrap())
            })
        })
    });
    let p = PatchMatchParams::default().d_min(-max_d).d_max(max_d);
    let rs = patchmatch(&a, &b, &p).unwrap();
    let sr = patchmatch(&b, &a, &p).unwrap();
    let src = to_samples(&sc.views[1], &sc.crf, sc.times[1])
        .unwrap()
        .stacked();
    g.bench_function("vote_bds 1282x1110, radiance + weight + level", |bch| {
        bch.iter(|| black_box(vote_bds(&src, &rs, &sr, 7).unwrap()))
    });
    let times = [0.005, 0.03, 0.061, 0.122, 0.28];
    let stack: Vec<_> = times
        .iter()
        .enumerate()
        .map(|(k, &t)| encode(&sc.radiance[1], t, cfg.response, 0.002, 8, k as u64).unwrap())
        .collect();
    let crfs = [sc.crf.clone()];
    g.bench_function("merge_stack 5 x 1282x1110x3", |bch| {
        bch.iter(|| black_box(merge_stack(&stack, &times, &crfs).unwrap()))
    });
    let mp = MultiscopicParams::default().pm(p);
    g.bench_function("multiscopic_hdr 3 views 1282x1110, 2 it", |bch| {
        bch.iter(|| {
            black_box(multiscopic_hdr(&sc.views, &sc.times, &crfs, &mp, &NoProgress).unwrap())
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
