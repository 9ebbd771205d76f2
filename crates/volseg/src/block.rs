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

    /// Solves from the initial guess in `x` (`n·K`, interleaved; it must be zero on seeds and
    /// excluded nodes) and leaves the solution there.
    pub(crate) fn solve<T: Lane>(&self, x: &mut [T]) -> BlockOutcome {
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
        let mut r = vec![zero; n * k];
        let mut p = vec![zero; n * k];
        let mut q = vec![zero; n * k];
        // r = b − A x, p = M⁻¹ r; partial sums of ‖b‖², ‖r‖² and (r, M⁻¹ r) per label.
        let parts: Vec<Vec<f64>> = r
            .par_chunks_mut(CHUNK * k)
            .zip(p.par_chunks_mut(CHUNK * k))
            .enumerate()
            .map(|(c, (rc, pc))| {
                let mut acc = vec![0.0; 3 * k];
                let mut ax = vec![zero; k];
                for (a, (ri, pi)) in rc
                    .chunks_exact_mut(k)
                    .zip(pc.chunks_exact_mut(k))
                    .enumerate()
                {
                    let i = c * CHUNK + a;
                    if self.role[i] != UNKNOWN {
                        continue;
                    }
                    let d = self.kappa + self.g.degree(i);
                    self.apply_row(i, T::from_f64(d), x, &mut ax);
                    for (&j, &w) in self.g.neighbours(i).iter().zip(self.g.weights(i)) {
                        if j != NONE {
                            let s = self.role[j as usize];
                            if s != UNKNOWN && s != EXCLUDED && (s as usize) <= k {
                                ri[s as usize - 1] = ri[s as usize - 1] + T::from_f64(f64::from(w));
                            }
                        }
                    }
                    for l in 0..k {
                        let b = ri[l].to_f64();
                        acc[l] += b * b;
                        ri[l] = ri[l] - ax[l];
                        pi[l] = dinv[i] * ri[l];
                        let rv = ri[l].to_f64();
                        acc[k + l] += rv * rv;
                        acc[2 * k + l] += rv * pi[l].to_f64();
                    }
                }
                acc
            })
            .collect();
        let s = reduce(parts, 3 * k);
        let bnorm: Vec<f64> = s[..k].iter().map(|v| v.sqrt()).collect();
        let mut rnorm: Vec<f64> = s[k..2 * k].iter().map(|v| v.sqrt()).collect();
        let mut rz: Vec<f64> = s[2 * k..].to_vec();
        let mut out = BlockOutcome {
            iterations: vec![0; k],
            residuals: vec![0.0; k],
            converged: vec![false; k],
        };
        let mut active = vec![true; k];
        let check = |l: usize, rn: f64, out: &mut BlockOutcome, active: &mut [bool]| {
            out.residuals[l] = if bnorm[l] > 0.0 { rn / bnorm[l] } else { 0.0 };
            if bnorm[l] == 0.0 || rn <= self.tol * bnorm[l] {
                out.converged[l] = true;
                active[l] = false;
            }
        };
        for l in 0..k {
            check(l, rnorm[l], &mut out, &mut active);
            if bnorm[l] == 0.0 {
                // No seed of this label touches an unknown: the solution is exactly 0.
                x.par_chunks_mut(k).for_each(|xi| xi[l] = zero);
            }
        }
        let mut it = 0;
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
                    for ((ri, qi), &di) in rc.chunks_exact_mut(k).zip(qc.chunks_exact(k)).zip(dc) {
                        let di = di.to_f64();
                        for (l, ((rv, &qv), &a)) in ri.iter_mut().zip(qi).zip(&alpha).enumerate() {
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
                rnorm[l] = s[l].sqrt();
                out.iterations[l] = it;
                check(l, rnorm[l], &mut out, &mut active);
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
        out
    }
}
