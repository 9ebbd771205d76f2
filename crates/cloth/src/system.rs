//! What the integrators share: the result of a step, the elastic forces, the candidate
//! state `x~`, and the linearised implicit Euler operator `M + h^2 K` with the velocity
//! filters of Baraff and Witkin (1998) that the baselines, the Newton and the NCG solvers
//! build on.

use nalgebra::{Matrix3, Vector3};
use wscg_math::sparse::{CsrMatrix, LinOp};
use wscg_math::{Error, Result};

use crate::collision::StepContacts;
use crate::model::ClothModel;
use crate::vecs::{into_arrays, v3s, V3};

/// What a step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepStats {
    /// Largest constraint residual `|alpha (c + gamma J v) + Lambda|` met in the last sweep
    /// (m): the correction the last sweep still had to make (0 when converged).
    pub max_residual: f64,
    /// Contacts found at the start of the step (obstacle contacts and particle pairs).
    pub contacts: usize,
    /// Largest contact penetration corrected in the last iteration (m).
    pub max_penetration: f64,
}

/// The result of one step, committed only when finite.
pub(crate) struct Stepped {
    pub(crate) x: Vec<Vector3<f64>>,
    pub(crate) v: Vec<Vector3<f64>>,
    pub(crate) lambda: Vec<f64>,
    pub(crate) stats: StepStats,
}

impl Stepped {
    pub(crate) fn new(x: Vec<Vector3<f64>>, v: Vec<Vector3<f64>>, lambda: Vec<f64>) -> Self {
        Self {
            x,
            v,
            lambda,
            stats: StepStats::default(),
        }
    }

    /// The result of a projection step, with its residual and contact statistics.
    pub(crate) fn projected(
        x: Vec<Vector3<f64>>,
        v: Vec<Vector3<f64>>,
        lambda: Vec<f64>,
        max_residual: f64,
        contacts: &Option<StepContacts>,
        max_penetration: f64,
    ) -> Self {
        Self {
            x,
            v,
            lambda,
            stats: StepStats {
                max_residual,
                contacts: contacts.as_ref().map_or(0, StepContacts::len),
                max_penetration,
            },
        }
    }
}

/// Elastic forces `-sum J' C^-1 c` at positions `x`: soft links and membrane triangles.
pub fn elastic_forces(m: &ClothModel, x: &[[f64; 3]]) -> Vec<[f64; 3]> {
    into_arrays(elastic_forces_v(m, v3s(x)))
}

/// [`elastic_forces`] on the solvers' vectors.
pub(crate) fn elastic_forces_v(m: &ClothModel, x: &[V3]) -> Vec<V3> {
    let mut f = vec![Vector3::zeros(); x.len()];
    for l in m.links.iter().filter(|l| l.compliance > 0.0) {
        let d = x[l.i] - x[l.j];
        let len = d.norm();
        if len < 1e-12 {
            continue;
        }
        let g = d * (-(len - l.rest) / (l.compliance * len));
        f[l.i] += g;
        f[l.j] -= g;
    }
    for t in &m.tris {
        crate::fem::add_forces(t, x, &mut f);
    }
    f
}

/// The candidate `x~ = x + h v + h^2 g` (pinned particles: `x + h v`).
pub fn inertial_target(m: &ClothModel, h: f64) -> Vec<[f64; 3]> {
    into_arrays(inertial_target_v(m, h))
}

/// [`inertial_target`] as the solvers' vectors.
pub(crate) fn inertial_target_v(m: &ClothModel, h: f64) -> Vec<V3> {
    let (x, v) = (m.xs(), m.vs());
    (0..m.len())
        .map(|q| {
            let g = if m.inv_mass[q] > 0.0 {
                m.g()
            } else {
                Vector3::zeros()
            };
            x[q] + (v[q] + g * h) * h
        })
        .collect()
}

/// The particles on rollers, each with the indices of its rollers (in the order they were
/// added).
fn roller_groups(m: &ClothModel) -> Vec<(usize, Vec<usize>)> {
    let mut groups: Vec<(usize, Vec<usize>)> = Vec::new();
    for (k, r) in m.rollers.iter().enumerate() {
        match groups.iter_mut().find(|(p, _)| *p == r.p) {
            Some((_, rows)) => rows.push(k),
            None => groups.push((r.p, vec![k])),
        }
    }
    groups
}

/// The least-squares solution `l` of `(N' N) l = b`, `N` the unit normals of the rollers
/// `rows` as columns (a pseudo-inverse when the normals are dependent; zeros if that fails).
fn normal_solve(m: &ClothModel, rows: &[usize], b: nalgebra::DVector<f64>) -> Vec<f64> {
    let nrm = nalgebra::DMatrix::from_fn(3, rows.len(), |i, c| m.rollers[rows[c]].normal[i]);
    let a = nrm.transpose() * &nrm;
    let l = a
        .clone()
        .cholesky()
        .map(|c| c.solve(&b))
        .or_else(|| a.pseudo_inverse(1e-12).ok().map(|pi| pi * &b))
        .unwrap_or_else(|| nalgebra::DVector::zeros(rows.len()));
    l.iter().copied().collect()
}

/// Moves every free particle on rollers to the nearest point of its rollers' planes
/// `n . x = offset`: `x += N (N' N)^-1 (offset - N' x)`. The Newton and constraint-space
/// solvers start from there and keep such particles in their planes by the velocity
/// filters [`filters`].
pub(crate) fn project_onto_rollers(m: &ClothModel, x: &mut [V3]) {
    for (p, rows) in roller_groups(m) {
        if m.inv_mass[p] <= 0.0 {
            continue;
        }
        let b = nalgebra::DVector::from_iterator(
            rows.len(),
            rows.iter().map(|&j| {
                let r = &m.rollers[j];
                r.offset - V3::from(r.normal).dot(&x[p])
            }),
        );
        for (&j, l) in rows.iter().zip(normal_solve(m, &rows, b)) {
            x[p] += V3::from(m.rollers[j].normal) * l;
        }
    }
}

/// The rollers' reaction forces (N, along their normals) of a step from the model's state to
/// `(x, v)` over `h`: the constraint force `m (v - v0) / h - m g - f(x)` of each particle on
/// rollers, split over its rollers' normals (least squares, `(N' N) l = N' F`), into `out`
/// (one entry per roller).
pub(crate) fn roller_reactions(m: &ClothModel, x: &[V3], v: &[V3], h: f64, out: &mut [f64]) {
    let f = elastic_forces_v(m, x);
    let (v0, g) = (m.vs(), m.g());
    for (p, rows) in roller_groups(m) {
        let w = m.inv_mass[p];
        if w <= 0.0 {
            for &j in &rows {
                out[j] = 0.0;
            }
            continue;
        }
        let fc = (v[p] - v0[p]) / (h * w) - g / w - f[p];
        let b = nalgebra::DVector::from_iterator(
            rows.len(),
            rows.iter().map(|&j| V3::from(m.rollers[j].normal).dot(&fc)),
        );
        for (&j, l) in rows.iter().zip(normal_solve(m, &rows, b)) {
            out[j] = l;
        }
    }
}

/// Refuses a particle on rollers that does not lie on a roller's plane: the velocity filters
/// keep a particle where it starts. Errors name the particle and its distance to the plane.
pub(crate) fn require_on_rollers(m: &ClothModel) -> Result<()> {
    for r in &m.rollers {
        let x = V3::from(m.x[r.p]);
        let d = V3::from(r.normal).dot(&x) - r.offset;
        let tol = 1e-9 * (1.0 + x.norm() + r.offset.abs());
        if m.inv_mass[r.p] > 0.0 && d.abs() > tol {
            return Err(Error::invalid(
                "rollers",
                format!(
                    "particle {} lies {d:.3e} off its roller plane (normal {:?}, offset {}); \
                     this method keeps particles on rollers by velocity filters, so they must \
                     start on their planes",
                    r.p, r.normal, r.offset
                ),
            ));
        }
    }
    Ok(())
}

/// Per-particle velocity filters of Baraff and Witkin (1998): the identity for a free
/// particle, zero for a pinned one, and the projection onto the rollers' planes for a
/// particle on rollers.
pub(crate) fn filters(m: &ClothModel) -> Vec<Matrix3<f64>> {
    let mut normals: Vec<Vec<Vector3<f64>>> = vec![Vec::new(); m.len()];
    for r in &m.rollers {
        // Gram-Schmidt against the particle's earlier normals.
        let mut n = V3::from(r.normal);
        for e in &normals[r.p] {
            n -= e * e.dot(&n);
        }
        if n.norm() > 1e-9 {
            normals[r.p].push(n.normalize());
        }
    }
    (0..m.len())
        .map(|q| {
            if m.inv_mass[q] > 0.0 {
                normals[q]
                    .iter()
                    .fold(Matrix3::identity(), |s, n| s - n * n.transpose())
            } else {
                Matrix3::zeros()
            }
        })
        .collect()
}

/// `S (M + h^2 J' C^-1 J) S + (I - S)` with the filters `S` (symmetric positive definite),
/// the Jacobians taken at the candidate state.
pub(crate) struct ImplicitOperator<'a> {
    m: &'a ClothModel,
    /// Stiffness block of each link (`k n n'` for Gauss-Newton).
    link_k: Vec<Matrix3<f64>>,
    /// Strain gradients of each triangle at the candidate state.
    tri_grads: Vec<[[Vector3<f64>; 3]; 3]>,
    filters: &'a [Matrix3<f64>],
    h2: f64,
}

/// Stiffness block of a link at positions `x`: the Gauss-Newton part `k n n'`, plus with
/// `geometric` the positive part of the geometric term, `k max(0, 1 - rest/len) (I - n n')`
/// (the link Hessian projected to be positive semi-definite).
pub(crate) fn link_stiffness(
    m: &ClothModel,
    x: &[Vector3<f64>],
    geometric: bool,
) -> Vec<Matrix3<f64>> {
    m.links
        .iter()
        .map(|l| {
            let d = x[l.i] - x[l.j];
            let len = d.norm();
            if len < 1e-12 {
                return Matrix3::zeros();
            }
            let n = d / len;
            let nn = n * n.transpose();
            let k = 1.0 / l.compliance;
            let geo = if geometric {
                (Matrix3::identity() - nn) * (1.0 - l.rest / len).max(0.0)
            } else {
                Matrix3::zeros()
            };
            (nn + geo) * k
        })
        .collect()
}

impl<'a> ImplicitOperator<'a> {
    /// `M + h2 K` with the Jacobians taken at positions `x` (`geometric`: see
    /// [`link_stiffness`]).
    pub(crate) fn at(
        m: &'a ClothModel,
        x: &[Vector3<f64>],
        filters: &'a [Matrix3<f64>],
        h2: f64,
        geometric: bool,
    ) -> Self {
        let tri_grads = m.tris.iter().map(|t| t.strain_grad(x).1).collect();
        Self {
            m,
            link_k: link_stiffness(m, x, geometric),
            tri_grads,
            filters,
            h2,
        }
    }
}

impl ImplicitOperator<'_> {
    /// The operator assembled as a sparse `3n x 3n` matrix (the same entries `apply` uses).
    pub(crate) fn assemble(&self) -> Result<CsrMatrix> {
        let m = self.m;
        let mut t: Vec<(usize, usize, f64)> = Vec::new();
        // Adds `S_a B S_b` at block (a, b).
        let mut block = |a: usize, b: usize, blk: Matrix3<f64>| {
            let v = self.filters[a] * blk * self.filters[b];
            for r in 0..3 {
                for c in 0..3 {
                    if v[(r, c)] != 0.0 {
                        t.push((3 * a + r, 3 * b + c, v[(r, c)]));
                    }
                }
            }
        };
        for q in 0..m.len() {
            let w = m.inv_mass[q];
            let mass = if w > 0.0 { 1.0 / w } else { 0.0 };
            block(q, q, Matrix3::identity() * mass);
        }
        for (l, k) in m.links.iter().zip(&self.link_k) {
            let k = k * self.h2;
            block(l.i, l.i, k);
            block(l.j, l.j, k);
            block(l.i, l.j, -k);
            block(l.j, l.i, -k);
        }
        for (tri, g) in m.tris.iter().zip(&self.tri_grads) {
            let e = tri.elasticity() * (tri.area * self.h2);
            for a in 0..3 {
                for b in 0..3 {
                    let mut blk = Matrix3::zeros();
                    for k in 0..3 {
                        for l in 0..3 {
                            blk += g[k][a] * g[l][b].transpose() * e[(k, l)];
                        }
                    }
                    block(tri.idx[a], tri.idx[b], blk);
                }
            }
        }
        // (I - S) on the diagonal.
        for (q, s) in self.filters.iter().enumerate() {
            let v = Matrix3::identity() - s;
            for r in 0..3 {
                for c in 0..3 {
                    if v[(r, c)] != 0.0 {
                        t.push((3 * q + r, 3 * q + c, v[(r, c)]));
                    }
                }
            }
        }
        CsrMatrix::from_triplets(3 * m.len(), 3 * m.len(), &t)
    }
}

impl LinOp for ImplicitOperator<'_> {
    fn nrows(&self) -> usize {
        3 * self.m.len()
    }
    fn ncols(&self) -> usize {
        3 * self.m.len()
    }
    fn apply(&self, p: &[f64], y: &mut [f64]) {
        let m = self.m;
        let raw = |q: usize| Vector3::new(p[3 * q], p[3 * q + 1], p[3 * q + 2]);
        let fp: Vec<Vector3<f64>> = (0..m.len()).map(|q| self.filters[q] * raw(q)).collect();
        let mut out: Vec<Vector3<f64>> = (0..m.len())
            .map(|q| {
                let w = m.inv_mass[q];
                if w > 0.0 {
                    fp[q] / w
                } else {
                    Vector3::zeros()
                }
            })
            .collect();
        for (l, k) in m.links.iter().zip(&self.link_k) {
            let f = k * (fp[l.i] - fp[l.j]) * self.h2;
            out[l.i] += f;
            out[l.j] -= f;
        }
        for (t, g) in m.tris.iter().zip(&self.tri_grads) {
            let jp = Vector3::from_fn(|k, _| (0..3).map(|q| g[k][q].dot(&fp[t.idx[q]])).sum());
            let s = t.elasticity() * jp * (t.area * self.h2);
            for q in 0..3 {
                out[t.idx[q]] += g[0][q] * s[0] + g[1][q] * s[1] + g[2][q] * s[2];
            }
        }
        for (q, o) in out.iter().enumerate() {
            let r = self.filters[q] * o + (raw(q) - fp[q]);
            y[3 * q..3 * q + 3].copy_from_slice(r.as_slice());
        }
    }
}
