//! The global constraint-space system of one soft-projection iteration (paper section 7):
//! `(h^2 J W J' + C) dl = -rhs`, with one row per link and three per membrane triangle,
//! applied matrix-free (`J W J' p` as two sparse products). The paper solves it with
//! Conjugate Residuals rather than Conjugate Gradients: the transformed steepest-descent step
//! becomes a minimum-residual step in constraint space.
//!
//! Rollers (`n . x_p = offset`, section 5) are eliminated rather than given rows: a particle
//! on rollers starts on their planes and its inverse mass becomes `w S`, `S = I - n n'` the
//! projection onto its planes (Baraff and Witkin's filter), so every move stays in them; the
//! reactions are the normal part of the momentum residual at convergence.

use nalgebra::{Matrix3, Vector3};
use wscg_math::sparse::LinOp;

use crate::model::ClothModel;
use crate::vecs::{arrays, into_arrays, v3s, V3};

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
    /// Inverse mass of every particle, `w S` with the rollers' filter `S`.
    inv_mass: Vec<Matrix3<f64>>,
    scale: f64,
}

impl ConstraintSystem {
    /// The system at positions `x` with `scale = alpha h (beta h + gamma)` (`h^2` for
    /// implicit Euler). Links of zero length contribute zero rows. A particle on rollers
    /// moves only in their planes: its inverse mass is `w S`.
    pub fn new(m: &ClothModel, x: &[[f64; 3]], scale: f64) -> Self {
        let x = v3s(x);
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
            let grad = t.strain_grad(x).1;
            let (c2, cs) = t.compliance();
            let mut c = Matrix3::zeros();
            c.fixed_view_mut::<2, 2>(0, 0).copy_from(&c2);
            c[(2, 2)] = cs;
            blocks.push((rows.len(), 3, c));
            for g in grad {
                rows.push(Row {
                    parts: t.idx.into_iter().zip(g).collect(),
                });
            }
        }
        let inv_mass = crate::system::filters(m)
            .into_iter()
            .zip(&m.inv_mass)
            .map(|(s, &w)| s * w)
            .collect();
        Self {
            rows,
            blocks,
            inv_mass,
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

    /// `W J' p`: the per-particle effect of multipliers `p`.
    pub fn w_jt(&self, p: &[f64]) -> Vec<[f64; 3]> {
        into_arrays(self.w_jt_v(p))
    }

    fn w_jt_v(&self, p: &[f64]) -> Vec<V3> {
        let mut f = self.jt_v(p);
        for (fq, w) in f.iter_mut().zip(&self.inv_mass) {
            *fq = w * *fq;
        }
        f
    }

    /// `J' p` (no mass weighting).
    pub fn jt(&self, p: &[f64]) -> Vec<[f64; 3]> {
        into_arrays(self.jt_v(p))
    }

    fn jt_v(&self, p: &[f64]) -> Vec<V3> {
        let mut f = vec![Vector3::zeros(); self.inv_mass.len()];
        for (row, &pk) in self.rows.iter().zip(p) {
            for &(q, g) in &row.parts {
                f[q] += g * pk;
            }
        }
        f
    }

    /// `J f` for per-particle vectors `f`.
    pub fn j(&self, f: &[[f64; 3]]) -> Vec<f64> {
        let f = v3s(f);
        self.rows
            .iter()
            .map(|row| row.parts.iter().map(|&(q, g)| g.dot(&f[q])).sum())
            .collect()
    }

    /// Adds `C p` to `y`.
    pub fn add_compliance(&self, p: &[f64], y: &mut [f64]) {
        for &(r0, size, c) in &self.blocks {
            for a in 0..size {
                y[r0 + a] += (0..size).map(|b| c[(a, b)] * p[r0 + b]).sum::<f64>();
            }
        }
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
        // y = scale J (W J' p) + C p.
        let f = self.w_jt_v(p);
        for (k, row) in self.rows.iter().enumerate() {
            y[k] = self.scale * row.parts.iter().map(|&(q, g)| g.dot(&f[q])).sum::<f64>();
        }
        self.add_compliance(p, y);
    }
}

/// Constraint values at `x`: one per link (`|x_i - x_j| - rest`), three per triangle (the
/// strains), in the row order of [`ConstraintSystem`].
pub fn constraint_values(m: &ClothModel, x: &[[f64; 3]]) -> Vec<f64> {
    let x = v3s(x);
    let mut c: Vec<f64> = m
        .links
        .iter()
        .map(|l| (x[l.i] - x[l.j]).norm() - l.rest)
        .collect();
    for t in &m.tris {
        c.extend(t.strain_grad(x).0);
    }
    c
}

/// Exact implicit Euler through the constraint space (the Schur complement of the KKT Newton
/// step with `K ~ M/h^2`): each outer iteration solves
/// `(h^2 A + C) dl = -(c + C lambda) + h^2 J W g` by Conjugate Residuals and moves
/// `dx = h^2 W (J' dl - g)`, where `g = M (x - x~)/h^2 - J' lambda` is the momentum residual.
/// With `primal_residual = false`, `g` is dropped: the XPBD fixed point `c + C lambda = 0`,
/// which is not the implicit Euler minimiser when the constraint gradients rotate.
pub(crate) fn global_step(
    m: &ClothModel,
    h: f64,
    outer: usize,
    tol: f64,
    primal_residual: bool,
) -> wscg_math::Result<crate::system::Stepped> {
    use wscg_math::sparse::{conjugate_residual, InitialGuess, PcgParams};
    if m.links.iter().any(|l| l.compliance == 0.0) {
        return Err(wscg_math::Error::invalid(
            "method",
            "the global constraint solve needs soft links only (no hard links)",
        ));
    }
    let xt = crate::system::inertial_target_v(m, h);
    let mut x = xt.clone();
    crate::system::project_onto_rollers(m, &mut x);
    let mut lambda = vec![0.0; m.links.len() + 3 * m.tris.len()];
    let h2 = h * h;
    for _ in 0..outer {
        wscg_math::cancel::check()?;
        let sys = ConstraintSystem::new(m, arrays(&x), h2);
        let g: Vec<Vector3<f64>> = if primal_residual {
            let jl = sys.jt_v(&lambda);
            (0..m.len())
                .map(|q| {
                    let w = m.inv_mass[q];
                    if w > 0.0 {
                        (x[q] - xt[q]) / (w * h2) - jl[q]
                    } else {
                        Vector3::zeros()
                    }
                })
                .collect()
        } else {
            vec![Vector3::zeros(); m.len()]
        };
        let wg: Vec<Vector3<f64>> = g.iter().zip(&sys.inv_mass).map(|(gq, w)| w * gq).collect();
        let jwg = sys.j(arrays(&wg));
        let mut rhs = constraint_values(m, arrays(&x));
        sys.add_compliance(&lambda, &mut rhs);
        for (r, j) in rhs.iter_mut().zip(&jwg) {
            *r = -*r + h2 * j;
        }
        let sol = conjugate_residual(
            &sys,
            &rhs,
            InitialGuess::Zero,
            &PcgParams::default()
                .tol(tol)
                .max_iter(Some(10 * rhs.len().max(1))),
        )?;
        let wjd = sys.w_jt_v(&sol.x);
        for q in 0..m.len() {
            x[q] += (wjd[q] - wg[q]) * h2;
        }
        for (l, d) in lambda.iter_mut().zip(&sol.x) {
            *l += d;
        }
    }
    let v = x.iter().zip(m.xs()).map(|(a, b)| (a - b) / h).collect();
    let mut full = lambda;
    full.resize(m.constraint_rows(), 0.0);
    Ok(crate::system::Stepped::new(x, v, full))
}
