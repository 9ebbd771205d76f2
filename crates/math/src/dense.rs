//! Dense linear algebra through faer: Gram matrices `X'X` (half the work of a general
//! product), symmetric eigendecomposition (all, largest k, smallest k), thin SVD, minimum-norm least squares and the generalized symmetric-definite
//! eigenproblem `A v = lambda B v`.
//!
//! Matrices are `faer::Mat<f64>` / `MatRef<f64>`. Every function checks that its input is
//! non-empty and finite (and symmetric where required) and returns an [`Error`] naming the
//! argument otherwise.

use faer::{Mat, MatRef, Side};

use crate::error::{Error, Result};
pub use crate::sym_eigen::{check_matrix, check_symmetric, eigh, SymEigen};

/// Thin singular value decomposition `A = U diag(s) V'`.
#[derive(Clone, Debug)]
pub struct Svd {
    /// `m x r` left singular vectors, `r = min(m, n)`.
    pub u: Mat<f64>,
    /// `r` singular values, non-increasing.
    pub s: Vec<f64>,
    /// `n x r` right singular vectors.
    pub v: Mat<f64>,
}

/// Adds `alpha X'X` to the symmetric `acc` (`p x p` for `x` of `n x p`): only the lower
/// triangle is computed (a symmetric rank-k update, half the flops of `x' * x`), then
/// mirrored, so `acc` stays exactly symmetric.
///
/// # Panics
/// When `acc` is not `p x p` (a programming error, not a data error).
pub fn gram_accumulate(acc: &mut Mat<f64>, x: MatRef<'_, f64>, alpha: f64) {
    lower_accumulate(acc, x, alpha);
    mirror_lower(acc);
}

/// Adds `alpha X'X` to the lower triangle (diagonal included) of `acc`.
fn lower_accumulate(acc: &mut Mat<f64>, x: MatRef<'_, f64>, alpha: f64) {
    use faer::linalg::matmul::triangular::{matmul, BlockStructure};
    crate::faer_par::fix_faer_parallelism();
    let p = x.ncols();
    assert!(
        acc.nrows() == p && acc.ncols() == p,
        "gram_accumulate: acc is not p x p"
    );
    matmul(
        acc.as_mut(),
        BlockStructure::TriangularLower,
        faer::Accum::Add,
        x.transpose(),
        BlockStructure::Rectangular,
        x,
        BlockStructure::Rectangular,
        alpha,
        faer::get_global_parallelism(),
    );
}

/// Copies the strict lower triangle of the square `a` onto its upper triangle.
fn mirror_lower(a: &mut Mat<f64>) {
    for j in 1..a.ncols() {
        for i in 0..j {
            a[(i, j)] = a[(j, i)];
        }
    }
}

/// `alpha (X - 1 mean')'(X - 1 mean)`, exactly symmetric: the scatter matrix of the rows of
/// `x` about `mean` (`p` values). The rows are centred block by block into one reused buffer,
/// so no centred copy of `x` is made.
///
/// # Panics
/// When `mean.len() != x.ncols()`.
pub fn centered_gram(x: MatRef<'_, f64>, mean: &[f64], alpha: f64) -> Mat<f64> {
    let cols: Vec<usize> = (0..x.ncols()).collect();
    centered_gram_of(x, &cols, mean, alpha)
}

/// [`centered_gram`] of the columns `cols` of `x` only (`q x q` for `q = cols.len()`,
/// `mean` holding the `q` means of those columns): e.g. the non-constant columns, whose
/// scatter is all a covariance needs.
///
/// # Panics
/// When `mean.len() != cols.len()` or a column index is out of range.
pub fn centered_gram_of(x: MatRef<'_, f64>, cols: &[usize], mean: &[f64], alpha: f64) -> Mat<f64> {
    use rayon::prelude::*;
    let (n, p) = (x.nrows(), cols.len());
    assert_eq!(mean.len(), p, "centered_gram: mean has the wrong length");
    let mut g = Mat::zeros(p, p);
    // Blocks of about 2^22 values (32 MB).
    let block = ((1usize << 22) / p.max(1)).clamp(64, n.max(64));
    let mut buf = Mat::<f64>::zeros(block.min(n), p);
    let mut start = 0;
    while start < n {
        let len = block.min(n - start);
        let b = buf.as_mut().subrows_mut(0, len);
        b.par_col_iter_mut().enumerate().for_each(|(k, c)| {
            let src = x.col(cols[k]).subrows(start, len);
            for (o, v) in c.iter_mut().zip(src.iter()) {
                *o = v - mean[k];
            }
        });
        lower_accumulate(&mut g, buf.as_ref().subrows(0, len), alpha);
        start += len;
    }
    mirror_lower(&mut g);
    g
}

/// The `rows x cols` matrix stored row by row in `v` (numpy's C order) as a column-major
/// [`Mat`] (see [`copy_row_major`]).
///
/// # Panics
/// When `v.len() != rows * cols`.
pub fn from_row_major(v: &[f64], rows: usize, cols: usize) -> Mat<f64> {
    let mut m = Mat::<f64>::zeros(rows, cols);
    copy_row_major(v, m.as_mut());
    m
}

/// Copies the matrix stored row by row in `v` into `dst` (same shape): a cache-blocked
/// transpose, column blocks in parallel (several times faster than filling `dst` element by
/// element from the strided source).
///
/// # Panics
/// When `v.len() != dst.nrows() * dst.ncols()`.
pub fn copy_row_major(v: &[f64], dst: faer::MatMut<'_, f64>) {
    use rayon::prelude::*;
    const COLS: usize = 32;
    let (rows, cols) = (dst.nrows(), dst.ncols());
    assert_eq!(v.len(), rows * cols, "copy_row_major: wrong length");
    if rows == 0 || cols == 0 {
        return;
    }
    dst.par_col_chunks_mut(COLS)
        .enumerate()
        .for_each(|(b, mut blk)| {
            let j0 = b * COLS;
            for i in 0..rows {
                let src = &v[i * cols + j0..i * cols + j0 + blk.ncols()];
                for (j, &x) in src.iter().enumerate() {
                    blk[(i, j)] = x;
                }
            }
        });
}

/// `f` applied to consecutive blocks of rows of the C-order `rows x cols` matrix `v`, each
/// block copied into one reused column-major buffer of at most 16 MB: a row-wise map
/// (projection, prediction) over a large input without a column-major copy of all of it.
/// Returns the per-block results in order; stops at the first error.
///
/// # Panics
/// When `v.len() != rows * cols`.
pub fn map_row_blocks<T>(
    v: &[f64],
    rows: usize,
    cols: usize,
    mut f: impl FnMut(MatRef<'_, f64>) -> Result<T>,
) -> Result<Vec<T>> {
    assert_eq!(v.len(), rows * cols, "map_row_blocks: wrong length");
    let block = ((1usize << 21) / cols.max(1)).clamp(64, rows.max(64));
    let mut buf = Mat::<f64>::zeros(block.min(rows), cols);
    let mut out = Vec::with_capacity(rows.div_ceil(block));
    let mut start = 0;
    loop {
        let len = block.min(rows - start);
        copy_row_major(
            &v[start * cols..(start + len) * cols],
            buf.as_mut().subrows_mut(0, len),
        );
        out.push(f(buf.as_ref().subrows(0, len))?);
        start += len;
        if start >= rows {
            return Ok(out);
        }
    }
}

/// `alpha X'X`, exactly symmetric (see [`gram_accumulate`]).
pub fn gram(x: MatRef<'_, f64>, alpha: f64) -> Mat<f64> {
    let mut g = Mat::zeros(x.ncols(), x.ncols());
    gram_accumulate(&mut g, x, alpha);
    g
}

fn select(e: SymEigen, k: usize, largest: bool) -> Result<SymEigen> {
    let n = e.values.len();
    if k == 0 || k > n {
        return Err(Error::invalid(
            "k",
            format!("must be between 1 and the matrix size {n}, got {k}"),
        ));
    }
    let idx: Vec<usize> = if largest {
        (n - k..n).rev().collect()
    } else {
        (0..k).collect()
    };
    Ok(SymEigen {
        values: idx.iter().map(|&i| e.values[i]).collect(),
        vectors: Mat::from_fn(n, k, |r, c| e.vectors[(r, idx[c])]),
    })
}

/// The `k` largest eigenpairs of the symmetric `a`, eigenvalues in non-increasing order.
///
/// For `k <= n / 4` only the wanted eigenpairs are computed: by block Krylov iteration when
/// its residual test passes ([`crate::eigh_krylov`]; fast for quickly decaying spectra such
/// as kernel matrices), else by tridiagonalisation, bisection and inverse iteration
/// ([`crate::eigh_partial`]); for larger `k` the full decomposition is taken.
pub fn eigh_largest(a: MatRef<'_, f64>, k: usize) -> Result<SymEigen> {
    selected(a, k, true)
}

/// The `k` smallest eigenpairs of the symmetric `a`, eigenvalues in non-decreasing order
/// (computed as [`eigh_largest`] is).
pub fn eigh_smallest(a: MatRef<'_, f64>, k: usize) -> Result<SymEigen> {
    selected(a, k, false)
}

fn selected(a: MatRef<'_, f64>, k: usize, largest: bool) -> Result<SymEigen> {
    crate::faer_par::fix_faer_parallelism();
    check_symmetric("a", a)?;
    if k >= 1 && 4 * k <= a.nrows() {
        if largest {
            if let Some(e) = crate::eigh_krylov::eigh_largest_krylov(a, k) {
                return Ok(e);
            }
        }
        crate::eigh_partial::eigh_selected(a, k, largest)
    } else {
        select(eigh(a)?, k, largest)
    }
}

/// Thin SVD of `a` (`m x n`), singular values non-increasing.
pub fn svd(a: MatRef<'_, f64>) -> Result<Svd> {
    crate::faer_par::fix_faer_parallelism();
    check_matrix("a", a)?;
    let d = a
        .thin_svd()
        .map_err(|e| Error::Numerical(format!("SVD did not converge: {e:?}")))?;
    let r = a.nrows().min(a.ncols());
    Ok(Svd {
        u: d.U().to_owned(),
        s: (0..r).map(|i| d.S()[i]).collect(),
        v: d.V().to_owned(),
    })
}

/// Minimum-norm least-squares solution `X` of `A X = B` (`a`: `m x n`, `b`: `m x k`),
/// through the SVD with singular values below `rcond * s_max` treated as zero (`rcond =
/// None` uses `eps * max(m, n)`, numpy's `lstsq` default). Handles over- and
/// under-determined and rank-deficient systems.
pub fn lstsq(a: MatRef<'_, f64>, b: MatRef<'_, f64>, rcond: Option<f64>) -> Result<Mat<f64>> {
    crate::faer_par::fix_faer_parallelism();
    check_matrix("a", a)?;
    check_matrix("b", b)?;
    if b.nrows() != a.nrows() {
        return Err(Error::ShapeMismatch(format!(
            "a has {} rows but b has {}",
            a.nrows(),
            b.nrows()
        )));
    }
    let d = svd(a)?;
    let rcond = rcond.unwrap_or(f64::EPSILON * a.nrows().max(a.ncols()) as f64);
    if !(rcond.is_finite() && rcond >= 0.0) {
        return Err(Error::invalid(
            "rcond",
            format!("must be finite and >= 0, got {rcond}"),
        ));
    }
    let cut = rcond * d.s.first().copied().unwrap_or(0.0);
    // X = V diag(1/s) U' B over the kept singular values.
    let utb = d.u.transpose() * b;
    let scaled = Mat::from_fn(utb.nrows(), utb.ncols(), |i, j| {
        if d.s[i] > cut {
            utb[(i, j)] / d.s[i]
        } else {
            0.0
        }
    });
    Ok(&d.v * &scaled)
}

/// Generalized symmetric-definite eigenproblem `A v = lambda B v` with `B` positive
/// definite: through the Cholesky factor `B = L L'`, the standard problem
/// `L^-1 A L^-T w = lambda w`, and `v = L^-T w`. Eigenvalues non-decreasing; eigenvectors
/// `B`-orthonormal (`V' B V = I`).
///
/// Errors: `a`, `b` not symmetric or of different size; `b` not positive definite.
pub fn eigh_generalized(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Result<SymEigen> {
    crate::faer_par::fix_faer_parallelism();
    check_symmetric("a", a)?;
    check_symmetric("b", b)?;
    if a.nrows() != b.nrows() {
        return Err(Error::ShapeMismatch(format!(
            "a is {0}x{0} but b is {1}x{1}",
            a.nrows(),
            b.nrows()
        )));
    }
    let llt = b
        .llt(Side::Lower)
        .map_err(|_| Error::invalid("b", "must be positive definite (Cholesky failed)"))?;
    let l = llt.L();
    // X = L^-1 A, then C = L^-1 X' = L^-1 A L^-T.
    let mut x = a.to_owned();
    l.solve_lower_triangular_in_place(x.as_mut());
    let mut c = x.transpose().to_owned();
    l.solve_lower_triangular_in_place(c.as_mut());
    let n = c.nrows();
    let c = Mat::from_fn(n, n, |i, j| 0.5 * (c[(i, j)] + c[(j, i)]));
    let e = eigh(c.as_ref())?;
    let mut v = e.vectors;
    l.transpose().solve_upper_triangular_in_place(v.as_mut());
    Ok(SymEigen {
        values: e.values,
        vectors: v,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    fn random(m: usize, n: usize, seed: u64) -> Mat<f64> {
        let mut r = crate::rng::seeded(seed);
        Mat::from_fn(m, n, |_, _| r.random_range(-1.0..1.0))
    }

    #[test]
    fn from_row_major_is_the_c_order_matrix() {
        // Widths below, at and above one column block of the transpose, and empty shapes.
        for (r, c) in [(7, 5), (3, 32), (41, 70), (0, 4), (4, 0)] {
            let v: Vec<f64> = (0..r * c).map(|k| k as f64 * 0.5 - 3.0).collect();
            let m = from_row_major(&v, r, c);
            assert_eq!((m.nrows(), m.ncols()), (r, c));
            let sums = map_row_blocks(&v, r, c, |b| Ok((b.nrows(), b.sum()))).unwrap();
            assert_eq!(sums.iter().map(|s| s.0).sum::<usize>(), r);
            let total: f64 = v.iter().sum();
            assert!((sums.iter().map(|s| s.1).sum::<f64>() - total).abs() < 1e-9);
            for i in 0..r {
                for j in 0..c {
                    assert_eq!(m[(i, j)], v[i * c + j]);
                }
            }
        }
    }

    #[test]
    fn row_blocks_cover_the_rows_in_order() {
        // 2^21 / 40000 < 64: blocks of 64 rows, the last one shorter.
        let (r, c) = (150, 40_000);
        let v: Vec<f64> = (0..r * c)
            .map(|k| (k / c) as f64 + (k % c) as f64 * 1e-6)
            .collect();
        let blocks = map_row_blocks(&v, r, c, |b| {
            Ok((b.nrows(), b[(0, 0)], b[(b.nrows() - 1, c - 1)]))
        })
        .unwrap();
        assert_eq!(
            blocks,
            vec![
                (64, 0.0, 63.0 + 0.039999),
                (64, 64.0, 127.0 + 0.039999),
                (22, 128.0, 149.0 + 0.039999)
            ]
        );
        let err = map_row_blocks(&v, r, c, |b| {
            if b[(0, 0)] > 0.0 {
                Err(Error::invalid("x", "stop"))
            } else {
                Ok(())
            }
        });
        assert!(err.is_err());
    }

    #[test]
    fn gram_equals_the_full_product_and_is_symmetric() {
        let x = random(57, 23, 9);
        let full = x.transpose() * &x;
        let mut g = gram(x.as_ref(), 0.5);
        for i in 0..23 {
            for j in 0..23 {
                assert!((g[(i, j)] - 0.5 * full[(i, j)]).abs() < 1e-12);
                assert_eq!(g[(i, j)], g[(j, i)]);
            }
        }
        gram_accumulate(&mut g, x.as_ref(), 0.5);
        assert!((g[(3, 7)] - full[(3, 7)]).abs() < 1e-12);
        // Centred, with more rows than one block (2^22 / 40 = 104857) holds.
        let (n, p) = (110_000, 40);
        let x = random(n, p, 10);
        let mean: Vec<f64> = (0..p)
            .map(|j| x.col(j).iter().sum::<f64>() / n as f64 + 0.25)
            .collect();
        let xc = Mat::from_fn(n, p, |i, j| x[(i, j)] - mean[j]);
        let want = xc.transpose() * &xc;
        let got = centered_gram(x.as_ref(), &mean, 1.0);
        for i in 0..p {
            for j in 0..p {
                assert!((got[(i, j)] - want[(i, j)]).abs() < 1e-8 * want[(i, i)].abs());
            }
        }
    }

    fn spd(n: usize, seed: u64) -> Mat<f64> {
        let g = random(n, n, seed);
        let mut a = &g * g.transpose();
        for i in 0..n {
            a[(i, i)] += n as f64;
        }
        a
    }

    fn max_abs(m: &Mat<f64>) -> f64 {
        let mut v = 0.0f64;
        for j in 0..m.ncols() {
            for i in 0..m.nrows() {
                v = v.max(m[(i, j)].abs());
            }
        }
        v
    }

    #[test]
    fn eigh_reconstructs_and_orders() {
        let a = spd(30, 1);
        let e = eigh(a.as_ref()).unwrap();
        assert!(e.values.windows(2).all(|w| w[0] <= w[1]));
        let d = Mat::from_fn(30, 30, |i, j| if i == j { e.values[i] } else { 0.0 });
        let rec = &e.vectors * &d * e.vectors.transpose();
        assert!(max_abs(&(&rec - &a)) < 1e-10);
        let big = eigh_largest(a.as_ref(), 3).unwrap();
        for (c, v) in big.values.iter().enumerate() {
            assert!((v - e.values[29 - c]).abs() < 1e-12 * e.values[29]);
        }
        // A v = lambda v for the selected pairs.
        let av = &a * &big.vectors;
        for c in 0..3 {
            for r in 0..30 {
                assert!((av[(r, c)] - big.values[c] * big.vectors[(r, c)]).abs() < 1e-9);
            }
        }
        let small = eigh_smallest(a.as_ref(), 2).unwrap();
        for (c, v) in small.values.iter().enumerate() {
            assert!((v - e.values[c]).abs() < 1e-12 * e.values[29]);
        }
        assert!(eigh_largest(a.as_ref(), 31).is_err());
        assert!(eigh_largest(a.as_ref(), 0).is_err());
    }

    #[test]
    fn known_eigenvalues_of_the_1d_laplacian() {
        // tridiag(-1, 2, -1) of size n: lambda_k = 2 - 2 cos(k pi / (n + 1)).
        let n = 12;
        let a = Mat::from_fn(n, n, |i, j| {
            if i == j {
                2.0
            } else if i.abs_diff(j) == 1 {
                -1.0
            } else {
                0.0
            }
        });
        let e = eigh(a.as_ref()).unwrap();
        for (k, v) in e.values.iter().enumerate() {
            let exact = 2.0 - 2.0 * ((k + 1) as f64 * std::f64::consts::PI / (n + 1) as f64).cos();
            assert!((v - exact).abs() < 1e-12);
        }
    }

    #[test]
    fn svd_reconstructs_and_lstsq_matches_normal_equations() {
        let a = random(40, 7, 3);
        let d = svd(a.as_ref()).unwrap();
        assert!(d.s.windows(2).all(|w| w[0] >= w[1]));
        let s = Mat::from_fn(7, 7, |i, j| if i == j { d.s[i] } else { 0.0 });
        assert!(max_abs(&(&d.u * &s * d.v.transpose() - &a)) < 1e-12);
        let b = random(40, 2, 4);
        let x = lstsq(a.as_ref(), b.as_ref(), None).unwrap();
        // Normal equations: A'(Ax - b) = 0.
        let g = a.transpose() * (&a * &x - &b);
        assert!(max_abs(&g) < 1e-10);
        // Rank-deficient: duplicate column gives the minimum-norm solution (equal split).
        let a2 = Mat::from_fn(5, 2, |i, _| (i + 1) as f64);
        let b2 = Mat::from_fn(5, 1, |i, _| 2.0 * (i + 1) as f64);
        let x2 = lstsq(a2.as_ref(), b2.as_ref(), None).unwrap();
        assert!((x2[(0, 0)] - 1.0).abs() < 1e-10 && (x2[(1, 0)] - 1.0).abs() < 1e-10);
        assert!(lstsq(a.as_ref(), random(3, 1, 1).as_ref(), None).is_err());
    }

    #[test]
    fn generalized_eigen_satisfies_the_pencil() {
        let n = 15;
        let a = {
            let g = random(n, n, 5);
            &g + g.transpose()
        };
        let b = spd(n, 6);
        let e = eigh_generalized(a.as_ref(), b.as_ref()).unwrap();
        let av = &a * &e.vectors;
        let bv = &b * &e.vectors;
        for c in 0..n {
            for r in 0..n {
                assert!((av[(r, c)] - e.values[c] * bv[(r, c)]).abs() < 1e-9);
            }
        }
        let vbv = e.vectors.transpose() * &b * &e.vectors;
        assert!(max_abs(&(&vbv - Mat::<f64>::identity(n, n))) < 1e-9);
        // B = I reduces to the standard problem.
        let std = eigh(a.as_ref()).unwrap();
        let gi = eigh_generalized(a.as_ref(), Mat::<f64>::identity(n, n).as_ref()).unwrap();
        for (x, y) in std.values.iter().zip(&gi.values) {
            assert!((x - y).abs() < 1e-10);
        }
    }

    #[test]
    fn bad_matrices_are_rejected() {
        let nonsym = Mat::from_fn(3, 3, |i, j| (i * 3 + j) as f64);
        assert!(eigh(nonsym.as_ref()).is_err());
        let rect = Mat::<f64>::zeros(2, 3);
        assert!(matches!(eigh(rect.as_ref()), Err(Error::ShapeMismatch(_))));
        let mut nan = spd(3, 1);
        nan[(1, 1)] = f64::NAN;
        assert!(matches!(eigh(nan.as_ref()), Err(Error::NonFinite { .. })));
        assert!(matches!(
            svd(Mat::<f64>::zeros(0, 3).as_ref()),
            Err(Error::Empty(_))
        ));
        let indefinite = Mat::from_fn(2, 2, |i, j| if i == j { -1.0 } else { 0.0 });
        assert!(eigh_generalized(spd(2, 1).as_ref(), indefinite.as_ref()).is_err());
        assert!(eigh_generalized(spd(2, 1).as_ref(), spd(3, 1).as_ref()).is_err());
    }
}
