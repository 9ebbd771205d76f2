//! Central-difference vertex normals (paper eq. 1, with the grid spacing): the gradient at each
//! end of the vertex's edge, linearly interpolated at `t` (the classic marching-cubes normal).
//! One-sided differences at the grid border; undefined when any needed sample is missing, or
//! when the interpolated gradient is zero.

use super::{unit, EdgeVertex, Outcome};
use crate::grid::{Sample, ScalarGrid};

/// Central-difference gradient at grid point `p` (eq. 1 divided by the spacing); one-sided at
/// the border; `None` when a needed sample is missing.
pub fn gradient_at<T: Sample>(g: &ScalarGrid<T>, p: [usize; 3]) -> Option<[f64; 3]> {
    let f0 = g.value(p)?.to_f64();
    let mut grad = [0.0f64; 3];
    for m in 0..3 {
        let fwd = || g.neighbour(p, m, 1).map(T::to_f64);
        let bwd = || g.neighbour(p, m, -1).map(T::to_f64);
        let h = g.spacing[m].to_f64();
        grad[m] = if p[m] == 0 {
            (fwd()? - f0) / h
        } else if p[m] + 1 == g.dims[m] {
            (f0 - bwd()?) / h
        } else {
            (fwd()? - bwd()?) / (2.0 * h)
        };
    }
    Some(grad)
}

pub(crate) fn normal<T: Sample>(g: &ScalarGrid<T>, v: &EdgeVertex<T>) -> ([T; 3], Outcome) {
    let (Some(gp), Some(gq)) = (gradient_at(g, v.p), gradient_at(g, v.q)) else {
        return ([T::default(); 3], Outcome::Undefined);
    };
    let t = v.t.to_f64();
    let n = [0, 1, 2].map(|i| (1.0 - t) * gp[i] + t * gq[i]);
    match unit(n) {
        Some(u) => (u, Outcome::Defined),
        None => ([T::default(); 3], Outcome::Undefined),
    }
}
