//! Match lists (paper 06: `ML` at the working resolution, `MLH` at finer ones): for every hole
//! pixel, the centre of the source cube its colour was copied from; and their transfer from a
//! coarse level to a finer one (section 3.4, Fig. 8).

use rayon::prelude::*;

use crate::patch::{Cubes, PatchSize};
use crate::patchmatch::{Match, TargetSet, P3};
use crate::video::{Mask3, Video};

/// One match per hole pixel of a level.
#[derive(Clone, Debug, PartialEq)]
pub struct MatchField {
    /// The hole pixels, in scan order.
    pub targets: TargetSet,
    /// The match of each hole pixel (same order); `dist` is `D(w_p, w_p')` when last computed.
    pub matches: Vec<Match>,
}

impl MatchField {
    /// Number of matches.
    pub fn len(&self) -> usize {
        self.matches.len()
    }

    /// Whether there are no matches (no hole).
    pub fn is_empty(&self) -> bool {
        self.matches.is_empty()
    }

    /// The match of hole pixel `p`, if `p` is a hole pixel.
    pub fn get(&self, p: P3) -> Option<Match> {
        self.targets.rank(p).map(|i| self.matches[i])
    }

    /// The four spatial neighbour steps `(dt, dy, dx)`: top, right, bottom, left.
    pub const SPATIAL_STEPS: [(i64, i64, i64); 4] = [(0, -1, 0), (0, 0, 1), (0, 1, 0), (0, 0, -1)];
    /// The two temporal neighbour steps.
    pub const TEMPORAL_STEPS: [(i64, i64, i64); 2] = [(-1, 0, 0), (1, 0, 0)];

    /// The source that the match of `p`'s neighbour `q = p + step` (`(dt, dy, dx)`) implies
    /// for `p` (coherence: `q' - step`), with `q`'s index in the field; `None` when `q` is
    /// not a hole pixel or the implied source lies outside the video or is not a valid
    /// source. Used by stage 2's refinement and stage 3's propagation.
    pub fn implied_source(
        &self,
        p: P3,
        step: (i64, i64, i64),
        dims: [usize; 3],
        sources: &Mask3,
    ) -> Option<(usize, P3)> {
        let (dt, dy, dx) = step;
        let inside = |v: [i64; 3]| -> Option<P3> {
            v.iter()
                .zip(dims)
                .all(|(&c, n)| c >= 0 && c < n as i64)
                .then(|| [v[0] as u32, v[1] as u32, v[2] as u32])
        };
        let q = inside([p[0] as i64 + dt, p[1] as i64 + dy, p[2] as i64 + dx])?;
        let j = self.targets.rank(q)?;
        let s = self.matches[j].source;
        let c = inside([s[0] as i64 - dt, s[1] as i64 - dy, s[2] as i64 - dx])?;
        sources.contains(c).then_some((j, c))
    }

    /// Recomputes every `dist` with the current colours; returns the energy
    /// `E = sum_p D(w_p, w_NN(p))`: eq. 1 as a sum instead of a product, since the product of
    /// distances is degenerate (one exact match makes it zero).
    pub fn refresh(&mut self, cubes: &Cubes<'_>) -> f64 {
        let targets = &self.targets;
        self.matches.par_iter_mut().enumerate().for_each(|(i, m)| {
            m.dist = cubes.ssd(targets.get(i), m.source, f32::INFINITY);
        });
        self.energy()
    }

    /// `sum_p dist(p)` of the stored distances.
    pub fn energy(&self) -> f64 {
        self.matches.iter().map(|m| m.dist as f64).sum()
    }

    /// Copies every match's source colour onto its hole pixel (single best match, no
    /// blending: the paper's way of keeping grain and noise).
    pub fn apply(&self, video: &mut Video) {
        for (i, m) in self.matches.iter().enumerate() {
            video.copy_pixel(self.targets.get(i), m.source);
        }
    }
}

/// Whether `s` may be copied from as a temporal candidate: a known pixel (`s` in `E`, as in
/// eq. 1's `p' in E`) whose cube lies inside the video. Unlike the valid sources of the
/// search, its cube may hold hole pixels, which compare with their current colours.
pub fn copyable(hole: &Mask3, patch: PatchSize, s: P3) -> bool {
    let r = patch.radius();
    (0..3).all(|a| s[a] >= r[a] && (s[a] + r[a]) < hole.dims()[a] as u32) && !hole.contains(s)
}

/// The temporal candidates of hole pixel `p = (t, y, x)`: the same position `(t', y, x)` in
/// the nearest earlier frame and in the nearest later frame where it is [`copyable`] (at most
/// two, earlier first). Behind a moving object filmed by a static camera these are exact
/// copies of what the object hides (the background mosaics of the static-camera methods the
/// paper reviews in section 2.1), which the paper's spatial search reaches only by chance;
/// and when the object hides a pixel for most of the clip, no hole-free cube is centred on
/// its visible copies at all.
pub fn temporal_sources(hole: &Mask3, patch: PatchSize, p: P3) -> impl Iterator<Item = P3> + '_ {
    let at = move |u: u32| [u, p[1], p[2]];
    let ok = move |s: &P3| copyable(hole, patch, *s);
    let before = (0..p[0]).rev().map(at).find(ok);
    let after = (p[0] + 1..hole.frames as u32).map(at).find(ok);
    before.into_iter().chain(after)
}

/// The valid source nearest to `p` in its frame (Chebyshev rings of growing radius, scan order
/// within a ring), then in the nearest frames; `None` when the level has no source at all.
pub fn nearest_source(sources: &Mask3, p: P3) -> Option<P3> {
    let [f, h, w] = sources.dims();
    let max_r = h.max(w);
    let t0 = p[0] as i64;
    let (y0, x0) = (p[1] as i64, p[2] as i64);
    for dt in 0..f as i64 {
        let frames: Vec<i64> = if dt == 0 {
            vec![t0]
        } else {
            vec![t0 - dt, t0 + dt]
        };
        let frames: Vec<i64> = frames
            .into_iter()
            .filter(|&t| t >= 0 && t < f as i64)
            .collect();
        for r in 0..=max_r as i64 {
            for &t in &frames {
                for y in y0 - r..=y0 + r {
                    if y < 0 || y >= h as i64 {
                        continue;
                    }
                    let edge = y == y0 - r || y == y0 + r;
                    let step = if edge { 1 } else { (2 * r).max(1) as usize };
                    for x in (x0 - r..=x0 + r).step_by(step) {
                        if x >= 0
                            && x < w as i64
                            && sources.contains([t as u32, y as u32, x as u32])
                        {
                            return Some([t as u32, y as u32, x as u32]);
                        }
                    }
                }
            }
        }
    }
    None
}

/// The matches of the finer level's hole pixels from the coarse level's (factor `s`): for
/// `p_h = (t, y, x)`, `p_l = (t, y / s, x / s)` (a coarse hole pixel by the "any" rule) and
/// `p'_h = (t'_l, s y'_l + y mod s, s x'_l + x mod s)` with `(t'_l, y'_l, x'_l) = ML[p_l]`: the
/// offset inside the block keeps neighbouring fine pixels on neighbouring sources. An invalid
/// `p'_h` is replaced by the nearest valid source ([`nearest_source`]), unless `temporal`
/// holds the fine level's hole and patch and `p'_h` is [`copyable`] there (the up-scaled
/// match of a temporal candidate). Distances are left infinite (not computed). `None` when
/// the fine level has no valid source.
pub fn upscale_matches(
    coarse: &MatchField,
    fine_targets: &TargetSet,
    fine_sources: &Mask3,
    temporal: Option<(&Mask3, PatchSize)>,
    s: usize,
) -> Option<Vec<Match>> {
    let up = upscale_sources(
        &coarse.targets,
        |j| coarse.matches[j].source,
        fine_targets,
        fine_sources,
        temporal,
        s,
    )?;
    Some(
        up.into_iter()
            .map(|source| Match {
                source,
                dist: f32::INFINITY,
            })
            .collect(),
    )
}

/// [`upscale_matches`] for any per-pixel source of the coarse level: `source_of(j)` is the
/// source of the coarse hole pixel `coarse_targets.get(j)`.
pub fn upscale_sources(
    coarse_targets: &TargetSet,
    source_of: impl Fn(usize) -> P3 + Sync,
    fine_targets: &TargetSet,
    fine_sources: &Mask3,
    temporal: Option<(&Mask3, PatchSize)>,
    s: usize,
) -> Option<Vec<P3>> {
    let s32 = s as u32;
    let dims = fine_targets.dims();
    (0..fine_targets.len())
        .into_par_iter()
        .map(|i| {
            let p = fine_targets.get(i);
            let parent = [p[0], p[1] / s32, p[2] / s32];
            let guess = coarse_targets.rank(parent).map(|j| {
                let c = source_of(j);
                [
                    c[0],
                    (c[1] * s32 + p[1] % s32).min(dims[1] as u32 - 1),
                    (c[2] * s32 + p[2] % s32).min(dims[2] as u32 - 1),
                ]
            });
            Some(match guess {
                Some(g)
                    if fine_sources.contains(g)
                        || temporal.is_some_and(|(hole, patch)| copyable(hole, patch, g)) =>
                {
                    g
                }
                Some(g) => nearest_source(fine_sources, g)?,
                None => nearest_source(fine_sources, p)?,
            })
        })
        .collect()
}

/// The stopping rule of stages 1 and 3: an iteration that took the energy from `prev` to
/// `last` lowered it by no more than the fraction `min_drop` (a plateau, including an exact
/// completion at energy 0, or a rise).
pub fn energy_settled(prev: f64, last: f64, min_drop: f64) -> bool {
    prev - last <= min_drop * prev
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_source_searches_rings_then_frames() {
        let src = Mask3::from_fn(3, 10, 10, |t, y, x| {
            t == 2 && y == 7 && x == 1 || t == 0 && y == 2 && x == 9
        });
        assert_eq!(nearest_source(&src, [0, 2, 2]), Some([0, 2, 9]));
        assert_eq!(nearest_source(&src, [1, 7, 2]), Some([2, 7, 1]));
        assert_eq!(nearest_source(&Mask3::empty(2, 3, 3), [0, 0, 0]), None);
    }

    #[test]
    fn upscaling_keeps_the_offset_in_the_block() {
        let dims = [1, 8, 8];
        let coarse_hole = Mask3::from_fn(1, 4, 4, |_, y, x| y == 1 && x == 1);
        let coarse = MatchField {
            targets: TargetSet::new([1, 4, 4], coarse_hole.points()),
            matches: vec![Match {
                source: [0, 3, 2],
                dist: 0.0,
            }],
        };
        let fine_hole = Mask3::from_fn(1, 8, 8, |_, y, x| {
            (2..4).contains(&y) && (2..4).contains(&x)
        });
        let fine_targets = TargetSet::new(dims, fine_hole.points());
        let all = Mask3::from_fn(1, 8, 8, |_, _, _| true);
        let up = upscale_matches(&coarse, &fine_targets, &all, None, 2).unwrap();
        let got: Vec<P3> = up.iter().map(|m| m.source).collect();
        assert_eq!(got, vec![[0, 6, 4], [0, 6, 5], [0, 7, 4], [0, 7, 5]]);
    }
}
