//! Acceptance checks of paper 01 (FDKECA).

use faer::Mat;
use rand::Rng;
use wscg_biometrics::data::{finger_veins, split_per_subject, FingerVeinParams};
use wscg_biometrics::subspace::*;
use wscg_math::rng;

fn random(n: usize, d: usize, seed: u64) -> Mat<f64> {
    let mut r = rng::seeded(seed);
    Mat::from_fn(n, d, |_, _| r.random_range(-1.0..1.0))
}

/// Random data with a decaying, well-separated spectrum (distinct PCA eigenvalues).
fn structured(n: usize, d: usize, seed: u64) -> Mat<f64> {
    let z = random(n, d, seed);
    Mat::from_fn(n, d, |i, j| {
        z[(i, j)] * (1.0 + 3.0 * (-(j as f64) / 6.0).exp()) + 0.1 * j as f64
    })
}

fn kernels() -> Vec<Kernel> {
    vec![
        Kernel::Linear,
        Kernel::Polynomial {
            degree: 2,
            gamma: Gamma::InvDim,
            coef0: 1.0,
        },
        Kernel::Gaussian {
            sigma: Sigma::Median { scale: 1.0 },
        },
        Kernel::Gaussian {
            sigma: Sigma::Fixed(3.0),
        },
    ]
}

#[test]
fn entropy_identity_and_ordering_for_every_kernel() {
    let x = structured(60, 25, 1);
    for kernel in kernels() {
        let m = Fdkeca::fit(x.as_ref(), &FdkecaParams::default().kernel(kernel)).unwrap();
        let total: f64 = m.entropy_terms.iter().sum();
        assert!(
            (total - m.kernel_sum).abs() <= 1e-10 * m.kernel_sum.abs(),
            "{kernel:?}"
        );
        assert!(
            m.entropy_terms.windows(2).all(|w| w[0] >= w[1]),
            "{kernel:?}"
        );
        if let Kernel::Gaussian { .. } = kernel {
            let v = m.renyi_entropy_estimate();
            assert!(v > 0.0 && v <= 1.0, "{v}");
        }
    }
}

#[test]
fn linear_kernel_reduces_to_pca() {
    let (n, d) = (200, 30);
    let x = structured(n, d, 2);
    let p = FdkecaParams::default()
        .kernel(Kernel::Linear)
        .ordering(Ordering::Eigenvalue)
        .center(true)
        .n_components(None);
    let f = Fdkeca::fit(x.as_ref(), &p).unwrap();
    let pca = Pca::fit(x.as_ref(), None, false).unwrap();
    for k in 0..d {
        // FDKECA's linear kernel is Xc'Xc = N * covariance.
        let rel = (f.eigenvalues[k] - n as f64 * pca.variances[k]).abs() / f.eigenvalues[0];
        assert!(rel < 1e-10, "eigenvalue {k}: {rel}");
        let cos: f64 = (0..d).map(|t| f.axes[k][t] * pca.components[k][t]).sum();
        assert!(cos.abs() >= 1.0 - 1e-8, "axis {k}: |cos| = {}", cos.abs());
    }
}

#[test]
fn constant_columns_leave_pca_unchanged() {
    // PCA skips constant columns: with two constant columns inserted, the axes are those of
    // the data without them, zero at the inserted positions, and the projections agree; asking
    // for every axis completes the set with the constant columns' unit axes (variance 0).
    let (n, d) = (150, 12);
    let x = structured(n, d, 4);
    let src = |j: usize| {
        if j < 3 {
            Some(j)
        } else if j == 3 || j == 8 {
            None
        } else if j < 8 {
            Some(j - 1)
        } else {
            Some(j - 2)
        }
    };
    let wide = Mat::from_fn(n, d + 2, |i, j| {
        src(j).map_or(if j == 3 { 0.0 } else { 2.5 }, |s| x[(i, s)])
    });
    let a = Pca::fit(x.as_ref(), Some(6), false).unwrap();
    let b = Pca::fit(wide.as_ref(), Some(6), false).unwrap();
    for k in 0..6 {
        assert!((a.variances[k] - b.variances[k]).abs() <= 1e-12 * a.variances[0]);
        let cos: f64 = (0..d + 2)
            .filter_map(|j| src(j).map(|s| a.components[k][s] * b.components[k][j]))
            .sum();
        assert!(cos.abs() > 1.0 - 1e-10, "axis {k}: |cos| = {}", cos.abs());
        assert_eq!((b.components[k][3], b.components[k][8]), (0.0, 0.0));
    }
    let (pa, pb) = (
        a.transform(x.as_ref()).unwrap(),
        b.transform(wide.as_ref()).unwrap(),
    );
    for k in 0..6 {
        let sign = if (0..n).map(|i| pa[(i, k)] * pb[(i, k)]).sum::<f64>() < 0.0 {
            -1.0
        } else {
            1.0
        };
        for i in 0..n {
            assert!((pa[(i, k)] - sign * pb[(i, k)]).abs() < 1e-9);
        }
    }
    let all = Pca::fit(wide.as_ref(), None, false).unwrap();
    assert_eq!(all.components.len(), d + 2);
    assert_eq!(&all.variances[d..], &[0.0, 0.0]);
    assert_eq!((all.components[d][3], all.components[d + 1][8]), (1.0, 1.0));
}

#[test]
fn full_rotation_keeps_nearest_neighbours() {
    // At l = d the projections are rotations of the centred data: 1-NN predictions must equal
    // raw-pixel 1-NN (no ties with continuous random data).
    let x = structured(120, 20, 3);
    let labels: Vec<u32> = (0..120).map(|i| (i % 7) as u32).collect();
    let (tr, te): (Vec<usize>, Vec<usize>) = (0..120).partition(|i| i % 2 == 0);
    let pick = |idx: &[usize]| select_rows(x.as_ref(), idx);
    let (xtr, xte) = (pick(&tr), pick(&te));
    let ytr: Vec<u32> = tr.iter().map(|&i| labels[i]).collect();
    let raw = nn_classify(xtr.as_ref(), &ytr, xte.as_ref(), Metric::Euclidean).unwrap();
    let f = Fdkeca::fit(xtr.as_ref(), &FdkecaParams::default()).unwrap();
    let pca = Pca::fit(xtr.as_ref(), None, false).unwrap();
    for model in [&f as &dyn Projector, &pca] {
        let ztr = model.transform(xtr.as_ref()).unwrap();
        let zte = model.transform(xte.as_ref()).unwrap();
        let pred = nn_classify(ztr.as_ref(), &ytr, zte.as_ref(), Metric::Euclidean).unwrap();
        assert_eq!(pred, raw);
    }
}

#[test]
fn keca_two_cluster_analytic_case() {
    // 30 copies of a and 20 of b, |a - b| = 50 sigma: K = blockdiag(J30, J20).
    let sigma = 1.0;
    let mut r = rng::seeded(4);
    let x = Mat::from_fn(50, 2, |i, j| {
        let base = if i < 30 { [0.0, 0.0] } else { [30.0, 40.0] };
        base[j] + 1e-9 * r.random_range(-1.0..1.0)
    });
    let k = Kernel::Gaussian {
        sigma: Sigma::Fixed(sigma),
    };
    let keca = Keca::fit(x.as_ref(), &k, Some(2)).unwrap();
    assert!((keca.entropy_terms[0] - 900.0).abs() < 1e-6);
    assert!((keca.entropy_terms[1] - 400.0).abs() < 1e-6);
    assert!((keca.renyi_entropy_estimate() - 0.52).abs() < 1e-9);
    let z = keca.embedding();
    // Cluster a on one axis, cluster b on the other: orthogonal rays.
    let (a, b) = ([z[(0, 0)], z[(0, 1)]], [z[(40, 0)], z[(40, 1)]]);
    let cos = (a[0] * b[0] + a[1] * b[1]) / ((a[0].hypot(a[1])) * (b[0].hypot(b[1])));
    assert!(
        cos.abs() < (0.5f64).to_radians().sin(),
        "angle off 90 degrees: cos {cos}"
    );
    // KPCA's first component separates the clusters with opposite signs.
    let kp = KernelPca::fit(x.as_ref(), &k, Some(1)).unwrap();
    let e = kp.embedding();
    assert!(e[(0, 0)] * e[(40, 0)] < 0.0);
}

#[test]
fn kpca_out_of_sample_matches_training_embedding() {
    let x = structured(80, 12, 5);
    let k = Kernel::Gaussian {
        sigma: Sigma::Median { scale: 1.0 },
    };
    let m = KernelPca::fit(x.as_ref(), &k, Some(10)).unwrap();
    let z = m.transform(x.as_ref()).unwrap();
    let e = m.embedding();
    for i in 0..80 {
        for j in 0..10 {
            assert!((z[(i, j)] - e[(i, j)]).abs() < 1e-9, "{i},{j}");
        }
    }
    // Centred embedding has zero column means.
    for j in 0..10 {
        let s: f64 = (0..80).map(|i| e[(i, j)]).sum();
        assert!(s.abs() < 1e-9);
    }
    let kc = Keca::fit(x.as_ref(), &k, Some(5)).unwrap();
    let zk = kc.transform(x.as_ref()).unwrap();
    let ek = kc.embedding();
    for i in 0..80 {
        for j in 0..5 {
            assert!((zk[(i, j)] - ek[(i, j)]).abs() < 1e-8);
        }
    }
}

#[test]
fn fdkeca_problem_size_is_independent_of_n() {
    let d = 16;
    for n in [20, 400] {
        let m = Fdkeca::fit(random(n, d, n as u64).as_ref(), &FdkecaParams::default()).unwrap();
        assert_eq!(m.axes.len(), d);
        assert!(m.axes.iter().all(|a| a.len() == d));
        assert_eq!(m.n_train, n);
    }
}

#[test]
fn ranks_for_few_samples() {
    // Check 9 on generic data: N = 10 centred images of d = 625 pixels.
    let x = random(10, 625, 9);
    let pca = Pca::fit(x.as_ref(), None, false).unwrap();
    let rank = |v: &[f64]| v.iter().filter(|&&e| e > 1e-10 * v[0]).count();
    assert_eq!(rank(&pca.variances), 9);
    for (coef0, expect) in [(1.0, 55), (0.0, 45)] {
        let p = FdkecaParams::default()
            .kernel(Kernel::Polynomial {
                degree: 2,
                gamma: Gamma::InvDim,
                coef0,
            })
            .ordering(Ordering::Eigenvalue);
        let m = Fdkeca::fit(x.as_ref(), &p).unwrap();
        assert_eq!(rank(&m.eigenvalues), expect, "coef0 = {coef0}");
    }
}

#[test]
fn accuracy_curve_and_cv_selection() {
    // Two well separated clusters per label in 6-D.
    let mut r = rng::seeded(11);
    let n = 90;
    let labels: Vec<u32> = (0..n).map(|i| (i % 3) as u32).collect();
    let x = Mat::from_fn(n, 6, |i, j| {
        let l = labels[i] as f64;
        let centre = if j == 0 { 5.0 * l } else { 0.0 };
        centre + r.random_range(-1.0..1.0)
    });
    let (tr, te): (Vec<usize>, Vec<usize>) = (0..n).partition(|i| i % 3 != 0 || *i < 45);
    let pick = |idx: &[usize]| select_rows(x.as_ref(), idx);
    let ytr: Vec<u32> = tr.iter().map(|&i| labels[i]).collect();
    let yte: Vec<u32> = te.iter().map(|&i| labels[i]).collect();
    let pca = Pca::fit(pick(&tr).as_ref(), None, false).unwrap();
    let ztr = pca.transform(pick(&tr).as_ref()).unwrap();
    let zte = pca.transform(pick(&te).as_ref()).unwrap();
    let curve = accuracy_curve(
        ztr.as_ref(),
        &ytr,
        zte.as_ref(),
        &yte,
        &[1, 2, 6],
        Metric::Euclidean,
    )
    .unwrap();
    assert_eq!(curve.len(), 3);
    assert!(curve[0].1 > 0.95, "{curve:?}");
    // The curve's last point equals plain 1-NN on all components.
    let pred = nn_classify(ztr.as_ref(), &ytr, zte.as_ref(), Metric::Euclidean).unwrap();
    assert_eq!(accuracy(&pred, &yte).unwrap(), curve[2].1);
    assert_eq!(
        best_dimension(&curve).unwrap().1,
        curve.iter().map(|c| c.1).fold(0.0, f64::max)
    );
    let fit = |m: faer::MatRef<'_, f64>| -> wscg_math::Result<Box<dyn Projector>> {
        Ok(Box::new(Pca::fit(m, None, false)?))
    };
    let (l, mean) = select_dimension_cv(
        pick(&tr).as_ref(),
        &ytr,
        &[1, 2, 3, 6],
        5,
        0,
        &fit,
        Metric::Euclidean,
    )
    .unwrap();
    assert!(mean.iter().any(|c| c.0 == l));
    let clf = SubspaceClassifier::new(pca, pick(&tr).as_ref(), &ytr, Metric::Cosine).unwrap();
    assert_eq!(clf.predict(pick(&te).as_ref()).unwrap().len(), te.len());
}

#[test]
fn finger_vein_generator_is_deterministic() {
    let p = FingerVeinParams::default().subjects(4).samples(3).seed(7);
    let a = finger_veins(&p).unwrap();
    let b = finger_veins(&p).unwrap();
    assert_eq!((a.x.nrows(), a.x.ncols()), (12, 200));
    assert_eq!(a.x, b.x);
    assert_eq!(a.labels, vec![0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3]);
    let c = finger_veins(&p.seed(8)).unwrap();
    assert_ne!(a.x, c.x);
    // Samples of one subject are closer to each other than to other subjects on average.
    let dist = |i: usize, j: usize| {
        (0..200)
            .map(|t| (a.x[(i, t)] - a.x[(j, t)]).powi(2))
            .sum::<f64>()
    };
    assert!(dist(0, 1) < dist(0, 3) && dist(3, 4) < dist(3, 7));
    assert!(finger_veins(&p.subjects(0)).is_err());
}

/// Check 8: the paper's Table 1 protocol on 200 x 10 synthetic finger veins, 5/5 split,
/// three seeds, all four methods over l = 1..200, paper and validated protocols.
#[test]
fn recognition_on_synthetic_finger_veins() {
    let methods = Method::table1(Some(200));
    let opt = ProtocolParams::default();
    println!("seed method  max acc %  (l)   validated %  (l)");
    for seed in 0..3 {
        let data = finger_veins(&FingerVeinParams::default().seed(seed)).unwrap();
        let (tr, te) = split_per_subject(&data.labels, 5, seed).unwrap();
        let pick = |idx: &[usize]| select_rows(data.x.as_ref(), idx);
        let (xtr, xte) = (pick(&tr), pick(&te));
        let ytr: Vec<u32> = tr.iter().map(|&i| data.labels[i]).collect();
        let yte: Vec<u32> = te.iter().map(|&i| data.labels[i]).collect();
        let mut best = std::collections::HashMap::new();
        for m in &methods {
            let r = evaluate(m, xtr.as_ref(), &ytr, xte.as_ref(), &yte, &opt).unwrap();
            assert_eq!(r.curve.len(), 200, "{} sweeps l = 1..200", r.method);
            let (vl, va) = r.validated.unwrap();
            println!(
                "{seed:>4} {:<7} {:>8.1} ({:>3}) {:>10.1} ({vl:>3})",
                r.method,
                100.0 * r.best.1,
                r.best.0,
                100.0 * va
            );
            assert!(va <= r.best.1);
            best.insert(r.method, r.best.1);
        }
        assert!(best["PCA"] >= 0.85, "seed {seed}: PCA {:.3}", best["PCA"]);
        assert!(
            best["FDKECA"] >= best["PCA"] - 0.03,
            "seed {seed}: FDKECA {:.3} vs PCA {:.3}",
            best["FDKECA"],
            best["PCA"]
        );
    }
}

#[test]
fn bad_input_is_rejected() {
    let x = random(10, 5, 1);
    let p = FdkecaParams::default();
    assert!(Fdkeca::fit(Mat::<f64>::zeros(0, 5).as_ref(), &p).is_err());
    assert!(Fdkeca::fit(Mat::<f64>::zeros(1, 5).as_ref(), &p).is_err());
    assert!(Fdkeca::fit(Mat::<f64>::zeros(10, 0).as_ref(), &p).is_err());
    let mut nan = x.clone();
    nan[(3, 2)] = f64::NAN;
    assert!(Fdkeca::fit(nan.as_ref(), &p).is_err());
    assert!(Pca::fit(nan.as_ref(), None, false).is_err());
    assert!(KernelPca::fit(nan.as_ref(), &Kernel::Linear, None).is_err());
    assert!(Keca::fit(nan.as_ref(), &Kernel::Linear, None).is_err());
    let m = Fdkeca::fit(x.as_ref(), &p).unwrap();
    assert!(m.transform(random(3, 4, 2).as_ref()).is_err());
    assert!(m.truncated(0).is_err() && m.truncated(6).is_err());
    assert!(Fdkeca::fit(x.as_ref(), &p.n_components(Some(0))).is_err());
    assert!(Fdkeca::fit(x.as_ref(), &p.n_components(Some(6))).is_err());
    let bad_sigma = p.kernel(Kernel::Gaussian {
        sigma: Sigma::Fixed(-1.0),
    });
    assert!(Fdkeca::fit(x.as_ref(), &bad_sigma).is_err());
    let bad_degree = p.kernel(Kernel::Polynomial {
        degree: 0,
        gamma: Gamma::InvDim,
        coef0: 1.0,
    });
    assert!(Fdkeca::fit(x.as_ref(), &bad_degree).is_err());
    let constant = Mat::from_fn(10, 5, |_, _| 2.0);
    let err = Fdkeca::fit(constant.as_ref(), &p).unwrap_err().to_string();
    assert!(err.contains("identical"), "{err}");
    assert!(nn_classify(x.as_ref(), &[0, 1], x.as_ref(), Metric::Euclidean).is_err());
    assert!(KernelPca::fit(x.as_ref(), &Kernel::Linear, Some(50)).is_err());
    let json = m.to_json().unwrap();
    assert_eq!(Fdkeca::from_json(&json).unwrap(), m);
    assert!(Fdkeca::from_json("{").is_err());
}
