//! Random walks on the bone graph (Grady 2006; paper section 2.3): one combinatorial
//! Dirichlet problem per label, Jacobi-preconditioned CG, warm start, maximum-probability
//! labelling.

use std::time::Instant;

use rayon::prelude::*;
use wscg_math::sparse::{pcg, InitialGuess, Jacobi, LinOp, PcgOptions};
use wscg_math::{Error, Result, Volume};

use crate::graph::{BoneGraph, NONE};
use crate::params::RwParams;

/// Outcome of one [`RwSession::solve`], per label `1..=K`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// CG iterations.
    pub iterations: Vec<usize>,
    /// Final relative residuals `‖r‖ / ‖b‖`.
    pub residuals: Vec<f64>,
    /// Whether the tolerance was met.
    pub converged: Vec<bool>,
    /// Wall-clock seconds.
    pub seconds: Vec<f64>,
}

/// The system `(L_U + κ I) x = b` on the unseeded nodes, applied matrix-free on the graph.
struct System<'a> {
    g: &'a BoneGraph,
    /// Compact index of every node, [`NONE`] for seeds.
    u_of_node: Vec<u32>,
    /// Node of every unknown.
    node_of_u: Vec<u32>,
    /// Diagonal `κ + Σ_j w_ij` (edges to seeds included).
    diag: Vec<f64>,
}

impl LinOp for System<'_> {
    fn nrows(&self) -> usize {
        self.node_of_u.len()
    }
    fn ncols(&self) -> usize {
        self.node_of_u.len()
    }
    fn apply(&self, x: &[f64], y: &mut [f64]) {
        y.par_iter_mut()
            .enumerate()
            .with_min_len(4096)
            .for_each(|(a, ya)| {
                let i = self.node_of_u[a] as usize;
                let mut s = self.diag[a] * x[a];
                for (&j, &w) in self.g.neighbours(i).iter().zip(self.g.weights(i)) {
                    if j != NONE {
                        let u = self.u_of_node[j as usize];
                        if u != NONE {
                            s -= w * x[u as usize];
                        }
                    }
                }
                *ya = s;
            });
    }
}

/// An interactive segmentation: the graph, the seeds placed so far and the last solution.
#[derive(Clone, Debug)]
pub struct RwSession {
    graph: BoneGraph,
    params: RwParams,
    /// Seed label of every node (0 = unseeded).
    seeds: Vec<u16>,
    /// Probabilities per label (index `k - 1`) and node, from the last solve.
    x: Vec<Vec<f64>>,
}

impl RwSession {
    /// A session on `graph`. Errors: invalid parameters.
    pub fn new(graph: BoneGraph, params: RwParams) -> Result<Self> {
        params.validate()?;
        let n = graph.len();
        Ok(Self {
            graph,
            params,
            seeds: vec![0; n],
            x: Vec::new(),
        })
    }

    /// The graph.
    pub fn graph(&self) -> &BoneGraph {
        &self.graph
    }

    /// Replaces all seeds by the non-zero voxels of `seeds` (labels 1..=K) that are bone;
    /// returns how many seed voxels lie on the graph. Errors: shape mismatch.
    pub fn set_seeds(&mut self, seeds: &Volume<u16>) -> Result<usize> {
        if seeds.dims() != self.graph.dims() {
            return Err(Error::ShapeMismatch(format!(
                "seeds are {:?}, the CT {:?}",
                seeds.dims(),
                self.graph.dims()
            )));
        }
        self.seeds.iter_mut().for_each(|s| *s = 0);
        let mut used = 0;
        for (v, &l) in seeds.data().iter().enumerate() {
            if l != 0 {
                if let Some(i) = self.graph.node(v) {
                    self.seeds[i] = l;
                    used += 1;
                }
            }
        }
        Ok(used)
    }

    /// Adds seeds of `label` at the given voxel indices (non-bone voxels are skipped); returns
    /// how many were placed. Errors: label 0, a voxel index outside the volume.
    pub fn add_seeds(&mut self, voxels: &[usize], label: u16) -> Result<usize> {
        if label == 0 {
            return Err(Error::invalid(
                "label",
                "labels start at 1 (0 means no seed)",
            ));
        }
        let total: usize = self.graph.dims().iter().product();
        let mut used = 0;
        for &v in voxels {
            if v >= total {
                return Err(Error::invalid(
                    "voxels",
                    format!("index {v} is outside the volume of {total} voxels"),
                ));
            }
            if let Some(i) = self.graph.node(v) {
                self.seeds[i] = label;
                used += 1;
            }
        }
        Ok(used)
    }

    /// Number of labels `K` (the largest seed label).
    pub fn n_labels(&self) -> usize {
        self.seeds.iter().copied().max().unwrap_or(0) as usize
    }

    /// Solves the K systems `(L_U + κ I) x_k = −Bᵀ m_k` by Jacobi-PCG; `warm_start` starts
    /// each from the previous solution (Grady's suggestion for added seeds).
    ///
    /// Errors: no seeds on the graph.
    pub fn solve(&mut self, warm_start: bool) -> Result<SolveReport> {
        let k = self.n_labels();
        if k == 0 {
            return Err(Error::invalid(
                "seeds",
                "no seed lies on a bone voxel; place at least one stroke on the bone",
            ));
        }
        let g = &self.graph;
        let n = g.len();
        let mut u_of_node = vec![NONE; n];
        let mut node_of_u = Vec::new();
        for (i, (u, &s)) in u_of_node.iter_mut().zip(&self.seeds).enumerate() {
            if s == 0 {
                *u = node_of_u.len() as u32;
                node_of_u.push(i as u32);
            }
        }
        let diag: Vec<f64> = node_of_u
            .iter()
            .map(|&i| self.params.kappa + g.degree(i as usize))
            .collect();
        let sys = System {
            g,
            u_of_node,
            node_of_u,
            diag,
        };
        let mut report = SolveReport::default();
        let mut x_new = Vec::with_capacity(k);
        let pre = if sys.nrows() > 0 {
            Some(Jacobi::new(&sys.diag)?)
        } else {
            None
        };
        for label in 1..=k as u16 {
            let t = Instant::now();
            let b: Vec<f64> = sys
                .node_of_u
                .par_iter()
                .map(|&i| {
                    let i = i as usize;
                    g.neighbours(i)
                        .iter()
                        .zip(g.weights(i))
                        .filter(|(&j, _)| j != NONE && self.seeds[j as usize] == label)
                        .map(|(_, &w)| w)
                        .sum()
                })
                .collect();
            let mut xk: Vec<f64> = self
                .seeds
                .iter()
                .map(|&s| f64::from(u8::from(s == label)))
                .collect();
            if let Some(pre) = &pre {
                let prev: Option<Vec<f64>> =
                    (warm_start && self.x.len() >= label as usize).then(|| {
                        sys.node_of_u
                            .iter()
                            .map(|&i| self.x[label as usize - 1][i as usize])
                            .collect()
                    });
                let guess = prev
                    .as_deref()
                    .map_or(InitialGuess::Zero, InitialGuess::Given);
                let opts = PcgOptions {
                    tol: self.params.tol,
                    max_iter: Some(self.params.max_iter),
                };
                let r = pcg(&sys, &b, guess, pre, &opts)?;
                for (a, &i) in sys.node_of_u.iter().enumerate() {
                    xk[i as usize] = r.x[a];
                }
                report.iterations.push(r.iterations);
                report.residuals.push(r.relative_residual);
                report.converged.push(r.converged);
            } else {
                report.iterations.push(0);
                report.residuals.push(0.0);
                report.converged.push(true);
            }
            report.seconds.push(t.elapsed().as_secs_f64());
            x_new.push(xk);
        }
        self.x = x_new;
        Ok(report)
    }

    /// Probability of `label` at every node from the last solve (empty before a solve).
    pub fn node_probabilities(&self, label: u16) -> &[f64] {
        label
            .checked_sub(1)
            .and_then(|k| self.x.get(k as usize))
            .map_or(&[], Vec::as_slice)
    }

    /// The label of every node: seeds keep theirs; others take the label of largest
    /// probability (ties: the lowest), 0 when no label reaches them (probability <= 1e-12).
    pub fn node_labels(&self) -> Vec<u16> {
        (0..self.graph.len())
            .map(|i| {
                if self.seeds[i] != 0 {
                    return self.seeds[i];
                }
                let mut best = (0u16, 1e-12);
                for (k, x) in self.x.iter().enumerate() {
                    if x[i] > best.1 {
                        best = (k as u16 + 1, x[i]);
                    }
                }
                best.0
            })
            .collect()
    }

    /// The label volume (0 on non-bone and unreached voxels).
    pub fn labels(&self) -> Result<Volume<u16>> {
        let mut out = vec![0u16; self.graph.dims().iter().product()];
        for (i, l) in self.node_labels().into_iter().enumerate() {
            out[self.graph.voxel(i)] = l;
        }
        Volume::new(self.graph.dims(), self.graph.spacing(), out)
    }
}
