//! Sparse matrices (CSR, stored in faer's `SparseRowMat`) and a preconditioned conjugate
//! gradient written against small operator traits.
//!
//! [`pcg`] solves `A x = b` for a symmetric positive definite operator `A` given as any
//! [`LinOp`] (a [`CsrMatrix`], or a matrix-free operator of a paper crate), with a
//! [`Preconditioner`] ([`Jacobi`] or [`IdentityPrecond`]), a typed [`InitialGuess`] and a
//! relative-residual tolerance. It reports the iterations used and the final relative
//! residual `||b - A x|| / ||b||`; not converging within `max_iter` is reported in the
//! result (`converged == false`), not as an error, as `scipy.sparse.linalg.cg` does.
//! Vector operations and the CSR product run in parallel with rayon.

use faer::sparse::{SparseRowMat, SymbolicSparseRowMat, Triplet};
use faer::Mat;
use rayon::prelude::*;

use crate::error::{ensure_finite, ensure_positive, Error, Result};

/// Minimum vector length per rayon task in the vector kernels.
const MIN_LEN: usize = 1 << 13;

/// A linear operator `y = A x` of size `nrows x ncols`.
pub trait LinOp: Sync {
    /// Number of rows (length of `y`).
    fn nrows(&self) -> usize;
    /// Number of columns (length of `x`).
    fn ncols(&self) -> usize;
    /// Computes `y = A x`; `x.len() == ncols()`, `y.len() == nrows()`.
    fn apply(&self, x: &[f64], y: &mut [f64]);
}

/// A preconditioner `z = M^-1 r` for [`pcg`]; must be symmetric positive definite.
pub trait Preconditioner: Sync {
    /// Computes `z = M^-1 r`.
    fn apply(&self, r: &[f64], z: &mut [f64]);
}

/// No preconditioning (`M = I`).
#[derive(Clone, Copy, Debug, Default)]
pub struct IdentityPrecond;

impl Preconditioner for IdentityPrecond {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        z.copy_from_slice(r);
    }
}

/// Jacobi (diagonal) preconditioner `M = diag(A)`.
#[derive(Clone, Debug)]
pub struct Jacobi {
    inv_diag: Vec<f64>,
}

impl Jacobi {
    /// Builds from the diagonal of `A`. Errors if an entry is not finite and > 0 (an SPD
    /// matrix has a positive diagonal).
    pub fn new(diagonal: &[f64]) -> Result<Self> {
        if let Some(i) = diagonal.iter().position(|&d| !(d.is_finite() && d > 0.0)) {
            return Err(Error::invalid(
                "diagonal",
                format!(
                    "Jacobi needs a positive diagonal; entry {i} is {}",
                    diagonal[i]
                ),
            ));
        }
        Ok(Self {
            inv_diag: diagonal.iter().map(|d| 1.0 / d).collect(),
        })
    }
}

impl Preconditioner for Jacobi {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        z.par_iter_mut()
            .with_min_len(MIN_LEN)
            .zip(r.par_iter().zip(&self.inv_diag))
            .for_each(|(z, (r, d))| *z = r * d);
    }
}

/// A sparse matrix in compressed sparse row form (faer storage, `usize` indices, f64 values).
#[derive(Clone, Debug)]
pub struct CsrMatrix {
    inner: SparseRowMat<usize, f64>,
}

impl CsrMatrix {
    /// Builds from `(row, col, value)` triplets; duplicate entries are summed.
    ///
    /// Errors: an index out of range, a non-finite value.
    pub fn from_triplets(
        nrows: usize,
        ncols: usize,
        triplets: &[(usize, usize, f64)],
    ) -> Result<Self> {
        for (k, &(i, j, v)) in triplets.iter().enumerate() {
            if i >= nrows || j >= ncols {
                return Err(Error::invalid(
                    "triplets",
                    format!("entry {k} at ({i}, {j}) is outside a {nrows}x{ncols} matrix"),
                ));
            }
            if !v.is_finite() {
                return Err(Error::NonFinite {
                    name: "triplets",
                    index: k,
                });
            }
        }
        let t: Vec<Triplet<usize, usize, f64>> = triplets
            .iter()
            .map(|&(i, j, v)| Triplet::new(i, j, v))
            .collect();
        let inner = SparseRowMat::try_new_from_triplets(nrows, ncols, &t)
            .map_err(|e| Error::invalid("triplets", format!("{e:?}")))?;
        Ok(Self { inner })
    }

    /// Builds from scipy-style CSR arrays (`indptr` of length `nrows + 1`, `indices` and
    /// `data` of length `nnz`); unsorted and duplicate column indices are accepted (summed).
    ///
    /// Errors: inconsistent lengths, decreasing `indptr`, indices out of range, non-finite data.
    pub fn from_csr_arrays(
        nrows: usize,
        ncols: usize,
        indptr: &[usize],
        indices: &[usize],
        data: &[f64],
    ) -> Result<Self> {
        if indptr.len() != nrows + 1 {
            return Err(Error::ShapeMismatch(format!(
                "indptr has length {}, expected nrows + 1 = {}",
                indptr.len(),
                nrows + 1
            )));
        }
        if indices.len() != data.len() || indptr[nrows] != data.len() || indptr[0] != 0 {
            return Err(Error::ShapeMismatch(format!(
                "indptr[0] = {}, indptr[-1] = {}, {} indices and {} values do not agree",
                indptr[0],
                indptr[nrows],
                indices.len(),
                data.len()
            )));
        }
        if indptr.windows(2).any(|w| w[1] < w[0]) {
            return Err(Error::invalid("indptr", "must be non-decreasing"));
        }
        if let Some(k) = indices.iter().position(|&j| j >= ncols) {
            return Err(Error::invalid(
                "indices",
                format!(
                    "entry {k} is column {} of a matrix with {ncols} columns",
                    indices[k]
                ),
            ));
        }
        ensure_finite("data", data)?;
        let canonical = (0..nrows).all(|i| {
            indices[indptr[i]..indptr[i + 1]]
                .windows(2)
                .all(|w| w[0] < w[1])
        });
        if canonical {
            // Sorted, duplicate-free rows (scipy's canonical format): adopt the arrays as
            // they are; the checks above are exactly faer's invariants.
            let symbolic = SymbolicSparseRowMat::new_checked(
                nrows,
                ncols,
                indptr.to_vec(),
                None,
                indices.to_vec(),
            );
            return Ok(Self {
                inner: SparseRowMat::new(symbolic, data.to_vec()),
            });
        }
        let mut t = Vec::with_capacity(data.len());
        for i in 0..nrows {
            for k in indptr[i]..indptr[i + 1] {
                t.push((i, indices[k], data[k]));
            }
        }
        Self::from_triplets(nrows, ncols, &t)
    }

    /// The 7-point finite-difference Laplacian `-Δ` of an `nx x ny x nz` grid with unit
    /// spacing and zero Dirichlet boundary (diagonal 6, neighbours -1), unknowns ordered with
    /// x fastest. Symmetric positive definite; a standard test and benchmark problem.
    pub fn laplacian_3d(nx: usize, ny: usize, nz: usize) -> Result<Self> {
        if nx == 0 || ny == 0 || nz == 0 {
            return Err(Error::Empty("grid (nx, ny, nz must be > 0)"));
        }
        let what = "nx, ny, nz";
        let n = crate::alloc::elements(what, &[nx, ny, nz])?;
        let idx = |x: usize, y: usize, z: usize| x + nx * (y + ny * z);
        let mut t = crate::alloc::try_with_capacity(what, crate::alloc::elements(what, &[n, 7])?)?;
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let i = idx(x, y, z);
                    t.push((i, i, 6.0));
                    if x > 0 {
                        t.push((i, idx(x - 1, y, z), -1.0));
                    }
                    if x + 1 < nx {
                        t.push((i, idx(x + 1, y, z), -1.0));
                    }
                    if y > 0 {
                        t.push((i, idx(x, y - 1, z), -1.0));
                    }
                    if y + 1 < ny {
                        t.push((i, idx(x, y + 1, z), -1.0));
                    }
                    if z > 0 {
                        t.push((i, idx(x, y, z - 1), -1.0));
                    }
                    if z + 1 < nz {
                        t.push((i, idx(x, y, z + 1), -1.0));
                    }
                }
            }
        }
        Self::from_triplets(n, n, &t)
    }

    /// Number of rows.
    pub fn nrows(&self) -> usize {
        self.inner.nrows()
    }
    /// Number of columns.
    pub fn ncols(&self) -> usize {
        self.inner.ncols()
    }
    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.inner.val().len()
    }
    /// Row pointers (length `nrows + 1`).
    pub fn indptr(&self) -> &[usize] {
        self.inner.symbolic().row_ptr()
    }
    /// Column indices, sorted within each row.
    pub fn indices(&self) -> &[usize] {
        self.inner.symbolic().col_idx()
    }
    /// Stored values.
    pub fn values(&self) -> &[f64] {
        self.inner.val()
    }
    /// The faer matrix, for faer's sparse factorizations.
    pub fn as_faer(&self) -> &SparseRowMat<usize, f64> {
        &self.inner
    }
    /// The diagonal (zeros where no entry is stored).
    pub fn diagonal(&self) -> Vec<f64> {
        let (p, c, v) = (self.indptr(), self.indices(), self.values());
        (0..self.nrows().min(self.ncols()))
            .map(|i| (p[i]..p[i + 1]).filter(|&k| c[k] == i).map(|k| v[k]).sum())
            .collect()
    }
    /// Dense copy (for tests and small problems).
    pub fn to_dense(&self) -> Mat<f64> {
        let mut m = Mat::zeros(self.nrows(), self.ncols());
        let (p, c, v) = (self.indptr(), self.indices(), self.values());
        for i in 0..self.nrows() {
            for k in p[i]..p[i + 1] {
                m[(i, c[k])] += v[k];
            }
        }
        m
    }
    /// Solves `A x = b` for a symmetric positive definite `A` by sparse Cholesky
    /// factorisation (faer's supernodal/simplicial `L L'` with a fill-reducing ordering).
    ///
    /// Errors: a non-square matrix, `b` of the wrong length or non-finite, a matrix that is
    /// not numerically positive definite.
    pub fn cholesky_solve(&self, b: &[f64]) -> Result<Vec<f64>> {
        use faer::linalg::solvers::Solve;
        if self.nrows() != self.ncols() || b.len() != self.nrows() {
            return Err(Error::ShapeMismatch(format!(
                "Cholesky solve of a {}x{} matrix with a right-hand side of length {}",
                self.nrows(),
                self.ncols(),
                b.len()
            )));
        }
        ensure_finite("b", b)?;
        let llt = self
            .inner
            .sp_cholesky(faer::Side::Lower)
            .map_err(|e| Error::Numerical(format!("sparse Cholesky failed: {e:?}")))?;
        let mut x = Mat::from_fn(b.len(), 1, |i, _| b[i]);
        llt.solve_in_place(x.as_mut());
        Ok((0..b.len()).map(|i| x[(i, 0)]).collect())
    }

    /// `y = A x` as a new vector. Errors when `x.len() != ncols`.
    pub fn mul_vec(&self, x: &[f64]) -> Result<Vec<f64>> {
        if x.len() != self.ncols() {
            return Err(Error::ShapeMismatch(format!(
                "x has length {}, matrix has {} columns",
                x.len(),
                self.ncols()
            )));
        }
        let mut y = vec![0.0; self.nrows()];
        self.apply(x, &mut y);
        Ok(y)
    }
}

impl LinOp for CsrMatrix {
    fn nrows(&self) -> usize {
        self.inner.nrows()
    }
    fn ncols(&self) -> usize {
        self.inner.ncols()
    }
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        let (p, c, v) = (self.indptr(), self.indices(), self.values());
        y.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(i, yi)| {
                *yi = (p[i]..p[i + 1]).map(|k| v[k] * x[c[k]]).sum();
            });
    }
}

/// Starting point of an iterative solve.
#[derive(Clone, Copy, Debug, Default)]
pub enum InitialGuess<'a> {
    /// Start from `x = 0`.
    #[default]
    Zero,
    /// Start from the given vector (warm start).
    Given(&'a [f64]),
}

crate::params! {
    /// Stopping rules of [`pcg`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct PcgParams {
        /// Stop when `||b - A x|| <= tol * ||b||` (default 1e-8).
        pub tol: f64,
        /// Maximum number of iterations (default: `None`, meaning `10 * n`).
        pub max_iter: Option<usize>,
    }
}

impl Default for PcgParams {
    fn default() -> Self {
        Self {
            tol: 1e-8,
            max_iter: None,
        }
    }
}

impl PcgParams {
    /// Checks the ranges: `tol` finite and > 0 (`max_iter` may be any count; `Some(0)`
    /// returns the starting vector).
    pub fn validate(&self) -> Result<()> {
        ensure_positive("tol", self.tol)
    }
}

/// Outcome of [`pcg`].
#[derive(Clone, Debug)]
pub struct PcgResult {
    /// The solution estimate.
    pub x: Vec<f64>,
    /// Iterations performed.
    pub iterations: usize,
    /// Final `||b - A x|| / ||b||` (0 when `b = 0`).
    pub relative_residual: f64,
    /// Whether the tolerance was met.
    pub converged: bool,
}

/// Sums per-chunk partial results in chunk order: the total does not depend on the number
/// of threads (rayon's adaptive splitting would change the rounding).
fn ordered_sum(partials: Vec<f64>) -> f64 {
    partials.iter().sum()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    ordered_sum(
        a.par_chunks(MIN_LEN)
            .zip(b.par_chunks(MIN_LEN))
            .map(|(x, y)| x.iter().zip(y).map(|(p, q)| p * q).sum())
            .collect(),
    )
}

/// Checks a Krylov solver's inputs; returns the size, the starting vector and the
/// iteration cap.
fn krylov_setup(
    solver: &str,
    a: &dyn LinOp,
    b: &[f64],
    guess: InitialGuess<'_>,
    opts: &PcgParams,
) -> Result<(usize, Vec<f64>, usize)> {
    opts.validate()?;
    let n = a.nrows();
    if a.ncols() != n {
        return Err(Error::ShapeMismatch(format!(
            "{solver} needs a square operator, got {}x{}",
            n,
            a.ncols()
        )));
    }
    if b.len() != n {
        return Err(Error::ShapeMismatch(format!(
            "b has length {}, operator has {n} rows",
            b.len()
        )));
    }
    ensure_finite("b", b)?;
    let max_iter = opts.max_iter.unwrap_or(10 * n.max(1));
    let x = match guess {
        InitialGuess::Zero => vec![0.0; n],
        InitialGuess::Given(x0) => {
            if x0.len() != n {
                return Err(Error::ShapeMismatch(format!(
                    "initial guess has length {}, expected {n}",
                    x0.len()
                )));
            }
            ensure_finite("x0", x0)?;
            x0.to_vec()
        }
    };
    Ok((n, x, max_iter))
}

/// Preconditioned conjugate gradient for symmetric positive definite `a`
/// (Hestenes and Stiefel 1952; Saad, "Iterative Methods for Sparse Linear Systems", alg. 9.1).
///
/// Errors: non-square operator, lengths that do not match, non-finite `b` or guess, bad
/// options, and [`Error::Numerical`] when a search direction has `p' A p <= 0` (the
/// operator or preconditioner is not positive definite).
pub fn pcg(
    a: &dyn LinOp,
    b: &[f64],
    guess: InitialGuess<'_>,
    precond: &dyn Preconditioner,
    opts: &PcgParams,
) -> Result<PcgResult> {
    solve_scaled(
        b,
        guess,
        |b, guess| pcg_in_range(a, b, guess, precond, opts),
        |r, s| r.x.iter_mut().for_each(|v| *v *= s),
    )
}

/// The factor that brings `b`'s largest entry to 1 when squaring the entries could overflow
/// or underflow (largest magnitude beyond 1e±150), else None.
fn rhs_scale(b: &[f64]) -> Option<f64> {
    let m = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (m > 0.0 && m.is_finite() && !(1e-150..=1e150).contains(&m)).then_some(m)
}

/// Runs a Krylov solve on `A x = b / s` with the guess divided by `s` and multiplies the
/// solution (and any absolute residual) by `s` through `rescale`, where `s` is [`rhs_scale`]: the iterates' dot products stay in range for
/// any finite `b` (without it a right-hand side of 1e300 overflows `b'b` and the solver
/// reports `x = 0` as converged). The relative residual does not change with `s`.
fn solve_scaled<T>(
    b: &[f64],
    guess: InitialGuess<'_>,
    solve: impl FnOnce(&[f64], InitialGuess<'_>) -> Result<T>,
    rescale: impl FnOnce(&mut T, f64),
) -> Result<T> {
    let Some(s) = rhs_scale(b) else {
        return solve(b, guess);
    };
    let scaled: Vec<f64> = b.iter().map(|v| v / s).collect();
    let start: Vec<f64>;
    let guess = match guess {
        InitialGuess::Zero => InitialGuess::Zero,
        InitialGuess::Given(x0) => {
            start = x0.iter().map(|v| v / s).collect();
            InitialGuess::Given(&start)
        }
    };
    let mut out = solve(&scaled, guess)?;
    rescale(&mut out, s);
    Ok(out)
}

/// [`pcg`] for a right-hand side whose squared norm does not overflow.
fn pcg_in_range(
    a: &dyn LinOp,
    b: &[f64],
    guess: InitialGuess<'_>,
    precond: &dyn Preconditioner,
    opts: &PcgParams,
) -> Result<PcgResult> {
    let (n, mut x, max_iter) = krylov_setup("conjugate gradient", a, b, guess, opts)?;
    let bnorm = dot(b, b).sqrt();
    if bnorm == 0.0 {
        return Ok(PcgResult {
            x: vec![0.0; n],
            iterations: 0,
            relative_residual: 0.0,
            converged: true,
        });
    }
    let mut r = vec![0.0; n];
    a.apply(&x, &mut r);
    r.par_iter_mut()
        .with_min_len(MIN_LEN)
        .zip(b)
        .for_each(|(r, b)| *r = b - *r);
    let mut z = vec![0.0; n];
    precond.apply(&r, &mut z);
    let mut p = z.clone();
    let mut ap = vec![0.0; n];
    let mut rz = dot(&r, &z);
    let mut rnorm = dot(&r, &r).sqrt();
    let target = opts.tol * bnorm;
    let mut it = 0;
    while rnorm > target && it < max_iter {
        crate::cancel::check()?;
        a.apply(&p, &mut ap);
        let pap = dot(&p, &ap);
        if pap.is_nan() || pap <= 0.0 || pap.is_infinite() {
            return Err(Error::Numerical(format!(
                "conjugate gradient broke down at iteration {it}: p'Ap = {pap:e}; the operator \
                 must be symmetric positive definite"
            )));
        }
        let alpha = rz / pap;
        // x += alpha p and r -= alpha A p, accumulating |r|^2 in the same pass.
        let rr = ordered_sum(
            x.par_chunks_mut(MIN_LEN)
                .zip(r.par_chunks_mut(MIN_LEN))
                .zip(p.par_chunks(MIN_LEN).zip(ap.par_chunks(MIN_LEN)))
                .map(|((x, r), (p, ap))| {
                    let mut acc = 0.0;
                    for i in 0..x.len() {
                        x[i] += alpha * p[i];
                        r[i] -= alpha * ap[i];
                        acc += r[i] * r[i];
                    }
                    acc
                })
                .collect(),
        );
        rnorm = rr.sqrt();
        if rnorm <= target {
            it += 1;
            break;
        }
        precond.apply(&r, &mut z);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        p.par_iter_mut()
            .with_min_len(MIN_LEN)
            .zip(&z)
            .for_each(|(p, z)| *p = z + beta * *p);
        it += 1;
    }
    log_solve("conjugate gradients", it, rnorm / bnorm, rnorm <= target);
    Ok(PcgResult {
        x,
        iterations: it,
        relative_residual: rnorm / bnorm,
        converged: rnorm <= target,
    })
}

/// Result of [`conjugate_residual`].
#[derive(Clone, Debug)]
pub struct ConjugateResidualResult {
    /// The solution estimate.
    pub x: Vec<f64>,
    /// Iterations performed.
    pub iterations: usize,
    /// `||b - A x||` after each iteration, starting with the initial residual.
    pub residuals: Vec<f64>,
    /// Whether `||b - A x|| <= tol ||b||` was met.
    pub converged: bool,
}

/// Conjugate residuals for a symmetric (possibly indefinite) operator (Saad, "Iterative
/// Methods for Sparse Linear Systems", alg. 6.20): minimises `||b - A x||` over the Krylov
/// space, so the residual norm never increases.
///
/// Errors: as [`pcg`]; [`Error::Numerical`] when `A p = 0` for a search direction.
pub fn conjugate_residual(
    a: &dyn LinOp,
    b: &[f64],
    guess: InitialGuess<'_>,
    opts: &PcgParams,
) -> Result<ConjugateResidualResult> {
    solve_scaled(
        b,
        guess,
        |b, guess| conjugate_residual_in_range(a, b, guess, opts),
        |r, s| {
            r.x.iter_mut().for_each(|v| *v *= s);
            r.residuals.iter_mut().for_each(|v| *v *= s);
        },
    )
}

/// [`conjugate_residual`] for a right-hand side whose squared norm does not overflow.
fn conjugate_residual_in_range(
    a: &dyn LinOp,
    b: &[f64],
    guess: InitialGuess<'_>,
    opts: &PcgParams,
) -> Result<ConjugateResidualResult> {
    let (n, mut x, max_iter) = krylov_setup("conjugate residual", a, b, guess, opts)?;
    let mut r = vec![0.0; n];
    a.apply(&x, &mut r);
    r.iter_mut().zip(b).for_each(|(r, b)| *r = b - *r);
    let bnorm = dot(b, b).sqrt();
    let target = opts.tol * bnorm;
    let mut rnorm = dot(&r, &r).sqrt();
    let mut residuals = vec![rnorm];
    let mut p = r.clone();
    let mut ar = vec![0.0; n];
    a.apply(&r, &mut ar);
    let mut ap = ar.clone();
    let mut rar = dot(&r, &ar);
    let mut it = 0;
    while rnorm > target && it < max_iter {
        crate::cancel::check()?;
        let apap = dot(&ap, &ap);
        if !(apap > 0.0 && apap.is_finite()) {
            return Err(Error::Numerical(format!(
                "conjugate residual broke down at iteration {it}: |A p|^2 = {apap:e}"
            )));
        }
        let alpha = rar / apap;
        for i in 0..n {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
        }
        rnorm = dot(&r, &r).sqrt();
        residuals.push(rnorm);
        it += 1;
        if rnorm <= target {
            break;
        }
        a.apply(&r, &mut ar);
        let rar_new = dot(&r, &ar);
        let beta = rar_new / rar;
        rar = rar_new;
        for i in 0..n {
            p[i] = r[i] + beta * p[i];
            ap[i] = ar[i] + beta * ap[i];
        }
    }
    log_solve(
        "conjugate residual",
        it,
        rnorm / bnorm.max(f64::MIN_POSITIVE),
        rnorm <= target,
    );
    Ok(ConjugateResidualResult {
        x,
        iterations: it,
        converged: rnorm <= target,
        residuals,
    })
}

/// One debug record per Krylov solve: its iterations and relative residual. Not a warning
/// when it stops at the cap: inexact inner solves (a Newton step, a warm-started sweep) stop
/// there by design, and the result says so in `converged`; the methods that need
/// convergence warn themselves.
fn log_solve(method: &str, iterations: usize, relative_residual: f64, converged: bool) {
    let outcome = if converged {
        "converged"
    } else {
        "stopped at the iteration cap"
    };
    log::debug!(
        "{method}: {outcome} after {iterations} iterations, relative residual \
         {relative_residual:.3e}"
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::solvers::Solve;
    use faer::Side;
    use rand::Rng;

    #[test]
    fn conjugate_residual_is_monotone_and_agrees_with_cg() {
        let a = random_spd(300, 9);
        let b: Vec<f64> = (0..300).map(|i| ((i * 7) % 13) as f64 - 6.0).collect();
        let opts = PcgParams {
            tol: 1e-12,
            max_iter: None,
        };
        let cr = conjugate_residual(&a, &b, InitialGuess::Zero, &opts).unwrap();
        assert!(cr.converged);
        assert!(cr
            .residuals
            .windows(2)
            .all(|w| w[1] <= w[0] * (1.0 + 1e-12)));
        let cg = pcg(&a, &b, InitialGuess::Zero, &IdentityPrecond, &opts).unwrap();
        let diff =
            cr.x.iter()
                .zip(&cg.x)
                .map(|(p, q)| (p - q).abs())
                .fold(0.0, f64::max);
        assert!(diff < 1e-8, "{diff}");
        assert!(conjugate_residual(&a, &b[..10], InitialGuess::Zero, &opts).is_err());
    }

    /// A random sparse SPD matrix: B'B-like pattern plus a scaled diagonal.
    fn random_spd(n: usize, seed: u64) -> CsrMatrix {
        let mut r = crate::rng::seeded(seed);
        let mut t = Vec::new();
        for i in 0..n {
            let mut off = 0.0;
            for _ in 0..4 {
                let j = r.random_range(0..n);
                if j != i {
                    let v: f64 = r.random_range(-1.0..1.0);
                    t.push((i, j, v));
                    t.push((j, i, v));
                    off += v.abs();
                }
            }
            // Diagonal dominance (checked per row below through the sum) with varied scale.
            t.push((i, i, 10.0 + off + r.random_range(0.0..1000.0)));
        }
        // Make strict dominance hold for the symmetrised rows.
        let m = CsrMatrix::from_triplets(n, n, &t).unwrap();
        let d = m.to_dense();
        let mut t2 = t.clone();
        for i in 0..n {
            let row: f64 = (0..n).filter(|&j| j != i).map(|j| d[(i, j)].abs()).sum();
            t2.push((i, i, row));
        }
        CsrMatrix::from_triplets(n, n, &t2).unwrap()
    }

    #[test]
    fn pcg_matches_a_dense_cholesky_solve() {
        let n = 200;
        let a = random_spd(n, 1);
        let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        let dense = a.to_dense();
        let llt = dense.llt(Side::Lower).unwrap();
        let bm = Mat::from_fn(n, 1, |i, _| b[i]);
        let xd = llt.solve(&bm);
        let res = pcg(
            &a,
            &b,
            InitialGuess::Zero,
            &Jacobi::new(&a.diagonal()).unwrap(),
            &PcgParams {
                tol: 1e-12,
                max_iter: None,
            },
        )
        .unwrap();
        assert!(res.converged);
        let err = (0..n)
            .map(|i| (res.x[i] - xd[(i, 0)]).abs())
            .fold(0.0, f64::max);
        let scale = (0..n).map(|i| xd[(i, 0)].abs()).fold(0.0, f64::max);
        assert!(err < 1e-9 * scale, "max error {err}");
        // Residual reported matches the true residual.
        let ax = a.mul_vec(&res.x).unwrap();
        let true_res = ax
            .iter()
            .zip(&b)
            .map(|(p, q)| (p - q).powi(2))
            .sum::<f64>()
            .sqrt()
            / b.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((true_res - res.relative_residual).abs() < 1e-10);
    }

    #[test]
    fn jacobi_helps_on_badly_scaled_systems_and_warm_start_is_free() {
        let n = 300;
        let a = random_spd(n, 2);
        let b = vec![1.0; n];
        let opts = PcgParams {
            tol: 1e-10,
            max_iter: Some(5000),
        };
        let plain = pcg(&a, &b, InitialGuess::Zero, &IdentityPrecond, &opts).unwrap();
        let jac = pcg(
            &a,
            &b,
            InitialGuess::Zero,
            &Jacobi::new(&a.diagonal()).unwrap(),
            &opts,
        )
        .unwrap();
        assert!(plain.converged && jac.converged);
        assert!(
            jac.iterations < plain.iterations,
            "{} vs {}",
            jac.iterations,
            plain.iterations
        );
        let warm = pcg(&a, &b, InitialGuess::Given(&jac.x), &IdentityPrecond, &opts).unwrap();
        assert_eq!(warm.iterations, 0);
    }

    #[test]
    fn result_is_identical_for_any_thread_count() {
        let a = CsrMatrix::laplacian_3d(30, 30, 30).unwrap();
        let b: Vec<f64> = (0..a.nrows())
            .map(|i| ((i * 13) % 17) as f64 - 8.0)
            .collect();
        let opts = PcgParams {
            tol: 1e-9,
            max_iter: None,
        };
        let jac = Jacobi::new(&a.diagonal()).unwrap();
        let many = pcg(&a, &b, InitialGuess::Zero, &jac, &opts).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let one = pool.install(|| pcg(&a, &b, InitialGuess::Zero, &jac, &opts).unwrap());
        assert_eq!(many.x, one.x);
        assert_eq!(many.iterations, one.iterations);
    }

    #[test]
    fn cholesky_solves_a_manufactured_problem_and_rejects_indefinite() {
        let a = CsrMatrix::laplacian_3d(9, 8, 7).unwrap();
        let xs: Vec<f64> = (0..a.nrows()).map(|i| ((i % 5) as f64).cos()).collect();
        let b = a.mul_vec(&xs).unwrap();
        let x = a.cholesky_solve(&b).unwrap();
        let err = x
            .iter()
            .zip(&xs)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-11, "{err}");
        let indefinite = CsrMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, -1.0)]).unwrap();
        assert!(indefinite.cholesky_solve(&[1.0, 1.0]).is_err());
        assert!(a.cholesky_solve(&[1.0]).is_err());
    }

    #[test]
    fn laplacian_3d_solves_a_manufactured_problem() {
        let (nx, ny, nz) = (12, 10, 8);
        let a = CsrMatrix::laplacian_3d(nx, ny, nz).unwrap();
        assert_eq!(
            a.nnz(),
            7 * nx * ny * nz - 2 * (ny * nz + nx * nz + nx * ny)
        );
        let xs: Vec<f64> = (0..a.nrows()).map(|i| ((i % 7) as f64).sin()).collect();
        let b = a.mul_vec(&xs).unwrap();
        let res = pcg(
            &a,
            &b,
            InitialGuess::Zero,
            &IdentityPrecond,
            &PcgParams {
                tol: 1e-11,
                max_iter: None,
            },
        )
        .unwrap();
        let err = res
            .x
            .iter()
            .zip(&xs)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-8, "{err}");
        // CG on an n-dimensional SPD system converges in at most n steps in exact arithmetic;
        // for this well-conditioned grid it needs far fewer.
        assert!(res.iterations < 100);
    }

    #[test]
    fn duplicates_are_summed_and_csr_arrays_are_validated() {
        let m = CsrMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (0, 0, 2.0), (1, 0, 4.0)]).unwrap();
        assert_eq!(m.nnz(), 2);
        assert_eq!(m.to_dense()[(0, 0)], 3.0);
        let c = CsrMatrix::from_csr_arrays(2, 3, &[0, 2, 3], &[2, 0, 1], &[1.0, 2.0, 3.0]).unwrap();
        assert_eq!(c.mul_vec(&[1.0, 10.0, 100.0]).unwrap(), vec![102.0, 30.0]);
        assert!(CsrMatrix::from_csr_arrays(2, 3, &[0, 2], &[0], &[1.0]).is_err());
        assert!(CsrMatrix::from_csr_arrays(2, 3, &[0, 2, 1], &[0, 1], &[1.0, 1.0]).is_err());
        assert!(CsrMatrix::from_triplets(2, 2, &[(2, 0, 1.0)]).is_err());
        // Canonical arrays (sorted, unique) take the direct path and give the same matrix.
        let l = CsrMatrix::laplacian_3d(3, 4, 2).unwrap();
        let c = CsrMatrix::from_csr_arrays(24, 24, l.indptr(), l.indices(), l.values()).unwrap();
        assert_eq!(
            (c.indptr(), c.indices(), c.values()),
            (l.indptr(), l.indices(), l.values())
        );
        assert!(CsrMatrix::from_csr_arrays(2, 2, &[0, 1, 2], &[0, 2], &[1.0, 1.0]).is_err());
        assert!(CsrMatrix::from_csr_arrays(2, 2, &[0, 1, 2], &[0, 1], &[1.0, f64::NAN]).is_err());
        assert!(CsrMatrix::from_triplets(2, 2, &[(0, 0, f64::NAN)]).is_err());
    }

    #[test]
    fn right_hand_sides_near_the_float_range_solve_like_their_scaled_copies() {
        // b'b overflows for b ~ 1e300 and underflows for b ~ 1e-300; the solution is linear
        // in b, so x(b s) = s x(b) must hold at both ends.
        let a = CsrMatrix::laplacian_3d(6, 5, 4).unwrap();
        let n = a.nrows();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
        let opts = PcgParams::default().tol(1e-10);
        let unit = pcg(&a, &b, InitialGuess::Zero, &IdentityPrecond, &opts).unwrap();
        for s in [1e300, 1e-300] {
            let big: Vec<f64> = b.iter().map(|v| v * s).collect();
            let guess: Vec<f64> = unit.x.iter().map(|v| 0.5 * v * s).collect();
            for g in [InitialGuess::Zero, InitialGuess::Given(&guess)] {
                let r = pcg(&a, &big, g, &IdentityPrecond, &opts).unwrap();
                assert!(r.converged && r.relative_residual.is_finite(), "{s}: {r:?}");
                for (x, u) in r.x.iter().zip(&unit.x) {
                    assert!(
                        (x / s - u).abs() <= 1e-8 * u.abs().max(1.0),
                        "{s}: {x} vs {u}"
                    );
                }
            }
            let cr = conjugate_residual(&a, &big, InitialGuess::Zero, &opts).unwrap();
            assert!(cr.converged, "{s}");
            assert!(
                (cr.residuals[0] / s - b.iter().map(|v| v * v).sum::<f64>().sqrt()).abs()
                    <= 1e-9 * b.iter().map(|v| v * v).sum::<f64>().sqrt()
            );
            for (x, u) in cr.x.iter().zip(&unit.x) {
                assert!(
                    (x / s - u).abs() <= 1e-7 * u.abs().max(1.0),
                    "{s}: {x} vs {u}"
                );
            }
        }
    }

    #[test]
    fn bad_systems_are_rejected() {
        let a = CsrMatrix::from_triplets(2, 2, &[(0, 0, 1.0), (1, 1, -1.0)]).unwrap();
        let e = pcg(
            &a,
            &[0.0, 1.0],
            InitialGuess::Zero,
            &IdentityPrecond,
            &PcgParams::default(),
        );
        assert!(matches!(e, Err(Error::Numerical(_))));
        assert!(Jacobi::new(&a.diagonal()).is_err());
        let r = CsrMatrix::from_triplets(2, 3, &[(0, 0, 1.0)]).unwrap();
        assert!(pcg(
            &r,
            &[1.0, 1.0],
            InitialGuess::Zero,
            &IdentityPrecond,
            &PcgParams::default()
        )
        .is_err());
        let ok = CsrMatrix::laplacian_3d(2, 2, 2).unwrap();
        assert!(pcg(
            &ok,
            &[1.0; 7],
            InitialGuess::Zero,
            &IdentityPrecond,
            &PcgParams::default()
        )
        .is_err());
        assert!(pcg(
            &ok,
            &[f64::NAN; 8],
            InitialGuess::Zero,
            &IdentityPrecond,
            &PcgParams::default()
        )
        .is_err());
        assert!(pcg(
            &ok,
            &[1.0; 8],
            InitialGuess::Given(&[0.0; 3]),
            &IdentityPrecond,
            &PcgParams::default()
        )
        .is_err());
        let bad_tol = PcgParams {
            tol: 0.0,
            max_iter: None,
        };
        assert!(pcg(
            &ok,
            &[1.0; 8],
            InitialGuess::Zero,
            &IdentityPrecond,
            &bad_tol
        )
        .is_err());
        // Too few iterations: reported, not an error.
        let few = PcgParams {
            tol: 1e-14,
            max_iter: Some(1),
        };
        let res = pcg(
            &CsrMatrix::laplacian_3d(5, 5, 5).unwrap(),
            &[1.0; 125],
            InitialGuess::Zero,
            &IdentityPrecond,
            &few,
        )
        .unwrap();
        assert!(!res.converged && res.iterations == 1);
    }
}
