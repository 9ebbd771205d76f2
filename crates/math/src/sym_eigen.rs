//! What the dense eigensolvers share: [`SymEigen`], the input checks and the full symmetric
//! eigendecomposition through faer. [`crate::dense`] re-exports all of it; the partial solvers
//! ([`crate::eigh_partial`], [`crate::eigh_krylov`]) build on it, and `dense` chooses between
//! them, so the three depend on this module and never on each other in a circle.

use faer::{Mat, MatRef, Side};

use crate::error::{Error, Result};

/// Eigenvalues and eigenvectors of a symmetric matrix.
#[derive(Clone, Debug)]
pub struct SymEigen {
    /// Eigenvalues, in the order documented by the function that returned them.
    pub values: Vec<f64>,
    /// Unit eigenvectors as columns, in the same order as `values`.
    pub vectors: Mat<f64>,
}

/// Errors unless `a` is non-empty and finite.
pub fn check_matrix(name: &'static str, a: MatRef<'_, f64>) -> Result<()> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return Err(Error::Empty(name));
    }
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            if !a[(i, j)].is_finite() {
                return Err(Error::NonFinite {
                    name,
                    index: i * a.ncols() + j,
                });
            }
        }
    }
    Ok(())
}

/// Errors unless `a` is square, finite and symmetric to a relative tolerance of 1e-8.
pub fn check_symmetric(name: &'static str, a: MatRef<'_, f64>) -> Result<()> {
    check_matrix(name, a)?;
    let n = a.nrows();
    if a.ncols() != n {
        return Err(Error::ShapeMismatch(format!(
            "`{name}` must be square, got {}x{}",
            n,
            a.ncols()
        )));
    }
    let mut scale = 0.0f64;
    let mut asym = 0.0f64;
    for j in 0..n {
        for i in 0..n {
            scale = scale.max(a[(i, j)].abs());
            asym = asym.max((a[(i, j)] - a[(j, i)]).abs());
        }
    }
    if asym > 1e-8 * scale.max(f64::MIN_POSITIVE) {
        return Err(Error::invalid(
            name,
            format!("must be symmetric; max |A - A'| = {asym:e} (max |A| = {scale:e})"),
        ));
    }
    Ok(())
}

/// All eigenpairs of the symmetric matrix `a`, eigenvalues in non-decreasing order.
pub fn eigh(a: MatRef<'_, f64>) -> Result<SymEigen> {
    crate::faer_par::fix_faer_parallelism();
    check_symmetric("a", a)?;
    let e = a
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| Error::Numerical(format!("symmetric eigendecomposition failed: {e:?}")))?;
    let values = (0..a.nrows()).map(|i| e.S()[i]).collect();
    Ok(SymEigen {
        values,
        vectors: e.U().to_owned(),
    })
}
