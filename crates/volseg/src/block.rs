//! The K-block Jacobi-preconditioned conjugate gradient of spec section 2.2 step 6: the K
//! systems `(L_U + κ I) x_k = −Bᵀ m_k` (Grady 2006; paper section 2.3) advance in lockstep,
//! so one sweep over the bone graph serves every label. Vectors are interleaved per node
//! (`v[i·K + k]`), stored as `f32` or `f64`; dot products accumulate in `f64` per fixed-size
//! chunk of nodes and the chunk sums are added in order, so results do not depend on the
//! number of threads. A label stops when `‖r_k‖ ≤ tol ‖b_k‖`; the others go on.
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

/// One K-block solve: the graph, the node roles (see [`UNKNOWN`], [`EXCLUDED`]; other values
/// are seed labels `1..=K`) and the stopping rule.
pub(crate) struct Block<'a> {
    pub g: &'a BoneGraph,
    pub role: &'a [u16],
    pub k: usize,
    pub kappa: f64,
    pub tol: f64,
    pub max_iter: usize,
    /// Jacobi preconditioner (`false`: plain CG).
    pub jacobi: bool,
}

/// Per-label outcome of [`Block::solve`].
pub(crate) struct BlockOutcome {
    pub iterations: Vec<usize>,
    pub residuals: Vec<f64>,
    pub converged: Vec<bool>,
}

/// A zeroed vector of `len` values, or an error when the memory is not available (instead of
/// aborting the process).
pub(crate) fn try_zeros<T: Default + Clone>(len: usize) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        Error::LimitExceeded(format!(
            "cannot allocate {} MB for the random-walk vectors (nodes x labels too large)",
            len.saturating_mul(std::mem::size_of::<T>()) / 1_000_000
        ))
    })?;
    v.resize(len, T::default());
    Ok(v)
}

/// Sums per-chunk partial vectors in chunk order.
fn reduce(parts: Vec<Vec<f64>>, len: usize) -> Vec<f64> {
    let mut s = vec![0.0; len];
    for p in parts {
        for (a, b) in s.iter_mut().zip(p) {
            *a += b;
        }
    }
    s
}

impl Block<'_> {
    /// `(A v)_i` for every lane of unknown node `i` into `out`.
    #[inline]
    fn apply_row<T: Lane>(&self, i: usize, d: T, v: &[T], out: &mut [T]) {
        let k = self.k;
        let vi = &v[i * k..(i + 1) * k];
        for (o, &x) in out.iter_mut().zip(vi) {
            *o = d * x;
        }
        for (&j, &w) in self.g.neighbours(i).iter().zip(self.g.weights(i)) {
            if j != NONE {
                let w = T::from_f64(f64::from(w));
                let vj = &v[j as usize * k..(j as usize + 1) * k];
                for (o, &x) in out.iter_mut().zip(vj) {
                    *o = *o - w * x;
                }
            }
        }
    }

    /// `r = b − A x` and `p = M⁻¹ r` on every lane; returns the per-label sums of `‖b‖²`,
    /// `‖r‖²` and `(r, M⁻¹ r)` (`3K` values).
    fn residual<T: Lane>(&self, x: &[T], dinv: &[T], r: &mut [T], p: &mut [T]) -> Vec<f64> {
        let k = self.k;
        let zero = T::default();
        let parts: Vec<Vec<f64>> = r
            .par_chunks_mut(CHUNK * k)
            .zip(p.par_chunks_mut(CHUNK * k))
            .enumerate()
            .map(|(c, (rc, pc))| {
                let mut acc = vec![0.0; 3 * k];
                // In f64 whatever T is: the true residual decides convergence.
                let (mut ax, mut b) = (vec![0.0f64; k], vec![0.0f64; k]);
                for (a, (ri, pi)) in rc
                    .chunks_exact_mut(k)
                    .zip(pc.chunks_exact_mut(k))
                    .enumerate()
                {
                    let i = c * CHUNK + a;
                    ri.fill(zero);
                    pi.fill(zero);
                    if self.role[i] != UNKNOWN {
                        continue;
                    }
                    let d = self.kappa + self.g.degree(i);
                    for (o, v) in ax.iter_mut().zip(&x[i * k..(i + 1) * k]) {
                        *o = d * v.to_f64();
                    }
                    b.fill(0.0);
                    for (&j, &w) in self.g.neighbours(i).iter().zip(self.g.weights(i)) {
                        if j == NONE {
                            continue;
                        }
                        let (j, w) = (j as usize, f64::from(w));
                        for (o, v) in ax.iter_mut().zip(&x[j * k..(j + 1) * k]) {
                            *o -= w * v.to_f64();
                        }
                        // b_i = Σ of the weights to seeds of each label.
                        let s = self.role[j];
                        if s != UNKNOWN && s != EXCLUDED && (s as usize) <= k {
                            b[s as usize - 1] += w;
                        }
                    }
                    let di = dinv[i].to_f64();
                    for l in 0..k {
                        let rv = b[l] - ax[l];
                        ri[l] = T::from_f64(rv);
                        pi[l] = T::from_f64(di * rv);
                        acc[l] += b[l] * b[l];
                        acc[k + l] += rv * rv;
                        acc[2 * k + l] += rv * rv * di;
                    }
                }
                acc
            })
            .collect();
        reduce(parts, 3 * k)
    }

    /// Solves from the initial guess in `x` (`n·K`, interleaved; it must be zero on seeds and
    /// excluded nodes) and leaves the solution there. A label counts as converged only when
    /// its *true* residual `b − A x` meets the tolerance: when the recursively updated
    /// residuals of all running labels say so, the true ones are computed and CG restarts from
    /// `x` for the labels that fall short (rounding in `f32` makes the two drift apart at tight
    /// tolerances). At `max_iter`, or when a restart no longer halves the true residuals (the
    /// precision's floor), the remaining labels are reported as not converged.
    ///
    /// Errors: the vectors (`3 n K` values besides `x`) cannot be allocated.
    pub(crate) fn solve<T: Lane>(&self, x: &mut [T]) -> Result<BlockOutcome> {
        let (n, k) = (self.g.len(), self.k);
        debug_assert_eq!(x.len(), n * k);
        let zero = T::default();
        // Preconditioner 1 / d_i on unknowns, 0 elsewhere (so p = dinv r stays 0 there).
        let dinv: Vec<T> = (0..n)
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|i| {
                if self.role[i] != UNKNOWN {
                    zero
                } else if self.jacobi {
                    T::from_f64(1.0 / (self.kappa + self.g.degree(i)))
                } else {
                    T::from_f64(1.0)
                }
            })
            .collect();
        let mut r = try_zeros::<T>(n * k)?;
        let mut p = try_zeros::<T>(n * k)?;
        let mut q = try_zeros::<T>(n * k)?;
        let mut out = BlockOutcome {
            iterations: vec![0; k],
            residuals: vec![0.0; k],
            converged: vec![false; k],
        };
        let mut it = 0;
        let (mut restarts, mut last_true) = (0usize, vec![f64::INFINITY; k]);
        loop {
            let s = self.residual(x, &dinv, &mut r, &mut p);
            let bnorm: Vec<f64> = s[..k].iter().map(|v| v.sqrt()).collect();
            let mut rz: Vec<f64> = s[2 * k..].to_vec();
            let mut active = vec![false; k];
            for l in 0..k {
                let rn = s[k + l].sqrt();
                out.residuals[l] = if bnorm[l] > 0.0 { rn / bnorm[l] } else { 0.0 };
                out.converged[l] = bnorm[l] == 0.0 || rn <= self.tol * bnorm[l];
                active[l] = !out.converged[l];
                if bnorm[l] == 0.0 && it == 0 {
                    // No seed of this label touches an unknown: the solution is exactly 0.
                    x.par_chunks_mut(k).for_each(|xi| xi[l] = zero);
                }
            }
            // Stop when a restart no longer helps: every running label's true residual
            // failed to halve since the previous restart (the precision's floor).
            let stalled =
                restarts > 0 && (0..k).all(|l| !active[l] || out.residuals[l] > 0.5 * last_true[l]);
            if !active.iter().any(|&a| a) || it >= self.max_iter || stalled {
                break;
            }
            last_true.copy_from_slice(&out.residuals);
            restarts += 1;
            let check = |l: usize, rn: f64, active: &mut [bool]| {
                if rn <= self.tol * bnorm[l] {
                    active[l] = false;
                }
            };
            while active.iter().any(|&a| a) && it < self.max_iter {
                it += 1;
                // q = A p, (p, q).
                let parts: Vec<Vec<f64>> = q
                    .par_chunks_mut(CHUNK * k)
                    .enumerate()
                    .map(|(c, qc)| {
                        let mut acc = vec![0.0; k];
                        for (a, qi) in qc.chunks_exact_mut(k).enumerate() {
                            let i = c * CHUNK + a;
                            if self.role[i] != UNKNOWN {
                                continue;
                            }
                            let d = T::from_f64(self.kappa + self.g.degree(i));
                            self.apply_row(i, d, &p, qi);
                            for (l, (qv, pv)) in qi.iter().zip(&p[i * k..(i + 1) * k]).enumerate() {
                                acc[l] += qv.to_f64() * pv.to_f64();
                            }
                        }
                        acc
                    })
                    .collect();
                let pq = reduce(parts, k);
                let alpha: Vec<T> = (0..k)
                    .map(|l| {
                        if active[l] && pq[l] > 0.0 {
                            T::from_f64(rz[l] / pq[l])
                        } else {
                            zero
                        }
                    })
                    .collect();
                // r −= α q, ‖r‖², (r, M⁻¹ r).
                let parts: Vec<Vec<f64>> = r
                    .par_chunks_mut(CHUNK * k)
                    .zip(q.par_chunks(CHUNK * k))
                    .zip(dinv.par_chunks(CHUNK))
                    .map(|((rc, qc), dc)| {
                        let mut acc = vec![0.0; 2 * k];
                        for ((ri, qi), &di) in
                            rc.chunks_exact_mut(k).zip(qc.chunks_exact(k)).zip(dc)
                        {
                            let di = di.to_f64();
                            for (l, ((rv, &qv), &a)) in
                                ri.iter_mut().zip(qi).zip(&alpha).enumerate()
                            {
                                *rv = *rv - a * qv;
                                let r2 = rv.to_f64() * rv.to_f64();
                                acc[l] += r2;
                                acc[k + l] += r2 * di;
                            }
                        }
                        acc
                    })
                    .collect();
                let s = reduce(parts, 2 * k);
                let mut beta = vec![zero; k];
                for l in 0..k {
                    if !active[l] {
                        continue;
                    }
                    out.iterations[l] = it;
                    check(l, s[l].sqrt(), &mut active);
                    if rz[l] > 0.0 {
                        beta[l] = T::from_f64(s[k + l] / rz[l]);
                    }
                    rz[l] = s[k + l];
                }
                // x += α p with the old p, then p = M⁻¹ r + β p on the labels still running.
                x.par_chunks_mut(CHUNK * k)
                    .zip(p.par_chunks_mut(CHUNK * k))
                    .zip(r.par_chunks(CHUNK * k))
                    .zip(dinv.par_chunks(CHUNK))
                    .for_each(|(((xc, pc), rc), dc)| {
                        for (((xi, pi), ri), &di) in xc
                            .chunks_exact_mut(k)
                            .zip(pc.chunks_exact_mut(k))
                            .zip(rc.chunks_exact(k))
                            .zip(dc)
                        {
                            for l in 0..k {
                                xi[l] = xi[l] + alpha[l] * pi[l];
                                if active[l] {
                                    pi[l] = di * ri[l] + beta[l] * pi[l];
                                }
                            }
                        }
                    });
            }
        }
        Ok(out)
    }
}
