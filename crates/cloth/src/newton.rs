//! Exact implicit Euler: the minimiser of the incremental potential (the paper's eq. 4)
//! `Phi(x) = (1/2h^2) (x - x~)' M (x - x~) + U(x)`, `x~ = x^n + h v^n + h^2 g`,
//! found by Newton's method with a backtracking line search. The Hessian of each link is
//! projected to be positive semi-definite (`k (n n' + max(0, 1 - rest/len) (I - n n'))`);
//! membrane triangles use their Gauss-Newton part `J' C^-1 J`. The Newton systems are solved
//! by conjugate gradients. This is the reference the paper's equivalence claim (section 2)
//! is checked against; it is also usable as an integrator.
//!
//! Rollers (the linear equalities `n . x_p = offset` of section 5) are eliminated: the start
//! is projected onto their planes and the gradient and Newton system are filtered per
//! particle (Baraff and Witkin's `S = I - n n'`), so the minimisation runs over the planes;
//! the reactions are the normal part of the gradient at the minimiser.

use nalgebra::{Matrix3, Vector3};
use wscg_math::sparse::{pcg, IdentityPrecond, InitialGuess, PcgParams};
use wscg_math::{Error, Result};

use crate::energy::elastic_energy;
use crate::model::ClothModel;
pub use crate::system::inertial_target;
use crate::system::{
    elastic_forces_v, filters, inertial_target_v, project_onto_rollers, ImplicitOperator, Stepped,
};
use crate::vecs::{arrays, into_arrays, v3s, V3};

fn free(m: &ClothModel, q: usize) -> bool {
    m.inv_mass[q] > 0.0
}

/// `Phi` at positions `x` (`xt` the candidate [`inertial_target`]).
pub fn incremental_potential(m: &ClothModel, x: &[[f64; 3]], xt: &[[f64; 3]], h: f64) -> f64 {
    potential(m, v3s(x), v3s(xt), h)
}

fn potential(m: &ClothModel, x: &[V3], xt: &[V3], h: f64) -> f64 {
    let inertia: f64 = (0..m.len())
        .filter(|&q| free(m, q))
        .map(|q| (x[q] - xt[q]).norm_squared() / m.inv_mass[q])
        .sum::<f64>()
        / (2.0 * h * h);
    inertia + elastic_energy(m, arrays(x))
}

/// `grad Phi = M (x - x~)/h^2 - f(x)` at `x`, filtered by `filt` (zero at pinned
/// particles, in the planes of particles on rollers), and the forces `f(x)`.
fn gradient(
    m: &ClothModel,
    x: &[Vector3<f64>],
    xt: &[Vector3<f64>],
    h: f64,
    filt: &[Matrix3<f64>],
) -> (Vec<Vector3<f64>>, Vec<Vector3<f64>>) {
    let f = elastic_forces_v(m, x);
    let g = (0..m.len())
        .map(|q| {
            if free(m, q) {
                filt[q] * ((x[q] - xt[q]) / (h * h * m.inv_mass[q]) - f[q])
            } else {
                Vector3::zeros()
            }
        })
        .collect();
    (g, f)
}

fn norm(v: &[Vector3<f64>]) -> f64 {
    v.iter().map(|g| g.norm_squared()).sum::<f64>().sqrt()
}

/// Minimises `Phi` from the start `x0` until `|grad Phi| <= tol max(|M (x - x~)/h^2|, |f|)`
/// (a relative tolerance; the gradient is the difference of the two terms), or until the
/// gradient stalls at its round-off floor below `1e-6` of that scale; returns the
/// minimiser.
pub fn minimize(
    m: &ClothModel,
    xt: &[[f64; 3]],
    x0: &[[f64; 3]],
    h: f64,
    tol: f64,
    max_newton: usize,
) -> Result<Vec<[f64; 3]>> {
    minimize_v(m, v3s(xt), v3s(x0), h, tol, max_newton).map(into_arrays)
}

/// [`minimize`] on the solvers' vectors.
fn minimize_v(
    m: &ClothModel,
    xt: &[V3],
    x0: &[V3],
    h: f64,
    tol: f64,
    max_newton: usize,
) -> Result<Vec<V3>> {
    if m.links.iter().any(|l| l.compliance == 0.0) {
        return Err(Error::invalid(
            "method",
            "the Newton implicit Euler needs soft links only (no hard links)",
        ));
    }
    let n = m.len();
    let inv_h2 = 1.0 / (h * h);
    let mut x = x0.to_vec();
    for q in 0..n {
        if !free(m, q) {
            x[q] = xt[q];
        }
    }
    project_onto_rollers(m, &mut x);
    let filt = filters(m);
    let mut best = (f64::INFINITY, 0usize);
    for _ in 0..max_newton {
        // Gradient of Phi: M (x - x~)/h^2 - f(x), in the rollers' planes.
        let (grad, f) = gradient(m, &x, xt, h, &filt);
        // Relative test: the gradient against the size of its two terms (the forces can be
        // large where round-off makes an absolute tolerance unreachable).
        let gnorm = norm(&grad);
        let sum = |v: &mut dyn Iterator<Item = f64>| v.sum::<f64>().sqrt();
        let fnorm = sum(&mut (0..n).filter(|&q| free(m, q)).map(|q| f[q].norm_squared()));
        let inorm = sum(&mut (0..n)
            .filter(|&q| free(m, q))
            .map(|q| ((x[q] - xt[q]) * (inv_h2 / m.inv_mass[q])).norm_squared()));
        let scale = fnorm.max(inorm).max(f64::MIN_POSITIVE);
        if gnorm <= tol * scale || gnorm == 0.0 {
            return Ok(x);
        }
        // Round-off floor: the gradient is a difference of large element forces and stops
        // shrinking; once it is small (1e-6 relative) and has not improved by 10 % in five
        // iterations, the minimiser is as accurate as double precision allows.
        if gnorm < 0.9 * best.0 {
            best = (gnorm, 0);
        } else {
            best.1 += 1;
            if best.1 >= 5 && gnorm <= 1e-6 * scale {
                return Ok(x);
            }
        }
        // The Newton system (M/h^2 + K) dx = -grad, scaled by h^2.
        let hess = ImplicitOperator::at(m, &x, &filt, h * h, true);
        let b: Vec<f64> = grad
            .iter()
            .flat_map(|g| [-g.x * h * h, -g.y * h * h, -g.z * h * h])
            .collect();
        let sol = pcg(
            &hess,
            &b,
            InitialGuess::Zero,
            &IdentityPrecond,
            &PcgParams::default().tol(1e-14).max_iter(Some(20 * 3 * n)),
        )?;
        let dir: Vec<Vector3<f64>> = (0..n)
            .map(|q| Vector3::new(sol.x[3 * q], sol.x[3 * q + 1], sol.x[3 * q + 2]))
            .collect();
        // Backtracking (Armijo) line search on Phi. Near the minimum the decrease of Phi
        // falls below its round-off; the full step is then accepted when it shrinks the
        // gradient instead.
        let phi0 = potential(m, &x, xt, h);
        let slope: f64 = grad.iter().zip(&dir).map(|(g, d)| g.dot(d)).sum();
        let full: Vec<Vector3<f64>> = x.iter().zip(&dir).map(|(a, d)| a + d).collect();
        let lost_in_roundoff = -slope <= 1e-12 * phi0.abs().max(f64::MIN_POSITIVE);
        if lost_in_roundoff && norm(&gradient(m, &full, xt, h, &filt).0) < gnorm {
            x = full;
            project_onto_rollers(m, &mut x);
            continue;
        }
        let mut step = 1.0;
        loop {
            let trial: Vec<Vector3<f64>> = x.iter().zip(&dir).map(|(a, d)| a + d * step).collect();
            if potential(m, &trial, xt, h) <= phi0 + 1e-4 * step * slope || step < 1e-12 {
                x = trial;
                break;
            }
            step *= 0.5;
        }
        // The filtered direction lies in the rollers' planes; this removes its round-off.
        project_onto_rollers(m, &mut x);
    }
    Err(Error::Numerical(format!(
        "Newton's method did not reach the relative gradient tolerance {tol:e} in {max_newton} \
         iterations"
    )))
}

/// One exact implicit Euler step.
pub(crate) fn step(m: &ClothModel, h: f64, tol: f64) -> Result<Stepped> {
    let xt = inertial_target_v(m, h);
    let x = minimize_v(m, &xt, &xt, h, tol, 100)?;
    let v = x.iter().zip(m.xs()).map(|(a, b)| (a - b) / h).collect();
    Ok(Stepped::new(x, v, vec![0.0; m.constraint_rows()]))
}
