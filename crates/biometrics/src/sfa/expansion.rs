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

    /// Expands every row of `x` (`n x d`) to `n x out_dim(d)`, rows in parallel.
    pub fn expand(&self, x: MatRef<'_, f64>) -> Mat<f64> {
        let (n, d) = (x.nrows(), x.ncols());
        let big = self.out_dim(d);
        let mut rows = vec![0.0; n * big];
        rows.par_chunks_mut(big.max(1)).enumerate().for_each_init(
            || vec![0.0; d],
            |buf, (i, out)| {
                for (c, b) in buf.iter_mut().enumerate() {
                    *b = x[(i, c)];
                }
                self.expand_row(buf, out);
            },
        );
        Mat::from_fn(n, big, |i, j| rows[i * big + j])
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
