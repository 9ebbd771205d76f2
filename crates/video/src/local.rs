//! Stage 3 of paper 06 (section 3.4, Figs. 8-9): localized search completion at the finer
//! resolutions. Each hole pixel searches exactly, on uncompressed data, only a small window
//! `S` around its current match (17, 13, 9 then 5 pixels wide, re-centred after each
//! iteration) instead of every cube of the video, and no search structure, so the memory is
//! the video plus one match per hole pixel.
//!
//! The paper's stage 3 iterates "similar to ... the low-resolution process", with the
//! window "decreased after each iteration (13 x 13, 9 x 9, 5 x 5)". Its iterations therefore
//! go on at the last window, and stop like stage 1's: once an iteration lowers the energy by
//! no more than a fraction (`min_energy_drop`), after `max_iterations`, or before an iteration
//! that would take the candidates compared per pixel over `max_candidates`, 1000 by default:
//! the paper's "less than a thousand patches are searched for each p_h".
//!
//! The default windows also reach one frame on each side of the match's frame once they are
//! 5 pixels wide (`temporal_radius` 0, 0, 0, 1): 289 + 169 + 81 + 75 per iteration, plus
//! eight coherence and temporal candidates per iteration, so eight iterations fit the budget
//! (978 candidates per pixel). The paper's windows stay within the match's frame
//! (`temporal_radius` 0).
//!
//! When stage 1 searched with the paper's PCA + kd-tree index, each pixel's first iteration
//! also searches 3 x 3 windows around stage 1's six next-best sources ([`crate::hypotheses`]),
//! 54 candidates that the budget counts (seven iterations then fit).

use rayon::prelude::*;

use crate::field::{energy_settled, temporal_sources, MatchField};
use crate::onion::onion_order;
use crate::patch::{Cubes, PatchSize};
use crate::patchmatch::{Match, P3};
use crate::video::{Mask3, Video};

/// How stage 3 climbs from the working resolution to the full one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpscaleStep {
    /// Doubling per level (480 -> 960 -> 1920); the last step takes what remains.
    Double,
    /// One step to full resolution (the paper's Fig. 8 shows this).
    Direct,
}

wscg_math::params! {
    /// Parameters of stage 3.
    #[derive(Clone, Debug, PartialEq)]
    pub struct LocalSearchParams {
        /// Window widths of the first iterations (17, 13, 9, 5: Fig. 9); later iterations keep
        /// the last width.
        pub windows: Vec<usize>,
        /// Iterations at most (at least `windows.len()` are run): 16.
        pub max_iterations: usize,
        /// Candidate cubes per hole pixel at most, over all iterations of a level: the
        /// iterations stop before one whose window and extra candidates would exceed it (at
        /// least `windows.len()` are run). 1000: the paper's "less than a thousand patches are
        /// searched for each p_h" (section 3.4).
        pub max_candidates: usize,
        /// After the listed windows, stop once an iteration lowers the energy by no more than
        /// this fraction (stage 1's rule; a plateau or a rise stops too): 5e-3.
        pub min_energy_drop: f64,
        /// Frames searched on each side of the match's frame, per iteration like `windows`
        /// (the last value repeats; 0: the match's frame only, as in the paper's Fig. 9):
        /// 0, 0, 0, 1, so the 5-pixel windows are 5 x 5 x 3 blocks.
        pub temporal_radius: Vec<usize>,
        /// Level schedule.
        pub step: UpscaleStep,
        /// After its window, each pixel also tries the sources its six space-time neighbours'
        /// current matches imply (`q' - (q - p)`, the coherence candidates of stage 2). The
        /// paper's windows are re-centred on a pixel's own match only, so a region whose best
        /// sources lie beyond the window from the up-scaled match cannot reach them; the
        /// neighbours' matches carry good offsets across it. Six more candidates per pixel;
        /// `false` is the paper's stage 3 alone. True.
        pub propagate: bool,
        /// Each pixel also tries its temporal candidates, the same position in the nearest
        /// earlier and later frames where it is known ([`crate::field::temporal_sources`]):
        /// two more candidates per pixel. True.
        pub temporal_candidates: bool,
        /// After each iteration, a raster scan and its reverse in which each hole pixel tries
        /// the sources its already-scanned neighbours' matches imply (PatchMatch's
        /// propagation order, Barnes et al. 2009). The shells of an iteration are searched in
        /// parallel from the state before them, so an offset that one pixel finds reaches
        /// its shell-mates only one pixel per iteration; the scan carries it across the
        /// region at once. Four more candidates per pixel and iteration (the budget still
        /// fits seven iterations); the scan is sequential. Measured on 19 zoom clips (check
        /// 5's size, seeds the check does not use): 3.3 % lower energy in the geometric mean
        /// (one clip 0.8 % higher), 3.6 % on four other seeds. False: off by default, since
        /// it is serial.
        pub scan_propagation: bool,
        /// Stage 1's next-best sources kept per hole pixel ([`crate::hypotheses`]): at the
        /// first level, each pixel also searches a `hypothesis_window`-wide window around each
        /// of them, up-scaled, in the first `hypothesis_iterations` iterations, so a region can
        /// leave the copy its up-scaled match started it on for one that the windows around
        /// that match never reach (the local minimum of the paper's section 5). Only stage 1's
        /// PCA + kd-tree search ranks them ([`crate::search::SearchMethod::PcaKdTree`]); with
        /// another search there are none. 6: 54 more candidates per pixel in the first
        /// iteration, out of `max_candidates`, so one iteration fewer fits the budget (seven).
        /// 0: the paper's stage 3, around the best match only.
        pub hypotheses: usize,
        /// Width of the window around each hypothesis (odd): 3.
        pub hypothesis_window: usize,
        /// Iterations that search around the hypotheses: 1.
        pub hypothesis_iterations: usize,
    }
}

impl LocalSearchParams {
    /// Iterations at most: `max_iterations`, and no more than fit in `max_candidates`
    /// ([`Self::candidates`]), but at least one per listed window.
    pub fn iteration_cap(&self) -> usize {
        // Iterations cost the same in runs: each listed one alone, then those with the
        // hypotheses, then the rest; a run is counted at once (a huge limit costs nothing).
        let listed = self.windows.len().max(self.temporal_radius.len());
        let hyp_end = self.hypothesis_iterations.max(listed);
        let mut left = self.max_candidates;
        let mut fit = 0;
        while fit < self.max_iterations {
            let end = match fit {
                k if k < listed => k + 1,
                k if k < hyp_end => hyp_end,
                _ => self.max_iterations,
            }
            .min(self.max_iterations);
            let each = self.candidates(fit).max(1);
            let n = (left / each).min(end - fit);
            left -= n * each;
            fit += n;
            if fit < end {
                break;
            }
        }
        fit.max(self.windows.len())
    }

    /// Window width of iteration `k` (0-based): the listed widths, then the last one.
    pub fn window(&self, k: usize) -> usize {
        self.windows[k.min(self.windows.len() - 1)]
    }

    /// Temporal radius of iteration `k` (0-based): the listed radii, then the last one.
    pub fn radius_t(&self, k: usize) -> usize {
        self.temporal_radius[k.min(self.temporal_radius.len() - 1)]
    }

    /// The most candidate cubes a hole pixel compares in iteration `k`: the window's
    /// `w * w * (2 r_t + 1)` cubes (the current match among them), six coherence candidates
    /// with `propagate`, two temporal ones with `temporal_candidates` and four with
    /// `scan_propagation`.
    pub fn candidates(&self, k: usize) -> usize {
        // Saturating: a count beyond `usize` exceeds any budget.
        let cube = |w: usize, r: usize| {
            w.saturating_mul(w)
                .saturating_mul(r.saturating_mul(2).saturating_add(1))
        };
        let hyp = if k < self.hypothesis_iterations {
            self.hypotheses
                .saturating_mul(cube(self.hypothesis_window, 0))
        } else {
            0
        };
        cube(self.window(k), self.radius_t(k))
            .saturating_add(hyp)
            .saturating_add(if self.propagate { 6 } else { 0 })
            .saturating_add(if self.temporal_candidates { 2 } else { 0 })
            .saturating_add(if self.scan_propagation { 4 } else { 0 })
    }

    /// The paper's stage 3 (section 3.4, Fig. 9): the windows within the match's frame, no
    /// coherence or temporal candidates, the iteration and budget rules kept.
    pub fn paper() -> Self {
        Self {
            temporal_radius: vec![0],
            propagate: false,
            temporal_candidates: false,
            hypotheses: 0,
            ..Self::default()
        }
    }

    /// Whether stage 3 stops after the iterations whose energies are `energy`: every listed
    /// window has run and the last iteration lowered the energy by no more than
    /// `min_energy_drop` (or left it unchanged or raised it), or the cap is reached.
    pub fn converged(&self, energy: &[f64]) -> bool {
        let k = energy.len();
        if k >= self.iteration_cap() {
            return true;
        }
        if k < self.windows.len().max(2) {
            return false;
        }
        energy_settled(energy[k - 2], energy[k - 1], self.min_energy_drop)
    }
}

impl Default for LocalSearchParams {
    fn default() -> Self {
        Self {
            windows: vec![17, 13, 9, 5],
            max_iterations: 16,
            max_candidates: 1000,
            min_energy_drop: 5e-3,
            temporal_radius: vec![0, 0, 0, 1],
            step: UpscaleStep::Double,
            propagate: true,
            temporal_candidates: true,
            scan_propagation: false,
            hypotheses: 6,
            hypothesis_window: 3,
            hypothesis_iterations: 1,
        }
    }
}

impl LocalSearchParams {
    /// Errors: no window, a window width that is even or zero, an even `hypothesis_window`, no
    /// temporal radius, a negative or non-finite `min_energy_drop`.
    pub fn validate(&self) -> wscg_math::Result<()> {
        if self.hypothesis_window.is_multiple_of(2) {
            return Err(wscg_math::Error::invalid(
                "hypothesis_window",
                format!("must be odd, got {}", self.hypothesis_window),
            ));
        }
        if self.windows.is_empty() || self.windows.iter().any(|&w| w == 0 || w % 2 == 0) {
            return Err(wscg_math::Error::invalid(
                "windows",
                format!(
                    "window widths must be odd and positive, got {:?}",
                    self.windows
                ),
            ));
        }
        if self.temporal_radius.is_empty() {
            return Err(wscg_math::Error::invalid(
                "temporal_radius",
                "needs the radius of at least one iteration",
            ));
        }
        if !(self.min_energy_drop.is_finite() && self.min_energy_drop >= 0.0) {
            return Err(wscg_math::Error::invalid(
                "min_energy_drop",
                format!("must be finite and >= 0, got {}", self.min_energy_drop),
            ));
        }
        Ok(())
    }
}

/// What stage 3 did at one level.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalStats {
    /// Frame size `(height, width)`.
    pub size: (usize, usize),
    /// Hole pixels.
    pub hole_pixels: usize,
    /// Energy after each window iteration.
    pub energy: Vec<f64>,
    /// Candidate cubes compared in total.
    pub candidates: u64,
}

/// Runs the localized search on one level: `field` holds the up-scaled matches (`MLH`) and
/// the hole colours of `video` their sources' colours. For each window width, hole pixels are
/// visited shell by shell (each shell in parallel from the current state); each takes the
/// best valid source in the window around its current match, and its colour. `hypotheses`
/// holds `cfg.hypotheses` further sources per hole pixel (pixel-major), around which the
/// first `cfg.hypothesis_iterations` iterations also search; empty, none are searched, but
/// the budget still counts `cfg.hypotheses` (set it to 0).
///
/// Errors: invalid `cfg`; `hypotheses` neither empty nor `cfg.hypotheses` per hole pixel.
pub fn localized_search(
    video: &mut Video,
    hole: &Mask3,
    sources: &Mask3,
    field: &mut MatchField,
    patch: PatchSize,
    cfg: &LocalSearchParams,
    hypotheses: &[P3],
) -> wscg_math::Result<LocalStats> {
    cfg.validate()?;
    let per = cfg.hypotheses;
    if !hypotheses.is_empty() && hypotheses.len() != per * field.len() {
        return Err(wscg_math::Error::invalid(
            "hypotheses",
            format!(
                "{} sources for {} hole pixels, expected {per} each",
                hypotheses.len(),
                field.len()
            ),
        ));
    }
    let order = onion_order(hole, &field.targets)?;
    let dims = video.dims();
    let mut st = LocalStats {
        size: (video.height, video.width),
        hole_pixels: field.len(),
        energy: Vec::new(),
        candidates: 0,
    };
    while !cfg.converged(&st.energy) {
        wscg_math::cancel::check()?;
        // Half-widths beyond i64 cover the whole video anyway.
        let half = |n: usize| i64::try_from(n).unwrap_or(i64::MAX);
        let r = half(cfg.window(st.energy.len()) / 2);
        let rt = half(cfg.radius_t(st.energy.len()));
        let rh = half(cfg.hypothesis_window / 2);
        let with_hyp = !hypotheses.is_empty() && st.energy.len() < cfg.hypothesis_iterations;
        for shell in &order {
            let new: Vec<(Match, u64)> = {
                let cubes = Cubes::new(video, sources, patch);
                shell
                    .par_iter()
                    .map(|&i| {
                        let i = i as usize;
                        let p = field.targets.get(i);
                        let c = field.matches[i].source;
                        let mut best = Match {
                            source: c,
                            dist: cubes.ssd(p, c, f32::INFINITY),
                        };
                        let mut n = 1u64;
                        // A candidate other than the best so far (a valid source).
                        let mut try_source = |s: P3| {
                            if s != best.source {
                                n += 1;
                                let d = cubes.ssd(p, s, best.dist);
                                if d < best.dist {
                                    best = Match { source: s, dist: d };
                                }
                            }
                        };
                        window(c, r, rt, dims, sources, &mut try_source);
                        if with_hyp {
                            for &h in &hypotheses[i * per..(i + 1) * per] {
                                if sources.contains(h) {
                                    try_source(h);
                                }
                                window(h, rh, 0, dims, sources, &mut try_source);
                            }
                        }
                        if cfg.temporal_candidates {
                            temporal_sources(hole, patch, p).for_each(&mut try_source);
                        }
                        if cfg.propagate {
                            let steps = MatchField::SPATIAL_STEPS
                                .into_iter()
                                .chain(MatchField::TEMPORAL_STEPS);
                            for step in steps {
                                if let Some((_, s)) = field.implied_source(p, step, dims, sources) {
                                    try_source(s);
                                }
                            }
                        }
                        (best, n)
                    })
                    .collect()
            };
            for (&i, (m, n)) in shell.iter().zip(new) {
                let i = i as usize;
                st.candidates += n;
                field.matches[i] = m;
                video.copy_pixel(field.targets.get(i), m.source);
            }
        }
        if cfg.scan_propagation {
            st.candidates += scan_propagate(video, sources, field, patch);
        }
        st.energy
            .push(field.refresh(&Cubes::new(video, sources, patch)));
    }
    Ok(st)
}

/// One raster scan of the hole pixels in which each tries the sources its left and upper
/// neighbours' matches imply, then the reverse scan with the right and lower ones (PatchMatch's
/// propagation order, Barnes et al. 2009): a pixel sees the matches its neighbours took
/// earlier in the same scan, so one offset crosses a whole region. Colours are copied as
/// matches change. Returns the candidates compared.
fn scan_propagate(
    video: &mut Video,
    sources: &Mask3,
    field: &mut MatchField,
    patch: PatchSize,
) -> u64 {
    const FORWARD: [(i64, i64, i64); 2] = [(0, 0, -1), (0, -1, 0)];
    const BACKWARD: [(i64, i64, i64); 2] = [(0, 0, 1), (0, 1, 0)];
    let dims = video.dims();
    let len = field.len();
    let mut n = 0u64;
    for (steps, forward) in [(FORWARD, true), (BACKWARD, false)] {
        for k in 0..len {
            let i = if forward { k } else { len - 1 - k };
            let p = field.targets.get(i);
            let cubes = Cubes::new(video, sources, patch);
            // The stored distance is from before this iteration's later colour changes.
            let mut best = field.matches[i];
            best.dist = cubes.ssd(p, best.source, f32::INFINITY);
            let old = best.source;
            for step in steps {
                if let Some((_, s)) = field.implied_source(p, step, dims, sources) {
                    if s != best.source {
                        n += 1;
                        let d = cubes.ssd(p, s, best.dist);
                        if d < best.dist {
                            best = Match { source: s, dist: d };
                        }
                    }
                }
            }
            field.matches[i] = best;
            if best.source != old {
                video.copy_pixel(p, best.source);
            }
        }
    }
    n
}

/// Calls `f` on every valid source of the window of half-width `r` (frames `rt` either side)
/// around `c`, other than `c`.
#[inline]
fn window(c: P3, r: i64, rt: i64, dims: [usize; 3], sources: &Mask3, f: &mut impl FnMut(P3)) {
    let range = |a: usize, r: i64| {
        (c[a] as i64).saturating_sub(r).max(0)
            ..=(c[a] as i64).saturating_add(r).min(dims[a] as i64 - 1)
    };
    for t in range(0, rt) {
        for y in range(1, r) {
            for x in range(2, r) {
                let s = [t as u32, y as u32, x as u32];
                if s != c && sources.contains(s) {
                    f(s);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patchmatch::TargetSet;
    use crate::search::exact_best_all;

    #[test]
    fn the_scan_carries_one_pixels_offset_across_its_region() {
        // A static clip: every hole pixel's exact copy is its own position three frames
        // later. Only the first (or the last) hole pixel starts on it, the others on a poor
        // source, and a 1-pixel window without coherence candidates cannot leave it; one
        // scan spreads the offset to the whole block (the reverse scan from the last).
        let (f, h, w) = (9, 12, 14);
        let data: Vec<u8> = (0..f * h * w * 3)
            .map(|k| {
                let (px, c) = (k / 3 % (h * w), k % 3);
                let (y, x) = (px / w, px % w);
                ((y * 37 + x * 11 + c * 5 + (x * y) % 7 * 19) % 251) as u8
            })
            .collect();
        let video = Video::new(f, h, w, 3, data).unwrap();
        let hole = Mask3::from_fn(f, h, w, |t, y, x| {
            t == 2 && (4..8).contains(&y) && (5..9).contains(&x)
        });
        let patch = PatchSize {
            px: 3,
            py: 3,
            pt: 3,
        };
        let sources = crate::patch::valid_sources(&hole, patch);
        let targets = TargetSet::new(hole.dims(), hole.iter_points());
        let later = |p: P3| [p[0] + 3, p[1], p[2]];
        let poor = [6, 1, 1];
        let run = |scan: bool, start: usize| {
            let mut v = video.clone();
            let mut matches: Vec<Match> = (0..targets.len())
                .map(|_| Match {
                    source: poor,
                    dist: f32::INFINITY,
                })
                .collect();
            matches[start].source = later(targets.get(start));
            let mut field = MatchField {
                targets: targets.clone(),
                matches,
            };
            field.apply(&mut v);
            let cfg = LocalSearchParams::paper()
                .windows(vec![1])
                .max_iterations(1)
                .scan_propagation(scan);
            assert_eq!(cfg.candidates(0), 1 + if scan { 4 } else { 0 });
            let st = localized_search(&mut v, &hole, &sources, &mut field, patch, &cfg, &[]);
            (field, st.unwrap(), v)
        };
        for start in [0, targets.len() - 1] {
            let (without, _, _) = run(false, start);
            assert_eq!(
                without.matches.iter().filter(|m| m.source != poor).count(),
                1
            );
            let (with, st, v) = run(true, start);
            for (i, m) in with.matches.iter().enumerate() {
                assert_eq!(m.source, later(with.targets.get(i)));
            }
            assert_eq!(st.energy, vec![0.0]);
            assert_eq!(v, video);
        }
    }

    #[test]
    fn the_first_iteration_searches_around_the_hypotheses() {
        // Every hole pixel starts on one poor source, and a 1-pixel window cannot leave it;
        // a hypothesis one pixel off the pixel's exact best source puts that source into its
        // 3 x 3 window.
        let (clip, patch, sources) = crate::testing::small_pan();
        let all = sources.points();
        let targets = TargetSet::new(clip.hole.dims(), clip.hole.iter_points());
        let points: Vec<P3> = (0..targets.len()).map(|i| targets.get(i)).collect();
        let best = exact_best_all(&Cubes::new(&clip.clean, &sources, patch), &points, &all);
        let poor = Match {
            source: all[0],
            dist: f32::INFINITY,
        };
        let hyps: Vec<P3> = best
            .iter()
            .map(|m| {
                let s = m.source;
                let x = if sources.contains([s[0], s[1], s[2] + 1]) {
                    s[2] + 1
                } else {
                    s[2] - 1
                };
                [s[0], s[1], x]
            })
            .collect();
        let cfg = LocalSearchParams::paper()
            .windows(vec![1])
            .max_iterations(1)
            .hypotheses(1)
            .hypothesis_window(3);
        assert_eq!(cfg.candidates(0), 1 + 9);
        let run = |h: &[P3]| {
            let mut v = clip.clean.clone();
            let mut field = MatchField {
                targets: targets.clone(),
                matches: vec![poor; targets.len()],
            };
            field.apply(&mut v);
            localized_search(&mut v, &clip.hole, &sources, &mut field, patch, &cfg, h).unwrap();
            field
        };
        let mut v = clip.clean.clone();
        let mut field = MatchField {
            targets: targets.clone(),
            matches: vec![poor; targets.len()],
        };
        let short = localized_search(
            &mut v,
            &clip.hole,
            &sources,
            &mut field,
            patch,
            &cfg,
            &hyps[1..],
        );
        assert!(short.unwrap_err().to_string().contains("hypotheses"));
        let without = run(&[]);
        assert!(without.matches.iter().all(|m| m.source == poor.source));
        let with = run(&hyps);
        let near = with
            .matches
            .iter()
            .zip(&best)
            .filter(|(m, b)| {
                m.source[0] == b.source[0]
                    && m.source[1]
                        .abs_diff(b.source[1])
                        .max(m.source[2].abs_diff(b.source[2]))
                        <= 2
            })
            .count();
        assert!(
            near * 10 >= 9 * targets.len(),
            "{near} of {}",
            targets.len()
        );
        assert!(with.energy() < 0.5 * without.energy());
    }

    #[test]
    fn the_iteration_cap_counts_the_budget_iteration_by_iteration() {
        // Against adding the candidates of one iteration after another, on schedules whose
        // lists, hypothesis iterations and budgets end in every order.
        let by_steps = |c: &LocalSearchParams| {
            let mut total = 0usize;
            let fit = (0..c.max_iterations)
                .take_while(|&k| {
                    total += c.candidates(k);
                    total <= c.max_candidates
                })
                .count();
            fit.max(c.windows.len())
        };
        for windows in [vec![17, 13, 9, 5], vec![9], vec![5, 3]] {
            for radii in [vec![0, 0, 0, 1], vec![1], vec![0, 2, 0, 0, 0, 1]] {
                for (hyp, hi) in [(0, 1), (6, 1), (2, 3), (4, 9)] {
                    for max_iterations in [0, 1, 3, 7, 16, 40] {
                        for budget in [0, 100, 500, 1000, 2000, 10_000] {
                            let c = LocalSearchParams::default()
                                .windows(windows.clone())
                                .temporal_radius(radii.clone())
                                .hypotheses(hyp)
                                .hypothesis_iterations(hi)
                                .max_iterations(max_iterations)
                                .max_candidates(budget);
                            assert_eq!(c.iteration_cap(), by_steps(&c), "{c:?}");
                        }
                    }
                }
            }
        }
        // Without a budget and with no iteration limit to speak of, the cap is found at once;
        // a window or radius too large to count exceeds any budget.
        let endless = LocalSearchParams::default()
            .max_iterations(usize::MAX)
            .max_candidates(usize::MAX - 1);
        assert!(endless.iteration_cap() > 1 << 50);
        let huge = LocalSearchParams::default().windows(vec![usize::MAX]);
        assert_eq!(huge.candidates(0), usize::MAX);
        assert_eq!(huge.iteration_cap(), 1);
        let deep = LocalSearchParams::default().temporal_radius(vec![usize::MAX / 2]);
        assert_eq!(deep.candidates(0), usize::MAX);
        assert_eq!(deep.iteration_cap(), 4);
    }

    #[test]
    fn iterations_keep_the_last_window_and_stop_when_the_energy_settles() {
        let cfg = LocalSearchParams::default();
        let widths: Vec<usize> = (0..7).map(|k| cfg.window(k)).collect();
        assert_eq!(widths, [17, 13, 9, 5, 5, 5, 5]);
        // Every listed window runs, whatever the energies do.
        assert!(!cfg.converged(&[]));
        assert!(!cfg.converged(&[10.0, 10.0, 10.0]));
        // Then a drop of 1 % goes on, 0.4 % or a rise stops.
        assert!(!cfg.converged(&[10.0, 9.0, 8.0, 7.0]));
        assert!(cfg.converged(&[10.0, 9.0, 8.0, 7.98]));
        assert!(!cfg.converged(&[10.0, 9.0, 8.0, 7.0, 6.93]));
        assert!(cfg.converged(&[10.0, 9.0, 8.0, 7.0, 7.01]));
        // An exact completion stops once the listed windows have run.
        assert!(cfg.converged(&[1.0, 0.0, 0.0, 0.0]));
        let no_drop = LocalSearchParams {
            min_energy_drop: 0.0,
            ..LocalSearchParams::default()
        };
        assert!(no_drop.converged(&[3.0, 2.0, 1.0, 1.0]));
        assert!(!no_drop.converged(&[3.0, 2.0, 1.0, 0.999]));
        // The patch budget: 351 + 177 + 89 + 4 x 83 = 949 <= 1000 candidates per pixel with
        // the six hypotheses' 3 x 3 windows in the first iteration, an eighth iteration would
        // make 1032; without hypotheses 297 + 177 + 89 + 5 x 83 = 978, eight iterations.
        let per: Vec<usize> = (0..5).map(|k| cfg.candidates(k)).collect();
        assert_eq!(
            per,
            [17 * 17 + 8 + 54, 13 * 13 + 8, 9 * 9 + 8, 75 + 8, 75 + 8]
        );
        assert_eq!(cfg.iteration_cap(), 7);
        assert_eq!(cfg.clone().hypotheses(0).iteration_cap(), 8);
        let halving: Vec<f64> = (0..16).map(|k| 0.5f64.powi(k)).collect();
        assert!(!cfg.converged(&halving[..6]));
        assert!(cfg.converged(&halving[..7]));
        // The paper's windows: 289 + 169 + 81 + 25 k fits 16 iterations (864).
        let paper = LocalSearchParams::paper();
        assert_eq!(paper.iteration_cap(), 16);
        assert_eq!((0..16).map(|k| paper.candidates(k)).sum::<usize>(), 864);
        // Without a budget, the cap, at least one iteration per window.
        let cfg = cfg.max_candidates(usize::MAX);
        assert!(!cfg.converged(&halving[..15]));
        assert!(cfg.converged(&halving));
        // A budget below the listed windows still runs each of them once.
        assert_eq!(
            LocalSearchParams::default()
                .max_candidates(0)
                .iteration_cap(),
            4
        );
        // Hypotheses add their windows to the first iterations only.
        let hyp = LocalSearchParams::default().hypotheses(4);
        assert_eq!(hyp.candidates(0), 17 * 17 + 8 + 36);
        assert_eq!(hyp.candidates(1), 13 * 13 + 8);
        assert!(hyp.clone().hypothesis_window(4).validate().is_err());
        let short = LocalSearchParams {
            max_iterations: 2,
            ..LocalSearchParams::default()
        };
        assert!(short.validate().is_ok());
        assert!(LocalSearchParams::default()
            .temporal_radius(vec![])
            .validate()
            .is_err());
        assert_eq!(short.iteration_cap(), 4);
        let one = LocalSearchParams {
            windows: vec![9],
            max_iterations: 3,
            ..LocalSearchParams::default()
        };
        assert!(!one.converged(&[4.0]));
        assert!(!one.converged(&[4.0, 2.0]));
        assert!(one.converged(&[4.0, 2.0, 1.0]));
    }
}
