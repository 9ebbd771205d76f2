//! Stage 1 of paper 06 (section 3.2, Fig. 3 stages 1.1-1.3): the dual inpainting-sampling
//! filling-order completion at low resolution. A spatial pyramid of the working-resolution
//! video (temporal resolution kept), the hole initialised by inpainting at the coarsest
//! level, then per level a few sweeps in which every hole pixel, shell by shell from the
//! outside ("3D hole-filling"), takes the centre colour of its single best-matching source
//! cube. Matches are carried to the next finer level offset-preserving.

use wscg_math::{Error, Result};

use crate::field::{energy_settled, temporal_sources, upscale_matches, MatchField};
use crate::init::{initialize, InitMethod};
use crate::onion::{onion_order, scanline_order};
use crate::patch::{valid_sources, Cubes, PatchSize};
use crate::patchmatch::{patchmatch, Match, PatchMatchParams, TargetSet};
use crate::pca_index::PcaIndex;
use crate::pyramid::downscale;
use crate::search::{random_matches, SearchMethod, Searcher};
use crate::video::{Mask3, Video};

wscg_math::params! {
    /// Parameters of stage 1.
    #[derive(Clone, Debug, PartialEq)]
    pub struct LowResParams {
        /// Width of the working resolution (480 in the paper: 1920 x 1080 is completed at
        /// 480 x 270).
        pub target_width: usize,
        /// Pyramid levels below the working resolution included (`None`: halve while the next
        /// level is at least 120 pixels wide and the hole is thicker than two patch radii).
        pub levels: Option<usize>,
        /// Patch extents.
        pub patch: PatchSize,
        /// Sweeps per level, coarsest first (the last value repeats for further levels).
        pub iters: Vec<usize>,
        /// Initial colours of the hole at the coarsest level.
        pub init: InitMethod,
        /// Best-match search.
        pub search: SearchMethod,
        /// Onion-peel filling order (`false`: scan-line order, the ablation).
        pub onion_order: bool,
        /// The first sweep at the coarsest level fills the hole causally: pixel after pixel in
        /// the filling order, each comparing only known pixels and pixels already filled in that
        /// sweep (a weighted SSD with weight 0 for not yet visited hole pixels; the paper, §3.2:
        /// "space-time points in E or space-time points already processed during the
        /// current iteration"). `false`: the first sweep compares with the inpainted colours,
        /// shell by shell in parallel like the later sweeps.
        pub causal_first_sweep: bool,
        /// Every approximate search (PatchMatch or PCA + kd-tree) also tries the hole pixel's
        /// temporal candidates, the same position in the nearest earlier and later frames where
        /// it is known ([`crate::field::temporal_sources`]), and the coarsest level's match
        /// list starts from them where they exist. Behind a moving hole filmed by a static
        /// camera they are exact copies, which the paper's search (section 3.2) finds only by
        /// chance; two more candidates per pixel and update. `false`: the paper's search
        /// alone. True.
        pub temporal_candidates: bool,
        /// A level stops early when fewer than this fraction of matches change in a sweep...
        pub min_changed: f64,
        /// ...or the energy drops by no more than this fraction ([`crate::field::energy_settled`]).
        pub min_energy_drop: f64,
    }
}

impl Default for LowResParams {
    fn default() -> Self {
        Self {
            target_width: 480,
            levels: None,
            patch: PatchSize::default(),
            iters: vec![10, 5, 3],
            init: InitMethod::Harmonic2D,
            search: SearchMethod::default(),
            onion_order: true,
            causal_first_sweep: true,
            temporal_candidates: true,
            min_changed: 1e-3,
            min_energy_drop: 5e-3,
        }
    }
}

impl LowResParams {
    /// Errors: `target_width == 0`, an even or zero patch extent, no sweep count, invalid
    /// PCA + kd-tree parameters, a negative or non-finite `min_changed` or `min_energy_drop`.
    pub fn validate(&self) -> Result<()> {
        if self.target_width == 0 {
            return Err(Error::invalid("target_width", "must be positive, got 0"));
        }
        self.patch.validate()?;
        if self.iters.is_empty() {
            return Err(Error::invalid(
                "iters",
                "needs the sweep count of at least one level",
            ));
        }
        if let SearchMethod::PcaKdTree(p) = &self.search {
            p.validate()?;
        }
        for (name, v) in [
            ("min_changed", self.min_changed),
            ("min_energy_drop", self.min_energy_drop),
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

/// What stage 1 did at one level.
#[derive(Clone, Debug, PartialEq)]
pub struct LevelStats {
    /// Frame size `(height, width)` of the level.
    pub size: (usize, usize),
    /// Hole pixels.
    pub hole_pixels: usize,
    /// Energy after each sweep.
    pub energy: Vec<f64>,
    /// Matches changed in each sweep.
    pub changed: Vec<usize>,
}

/// The pyramid of stage 1 below the working level: each coarser level, finest first.
fn pyramid(video: &Video, hole: &Mask3, cfg: &LowResParams) -> Vec<(Video, Mask3)> {
    let mut levels: Vec<(Video, Mask3)> = Vec::new();
    let r = cfg.patch.radius()[1].max(cfg.patch.radius()[2]) as f64;
    loop {
        let (v, m) = levels.last().map_or((video, hole), |(v, m)| (v, m));
        let next_w = v.width.div_ceil(2);
        let more = match cfg.levels {
            Some(l) => levels.len() < l,
            None => next_w >= 120 && hole_thickness(m) > 2.0 * r,
        };
        if !more || v.width < 2 || v.height < 2 {
            break;
        }
        let (cv, cm) = downscale(v, m, 2);
        if cfg.patch.check(cv.dims()).is_err() {
            break;
        }
        levels.push((cv, cm));
    }
    levels
}

/// Largest distance of a hole pixel to the known region (voxel units; 0 without a hole).
fn hole_thickness(hole: &Mask3) -> f64 {
    crate::onion::distance_to_known(hole, hole.iter_points())
        .map(|d| d.into_iter().fold(0.0f64, f64::max))
        .unwrap_or(0.0)
}

/// Stage 1 on the working-resolution `video` (hole pixels are overwritten with the
/// completion): returns the match list `ML` and per-level statistics, coarsest level first.
///
/// Errors: a level without any valid source cube ("the known region is too thin for the
/// patch"), a mask covering every pixel, bad patch sizes.
pub fn lowres_complete(
    video: &mut Video,
    hole: &Mask3,
    cfg: &LowResParams,
) -> Result<(MatchField, Vec<LevelStats>)> {
    lowres_complete_indexed(video, hole, cfg).map(|(field, stats, _)| (field, stats))
}

/// [`lowres_complete`], also returning the working level's PCA + kd-tree index when stage 1
/// searched with one.
pub(crate) fn lowres_complete_indexed(
    video: &mut Video,
    hole: &Mask3,
    cfg: &LowResParams,
) -> Result<(MatchField, Vec<LevelStats>, Option<PcaIndex>)> {
    cfg.validate()?;
    video.check_mask(hole)?;
    cfg.patch.check(video.dims())?;
    let mut coarser = pyramid(video, hole, cfg);
    let mut stats = Vec::new();
    let mut prev: Option<MatchField> = None;
    while let Some((mut lv, lm)) = coarser.pop() {
        let (field, st, _) = complete_level(&mut lv, &lm, prev.as_ref(), cfg, stats.len())?;
        stats.push(st);
        prev = Some(field);
    }
    let (field, st, searcher) = complete_level(video, hole, prev.as_ref(), cfg, stats.len())?;
    stats.push(st);
    let index = match searcher {
        Searcher::Pca(index) => Some(index),
        _ => None,
    };
    Ok((field, stats, index))
}

/// One level of stage 1 (the `k`-th processed, coarsest first), in place on `v`.
fn complete_level(
    v: &mut Video,
    lm: &Mask3,
    prev: Option<&MatchField>,
    cfg: &LowResParams,
    k: usize,
) -> Result<(MatchField, LevelStats, Searcher)> {
    let sources = valid_sources(lm, cfg.patch);
    if sources.count() == 0 {
        return Err(Error::invalid(
            "mask",
            format!(
                "no valid {} x {} x {} source cube at {} x {}: the known region is too thin for the patch",
                cfg.patch.px, cfg.patch.py, cfg.patch.pt, v.width, v.height
            ),
        ));
    }
    // The sources' cubes hold no hole pixel: the structure is built once per level.
    let searcher = Searcher::new(cfg.search, v, &sources, cfg.patch)?;
    let targets = TargetSet::new(lm.dims(), lm.iter_points());
    let (seed, pm_iters) = match cfg.search {
        SearchMethod::PatchMatch3D { seed, iters } => (seed, iters),
        SearchMethod::PcaKdTree(p) => (p.seed, 0),
        SearchMethod::Exact => (0, 0),
    };
    let mut ignore = None;
    // Random colours carry no information: a random start always fills causally first.
    let causal =
        prev.is_none() && (cfg.causal_first_sweep || matches!(cfg.init, InitMethod::Random { .. }));
    let matches = match prev {
        None => {
            initialize(v, lm, cfg.init);
            let mut start = random_matches(&sources, targets.len(), seed);
            if cfg.temporal_candidates {
                seed_temporal(&mut start, &targets, lm, cfg.patch);
            }
            start
        }
        Some(coarse) => {
            let temporal = cfg.temporal_candidates.then_some((lm, cfg.patch));
            let up = upscale_matches(coarse, &targets, &sources, temporal, 2).ok_or_else(|| {
                Error::invalid("mask", "no valid source at a finer pyramid level")
            })?;
            for (i, m) in up.iter().enumerate() {
                v.copy_pixel(targets.get(i), m.source);
            }
            up
        }
    };
    let mut field = MatchField { targets, matches };
    let sweeps = cfg
        .iters
        .get(levels_index(&cfg.iters, k))
        .copied()
        .unwrap_or(1);
    let order = if cfg.onion_order {
        onion_order(lm, &field.targets)?
    } else {
        scanline_order(&field.targets)
    };
    let mut st = LevelStats {
        size: (v.height, v.width),
        hole_pixels: field.len(),
        energy: Vec::new(),
        changed: Vec::new(),
    };
    for sweep in 0..sweeps {
        wscg_math::cancel::check()?;
        // Whole-field PatchMatch with the current colours (before the causal first sweep:
        // the inpainted ones, which is what the initialisation is for).
        if pm_iters > 0 {
            let cubes = Cubes::new(v, &sources, cfg.patch);
            field.refresh(&cubes);
            let p = PatchMatchParams::default()
                .iterations(pm_iters)
                .seed(seed ^ (1000 * (k + 1) + sweep) as u64)
                .max_radius(None);
            patchmatch(&cubes, &field.targets, &mut field.matches, &p);
        }
        // The causal first sweep: one pixel at a time, comparing only known pixels and
        // pixels already filled in this sweep.
        let seq: Vec<Vec<u32>>;
        let ord = if causal && sweep == 0 {
            ignore = Some(lm.clone());
            seq = order.iter().flatten().map(|&i| vec![i]).collect();
            &seq
        } else {
            &order
        };
        let changed = sweep_once(
            v,
            &sources,
            &searcher,
            &mut field,
            ord,
            cfg.patch,
            sweep,
            cfg.temporal_candidates.then_some(lm),
            ignore.as_mut(),
        );
        ignore = None;
        let e = field.refresh(&Cubes::new(v, &sources, cfg.patch));
        let last = st.energy.last().copied();
        st.energy.push(e);
        st.changed.push(changed);
        let few = (changed as f64) < cfg.min_changed * field.len() as f64;
        let flat = last.is_some_and(|l| energy_settled(l, e, cfg.min_energy_drop));
        if few || flat {
            break;
        }
    }
    Ok((field, st, searcher))
}

/// Replaces the start match of every target that has temporal candidates by the one nearer in
/// time (the earlier on a tie).
fn seed_temporal(matches: &mut [Match], targets: &TargetSet, hole: &Mask3, patch: PatchSize) {
    use rayon::prelude::*;
    matches.par_iter_mut().enumerate().for_each(|(i, m)| {
        let t = targets.get(i);
        if let Some(s) = temporal_sources(hole, patch, t).min_by_key(|s| s[0].abs_diff(t[0])) {
            m.source = s;
        }
    });
}

/// Index into `iters` for the `k`-th level processed (coarsest first).
fn levels_index(iters: &[usize], k: usize) -> usize {
    k.min(iters.len().saturating_sub(1))
}

/// One sweep over the shells: each shell's best matches are computed in parallel from the
/// current state, then its pixels take their sources' colours (Jacobi inside a shell,
/// Gauss-Seidel across shells, so the result does not depend on the thread count). With
/// the hole in `temporal`, approximate searches also try the temporal candidates. With
/// `ignore`, pixels leave the ignored set as they are updated. Returns the changed matches.
#[allow(clippy::too_many_arguments)]
pub(crate) fn sweep_once(
    v: &mut Video,
    sources: &Mask3,
    searcher: &Searcher,
    field: &mut MatchField,
    order: &[Vec<u32>],
    patch: PatchSize,
    sweep: usize,
    temporal: Option<&Mask3>,
    mut ignore: Option<&mut Mask3>,
) -> usize {
    use rayon::prelude::*;
    let mut changed = 0;
    for shell in order {
        let new: Vec<Match> = {
            let cubes = Cubes {
                video: v,
                sources,
                patch,
                ignore: ignore.as_deref(),
            };
            shell
                .par_iter()
                .map(|&i| {
                    searcher.best(
                        &cubes,
                        &field.targets,
                        &field.matches,
                        i as usize,
                        sweep,
                        temporal,
                    )
                })
                .collect()
        };
        for (&i, m) in shell.iter().zip(new) {
            let i = i as usize;
            let t = field.targets.get(i);
            if field.matches[i].source != m.source {
                changed += 1;
            }
            field.matches[i] = m;
            v.copy_pixel(t, m.source);
            if let Some(ig) = ignore.as_deref_mut() {
                ig.remove(t);
            }
        }
    }
    changed
}
