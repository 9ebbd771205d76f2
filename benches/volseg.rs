//! Criterion benchmarks of paper 18 (BoneSplit, random walks on the bone-only graph),
//! specification section 5, on the 256³ fractured-shell phantom with K = 8 (the input of
//! benches/peers/18.py): graph construction, the K-block Jacobi-PCG solve (f32, all labels
//! in one sweep) and the per-label Jacobi-PCG of the paper's CPU path, and a warm-started
//! re-solve after one extra stroke. The scale case (512×512×337, K = 15) is timed by
//! `cargo run --release --example bone_separation`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::volseg::{
    fractured_shell_phantom, BoneGraph, PhantomParams, RandomWalkParams, RandomWalkSession, Solver,
};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper18");
    g.sample_size(10);
    let ph =
        fractured_shell_phantom(&PhantomParams::default().dims([256; 3]).fragments(8)).unwrap();
    // The paper's weights, as in the figures of BENCHMARKS.md.
    let p = RandomWalkParams::paper();
    let graph = BoneGraph::build(&ph.ct, &p).unwrap();
    let n = graph.len();
    g.bench_function(format!("bone graph 256^3 ({n} nodes)"), |b| {
        b.iter(|| BoneGraph::build(black_box(&ph.ct), &p).unwrap())
    });
    for (name, q) in [
        ("K-block Jacobi-PCG f32", p),
        ("per-label Jacobi-PCG f32", p.solver(Solver::PerLabel)),
    ] {
        let mut s = RandomWalkSession::new(graph.clone(), q).unwrap();
        s.set_seeds(&ph.seeds).unwrap();
        g.bench_function(format!("{name}, K = 8, {n} nodes"), |b| {
            b.iter(|| s.solve(false).unwrap())
        });
    }
    // Warm start after one more stroke of label 1 (a few voxels of its truth region).
    let mut s = RandomWalkSession::new(graph.clone(), p).unwrap();
    s.set_seeds(&ph.seeds).unwrap();
    s.solve(false).unwrap();
    let extra: Vec<usize> = ph
        .truth
        .data()
        .iter()
        .enumerate()
        .filter(|&(_, &l)| l == 1)
        .map(|(i, _)| i)
        .step_by(997)
        .take(20)
        .collect();
    s.add_seeds(&extra, 1).unwrap();
    g.bench_function("warm re-solve after one stroke, K = 8", |b| {
        b.iter_batched(
            || s.clone(),
            |mut t| t.solve(true).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
