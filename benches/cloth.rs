//! Criterion benchmarks of paper 02 (cloth with soft constraints): one time step of the
//! scenes of the specification's performance targets.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::cloth::{ClothModel, Method, NcgVariant, Sim, SolverConfig};

fn sim(model: &ClothModel, method: Method) -> Sim {
    let mut s = Sim::new(
        model.clone(),
        SolverConfig {
            method,
            ..Default::default()
        },
    )
    .unwrap();
    // Start from a moving, deformed state.
    s.run(1.0 / 60.0, 30).unwrap();
    s
}

fn bench_steps(c: &mut Criterion) {
    let h = 1.0 / 60.0;
    let mut g = c.benchmark_group("paper02");
    g.sample_size(20);
    let links =
        ClothModel::grid(40, 40, (1.0, 1.0), 0.1, 2000.0, Some(2000.0), Some(2000.0)).unwrap();
    let fem = ClothModel::fem_grid(83, 83, (1.0, 1.0), 0.1, 1000.0, 0.3).unwrap();
    for (name, model, method) in [
        (
            "soft step 40x40 links 25 it",
            &links,
            Method::SoftProjection,
        ),
        (
            "NCG step 40x40 links 25 it",
            &links,
            Method::Ncg {
                variant: NcgVariant::Consistent,
            },
        ),
        (
            "PBD step 40x40 links 25 it",
            &links,
            Method::PlainPbd { stiffness: 1.0 },
        ),
        (
            "soft step 83x83 FEM (dress size) 25 it",
            &fem,
            Method::SoftProjection,
        ),
    ] {
        let mut s = sim(model, method);
        g.bench_function(name, |b| b.iter(|| black_box(s.step(h).unwrap())));
    }
    g.finish();
}

criterion_group!(benches, bench_steps);
criterion_main!(benches);
