//! Criterion benchmarks of paper 01 (FDKECA) and paper 05 (class-wise SFA). Workload names
//! match `benches/peers/01.py` and `benches/peers/05.py`, which time the Python binding
//! against scikit-learn, a numpy/scipy SFA pipeline and MDP on the same kind of input.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use faer::Mat;
use wscg::biometrics::data::{finger_veins, FingerVeinParams};
use wscg::biometrics::sfa::handpose::protocol::rows_to_mat;
use wscg::biometrics::sfa::handpose::{generate, split_protocol, HandposeSynthParams};
use wscg::biometrics::sfa::{ClassSfaParams, PerClassSfa, QuadraticExpansion, TemporalSfa};
use wscg::biometrics::subspace::{FdkecaParams, Kernel, Method, Projector};

fn images(n: usize, side: usize, seed: u64) -> Mat<f64> {
    finger_veins(
        &FingerVeinParams::default()
            .subjects(n / 10)
            .samples(10)
            .size((side, side))
            .canvas((4 * side, 4 * side))
            .seed(seed),
    )
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
    let fd = Method::Fdkeca(FdkecaParams::default().n_components(l));
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

/// A `t x 35` signal: channel `j` is a sine of frequency `j + 1` over the run plus 0.3 times
/// uniform noise from splitmix64 of `35 i + j` (the temporal SFA workload; `benches/peers/05.py`
/// builds the same signal).
fn mixed_sines(t: usize) -> Mat<f64> {
    Mat::from_fn(t, 35, |i, j| {
        let mut z = ((35 * i + j) as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let noise = 2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0;
        let s = i as f64 / t as f64 * std::f64::consts::TAU;
        (s * (j + 1) as f64 + j as f64).sin() + 0.3 * noise
    })
}

fn bench_sfa(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper05");
    g.sample_size(10);
    // The paper's protocol: 3000 frames per class, 300 test frames per class, 1000 rotated
    // copies per class: 18500 training rows of 2200 pixels.
    let data = generate(&HandposeSynthParams::default()).unwrap();
    let split = split_protocol(&data, 300, 1000, 0).unwrap();
    let x = rows_to_mat(&split.train_x, split.dim);
    let cfg = ClassSfaParams::default();
    g.bench_function("PerClassSFA fit 18500x2200", |b| {
        b.iter(|| black_box(PerClassSfa::fit(x.as_ref(), &split.train_y, &cfg).unwrap()))
    });
    let model = PerClassSfa::fit(x.as_ref(), &split.train_y, &cfg).unwrap();
    let q = Mat::from_fn(10_000, split.dim, |i, j| x[(i * 7 % x.nrows(), j)]);
    g.bench_function("PerClassSFA predict 10000x2200", |b| {
        b.iter(|| black_box(model.predict(q.as_ref()).unwrap()))
    });
    let signal = mixed_sines(100_000);
    g.bench_function("TemporalSFA quadratic fit 100000x35", |b| {
        b.iter(|| {
            black_box(
                TemporalSfa::fit(
                    signal.as_ref(),
                    10,
                    Some(QuadraticExpansion::default()),
                    1e-10,
                )
                .unwrap(),
            )
        })
    });
    g.finish();
}

criterion_group!(benches, bench_subspace, bench_sfa);
criterion_main!(benches);
