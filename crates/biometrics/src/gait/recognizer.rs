//! The recognition pipeline of paper 17 (sections 3.1-3.4, Fig. 6): gait cycle → JRA
//! sequences → relevant pairs (on the training walks) → DTW kernel Δ against every training
//! walk → vote.

use std::sync::OnceLock;

use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::cycle::{detect_gait_cycle, CycleParams, GaitCycle};
use super::jra::{jra_matrix, JraSet};
use super::relevance::{relevance_matrix, select_pairs, HistSpec, JointMap};
use super::skeleton::{Joint, Pair, SkeletonSeq};
use crate::dtw::fused::Interleaved;
use crate::dtw::matrix::pair_delta;
use crate::dtw::{check_sample, interleave_all, DtwParams, Multivariate};

/// How the ranked training walks decide the identity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Vote {
    /// The label of the walk with the smallest Δ (1-NN; default, unambiguous).
    #[default]
    Nearest,
    /// Majority among the `k` walks of smallest Δ.
    Majority {
        /// Number of voters.
        k: usize,
    },
    /// The paper's rule (section 3.4): majority among the top N + 1 walks, N = number of
    /// classes.
    PaperTopClassesPlusOne,
}

impl Vote {
    /// Parses `"nearest"`, `"paper"` or `"majority:K"`.
    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "nearest" | "1nn" => Ok(Self::Nearest),
            "paper" => Ok(Self::PaperTopClassesPlusOne),
            _ => match s.strip_prefix("majority:").map(str::parse::<usize>) {
                Some(Ok(k)) if k > 0 => Ok(Self::Majority { k }),
                _ => Err(Error::invalid(
                    "vote",
                    format!("`{s}` is not a valid vote. Valid votes are \"nearest\", \"paper\" and \"majority:K\" (K >= 1)"),
                )),
            },
        }
    }
}

/// Decides a label from training walks ranked by Δ (`ranked[i] = (label, Δ)`, ascending Δ).
/// Majority ties go to the tied class with the smallest sum of its voters' ranks, then the
/// smallest Δ. Errors: no walks, `k = 0`.
pub fn vote(ranked: &[(u32, f64)], rule: Vote) -> Result<u32> {
    if ranked.is_empty() {
        return Err(Error::Empty("gallery"));
    }
    let k = match rule {
        Vote::Nearest => return Ok(ranked[0].0),
        Vote::Majority { k } => k,
        Vote::PaperTopClassesPlusOne => {
            let mut c: Vec<u32> = ranked.iter().map(|r| r.0).collect();
            c.sort_unstable();
            c.dedup();
            c.len() + 1
        }
    };
    if k == 0 {
        return Err(Error::invalid("k", "a vote needs at least one voter"));
    }
    // (label, votes, rank sum, best Δ)
    let mut tally: Vec<(u32, usize, usize, f64)> = Vec::new();
    for (rank, &(label, d)) in ranked.iter().take(k).enumerate() {
        match tally.iter_mut().find(|t| t.0 == label) {
            Some(t) => {
                t.1 += 1;
                t.2 += rank;
            }
            None => tally.push((label, 1, rank, d)),
        }
    }
    tally.sort_by(|a, b| b.1.cmp(&a.1).then(a.2.cmp(&b.2)).then(a.3.total_cmp(&b.3)));
    Ok(tally[0].0)
}

wscg_math::params! {
    /// Parameters of the pipeline, the paper's values by default.
    #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
    pub struct GaitParams {
        /// Gait cycle detection.
        pub cycle: CycleParams,
        /// Reference joint of the angles (SpineBase).
        pub reference: Joint,
        /// Histogram of the relevance measure (1° bins on [0°, 180°]).
        pub hist: HistSpec,
        /// Relevance threshold `t`: keep pairs occupying at least this many bins (20).
        pub min_bins: f64,
        /// DTW of the kernel (absolute cost, full window).
        pub dtw: DtwParams,
        /// Vote rule (1-NN).
        pub vote: Vote,
    }
}

impl Default for GaitParams {
    fn default() -> Self {
        Self {
            cycle: CycleParams::default(),
            reference: Joint::SpineBase,
            hist: HistSpec::default(),
            min_bins: 20.0,
            dtw: DtwParams::default(),
            vote: Vote::Nearest,
        }
    }
}

impl GaitParams {
    /// Errors: invalid cycle detection, histogram or DTW parameters (the error names the
    /// field), a non-finite `min_bins`, a majority vote with `k == 0`.
    pub fn validate(&self) -> Result<()> {
        self.cycle.validate()?;
        self.hist.validate()?;
        if !self.min_bins.is_finite() {
            return Err(Error::invalid(
                "min_bins",
                format!("must be finite, got {}", self.min_bins),
            ));
        }
        self.dtw.validate()?;
        if self.dtw.multivariate != Multivariate::Independent {
            return Err(Error::invalid(
                "multivariate",
                "the gait recognizer uses the DTW kernel of eq. 6 (independent DTW over the \
                 selected pairs); the dependent DTW is available in dissimilarity_matrix and \
                 nearest",
            ));
        }
        if self.vote == (Vote::Majority { k: 0 }) {
            return Err(Error::invalid(
                "vote",
                "a majority vote needs k >= 1 voters, got 0",
            ));
        }
        Ok(())
    }
}

/// One walk prepared for recognition: its cycle and the JRA sequences of all 276 pairs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaitSample {
    /// The detected cycle.
    pub cycle: GaitCycle,
    /// JRA sequences of every pair over the cycle.
    pub jra: JraSet,
}

/// Detects the cycle of a walk and computes its JRA sequences.
pub fn gait_sample(s: &SkeletonSeq, p: &GaitParams) -> Result<GaitSample> {
    p.validate()?;
    let cycle = detect_gait_cycle(s, &p.cycle)?;
    let jra = jra_matrix(s, &cycle, p.reference)?;
    Ok(GaitSample { cycle, jra })
}

/// The result of [`GaitRecognizer::predict`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Prediction {
    /// The decided identity.
    pub label: u32,
    /// Training walks by ascending Δ: `(training index, label, Δ)`.
    pub ranked: Vec<(usize, u32, f64)>,
    /// The query's gait cycle (when predicted from a walk).
    pub cycle: Option<GaitCycle>,
}

/// A fitted gait recognizer: the selected pairs and the training walks' JRA sequences.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GaitRecognizer {
    /// Parameters used.
    pub params: GaitParams,
    /// Relevance map of the training walks (Fig. 8).
    pub relevance: JointMap,
    /// Selected pairs (Fig. 10).
    pub pairs: Vec<Pair>,
    /// Training samples restricted to the selected pairs.
    pub gallery: Vec<Vec<Vec<f64>>>,
    /// Training labels.
    pub labels: Vec<u32>,
    /// The gallery interleaved for the channel-fused DTW, built on the first prediction
    /// (`None` inside when the fused kernel does not apply).
    #[serde(skip)]
    fused_gallery: OnceLock<Option<Vec<Interleaved>>>,
}

impl GaitRecognizer {
    /// Fits on whole walks. Errors: empty gallery, label count, a walk without a full gait
    /// cycle (the error names the walk), no pair above the threshold.
    pub fn fit(walks: &[SkeletonSeq], labels: &[u32], p: &GaitParams) -> Result<Self> {
        p.validate()?;
        let samples = walks
            .iter()
            .enumerate()
            .map(|(i, w)| {
                gait_sample(w, p)
                    .map(|s| s.jra)
                    .map_err(|e| Error::invalid("walks", format!("training walk {i}: {e}")))
            })
            .collect::<Result<Vec<_>>>()?;
        Self::fit_samples(&samples, labels, p)
    }

    /// Fits on prepared JRA sets, selecting pairs on them.
    pub fn fit_samples(samples: &[JraSet], labels: &[u32], p: &GaitParams) -> Result<Self> {
        Self::fit_samples_with_relevance(samples, labels, &[], p)
    }

    /// Fits on prepared JRA sets, computing the relevance map on `samples` plus `extra` (the
    /// paper's leaky protocol passes the test walks as `extra`).
    pub fn fit_samples_with_relevance(
        samples: &[JraSet],
        labels: &[u32],
        extra: &[JraSet],
        p: &GaitParams,
    ) -> Result<Self> {
        p.validate()?;
        if samples.is_empty() {
            return Err(Error::Empty("training walks"));
        }
        if labels.len() != samples.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} labels for {} training walks",
                labels.len(),
                samples.len()
            )));
        }
        let all: Vec<&JraSet> = samples.iter().chain(extra).collect();
        let relevance = relevance_matrix(&all, &p.hist)?;
        let pairs = select_pairs(&relevance, p.min_bins)?;
        Self::fit_with_pairs(samples, labels, relevance, pairs, p)
    }

    /// Fits with a given pair list (for example chosen on other data).
    pub fn fit_with_pairs(
        samples: &[JraSet],
        labels: &[u32],
        relevance: JointMap,
        pairs: Vec<Pair>,
        p: &GaitParams,
    ) -> Result<Self> {
        p.validate()?;
        if pairs.is_empty() {
            return Err(Error::Empty("pairs"));
        }
        if labels.len() != samples.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} labels for {} training walks",
                labels.len(),
                samples.len()
            )));
        }
        let gallery = samples
            .iter()
            .map(|s| s.select(&pairs))
            .collect::<Result<Vec<_>>>()?;
        for g in &gallery {
            check_sample("training walk", g)?;
        }
        Ok(Self {
            params: *p,
            relevance,
            pairs,
            gallery,
            labels: labels.to_vec(),
            fused_gallery: OnceLock::new(),
        })
    }

    /// Checks that a recognizer read from a file is consistent: valid parameters, at least
    /// one pair, a label for every gallery walk, and every gallery walk a non-empty, finite
    /// sequence for each selected pair (as prediction indexes them).
    pub fn check_shapes(&self) -> Result<()> {
        self.params.validate()?;
        if self.pairs.is_empty() {
            return Err(Error::Empty("pairs"));
        }
        if self.gallery.is_empty() {
            return Err(Error::Empty("gallery"));
        }
        if self.labels.len() != self.gallery.len() {
            return Err(Error::invalid(
                "model",
                format!(
                    "{} labels for {} gallery walks",
                    self.labels.len(),
                    self.gallery.len()
                ),
            ));
        }
        if let Some(i) = self
            .gallery
            .iter()
            .position(|g| g.len() != self.pairs.len())
        {
            return Err(Error::invalid(
                "model",
                format!(
                    "gallery walk {i} has {} sequences for {} pairs",
                    self.gallery[i].len(),
                    self.pairs.len()
                ),
            ));
        }
        // Every sequence non-empty and finite.
        crate::dtw::matrix::check_set("gallery", &self.gallery, self.pairs.len())
    }

    /// Identifies a walk.
    pub fn predict(&self, walk: &SkeletonSeq) -> Result<Prediction> {
        let s = gait_sample(walk, &self.params)?;
        let mut out = self.predict_sample(&s.jra)?;
        out.cycle = Some(s.cycle);
        Ok(out)
    }

    /// Identifies a prepared JRA set (it must hold the selected pairs).
    pub fn predict_sample(&self, jra: &JraSet) -> Result<Prediction> {
        let q = jra.select(&self.pairs)?;
        self.predict_selected(&q)
    }

    /// Identifies a sample already restricted to [`Self::pairs`], in that order.
    pub fn predict_selected(&self, q: &[Vec<f64>]) -> Result<Prediction> {
        check_sample("query", q)?;
        if q.len() != self.pairs.len() {
            return Err(Error::ShapeMismatch(format!(
                "the query has {} sequences, the recognizer uses {} pairs",
                q.len(),
                self.pairs.len()
            )));
        }
        let (mut scratch, mut lanes) = (Vec::new(), Vec::new());
        // Channel-fused DTW when it applies (no band; the channels of one walk share a length).
        let p = &self.params.dtw;
        let fused = self
            .fused_gallery
            .get_or_init(|| interleave_all(&self.gallery, p));
        let fq = if p.window.is_none() {
            Interleaved::new(q)
        } else {
            None
        };
        let mut ranked: Vec<(usize, u32, f64)> = self
            .gallery
            .iter()
            .zip(&self.labels)
            .enumerate()
            .map(|(i, (g, &l))| {
                let fg = fused.as_ref().map(|f| &f[i]);
                let d = pair_delta(
                    q,
                    g,
                    fq.as_ref().into(),
                    fg.into(),
                    p,
                    &mut scratch,
                    &mut lanes,
                );
                (i, l, d)
            })
            .collect();
        ranked.sort_by(|a, b| a.2.total_cmp(&b.2).then(a.0.cmp(&b.0)));
        let pairs: Vec<(u32, f64)> = ranked.iter().map(|r| (r.1, r.2)).collect();
        let label = vote(&pairs, self.params.vote)?;
        Ok(Prediction {
            label,
            ranked,
            cycle: None,
        })
    }

    /// The fitted recognizer as JSON (parameters, relevance map, pairs, gallery, labels).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::invalid("model", e.to_string()))
    }

    /// A recognizer from [`Self::to_json`] output. Errors: not a recognizer, or a gallery
    /// whose sizes disagree (label count, one sequence per selected pair).
    pub fn from_json(s: &str) -> Result<Self> {
        crate::model_json::checked_from_json(s, "gait recognizer", Self::check_shapes)
    }
}
