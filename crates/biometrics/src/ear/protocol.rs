//! The paper's experiments (section 4) on a labelled probe set: CMC curves of the four score
//! rules (Fig. 11) and of the whole-ear baseline (Fig. 12), rank-1 per estimated-occlusion
//! bin (Fig. 13), the rejection rate, and the accuracy of the occlusion estimate against the
//! generator's ground truth.

use rayon::prelude::*;
use wscg_math::image::Image;
use wscg_math::{Error, Result};

use super::features::enroll;
use super::matching::{cmc, identify_baseline, make_probe, rank, scores_by_rule, Gallery};
use super::params::{EarParams, ScoreRule};
use super::synth::EarSet;

/// What happened to one probe.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeOutcome {
    /// True gallery index.
    pub subject: usize,
    /// Estimated occlusion percentage `E`.
    pub estimated_pct: f64,
    /// Ground-truth occlusion percentage, when known.
    pub true_pct: Option<f64>,
    /// Whether the probe was rejected (`E > reject_above_pct`).
    pub rejected: bool,
    /// 0-based rank of the true subject under each rule of [`ScoreRule::ALL`] (`None` when
    /// rejected).
    pub ranks: [Option<usize>; 5],
    /// 0-based rank under the baseline (which never rejects).
    pub baseline_rank: usize,
}

/// Results of [`evaluate`].
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// Per-probe outcomes, in probe order.
    pub outcomes: Vec<ProbeOutcome>,
    /// CMC (ranks 1..=max_rank) of each rule of [`ScoreRule::ALL`], over accepted probes.
    pub cmc: Vec<Vec<f64>>,
    /// CMC of the baseline over the same accepted probes.
    pub baseline_cmc: Vec<f64>,
    /// CMC of the baseline over every probe (it has no reject path).
    pub baseline_cmc_all: Vec<f64>,
}

impl Evaluation {
    /// CMC of `rule`.
    pub fn cmc_of(&self, rule: ScoreRule) -> &[f64] {
        &self.cmc[rule.index()]
    }

    /// Fraction of probes rejected.
    pub fn rejection_rate(&self) -> f64 {
        let n = self.outcomes.iter().filter(|o| o.rejected).count();
        n as f64 / self.outcomes.len().max(1) as f64
    }

    /// Rank-1 rate of `rule` per bin of estimated occlusion `[lo, hi)` (the last bin
    /// includes its upper edge) over accepted probes, with the number of probes in each bin:
    /// `(lo, hi, count, rank1)` (Fig. 13; `rank1` is NaN for an empty bin).
    pub fn degradation(&self, rule: ScoreRule, edges: &[f64]) -> Vec<(f64, f64, usize, f64)> {
        let ri = rule.index();
        edges
            .windows(2)
            .enumerate()
            .map(|(i, e)| {
                let last = i + 2 == edges.len();
                let inside: Vec<&ProbeOutcome> = self
                    .outcomes
                    .iter()
                    .filter(|o| {
                        !o.rejected
                            && o.estimated_pct >= e[0]
                            && (o.estimated_pct < e[1] || (last && o.estimated_pct <= e[1]))
                    })
                    .collect();
                let hits = inside.iter().filter(|o| o.ranks[ri] == Some(0)).count();
                let rate = if inside.is_empty() {
                    f64::NAN
                } else {
                    hits as f64 / inside.len() as f64
                };
                (e[0], e[1], inside.len(), rate)
            })
            .collect()
    }
}

/// Enrols `set.enrol`, identifies every probe under all rules and the baseline.
///
/// Errors: an empty set, `max_rank == 0`, bad parameters.
pub fn evaluate(set: &EarSet, p: &EarParams, max_rank: usize) -> Result<Evaluation> {
    let images: Vec<(usize, &Image<u8>, Option<f64>)> = set
        .probes
        .iter()
        .map(|pr| (pr.subject, &pr.image.rgb, Some(pr.occluded_pct())))
        .collect();
    evaluate_images(&set.enrol, &images, p, max_rank)
}

/// [`evaluate`] on any images: `gallery_images[i]` enrols identity `i`; each probe is
/// `(true identity, image, ground-truth occlusion percentage if known)`.
pub fn evaluate_images(
    gallery_images: &[Image<u8>],
    probes: &[(usize, &Image<u8>, Option<f64>)],
    p: &EarParams,
    max_rank: usize,
) -> Result<Evaluation> {
    if probes.is_empty() {
        return Err(Error::Empty("probes"));
    }
    if let Some(&(s, _, _)) = probes.iter().find(|pr| pr.0 >= gallery_images.len()) {
        return Err(Error::invalid(
            "probes",
            format!("identity {s} outside a gallery of {}", gallery_images.len()),
        ));
    }
    let templates = gallery_images
        .par_iter()
        .map(|im| enroll(im, p))
        .collect::<Result<Vec<_>>>()?;
    let gallery = Gallery::new(&templates)?;
    let outcomes = probes
        .par_iter()
        .map(|&(subject, img, true_pct)| {
            let probe = make_probe(img, p)?;
            let report = probe.report.as_ref().ok_or(Error::Empty("report"))?;
            let rejected = report.rejected;
            let mut ranks = [None; 5];
            if !rejected && !probe.is_empty() {
                let all = scores_by_rule(&probe, &gallery, p, &ScoreRule::ALL)?;
                for (slot, s) in ranks.iter_mut().zip(&all) {
                    *slot = rank(s).iter().position(|&(g, _)| g == subject);
                }
            }
            let baseline_rank = identify_baseline(img, &gallery, p)?
                .rank_of(subject)
                .unwrap_or(usize::MAX);
            Ok(ProbeOutcome {
                subject,
                estimated_pct: report.occluded_pct,
                true_pct,
                rejected,
                ranks,
                baseline_rank,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let accepted: Vec<&ProbeOutcome> = outcomes.iter().filter(|o| !o.rejected).collect();
    let cmc_rules = (0..ScoreRule::ALL.len())
        .map(|ri| {
            let ranks: Vec<Option<usize>> = accepted.iter().map(|o| o.ranks[ri]).collect();
            cmc(&ranks, max_rank)
        })
        .collect::<Result<Vec<_>>>()?;
    let base: Vec<Option<usize>> = accepted.iter().map(|o| Some(o.baseline_rank)).collect();
    let base_all: Vec<Option<usize>> = outcomes.iter().map(|o| Some(o.baseline_rank)).collect();
    Ok(Evaluation {
        cmc: cmc_rules,
        baseline_cmc: cmc(&base, max_rank)?,
        baseline_cmc_all: cmc(&base_all, max_rank)?,
        outcomes,
    })
}
