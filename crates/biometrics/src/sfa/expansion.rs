//! The quadratic expansion of paper 05, section 3.1: `z = [x_1..x_d, x_i x_j (i <= j)]`.
//!
//! The paper calls the expanded PCA-35 vector "of size 630": the quadratic monomials alone.
//! By default the linear terms are kept as well (`d + d(d+1)/2`, 665 for `d = 35`, the
//! convention of Berkes 2005 and MDP's `QuadraticExpansionNode`); `include_linear = false`
//! gives the paper's literal 630.

use faer::{Mat, MatRef};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Rows expanded per block by the streaming consumers.
pub const CHUNK: usize = 4096;

/// All monomials of degree 1 (optional) and 2 of the input components.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct QuadraticExpansion {
    /// Keep `x_1..x_d` in front of the products.
    pub include_linear: bool,
}

impl Default for QuadraticExpansion {
    fn default() -> Self {
        Self {
            include_linear: true,
        }
    }
}

impl QuadraticExpansion {
    /// Output dimension for input dimension `d`.
    pub fn out_dim(&self, d: usize) -> usize {
        d * (d + 1) / 2 + if self.include_linear { d } else { 0 }
    }

    /// Expands one row into `out` (length [`Self::out_dim`]).
    pub fn expand_row(&self, x: &[f64], out: &mut [f64]) {
        let d = x.len();
        let mut k = 0;
        if self.include_linear {
            out[..d].copy_from_slice(x);
            k = d;
        }
        for i in 0..d {
            for j in i..d {
                out[k] = x[i] * x[j];
                k += 1;
            }
        }
    }

    /// The input columns `(i, j)` of every output column, in the order of
    /// [`Self::expand_row`] (`j = None` for a linear term).
    fn terms(&self, d: usize) -> Vec<(usize, Option<usize>)> {
        let linear = (0..d).filter(|_| self.include_linear).map(|i| (i, None));
        let products = (0..d).flat_map(|i| (i..d).map(move |j| (i, Some(j))));
        linear.chain(products).collect()
    }

    /// Expands every row of `x` (`n x d`) to `n x out_dim(d)`: each output column is an input
    /// column or the element-wise product of two, written contiguously, columns in parallel.
    pub fn expand(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let n = x.nrows();
        // Column-major input, so that every input column is one contiguous slice.
        let owned;
        let x = if x.row_stride() == 1 {
            x
        } else {
            owned = x.to_owned();
            owned.as_ref()
        };
        let col = |i: usize| -> &[f64] {
            x.col(i)
                .try_as_col_major()
                .map(|c| c.as_slice())
                .expect("column-major")
        };
        let terms = self.terms(x.ncols());
        let mut z = Mat::<f64>::zeros(n, terms.len());
        z.par_col_iter_mut()
            .zip(terms.par_iter())
            .for_each(|(out, &(i, j))| {
                let out = out
                    .try_as_col_major_mut()
                    .expect("fresh matrix")
                    .as_slice_mut();
                match j {
                    None => out.copy_from_slice(col(i)),
                    Some(j) => {
                        for ((o, a), b) in out.iter_mut().zip(col(i)).zip(col(j)) {
                            *o = a * b;
                        }
                    }
                }
            });
        z
    }
}

/// An optional expansion: the identity when `None`.
pub(crate) fn expand_opt(e: Option<QuadraticExpansion>, x: MatRef<'_, f64>) -> Mat<f64> {
    match e {
        Some(e) => e.expand(x),
        None => x.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monomials_in_order() {
        let x = Mat::from_fn(2, 3, |i, j| (1 + i * 3 + j) as f64);
        let e = QuadraticExpansion::default();
        assert_eq!(e.out_dim(3), 9);
        assert_eq!(e.out_dim(35), 665);
        assert_eq!(
            QuadraticExpansion {
                include_linear: false
            }
            .out_dim(35),
            630
        );
        let z = e.expand(x.as_ref());
        let want = [1.0, 2.0, 3.0, 1.0, 2.0, 3.0, 4.0, 6.0, 9.0];
        for (j, w) in want.iter().enumerate() {
            assert_eq!(z[(0, j)], *w);
        }
        assert_eq!(z[(1, 8)], 36.0);
    }
}
