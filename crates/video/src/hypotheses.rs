//! Multiple hypotheses for stage 3 of paper 06: stage 1's next-best sources of each hole
//! pixel, searched around at the first iteration of the localized search.
//!
//! The localized search (section 3.4) looks only around each pixel's up-scaled match, so a
//! region whose match list settled on a poor copy keeps it: the local minimum the paper names
//! in its section 5. Exact global search instead copies such regions from wherever the video
//! repeats them, often far away or in other frames. The paper's own search structure (PCA and
//! a kd-tree over every valid source, section 3.2) already ranks those copies at the working
//! resolution: keeping its `k` best distinct sources per pixel and searching a small window
//! around each, up-scaled, lets the finer levels reach them for `k w^2` more candidates per
//! pixel, once, and no more memory than `k` sources per hole pixel.

use rayon::prelude::*;
use wscg_math::alloc::ensure_shape;

use crate::field::{upscale_sources, MatchField};
use crate::patch::{Cubes, PatchSize};
use crate::patchmatch::{TargetSet, P3};
use crate::pca_index::PcaIndex;
use crate::video::{Mask3, Video};

/// `per` sources for every hole pixel of a level, pixel-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Hypotheses {
    /// Sources per hole pixel.
    pub per: usize,
    /// The hole pixels, in scan order.
    pub targets: TargetSet,
    /// `per` sources of each hole pixel, best first (pixel-major).
    pub sources: Vec<P3>,
}

impl Hypotheses {
    /// The `k` best sources of each hole pixel of `ml` other than its match, by `index`'s
    /// search with the current colours of `video` (the completed working level), each more
    /// than one pixel from the match and from each other. A pixel with fewer such sources
    /// repeats its match.
    ///
    /// Errors: [`wscg_math::Error::OutOfMemory`] naming `hypotheses` when `k` sources per hole
    /// pixel exceed the memory limit ([`wscg_math::alloc`]).
    pub fn next_best(
        video: &Video,
        sources: &Mask3,
        ml: &MatchField,
        patch: PatchSize,
        index: &PcaIndex,
        k: usize,
    ) -> wscg_math::Result<Self> {
        ensure_shape::<P3>("hypotheses", &[ml.len(), k])?;
        let cubes = Cubes::new(video, sources, patch);
        let lists: Vec<Vec<P3>> = (0..ml.len())
            .into_par_iter()
            .map(|i| {
                let own = ml.matches[i].source;
                let mut l: Vec<P3> = index
                    .best_k(&cubes, ml.targets.get(i), k, own, 1)
                    .into_iter()
                    .map(|m| m.source)
                    .collect();
                l.resize(k, own);
                l
            })
            .collect();
        Ok(Self {
            per: k,
            targets: ml.targets.clone(),
            sources: lists.concat(),
        })
    }

    /// The hypotheses of the finer level's hole pixels (factor `s`), up-scaled offset-preserving
    /// like the matches ([`crate::field::upscale_matches`]); pixel-major, `per` each. `None`
    /// when the fine level has no valid source.
    ///
    /// Errors: [`wscg_math::Error::OutOfMemory`] naming `hypotheses` when `per` sources per
    /// fine hole pixel exceed the memory limit.
    pub fn upscale(
        &self,
        fine_targets: &TargetSet,
        fine_sources: &Mask3,
        temporal: Option<(&Mask3, PatchSize)>,
        s: usize,
    ) -> wscg_math::Result<Option<Vec<P3>>> {
        let per = self.per;
        ensure_shape::<P3>("hypotheses", &[fine_targets.len(), per])?;
        let ranks: Option<Vec<Vec<P3>>> = (0..per)
            .map(|j| {
                upscale_sources(
                    &self.targets,
                    |i| self.sources[i * per + j],
                    fine_targets,
                    fine_sources,
                    temporal,
                    s,
                )
            })
            .collect();
        Ok(ranks.map(|ranks| {
            (0..fine_targets.len())
                .flat_map(|i| ranks.iter().map(move |r| r[i]))
                .collect()
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::upscale_matches;
    use crate::patch::valid_sources;
    use crate::patchmatch::Match;
    use crate::pca_index::PcaKdParams;
    use crate::search::exact_best_all;

    fn setup() -> (crate::synth::Clip, Mask3, PatchSize, MatchField) {
        let (clip, patch, sources) = crate::testing::small_pan();
        let targets = TargetSet::new(clip.hole.dims(), clip.hole.iter_points());
        let points: Vec<P3> = (0..targets.len()).map(|i| targets.get(i)).collect();
        let cubes = Cubes::new(&clip.observed, &sources, patch);
        let matches = exact_best_all(&cubes, &points, &sources.points());
        (clip, sources, patch, MatchField { targets, matches })
    }

    #[test]
    fn next_best_are_the_exact_runners_up_apart_from_the_match() {
        // With every axis kept and a re-ranking list as long as the sources, the index's
        // ranking is exact: the hypotheses are the greedy best sources by exact D that lie more
        // than one pixel from the match and from each better hypothesis (same frame).
        let (clip, sources, patch, ml) = setup();
        let all = sources.points();
        let params = PcaKdParams {
            dims: 27,
            rerank: all.len(),
            max_checks: usize::MAX,
            samples: 100_000,
            seed: 1,
        };
        let index = PcaIndex::build(&clip.observed, &sources, patch, params).unwrap();
        let k = 3;
        let h = Hypotheses::next_best(&clip.observed, &sources, &ml, patch, &index, k).unwrap();
        assert_eq!(h.sources.len(), k * ml.len());
        let cubes = Cubes::new(&clip.observed, &sources, patch);
        let apart = |a: P3, b: P3| a[0] != b[0] || a[1].abs_diff(b[1]).max(a[2].abs_diff(b[2])) > 1;
        for i in 0..ml.len() {
            let t = ml.targets.get(i);
            let mut ranked: Vec<(f32, P3)> = all
                .iter()
                .map(|&s| (cubes.ssd(t, s, f32::INFINITY), s))
                .collect();
            ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let mut want: Vec<P3> = Vec::new();
            for (_, s) in ranked {
                if apart(s, ml.matches[i].source) && want.iter().all(|&w| apart(w, s)) {
                    want.push(s);
                    if want.len() == k {
                        break;
                    }
                }
            }
            assert_eq!(&h.sources[i * k..(i + 1) * k], &want[..], "pixel {t:?}");
        }
    }

    #[test]
    fn upscaling_each_rank_is_upscaling_it_as_a_match_list() {
        let (clip, sources, patch, ml) = setup();
        let index =
            PcaIndex::build(&clip.observed, &sources, patch, PcaKdParams::default()).unwrap();
        let h = Hypotheses::next_best(&clip.observed, &sources, &ml, patch, &index, 2).unwrap();
        let [f, hh, ww] = clip.hole.dims();
        let fine_hole = Mask3::from_fn(f, 2 * hh, 2 * ww, |t, y, x| {
            clip.hole
                .contains([t as u32, (y / 2) as u32, (x / 2) as u32])
        });
        let fine_targets = TargetSet::new(fine_hole.dims(), fine_hole.iter_points());
        let fine_sources = valid_sources(&fine_hole, patch);
        let up = h
            .upscale(&fine_targets, &fine_sources, None, 2)
            .unwrap()
            .unwrap();
        for j in 0..2 {
            let rank = MatchField {
                targets: ml.targets.clone(),
                matches: (0..ml.len())
                    .map(|i| Match {
                        source: h.sources[i * 2 + j],
                        dist: 0.0,
                    })
                    .collect(),
            };
            let want = upscale_matches(&rank, &fine_targets, &fine_sources, None, 2).unwrap();
            let got: Vec<P3> = (0..fine_targets.len()).map(|i| up[i * 2 + j]).collect();
            assert_eq!(got, want.iter().map(|m| m.source).collect::<Vec<_>>());
        }
    }
}
