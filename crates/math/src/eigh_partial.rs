//! Selected eigenpairs of a symmetric matrix, the way LAPACK's `dsyevx` computes them:
//! Householder tridiagonalisation `A = Q T Q'` (faer), Sturm-sequence bisection for the
//! wanted eigenvalues of `T`, inverse iteration for their eigenvectors (re-orthogonalised
//! inside clusters of close eigenvalues, as `dstein`), and the back-transformation `Q s`.
//!
//! For `k` of `n` eigenpairs this costs `4/3 n^3` (the reduction) plus `O(n^2 k)`, against
//! roughly `4 n^3` more for all eigenvectors; kernel PCA with a few components of a large
//! kernel matrix is the typical use.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::evd::tridiag;
use faer::linalg::householder;
use faer::{Conj, Mat, MatRef};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::sym_eigen::SymEigen;

/// The symmetric tridiagonal matrix: diagonal `d` (length `n`) and off-diagonal `e`
/// (length `n - 1`).
struct Tridiagonal {
    d: Vec<f64>,
    e: Vec<f64>,
}

impl Tridiagonal {
    /// Number of eigenvalues smaller than `x` (Sturm count of the `LDL'` pivots).
    fn count_below(&self, x: f64, tiny: f64) -> usize {
        // A pivot smaller than `tiny` is replaced by `-tiny` before it is counted (dstebz).
        let guard = |q: f64| if q.abs() < tiny { -tiny } else { q };
        let mut q = guard(self.d[0] - x);
        let mut count = usize::from(q < 0.0);
        for i in 1..self.d.len() {
            q = guard(self.d[i] - x - self.e[i - 1] * self.e[i - 1] / q);
            count += usize::from(q < 0.0);
        }
        count
    }

    /// Gershgorin interval holding every eigenvalue.
    fn bounds(&self) -> (f64, f64) {
        let n = self.d.len();
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for i in 0..n {
            let r = if i > 0 { self.e[i - 1].abs() } else { 0.0 }
                + if i + 1 < n { self.e[i].abs() } else { 0.0 };
            lo = lo.min(self.d[i] - r);
            hi = hi.max(self.d[i] + r);
        }
        (lo, hi)
    }

    /// The `j`-th smallest eigenvalue (0-based) by bisection to full precision.
    fn eigenvalue(&self, j: usize, (lo, hi): (f64, f64), tiny: f64) -> f64 {
        let (mut a, mut b) = (lo, hi);
        let scale = lo.abs().max(hi.abs());
        for _ in 0..200 {
            let mid = 0.5 * (a + b);
            if b - a <= 2.0 * f64::EPSILON * scale.max(mid.abs()) + f64::MIN_POSITIVE {
                break;
            }
            if self.count_below(mid, tiny) > j {
                b = mid;
            } else {
                a = mid;
            }
        }
        0.5 * (a + b)
    }

    /// One solve of `(T - lambda I) x = y` by Gaussian elimination with partial pivoting
    /// (the factorisation of LAPACK's `dlagtf`); `y` is overwritten with `x`.
    fn shifted_solve(&self, lambda: f64, tiny: f64, y: &mut [f64]) {
        let n = self.d.len();
        let (mut u0, mut u1, mut u2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let (mut l, mut swapped) = (vec![0.0; n], vec![false; n]);
        u0[0] = self.d[0] - lambda;
        if n > 1 {
            u1[0] = self.e[0];
        }
        for k in 0..n.saturating_sub(1) {
            let sub = self.e[k];
            let nd = self.d[k + 1] - lambda;
            let ne = if k + 2 < n { self.e[k + 1] } else { 0.0 };
            if u0[k].abs() >= sub.abs() {
                if u0[k].abs() < tiny {
                    u0[k] = tiny;
                }
                let m = sub / u0[k];
                l[k] = m;
                u0[k + 1] = nd - m * u1[k];
                u1[k + 1] = ne - m * u2[k];
            } else {
                let m = u0[k] / sub;
                l[k] = m;
                swapped[k] = true;
                let (a1, a2) = (u1[k], u2[k]);
                u0[k] = sub;
                u1[k] = nd;
                u2[k] = ne;
                u0[k + 1] = a1 - m * nd;
                u1[k + 1] = a2 - m * ne;
            }
        }
        if u0[n - 1].abs() < tiny {
            u0[n - 1] = tiny;
        }
        for k in 0..n.saturating_sub(1) {
            if swapped[k] {
                y.swap(k, k + 1);
            }
            y[k + 1] -= l[k] * y[k];
        }
        for k in (0..n).rev() {
            let mut v = y[k];
            if k + 1 < n {
                v -= u1[k] * y[k + 1];
            }
            if k + 2 < n {
                v -= u2[k] * y[k + 2];
            }
            y[k] = v / u0[k];
        }
    }
}

fn normalise(v: &mut [f64]) {
    let s = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    if s > 0.0 {
        v.iter_mut().for_each(|x| *x /= s);
    }
}

/// Eigenvectors of `t` for the ascending eigenvalues `lambdas` of one cluster, by inverse
/// iteration orthogonalised against the cluster's earlier vectors.
fn cluster_vectors(t: &Tridiagonal, lambdas: &[f64], first: usize, tiny: f64) -> Vec<Vec<f64>> {
    let n = t.d.len();
    let mut out: Vec<Vec<f64>> = Vec::with_capacity(lambdas.len());
    let mut prev = f64::NEG_INFINITY;
    for (j, &lam) in lambdas.iter().enumerate() {
        // Separate (nearly) equal eigenvalues slightly, as dstein does.
        let pert = 10.0 * f64::EPSILON * lam.abs().max(tiny);
        let lam = if lam - prev < pert { prev + pert } else { lam };
        prev = lam;
        let mut v = crate::rng::uniform_vec(0x5eed ^ (first + j) as u64, n, -1.0, 1.0)
            .expect("valid range");
        for _ in 0..5 {
            t.shifted_solve(lam, tiny, &mut v);
            for u in &out {
                let dot: f64 = u.iter().zip(&v).map(|(a, b)| a * b).sum();
                v.iter_mut().zip(u).for_each(|(x, a)| *x -= dot * a);
            }
            normalise(&mut v);
        }
        out.push(v);
    }
    out
}

/// The `k` largest (`largest = true`, returned in non-increasing order) or smallest
/// (non-decreasing order) eigenpairs of the symmetric matrix `a`, whose lower triangle is
/// read.
///
/// Errors: `k` outside `1..=n`.
pub fn eigh_selected(a: MatRef<'_, f64>, k: usize, largest: bool) -> Result<SymEigen> {
    crate::faer_par::fix_faer_parallelism();
    let n = a.nrows();
    if k == 0 || k > n {
        return Err(Error::invalid(
            "k",
            format!("must be between 1 and the matrix size {n}, got {k}"),
        ));
    }
    let par = faer::get_global_parallelism();
    // Householder reduction A = Q T Q'.
    let mut trid = Mat::<f64>::zeros(n, n);
    trid.copy_from_triangular_lower(a);
    let bs = faer::linalg::qr::no_pivoting::factor::recommended_block_size::<f64>(n, n);
    let mut hh = Mat::<f64>::zeros(bs, n.saturating_sub(1));
    let mut buf = MemBuffer::new(StackReq::any_of(&[
        tridiag::tridiag_in_place_scratch::<f64>(n, par, Default::default()),
        householder::apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(
            n.saturating_sub(1),
            bs,
            k,
        ),
    ]));
    if n > 1 {
        tridiag::tridiag_in_place(
            trid.as_mut(),
            hh.as_mut(),
            par,
            MemStack::new(&mut buf),
            Default::default(),
        );
    }
    let t = Tridiagonal {
        d: (0..n).map(|i| trid[(i, i)]).collect(),
        e: (0..n.saturating_sub(1)).map(|i| trid[(i + 1, i)]).collect(),
    };
    let bounds = t.bounds();
    let norm = bounds.0.abs().max(bounds.1.abs()).max(f64::MIN_POSITIVE);
    let tiny = f64::EPSILON * norm;
    // Wanted eigenvalues in ascending order.
    let first = if largest { n - k } else { 0 };
    let lambdas: Vec<f64> = (first..first + k)
        .into_par_iter()
        .map(|j| t.eigenvalue(j, bounds, tiny))
        .collect();
    // Clusters: neighbours closer than 1e-3 |T| (dstein's criterion).
    let mut clusters: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for j in 1..=k {
        if j == k || lambdas[j] - lambdas[j - 1] > 1e-3 * norm {
            clusters.push((start, j));
            start = j;
        }
    }
    let vectors: Vec<Vec<f64>> = clusters
        .par_iter()
        .flat_map_iter(|&(s, e)| cluster_vectors(&t, &lambdas[s..e], first + s, tiny))
        .collect();
    // Back-transformation U = Q S (Q acts on rows 1..n).
    let order: Vec<usize> = if largest {
        (0..k).rev().collect()
    } else {
        (0..k).collect()
    };
    let mut u = Mat::from_fn(n, k, |i, c| vectors[order[c]][i]);
    if n > 1 {
        householder::apply_block_householder_sequence_on_the_left_in_place_with_conj(
            trid.as_ref().submatrix(1, 0, n - 1, n - 1),
            hh.as_ref(),
            Conj::No,
            u.as_mut().subrows_mut(1, n - 1),
            par,
            MemStack::new(&mut buf),
        );
    }
    Ok(SymEigen {
        values: order.iter().map(|&j| lambdas[j]).collect(),
        vectors: u,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sym_eigen::eigh;

    /// `Q diag(values) Q'` with a random orthogonal `Q`.
    fn with_spectrum(values: &[f64], seed: u64) -> Mat<f64> {
        let n = values.len();
        let g = crate::rng::normal_vec(seed, n * n, 0.0, 1.0).unwrap();
        let g = Mat::from_fn(n, n, |i, j| g[i * n + j]);
        let q = g.qr().compute_Q();
        let d = Mat::from_fn(n, n, |i, j| if i == j { values[i] } else { 0.0 });
        let a = &q * &d * q.transpose();
        Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
    }

    fn check(a: &Mat<f64>, k: usize, largest: bool) {
        let n = a.nrows();
        let full = eigh(a.as_ref()).unwrap();
        let sel = eigh_selected(a.as_ref(), k, largest).unwrap();
        let scale = full
            .values
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1e-300);
        for c in 0..k {
            let want = if largest {
                full.values[n - 1 - c]
            } else {
                full.values[c]
            };
            assert!(
                (sel.values[c] - want).abs() <= 1e-12 * scale,
                "n {n} k {k} value {c}: {} vs {want}",
                sel.values[c]
            );
            // Residual |A v - lambda v|.
            let v = sel.vectors.col(c);
            let av = a * v;
            let r = (0..n)
                .map(|i| (av[i] - sel.values[c] * v[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(r <= 1e-11 * scale, "residual {c}: {r}");
        }
        let g = sel.vectors.transpose() * &sel.vectors;
        for i in 0..k {
            for j in 0..k {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (g[(i, j)] - want).abs() <= 1e-10,
                    "V'V at {i},{j}: {}",
                    g[(i, j)]
                );
            }
        }
    }

    #[test]
    fn matches_full_decomposition() {
        let n = 120;
        let a = crate::rng::normal_vec(3, n * n, 0.0, 1.0).unwrap();
        let a = Mat::from_fn(n, n, |i, j| a[i * n + j] + a[j * n + i]);
        check(&a, 10, true);
        check(&a, 7, false);
        check(&a, n, true);
        // Decaying PSD spectrum with exact zeros (a centred kernel matrix).
        let vals: Vec<f64> = (0..80)
            .map(|i| {
                if i < 60 {
                    (-(i as f64) / 5.0).exp()
                } else {
                    0.0
                }
            })
            .collect();
        check(&with_spectrum(&vals, 4), 20, true);
        check(&with_spectrum(&vals, 4), 30, false);
        // Repeated eigenvalues: a cluster needs orthogonalisation.
        let vals: Vec<f64> = (0..50)
            .map(|i| if i < 6 { 5.0 } else { i as f64 / 50.0 })
            .collect();
        check(&with_spectrum(&vals, 5), 8, true);
        check(&Mat::from_fn(1, 1, |_, _| 2.5), 1, true);
        check(
            &Mat::from_fn(2, 2, |i, j| if i == j { 1.0 } else { 3.0 }),
            1,
            false,
        );
        for m in [3usize, 4, 5, 17] {
            let b = crate::rng::normal_vec(m as u64, m * m, 0.0, 1.0).unwrap();
            let b = Mat::from_fn(m, m, |i, j| b[i * m + j] + b[j * m + i]);
            check(&b, 1, false);
            check(&b, m, true);
        }
        assert!(eigh_selected(a.as_ref(), 0, true).is_err());
        assert!(eigh_selected(a.as_ref(), n + 1, true).is_err());
    }
}
