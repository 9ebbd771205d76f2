//! Best-match search for one hole pixel at the low resolutions (paper 06, section 3.2): exact
//! search over every valid source, or space-time PatchMatch (Barnes et al. 2009 as in
//! Newson et al. 2014) embedded in the filling order: the current match, the matches of the
//! six grid neighbours shifted back (those in earlier shells were already updated in this
//! sweep) and a random search around the best so far.

use rayon::prelude::*;

use crate::field::temporal_sources;
use crate::patch::Cubes;
use crate::patchmatch::{propagate, random_search, target_rng, Match, TargetSet, P3};
use crate::pca_index::{PcaIndex, PcaKdParams};
use crate::video::Mask3;

/// How stage 1 finds the best source of a hole pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchMethod {
    /// Every valid source, exact SSD (small videos and tests).
    Exact,
    /// Space-time PatchMatch (memory: one match per hole pixel): before each sweep, `iters`
    /// Jacobi PatchMatch iterations over the whole match list with the current colours, then
    /// one PatchMatch update per pixel inside the filling order.
    PatchMatch3D {
        /// Whole-field iterations before each sweep (5).
        iters: usize,
        /// Random-search seed.
        seed: u64,
    },
    /// The paper's search: PCA of the patches, a kd-tree over all valid sources, bounded
    /// best-bin-first queries and exact re-ranking ([`crate::pca_index`]). Memory: `dims`
    /// floats per valid source.
    PcaKdTree(PcaKdParams),
}

/// The search structure of one level.
pub(crate) enum Searcher {
    /// Every valid source.
    Exact(Vec<P3>),
    /// PatchMatch updates.
    PatchMatch {
        /// Random-search seed.
        seed: u64,
    },
    /// PCA + kd-tree index.
    Pca(PcaIndex),
}

impl Searcher {
    /// The structure `method` needs on a level.
    pub(crate) fn new(
        method: SearchMethod,
        video: &crate::video::Video,
        sources: &Mask3,
        patch: crate::patch::PatchSize,
    ) -> wscg_math::Result<Self> {
        Ok(match method {
            SearchMethod::Exact => Self::Exact(source_list(sources)),
            SearchMethod::PatchMatch3D { seed, .. } => Self::PatchMatch { seed },
            SearchMethod::PcaKdTree(p) => Self::Pca(PcaIndex::build(video, sources, patch, p)?),
        })
    }

    /// The new match of target `i` in sweep `sweep`; with the level's hole in `temporal`, the
    /// search also tries the target's temporal candidates ([`temporal_sources`]; exact search
    /// then stays exact over the valid sources and the temporal candidates).
    pub(crate) fn best(
        &self,
        cubes: &Cubes<'_>,
        targets: &TargetSet,
        ml: &[Match],
        i: usize,
        sweep: usize,
        temporal: Option<&Mask3>,
    ) -> Match {
        let t = targets.get(i);
        let mut best = match self {
            Self::Exact(list) => exact_best(cubes, t, list),
            Self::PatchMatch { seed } => patchmatch_update(cubes, targets, ml, i, *seed, sweep),
            Self::Pca(index) => index.best(
                cubes,
                t,
                Some(ml[i].source).filter(|s| cubes.sources.contains(*s)),
            ),
        };
        if let Some(hole) = temporal {
            for s in temporal_sources(hole, cubes.patch, t) {
                if s != best.source {
                    let d = cubes.ssd(t, s, best.dist);
                    if d < best.dist {
                        best = Match { source: s, dist: d };
                    }
                }
            }
        }
        best
    }
}

impl Default for SearchMethod {
    fn default() -> Self {
        Self::PatchMatch3D { iters: 5, seed: 0 }
    }
}

/// The valid sources of a level as a list (for exact search and random starts).
pub fn source_list(sources: &Mask3) -> Vec<P3> {
    sources.points()
}

/// The exact best source of `t` among `sources` (ties to the first in scan order).
pub fn exact_best(cubes: &Cubes<'_>, t: P3, sources: &[P3]) -> Match {
    let mut best = Match {
        source: sources[0],
        dist: f32::INFINITY,
    };
    for &s in sources {
        let d = cubes.ssd(t, s, best.dist);
        if d < best.dist {
            best = Match { source: s, dist: d };
        }
    }
    best
}

/// Exact best sources of many targets, in parallel.
pub fn exact_best_all(cubes: &Cubes<'_>, targets: &[P3], sources: &[P3]) -> Vec<Match> {
    targets
        .par_iter()
        .map(|&t| exact_best(cubes, t, sources))
        .collect()
}

/// One PatchMatch update of target `i` (position `t`): current match (distance recomputed
/// with the current colours), propagation from the grid neighbours' matches in `ml`, random
/// search with radii halving from the video extents.
pub fn patchmatch_update(
    cubes: &Cubes<'_>,
    targets: &TargetSet,
    ml: &[Match],
    i: usize,
    seed: u64,
    sweep: usize,
) -> Match {
    let t = targets.get(i);
    let dims = targets.dims();
    let mut best = Match {
        source: ml[i].source,
        dist: cubes.ssd(t, ml[i].source, f32::INFINITY),
    };
    propagate(cubes, targets, ml, t, &mut best);
    let mut r = target_rng(seed, sweep, i);
    let radius = [dims[0] as u32, dims[1] as u32, dims[2] as u32];
    random_search(cubes, t, &mut best, radius, &mut r);
    best
}

/// A random valid source for every target (PatchMatch's start), deterministic in `seed`:
/// a uniformly drawn grid point if it is a source (up to 64 draws), else the first source at
/// or after the last draw in scan order (wrapping). `sources` must not be empty.
pub fn random_matches(sources: &Mask3, n: usize, seed: u64) -> Vec<Match> {
    use rand::Rng as _;
    let dims = sources.dims();
    let total = sources.len_grid();
    (0..n)
        .into_par_iter()
        .map(|i| {
            let mut r = wscg_math::rng::stream(seed, i as u64);
            let mut k = 0;
            for _ in 0..64 {
                k = r.random_range(0..total);
                if sources.contains_index(k) {
                    break;
                }
            }
            let k = (0..total)
                .map(|j| (k + j) % total)
                .find(|&j| sources.contains_index(j))
                .expect("a source");
            Match {
                source: crate::patchmatch::position(dims, k as u64),
                dist: f32::INFINITY,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patch::Cubes;
    use crate::pca_index::{PcaIndex, PcaKdParams};

    #[test]
    fn a_rerank_list_longer_than_the_sources_is_the_exact_search() {
        // A `rerank` beyond the sources' count re-ranks every source (the length of its list
        // overflowed): the exact best of every hole pixel, and as many hypotheses as asked
        // where the sources allow.
        let (clip, patch, sources) = crate::testing::small_pan();
        let p = PcaKdParams {
            dims: 4,
            rerank: usize::MAX,
            max_checks: usize::MAX,
            samples: 1000,
            seed: 1,
        };
        let index = PcaIndex::build(&clip.observed, &sources, patch, p).unwrap();
        let cubes = Cubes::new(&clip.observed, &sources, patch);
        let all = source_list(&sources);
        for t in clip.hole.iter_points().step_by(11) {
            let exact = exact_best(&cubes, t, &all);
            assert_eq!(index.best(&cubes, t, None).dist, exact.dist, "{t:?}");
            let k = index.best_k(&cubes, t, usize::MAX, exact.source, 1);
            assert!(k.len() > 1 && k.len() < all.len(), "{}", k.len());
        }
    }
}
