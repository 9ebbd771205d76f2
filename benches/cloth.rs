//! Criterion benchmarks of paper 02 (cloth with soft constraints): one time step of the
//! scenes of the specification's performance targets, sequential and graph-coloured
//! Gauss-Seidel on one and on all threads.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::cloth::{
    grid_triangles, ClothModel, Method, NcgVariant, Relaxation, Simulation, SolverParams,
};

fn sim(model: &ClothModel, method: Method, relaxation: Relaxation) -> Simulation {
    let mut s = Simulation::new(
        model.clone(),
        SolverParams::default()
            .method(method)
            .relaxation(relaxation),
    )
    .unwrap();
    // Start from a moving, deformed state.
    s.run(1.0 / 60.0, 30).unwrap();
    s
}

/// A dress-size membrane: an `n x n` grid (1 m) of StVK triangles with bending links, the two
/// corners of the first row pinned.
fn fem_with_bending(n: usize) -> ClothModel {
    let mut m = ClothModel::fem_grid(n, n, (1.0, 1.0), 0.1, 1000.0, 0.3).unwrap();
    m.add_bending_links(&grid_triangles(n, n), 50.0).unwrap();
    m
}

fn bench_steps(c: &mut Criterion) {
    let h = 1.0 / 60.0;
    let mut g = c.benchmark_group("paper02");
    g.sample_size(20);
    let links =
        ClothModel::grid(40, 40, (1.0, 1.0), 0.1, 2000.0, Some(2000.0), Some(2000.0)).unwrap();
    let fem = fem_with_bending(83);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let gs = Relaxation::GaussSeidel;
    let colored = Relaxation::ColoredGaussSeidel;
    let soft = Method::SoftProjection;
    for (name, model, method, relaxation) in [
        ("soft step 40x40 links 25 it", &links, soft, gs),
        ("soft step 40x40 links 25 it colored", &links, soft, colored),
        (
            "NCG step 40x40 links 25 it",
            &links,
            Method::Ncg {
                variant: NcgVariant::Consistent,
            },
            gs,
        ),
        (
            "PBD step 40x40 links 25 it",
            &links,
            Method::PlainPbd { stiffness: 1.0 },
            gs,
        ),
        ("soft step 83x83 FEM+bending 25 it", &fem, soft, gs),
        (
            "soft step 83x83 FEM+bending 25 it colored",
            &fem,
            soft,
            colored,
        ),
    ] {
        let mut s = sim(model, method, relaxation);
        g.bench_function(format!("{name} 1 thread"), |b| {
            one.install(|| b.iter(|| black_box(s.step(h).unwrap())))
        });
        if relaxation == colored {
            g.bench_function(
                format!("{name} {} threads", rayon::current_num_threads()),
                |b| b.iter(|| black_box(s.step(h).unwrap())),
            );
        }
    }
    g.finish();
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);
