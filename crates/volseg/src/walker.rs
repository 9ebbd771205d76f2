//! Random walks on the bone graph (Grady 2006; paper section 2.4): one combinatorial
//! Dirichlet problem per label, Jacobi-preconditioned CG (all labels in one block by
//! default, see [`crate::params::Solver`]), warm start, maximum-probability labelling.

use std::time::Instant;

use wscg_math::{Error, Result, Volume};

use crate::baseline::nearest_seed_labels;
use crate::block::{try_filled, Block, BlockOutcome, Lane, EXCLUDED, MAX_LANES, UNKNOWN};
use crate::graph::BoneGraph;
use crate::params::{Precision, RandomWalkParams, Solver};

/// Outcome of one [`RandomWalkSession::solve`], per label `1..=K`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// CG iterations.
    pub iterations: Vec<usize>,
    /// Final relative residuals `‖r‖ / ‖b‖`.
    pub residuals: Vec<f64>,
    /// Whether the tolerance was met.
    pub converged: Vec<bool>,
    /// Wall-clock seconds per label (for the block solver, the block's time divided by K).
    pub seconds: Vec<f64>,
    /// Unseeded nodes in components without any seed: excluded from the systems (their
    /// probabilities are 0, their label 0). Without them κ = 0 would make the systems singular.
    pub unreached: usize,
}

impl SolveReport {
    /// Mean CG iterations per label (0 without labels).
    pub fn mean_iterations(&self) -> f64 {
        mean(self.iterations.iter().map(|&i| i as f64))
    }

    /// Mean wall-clock seconds per label (0 without labels).
    pub fn mean_seconds(&self) -> f64 {
        mean(self.seconds.iter().copied())
    }
}

fn mean(v: impl ExactSizeIterator<Item = f64>) -> f64 {
    let n = v.len();
    if n == 0 {
        0.0
    } else {
        v.sum::<f64>() / n as f64
    }
}

/// Probabilities of the last solve, interleaved per node (`x[i·K + k − 1]`).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
enum Probs {
    F32(Vec<f32>),
    F64(Vec<f64>),
}

/// An interactive segmentation: the graph, the seeds placed so far and the last solution.
///
/// It serialises with `serde`: graph, parameters, seeds and the last solution, so that a
/// deserialised session re-solves (warm start included) exactly as the original would;
/// deserialising checks that the parts agree.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "SessionParts")]
pub struct RandomWalkSession {
    graph: BoneGraph,
    params: RandomWalkParams,
    /// Seed label of every node (0 = unseeded).
    seeds: Vec<u16>,
    /// Number of labels of the last solve.
    k: usize,
    /// Probabilities from the last solve (`None` before the first).
    x: Option<Probs>,
}

/// The serialised fields of a [`RandomWalkSession`], in its field order.
#[derive(serde::Deserialize)]
struct SessionParts {
    graph: BoneGraph,
    params: RandomWalkParams,
    seeds: Vec<u16>,
    k: usize,
    x: Option<Probs>,
}

impl TryFrom<SessionParts> for RandomWalkSession {
    type Error = Error;

    /// Checks that the parts agree: valid parameters, one seed per node, `K` probabilities
    /// per node.
    fn try_from(p: SessionParts) -> Result<Self> {
        p.params.validate()?;
        let n = p.graph.len();
        let lanes = match &p.x {
            Some(Probs::F32(x)) => Some(x.len()),
            Some(Probs::F64(x)) => Some(x.len()),
            None => None,
        };
        let consistent = p.seeds.len() == n
            && match lanes {
                Some(len) => p.k.checked_mul(n) == Some(len),
                // A failed solve leaves no solution and the earlier label count.
                None => true,
            };
        if !consistent {
            return Err(Error::invalid(
                "session",
                "seeds or probabilities do not match the graph",
            ));
        }
        Ok(Self {
            graph: p.graph,
            params: p.params,
            seeds: p.seeds,
            k: p.k,
            x: p.x,
        })
    }
}

impl RandomWalkSession {
    /// A session on `graph`. Errors: invalid parameters.
    pub fn new(graph: BoneGraph, params: RandomWalkParams) -> Result<Self> {
        params.validate()?;
        let n = graph.len();
        Ok(Self {
            graph,
            params,
            seeds: vec![0; n],
            k: 0,
            x: None,
        })
    }

    /// The graph.
    pub fn graph(&self) -> &BoneGraph {
        &self.graph
    }

    /// The parameters.
    pub fn params(&self) -> &RandomWalkParams {
        &self.params
    }

    /// Seed label of every node (0 = unseeded).
    pub fn node_seeds(&self) -> &[u16] {
        &self.seeds
    }

    /// Replaces all seeds by the non-zero voxels of `seeds` (labels 1..=K) that are bone;
    /// returns how many seed voxels lie on the graph (seeds on non-bone voxels, e.g. strokes
    /// painted on soft tissue, are dropped). Errors: shape mismatch.
    pub fn set_seeds(&mut self, seeds: &Volume<u16>) -> Result<usize> {
        if seeds.dims() != self.graph.dims() {
            return Err(Error::ShapeMismatch(format!(
                "seeds are {:?}, the CT {:?}",
                seeds.dims(),
                self.graph.dims()
            )));
        }
        if let Some(index) = seeds.data().iter().position(|&l| l == EXCLUDED) {
            return Err(Error::invalid(
                "seeds",
                format!("label 65535 at voxel {index} (labels go up to 65534)"),
            ));
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
    /// how many were placed. Errors: label 0 or 65535, a voxel index outside the volume.
    pub fn add_seeds(&mut self, voxels: &[usize], label: u16) -> Result<usize> {
        if label == 0 || label == EXCLUDED {
            return Err(Error::invalid(
                "label",
                format!("labels go from 1 to 65534 (0 means no seed), got {label}"),
            ));
        }
        let total: usize = self.graph.dims().iter().product();
        if let Some(&v) = voxels.iter().find(|&&v| v >= total) {
            return Err(Error::invalid(
                "voxels",
                format!("index {v} is outside the volume of {total} voxels"),
            ));
        }
        let mut used = 0;
        for &v in voxels {
            if let Some(i) = self.graph.node(v) {
                self.seeds[i] = label;
                used += 1;
            }
        }
        Ok(used)
    }

    /// Number of labels of the last solve (0 before the first): the lanes of
    /// [`Self::node_probabilities`], which [`Self::n_labels`] may exceed once seeds of a new
    /// label are added.
    pub fn solved_labels(&self) -> usize {
        self.k
    }

    /// Number of labels `K` (the largest seed label); the solver needs `K` probability
    /// vectors, so labels should be numbered from 1 without large gaps.
    pub fn n_labels(&self) -> usize {
        self.seeds.iter().copied().max().unwrap_or(0) as usize
    }

    /// Solves the K systems `(L_U + κ I) x_k = −Bᵀ m_k` by (Jacobi-preconditioned) CG;
    /// `warm_start` starts each from the previous solution (Grady's suggestion for added
    /// seeds). Components without a seed are excluded first ([`SolveReport::unreached`]).
    ///
    /// Errors: no seeds on the graph; a thread pool that cannot be built.
    pub fn solve(&mut self, warm_start: bool) -> Result<SolveReport> {
        let k = self.n_labels();
        if k == 0 {
            return Err(Error::invalid(
                "seeds",
                "no seed lies on a bone voxel; place at least one stroke on the bone",
            ));
        }
        match self.params.threads {
            Some(t) => rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .map_err(|e| Error::invalid("threads", e.to_string()))?
                .install(|| self.solve_in_pool(k, warm_start)),
            None => self.solve_in_pool(k, warm_start),
        }
    }

    fn solve_in_pool(&mut self, k: usize, warm_start: bool) -> Result<SolveReport> {
        let reached = nearest_seed_labels(&self.graph, &self.seeds);
        let role: Vec<u16> = self
            .seeds
            .iter()
            .zip(&reached)
            .map(|(&s, &r)| match (s, r) {
                (0, 0) => EXCLUDED,
                (0, _) => UNKNOWN,
                (s, _) => s,
            })
            .collect();
        let unreached = role.iter().filter(|&&r| r == EXCLUDED).count();
        let prev = if warm_start { self.x.take() } else { None };
        let (probs, mut report) = match (self.params.precision, prev) {
            (Precision::F32, Some(Probs::F32(p))) => self.run(&role, k, Some(&p), Probs::F32),
            (Precision::F32, _) => self.run::<f32>(&role, k, None, Probs::F32),
            (Precision::F64, Some(Probs::F64(p))) => self.run(&role, k, Some(&p), Probs::F64),
            (Precision::F64, _) => self.run::<f64>(&role, k, None, Probs::F64),
        }?;
        report.unreached = unreached;
        self.x = Some(probs);
        self.k = k;
        Ok(report)
    }

    /// Solves `labels` (at most `L`) in one sweep of `L` lanes, reading and writing their
    /// lanes of the interleaved `x` (`n·k`), at most `max_iter` iterations; with `shrink`,
    /// labels still running when three quarters of the lanes are done come back unfinished.
    fn group<T: Lane, const L: usize>(
        &self,
        role: &[u16],
        x: &mut [T],
        k: usize,
        labels: &[usize],
        max_iter: usize,
        shrink: bool,
    ) -> Result<BlockOutcome> {
        let n = self.graph.len();
        let mut xg = try_filled(n + 1, [T::default(); L])?;
        for (i, xi) in xg[..n].iter_mut().enumerate() {
            for (v, &label) in xi.iter_mut().zip(labels) {
                *v = x[i * k + label - 1];
            }
        }
        let mut lane_of_label = vec![u8::MAX; k + 1];
        for (lane, &label) in labels.iter().enumerate() {
            lane_of_label[label] = lane as u8;
        }
        let p = &self.params;
        let o = Block {
            g: &self.graph,
            role,
            lane_of_label: &lane_of_label,
            used: labels.len(),
            shrink: shrink && labels.len() > 1,
            kappa: p.kappa,
            tol: p.tol,
            max_iter,
            jacobi: p.jacobi,
        }
        .solve(&mut xg)?;
        for (i, xi) in xg[..n].iter().enumerate() {
            for (&v, &label) in xi.iter().zip(labels) {
                x[i * k + label - 1] = v;
            }
        }
        Ok(o)
    }

    /// Runs the configured solver in precision `T` from `prev` (warm start) and returns the
    /// probabilities (seeds set to their indicator).
    fn run<T: Lane>(
        &self,
        role: &[u16],
        k: usize,
        prev: Option<&[T]>,
        wrap: fn(Vec<T>) -> Probs,
    ) -> Result<(Probs, SolveReport)> {
        let n = self.graph.len();
        let mut x = try_filled(n.saturating_mul(k), T::default())?;
        if let Some(prev) = prev {
            let kp = self.k;
            for i in (0..n).filter(|&i| role[i] == UNKNOWN) {
                for l in 0..k.min(kp) {
                    x[i * k + l] = prev[i * kp + l];
                }
            }
        }
        let mut report = SolveReport::default();
        // Groups of labels solved in one sweep: up to MAX_LANES for the block solver, one label
        // at a time for the per-label variants. In a warm re-solve usually only the labels
        // near the new strokes run long: once three quarters of a block are done, the others
        // continue (restarted from x) in a narrower block. A cold solve keeps one Krylov space
        // per label (the iterates of a per-label Jacobi-PCG).
        let warm = prev.is_some();
        let width = match self.params.solver {
            Solver::Block => MAX_LANES,
            Solver::PerLabel => 1,
        };
        report.iterations = vec![0; k];
        report.residuals = vec![0.0; k];
        report.converged = vec![false; k];
        report.seconds = vec![0.0; k];
        let mut queue: Vec<Vec<usize>> = (1..=k)
            .step_by(width)
            .map(|first| (first..(first + width).min(k + 1)).collect())
            .collect();
        while let Some(labels) = queue.pop() {
            let t = Instant::now();
            let used = labels.len();
            // Labels handed back together ran the same number of iterations.
            let left = self.params.max_iter - report.iterations[labels[0] - 1];
            let o = match used {
                1 => self.group::<T, 1>(role, &mut x, k, &labels, left, warm),
                2 => self.group::<T, 2>(role, &mut x, k, &labels, left, warm),
                3..=4 => self.group::<T, 4>(role, &mut x, k, &labels, left, warm),
                5..=8 => self.group::<T, 8>(role, &mut x, k, &labels, left, warm),
                _ => self.group::<T, MAX_LANES>(role, &mut x, k, &labels, left, warm),
            }?;
            let secs = t.elapsed().as_secs_f64() / used as f64;
            let mut rest = Vec::new();
            for (lane, &l) in labels.iter().enumerate() {
                report.iterations[l - 1] += o.iterations[lane];
                report.residuals[l - 1] = o.residuals[lane];
                report.converged[l - 1] = o.converged[lane];
                report.seconds[l - 1] += secs;
                if o.unfinished[lane] {
                    rest.push(l);
                }
            }
            if !rest.is_empty() {
                queue.push(rest);
            }
        }
        for (i, &s) in self.seeds.iter().enumerate() {
            if s != 0 {
                x[i * k + s as usize - 1] = T::from_f64(1.0);
            }
        }
        log_report(&report, warm);
        Ok((wrap(x), report))
    }

    /// Probability of `label` at every node from the last solve (empty before a solve or for
    /// a label beyond K).
    pub fn node_probabilities(&self, label: u16) -> Vec<f64> {
        fn lane<T: Lane>(x: &[T], k: usize, l: usize) -> Vec<f64> {
            x.iter().skip(l).step_by(k).map(|v| v.to_f64()).collect()
        }
        match (&self.x, label.checked_sub(1).map(usize::from)) {
            (Some(Probs::F32(x)), Some(l)) if l < self.k => lane(x, self.k, l),
            (Some(Probs::F64(x)), Some(l)) if l < self.k => lane(x, self.k, l),
            _ => Vec::new(),
        }
    }

    /// The probability volume of `label` (0 on non-bone voxels). Errors: no solve yet, or
    /// `label` not in `1..=K`.
    pub fn probabilities(&self, label: u16) -> Result<Volume<f32>> {
        let p = self.node_probabilities(label);
        if p.is_empty() && !self.graph.is_empty() {
            return Err(Error::invalid(
                "label",
                format!(
                    "no probabilities for label {label} (labels 1..={} after a solve)",
                    self.k
                ),
            ));
        }
        let mut out = vec![0f32; self.graph.dims().iter().product()];
        for (i, v) in p.into_iter().enumerate() {
            out[self.graph.voxel(i)] = v as f32;
        }
        Volume::new(self.graph.dims(), self.graph.spacing(), out)
    }

    /// The label of every node: seeds keep theirs; others take the label of largest
    /// probability (ties: the lowest), 0 when no label reaches them (probability <= 1e-12).
    pub fn node_labels(&self) -> Vec<u16> {
        fn argmax<T: Lane>(x: &[T], k: usize, seeds: &[u16]) -> Vec<u16> {
            x.chunks_exact(k)
                .zip(seeds)
                .map(|(xi, &s)| {
                    if s != 0 {
                        return s;
                    }
                    let mut best = (0u16, 1e-12);
                    for (l, v) in xi.iter().enumerate() {
                        if v.to_f64() > best.1 {
                            best = (l as u16 + 1, v.to_f64());
                        }
                    }
                    best.0
                })
                .collect()
        }
        match &self.x {
            Some(Probs::F32(x)) => argmax(x, self.k, &self.seeds),
            Some(Probs::F64(x)) => argmax(x, self.k, &self.seeds),
            None => self.seeds.clone(),
        }
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

/// One record per solve: labels, iterations and time at info level; a warning naming the
/// labels that stopped at the iteration cap (their probabilities are approximate).
fn log_report(report: &SolveReport, warm: bool) {
    let seconds: f64 = report.seconds.iter().sum();
    log::info!(
        "random walker ({}): {} labels, iterations {:?}, {seconds:.2} s",
        if warm { "warm re-solve" } else { "cold solve" },
        report.iterations.len(),
        report.iterations
    );
    let stopped: Vec<usize> = (0..report.converged.len())
        .filter(|&l| !report.converged[l])
        .map(|l| l + 1)
        .collect();
    if !stopped.is_empty() {
        log::warn!(
            "random walker: labels {stopped:?} reached the iteration cap before the tolerance \
             (relative residuals {:?})",
            stopped
                .iter()
                .map(|&l| report.residuals[l - 1])
                .collect::<Vec<_>>()
        );
    }
}
