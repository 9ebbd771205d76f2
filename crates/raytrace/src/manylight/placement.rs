//! Where the records go: the baseline's jittered screen grid (Georgiev et al. 2012) and the
//! paper's clustering of the shading points followed by adaptive insertion (section 4.1-4.2).

use rand::seq::SliceRandom;
use rand::Rng;
use rayon::prelude::*;
use wscg_math::{Error, Result};

use super::cache::{Distributions, ImportanceCache, Record, FULL, UNOCCLUDED};
use super::gbuffer::{shade_point, GBuffer};
use super::shading::Shading;
use super::weights::Interp;

wscg_math::params! {
    /// Parameters of the paper's placement. The paper gives no thresholds; these are ours.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct AdaptiveParams {
        /// Share of the record budget placed by the clustering (0.6); the rest is inserted.
        pub init_fraction: f64,
        /// A cluster whose 6-D box diagonal is at most this is not split (0.02).
        pub leaf_min_extent: f64,
        /// Insertion threshold on the disagreement `D_i` of eq. (5) (0.5; `D_i` lies in [0, 2]).
        pub delta: f64,
        /// A pass that inserts fewer records than this share of the records ends the insertion
        /// (0.01, at least one record).
        pub min_inserted_fraction: f64,
        /// Most insertion passes (8).
        pub max_passes: u32,
    }
}

impl Default for AdaptiveParams {
    fn default() -> Self {
        Self {
            init_fraction: 0.6,
            leaf_min_extent: 0.02,
            delta: 0.5,
            min_inserted_fraction: 0.01,
            max_passes: 8,
        }
    }
}

impl AdaptiveParams {
    /// Errors: `init_fraction` outside (0, 1], a negative `delta` or extent, a negative
    /// insertion share.
    pub fn validate(&self) -> Result<()> {
        if !(self.init_fraction > 0.0 && self.init_fraction <= 1.0) {
            return Err(Error::invalid(
                "init_fraction",
                format!("must lie in (0, 1], got {}", self.init_fraction),
            ));
        }
        for (name, v) in [
            ("delta", self.delta),
            ("leaf_min_extent", self.leaf_min_extent),
            ("min_inserted_fraction", self.min_inserted_fraction),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
        Ok(())
    }
}

/// Record placement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// Importance caching (Georgiev 2012): one jittered primary ray per cell of a screen grid.
    RandomScreen,
    /// The paper: 6-D clustering of the shading points, then adaptive insertion.
    Adaptive(AdaptiveParams),
}

/// `n` records at jittered positions of a stratified screen grid (cells chosen at random
/// when the grid has more than `n`); the primary rays that miss are dropped. Each record's
/// radius covers its cell's surface area.
pub fn random_screen(scene: &super::scene::Scene, g: &GBuffer, n: usize, seed: u64) -> Vec<Record> {
    let (w, h) = (g.width as f64, g.height as f64);
    let aspect = w / h;
    let mut gx = ((n as f64 * aspect).sqrt().round() as usize).max(1);
    let gy = (n.div_ceil(gx)).max(1);
    if gx * gy < n {
        gx = n.div_ceil(gy);
    }
    let mut cells: Vec<usize> = (0..gx * gy).collect();
    let mut rng = wscg_math::rng::stream(seed, u64::MAX);
    if cells.len() > n {
        cells.shuffle(&mut rng);
        cells.truncate(n);
        cells.sort_unstable();
    }
    let (cw, ch) = (w / gx as f64, h / gy as f64);
    cells
        .par_iter()
        .filter_map(|&c| {
            let mut rng = wscg_math::rng::stream(seed, c as u64);
            let x = ((c % gx) as f64 + rng.random::<f64>()) * cw;
            let y = ((c / gx) as f64 + rng.random::<f64>()) * ch;
            let p = shade_point(scene, &g.frame, x, y, cw * ch)?;
            Some(Record {
                at: p.receiver(),
                radius: (p.footprint / std::f64::consts::PI).sqrt(),
                pixel: None,
                cluster: None,
                inserted: false,
            })
        })
        .collect()
}

/// The 6-D feature `(s (x - centre), n)` of each pixel in `ids` (valid pixels), `s`
/// scaling the box of their positions into `[-1, 1]^3`.
pub fn features(g: &GBuffer, ids: &[usize]) -> Vec<[f64; 6]> {
    let pts: Vec<_> = ids
        .iter()
        .map(|&i| g.points[i].expect("valid pixel"))
        .collect();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p.pos[k]);
            hi[k] = hi[k].max(p.pos[k]);
        }
    }
    let half = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max) * 0.5;
    let s = if half > 0.0 { 1.0 / half } else { 1.0 };
    let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    pts.iter()
        .map(|p| {
            [
                s * (p.pos[0] - c[0]),
                s * (p.pos[1] - c[1]),
                s * (p.pos[2] - c[2]),
                p.normal[0],
                p.normal[1],
                p.normal[2],
            ]
        })
        .collect()
}

fn bbox6(q: &[[f64; 6]], c: &[usize]) -> ([f64; 6], [f64; 6]) {
    let mut lo = [f64::INFINITY; 6];
    let mut hi = [f64::NEG_INFINITY; 6];
    for &i in c {
        for k in 0..6 {
            lo[k] = lo[k].min(q[i][k]);
            hi[k] = hi[k].max(q[i][k]);
        }
    }
    (lo, hi)
}

/// The 6-D clustering of section 4.1: the valid pixels' `(s (x - centre), n)`
/// ([`features`]) split at the midpoint of the longest axis of their box, the largest
/// cluster first, until there are `k0` clusters (fewer when the extent rule stops the
/// splits). Returns the clusters (pixel indices) and the leaf size `n_max` they satisfy:
/// every leaf holds at most `n_max` points (the size of the largest) or has a box diagonal
/// of at most `min_extent`. This is the paper's recursive subdivision with the size
/// threshold that gives `k0` clusters (the paper gives no thresholds; a fixed size threshold
/// `ceil(N / K0)` would give 1.5-2 `K0` leaves with midpoint splits).
pub fn cluster_to_count(g: &GBuffer, k0: usize, min_extent: f64) -> (Vec<Vec<usize>>, usize) {
    use std::collections::BinaryHeap;
    let ids: Vec<usize> = (0..g.points.len())
        .filter(|&i| g.points[i].is_some())
        .collect();
    if ids.is_empty() {
        return (Vec::new(), 0);
    }
    let q = features(g, &ids);
    // Splittable clusters by size (ties: creation order), and the finished leaves.
    let mut heap: BinaryHeap<(usize, std::cmp::Reverse<usize>)> = BinaryHeap::new();
    let mut members: Vec<Vec<usize>> = vec![(0..ids.len()).collect()];
    let mut leaves: Vec<usize> = Vec::new();
    heap.push((ids.len(), std::cmp::Reverse(0)));
    while leaves.len() + heap.len() < k0.max(1) {
        let Some((_, std::cmp::Reverse(k))) = heap.pop() else {
            break;
        };
        let c = std::mem::take(&mut members[k]);
        match split6(&q, c, min_extent) {
            Ok((left, right)) => {
                for part in [left, right] {
                    members.push(part);
                    let id = members.len() - 1;
                    heap.push((members[id].len(), std::cmp::Reverse(id)));
                }
            }
            Err(c) => {
                members[k] = c;
                leaves.push(k);
            }
        }
    }
    leaves.extend(heap.into_iter().map(|(_, std::cmp::Reverse(k))| k));
    leaves.sort_unstable();
    let clusters: Vec<Vec<usize>> = leaves
        .into_iter()
        .map(|k| members[k].iter().map(|&i| ids[i]).collect())
        .collect();
    let n_max = clusters.iter().map(Vec::len).max().unwrap_or(0);
    (clusters, n_max)
}

/// Splits a cluster at the midpoint of its 6-D box's longest axis (the median when all
/// points fall on one side); gives it back when its diagonal is at most `min_extent` or it
/// has one point.
fn split6(
    q: &[[f64; 6]],
    c: Vec<usize>,
    min_extent: f64,
) -> std::result::Result<(Vec<usize>, Vec<usize>), Vec<usize>> {
    let (lo, hi) = bbox6(q, &c);
    let ext: Vec<f64> = (0..6).map(|k| hi[k] - lo[k]).collect();
    let diag = ext.iter().map(|e| e * e).sum::<f64>().sqrt();
    if c.len() < 2 || diag <= min_extent {
        return Err(c);
    }
    let axis = (0..6)
        .max_by(|&a, &b| ext[a].total_cmp(&ext[b]))
        .unwrap_or(0);
    let mid = 0.5 * (lo[axis] + hi[axis]);
    let (left, right): (Vec<usize>, Vec<usize>) = c.iter().partition(|&&i| q[i][axis] < mid);
    if !left.is_empty() && !right.is_empty() {
        return Ok((left, right));
    }
    let mut all = c;
    all.sort_by(|&a, &b| q[a][axis].total_cmp(&q[b][axis]).then(a.cmp(&b)));
    let right = all.split_off(all.len() / 2);
    Ok((all, right))
}

/// A record on pixel `i` of `g` with radius `radius`.
pub fn record_at(g: &GBuffer, i: usize, radius: f64, cluster: usize, inserted: bool) -> Record {
    let p = g.points[i].expect("valid pixel");
    Record {
        at: p.receiver(),
        radius,
        pixel: Some(i),
        cluster: Some(cluster),
        inserted,
    }
}

/// Eq. (5): `D_i = sum_j |p_i(y_j) - p~_i(y_j)|` between record `i`'s full distribution
/// (unoccluded if it has none) and the one interpolated at it from the other records;
/// 2 (the largest value) when no neighbour has that distribution.
pub fn disagreement(cache: &ImportanceCache, i: usize) -> f64 {
    let r = &cache.records[i];
    let s = if cache.dists[i].pmf[FULL].is_some() {
        FULL
    } else {
        UNOCCLUDED
    };
    let Some(own) = cache.dists[i].pmf[s].as_ref() else {
        return 0.0;
    };
    let found = cache.lookup(r.at.pos, r.at.normal, Some(i));
    let mix = cache.mixture(&found, s);
    if mix.is_empty() {
        return 2.0;
    }
    let mut d = 0.0;
    for (j, p) in own.pdfs().iter().enumerate() {
        d += (*p as f64 - cache.pdf(&mix, s, j)).abs();
    }
    d
}

/// What the adaptive placement did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AdaptiveStats {
    /// Clusters (initial records).
    pub clusters: usize,
    /// Records inserted.
    pub inserted: usize,
    /// Insertion passes run.
    pub passes: u32,
}

/// The paper's placement: one record per cluster (a random member pixel), then passes that
/// add a record in the cluster of every record whose disagreement exceeds `delta`, the
/// largest first, within the budget `n_cache`.
pub fn adaptive(
    sh: &Shading,
    g: &GBuffer,
    n_cache: usize,
    interp: Interp,
    m: usize,
    a: &AdaptiveParams,
    seed: u64,
) -> Result<(ImportanceCache, AdaptiveStats)> {
    a.validate()?;
    let k0 = ((a.init_fraction * n_cache as f64).round() as usize).clamp(1, n_cache);
    let (clusters, _) = cluster_to_count(g, k0, a.leaf_min_extent);
    let area: Vec<f64> = clusters
        .iter()
        .map(|c| {
            c.iter()
                .map(|&i| g.points[i].expect("valid").footprint)
                .sum()
        })
        .collect();
    let mut used = vec![false; g.points.len()];
    let mut per_cluster = vec![1usize; clusters.len()];
    let mut records: Vec<Record> = clusters
        .iter()
        .enumerate()
        .map(|(c, members)| {
            let mut rng = wscg_math::rng::stream(seed, c as u64);
            let i = members[rng.random_range(0..members.len())];
            used[i] = true;
            record_at(g, i, (area[c] / std::f64::consts::PI).sqrt(), c, false)
        })
        .collect();
    records.truncate(n_cache);
    let mut cache = ImportanceCache::build(sh, records, interp, m)?;
    let mut stats = AdaptiveStats {
        clusters: clusters.len(),
        ..AdaptiveStats::default()
    };
    for pass in 1..=a.max_passes {
        let budget = n_cache.saturating_sub(cache.records.len());
        if budget == 0 {
            break;
        }
        let d: Vec<f64> = (0..cache.records.len())
            .into_par_iter()
            .map(|i| disagreement(&cache, i))
            .collect();
        let mut cand: Vec<usize> = (0..d.len()).filter(|&i| d[i] > a.delta).collect();
        cand.sort_by(|&x, &y| d[y].total_cmp(&d[x]).then(x.cmp(&y)));
        cand.truncate(budget);
        let mut rng = wscg_math::rng::stream(seed ^ 0x5eed_0000, pass as u64);
        let mut new = Vec::new();
        for &i in &cand {
            let Some(c) = cache.records[i].cluster else {
                continue;
            };
            let free: Vec<usize> = clusters[c].iter().copied().filter(|&p| !used[p]).collect();
            if free.is_empty() {
                continue;
            }
            let p = free[rng.random_range(0..free.len())];
            used[p] = true;
            per_cluster[c] += 1;
            let radius = (area[c] / (std::f64::consts::PI * per_cluster[c] as f64)).sqrt();
            new.push(record_at(g, p, radius, c, true));
        }
        let added = new.len();
        stats.passes = pass;
        stats.inserted += added;
        if added > 0 {
            let new_d: Vec<Distributions> = new
                .par_iter()
                .map(|r| Distributions::compute(sh, r))
                .collect();
            let mut records = std::mem::take(&mut cache.records);
            let mut dists = std::mem::take(&mut cache.dists);
            records.extend(new);
            dists.extend(new_d);
            cache = ImportanceCache::from_parts(sh, records, dists, interp, m)?;
        }
        let min_inserted = ((a.min_inserted_fraction * cache.records.len() as f64) as usize).max(1);
        if cand.len() < min_inserted || added == 0 {
            break;
        }
    }
    Ok((cache, stats))
}
