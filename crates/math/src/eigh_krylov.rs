//! The largest eigenpairs of a symmetric matrix by block Krylov iteration with Rayleigh-Ritz
//! extraction, accepted only when every Ritz pair's residual `|A v - theta v|` is below
//! `1e-13 |A|`; otherwise the caller falls back to the tridiagonal method of
//! [`crate::eigh_partial`]. Every step is a matrix-matrix product, so for a few of many
//! eigenpairs of a large, quickly decaying spectrum (kernel matrices) this is several times
//! faster than reducing the whole matrix.
//!
//! For slowly decaying spectra (geodesic kernels of Isomap, for instance) the growing basis
//! of [`eigh_largest_krylov`] runs out of budget; [`eigh_largest_restarted`] keeps the basis
//! small by thick restarts instead.
//!
//! The start blocks are seeded Gaussian blocks, so results are deterministic.

use faer::{Mat, MatRef};

use crate::eigh_partial::eigh_selected;
use crate::sym_eigen::SymEigen;

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
    crate::faer_par::fix_faer_parallelism();
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

/// `[a b]`: the columns of `a` followed by those of `b`.
fn hcat(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let (n, p) = (a.nrows(), a.ncols());
    let mut c = Mat::zeros(n, p + b.ncols());
    c.as_mut().submatrix_mut(0, 0, n, p).copy_from(a);
    c.as_mut().submatrix_mut(0, p, n, b.ncols()).copy_from(b);
    c
}

/// The `k` largest eigenpairs (non-increasing) of the symmetric `a` by block Lanczos with
/// thick restart (block size `k + 8`): the basis grows by the orthonormalised residuals of
/// the top Ritz pairs (the next block-Krylov directions), Rayleigh-Ritz on `V' A V` every
/// step, and on reaching five blocks is cut back to the top two blocks of Ritz vectors. Every
/// product with `a` is a matrix-matrix product. Accepted when every wanted Ritz pair has
/// `|A u - theta u| <= 1e-12 max|theta|`; `None` for matrices smaller than eight blocks, or
/// when convergence takes more than `max(n / 2, 40 b)` products (a dense method is then as
/// cheap).
pub fn eigh_largest_restarted(a: MatRef<'_, f64>, k: usize) -> Option<SymEigen> {
    crate::faer_par::fix_faer_parallelism();
    const TOL: f64 = 1e-12;
    let n = a.nrows();
    let b = k + 8;
    if k == 0 || n < 8 * b {
        return None;
    }
    let (max_basis, keep) = (5 * b, 2 * b);
    let start = crate::rng::normal_vec(0x1504_a9e5, n * b, 0.0, 1.0).ok()?;
    let mut w = Mat::from_fn(n, b, |i, j| start[i * b + j]);
    let mut v = Mat::<f64>::zeros(n, 0);
    let mut av = Mat::<f64>::zeros(n, 0);
    let mut products = 0;
    while products <= (n / 2).max(40 * b) {
        // Residual columns differ in size by orders of magnitude: normalise them so that
        // the rank test of the orthonormalisation is relative to each direction.
        for j in 0..w.ncols() {
            let norm = w.col(j).norm_l2();
            if norm > 0.0 {
                w.col_as_slice_mut(j).iter_mut().for_each(|x| *x /= norm);
            }
        }
        let q = orthonormal_block(v.as_ref(), w);
        if q.ncols() == 0 {
            return None;
        }
        products += q.ncols();
        let aq = a * &q;
        v = hcat(v.as_ref(), q.as_ref());
        av = hcat(av.as_ref(), aq.as_ref());
        let m = v.ncols();
        let h = v.transpose() * &av;
        let h = Mat::from_fn(m, m, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
        let e = crate::sym_eigen::eigh(h.as_ref()).ok()?;
        let norm = e
            .values
            .iter()
            .fold(0.0f64, |acc, x| acc.max(x.abs()))
            .max(f64::MIN_POSITIVE);
        let s = b.min(m);
        // Top s Ritz pairs, descending.
        let y = Mat::from_fn(m, s, |i, j| e.vectors[(i, m - 1 - j)]);
        let theta: Vec<f64> = (0..s).map(|j| e.values[m - 1 - j]).collect();
        let u = &v * &y;
        let mut r = &av * &y;
        for (j, t) in theta.iter().enumerate() {
            for (x, ux) in r.col_as_slice_mut(j).iter_mut().zip(u.col_as_slice(j)) {
                *x -= t * ux;
            }
        }
        let worst = (0..k.min(s))
            .map(|j| r.col(j).norm_l2())
            .fold(0.0f64, f64::max);
        if s >= k && worst <= TOL * norm {
            return Some(SymEigen {
                values: theta[..k].to_vec(),
                vectors: u.as_ref().subcols(0, k).to_owned(),
            });
        }
        if m + b > max_basis {
            let keep = keep.min(m);
            let yk = Mat::from_fn(m, keep, |i, j| e.vectors[(i, m - 1 - j)]);
            v = &v * &yk;
            av = &av * &yk;
        }
        w = r;
    }
    None
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

    #[test]
    fn restarted_lanczos_matches_dense_eigh() {
        // Symmetric, indefinite, slowly decaying spectrum with a near-tie at the cut.
        let n = 300;
        let g = crate::rng::normal_vec(4, n * n, 0.0, 1.0).unwrap();
        let q = Mat::from_fn(n, n, |i, j| g[i * n + j])
            .qr()
            .compute_thin_Q();
        let lam: Vec<f64> = (0..n)
            .map(|i| match i {
                8 => 10.0 / 9.0 + 1e-3,
                _ => 10.0 / (1.0 + i as f64) - 0.5,
            })
            .collect();
        let a = Mat::from_fn(n, n, |i, j| {
            (0..n).map(|t| q[(i, t)] * lam[t] * q[(j, t)]).sum::<f64>()
        });
        let a = Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]));
        let k = 9;
        let e = eigh_largest_restarted(a.as_ref(), k).expect("converges");
        let full = crate::sym_eigen::eigh(a.as_ref()).unwrap();
        for c in 0..k {
            let want = full.values[n - 1 - c];
            assert!((e.values[c] - want).abs() < 1e-11 * lam[0], "{c}");
            let cos: f64 = (0..n)
                .map(|i| e.vectors[(i, c)] * full.vectors[(i, n - 1 - c)])
                .sum();
            assert!(1.0 - cos.abs() < 1e-12, "{c}: {cos}");
        }
    }

    #[test]
    fn restarted_lanczos_declines_small_matrices() {
        let a = Mat::<f64>::identity(50, 50);
        assert!(eigh_largest_restarted(a.as_ref(), 3).is_none());
        assert!(eigh_largest_restarted(a.as_ref(), 0).is_none());
    }
}
