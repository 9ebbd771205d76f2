//! The paper's search structure for stage 1 (section 3.3: "principal component analysis
//! (PCA) and approximate nearest neighbors search (ANN)"): every valid source cube projected
//! on the leading principal axes of the patch space, a kd-tree over the projections, queries
//! by best-bin-first search with a bounded number of leaf visits (Arya and Mount), and an exact
//! SSD re-ranking of the few best candidates. Its matches are approximate, which is what the
//! refinement of stage 2 repairs.

use std::collections::BinaryHeap;

use faer::Mat;
use rand::Rng as _;
use rayon::prelude::*;
use wscg_math::Result;

use crate::patch::{Cubes, PatchSize};
use crate::patchmatch::{Match, P3};
use crate::telea::MinEntry;
use crate::video::{Mask3, Video};

wscg_math::params! {
    /// Parameters of the PCA + kd-tree search.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub struct PcaKdParams {
        /// Principal axes kept (24).
        pub dims: usize,
        /// Candidates re-ranked by exact SSD (8).
        pub rerank: usize,
        /// Leaves visited per query (64).
        pub max_checks: usize,
        /// Patches sampled to fit the PCA (50000).
        pub samples: usize,
        /// Seed of the sample.
        pub seed: u64,
    }
}

impl Default for PcaKdParams {
    fn default() -> Self {
        Self {
            dims: 24,
            rerank: 8,
            max_checks: 64,
            samples: 50_000,
            seed: 0,
        }
    }
}

impl PcaKdParams {
    /// Errors: `dims`, `rerank`, `max_checks` or `samples` zero.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("dims", self.dims),
            ("rerank", self.rerank),
            ("max_checks", self.max_checks),
            ("samples", self.samples),
        ] {
            if v == 0 {
                return Err(wscg_math::Error::invalid(name, "must be >= 1, got 0"));
            }
        }
        Ok(())
    }
}

const LEAF: usize = 16;

#[derive(Clone, Debug)]
enum Node {
    Leaf {
        start: usize,
        end: usize,
    },
    Split {
        axis: usize,
        value: f32,
        left: usize,
        right: usize,
    },
}

/// The index of one pyramid level.
pub struct PcaIndex {
    patch: PatchSize,
    mean: Vec<f32>,
    /// `dims x len` axes, axis-major.
    axes: Vec<f32>,
    dims: usize,
    /// Projections of the sources in tree order (`dims` values each).
    points: Vec<f32>,
    /// Source centre of each projected point (tree order).
    sources: Vec<P3>,
    nodes: Vec<Node>,
    params: PcaKdParams,
}

/// The cube of `c` channels around `p` as a vector, voxels outside the video clamped to the
/// nearest inside voxel.
fn patch_vector(v: &Video, patch: PatchSize, p: P3, out: &mut Vec<f32>) {
    out.clear();
    let [rt, ry, rx] = patch.radius().map(|r| r as i64);
    let clamp = |x: i64, n: usize| x.clamp(0, n as i64 - 1) as u32;
    for dt in -rt..=rt {
        for dy in -ry..=ry {
            for dx in -rx..=rx {
                let q = [
                    clamp(p[0] as i64 + dt, v.frames),
                    clamp(p[1] as i64 + dy, v.height),
                    clamp(p[2] as i64 + dx, v.width),
                ];
                out.extend(v.pixel(q).iter().map(|&c| c as f32));
            }
        }
    }
}

impl PcaIndex {
    /// Builds the index of the valid `sources` of `video` (its known colours: sources' cubes
    /// contain no hole pixel, so the index does not change while the hole is filled).
    ///
    /// Errors: invalid parameters; no source; a PCA failure.
    pub fn build(
        video: &Video,
        sources: &Mask3,
        patch: PatchSize,
        params: PcaKdParams,
    ) -> Result<Self> {
        params.validate()?;
        let list = sources.points();
        if list.is_empty() {
            return Err(wscg_math::Error::Empty("sources"));
        }
        let len = patch.voxels() * video.channels;
        let dims = params.dims.clamp(1, len);
        // PCA on a seeded sample.
        let mut r = wscg_math::rng::seeded(params.seed);
        let n = params.samples.min(list.len()).max(1);
        let sample: Vec<P3> = if n == list.len() {
            list.clone()
        } else {
            (0..n)
                .map(|_| list[r.random_range(0..list.len())])
                .collect()
        };
        let rows: Vec<Vec<f32>> = sample
            .par_iter()
            .map(|&p| {
                let mut v = Vec::with_capacity(len);
                patch_vector(video, patch, p, &mut v);
                v
            })
            .collect();
        let mean: Vec<f32> = (0..len)
            .map(|j| (rows.iter().map(|r| r[j] as f64).sum::<f64>() / n as f64) as f32)
            .collect();
        let x = Mat::from_fn(n, len, |i, j| (rows[i][j] - mean[j]) as f64);
        let cov = wscg_math::dense::gram(x.as_ref(), 1.0 / n as f64);
        let e = wscg_math::dense::eigh_largest(cov.as_ref(), dims)?;
        let axes: Vec<f32> = (0..dims)
            .flat_map(|k| (0..len).map(move |j| (k, j)))
            .map(|(k, j)| e.vectors[(j, k)] as f32)
            .collect();
        let mut index = Self {
            patch,
            mean,
            axes,
            dims,
            points: Vec::new(),
            sources: Vec::new(),
            nodes: Vec::new(),
            params,
        };
        let proj: Vec<Vec<f32>> = list
            .par_iter()
            .map_init(
                || Vec::with_capacity(len),
                |buf, &p| {
                    patch_vector(video, patch, p, buf);
                    index.project(buf)
                },
            )
            .collect();
        let mut order: Vec<usize> = (0..list.len()).collect();
        index.build_node(&proj, &mut order, 0, list.len());
        index.points = order
            .iter()
            .flat_map(|&i| proj[i].iter().copied())
            .collect();
        index.sources = order.iter().map(|&i| list[i]).collect();
        Ok(index)
    }

    fn project(&self, v: &[f32]) -> Vec<f32> {
        let len = self.mean.len();
        (0..self.dims)
            .map(|k| {
                let a = &self.axes[k * len..(k + 1) * len];
                a.iter()
                    .zip(v)
                    .zip(&self.mean)
                    .map(|((a, x), m)| a * (x - m))
                    .sum()
            })
            .collect()
    }

    /// Builds the subtree over `order[start..end]`; returns its node index.
    fn build_node(
        &mut self,
        proj: &[Vec<f32>],
        order: &mut [usize],
        start: usize,
        end: usize,
    ) -> usize {
        let id = self.nodes.len();
        if end - start <= LEAF {
            self.nodes.push(Node::Leaf { start, end });
            return id;
        }
        // Split the axis of largest spread at the median.
        let axis = (0..self.dims)
            .max_by(|&a, &b| {
                let spread = |k: usize| {
                    let (lo, hi) = order[start..end]
                        .iter()
                        .fold((f32::MAX, f32::MIN), |(l, h), &i| {
                            (l.min(proj[i][k]), h.max(proj[i][k]))
                        });
                    hi - lo
                };
                spread(a).total_cmp(&spread(b))
            })
            .unwrap_or(0);
        let mid = (start + end) / 2;
        order[start..end].select_nth_unstable_by(mid - start, |&a, &b| {
            proj[a][axis].total_cmp(&proj[b][axis]).then(a.cmp(&b))
        });
        let value = proj[order[mid]][axis];
        self.nodes.push(Node::Leaf { start: 0, end: 0 });
        let left = self.build_node(proj, order, start, mid);
        let right = self.build_node(proj, order, mid, end);
        self.nodes[id] = Node::Split {
            axis,
            value,
            left,
            right,
        };
        id
    }

    /// The best source for target `t` by the current colours of `cubes.video`: approximate
    /// nearest neighbours in PCA space, then exact `D` of the best `rerank`; `current` (when
    /// given) competes too.
    pub fn best(&self, cubes: &Cubes<'_>, t: P3, current: Option<P3>) -> Match {
        let mut q = Vec::with_capacity(self.mean.len());
        patch_vector(cubes.video, self.patch, t, &mut q);
        let q = self.project(&q);
        let cands = self.knn(&q, self.params.rerank);
        let mut best = Match {
            source: self.sources[cands[0]],
            dist: f32::INFINITY,
        };
        for s in cands.iter().map(|&i| self.sources[i]).chain(current) {
            let d = cubes.ssd(t, s, best.dist);
            if d < best.dist {
                best = Match { source: s, dist: d };
            }
        }
        best
    }

    /// Up to `k` sources for target `t`, best first by exact `D` with the current colours of
    /// `cubes.video`, each more than `min_sep` pixels (Chebyshev, in space) from `exclude` and
    /// from the better ones of its frame: the approximate nearest `max(rerank, 4 k)` in PCA
    /// space, re-ranked.
    pub fn best_k(
        &self,
        cubes: &Cubes<'_>,
        t: P3,
        k: usize,
        exclude: P3,
        min_sep: u32,
    ) -> Vec<Match> {
        // No more distinct sources exist than the index holds.
        let k = k.min(self.sources.len());
        let mut q = Vec::with_capacity(self.mean.len());
        patch_vector(cubes.video, self.patch, t, &mut q);
        let q = self.project(&q);
        let mut cands: Vec<Match> = self
            .knn(&q, self.params.rerank.max(4 * k))
            .into_iter()
            .map(|i| {
                let s = self.sources[i];
                Match {
                    source: s,
                    dist: cubes.ssd(t, s, f32::INFINITY),
                }
            })
            .collect();
        cands.sort_by(|a, b| a.dist.total_cmp(&b.dist).then(a.source.cmp(&b.source)));
        let apart =
            |a: P3, b: P3| a[0] != b[0] || a[1].abs_diff(b[1]).max(a[2].abs_diff(b[2])) > min_sep;
        let mut out: Vec<Match> = Vec::with_capacity(k);
        for m in cands {
            if apart(m.source, exclude) && out.iter().all(|o| apart(o.source, m.source)) {
                out.push(m);
                if out.len() == k {
                    break;
                }
            }
        }
        out
    }

    /// Indices (tree order) of the approximately `k` nearest points to `q`.
    fn knn(&self, q: &[f32], k: usize) -> Vec<usize> {
        // No more neighbours exist than points (a huge `rerank` asks for all of them).
        let k = k.clamp(1, self.sources.len().max(1));
        let mut best: Vec<(f32, usize)> = Vec::with_capacity(k + 1);
        let mut heap = BinaryHeap::new();
        heap.push(MinEntry(0.0, 0));
        let mut checks = 0;
        while let Some(MinEntry(bound, mut node)) = heap.pop() {
            if best.len() == k && bound >= best[k - 1].0 {
                break;
            }
            loop {
                match &self.nodes[node] {
                    Node::Split {
                        axis,
                        value,
                        left,
                        right,
                    } => {
                        let diff = q[*axis] - value;
                        let (near, far) = if diff < 0.0 {
                            (*left, *right)
                        } else {
                            (*right, *left)
                        };
                        heap.push(MinEntry(bound.max(diff * diff), far));
                        node = near;
                    }
                    Node::Leaf { start, end } => {
                        for i in *start..*end {
                            let p = &self.points[i * self.dims..(i + 1) * self.dims];
                            let d: f32 = p.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum();
                            if best.len() < k || d < best[k - 1].0 {
                                let pos = best.partition_point(|e| (e.0, e.1) < (d, i));
                                best.insert(pos, (d, i));
                                best.truncate(k);
                            }
                        }
                        break;
                    }
                }
            }
            checks += 1;
            if checks >= self.params.max_checks {
                break;
            }
        }
        best.into_iter().map(|e| e.1).collect()
    }

    /// Memory of the index in bytes (projections, sources, tree).
    pub fn bytes(&self) -> usize {
        self.points.len() * 4
            + self.sources.len() * 12
            + self.nodes.len() * std::mem::size_of::<Node>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_exact_copy_of_a_source_patch() {
        // With every axis kept and enough checks, the query of a source's own cube returns it
        // (distance 0; the texture has no other exact copy).
        let (clip, patch, sources) = crate::testing::small_pan();
        let p = PcaKdParams {
            dims: 27,
            rerank: 4,
            max_checks: 100_000,
            samples: 100_000,
            seed: 1,
        };
        let index = PcaIndex::build(&clip.observed, &sources, patch, p).unwrap();
        let cubes = Cubes::new(&clip.observed, &sources, patch);
        for s in sources.points().into_iter().step_by(37) {
            let m = index.best(&cubes, s, None);
            assert_eq!(m.dist, 0.0, "{s:?} -> {m:?}");
        }
        assert!(index.bytes() > 0);
    }
}
