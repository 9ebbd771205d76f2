//! Acceptance checks of paper 05 (class-wise slow feature analysis) that need no data set:
//! the generalized eigensolver (check 1), the closed forms of the paper's pairwise
//! objectives (check 2), and bad input.

use faer::Mat;
use rand::Rng;
use wscg_biometrics::sfa::scatter::{ClassMoments, Whitening};
use wscg_biometrics::sfa::{ClassSfaParams, GlobalRule, GlobalSfa, PerClassSfa};
use wscg_math::{dense, rng};

fn random(m: usize, n: usize, seed: u64) -> Mat<f64> {
    let mut r = rng::seeded(seed);
    Mat::from_fn(m, n, |_, _| r.random_range(-1.0..1.0))
}

/// A symmetric positive definite matrix with eigenvalues spread over `cond`.
fn spd(n: usize, cond: f64, seed: u64) -> Mat<f64> {
    let q = dense::eigh((random(n, n, seed) + random(n, n, seed).transpose()).as_ref())
        .unwrap()
        .vectors;
    let ev: Vec<f64> = (0..n)
        .map(|i| cond.powf(i as f64 / (n - 1) as f64))
        .collect();
    Mat::from_fn(n, n, |i, j| {
        (0..n).map(|k| q[(i, k)] * ev[k] * q[(j, k)]).sum()
    })
}

#[test]
fn generalized_eigensolver() {
    // Check 1: A w = lambda B w through the rank-cut whitening against the Cholesky route.
    let n = 50;
    let b = spd(n, 1e6, 0);
    let g = random(n, n, 1);
    let a = Mat::from_fn(n, n, |i, j| g[(i, j)] + g[(j, i)]);
    let white = Whitening::new(b.as_ref(), 1e-12).unwrap();
    assert_eq!(white.rank, n);
    let (vals, w) = white
        .smallest(white.project(a.as_ref()).as_ref(), n)
        .unwrap();
    let reference = dense::eigh_generalized(a.as_ref(), b.as_ref()).unwrap();
    let scale = reference.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (x, y) in vals.iter().zip(&reference.values) {
        assert!((x - y).abs() <= 1e-9 * scale, "{x} vs {y}");
    }
    let wbw = w.transpose() * &b * &w;
    for i in 0..n {
        for j in 0..n {
            let want = if i == j { 1.0 } else { 0.0 };
            assert!(
                (wbw[(i, j)] - want).abs() < 1e-10,
                "W'BW[{i},{j}] = {}",
                wbw[(i, j)]
            );
        }
    }
    // Rank-deficient B: ten duplicated columns of the data.
    let x0 = random(400, 30, 2);
    let x = Mat::from_fn(400, 40, |i, j| x0[(i, if j < 30 { j } else { j - 30 })]);
    let mom = ClassMoments::accumulate(x.as_ref(), &vec![0; 400], None);
    let white = Whitening::new(mom.total_covariance().as_ref(), 1e-10).unwrap();
    assert_eq!(white.rank, 30);
    let (vals, w) = white
        .smallest(white.project(mom.total_covariance().as_ref()).as_ref(), 5)
        .unwrap();
    assert!(vals.iter().all(|v| (v - 1.0).abs() < 1e-9));
    assert!((0..w.nrows()).all(|i| (0..5).all(|j| w[(i, j)].is_finite())));
}

#[test]
fn closed_forms_equal_the_pairwise_definitions() {
    // Check 2: N = 300, D = 20, 3 classes; eqs. 12-13 by pair loops (square root dropped,
    // mean-normalised) against 2 w'S_C w and w'(S_C + S_not + d d')w.
    let (n, d) = (300, 20);
    let x0 = random(n, d, 3);
    let y: Vec<u32> = (0..n).map(|i| [4u32, 7, 9][i % 3]).collect();
    // Class-dependent shifts so the classes differ.
    let x = Mat::from_fn(n, d, |i, j| {
        x0[(i, j)] + (y[i] as f64) * 0.1 * (j as f64 % 3.0)
    });
    let mom = ClassMoments::accumulate(x.as_ref(), &y, None);
    assert_eq!(mom.classes, vec![4, 7, 9]);
    let mut r = rng::seeded(5);
    for c in 0..3 {
        let t = mom.class_terms(c);
        let inc: Vec<usize> = (0..n).filter(|&i| y[i] == mom.classes[c]).collect();
        let out: Vec<usize> = (0..n).filter(|&i| y[i] != mom.classes[c]).collect();
        for _ in 0..100 {
            let w: Vec<f64> = (0..d).map(|_| r.random_range(-1.0..1.0)).collect();
            let p: Vec<f64> = (0..n)
                .map(|i| (0..d).map(|j| w[j] * x[(i, j)]).sum())
                .collect();
            let pair = |a: &[usize], b: &[usize]| {
                let s: f64 = a
                    .iter()
                    .flat_map(|&i| b.iter().map(move |&j| (i, j)))
                    .map(|(i, j)| (p[i] - p[j]).powi(2))
                    .sum();
                s / (a.len() * b.len()) as f64
            };
            let quad = |m: &Mat<f64>| -> f64 {
                (0..d)
                    .map(|i| (0..d).map(|j| w[i] * m[(i, j)] * w[j]).sum::<f64>())
                    .sum()
            };
            let within = pair(&inc, &inc);
            let across = pair(&inc, &out);
            let wd: f64 = (0..d).map(|i| w[i] * t.d[i]).sum();
            let closed_within = 2.0 * quad(&t.s_c);
            let closed_across = quad(&t.s_c) + quad(&t.s_not) + wd * wd;
            assert!((within - closed_within).abs() <= 1e-10 * within.abs().max(1e-300));
            assert!((across - closed_across).abs() <= 1e-10 * across.abs().max(1e-300));
        }
        // In sphered coordinates: A_C = (S_C - I)/pi_not - pi_not d d' for gamma = 1.
        let white = Whitening::new(mom.total_covariance().as_ref(), 1e-12).unwrap();
        let sc = white.project(t.s_c.as_ref());
        let sn = white.project(t.s_not.as_ref());
        let dw: Vec<f64> = (0..d)
            .map(|k| (0..d).map(|i| white.s[(i, k)] * t.d[i]).sum())
            .collect();
        let pn = 1.0 - t.pi_c;
        for i in 0..d {
            for j in 0..d {
                let a = sc[(i, j)] - sn[(i, j)] - dw[i] * dw[j];
                let id = if i == j { 1.0 } else { 0.0 };
                let b = (sc[(i, j)] - id) / pn - pn * dw[i] * dw[j];
                assert!((a - b).abs() < 1e-10, "{a} vs {b}");
            }
        }
    }
}

#[test]
fn bad_input_is_rejected() {
    let x = random(60, 8, 7);
    let y: Vec<u32> = (0..60).map(|i| (i % 3) as u32).collect();
    let cfg = ClassSfaParams::default().pca_dims(5).m_per_class(3);
    assert!(PerClassSfa::fit(x.as_ref(), &y, &cfg).is_ok());
    let empty = Mat::<f64>::zeros(0, 8);
    assert!(PerClassSfa::fit(empty.as_ref(), &[], &cfg).is_err());
    let mut nan = x.clone();
    nan[(3, 2)] = f64::NAN;
    assert!(PerClassSfa::fit(nan.as_ref(), &y, &cfg).is_err());
    assert!(PerClassSfa::fit(x.as_ref(), &y[..59], &cfg).is_err());
    assert!(PerClassSfa::fit(x.as_ref(), &[1; 60], &cfg).is_err());
    let mut few = y.clone();
    few[0] = 9; // a class with one row
    assert!(PerClassSfa::fit(x.as_ref(), &few, &cfg).is_err());
    assert!(PerClassSfa::fit(x.as_ref(), &y, &cfg.m_per_class(100)).is_err());
    assert!(PerClassSfa::fit(x.as_ref(), &y, &cfg.pca_dims(9)).is_err());
    let constant = Mat::from_fn(60, 8, |_, _| 1.0);
    assert!(PerClassSfa::fit(constant.as_ref(), &y, &cfg).is_err());
    let model = PerClassSfa::fit(x.as_ref(), &y, &cfg).unwrap();
    assert!(model.predict(random(4, 7, 1).as_ref()).is_err());
    assert!(model.responses(x.as_ref(), 5).is_err());
    // Non-contiguous labels come back as given; JSON round trip predicts identically.
    let y2: Vec<u32> = y.iter().map(|&l| [3, 7, 9][l as usize]).collect();
    let m2 = PerClassSfa::fit(x.as_ref(), &y2, &cfg).unwrap();
    let p = m2.predict(x.as_ref()).unwrap();
    assert!(p.iter().all(|l| [3, 7, 9].contains(l)));
    let back = PerClassSfa::from_json(&m2.to_json().unwrap()).unwrap();
    assert_eq!(back.predict(x.as_ref()).unwrap(), p);
    assert!(GlobalSfa::fit(x.as_ref(), &y, &cfg, GlobalRule::Gaussian).is_ok());
}
