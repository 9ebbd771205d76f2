//! The dense routines give the same bits in a thread pool of any size (faer's parallelism is
//! fixed for the process: `wscg_math::faer_par`).

use faer::Mat;
use wscg_math::dense;

fn same_bits(a: &Mat<f64>, b: &Mat<f64>) -> bool {
    a.nrows() == b.nrows()
        && a.ncols() == b.ncols()
        && (0..a.ncols())
            .all(|j| (0..a.nrows()).all(|i| a[(i, j)].to_bits() == b[(i, j)].to_bits()))
}

#[test]
fn dense_routines_are_bit_identical_in_one_and_two_thread_pools() {
    // A sample covariance of the size of a PCA of 5 x 5 x 5 colour patches (375 values): the
    // Krylov path of the largest eigenpairs and the tridiagonal fallback both run faer
    // products that rayon(0) split by the pool's thread count.
    let x = Mat::<f64>::from_fn(3000, 375, |i, j| {
        ((i * 31 + j * 17) % 97) as f64 * 0.37 - (i % 13) as f64 + ((i * j) % 7) as f64 * 0.01
    });
    let run = || {
        let g = dense::gram(x.as_ref(), 1.0 / 3000.0);
        let top = dense::eigh_largest(g.as_ref(), 24).unwrap();
        let low = dense::eigh_smallest(g.as_ref(), 24).unwrap();
        let svd = dense::svd(x.as_ref().subrows(0, 400)).unwrap();
        (g, top, low, svd)
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let a = one.install(run);
    let b = two.install(run);
    assert!(same_bits(&a.0, &b.0), "gram");
    for (name, (ea, eb)) in [("largest", (&a.1, &b.1)), ("smallest", (&a.2, &b.2))] {
        assert!(
            ea.values
                .iter()
                .zip(&eb.values)
                .all(|(p, q)| p.to_bits() == q.to_bits()),
            "{name} eigenvalues"
        );
        assert!(same_bits(&ea.vectors, &eb.vectors), "{name} eigenvectors");
    }
    assert!(
        same_bits(&a.3.u, &b.3.u) && same_bits(&a.3.v, &b.3.v),
        "svd"
    );
}
