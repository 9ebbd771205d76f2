//! Criterion benchmarks of paper 03 (hybrid ROI visualisation), the stages of the
//! specification's performance targets on the 256^3 thorax phantom: server encoding, ROI
//! extraction, the client's structure rebuild and a 512 x 512 hybrid frame.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::volren::phantoms::{thorax, thorax_tfs};
use wscg::volren::{Camera, HybridClient, HybridServer, RenderParams, ServerParams};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper03");
    g.sample_size(10);
    let n = 256;
    let v = thorax([n; 3], 1).unwrap();
    let tfs = thorax_tfs();
    g.bench_function("server: wavelets + gradient octree, thorax 256^3", |b| {
        b.iter(|| {
            black_box(HybridServer::new(&v, tfs.clone(), 0, ServerParams::default()).unwrap())
        })
    });
    let s = HybridServer::new(&v, tfs, 0, ServerParams::default()).unwrap();
    // The paper's thorax ROI 256 x 160 x 256 at half the size.
    let (lo, hi) = ([64, 48, 64], [192, 128, 192]);
    g.bench_function("server: ROI package 128 x 80 x 128", |b| {
        b.iter(|| black_box(s.roi_package(lo, hi).unwrap()))
    });
    let stat = s.static_package();
    g.bench_function("client: static package decode and rebuild", |b| {
        b.iter(|| black_box(HybridClient::from_static(&stat).unwrap()))
    });
    let mut client = HybridClient::from_static(&stat).unwrap();
    client.set_roi(&s.roi_package(lo, hi).unwrap()).unwrap();
    let cam = Camera::orbit([n; 3], 30.0, 20.0, 512);
    let opts = RenderParams::default();
    g.bench_function("client: hybrid frame 512 x 512", |b| {
        b.iter(|| black_box(client.render(&cam, 1, &opts).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
