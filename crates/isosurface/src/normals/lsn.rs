//! Locally Supported Normals (Nielson, Huang and Sylvester, "Approximating normals for marching
//! cubes applied to locally supported isosurfaces", Vis 2002), the paper's baseline,
//! **reconstructed** from the paper's description (section 2.2): a virtual mesh around each
//! vertex, independent of the MC triangulation, whose four face perps are averaged.
//!
//! For the vertex `V` on edge `e = (p, q)` along axis `a`, with `(a, b, c)` cyclic, the four
//! grid faces around `e` are taken in the order `d1 = +e_b`, `d2 = +e_c`, `d3 = -e_b`,
//! `d4 = -e_c`; face `F_m` has corners `p, q, q + d_m, p + d_m`. `W_m` is the MC vertex on the
//! other crossing edge of `F_m`; on an ambiguous face (all four edges cross) [`AmbiguousRule`]
//! decides which. A face outside the grid, or whose crossings cannot be computed (missing
//! samples), has no `W_m`. The perps are `N_m = (W_m - V) x (W_{m+1} - V)` for consecutive
//! present pairs (cyclically), and the normal is `sign(f(q) - f(p))` times their mean (the sign
//! orients it toward increasing `f`). A zero mean, as at degenerate triangles where the `W`
//! coincide with `V`, is reported as an undefined normal (the paper's Table 5), never replaced.

use super::{unit, EdgeVertex, Outcome};
use crate::edge::vertex_on_edge;
use crate::grid::{Sample, ScalarGrid};

/// Which vertex of an ambiguous face (four crossing edges) the virtual mesh connects `V` to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AmbiguousRule {
    /// The vertex on the face edge at the inside end of `V`'s edge (the inside corner is cut
    /// off on its own; the same assumption as our MC table).
    #[default]
    IsolateInside,
    /// The vertex on the face edge at the outside end of `V`'s edge.
    IsolateOutside,
}

wscg_math::params! {
    /// Options of the LSN baseline.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
    pub struct LsnParams {
        /// Ambiguous-face assumption.
        pub ambiguous_face: AmbiguousRule,
    }
}

impl LsnParams {
    /// Checks the ranges; the only field is a choice between two rules, each valid, so this
    /// always succeeds.
    pub fn validate(&self) -> wscg_math::Result<()> {
        Ok(())
    }
}

/// The MC vertex on the grid edge between `u` and `w` (adjacent grid points, any order).
fn vertex_between<T: Sample>(
    g: &ScalarGrid<T>,
    iso: T,
    u: [usize; 3],
    w: [usize; 3],
) -> Option<[T; 3]> {
    let axis = (0..3).find(|&i| u[i] != w[i])?;
    let lo = if u[axis] < w[axis] { u } else { w };
    vertex_on_edge(g, iso, lo, axis).map(|(pos, _)| pos)
}

/// `W_m` of the face spanned by the vertex's edge and direction `(axis, sign)`.
fn face_vertex<T: Sample>(
    g: &ScalarGrid<T>,
    iso: T,
    v: &EdgeVertex<T>,
    axis: usize,
    sign: isize,
    rule: AmbiguousRule,
) -> Option<[T; 3]> {
    let shift = |x: [usize; 3]| {
        let c = x[axis] as isize + sign;
        if c < 0 || c >= g.dims[axis] as isize {
            return None;
        }
        let mut y = x;
        y[axis] = c as usize;
        Some(y)
    };
    let (pd, qd) = (shift(v.p)?, shift(v.q)?);
    let at_q = vertex_between(g, iso, v.q, qd);
    let far = vertex_between(g, iso, pd, qd);
    let at_p = vertex_between(g, iso, v.p, pd);
    match (at_q, far, at_p) {
        (Some(w), None, None) | (None, Some(w), None) | (None, None, Some(w)) => Some(w),
        (Some(wq), Some(_), Some(wp)) => {
            let p_inside = v.fp >= iso;
            match (rule, p_inside) {
                (AmbiguousRule::IsolateInside, true) | (AmbiguousRule::IsolateOutside, false) => {
                    Some(wp)
                }
                _ => Some(wq),
            }
        }
        // No or two other crossings: impossible with known sides, so the face's samples are
        // incomplete.
        _ => None,
    }
}

pub(crate) fn normal<T: Sample>(
    g: &ScalarGrid<T>,
    iso: T,
    v: &EdgeVertex<T>,
    opts: &LsnParams,
) -> ([T; 3], Outcome) {
    let a = v.axis;
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let dirs = [(b, 1), (c, 1), (b, -1), (c, -1)];
    let w = dirs.map(|(axis, s)| face_vertex(g, iso, v, axis, s, opts.ambiguous_face));
    let o = v.position.map(T::to_f64);
    let rel = |x: [T; 3]| [0, 1, 2].map(|i| x[i].to_f64() - o[i]);
    let mut sum = [0.0f64; 3];
    let mut pairs = 0;
    for m in 0..4 {
        if let (Some(w1), Some(w2)) = (w[m], w[(m + 1) % 4]) {
            let (u, x) = (rel(w1), rel(w2));
            sum[0] += u[1] * x[2] - u[2] * x[1];
            sum[1] += u[2] * x[0] - u[0] * x[2];
            sum[2] += u[0] * x[1] - u[1] * x[0];
            pairs += 1;
        }
    }
    if pairs == 0 {
        return ([T::default(); 3], Outcome::Undefined);
    }
    let s = if v.fq > v.fp { 1.0 } else { -1.0 } / pairs as f64;
    match unit(sum.map(|x| s * x)) {
        Some(u) => (u, Outcome::Defined),
        None => ([T::default(); 3], Outcome::Undefined),
    }
}
