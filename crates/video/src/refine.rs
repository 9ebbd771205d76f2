//! Stage 2 of paper 06 (section 3.3, Fig. 6): coherence-based refinement of the match list.
//! The approximate search of stage 1 leaves poor matches; those whose distance is above a
//! threshold (first set so that 15 % of the pairs are refined, then lowered by 20 % of its
//! initial value per iteration) try the source that each good 4-neighbour's match implies:
//! for the top neighbour `q = p + (0, -1)` matched to `q'`, the pixel below `q'`.

use rayon::prelude::*;

use crate::field::MatchField;
use crate::onion::onion_order;
use crate::patch::{Cubes, PatchSize};
use crate::patchmatch::Match;
use crate::video::{Mask3, Video};

wscg_math::params! {
    /// Parameters of stage 2.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct RefineParams {
        /// Fraction of pairs above the first threshold (0.15).
        pub initial_fraction: f64,
        /// Threshold decrease per iteration, as a fraction of the initial threshold (0.20).
        pub decrement: f64,
        /// Iterations (4; Fig. 7 shows 2 and 4).
        pub iterations: usize,
        /// Also try the `+-t` neighbours (an extension; the paper uses the four spatial ones).
        pub temporal_neighbors: bool,
    }
}

impl Default for RefineParams {
    fn default() -> Self {
        Self {
            initial_fraction: 0.15,
            decrement: 0.20,
            iterations: 4,
            temporal_neighbors: false,
        }
    }
}

impl RefineParams {
    /// Errors: `initial_fraction` outside `(0, 1]`, a negative or non-finite `decrement`
    /// (zero iterations are allowed: stage 2 then changes nothing).
    pub fn validate(&self) -> wscg_math::Result<()> {
        if !(self.initial_fraction > 0.0 && self.initial_fraction <= 1.0) {
            return Err(wscg_math::Error::invalid(
                "initial_fraction",
                format!("must lie in (0, 1], got {}", self.initial_fraction),
            ));
        }
        if !(self.decrement.is_finite() && self.decrement >= 0.0) {
            return Err(wscg_math::Error::invalid(
                "decrement",
                format!("must be finite and >= 0, got {}", self.decrement),
            ));
        }
        Ok(())
    }
}

/// What stage 2 did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RefineStats {
    /// The first threshold `tau_0` (a distance `D`).
    pub initial_threshold: f64,
    /// Pairs above the threshold in each iteration.
    pub candidates: Vec<usize>,
    /// Pairs replaced in each iteration.
    pub changed: Vec<usize>,
    /// Mean distance of the pairs above `tau_0` before refinement, and after (distances
    /// recomputed with the final colours).
    pub initial_set_mean: (f64, f64),
    /// Pairs whose match was replaced at least once.
    pub pairs_changed: usize,
}

/// Refines `field` (matches of the hole pixels of `video`, whose colours are the completion)
/// in place and updates the colours. Within an iteration the pixels above the threshold are
/// visited shell by shell (onion order), each shell in parallel from the current state.
///
/// A replacement is accepted only when it lowers the pixel's own distance at the time, so
/// no stored distance ever increases during an iteration.
pub fn refine_matches(
    video: &mut Video,
    hole: &Mask3,
    sources: &Mask3,
    field: &mut MatchField,
    patch: PatchSize,
    cfg: &RefineParams,
) -> wscg_math::Result<RefineStats> {
    cfg.validate()?;
    let mut st = RefineStats::default();
    if field.is_empty() || cfg.iterations == 0 {
        return Ok(st);
    }
    field.refresh(&Cubes::new(video, sources, patch));
    let mut d: Vec<f32> = field.matches.iter().map(|m| m.dist).collect();
    let mut sorted = d.clone();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let q = ((1.0 - cfg.initial_fraction) * (sorted.len() - 1) as f64).round() as usize;
    let tau0 = sorted[q.min(sorted.len() - 1)] as f64;
    st.initial_threshold = tau0;
    let initial_set: Vec<usize> = (0..d.len()).filter(|&i| d[i] as f64 > tau0).collect();
    st.initial_set_mean.0 = mean_of(&d, &initial_set);
    let order = onion_order(hole, &field.targets)?;
    let mut ever = vec![false; d.len()];
    let dims = field.targets.dims();
    let mut steps = MatchField::SPATIAL_STEPS.to_vec();
    if cfg.temporal_neighbors {
        steps.extend(MatchField::TEMPORAL_STEPS);
    }
    for k in 0..cfg.iterations {
        wscg_math::cancel::check()?;
        let tau = (tau0 * (1.0 - cfg.decrement * k as f64)).max(0.0) as f32;
        let mut candidates = 0;
        let mut changed = 0;
        for shell in &order {
            let upd: Vec<Option<(usize, Match)>> = {
                let cubes = Cubes::new(video, sources, patch);
                shell
                    .par_iter()
                    .map(|&i| {
                        let i = i as usize;
                        if d[i] <= tau {
                            return None;
                        }
                        let p = field.targets.get(i);
                        let mut best = Match {
                            source: field.matches[i].source,
                            dist: d[i],
                        };
                        let mut improved = false;
                        for &step in &steps {
                            let Some((j, c)) = field.implied_source(p, step, dims, sources) else {
                                continue;
                            };
                            if d[j] > tau || c == best.source {
                                continue;
                            }
                            let dc = cubes.ssd(p, c, best.dist);
                            if dc < best.dist {
                                best = Match {
                                    source: c,
                                    dist: dc,
                                };
                                improved = true;
                            }
                        }
                        Some((
                            i,
                            if improved {
                                best
                            } else {
                                Match {
                                    source: field.matches[i].source,
                                    dist: d[i],
                                }
                            },
                        ))
                    })
                    .collect()
            };
            for (i, m) in upd.into_iter().flatten() {
                candidates += 1;
                if m.source != field.matches[i].source {
                    changed += 1;
                    ever[i] = true;
                    field.matches[i] = m;
                    d[i] = m.dist;
                    video.copy_pixel(field.targets.get(i), m.source);
                }
            }
        }
        st.candidates.push(candidates);
        st.changed.push(changed);
        // Colours changed: recompute every distance for the next iteration.
        field.refresh(&Cubes::new(video, sources, patch));
        for (di, m) in d.iter_mut().zip(&field.matches) {
            *di = m.dist;
        }
        if changed == 0 {
            break;
        }
    }
    st.initial_set_mean.1 = mean_of(&d, &initial_set);
    st.pairs_changed = ever.iter().filter(|&&e| e).count();
    Ok(st)
}

fn mean_of(d: &[f32], idx: &[usize]) -> f64 {
    if idx.is_empty() {
        return 0.0;
    }
    idx.iter().map(|&i| d[i] as f64).sum::<f64>() / idx.len() as f64
}
