//! The whole method of paper 06 (Fig. 3): stage 1 at the working resolution, stage 2
//! refinement of its match list, stage 3 localized search up to full resolution.

use std::time::Instant;

use wscg_math::progress::{NoProgress, Progress};
use wscg_math::{Error, Result};

use crate::field::{upscale_matches, MatchField};
use crate::hypotheses::Hypotheses;
use crate::local::{localized_search, LocalSearchParams, LocalStats, UpscaleStep};
use crate::lowres::{lowres_complete_indexed, sweep_once, LevelStats, LowResParams};
use crate::onion::onion_order;
use crate::patch::{valid_sources, Cubes, PatchSize};
use crate::patchmatch::TargetSet;
use crate::pyramid::{downscale, working_factor};
use crate::refine::{refine_matches, RefineParams, RefineStats};
use crate::search::{source_list, Searcher};
use crate::video::{Mask3, Video};

wscg_math::params! {
    /// Parameters of the whole completion.
    #[derive(Clone, Debug, PartialEq)]
    pub struct CompletionParams {
        /// Stage 1.
        pub low: LowResParams,
        /// Stage 2 (`None`: the no-refinement ablation of Fig. 5b).
        pub refine: Option<RefineParams>,
        /// Stage 3.
        pub local: LocalSearchParams,
        /// Replace stage 3's localized search by exact global search at every finer level (an
        /// ablation for small videos: the cost the paper avoids).
        pub global_fine_search: bool,
    }
}

impl Default for CompletionParams {
    fn default() -> Self {
        Self {
            low: LowResParams::default(),
            refine: Some(RefineParams::default()),
            local: LocalSearchParams::default(),
            global_fine_search: false,
        }
    }
}

impl CompletionParams {
    /// Errors: invalid stage 1, 2 or 3 parameters (the error names the field; see
    /// [`LowResParams::validate`], [`RefineParams::validate`] and
    /// [`LocalSearchParams::validate`]).
    pub fn validate(&self) -> Result<()> {
        self.low.validate()?;
        if let Some(r) = &self.refine {
            r.validate()?;
        }
        self.local.validate()
    }
}

/// Statistics of a completion.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    /// Working resolution `(height, width)` of stage 1 and its down-scaling factor.
    pub working_size: (usize, usize),
    /// Factor from full to working resolution.
    pub working_factor: usize,
    /// Stage 1, coarsest level first.
    pub lowres: Vec<LevelStats>,
    /// Stage 2.
    pub refine: Option<RefineStats>,
    /// Stage 3, one entry per finer level.
    pub local: Vec<LocalStats>,
    /// Wall time of stages 1, 2 and 3 in seconds.
    pub seconds: [f64; 3],
}

/// A completed video.
#[derive(Clone, Debug)]
pub struct Completion {
    /// The video with the hole filled (known pixels bit-identical to the input).
    pub video: Video,
    /// For every hole pixel at full resolution, the source it was copied from.
    pub matches: MatchField,
    /// What each stage did.
    pub stats: Stats,
}

/// Completes the hole `hole` of `video` (paper 06). See [`complete_video_with`].
pub fn complete_video(video: &Video, hole: &Mask3, cfg: &CompletionParams) -> Result<Completion> {
    complete_video_with(video, hole, cfg, &NoProgress)
}

/// Errors unless `video` and `hole` can be completed with `cfg` (shape, patch, a known pixel).
pub fn check_input(video: &Video, hole: &Mask3, cfg: &CompletionParams) -> Result<()> {
    cfg.validate()?;
    video.check_mask(hole)?;
    cfg.low.patch.check(video.dims())?;
    if hole.count() == hole.len_grid() {
        return Err(Error::invalid(
            "mask",
            "the mask covers the whole video: no known pixel to fill from",
        ));
    }
    Ok(())
}

/// Completes the hole of `video`: the known pixels are never written, each hole pixel takes
/// the colour of one source pixel. Stage 1 ([`lowres_complete`]) runs at the working
/// resolution (`width / round(width / 480)`), stage 2 ([`refine_matches`]) refines its match
/// list, stage 3 ([`localized_search`]) climbs to full resolution. An empty hole returns the
/// input unchanged. `progress` receives one stage per level.
///
/// Errors: mask and video shapes differ, bad patch or window sizes, a mask covering every
/// pixel, a known region too thin to hold one source cube at some level.
pub fn complete_video_with(
    video: &Video,
    hole: &Mask3,
    cfg: &CompletionParams,
    progress: &dyn Progress,
) -> Result<Completion> {
    let mut out = video.clone();
    let (matches, stats) = complete_in_place(&mut out, hole, cfg, progress)?;
    Ok(Completion {
        video: out,
        matches,
        stats,
    })
}

/// [`complete_video_with`] writing the completion into `video`'s own hole pixels (its known
/// pixels are only read): no copy of the video is made, so the peak memory is the video, one
/// match per hole pixel and the working-resolution copy. On error `video` may hold a partial
/// completion of its hole.
pub fn complete_in_place(
    video: &mut Video,
    hole: &Mask3,
    cfg: &CompletionParams,
    progress: &dyn Progress,
) -> Result<(MatchField, Stats)> {
    check_input(video, hole, cfg)?;
    let mut stats = Stats::default();
    if hole.count() == 0 {
        return Ok((
            MatchField {
                targets: TargetSet::new(video.dims(), []),
                matches: Vec::new(),
            },
            stats,
        ));
    }
    let patch = cfg.low.patch;
    let s0 = working_factor(video.width, cfg.low.target_width);
    stats.working_factor = s0;
    let clock = Instant::now();
    // The working level: a down-scaled copy, or the video itself at factor 1.
    let (mut owned, wm) = if s0 > 1 {
        let (v, m) = downscale(video, hole, s0);
        (Some(v), m)
    } else {
        (None, hole.clone())
    };
    let wv: &mut Video = match owned.as_mut() {
        Some(v) => v,
        None => &mut *video,
    };
    stats.working_size = (wv.height, wv.width);
    progress.begin(&format!("stage 1 at {} x {}", wv.width, wv.height), 1);
    let (mut ml, low, index) = lowres_complete_indexed(wv, &wm, &cfg.low)?;
    // Kept for stage 3's hypotheses only.
    let index = index.filter(|_| cfg.local.hypotheses > 0);
    progress.advance(1);
    progress.finish();
    stats.lowres = low;
    stats.seconds[0] = clock.elapsed().as_secs_f64();
    log::info!(
        "stage 1 (low-resolution completion) at {} x {}: {:.2} s",
        wv.width,
        wv.height,
        stats.seconds[0]
    );
    let clock = Instant::now();
    let sources = valid_sources(&wm, patch);
    if let Some(rc) = &cfg.refine {
        progress.begin("match refinement", 1);
        stats.refine = Some(refine_matches(wv, &wm, &sources, &mut ml, patch, rc)?);
        progress.advance(1);
        progress.finish();
    }
    // Stage 1's next-best sources of each hole pixel, ranked by its index on the completed
    // working level.
    let mut hyps = index
        .filter(|_| !cfg.global_fine_search)
        .map(|index| Hypotheses::next_best(wv, &sources, &ml, patch, &index, cfg.local.hypotheses))
        .transpose()?;
    drop(sources);
    stats.seconds[1] = clock.elapsed().as_secs_f64();
    drop(owned);
    let clock = Instant::now();
    let mut f = s0;
    while f > 1 {
        wscg_math::cancel::check()?;
        let next = match cfg.local.step {
            UpscaleStep::Double if f.is_multiple_of(2) => f / 2,
            _ => 1,
        };
        // Intermediate levels are down-scaled copies (their hole colours are rewritten);
        // the last level is the video itself.
        let (mut level, lm) = if next > 1 {
            let (v, m) = downscale(video, hole, next);
            (Some(v), m)
        } else {
            (None, hole.clone())
        };
        let lv: &mut Video = match level.as_mut() {
            Some(v) => v,
            None => &mut *video,
        };
        let sources = valid_sources(&lm, patch);
        let targets = TargetSet::new(lm.dims(), lm.iter_points());
        let temporal =
            (cfg.low.temporal_candidates || cfg.local.temporal_candidates).then_some((&lm, patch));
        let up = upscale_matches(&ml, &targets, &sources, temporal, f / next).ok_or_else(|| {
            Error::invalid(
                "mask",
                format!(
                    "no valid source cube at {} x {}: the known region is too thin",
                    lv.width, lv.height
                ),
            )
        })?;
        // The hypotheses are searched around at the first level only; stage 3 counts their
        // candidates where it has them.
        let around = match hyps.take() {
            Some(h) => h
                .upscale(&targets, &sources, temporal, f / next)?
                .unwrap_or_default(),
            None => Vec::new(),
        };
        let local = if around.is_empty() {
            cfg.local.clone().hypotheses(0)
        } else {
            cfg.local.clone()
        };
        progress.begin(
            &format!("localized search at {} x {}", lv.width, lv.height),
            local.iteration_cap() as u64,
        );
        let mut field = MatchField {
            targets,
            matches: up,
        };
        field.apply(lv);
        let st = if cfg.global_fine_search {
            global_search(lv, &lm, &sources, &mut field, patch, &local)?
        } else {
            localized_search(lv, &lm, &sources, &mut field, patch, &local, &around)?
        };
        progress.advance(local.iteration_cap() as u64);
        progress.finish();
        log::info!(
            "stage 3 at {} x {}: {} sweeps over {} hole pixels, energy {:.4e} -> {:.4e}",
            lv.width,
            lv.height,
            st.energy.len(),
            st.hole_pixels,
            st.energy.first().copied().unwrap_or(0.0),
            st.energy.last().copied().unwrap_or(0.0)
        );
        stats.local.push(st);
        ml = field;
        f = next;
    }
    stats.seconds[2] = clock.elapsed().as_secs_f64();
    Ok((ml, stats))
}

/// The global-search ablation of stage 3: exact sweeps over every valid source (and the
/// temporal candidates when stage 3 tries them), with stage 3's iteration count and stopping
/// rule.
fn global_search(
    video: &mut Video,
    hole: &Mask3,
    sources: &Mask3,
    field: &mut MatchField,
    patch: PatchSize,
    local: &LocalSearchParams,
) -> Result<LocalStats> {
    let order = onion_order(hole, &field.targets)?;
    let searcher = Searcher::Exact(source_list(sources));
    let mut st = LocalStats {
        size: (video.height, video.width),
        hole_pixels: field.len(),
        energy: Vec::new(),
        candidates: 0,
    };
    while !local.converged(&st.energy) {
        let sweep = st.energy.len();
        sweep_once(
            video,
            sources,
            &searcher,
            field,
            &order,
            patch,
            sweep,
            local.temporal_candidates.then_some(hole),
            None,
        );
        let temporal = if local.temporal_candidates { 2 } else { 0 };
        st.candidates += (field.len() * (sources.count() + temporal)) as u64;
        st.energy
            .push(field.refresh(&Cubes::new(video, sources, patch)));
    }
    Ok(st)
}
