//! The K-block Jacobi-preconditioned conjugate gradient (the paper's solver, section 2.5, run
//! on all labels at once): the K systems `(L_U + κ I) x_k = −Bᵀ m_k` (Grady 2006; paper
//! section 2.4) advance in lockstep,
//! so one sweep over the bone graph serves a group of up to [`MAX_LANES`] labels. Vectors
//! hold a fixed-size array of lanes per node (`[T; L]`, `L` in 1, 2, 4, 8, 16, compiled for
//! each, so the lane loops become SIMD), stored as `f32` or `f64`; dot products accumulate in
//! `f64` per fixed-size chunk of nodes and the chunk sums are added in order, so results do
//! not depend on the number of threads. A label stops when `‖r_k‖ ≤ tol ‖b_k‖`; the others
//! go on.
//!
//! Matrix-free: `(A v)_i = d_i v_i − Σ_{j~i, j∈U} w_ij v_j` with `d_i = κ + Σ_{j~i} w_ij`
//! (edges to seeds included). The iteration vectors are kept zero on seeds and on excluded
//! nodes, so neighbour sums over all graph neighbours equal the sums over unknowns.

use std::ops::{Add, Mul, Sub};

use rayon::prelude::*;
use wscg_math::volume::Real;

use wscg_math::{Error, Result};

use crate::graph::{BoneGraph, NONE};

/// Nodes per reduction chunk (fixed: the reduction order must not depend on the pool).
const CHUNK: usize = 2048;

/// Role of a node in a solve: an unknown, a seed of a label, or excluded.
pub(crate) const UNKNOWN: u16 = 0;
/// Role of a node that no seed can reach (its probabilities are 0).
pub(crate) const EXCLUDED: u16 = u16::MAX;

/// A scalar the block solver runs in (`f32` for speed and memory, `f64` for accuracy).
pub(crate) trait Lane:
    Real + Default + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self>
{
}
impl Lane for f32 {}
impl Lane for f64 {}

/// A vector of `len` copies of `value`, or an error when the memory is not available
/// (instead of aborting the process).
pub(crate) fn try_filled<T: Clone>(len: usize, value: T) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        Error::LimitExceeded(format!(
            "cannot allocate {} MB for the random-walk vectors (nodes x labels too large)",
            len.saturating_mul(std::mem::size_of::<T>()) / 1_000_000
        ))
    })?;
    v.resize(len, value);
    Ok(v)
}

/// Most labels solved in one sweep.
pub(crate) const MAX_LANES: usize = 16;

/// Per-lane sums of one chunk (up to three quantities).
type Sums<const L: usize> = [[f64; L]; 3];

/// Sums per-chunk partial sums in chunk order.
fn reduce<const L: usize>(parts: Vec<Sums<L>>) -> Sums<L> {
    let mut s = [[0.0; L]; 3];
    for p in parts {
        for (a, b) in s.iter_mut().zip(p) {
            for (x, y) in a.iter_mut().zip(b) {
                *x += y;
            }
        }
    }
    s
}

/// One block solve: the graph, the node roles (see [`UNKNOWN`], [`EXCLUDED`]; other values
/// are seed labels), the lane of every label, and the stopping rule.
pub(crate) struct Block<'a> {
    pub g: &'a BoneGraph,
    pub role: &'a [u16],
    /// Lane of every label (index = label; `u8::MAX` = not in this block).
    pub lane_of_label: &'a [u8],
    /// Lanes carrying a label (the others, up to `L`, stay zero).
    pub used: usize,
    /// Hand back the labels still running once at most a quarter of the lanes are (so that
    /// the caller continues them in a narrower block instead of sweeping idle lanes).
    pub shrink: bool,
    pub kappa: f64,
    pub tol: f64,
    pub max_iter: usize,
    /// Jacobi preconditioner (`false`: plain CG).
    pub jacobi: bool,
}

/// Per-lane outcome of [`Block::solve`] (`used` entries).
pub(crate) struct BlockOutcome {
    pub iterations: Vec<usize>,
    pub residuals: Vec<f64>,
    pub converged: Vec<bool>,
    /// Lanes handed back unfinished (see [`Block::shrink`]).
    pub unfinished: Vec<bool>,
}

impl Block<'_> {
    /// Lane of seed role `s`, if it carries one of this block's labels.
    #[inline]
    fn lane_of(&self, s: u16) -> Option<usize> {
        // UNKNOWN (0) maps to no lane; EXCLUDED lies beyond the table.
        match self.lane_of_label.get(s as usize) {
            Some(&l) if l != u8::MAX => Some(l as usize),
            _ => None,
        }
    }

    /// `(A v)_i = d_i v_i − Σ_j w_ij v_j` on every lane of unknown node `i`; `v` has one extra
    /// zero entry at index `n` that stands in for missing neighbours (weight 0).
    #[inline(always)]
    fn apply_row<T: Lane, const L: usize>(&self, i: usize, d: T, v: &[[T; L]]) -> [T; L] {
        let n = self.g.len() as u32;
        let mut out = v[i].map(|x| d * x);
        for (&j, &w) in self.g.neighbours(i).iter().zip(self.g.weights(i)) {
            let j = if j == NONE { n } else { j };
            let w = T::from_f64(f64::from(w));
            let vj = &v[j as usize];
            for (o, &x) in out.iter_mut().zip(vj) {
                *o = *o - w * x;
            }
        }
        out
    }

    /// `r = b − A x` and `p = M⁻¹ r` on every lane, the residual in `f64` whatever `T` is
    /// (it decides convergence); returns the per-lane sums of `‖b‖²`, `‖r‖²`, `(r, M⁻¹ r)`.
    fn residual<T: Lane, const L: usize>(
        &self,
        x: &[[T; L]],
        dinv: &[T],
        r: &mut [[T; L]],
        p: &mut [[T; L]],
    ) -> Sums<L> {
        let n = self.g.len();
        let zero = [T::default(); L];
        let parts: Vec<Sums<L>> = r[..n]
            .par_chunks_mut(CHUNK)
            .zip(p[..n].par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(c, (rc, pc))| {
                let mut acc = [[0.0; L]; 3];
                for (a, (ri, pi)) in rc.iter_mut().zip(pc.iter_mut()).enumerate() {
                    let i = c * CHUNK + a;
                    *ri = zero;
                    *pi = zero;
                    if self.role[i] != UNKNOWN {
                        continue;
                    }
                    let d = self.kappa + self.g.degree(i);
                    let mut ax = x[i].map(|v| d * v.to_f64());
                    let mut b = [0.0f64; L];
                    for (&j, &w) in self.g.neighbours(i).iter().zip(self.g.weights(i)) {
                        if j == NONE {
                            continue;
                        }
                        let (j, w) = (j as usize, f64::from(w));
                        for (o, v) in ax.iter_mut().zip(&x[j]) {
                            *o -= w * v.to_f64();
                        }
                        // b_i = Σ of the weights to seeds of each lane's label.
                        if let Some(l) = self.lane_of(self.role[j]) {
                            b[l] += w;
                        }
                    }
                    let di = dinv[i].to_f64();
                    for l in 0..L {
                        let rv = b[l] - ax[l];
                        ri[l] = T::from_f64(rv);
                        pi[l] = T::from_f64(di * rv);
                        acc[0][l] += b[l] * b[l];
                        acc[1][l] += rv * rv;
                        acc[2][l] += rv * rv * di;
                    }
                }
                acc
            })
            .collect();
        reduce(parts)
    }

    /// Solves from the initial guess in `x` (`n + 1` entries, the last one zero; zero on
    /// seeds and excluded nodes) and leaves the solution there. A label counts as converged
    /// only when its *true* residual `b − A x` meets the tolerance: when the recursively
    /// updated residuals of all running labels say so, the true ones are computed and CG
    /// restarts from `x` for the labels that fall short (rounding in `f32` makes the two drift
    /// apart at tight tolerances). At `max_iter`, or when a restart no longer halves the true
    /// residuals (the precision's floor), the remaining labels are reported as not converged.
    ///
    /// Errors: the vectors (3 more of the size of `x`) cannot be allocated.
    pub(crate) fn solve<T: Lane, const L: usize>(&self, x: &mut [[T; L]]) -> Result<BlockOutcome> {
        let n = self.g.len();
        debug_assert_eq!(x.len(), n + 1);
        debug_assert!(self.used <= L);
        let zero = T::default();
        // Preconditioner 1 / d_i on unknowns, 0 elsewhere (so p = dinv r stays 0 there), and
        // the diagonal d_i = κ + Σ_j w_ij.
        let (dinv, diag): (Vec<T>, Vec<T>) = (0..n)
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|i| {
                let d = self.kappa + self.g.degree(i);
                if self.role[i] != UNKNOWN {
                    (zero, zero)
                } else if self.jacobi {
                    (T::from_f64(1.0 / d), T::from_f64(d))
                } else {
                    (T::from_f64(1.0), T::from_f64(d))
                }
            })
            .unzip();
        let mut r = try_filled(n + 1, [T::default(); L])?;
        let mut p = try_filled(n + 1, [T::default(); L])?;
        let mut q = try_filled(n, [T::default(); L])?;
        let used = self.used;
        let mut out = BlockOutcome {
            iterations: vec![0; used],
            residuals: vec![0.0; used],
            converged: vec![false; used],
            unfinished: vec![false; used],
        };
        let mut it = 0;
        let (mut restarts, mut last_true) = (0usize, [f64::INFINITY; L]);
        let mut handed_back = false;
        let mut res = [0.0f64; L];
        loop {
            let s = self.residual(x, &dinv, &mut r, &mut p);
            let bnorm = s[0].map(f64::sqrt);
            let mut rz = s[2];
            let mut active = [false; L];
            for l in 0..L {
                let rn = s[1][l].sqrt();
                res[l] = if bnorm[l] > 0.0 { rn / bnorm[l] } else { 0.0 };
                active[l] = !(bnorm[l] == 0.0 || rn <= self.tol * bnorm[l]);
                if bnorm[l] == 0.0 && it == 0 {
                    // No seed of this label touches an unknown: the solution is exactly 0.
                    x.par_iter_mut().for_each(|xi| xi[l] = zero);
                }
            }
            // Stop when all labels are done, at the iteration cap, when handing labels back
            // (the caller continues them in a narrower block, warm-started from x), or when a
            // restart no longer helps: every running label's true residual failed to halve
            // since the previous restart (the precision's floor).
            let done = !active.iter().any(|&a| a) || it >= self.max_iter;
            let stalled = restarts > 0 && (0..L).all(|l| !active[l] || res[l] > 0.5 * last_true[l]);
            if done || handed_back || stalled {
                for l in 0..used {
                    out.residuals[l] = res[l];
                    out.converged[l] = !active[l];
                    out.unfinished[l] = active[l] && handed_back && !done;
                }
                break;
            }
            last_true = res;
            restarts += 1;
            while active.iter().any(|&a| a) && it < self.max_iter {
                wscg_math::cancel::check()?;
                if self.shrink && L >= 4 && 4 * active.iter().filter(|&&a| a).count() <= L {
                    handed_back = true;
                    break;
                }
                it += 1;
                // q = A p, (p, q).
                let parts: Vec<Sums<L>> = q
                    .par_chunks_mut(CHUNK)
                    .enumerate()
                    .map(|(c, qc)| {
                        let mut acc = [[0.0; L]; 3];
                        for (a, qi) in qc.iter_mut().enumerate() {
                            let i = c * CHUNK + a;
                            if self.role[i] != UNKNOWN {
                                continue;
                            }
                            *qi = self.apply_row(i, diag[i], &p);
                            for l in 0..L {
                                acc[0][l] += qi[l].to_f64() * p[i][l].to_f64();
                            }
                        }
                        acc
                    })
                    .collect();
                let pq = reduce(parts)[0];
                let alpha: [T; L] = std::array::from_fn(|l| {
                    if active[l] && pq[l] > 0.0 {
                        T::from_f64(rz[l] / pq[l])
                    } else {
                        zero
                    }
                });
                // r −= α q, ‖r‖², (r, M⁻¹ r).
                let parts: Vec<Sums<L>> = r[..n]
                    .par_chunks_mut(CHUNK)
                    .zip(q.par_chunks(CHUNK))
                    .zip(dinv.par_chunks(CHUNK))
                    .map(|((rc, qc), dc)| {
                        let mut acc = [[0.0; L]; 3];
                        for ((ri, qi), &di) in rc.iter_mut().zip(qc).zip(dc) {
                            let di = di.to_f64();
                            for l in 0..L {
                                ri[l] = ri[l] - alpha[l] * qi[l];
                                let r2 = ri[l].to_f64() * ri[l].to_f64();
                                acc[0][l] += r2;
                                acc[1][l] += r2 * di;
                            }
                        }
                        acc
                    })
                    .collect();
                let s = reduce(parts);
                let mut beta = [zero; L];
                for l in 0..L {
                    if !active[l] {
                        continue;
                    }
                    if l < used {
                        out.iterations[l] = it;
                    }
                    if s[0][l].sqrt() <= self.tol * bnorm[l] {
                        active[l] = false;
                    }
                    if rz[l] > 0.0 {
                        beta[l] = T::from_f64(s[1][l] / rz[l]);
                    }
                    rz[l] = s[1][l];
                }
                // x += α p with the old p, then p = M⁻¹ r + β p on the labels still running
                // (a finished label's p is zeroed so that its α stays 0).
                let keep: [T; L] =
                    std::array::from_fn(|l| T::from_f64(f64::from(u8::from(active[l]))));
                x[..n]
                    .par_chunks_mut(CHUNK)
                    .zip(p[..n].par_chunks_mut(CHUNK))
                    .zip(r[..n].par_chunks(CHUNK))
                    .zip(dinv.par_chunks(CHUNK))
                    .for_each(|(((xc, pc), rc), dc)| {
                        for (((xi, pi), ri), &di) in xc.iter_mut().zip(pc).zip(rc).zip(dc) {
                            for l in 0..L {
                                xi[l] = xi[l] + alpha[l] * pi[l];
                                pi[l] = keep[l] * (di * ri[l] + beta[l] * pi[l]);
                            }
                        }
                    });
            }
        }
        Ok(out)
    }
}
