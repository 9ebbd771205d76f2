//! The paper's estimator: a quadratic Bézier-Bernstein spline on one corner tetrahedron of each
//! cell sharing the vertex's edge (sections 3-4).
//!
//! On a tetrahedron `(v0, v1, v2, v3)` with data `f_m = f(v_m)`, the spline (eq. 2, Bernstein
//! basis eq. 4) has the control points of eq. 3 read with the data values,
//! `a_ijkl = (i f0 + j f1 + k f2 + l f3) / 2`: the degree-raised linear interpolant of the four
//! values (the seed writes eq. 3 with vertex symbols, which would give the domain points; the
//! paper states that the fit uses exactly four data values). Its directional derivative along
//! the edge `xi_phi = v_phi - v0` (eq. 7, obtained by one de Casteljau step, eq. 5) is then
//! `f_phi - f0` everywhere in the tetrahedron. The eight corner tetrahedra of a cell (Fig. 6)
//! are `(c, c + s_x e_x, c + s_y e_y, c + s_z e_z)` for a cell corner `c`, with `s_m = +1` when
//! `c` is on the cell's low side along `m` and `-1` otherwise (the paper's orienting
//! coefficients gamma), so the spline gradient in world axes is (eq. 8)
//! `grad = (s_x (f(c + s_x e_x) - f(c)) / h_x, s_y (...) / h_y, s_z (...) / h_z)`.
//!
//! The seed's eq. 8 keeps only the barycentric terms of the edge it differentiates, which on
//! the vertex's edge scales the two components across the edge by `lambda_0` and all three by
//! 1/2; [`SplineParams::eq8_literal`] reproduces it for experiments (the default is the exact
//! spline gradient).
//!
//! Of the two corner tetrahedra containing the vertex's edge `(p, q)`, the paper picks the one
//! its lookup-table rules choose from the cell's triangles ([`crate::tables::Selection`]); when
//! the chosen one lacks a sample the other is used. The vertex normal is the mean of the
//! gradients of the (up to four) cells sharing the edge, normalised. When no cell contributes,
//! a fallback uses `(f(q) - f(p)) / h_a` along the edge and one-sided differences across it, so
//! the spline normal is never zero (the paper's robustness claim).

use super::{unit, EdgeVertex, Outcome};
use crate::cell::{resolve_cell, CellState};
use crate::grid::{Sample, ScalarGrid};
use crate::tables::{case_table, corner_offset, edge_corners, edge_index, Selection};

/// Which corner tetrahedron of a cell gives the gradient.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TetSelection {
    /// The paper's rule from the cell's MC triangles (extended lookup table), ties to the
    /// nearer corner.
    #[default]
    MeshAware,
    /// The corner nearer to the vertex (the "static partition" the paper says is worse).
    NearestCorner,
    /// The mean of both candidate tetrahedra.
    AverageBoth,
}

wscg_math::params! {
    /// Options of the spline estimator; `Default` is the paper's method.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
    pub struct SplineParams {
        /// How the corner tetrahedron is chosen in each cell.
        pub selection: TetSelection,
        /// Use the seed's literal eq. 8 instead of the exact spline gradient.
        pub eq8_literal: bool,
        /// Normalise each cell's gradient before averaging (the paper averages raw gradients).
        pub normalize_before_mean: bool,
    }
}

impl SplineParams {
    /// Checks the ranges; the fields are a choice of tetrahedron and two switches, every
    /// value valid, so this always succeeds.
    pub fn validate(&self) -> wscg_math::Result<()> {
        Ok(())
    }
}

/// Gradient of the corner tetrahedron at local corner `k` of a cell with corner values `vals`
/// (NaN = missing) (eq. 8), or `None` when one of its four samples is missing. `lambda0` is the
/// barycentric weight of the corner at the vertex (used only by the literal eq. 8), `axis` the
/// vertex's edge axis.
#[inline(always)]
fn corner_gradient<T: Sample>(
    vals: &[T; 8],
    inv_h: [f64; 3],
    k: usize,
    axis: usize,
    lambda0: f64,
    literal: bool,
) -> Option<[f64; 3]> {
    let f0 = vals[k];
    if f0.is_nan() {
        return None;
    }
    let mut grad = [0.0; 3];
    for m in 0..3 {
        let n = k ^ (1 << m);
        let fm = vals[n];
        if fm.is_nan() {
            return None;
        }
        // s_m = +1 when the corner is on the low side along m.
        let s = if k >> m & 1 == 0 { 1.0 } else { -1.0 };
        let d = s * (fm.to_f64() - f0.to_f64()) * inv_h[m];
        grad[m] = if !literal {
            d
        } else if m == axis {
            0.5 * d
        } else {
            0.5 * lambda0 * d
        };
    }
    Some(grad)
}

/// Adds to `acc` the spline gradient(s) one active cell gives the vertex on its local edge
/// `le` at parameter `t` (from the edge's low end); returns how many were added (0, 1, or 2
/// for [`TetSelection::AverageBoth`]). `vals` are the cell's corner values (NaN = missing).
#[inline(always)]
pub(crate) fn cell_contribution<T: Sample>(
    vals: &[T; 8],
    config: u8,
    le: usize,
    t: f64,
    inv_h: [f64; 3],
    opts: &SplineParams,
    acc: &mut [f64; 3],
) -> usize {
    let a = le / 4;
    let (kp, kq) = edge_corners(le);
    // Barycentric weight of each candidate corner at the vertex.
    let lam = |k: usize| if k == kp { 1.0 - t } else { t };
    let grad = |k: usize| corner_gradient(vals, inv_h, k, a, lam(k), opts.eq8_literal);
    let mut add = |g: [f64; 3]| {
        let w = if opts.normalize_before_mean {
            let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
            if n > 0.0 {
                1.0 / n
            } else {
                return 0;
            }
        } else {
            1.0
        };
        for i in 0..3 {
            acc[i] += w * g[i];
        }
        1
    };
    let nearer = if t <= 0.5 { (kp, kq) } else { (kq, kp) };
    let (first, second) = match opts.selection {
        TetSelection::AverageBoth => {
            return grad(kp).map_or(0, &mut add) + grad(kq).map_or(0, &mut add);
        }
        TetSelection::MeshAware => match case_table()[config as usize].select[le] {
            Selection::Low => (kp, kq),
            Selection::High => (kq, kp),
            Selection::Nearer => nearer,
        },
        TetSelection::NearestCorner => nearer,
    };
    grad(first).or_else(|| grad(second)).map_or(0, add)
}

/// Reciprocal spacing.
#[inline]
pub(crate) fn inverse_spacing<T: Sample>(g: &ScalarGrid<T>) -> [f64; 3] {
    g.spacing.map(|h| 1.0 / h.to_f64())
}

/// Block index (see [`normal`]) of each corner of the cell `db + 2 dc` around an edge along
/// axis `a`: `BLOCK_INDEX[a][db + 2 dc][corner]`.
const BLOCK_INDEX: [[[u8; 8]; 4]; 3] = {
    let mut t = [[[0u8; 8]; 4]; 3];
    let mut a = 0;
    while a < 3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let mut cell = 0;
        while cell < 4 {
            let (db, dc) = (cell & 1, cell >> 1);
            let mut corner = 0;
            while corner < 8 {
                let o = corner_offset(corner);
                t[a][cell][corner] = (o[a] + 2 * ((o[b] + 1 - db) + 3 * (o[c] + 1 - dc))) as u8;
                corner += 1;
            }
            cell += 1;
        }
        a += 1;
    }
    t
};

pub(crate) fn normal<T: Sample>(
    g: &ScalarGrid<T>,
    iso: T,
    v: &EdgeVertex<T>,
    opts: &SplineParams,
) -> ([T; 3], Outcome) {
    let a = v.axis;
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let inv_h = inverse_spacing(g);
    // The 2 x 3 x 3 samples around the edge, read once: block index i + 2 (j + 3 k) for the
    // offsets i along a (0, 1), j - 1 along b and k - 1 along c.
    let stride = [1isize, g.dims[0] as isize, (g.dims[0] * g.dims[1]) as isize];
    let base = g.index(v.p) as isize;
    let mut vals = [T::NAN; 18];
    let mut flags = [0u8; 18];
    let inside_b = |d: isize| (0..g.dims[b] as isize).contains(&(v.p[b] as isize + d));
    let inside_c = |d: isize| (0..g.dims[c] as isize).contains(&(v.p[c] as isize + d));
    for k in 0..3 {
        for j in 0..3 {
            let (db, dc) = (j as isize - 1, k as isize - 1);
            if !inside_b(db) || !inside_c(dc) {
                continue;
            }
            for i in 0..2 {
                let idx =
                    (base + i as isize * stride[a] + db * stride[b] + dc * stride[c]) as usize;
                vals[i + 2 * (j + 3 * k)] = g.values[idx];
                flags[i + 2 * (j + 3 * k)] = g.flags(idx, iso);
            }
        }
    }
    let mut sum = [0.0f64; 3];
    let mut count = 0usize;
    for dc in 0..2 {
        for db in 0..2 {
            // The cell with low corner p - db e_b - dc e_c, when inside the grid.
            if !inside_b(-(db as isize)) || !inside_b(1 - db as isize) {
                continue;
            }
            if !inside_c(-(dc as isize)) || !inside_c(1 - dc as isize) {
                continue;
            }
            let mut cf = [0u8; 8];
            let mut cv = [T::default(); 8];
            for (corner, &bi) in BLOCK_INDEX[a][db + 2 * dc].iter().enumerate() {
                cf[corner] = flags[bi as usize];
                cv[corner] = vals[bi as usize];
            }
            let CellState::Active(config) = resolve_cell(&cf) else {
                continue;
            };
            let le = edge_index(a, db, dc);
            count += cell_contribution(&cv, config, le, v.t.to_f64(), inv_h, opts, &mut sum);
        }
    }
    if count > 0 {
        if let Some(u) = unit(sum) {
            return (u, Outcome::Defined);
        }
    }
    (fallback(g, v), Outcome::Fallback)
}

/// The fallback normal: `(f(q) - f(p)) / h_a` along the edge (never zero on a crossing edge),
/// and across it the mean of the one-sided differences available at `p` and `q`.
pub(crate) fn fallback<T: Sample>(g: &ScalarGrid<T>, v: &EdgeVertex<T>) -> [T; 3] {
    let a = v.axis;
    let (fp, fq) = (v.fp.to_f64(), v.fq.to_f64());
    let mut n = [0.0f64; 3];
    n[a] = (fq - fp) / g.spacing[a].to_f64();
    for m in (0..3).filter(|&m| m != a) {
        let mut sum = 0.0;
        let mut k = 0;
        for (end, f0) in [(v.p, fp), (v.q, fq)] {
            for s in [1isize, -1] {
                if let Some(f1) = g.neighbour(end, m, s) {
                    sum += s as f64 * (f1.to_f64() - f0) / g.spacing[m].to_f64();
                    k += 1;
                }
            }
        }
        if k > 0 {
            n[m] = sum / k as f64;
        }
    }
    unit(n).unwrap_or_else(|| {
        let mut u = [T::default(); 3];
        u[a] = T::from_f64((fq - fp).signum());
        u
    })
}
