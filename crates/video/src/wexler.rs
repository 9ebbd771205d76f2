//! Baselines of paper 06: space-time completion of Wexler et al. 2007 (random start, global
//! search at every pyramid level up to full resolution, weighted voting of all patches
//! covering a pixel) and per-frame image PatchMatch inpainting (the same algorithm on each
//! frame with flat patches, as an image tool would do it).
//!
//! Voting weights (Wexler et al. 2007, section 3.2): `w_i = exp(-D_i / (2 sigma^2)) *
//! 1.3^(-dist(p_i, E))`, `sigma^2` the 75th percentile of the patch distances `D_i` of the
//! level, `dist` the distance of the patch centre to the known region.

use wscg_math::{Error, Result};

use crate::complete::{Completion, Stats};
use crate::field::{upscale_matches, MatchField};
use crate::init::{initialize, InitMethod};
use crate::patch::{valid_sources, Cubes, PatchSize};
use crate::patchmatch::{patchmatch, vote, Match, PatchMatchParams, TargetSet, P3};
use crate::pyramid::downscale;
use crate::search::{exact_best_all, random_matches, source_list};
use crate::video::{Mask3, Video};

wscg_math::params! {
    /// Parameters of the Wexler baseline.
    #[derive(Clone, Debug, PartialEq)]
    pub struct WexlerParams {
        /// Patch extents.
        pub patch: PatchSize,
        /// Coarsest level width: the pyramid halves while the next level is at least this wide.
        pub min_width: usize,
        /// EM iterations (search + vote) per level, coarsest first; the last value repeats.
        pub iters: Vec<usize>,
        /// PatchMatch iterations per search (`0`: exact search over every source).
        pub patchmatch_iters: usize,
        /// Seed of the random start and the random search.
        pub seed: u64,
        /// Base of the distance-to-`E` weight decay (1.3).
        pub decay: f64,
        /// [`per_frame_patchmatch`] seeds frame `t` with `seed + t` (as separate runs of an image
        /// tool would be) instead of `seed` for every frame.
        pub seed_per_frame: bool,
    }
}

impl Default for WexlerParams {
    fn default() -> Self {
        Self {
            patch: PatchSize::default(),
            min_width: 64,
            iters: vec![10, 5, 3],
            patchmatch_iters: 4,
            seed: 0,
            decay: 1.3,
            seed_per_frame: false,
        }
    }
}

impl WexlerParams {
    /// Errors: an even or zero patch extent, a non-positive or non-finite `decay` (the
    /// weights are `decay^-distance`).
    pub fn validate(&self) -> Result<()> {
        self.patch.validate()?;
        if !(self.decay.is_finite() && self.decay > 0.0) {
            return Err(Error::invalid(
                "decay",
                format!("must be finite and > 0, got {}", self.decay),
            ));
        }
        Ok(())
    }
}

/// The points within the patch radius of the hole: every target patch that overlaps `H`.
fn dilated_targets(hole: &Mask3, r: [u32; 3]) -> TargetSet {
    let dims = hole.dims();
    let mut m = Mask3::empty(dims[0], dims[1], dims[2]);
    for p in hole.points() {
        let lo = |a: usize| p[a].saturating_sub(r[a]);
        let hi = |a: usize| (p[a] + r[a]).min(dims[a] as u32 - 1);
        for t in lo(0)..=hi(0) {
            for y in lo(1)..=hi(1) {
                for x in lo(2)..=hi(2) {
                    m.insert([t, y, x]);
                }
            }
        }
    }
    TargetSet::new(dims, m.iter_points())
}

/// Completes `hole` in `video` by Wexler et al.'s method. The returned match field holds the
/// hole pixels' own patch matches at full resolution.
///
/// Errors: shapes, patch sizes, a mask covering every pixel, no valid source at some level.
pub fn wexler_complete(video: &Video, hole: &Mask3, cfg: &WexlerParams) -> Result<Completion> {
    cfg.validate()?;
    video.check_mask(hole)?;
    cfg.patch.check(video.dims())?;
    if hole.count() == hole.len_grid() {
        return Err(Error::invalid(
            "mask",
            "the mask covers the whole video: no known pixel to fill from",
        ));
    }
    if hole.count() == 0 {
        return Ok(Completion {
            video: video.clone(),
            matches: MatchField {
                targets: TargetSet::new(video.dims(), []),
                matches: Vec::new(),
            },
            stats: Stats::default(),
        });
    }
    let mut factors = vec![1usize];
    while video.width / (2 * factors.last().unwrap()) >= cfg.min_width.max(cfg.patch.px)
        && video.height / (2 * factors.last().unwrap()) >= cfg.patch.py
    {
        factors.push(factors.last().unwrap() * 2);
    }
    let r = cfg.patch.radius();
    let mut prev: Option<MatchField> = None;
    let mut out = None;
    for (k, &f) in factors.iter().enumerate().rev() {
        let (mut v, m) = downscale(video, hole, f);
        let sources = valid_sources(&m, cfg.patch);
        if sources.count() == 0 {
            return Err(Error::invalid(
                "mask",
                format!("no valid source cube at {} x {}", v.width, v.height),
            ));
        }
        let targets = dilated_targets(&m, r);
        let known_dist = centre_distances(&m, &targets)?;
        let mut nnf = match &prev {
            None => {
                initialize(&mut v, &m, InitMethod::Random { seed: cfg.seed });
                random_matches(&sources, targets.len(), cfg.seed)
            }
            Some(coarse) => upscale_matches(coarse, &targets, &sources, None, 2)
                .ok_or_else(|| Error::invalid("mask", "no valid source at a finer level"))?,
        };
        let level_iters = cfg
            .iters
            .get(factors.len() - 1 - k)
            .or(cfg.iters.last())
            .copied()
            .unwrap_or(1);
        let hole_pts = m.points();
        if prev.is_some() {
            // Colours of the finer level from the up-scaled field.
            refresh(&v, &sources, cfg.patch, &targets, &mut nnf);
            vote_into(&mut v, &targets, &nnf, &known_dist, &hole_pts, r, cfg.decay);
        }
        for it in 0..level_iters {
            wscg_math::cancel::check()?;
            let cubes = Cubes::new(&v, &sources, cfg.patch);
            if cfg.patchmatch_iters == 0 {
                let pts: Vec<P3> = (0..targets.len()).map(|i| targets.get(i)).collect();
                nnf = exact_best_all(&cubes, &pts, &source_list(&sources));
            } else {
                refresh(&v, &sources, cfg.patch, &targets, &mut nnf);
                let p = PatchMatchParams::default()
                    .iterations(cfg.patchmatch_iters)
                    .seed(cfg.seed ^ ((k * 1000 + it) as u64))
                    .max_radius(None);
                patchmatch(&cubes, &targets, &mut nnf, &p);
            }
            let before = v.data.clone();
            vote_into(&mut v, &targets, &nnf, &known_dist, &hole_pts, r, cfg.decay);
            if v.data == before {
                break;
            }
        }
        refresh(&v, &sources, cfg.patch, &targets, &mut nnf);
        let field = MatchField {
            targets,
            matches: nnf,
        };
        if k == 0 {
            let hole_targets = TargetSet::new(m.dims(), hole_pts.iter().copied());
            let matches = (0..hole_targets.len())
                .map(|i| {
                    field
                        .get(hole_targets.get(i))
                        .expect("hole pixels are targets")
                })
                .collect();
            out = Some(Completion {
                video: v,
                matches: MatchField {
                    targets: hole_targets,
                    matches,
                },
                stats: Stats::default(),
            });
        }
        prev = Some(field);
    }
    out.ok_or_else(|| Error::invalid("video", "no pyramid level"))
}

/// Recomputes the distances of a field with the current colours.
fn refresh(v: &Video, sources: &Mask3, patch: PatchSize, targets: &TargetSet, nnf: &mut [Match]) {
    use rayon::prelude::*;
    let cubes = Cubes::new(v, sources, patch);
    nnf.par_iter_mut()
        .enumerate()
        .for_each(|(i, m)| m.dist = cubes.ssd(targets.get(i), m.source, f32::INFINITY));
}

/// Distance of every target centre to the known region (0 on it).
fn centre_distances(hole: &Mask3, targets: &TargetSet) -> Result<Vec<f32>> {
    let d = crate::onion::distance_to_known(hole, (0..targets.len()).map(|i| targets.get(i)))?;
    Ok(d.into_iter().map(|v| v as f32).collect())
}

/// Weighted voting of the hole pixels' colours.
fn vote_into(
    v: &mut Video,
    targets: &TargetSet,
    nnf: &[Match],
    known_dist: &[f32],
    hole_pts: &[P3],
    r: [u32; 3],
    decay: f64,
) {
    let mut d: Vec<f32> = nnf
        .iter()
        .map(|m| m.dist)
        .filter(|d| d.is_finite())
        .collect();
    d.sort_by(|a, b| a.total_cmp(b));
    let sigma2 = d
        .get((0.75 * d.len().saturating_sub(1) as f64) as usize)
        .copied()
        .unwrap_or(1.0)
        .max(1e-6) as f64;
    let weights: Vec<f32> = nnf
        .iter()
        .zip(known_dist)
        .map(|(m, &kd)| {
            if !m.dist.is_finite() {
                return 0.0;
            }
            ((-(m.dist as f64) / (2.0 * sigma2)).exp() * decay.powf(-(kd as f64))) as f32
        })
        .collect();
    let c = v.channels;
    let votes = {
        let vref: &Video = v;
        vote(targets, nnf, &weights, r, hole_pts, c, |q, k| {
            vref.pixel(q)[k] as f32
        })
    };
    for (p, val) in hole_pts.iter().zip(votes) {
        if let Some(val) = val {
            let o = v.offset(*p);
            for (d, x) in v.data[o..o + c].iter_mut().zip(&val) {
                *d = x.round().clamp(0.0, 255.0) as u8;
            }
        }
    }
}

/// Per-frame image PatchMatch inpainting: [`wexler_complete`] on every frame with a hole
/// separately, with flat `px x py x 1` patches (frames without a hole are copied).
pub fn per_frame_patchmatch(video: &Video, hole: &Mask3, cfg: &WexlerParams) -> Result<Video> {
    cfg.validate()?;
    video.check_mask(hole)?;
    let mut out = video.clone();
    let mut frame_cfg = cfg.clone();
    frame_cfg.patch.pt = 1;
    let (h, w, c) = (video.height, video.width, video.channels);
    for t in 0..video.frames {
        wscg_math::cancel::check()?;
        if !hole.frame_any(t) {
            continue;
        }
        let v = Video::new(1, h, w, c, video.frame(t).to_vec())?;
        let m = Mask3::from_fn(1, h, w, |_, y, x| {
            hole.contains([t as u32, y as u32, x as u32])
        });
        if cfg.seed_per_frame {
            frame_cfg.seed = cfg.seed.wrapping_add(t as u64);
        }
        let done = wexler_complete(&v, &m, &frame_cfg)?;
        let n = h * w * c;
        out.data[t * n..(t + 1) * n].copy_from_slice(&done.video.data);
    }
    Ok(out)
}
