//! Criterion benchmarks of paper 17 (Kinect gait recognition with joint relative angles and a
//! DTW kernel), specification section 5: the full Δ matrix of 300 walks over 100 joint pairs
//! (cycle lengths about 28-42 frames, squared cost, as the dtaidistance comparison of
//! benches/peers/17.py), the same matrix with the dependent multivariate DTW (one warp path over
//! the 100 channels, as `dtaidistance.dtw_ndim`), one DTW, the per-walk front end (cycle detection and the 276 JRA
//! sequences) and one identification against a 40-walk gallery.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::biometrics::dtw::{dtw, self_dissimilarity, DtwParams, LocalCost, Multivariate};
use wscg::biometrics::gait::synth::{walkers, SessionRanges};
use wscg::biometrics::gait::{gait_sample, GaitParams, GaitRecognizer};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper17");
    g.sample_size(10);
    let p = GaitParams::default();
    let set = walkers(100, 3, &SessionRanges::default(), 17).unwrap();
    let samples: Vec<_> = set
        .walks
        .iter()
        .map(|w| gait_sample(w, &p).unwrap())
        .collect();
    // 100 pairs: every other one of the first 200 in the 276-pair order.
    let walks: Vec<Vec<Vec<f64>>> = samples
        .iter()
        .map(|s| s.jra.seqs.iter().step_by(2).take(100).cloned().collect())
        .collect();
    let sq = DtwParams::with_cost(LocalCost::Squared);
    g.bench_function(
        "delta matrix 300 walks x 100 pairs, symmetric (squared)",
        |b| b.iter(|| self_dissimilarity(black_box(&walks), &sq).unwrap()),
    );
    let dep = sq.multivariate(Multivariate::Dependent);
    g.bench_function(
        "dependent DTW matrix 300 walks x 100 channels, symmetric (squared)",
        |b| b.iter(|| self_dissimilarity(black_box(&walks), &dep).unwrap()),
    );
    let (a, bb) = (&walks[0][0], &walks[1][0]);
    g.bench_function(format!("dtw {} x {} (abs)", a.len(), bb.len()), |b| {
        b.iter(|| dtw(black_box(a), black_box(bb), &DtwParams::default()).unwrap())
    });
    g.bench_function("cycle detection + 276 JRA sequences (one walk)", |b| {
        b.iter(|| gait_sample(black_box(&set.walks[0]), &p).unwrap())
    });
    let train: Vec<_> = (0..40).map(|i| samples[i].jra.clone()).collect();
    let labels: Vec<u32> = (0..40).map(|i| set.labels[i]).collect();
    let rec = GaitRecognizer::fit_samples(&train, &labels, &p).unwrap();
    g.bench_function(
        format!("identify one walk vs 40 walks ({} pairs)", rec.pairs.len()),
        |b| b.iter(|| rec.predict(black_box(&set.walks[150])).unwrap()),
    );
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
