//! The integrators the paper compares against (its Figs. 1 and 5):
//! - symplectic Euler with explicit spring forces and small substeps, the energy reference;
//! - implicit Euler with one linearised Newton step (Baraff and Witkin 1998), the system
//!   `(M + h^2 J' C^-1 J) dv = h f(x~)` (the Gauss-Newton stiffness, as the paper) solved by
//!   conjugate gradients or by a sparse Cholesky factorisation (the paper's "exact" solve),
//!   rollers enforced by Baraff and Witkin's velocity filters;
//! - the "velocity projection" damping of Fig. 5: after a step, each link's relative velocity
//!   along its direction is reduced by a factor `k_d`.

use nalgebra::Vector3;
use wscg_math::sparse::{pcg, IdentityPrecond, InitialGuess, PcgParams};
use wscg_math::{Error, Result};

use crate::model::ClothModel;
pub use crate::system::elastic_forces;
use crate::system::{elastic_forces_v, filters, ImplicitOperator, Stepped};

fn require_soft(m: &ClothModel, method: &str) -> Result<()> {
    if m.links.iter().any(|l| l.compliance == 0.0) {
        return Err(Error::invalid(
            "method",
            format!("{method} needs soft links (finite stiffness)"),
        ));
    }
    Ok(())
}

/// Symplectic Euler over `substeps` substeps of `h / substeps`.
pub(crate) fn symplectic_euler(m: &ClothModel, h: f64, substeps: usize) -> Result<Stepped> {
    require_soft(m, "symplectic Euler")?;
    if !m.rollers.is_empty() {
        return Err(Error::invalid(
            "method",
            "symplectic Euler does not support rollers",
        ));
    }
    let hs = h / substeps.max(1) as f64;
    let mut x = m.xs().to_vec();
    let mut v = m.vs().to_vec();
    let g = m.g();
    for _ in 0..substeps.max(1) {
        let f = elastic_forces_v(m, &x);
        for p in 0..x.len() {
            let w = m.inv_mass[p];
            if w > 0.0 {
                v[p] += (g + f[p] * w) * hs;
            }
            x[p] += v[p] * hs;
        }
    }
    Ok(Stepped::new(x, v, vec![0.0; m.constraint_rows()]))
}

/// How the linearised implicit Euler system is solved.
#[derive(Clone, Copy, Debug)]
pub(crate) enum LinearSolve {
    /// Conjugate gradients to a relative residual `tol` in at most `max_iter` iterations.
    Cg { tol: f64, max_iter: usize },
    /// Sparse Cholesky factorisation (the paper's "exact" solve).
    Cholesky,
}

/// One linearised implicit Euler step (Baraff and Witkin 1998):
/// `(M + h^2 J' C^-1 J) dv = h f(x~)` around the candidate `x~ = x + h (v + h g)`, then
/// `x = x~ + h dv`, `v = v~ + dv`. Rollers are enforced by filtering the velocity change, so
/// particles on rollers must start on their planes.
pub(crate) fn implicit_euler_linearised(
    m: &ClothModel,
    h: f64,
    solve: LinearSolve,
) -> Result<Stepped> {
    require_soft(m, "implicit Euler")?;
    crate::system::require_on_rollers(m)?;
    let n = m.len();
    let filters = filters(m);
    let (x0, v0, g) = (m.xs(), m.vs(), m.g());
    let vt: Vec<Vector3<f64>> = (0..n)
        .map(|q| {
            if m.inv_mass[q] > 0.0 {
                filters[q] * (v0[q] + g * h)
            } else {
                v0[q]
            }
        })
        .collect();
    let xt: Vec<Vector3<f64>> = (0..n).map(|q| x0[q] + vt[q] * h).collect();
    let f = elastic_forces_v(m, &xt);
    let b: Vec<f64> = (0..n)
        .flat_map(|q| {
            let r = filters[q] * f[q] * h;
            [r.x, r.y, r.z]
        })
        .collect();
    let op = ImplicitOperator::at(m, &xt, &filters, h * h, false);
    let sol = match solve {
        LinearSolve::Cg { tol, max_iter } => {
            pcg(
                &op,
                &b,
                InitialGuess::Zero,
                &IdentityPrecond,
                &PcgParams::default().tol(tol).max_iter(Some(max_iter)),
            )?
            .x
        }
        LinearSolve::Cholesky => op.assemble()?.cholesky_solve(&b)?,
    };
    let dv = |q: usize| Vector3::new(sol[3 * q], sol[3 * q + 1], sol[3 * q + 2]);
    let x = (0..n).map(|q| xt[q] + dv(q) * h).collect();
    let v = (0..n).map(|q| vt[q] + dv(q)).collect();
    Ok(Stepped::new(x, v, vec![0.0; m.constraint_rows()]))
}

/// Reduces each link's relative velocity along the link by the factor `kd` in `[0, 1]`,
/// sharing the change by inverse masses (the velocity-projection damping baseline).
pub(crate) fn project_velocities(
    m: &ClothModel,
    x: &[Vector3<f64>],
    v: &mut [Vector3<f64>],
    kd: f64,
) {
    for l in &m.links {
        let (wi, wj) = (m.inv_mass[l.i], m.inv_mass[l.j]);
        let a = wi + wj;
        let d = x[l.i] - x[l.j];
        let len = d.norm();
        if a <= 0.0 || len < 1e-12 {
            continue;
        }
        let n = d / len;
        let dv = n.dot(&(v[l.i] - v[l.j]));
        let imp = -kd * dv / a;
        v[l.i] += n * (imp * wi);
        v[l.j] -= n * (imp * wj);
    }
}
