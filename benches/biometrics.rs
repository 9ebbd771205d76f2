//! Criterion benchmarks of paper 01 (FDKECA). Workload names match `benches/peers/01.py`,
//! which times the Python binding against scikit-learn on the same kind of input.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use faer::Mat;
use wscg::biometrics::data::{finger_veins, FingerVeinParams};
use wscg::biometrics::subspace::{FdkecaParams, Kernel, Method, Projector};

fn images(n: usize, side: usize, seed: u64) -> Mat<f64> {
    finger_veins(&FingerVeinParams {
        subjects: n / 10,
        samples: 10,
        size: (side, side),
        canvas: (4 * side, 4 * side),
        seed,
        ..Default::default()
    })
    .unwrap()
    .x
}

fn fit_transform(method: &Method, xtr: &Mat<f64>, xte: &Mat<f64>) -> Mat<f64> {
    method
        .fit(xtr.as_ref())
        .unwrap()
        .transform(xte.as_ref())
        .unwrap()
}

fn bench_subspace(c: &mut Criterion) {
    let l = Some(100);
    let fd = Method::Fdkeca(FdkecaParams {
        n_components: l,
        ..Default::default()
    });
    let pca = Method::Pca {
        n_components: l,
        whiten: false,
    };
    let kpca = Method::KernelPca {
        kernel: Kernel::default(),
        n_components: l,
    };
    let keca = Method::Keca {
        kernel: Kernel::default(),
        n_components: l,
    };
    let mut g = c.benchmark_group("paper01");
    g.sample_size(10);
    let (xtr, xte) = (images(4000, 16, 0), images(1000, 16, 1));
    g.bench_function("FDKECA N=4000 d=256 l=100", |b| {
        b.iter(|| black_box(fit_transform(&fd, &xtr, &xte)))
    });
    g.bench_function("PCA N=4000 d=256 l=100", |b| {
        b.iter(|| black_box(fit_transform(&pca, &xtr, &xte)))
    });
    g.bench_function("KernelPCA N=4000 d=256 l=100", |b| {
        b.iter(|| black_box(fit_transform(&kpca, &xtr, &xte)))
    });
    // The N-independence claim: FDKECA against KECA at N = 1000 and 4000 (d = 256).
    for n in [1000, 4000] {
        let x = images(n, 16, 2);
        g.bench_function(format!("FDKECA fit N={n} d=256"), |b| {
            b.iter(|| black_box(fd.fit(x.as_ref()).unwrap()))
        });
        g.bench_function(format!("KECA fit N={n} d=256"), |b| {
            b.iter(|| black_box(keca.fit(x.as_ref()).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_subspace);
criterion_main!(benches);
