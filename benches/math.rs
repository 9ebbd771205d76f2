//! Criterion benchmarks of the shared math crate. Workload names match
//! `benches/peers/wscg_math.py`, which times the Python binding against numpy, scipy and
//! scikit-image on the same inputs.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use num_complex::Complex;
use wscg::math::fft::{self, Direction, Norm};
use wscg::math::image::Image;
use wscg::math::metrics::{ssim, SsimParams};
use wscg::math::rng;
use wscg::math::sparse::{pcg, CsrMatrix, InitialGuess, Jacobi, PcgParams};

fn bench_fft(c: &mut Criterion) {
    let n = 1024;
    let x: Vec<Complex<f64>> = rng::normal_vec(1, n * n, 0.0, 1.0)
        .unwrap()
        .into_iter()
        .map(|v| Complex::new(v, 0.0))
        .collect();
    c.bench_function("fft2_1024x1024", |b| {
        b.iter(|| {
            let mut y = x.clone();
            fft::fft2(&mut y, n, n, Direction::Forward, Norm::Backward).unwrap();
            black_box(y)
        })
    });
}

fn bench_pcg(c: &mut Criterion) {
    let n = 100;
    let a = CsrMatrix::laplacian_3d(n, n, n).unwrap();
    let b = vec![1.0; n * n * n];
    let jac = Jacobi::new(&a.diagonal()).unwrap();
    let opts = PcgParams::default().tol(1e-6).max_iter(Some(2000));
    let mut g = c.benchmark_group("pcg");
    g.sample_size(10);
    g.bench_function("pcg_poisson3d_100^3_tol1e-6", |bch| {
        bch.iter(|| black_box(pcg(&a, &b, InitialGuess::Zero, &jac, &opts).unwrap()))
    });
    g.finish();
}

fn bench_ssim(c: &mut Criterion) {
    let n = 2048;
    let a = Image::new(
        n,
        n,
        1,
        rng::uniform_vec(2, n * n, 0.0, 1.0)
            .unwrap()
            .into_iter()
            .map(|v| v as f32)
            .collect(),
    )
    .unwrap();
    let noise = rng::normal_vec(3, n * n, 0.0, 0.05).unwrap();
    let b = Image::new(
        n,
        n,
        1,
        a.data()
            .iter()
            .zip(&noise)
            .map(|(&p, &e)| p + e as f32)
            .collect(),
    )
    .unwrap();
    let mut g = c.benchmark_group("ssim");
    g.sample_size(10);
    g.bench_function("ssim_2048x2048", |bch| {
        bch.iter(|| black_box(ssim(&a, &b, &SsimParams::default()).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench_fft, bench_pcg, bench_ssim);
criterion_main!(benches);
