//! The largest eigenpairs of a symmetric matrix by block Krylov iteration with Rayleigh-Ritz
//! extraction, accepted only when every Ritz pair's residual `|A v - theta v|` is below
//! `1e-13 |A|`; otherwise the caller falls back to the tridiagonal method of
//! [`crate::eigh_partial`]. Every step is a matrix-matrix product, so for a few of many
//! eigenpairs of a large, quickly decaying spectrum (kernel matrices) this is several times
//! faster than reducing the whole matrix.
//!
//! The start block is a seeded Gaussian block, so results are deterministic.

use faer::{Mat, MatRef};

use crate::dense::{eigh, SymEigen};

/// Relative residual a Ritz pair must reach.
const TOL: f64 = 1e-13;
/// Relative residual above which, after four blocks, the iteration is abandoned.
const STALL: f64 = 1e-3;

/// Orthonormalises the columns of `w` against the columns of `v` (two passes of block
/// Gram-Schmidt) and then among themselves (QR). Columns that vanish (the Krylov space is
/// invariant) are dropped.
fn orthonormal_block(v: &Mat<f64>, mut w: Mat<f64>) -> Mat<f64> {
    for _ in 0..2 {
        if v.ncols() > 0 {
            let c = v.transpose() * &w;
            w -= v * c;
        }
    }
    let scale = w.norm_max().max(f64::MIN_POSITIVE);
    let qr = w.qr();
    let r = qr.thin_R();
    let q = qr.compute_thin_Q();
    let keep: Vec<usize> = (0..r.ncols().min(r.nrows()))
        .filter(|&i| r[(i, i)].abs() > 1e-10 * scale)
        .collect();
    Mat::from_fn(q.nrows(), keep.len(), |i, j| q[(i, keep[j])])
}

fn hcat(a: &Mat<f64>, b: &Mat<f64>) -> Mat<f64> {
    let n = a.nrows().max(b.nrows());
    Mat::from_fn(n, a.ncols() + b.ncols(), |i, j| {
        if j < a.ncols() {
            a[(i, j)]
        } else {
            b[(i, j - a.ncols())]
        }
    })
}

/// The `k` largest eigenpairs (non-increasing) of the symmetric `a`, or `None` when the
/// residual test is not met within the basis-size budget.
pub fn eigh_largest_krylov(a: MatRef<'_, f64>, k: usize) -> Option<SymEigen> {
    let n = a.nrows();
    if k == 0 || 4 * k > n {
        return None;
    }
    let b = k + 10;
    let max_basis = (n / 2).min(16 * b);
    let start = crate::rng::normal_vec(0x6b72_796c, n * b, 0.0, 1.0).ok()?;
    let mut q = orthonormal_block(
        &Mat::zeros(n, 0),
        Mat::from_fn(n, b, |i, j| start[i * b + j]),
    );
    let mut v = Mat::<f64>::zeros(n, 0);
    let mut av = Mat::<f64>::zeros(n, 0);
    loop {
        let aq = a * &q;
        v = hcat(&v, &q);
        av = hcat(&av, &aq);
        let h = v.transpose() * &av;
        let h = Mat::from_fn(h.nrows(), h.ncols(), |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
        let e = eigh(h.as_ref()).ok()?;
        let m = e.values.len();
        if m >= k {
            let cols: Vec<usize> = (m - k..m).rev().collect();
            let y = Mat::from_fn(m, k, |i, j| e.vectors[(i, cols[j])]);
            let theta: Vec<f64> = cols.iter().map(|&c| e.values[c]).collect();
            let norm = e
                .values
                .iter()
                .fold(0.0f64, |s, x| s.max(x.abs()))
                .max(f64::MIN_POSITIVE);
            let u = &v * &y;
            let mut r = &av * &y;
            for (j, t) in theta.iter().enumerate() {
                for i in 0..n {
                    r[(i, j)] -= t * u[(i, j)];
                }
            }
            let worst = (0..k)
                .map(|j| (0..n).map(|i| r[(i, j)] * r[(i, j)]).sum::<f64>().sqrt())
                .fold(0.0f64, f64::max);
            if worst <= TOL * norm {
                return Some(SymEigen {
                    values: theta,
                    vectors: u,
                });
            }
            // A flat spectrum: convergence would need most of the space; give up early.
            if v.ncols() >= 4 * b && worst > STALL * norm {
                return None;
            }
        }
        if v.ncols() + b > max_basis {
            return None;
        }
        q = orthonormal_block(&v, aq);
        if q.ncols() == 0 {
            return None;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn converges_on_decaying_spectrum_and_matches_full() {
        let n = 300;
        let g = crate::rng::normal_vec(7, n * n, 0.0, 1.0).unwrap();
        let gm = Mat::from_fn(n, n, |i, j| g[i * n + j]);
        let q = gm.qr().compute_Q();
        let vals: Vec<f64> = (0..n).map(|i| (-(i as f64) / 8.0).exp()).collect();
        let d = Mat::from_fn(n, n, |i, j| if i == j { vals[i] } else { 0.0 });
        let a = &q * &d * q.transpose();
        let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let e = eigh_largest_krylov(a.as_ref(), 20).expect("converges");
        for (j, v) in e.values.iter().enumerate() {
            assert!((v - vals[j]).abs() < 1e-12, "{j}: {v} vs {}", vals[j]);
            // Eigenvector equals the j-th column of Q up to sign.
            let dot: f64 = (0..n).map(|i| e.vectors[(i, j)] * q[(i, j)]).sum();
            assert!((dot.abs() - 1.0).abs() < 1e-10, "{j}: {dot}");
        }
        // A flat spectrum (random symmetric matrix) does not meet the test: `None`.
        let r = Mat::from_fn(n, n, |i, j| g[i * n + j] + g[j * n + i]);
        assert!(eigh_largest_krylov(r.as_ref(), 20).is_none());
        assert!(eigh_largest_krylov(a.as_ref(), 0).is_none());
    }
}
