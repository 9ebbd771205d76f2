//! Criterion benchmarks of paper 04 (joint bilateral mesh denoising): the specification's
//! speed targets on the noisy coloured cube with n = 128 (98k vertices), k = 20, 10
//! iterations, with and without rebuilding the neighbours, on one thread and on all.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::meshfilter::metrics::mean_vertex_distance;
use wscg::meshfilter::synth::{add_noise, colored_cube, NOISE_SEED};
use wscg::meshfilter::{jbmd, JbmdParams};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper04");
    g.sample_size(10);
    let cube = colored_cube(128).unwrap();
    let mvd = mean_vertex_distance(&cube).unwrap();
    let noisy = add_noise(&cube, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let p = JbmdParams::from_mvd(mvd);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    for (name, rebuild) in [("rebuild", true), ("fixed neighbours", false)] {
        let q = p.rebuild_neighbors(rebuild);
        g.bench_function(
            format!("JBMD 98k vertices k 20 10 it, {name}, 1 thread"),
            |b| one.install(|| b.iter(|| black_box(jbmd(&noisy, &q).unwrap()))),
        );
        g.bench_function(
            format!(
                "JBMD 98k vertices k 20 10 it, {name}, {} threads",
                rayon::current_num_threads()
            ),
            |b| b.iter(|| black_box(jbmd(&noisy, &q).unwrap())),
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
