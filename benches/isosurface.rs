//! Criterion benchmarks of paper 09 (sparse-grid isosurfaces): marching cubes of the
//! Marschner-Lobb signal on 256^3 (isovalue 0.5) with and without spline normals (the spec's
//! workload against scikit-image), and the normal estimators alone on the same mesh, the
//! paper's Table 6 comparison (spline against LSN, on the sparsified grid).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::isosurface::fields::{sample, MarschnerLobb};
use wscg::isosurface::{
    estimate_normals, extract, marching_cubes, sparsify_for_isosurface, NormalMethod, ScalarGrid,
};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper09");
    g.sample_size(10);
    let n = 256;
    let ml = sample(&MarschnerLobb::default(), [n; 3], [-1.0; 3], [1.0; 3]).unwrap();
    let grid = ml.grid().unwrap();
    let iso = 0.5;
    g.bench_function("ML 256^3 extraction", |b| {
        b.iter(|| black_box(extract(&grid, iso).unwrap()))
    });
    g.bench_function("ML 256^3 extraction + spline normals", |b| {
        b.iter(|| black_box(marching_cubes(&grid, iso, NormalMethod::spline()).unwrap()))
    });
    g.bench_function("ML 256^3 extraction + central differences", |b| {
        b.iter(|| black_box(marching_cubes(&grid, iso, NormalMethod::CentralDifference).unwrap()))
    });
    let mesh = extract(&grid, iso).unwrap();
    let (sparse, sides) = sparsify_for_isosurface(ml.view(), iso).unwrap();
    let sparse = sparse.into_data();
    let sg = ScalarGrid::with_spacing(ml.dims, ml.spacing, &sparse)
        .unwrap()
        .with_side_hint(&sides)
        .unwrap();
    let nv = mesh.vertices.len();
    for method in [NormalMethod::spline(), NormalMethod::lsn()] {
        g.bench_function(
            format!(
                "ML 256^3 sparse, {} normals of {nv} vertices",
                method.name()
            ),
            |b| {
                b.iter(|| black_box(estimate_normals(&sg, iso, &mesh.vertex_edge, method).unwrap()))
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
