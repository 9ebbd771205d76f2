//! Importance caches (Georgiev et al. 2012, as used by paper 08): records at sparse shading
//! points, each with exact distributions over the VPLs, interpolated at every pixel.

use rayon::prelude::*;
use wscg_math::knn::KdTree;
use wscg_math::vec3::dot;
use wscg_math::{Error, Result};

use super::pmf::{sample_list, Pmf};
use super::scene::luminance;
use super::shading::{Receiver, Shading};
use super::weights::{record_weight, Interp};

/// The four sampling strategies, in the order of the alpha-max heuristic's tie-break.
pub const STRATEGIES: [&str; 4] = ["full", "unoccluded", "bounded", "conservative"];
/// Index of the full distribution (visibility included).
pub const FULL: usize = 0;
/// Index of the unoccluded distribution.
pub const UNOCCLUDED: usize = 1;
/// Index of the bounded distribution.
pub const BOUNDED: usize = 2;
/// Index of the conservative (uniform) distribution.
pub const CONSERVATIVE: usize = 3;

/// A cache point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    /// Its shading point.
    pub at: Receiver,
    /// Radius of influence: the bounded distribution holds over the disc of this radius.
    pub radius: f64,
    /// The pixel it sits on, when placed on the G-buffer.
    pub pixel: Option<usize>,
    /// Its cluster (adaptive placement).
    pub cluster: Option<usize>,
    /// Whether the adaptive insertion added it.
    pub inserted: bool,
}

/// A record's distributions over the VPLs; `None` where every VPL has zero weight (a fully
/// occluded record has no full distribution). The conservative one is implicit (uniform).
#[derive(Clone, Debug, PartialEq)]
pub struct Distributions {
    /// Full, unoccluded and bounded distributions.
    pub pmf: [Option<Pmf>; 3],
}

impl Distributions {
    /// The distributions of a record: `Y(I_j)` with visibility (one shadow ray per VPL),
    /// without, and its bound over the record's disc.
    pub fn compute(sh: &Shading, r: &Record) -> Self {
        let n = sh.len();
        let mut full = vec![0.0; n];
        let mut unocc = vec![0.0; n];
        let mut bound = vec![0.0; n];
        for j in 0..n {
            let u = luminance(&sh.unoccluded(&r.at, j));
            unocc[j] = u;
            if u > 0.0 && sh.visible(&r.at, j) {
                full[j] = u;
            }
            bound[j] = sh.bound(&r.at, j, r.radius);
        }
        Self {
            pmf: [Pmf::new(&full), Pmf::new(&unocc), Pmf::new(&bound)],
        }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.pmf.iter().flatten().map(Pmf::bytes).sum()
    }
}

/// The records found for a shading point and their normalised weights.
pub type Lookup = Vec<(usize, f64)>;

/// Records, their distributions, and the search structure.
pub struct ImportanceCache {
    /// The records.
    pub records: Vec<Record>,
    /// Their distributions.
    pub dists: Vec<Distributions>,
    tree: KdTree,
    /// How records are interpolated.
    pub interp: Interp,
    /// Records mixed at a shading point (`M`, 3).
    pub m: usize,
    /// Search radius of the similarity weights.
    pub d_max: f64,
    /// VPLs of positive power (the conservative distribution is uniform over them).
    pub positive: Vec<bool>,
    /// Their number.
    pub n_positive: usize,
    /// Indices of the VPLs of positive power.
    pub positive_ids: Vec<u32>,
}

impl ImportanceCache {
    /// A cache over `records` (distributions computed in parallel, one record at a time).
    ///
    /// Errors: no record, `m = 0`, invalid interpolation parameters.
    pub fn build(sh: &Shading, records: Vec<Record>, interp: Interp, m: usize) -> Result<Self> {
        let dists = records
            .par_iter()
            .map(|r| Distributions::compute(sh, r))
            .collect();
        Self::from_parts(sh, records, dists, interp, m)
    }

    /// A cache over records whose distributions are known.
    pub fn from_parts(
        sh: &Shading,
        records: Vec<Record>,
        dists: Vec<Distributions>,
        interp: Interp,
        m: usize,
    ) -> Result<Self> {
        interp.validate()?;
        if m == 0 {
            return Err(Error::invalid(
                "m_nearest",
                "at least one record per lookup",
            ));
        }
        if records.is_empty() {
            return Err(Error::Empty("records"));
        }
        let pts: Vec<[f64; 3]> = records.iter().map(|r| r.at.pos).collect();
        let tree = KdTree::new(&pts)?;
        let positive: Vec<bool> = sh.intensity.iter().map(|i| luminance(i) > 0.0).collect();
        let positive_ids: Vec<u32> = (0..positive.len() as u32)
            .filter(|&j| positive[j as usize])
            .collect();
        let d_max = match interp {
            Interp::Clarberg { dmax_factor, .. } => {
                dmax_factor * median_mth_distance(&tree, &pts, m)
            }
            Interp::Uniform => f64::INFINITY,
        };
        Ok(Self {
            records,
            dists,
            tree,
            interp,
            m,
            d_max,
            n_positive: positive_ids.len(),
            positive,
            positive_ids,
        })
    }

    /// Bytes held by the distributions.
    pub fn bytes(&self) -> usize {
        self.dists.iter().map(Distributions::bytes).sum()
    }

    /// The records mixed at `(pos, normal)` and their weights (summing to 1), leaving out
    /// record `exclude`. Uniform: the `M` nearest records facing the same side; the
    /// similarity weights: the `M` nearest within `d_max`, weighted by eqs. (2)-(4), falling
    /// back to the uniform choice when none of them has a positive weight, and blended with
    /// the uniform choice by the defensive share `c`: `(1 - c) w_k + c u_k` (see
    /// [`Interp::Clarberg`]).
    pub fn lookup(&self, pos: [f64; 3], normal: [f64; 3], exclude: Option<usize>) -> Lookup {
        let Interp::Clarberg {
            theta_max,
            lambda,
            defensive,
            ..
        } = self.interp
        else {
            return self.uniform_lookup(&pos, normal, exclude);
        };
        let mut out: Lookup = self
            .tree
            .knn(&pos, self.m, exclude)
            .into_iter()
            .filter(|&(_, d)| d <= self.d_max)
            .map(|(k, _)| {
                let r = &self.records[k].at;
                let w = record_weight(pos, normal, r.pos, r.normal, self.d_max, theta_max, lambda);
                (k, w)
            })
            .filter(|&(_, w)| w > 0.0)
            .collect();
        let total: f64 = out.iter().map(|e| e.1).sum();
        if total.is_nan() || total <= 0.0 {
            return self.uniform_lookup(&pos, normal, exclude);
        }
        let keep = (1.0 - defensive) / total;
        out.iter_mut().for_each(|e| e.1 *= keep);
        if defensive > 0.0 {
            for (k, u) in self.uniform_lookup(&pos, normal, exclude) {
                match out.iter_mut().find(|e| e.0 == k) {
                    Some(e) => e.1 += defensive * u,
                    None => out.push((k, defensive * u)),
                }
            }
            out.retain(|e| e.1 > 0.0);
        }
        out
    }

    fn uniform_lookup(&self, q: &[f64; 3], normal: [f64; 3], exclude: Option<usize>) -> Lookup {
        let near = self.tree.knn(q, 8 * self.m, exclude);
        let mut out: Vec<usize> = near
            .iter()
            .map(|e| e.0)
            .filter(|&k| dot(self.records[k].at.normal, normal) > 0.0)
            .take(self.m)
            .collect();
        if out.is_empty() {
            out = near.iter().map(|e| e.0).take(self.m).collect();
        }
        let w = 1.0 / out.len().max(1) as f64;
        out.into_iter().map(|k| (k, w)).collect()
    }

    /// The mixture of strategy `s` over `found`, renormalised over the records that have it;
    /// empty when none has it.
    pub fn mixture(&self, found: &Lookup, s: usize) -> Lookup {
        let mut out: Lookup = found
            .iter()
            .filter(|(k, _)| self.dists[*k].pmf[s].is_some())
            .copied()
            .collect();
        let total: f64 = out.iter().map(|e| e.1).sum();
        if total > 0.0 {
            out.iter_mut().for_each(|e| e.1 /= total);
        } else {
            out.clear();
        }
        out
    }

    /// Probability of VPL `j` under the mixture `mix` of strategy `s` (the conservative
    /// strategy ignores `mix`).
    #[inline]
    pub fn pdf(&self, mix: &Lookup, s: usize, j: usize) -> f64 {
        if s == CONSERVATIVE {
            return if self.positive[j] {
                1.0 / self.n_positive as f64
            } else {
                0.0
            };
        }
        mix.iter()
            .map(|&(k, w)| w * self.dists[k].pmf[s].as_ref().map_or(0.0, |p| p.pdf(j)))
            .sum()
    }

    /// Draws a VPL from the mixture `mix` of strategy `s` with two uniform numbers.
    #[inline]
    pub fn sample(&self, mix: &Lookup, s: usize, u1: f64, u2: f64) -> Option<usize> {
        if s == CONSERVATIVE {
            if self.n_positive == 0 {
                return None;
            }
            let i = ((u1 * self.n_positive as f64) as usize).min(self.n_positive - 1);
            return Some(self.positive_ids[i] as usize);
        }
        let chosen = sample_list(mix, u1)?;
        Some(self.dists[chosen].pmf[s].as_ref()?.sample(u2))
    }
}

/// Median over the records of the distance to their `m`-th nearest other record.
fn median_mth_distance(tree: &KdTree, pts: &[[f64; 3]], m: usize) -> f64 {
    let mut d: Vec<f64> = pts
        .par_iter()
        .enumerate()
        .map(|(i, p)| tree.knn(p, m, Some(i)).last().map_or(0.0, |e| e.1))
        .collect();
    if d.is_empty() {
        return 0.0;
    }
    let mid = d.len() / 2;
    d.select_nth_unstable_by(mid, f64::total_cmp);
    let v = d[mid];
    if v > 0.0 {
        v
    } else {
        f64::INFINITY
    }
}
