//! The global constraint-space system of one soft-projection iteration (paper section 7):
//! `(h^2 J W J' + C) dl = -rhs`, with one row per link and three per membrane triangle,
//! applied matrix-free (`J W J' p` as two sparse products). The paper solves it with
//! Conjugate Residuals rather than Conjugate Gradients: the transformed steepest-descent step
//! becomes a minimum-residual step in constraint space.

use nalgebra::{Matrix3, Vector3};
use wscg_math::sparse::LinOp;

use crate::model::ClothModel;

/// One constraint row: its particles and their gradient vectors.
#[derive(Clone, Debug)]
struct Row {
    parts: Vec<(usize, Vector3<f64>)>,
}

/// `S = scale J W J' + C` at fixed positions.
#[derive(Clone, Debug)]
pub struct ConstraintSystem {
    rows: Vec<Row>,
    /// Compliance blocks on the diagonal: `(first row, block)`, 1x1 for links (stored in
    /// `[0][0]`), 3x3 for triangles.
    blocks: Vec<(usize, usize, Matrix3<f64>)>,
    inv_mass: Vec<f64>,
    scale: f64,
}

impl ConstraintSystem {
    /// The system at positions `x` with `scale = alpha h (beta h + gamma)` (`h^2` for
    /// implicit Euler). Links of zero length contribute zero rows.
    pub fn new(m: &ClothModel, x: &[Vector3<f64>], scale: f64) -> Self {
        let mut rows = Vec::with_capacity(m.constraint_rows());
        let mut blocks = Vec::new();
        for l in &m.links {
            let d = x[l.i] - x[l.j];
            let len = d.norm();
            let n = if len < 1e-12 {
                Vector3::zeros()
            } else {
                d / len
            };
            blocks.push((rows.len(), 1, Matrix3::from_diagonal_element(l.compliance)));
            rows.push(Row {
                parts: vec![(l.i, n), (l.j, -n)],
            });
        }
        for t in &m.tris {
            let st = t.strain(x);
            let (c2, cs) = t.compliance();
            let mut c = Matrix3::zeros();
            c.fixed_view_mut::<2, 2>(0, 0).copy_from(&c2);
            c[(2, 2)] = cs;
            blocks.push((rows.len(), 3, c));
            for k in 0..3 {
                rows.push(Row {
                    parts: (0..3).map(|p| (t.idx[p], st.grad[k][p])).collect(),
                });
            }
        }
        Self {
            rows,
            blocks,
            inv_mass: m.inv_mass.clone(),
            scale,
        }
    }

    /// Number of constraint rows `m`.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The dense matrix (for checks and small problems), row-major `m x m`.
    pub fn dense(&self) -> Vec<f64> {
        let m = self.len();
        let mut out = vec![0.0; m * m];
        let mut e = vec![0.0; m];
        let mut y = vec![0.0; m];
        for j in 0..m {
            e.iter_mut().for_each(|v| *v = 0.0);
            e[j] = 1.0;
            self.apply(&e, &mut y);
            for i in 0..m {
                out[i * m + j] = y[i];
            }
        }
        out
    }
}

impl LinOp for ConstraintSystem {
    fn nrows(&self) -> usize {
        self.rows.len()
    }
    fn ncols(&self) -> usize {
        self.rows.len()
    }
    fn apply(&self, p: &[f64], y: &mut [f64]) {
        // f = W J' p, then y = scale J f + C p.
        let mut f = vec![Vector3::zeros(); self.inv_mass.len()];
        for (row, &pk) in self.rows.iter().zip(p) {
            for &(q, g) in &row.parts {
                f[q] += g * (pk * self.inv_mass[q]);
            }
        }
        for (k, row) in self.rows.iter().enumerate() {
            y[k] = self.scale * row.parts.iter().map(|&(q, g)| g.dot(&f[q])).sum::<f64>();
        }
        for &(r0, size, c) in &self.blocks {
            for a in 0..size {
                y[r0 + a] += (0..size).map(|b| c[(a, b)] * p[r0 + b]).sum::<f64>();
            }
        }
    }
}
