//! The largest eigenpairs of a symmetric matrix by block Krylov iteration with Rayleigh-Ritz
//! extraction, accepted only when every Ritz pair's residual `|A v - theta v|` is below
//! `1e-13 |A|`; otherwise the caller falls back to the tridiagonal method of
//! [`crate::eigh_partial`]. Every step is a matrix-matrix product, so for a few of many
//! eigenpairs of a large, quickly decaying spectrum (kernel matrices) this is several times
//! faster than reducing the whole matrix.
//!
//! The start block is a seeded Gaussian block, so results are deterministic.

use faer::{Mat, MatRef};

use crate::dense::SymEigen;
use crate::eigh_partial::eigh_selected;

/// Relative residual a Ritz pair must reach.
const TOL: f64 = 1e-13;
/// Relative residual above which, after four blocks, the iteration is abandoned.
const STALL: f64 = 1e-3;

/// Orthonormalises the columns of `w` against the columns of `v` (two passes of block
/// Gram-Schmidt) and then among themselves (QR). Columns that vanish (the Krylov space is
/// invariant) are dropped.
fn orthonormal_block(v: MatRef<'_, f64>, mut w: Mat<f64>) -> Mat<f64> {
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
        Mat::zeros(n, 0).as_ref(),
        Mat::from_fn(n, b, |i, j| start[i * b + j]),
    );
    // Basis V, A V and the projected matrix H = V' A V, grown block by block.
    let mut v = Mat::<f64>::zeros(n, max_basis);
    let mut av = Mat::<f64>::zeros(n, max_basis);
    let mut h = Mat::<f64>::zeros(max_basis, max_basis);
    let mut m = 0;
    let (mut blocks, mut next_check) = (0usize, 0usize);
    let mut last: Option<(usize, f64)> = None;
    loop {
        let nb = q.ncols();
        if m + nb > max_basis {
            return None;
        }
        let aq = a * &q;
        v.as_mut().submatrix_mut(0, m, n, nb).copy_from(&q);
        av.as_mut().submatrix_mut(0, m, n, nb).copy_from(&aq);
        let m1 = m + nb;
        // New column block V' (A Q), mirrored into the new row block.
        let col = v.as_ref().submatrix(0, 0, n, m1).transpose() * &aq;
        for j in 0..nb {
            for i in 0..m1 {
                h[(i, m + j)] = col[(i, j)];
                h[(m + j, i)] = col[(i, j)];
            }
        }
        for j in 0..nb {
            for i in 0..nb {
                let s = 0.5 * (col[(m + i, j)] + col[(m + j, i)]);
                h[(m + i, m + j)] = s;
            }
        }
        m = m1;
        blocks += 1;
        let last_chance = m + b > max_basis;
        if m >= 2 * k && (blocks >= next_check || last_chance) {
            // Top k Ritz pairs (the largest Ritz value bounds |A| from below).
            let e = eigh_selected(h.as_ref().submatrix(0, 0, m, m), k, true).ok()?;
            let y = e.vectors;
            let theta = e.values;
            let norm = theta[0].abs().max(f64::MIN_POSITIVE);
            let u = v.as_ref().submatrix(0, 0, n, m) * &y;
            let mut r = av.as_ref().submatrix(0, 0, n, m) * &y;
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
            if m >= 4 * b && worst > STALL * norm {
                return None;
            }
            // Residuals fall geometrically per block: skip the Rayleigh-Ritz steps that
            // cannot converge yet.
            let rel = worst / norm;
            next_check = blocks + 1;
            if let Some((prev_blocks, prev)) = last {
                let rate = (rel / prev).powf(1.0 / (blocks - prev_blocks) as f64);
                if rate < 0.9 {
                    let needed = ((TOL / rel).ln() / rate.ln()).floor() as usize;
                    next_check = blocks + needed.max(1);
                }
            }
            last = Some((blocks, rel));
        }
        q = orthonormal_block(v.as_ref().submatrix(0, 0, n, m), aq);
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
