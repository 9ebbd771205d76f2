//! Second-moment statistics of (expanded) data per class, accumulated in one streaming pass
//! after a shift by the global mean (the squared monomials have large means, and
//! `sum z z' - N mu mu'` would cancel catastrophically), and the rank-robust whitening of
//! the total covariance (Konen 2009) used to solve the generalized eigenproblems of SFA.

use faer::{Mat, MatRef};
use rayon::prelude::*;
use wscg_math::{dense, Error, Result};

use super::expansion::{QuadraticExpansion, CHUNK};

/// Per-class sums of shifted expanded rows: `n_c`, `s_c = sum (z - shift)`,
/// `m_c = sum (z - shift)(z - shift)'`.
#[derive(Clone, Debug)]
pub struct ClassMoments {
    /// Distinct labels, ascending.
    pub classes: Vec<u32>,
    /// Rows per class.
    pub counts: Vec<usize>,
    /// The common shift (the global mean of the expanded rows).
    pub shift: Vec<f64>,
    /// Per-class first sums.
    pub sums: Vec<Vec<f64>>,
    /// Per-class second sums.
    pub second: Vec<Mat<f64>>,
    /// First sums over all classes.
    total_sum: Vec<f64>,
    /// Second sums over all classes.
    total_second: Mat<f64>,
}

/// Distinct labels, ascending, and the row indices of each.
pub fn group_labels(y: &[u32]) -> (Vec<u32>, Vec<Vec<usize>>) {
    let mut classes: Vec<u32> = y.to_vec();
    classes.sort_unstable();
    classes.dedup();
    let mut rows = vec![Vec::new(); classes.len()];
    for (i, l) in y.iter().enumerate() {
        let c = classes.binary_search(l).unwrap_or(0);
        rows[c].push(i);
    }
    (classes, rows)
}

/// Expands the rows `idx` of `x` (all when `None`) block by block, calling `f` on each
/// expanded block.
fn blocks(
    x: MatRef<'_, f64>,
    idx: &[usize],
    e: Option<QuadraticExpansion>,
    mut f: impl FnMut(Mat<f64>),
) {
    for part in idx.chunks(CHUNK) {
        let mut sub = Mat::<f64>::zeros(part.len(), x.ncols());
        for j in 0..x.ncols() {
            let (src, dst) = (x.col(j), sub.col_mut(j));
            dst.iter_mut().zip(part).for_each(|(d, &r)| *d = src[r]);
        }
        f(super::expansion::expand_opt(e, sub.as_ref()));
    }
}

/// The mean of `expand(x)` without expanding: the column means of `x` and, for the
/// products, the entries of `x' x / N`, in the order of
/// [`QuadraticExpansion::expand_row`].
fn expanded_mean(x: MatRef<'_, f64>, e: Option<QuadraticExpansion>) -> Vec<f64> {
    let n = x.nrows().max(1) as f64;
    let d = x.ncols();
    let means: Vec<f64> = (0..d).map(|j| x.col(j).iter().sum::<f64>() / n).collect();
    let Some(e) = e else {
        return means;
    };
    let g = wscg_math::dense::gram(x, 1.0);
    let mut out = Vec::with_capacity(e.out_dim(d));
    if e.include_linear {
        out.extend_from_slice(&means);
    }
    for i in 0..d {
        for j in i..d {
            out.push(g[(i, j)] / n);
        }
    }
    out
}

impl ClassMoments {
    /// Accumulates the moments of `expand(x)` per label of `y`, never holding more than
    /// [`CHUNK`] expanded rows.
    pub fn accumulate(x: MatRef<'_, f64>, y: &[u32], e: Option<QuadraticExpansion>) -> Self {
        let (classes, rows) = group_labels(y);
        let dim = e.map_or(x.ncols(), |e| e.out_dim(x.ncols()));
        let shift = expanded_mean(x, e);
        let mut sums = Vec::with_capacity(classes.len());
        let mut second = Vec::with_capacity(classes.len());
        for r in &rows {
            let mut s = vec![0.0; dim];
            let mut m = Mat::<f64>::zeros(dim, dim);
            blocks(x, r, e, |mut z| {
                for j in 0..dim {
                    let mut col_sum = 0.0;
                    for v in z.col_mut(j).iter_mut() {
                        *v -= shift[j];
                        col_sum += *v;
                    }
                    s[j] += col_sum;
                }
                wscg_math::dense::gram_accumulate(&mut m, z.as_ref(), 1.0);
            });
            sums.push(s);
            second.push(m);
        }
        let mut total_sum = vec![0.0; dim];
        let mut total_second = Mat::<f64>::zeros(dim, dim);
        for (sc, mc) in sums.iter().zip(&second) {
            total_sum.iter_mut().zip(sc).for_each(|(a, b)| *a += b);
            total_second += mc;
        }
        Self {
            counts: rows.iter().map(Vec::len).collect(),
            classes,
            shift,
            sums,
            second,
            total_sum,
            total_second,
        }
    }

    /// Dimension of the (expanded) rows.
    pub fn dim(&self) -> usize {
        self.shift.len()
    }

    /// Total row count.
    pub fn total(&self) -> usize {
        self.counts.iter().sum()
    }

    /// The covariance of all rows (`1/N` normalisation).
    pub fn total_covariance(&self) -> Mat<f64> {
        scatter(self.total(), &self.total_sum, &self.total_second)
    }

    /// The mean of class `c` (index into [`Self::classes`]).
    pub fn class_mean(&self, c: usize) -> Vec<f64> {
        let n = self.counts[c] as f64;
        self.shift
            .iter()
            .zip(&self.sums[c])
            .map(|(a, b)| a + b / n)
            .collect()
    }

    /// The within-class scatter `S_c`, the scatter of the other classes `S_not` and the
    /// mean difference `d = mu_c - mu_not` of class `c` (paper 05, eqs. 12-13 in closed
    /// form), with `pi_c = n_c / N`.
    pub fn class_terms(&self, c: usize) -> ClassTerms {
        let (n, s, m) = (self.total(), &self.total_sum, &self.total_second);
        let nc = self.counts[c];
        let nn = n - nc;
        let s_not: Vec<f64> = s.iter().zip(&self.sums[c]).map(|(a, b)| a - b).collect();
        let m_not = m - &self.second[c];
        let d = (0..self.dim())
            .map(|j| self.sums[c][j] / nc as f64 - if nn > 0 { s_not[j] / nn as f64 } else { 0.0 })
            .collect();
        ClassTerms {
            s_c: scatter(nc, &self.sums[c], &self.second[c]),
            s_not: if nn > 0 {
                scatter(nn, &s_not, &m_not)
            } else {
                Mat::zeros(self.dim(), self.dim())
            },
            d,
            pi_c: nc as f64 / n as f64,
        }
    }
}

/// The closed-form pieces of class `c`'s objective.
#[derive(Clone, Debug)]
pub struct ClassTerms {
    /// `S_C = (1/N_C) sum_{n in C} (z_n - mu_C)(z_n - mu_C)'`.
    pub s_c: Mat<f64>,
    /// The same over the complement.
    pub s_not: Mat<f64>,
    /// `mu_C - mu_not`.
    pub d: Vec<f64>,
    /// `N_C / N`.
    pub pi_c: f64,
}

/// `(m - s s' / n) / n`, symmetrized.
fn scatter(n: usize, s: &[f64], m: &Mat<f64>) -> Mat<f64> {
    let nf = n as f64;
    let dim = s.len();
    symmetrized(Mat::from_fn(dim, dim, |i, j| {
        (m[(i, j)] - s[i] * s[j] / nf) / nf
    }))
}

/// `(a + a') / 2`.
pub fn symmetrized(a: Mat<f64>) -> Mat<f64> {
    let n = a.nrows();
    Mat::from_fn(n, n, |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// A whitening `S` (`D x r`) of a covariance `B`: `S' B S = I` on the `r` directions whose
/// eigenvalue exceeds `rank_tol` times the largest; the others (constant pixels, duplicated
/// monomials) are dropped instead of inverted.
#[derive(Clone, Debug)]
pub struct Whitening {
    /// `U_r Lambda_r^{-1/2}`.
    pub s: Mat<f64>,
    /// Directions kept.
    pub rank: usize,
}

impl Whitening {
    /// Errors: a non-finite covariance, or rank 0 (all-constant data).
    pub fn new(b: MatRef<'_, f64>, rank_tol: f64) -> Result<Self> {
        if !(rank_tol.is_finite() && rank_tol >= 0.0) {
            return Err(Error::invalid(
                "rank_tol",
                format!("must be >= 0, got {rank_tol}"),
            ));
        }
        let e = dense::eigh(symmetrized(b.to_owned()).as_ref())?;
        let top = e.values.last().copied().unwrap_or(0.0);
        if top.is_nan() || top <= 0.0 {
            return Err(Error::invalid(
                "x",
                "the (expanded) data have no variance (rank 0): all rows are equal",
            ));
        }
        let keep: Vec<usize> = (0..e.values.len())
            .filter(|&i| e.values[i] > rank_tol * top)
            .collect();
        let dim = b.nrows();
        let s = Mat::from_fn(dim, keep.len(), |i, k| {
            e.vectors[(i, keep[k])] / e.values[keep[k]].sqrt()
        });
        Ok(Self {
            rank: keep.len(),
            s,
        })
    }

    /// `S' A S`, symmetrized.
    pub fn project(&self, a: MatRef<'_, f64>) -> Mat<f64> {
        symmetrized(self.s.transpose() * a * &self.s)
    }

    /// The `k` smallest eigenpairs of `A w = lambda B w` given `S' A S`: eigenvalues
    /// ascending and `W = S V` (`W' B W = I`).
    pub fn smallest(&self, a_white: MatRef<'_, f64>, k: usize) -> Result<(Vec<f64>, Mat<f64>)> {
        if k == 0 || k > self.rank {
            return Err(Error::invalid(
                "m",
                format!(
                    "must be between 1 and the rank {} of the (expanded) data, got {k}",
                    self.rank
                ),
            ));
        }
        let e = dense::eigh_smallest(symmetrized(a_white.to_owned()).as_ref(), k)?;
        Ok((e.values, &self.s * &e.vectors))
    }
}

/// `expand(x) W` (`n x W.ncols()`), blocks of [`CHUNK`] rows expanded and multiplied in
/// parallel, so the expanded rows are never all held at once.
pub(crate) fn project_blocks(
    x: MatRef<'_, f64>,
    e: Option<QuadraticExpansion>,
    w: MatRef<'_, f64>,
) -> Mat<f64> {
    let starts: Vec<usize> = (0..x.nrows()).step_by(CHUNK).collect();
    let parts: Vec<Mat<f64>> = starts
        .par_iter()
        .map(|&s| {
            let len = CHUNK.min(x.nrows() - s);
            super::expansion::expand_opt(e, x.subrows(s, len)) * w
        })
        .collect();
    let mut out = Mat::<f64>::zeros(x.nrows(), w.ncols());
    for (&s, p) in starts.iter().zip(&parts) {
        out.as_mut()
            .submatrix_mut(s, 0, p.nrows(), p.ncols())
            .copy_from(p);
    }
    out
}
