//! The nonlinear conjugate gradient implicit solver of the paper (section 3, Algorithm 1):
//! Fletcher-Reeves directions with the one-step line search `a = delta / (d' S d)`,
//! `S = M + h^2 J' C^-1 J` recomputed every iteration, restarts when `d' S d <= 0`
//! (Shewchuk 1994), pinned degrees of freedom projected out. The step length is one
//! Newton-Raphson step along the direction, `a = r'd / d'Sd` (the paper's `delta / d'Sd`
//! equals it only after an exact line search; used as printed, the iteration walks uphill on
//! stiff cloth).
//!
//! [`NcgVariant::Consistent`] (default) uses the true negative gradient of the incremental
//! potential, `r = P(h f - M (v - v~))`, and converges to the implicit Euler step;
//! [`NcgVariant::Paper`] uses `r = P(h f)` as printed, which converges to `f(x) = 0` (springs
//! at rest length), the same iteration dependence as the paper's printed projection. The
//! paper's "then delta' <- delta" is read as `delta <- delta'`.

use nalgebra::Vector3;
use wscg_math::sparse::LinOp;
use wscg_math::Result;

use crate::model::ClothModel;
use crate::system::{elastic_forces_v, filters, ImplicitOperator, Stepped};

/// Residual of the NCG iteration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum NcgVariant {
    /// `r = P(h f - M (v - v~))`: the gradient of the incremental potential (default).
    #[default]
    Consistent,
    /// `r = P(h f)`, as printed in the paper's Algorithm 1.
    Paper,
}

fn dot(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p.dot(q)).sum()
}

/// One NCG step of `iterations` iterations.
pub(crate) fn step(
    m: &ClothModel,
    h: f64,
    iterations: usize,
    variant: NcgVariant,
) -> Result<Stepped> {
    let n = m.len();
    let free = |q: usize| m.inv_mass[q] > 0.0;
    let (x0, v0, g) = (m.xs(), m.vs(), m.g());
    let vt: Vec<Vector3<f64>> = (0..n)
        .map(|q| if free(q) { v0[q] + g * h } else { v0[q] })
        .collect();
    let mut x: Vec<Vector3<f64>> = (0..n).map(|q| x0[q] + vt[q] * h).collect();
    let mut v = vt.clone();
    let residual = |x: &[Vector3<f64>], v: &[Vector3<f64>]| -> Vec<Vector3<f64>> {
        let f = elastic_forces_v(m, x);
        (0..n)
            .map(|q| {
                if !free(q) {
                    return Vector3::zeros();
                }
                match variant {
                    NcgVariant::Paper => f[q] * h,
                    NcgVariant::Consistent => f[q] * h - (v[q] - vt[q]) / m.inv_mass[q],
                }
            })
            .collect()
    };
    let mut r = residual(&x, &v);
    let mut d = r.clone();
    let mut delta = dot(&r, &r);
    let filt = filters(m);
    let mut flat = vec![0.0; 3 * n];
    let mut sq = vec![0.0; 3 * n];
    for _ in 0..iterations {
        wscg_math::cancel::check()?;
        if delta == 0.0 {
            break;
        }
        let op = ImplicitOperator::at(m, &x, &filt, h * h, false);
        for (q, dq) in d.iter().enumerate() {
            flat[3 * q..3 * q + 3].copy_from_slice(dq.as_slice());
        }
        op.apply(&flat, &mut sq);
        let dsd: f64 = (0..n)
            .filter(|&q| free(q))
            .map(|q| d[q].dot(&Vector3::new(sq[3 * q], sq[3 * q + 1], sq[3 * q + 2])))
            .sum();
        // One Newton-Raphson step along d: a = r'd / d'Sd. The paper's a = delta / d'Sd is the
        // same when r is orthogonal to the previous direction (an exact line search); with
        // one step per direction it is not, and it can walk uphill, so r'd is used and the
        // direction is reset to r when it is not a descent direction (or d'Sd <= 0).
        let rd = dot(&r, &d);
        if dsd <= 0.0 || rd <= 0.0 {
            if d == r {
                break;
            }
            d = r.clone();
            continue;
        }
        let a = rd / dsd;
        for q in 0..n {
            let p = d[q] * a;
            v[q] += p;
            x[q] += p * h;
        }
        r = residual(&x, &v);
        let delta_new = dot(&r, &r);
        let beta = delta_new / delta;
        delta = delta_new;
        for q in 0..n {
            d[q] = r[q] + d[q] * beta;
        }
    }
    Ok(Stepped::new(x, v, vec![0.0; m.constraint_rows()]))
}
