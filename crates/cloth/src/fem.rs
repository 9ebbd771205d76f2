//! StVK membrane triangles as soft constraints (paper section 9).
//!
//! A triangle with rest coordinates `(u, v)` per vertex has `D_m = [u1-u0, u2-u0; v1-v0,
//! v2-v0]` and `m = D_m^-1`. The deformation gradient's columns are `w_u = sum_p a_p x_p`
//! and `w_v = sum_p b_p x_p` with `a = (-(m00+m10), m00, m10)`, `b = (-(m01+m11), m01, m11)`;
//! the Green strains are `e_uu = (w_u.w_u - 1)/2`, `e_vv = (w_v.w_v - 1)/2` and the
//! engineering shear `g_uv = w_u.w_v` (paper eq. 26). The constraint is the strain vector with
//! compliance `E^-1 / area`, so that `1/2 c' C^-1 c = (area/2) e' E e`, the StVK membrane
//! energy with the plane-stress matrix `E = Y/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0,
//! (1-nu)/2]]` (`Y` in N/m). `E^-1` is block diagonal: the stretch pair has compliance
//! `(1/(Y area)) [[1, -nu], [-nu, 1]]` (the paper prints `[[1, nu], [-nu, 1]]`, a typo: the
//! matrix must be symmetric) and the shear `1/(G area)`, `G = Y/(2(1+nu))`; the solver
//! projects the stretch pair jointly (a 2 x 2 system) and the shear alone, as the paper does.

use nalgebra::{Matrix2, Matrix3, Vector3};
use wscg_math::{Error, Result};

use crate::vecs::{v3s, V3};

/// One membrane triangle.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FemTri {
    /// Vertex indices.
    pub idx: [usize; 3],
    /// Weights `a_p` of `w_u = sum a_p x_p`.
    pub a: [f64; 3],
    /// Weights `b_p` of `w_v = sum b_p x_p`.
    pub b: [f64; 3],
    /// Rest area (m^2).
    pub area: f64,
    /// Young's modulus of the membrane (N/m).
    pub young: f64,
    /// Poisson ratio in `[0, 0.5)`.
    pub poisson: f64,
}

/// Strains and their per-vertex gradients.
#[derive(Clone, Copy, Debug)]
pub struct Strain {
    /// `(e_uu, e_vv, g_uv)`.
    pub e: [f64; 3],
    /// `grad[k][p]`: gradient of strain component `k` with respect to vertex `p`.
    pub grad: [[[f64; 3]; 3]; 3],
}

impl FemTri {
    /// A triangle with rest coordinates `uv` (one `(u, v)` per vertex).
    ///
    /// Errors: a degenerate rest triangle (`|det D_m| < 1e-14`), non-finite coordinates,
    /// `young <= 0`, `poisson` outside `[0, 0.5)`.
    pub fn new(idx: [usize; 3], uv: [[f64; 2]; 3], young: f64, poisson: f64) -> Result<Self> {
        if uv.iter().flatten().any(|c| !c.is_finite()) {
            return Err(Error::invalid("uv", "rest coordinates must be finite"));
        }
        if young.is_nan() || young <= 0.0 {
            return Err(Error::invalid("young", format!("must be > 0, got {young}")));
        }
        if !(0.0..0.5).contains(&poisson) {
            return Err(Error::invalid(
                "poisson",
                format!("must be in [0, 0.5), got {poisson}"),
            ));
        }
        let dm = Matrix2::new(
            uv[1][0] - uv[0][0],
            uv[2][0] - uv[0][0],
            uv[1][1] - uv[0][1],
            uv[2][1] - uv[0][1],
        );
        let det = dm.determinant();
        if det.abs() < 1e-14 {
            return Err(Error::invalid(
                "triangle",
                format!("rest triangle {idx:?} is degenerate (det D_m = {det:e})"),
            ));
        }
        let m = dm.try_inverse().expect("non-singular");
        Ok(Self {
            idx,
            a: [-(m[(0, 0)] + m[(1, 0)]), m[(0, 0)], m[(1, 0)]],
            b: [-(m[(0, 1)] + m[(1, 1)]), m[(0, 1)], m[(1, 1)]],
            area: 0.5 * det.abs(),
            young,
            poisson,
        })
    }

    /// Rest coordinates of a triangle from its rest positions in 3-D (a local frame with
    /// `u` along the first edge).
    pub fn local_uv(p: [[f64; 3]; 3]) -> [[f64; 2]; 3] {
        let p = p.map(V3::from);
        let e1 = p[1] - p[0];
        let n = e1.cross(&(p[2] - p[0]));
        let u = e1.normalize();
        let v = n.cross(&u).normalize();
        let q = |x: Vector3<f64>| [(x - p[0]).dot(&u), (x - p[0]).dot(&v)];
        [q(p[0]), q(p[1]), q(p[2])]
    }

    /// Strains and gradients at positions `x`.
    pub fn strain(&self, x: &[[f64; 3]]) -> Strain {
        let (e, grad) = self.strain_grad(v3s(x));
        Strain {
            e,
            grad: grad.map(|g| g.map(Into::into)),
        }
    }

    /// Strains `(e_uu, e_vv, g_uv)` and their per-vertex gradients at positions `x`.
    pub(crate) fn strain_grad(&self, x: &[V3]) -> ([f64; 3], [[V3; 3]; 3]) {
        let [p0, p1, p2] = self.idx;
        let wu = x[p0] * self.a[0] + x[p1] * self.a[1] + x[p2] * self.a[2];
        let wv = x[p0] * self.b[0] + x[p1] * self.b[1] + x[p2] * self.b[2];
        let grad = [
            self.a.map(|a| wu * a),
            self.b.map(|b| wv * b),
            [0, 1, 2].map(|p| wv * self.a[p] + wu * self.b[p]),
        ];
        let e = [
            0.5 * (wu.dot(&wu) - 1.0),
            0.5 * (wv.dot(&wv) - 1.0),
            wu.dot(&wv),
        ];
        (e, grad)
    }

    /// The plane-stress elasticity matrix `E` (N/m).
    pub fn elasticity(&self) -> Matrix3<f64> {
        let (y, nu) = (self.young, self.poisson);
        Matrix3::new(1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu)) * (y / (1.0 - nu * nu))
    }

    /// Compliance of the stretch pair, `(1/(Y area)) [[1, -nu], [-nu, 1]]`, and of the
    /// shear, `1/(G area)`.
    pub fn compliance(&self) -> (Matrix2<f64>, f64) {
        let (y, nu) = (self.young, self.poisson);
        let g = y / (2.0 * (1.0 + nu));
        (
            Matrix2::new(1.0, -nu, -nu, 1.0) / (y * self.area),
            1.0 / (g * self.area),
        )
    }

    /// The StVK membrane energy `(area/2) e' E e` at positions `x`.
    pub fn energy(&self, x: &[[f64; 3]]) -> f64 {
        let e = Vector3::from(self.strain_grad(v3s(x)).0);
        0.5 * self.area * e.dot(&(self.elasticity() * e))
    }
}

/// Adds the triangle's elastic forces `-sum_k (area E e)_k grad e_k` at `x` to `f`.
pub(crate) fn add_forces(t: &FemTri, x: &[V3], f: &mut [V3]) {
    let (e, grad) = t.strain_grad(x);
    let s = t.elasticity() * Vector3::from(e) * t.area;
    for p in 0..3 {
        f[t.idx[p]] -= grad[0][p] * s[0] + grad[1][p] * s[1] + grad[2][p] * s[2];
    }
}
