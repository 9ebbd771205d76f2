//! Criterion benchmarks of paper 11 (CS-MRI with a UDCT prior), specification section 5:
//! the UDCT forward + backward at 256^2 and 512^2 (peer: the `curvelets` package), the
//! wrapping FDCT likewise (peer: `curvepy-fdct`), the SFLCT forward + adjoint (no peer
//! package exists), and 70 C-SALSA iterations at 256^2, 40% Cartesian, with the UDCT, FDCT,
//! MRSFLCT and db4 priors (peers: BART `pics -l1`, sigpy `L1WaveletRecon`), plus the FCSA
//! baseline.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use wscg::csmri::baselines::{self, CompositeParams};
use wscg::csmri::{
    csalsa, masks, phantom, sparsifier, CsalsaParams, Fdct, FdctParams, FdctSparsifier, KSpace,
    Redundancy, Regularizer, Sflct, SflctParams, Udct, UdctParams, UdctSparsifier,
    WaveletSparsifier,
};
use wscg::math::progress::NoProgress;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper11");
    g.sample_size(10);
    for n in [256usize, 512] {
        let u = Udct::new(n, n, &UdctParams::default()).unwrap();
        let x = phantom::shepp_logan_image(n).unwrap();
        g.bench_function(format!("udct [[6,6]] forward+backward {n}^2"), |b| {
            b.iter(|| black_box(u.backward(&u.forward(&x).unwrap()).unwrap()))
        });
        let f = Fdct::new(n, n, &FdctParams::default()).unwrap();
        g.bench_function(format!("fdct forward+backward {n}^2"), |b| {
            b.iter(|| black_box(f.backward(&f.forward_real(&x).unwrap()).unwrap()))
        });
        let xc: Vec<_> = x
            .iter()
            .map(|&v| num_complex::Complex64::new(v, 0.0))
            .collect();
        for red in [Redundancy::Less, Redundancy::More] {
            let cfg = SflctParams::default().redundancy(red);
            let t = Sflct::new(n, n, &cfg).unwrap();
            g.bench_function(format!("sflct {red:?} forward+adjoint {n}^2"), |b| {
                b.iter(|| black_box(t.adjoint(&t.forward(&xc).unwrap()).unwrap()))
            });
        }
    }
    let n = 256;
    let mask = masks::cartesian(n, n, 0.4, 0.08, 1).unwrap();
    let data = KSpace::new(n, n, phantom::shepp_logan_kspace(n).unwrap(), mask).unwrap();
    let udct = UdctSparsifier::new(n, n, &UdctParams::default()).unwrap();
    let db4 = WaveletSparsifier::new(n, n, 4, 4).unwrap();
    let p = CsalsaParams::default();
    g.bench_function("csalsa udct-l1 70 it 256^2", |b| {
        b.iter(|| {
            black_box(csalsa(&data, &udct, Regularizer::default(), &p, None, &NoProgress).unwrap())
        })
    });
    let pw = CsalsaParams::default().tau0(0.04);
    g.bench_function("csalsa db4-l1 70 it 256^2", |b| {
        b.iter(|| {
            black_box(csalsa(&data, &db4, Regularizer::default(), &pw, None, &NoProgress).unwrap())
        })
    });
    let fdct = FdctSparsifier::new(n, n, &FdctParams::default()).unwrap();
    let pf = CsalsaParams::default().tau0(sparsifier::tuned_tau0("fdct"));
    g.bench_function("csalsa fdct-l1 70 it 256^2", |b| {
        b.iter(|| {
            black_box(csalsa(&data, &fdct, Regularizer::default(), &pf, None, &NoProgress).unwrap())
        })
    });
    let mr = sparsifier::by_name("mrsflct", n, n, &sparsifier::PriorParams::default()).unwrap();
    let pm = CsalsaParams::default().tau0(sparsifier::tuned_tau0("mrsflct"));
    g.bench_function("csalsa mrsflct-l1 70 it 256^2", |b| {
        b.iter(|| {
            black_box(
                csalsa(
                    &data,
                    mr.as_ref(),
                    Regularizer::default(),
                    &pm,
                    None,
                    &NoProgress,
                )
                .unwrap(),
            )
        })
    });
    let cp = CompositeParams::default();
    g.bench_function("fcsa 70 it 256^2", |b| {
        b.iter(|| black_box(baselines::fcsa(&data, &cp, None, &NoProgress).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
