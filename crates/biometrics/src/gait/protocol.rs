//! The evaluation protocol of paper 17 (section 4.1): k-fold cross-validation where fold `k`
//! tests walk `k` of every subject and trains on the others, for the JRA + DTW kernel method
//! (three vote rules, threshold chosen on the training folds, accuracy versus threshold:
//! Fig. 9) and the baselines of Table 1 (Ball, Preis) plus our ablations (raw-coordinate DTW,
//! resampling with a Euclidean sum, path-length-normalised DTW).
//!
//! Per-channel DTW distances between all walks are computed once ([`ChannelCache`]); every
//! threshold and fold then sums cached channels, so a full report costs one pass of DTW.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::baselines::{
    ball_features, preis_features, raw_coordinate_sample, resample, GaussianNb, ZScoreNn,
};
use super::jra::JraSet;
use super::recognizer::{gait_sample, vote, GaitParams, GaitSample, Vote};
use super::relevance::{relevance_matrix, JointMap};
use super::skeleton::SkeletonSeq;
use crate::dtw::fused::fused_channels;
use crate::dtw::{dtw_bounded, interleave_all, DtwParams};

/// Per-channel DTW distances between all pairs of a sample set.
#[derive(Clone, Debug)]
pub struct ChannelCache {
    n: usize,
    channels: usize,
    d: Vec<f64>,
}

impl ChannelCache {
    /// DTW of every channel between every pair of `samples` (all with the same channel
    /// count), in parallel over the pairs.
    pub fn compute(samples: &[Vec<Vec<f64>>], p: &DtwParams) -> Self {
        let n = samples.len();
        let channels = samples.first().map_or(0, Vec::len);
        let pairs: Vec<(usize, usize)> = (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .collect();
        let fused = interleave_all(samples, p);
        let vals: Vec<Vec<f64>> = pairs
            .par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(scratch, lanes), &(i, j)| match &fused {
                    Some(f) => {
                        let mut out = vec![0.0; channels];
                        fused_channels(&f[i], &f[j], p.cost, lanes, &mut out);
                        if p.normalize {
                            let s = (f[i].len() + f[j].len()) as f64;
                            out.iter_mut().for_each(|v| *v /= s);
                        }
                        out
                    }
                    None => samples[i]
                        .iter()
                        .zip(&samples[j])
                        .map(|(a, b)| dtw_bounded(a, b, p, f64::INFINITY, scratch))
                        .collect(),
                },
            )
            .collect();
        let mut d = vec![0.0; n * n * channels];
        for (&(i, j), v) in pairs.iter().zip(&vals) {
            d[(i * n + j) * channels..(i * n + j + 1) * channels].copy_from_slice(v);
            d[(j * n + i) * channels..(j * n + i + 1) * channels].copy_from_slice(v);
        }
        Self { n, channels, d }
    }

    /// DTW of channel `k` between samples `i` and `j`.
    pub fn get(&self, i: usize, j: usize, k: usize) -> f64 {
        self.d[(i * self.n + j) * self.channels + k]
    }

    /// Δ between `i` and `j` over the channels `sel`.
    pub fn sum(&self, i: usize, j: usize, sel: &[usize]) -> f64 {
        let row = &self.d[(i * self.n + j) * self.channels..(i * self.n + j + 1) * self.channels];
        sel.iter().map(|&k| row[k]).sum()
    }
}

/// Walks prepared for the protocol: cycles, JRA sets, baseline features.
#[derive(Clone, Debug)]
pub struct PreparedWalks {
    /// Cycle and JRA sets of every walk.
    pub samples: Vec<GaitSample>,
    /// Ball et al.'s features.
    pub ball: Vec<Vec<f64>>,
    /// Preis et al.'s features.
    pub preis: Vec<Vec<f64>>,
    /// Raw SpineBase-relative coordinates over the cycle (72 channels).
    pub raw: Vec<Vec<Vec<f64>>>,
    /// Subject label of each walk.
    pub labels: Vec<u32>,
    /// Session (fold) index of each walk.
    pub session: Vec<usize>,
}

/// One prepared walk: sample, Ball features, Preis features, raw-coordinate channels.
type PreparedWalk = (GaitSample, Vec<f64>, Vec<f64>, Vec<Vec<f64>>);

/// Prepares walks (in parallel). Errors: label or session count, a walk without a full
/// cycle (named by index).
pub fn prepare(
    walks: &[SkeletonSeq],
    labels: &[u32],
    session: &[usize],
    p: &GaitParams,
) -> Result<PreparedWalks> {
    p.validate()?;
    if labels.len() != walks.len() || session.len() != walks.len() {
        return Err(Error::ShapeMismatch(format!(
            "{} walks, {} labels, {} session indices",
            walks.len(),
            labels.len(),
            session.len()
        )));
    }
    let per: Vec<PreparedWalk> = walks
        .par_iter()
        .enumerate()
        .map(|(i, w)| {
            let named = |e: Error| Error::invalid("walks", format!("walk {i}: {e}"));
            let s = gait_sample(w, p).map_err(named)?;
            let b = ball_features(w, &s.cycle)?.to_vec();
            let q = preis_features(w, &s.cycle)?.to_vec();
            let r = raw_coordinate_sample(w, &s.cycle)?;
            Ok((s, b, q, r))
        })
        .collect::<Result<_>>()?;
    let mut out = PreparedWalks {
        samples: Vec::new(),
        ball: Vec::new(),
        preis: Vec::new(),
        raw: Vec::new(),
        labels: labels.to_vec(),
        session: session.to_vec(),
    };
    for (s, b, q, r) in per {
        out.samples.push(s);
        out.ball.push(b);
        out.preis.push(q);
        out.raw.push(r);
    }
    Ok(out)
}

/// Options of [`cross_validate`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Protocol {
    /// Pipeline parameters (its `min_bins` is the fixed-threshold variant).
    pub params: GaitParams,
    /// Thresholds of the sweep and of the choice on the training folds (1..=30).
    pub thresholds: Vec<f64>,
    /// Voters of the `Majority` rule reported beside 1-NN and the paper's rule (3).
    pub majority_k: usize,
    /// Length of the resampling ablation (32).
    pub resample_len: usize,
    /// Compute the relevance map on the training and the test walks of each fold, as the
    /// paper did with all 60 videos (test data leaks into the pair selection; reproduction
    /// only). Default `false`: training walks only.
    pub relevance_on_all_walks: bool,
}

impl Default for Protocol {
    fn default() -> Self {
        Self {
            params: GaitParams::default(),
            thresholds: (1..=30).map(f64::from).collect(),
            majority_k: 3,
            resample_len: 32,
            relevance_on_all_walks: false,
        }
    }
}

/// Accuracies of one cross-validation, fractions in [0, 1].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CvReport {
    /// Number of test decisions.
    pub decisions: usize,
    /// JRA + DTW kernel, threshold chosen on the training folds, 1-NN.
    pub jra_nearest: f64,
    /// Same, the paper's vote (top #classes + 1).
    pub jra_paper_vote: f64,
    /// Same, majority of `majority_k`.
    pub jra_majority: f64,
    /// JRA + DTW kernel at the fixed threshold `params.min_bins`, 1-NN.
    pub jra_fixed: f64,
    /// JRA + DTW kernel normalised by the path-length bound `n + m`, chosen threshold, 1-NN.
    pub jra_normalized: f64,
    /// JRA sequences resampled to `resample_len` samples + Euclidean sum, chosen threshold.
    pub jra_resampled: f64,
    /// DTW kernel on raw SpineBase-relative coordinates (72 channels), 1-NN.
    pub raw_dtw: f64,
    /// Ball et al.: z-scored features, 1-NN.
    pub ball_nn: f64,
    /// Preis et al.: Gaussian Naive Bayes.
    pub preis_nb: f64,
    /// Preis et al.: z-scored features, 1-NN.
    pub preis_nn: f64,
    /// Threshold chosen on the training walks of each fold.
    pub chosen_t: Vec<f64>,
    /// Fig. 9 analogue: (threshold, 1-NN accuracy), relevance on the training walks; NaN where
    /// no pair reaches the threshold.
    pub curve: Vec<(f64, f64)>,
    /// Relevance map of all training walks of the first fold (Fig. 8 analogue).
    pub relevance: JointMap,
}

/// Channel indices (into the 276-pair order) of the pairs selected by `rel >= t`.
fn selected_channels(set: &JraSet, rel: &JointMap, t: f64) -> Vec<usize> {
    set.pairs
        .iter()
        .enumerate()
        .filter(|(_, (a, b))| {
            let r = rel[a.index()][b.index()];
            r >= t && r > 0.0
        })
        .map(|(k, _)| k)
        .collect()
}

/// Ranks `train` by a dissimilarity to a query and returns `(label, d)` ascending (stable on
/// training order).
fn ranked(train: &[usize], labels: &[u32], d: impl Fn(usize) -> f64) -> Vec<(u32, f64)> {
    let mut r: Vec<(usize, u32, f64)> = train.iter().map(|&j| (j, labels[j], d(j))).collect();
    r.sort_by(|a, b| a.2.total_cmp(&b.2).then(a.0.cmp(&b.0)));
    r.into_iter().map(|(_, l, d)| (l, d)).collect()
}

/// Chooses the threshold on the training walks (`sels[c]`: the channels candidate `c`
/// selects): leave-one-out 1-NN accuracy for every candidate; among the best, the centre of
/// the longest run of consecutive candidates. Returns the candidate's index.
fn choose_threshold(
    cache: &ChannelCache,
    train: &[usize],
    labels: &[u32],
    sels: &[Vec<usize>],
) -> usize {
    let acc: Vec<f64> = sels
        .iter()
        .map(|sel| {
            if sel.is_empty() {
                return -1.0;
            }
            let ok = train
                .iter()
                .filter(|&&i| {
                    let others: Vec<usize> = train.iter().copied().filter(|&j| j != i).collect();
                    let r = ranked(&others, labels, |j| cache.sum(i, j, sel));
                    r.first().is_some_and(|x| x.0 == labels[i])
                })
                .count();
            ok as f64 / train.len() as f64
        })
        .collect();
    let best = acc.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (mut run_start, mut best_run) = (None, (0usize, 0usize));
    for k in 0..=acc.len() {
        let on = k < acc.len() && acc[k] == best;
        match (on, run_start) {
            (true, None) => run_start = Some(k),
            (false, Some(s)) => {
                if k - s > best_run.1 - best_run.0 {
                    best_run = (s, k);
                }
                run_start = None;
            }
            _ => {}
        }
    }
    (best_run.0 + best_run.1 - 1) / 2
}

/// Cross-validation over the sessions of `train`: fold `k` trains on the walks of `train`
/// whose session is not `k` and tests the walks of `test` (default: `train`) whose session
/// is `k`. Relevance maps and thresholds use the training walks only.
///
/// Errors: no folds, a fold without training or test walks, bad protocol options.
pub fn cross_validate(
    train: &PreparedWalks,
    test: Option<&PreparedWalks>,
    proto: &Protocol,
) -> Result<CvReport> {
    if proto.thresholds.is_empty() || proto.thresholds.iter().any(|t| !t.is_finite()) {
        return Err(Error::invalid(
            "thresholds",
            "needs at least one finite threshold",
        ));
    }
    if proto.majority_k == 0 || proto.resample_len < 2 {
        return Err(Error::invalid(
            "protocol",
            "majority_k >= 1 and resample_len >= 2 are required",
        ));
    }
    let same = test.is_none();
    let test = test.unwrap_or(train);
    // One index space: training walks, then (if different) the test walks.
    let nt = train.samples.len();
    let idx_test = |i: usize| if same { i } else { nt + i };
    let all: Vec<&GaitSample> = if same {
        train.samples.iter().collect()
    } else {
        train.samples.iter().chain(&test.samples).collect()
    };
    let labels: Vec<u32> = if same {
        train.labels.clone()
    } else {
        train.labels.iter().chain(&test.labels).copied().collect()
    };
    let sets: Vec<&JraSet> = all.iter().map(|s| &s.jra).collect();
    let jra_samples: Vec<Vec<Vec<f64>>> = sets.iter().map(|s| s.seqs.clone()).collect();
    let raw: Vec<Vec<Vec<f64>>> = if same {
        train.raw.clone()
    } else {
        train.raw.iter().chain(&test.raw).cloned().collect()
    };
    let p = &proto.params;
    let cache = ChannelCache::compute(&jra_samples, &p.dtw);
    let raw_cache = ChannelCache::compute(&raw, &p.dtw);
    let raw_sel: Vec<usize> = (0..raw.first().map_or(0, Vec::len)).collect();
    let resampled: Vec<Vec<Vec<f64>>> = jra_samples
        .iter()
        .map(|s| s.iter().map(|c| resample(c, proto.resample_len)).collect())
        .collect();
    let lens: Vec<f64> = sets.iter().map(|s| s.frames() as f64).collect();

    let folds: Vec<usize> = {
        let mut f = train.session.clone();
        f.sort_unstable();
        f.dedup();
        f
    };
    if folds.is_empty() {
        return Err(Error::Empty("sessions"));
    }
    let mut counts = [0usize; 10];
    let mut decisions = 0;
    let mut chosen_t = Vec::new();
    let mut curve_ok = vec![0usize; proto.thresholds.len()];
    let mut curve_valid = vec![true; proto.thresholds.len()];
    let mut first_rel = None;
    for &k in &folds {
        let tr: Vec<usize> = (0..nt).filter(|&i| train.session[i] != k).collect();
        let te: Vec<usize> = (0..test.samples.len())
            .filter(|&i| test.session[i] == k)
            .map(idx_test)
            .collect();
        if tr.is_empty() || te.is_empty() {
            return Err(Error::invalid(
                "sessions",
                format!("fold {k} has no training or no test walks"),
            ));
        }
        let rel_walks = if proto.relevance_on_all_walks {
            tr.iter()
                .chain(&te)
                .map(|&i| sets[i])
                .collect::<Vec<&JraSet>>()
        } else {
            tr.iter().map(|&i| sets[i]).collect()
        };
        let rel = relevance_matrix(&rel_walks, &p.hist)?;
        first_rel.get_or_insert(rel);
        // The pairs each threshold selects, once per fold.
        let sels: Vec<Vec<usize>> = proto
            .thresholds
            .iter()
            .map(|&t| selected_channels(sets[tr[0]], &rel, t))
            .collect();
        let best = choose_threshold(&cache, &tr, &labels, &sels);
        chosen_t.push(proto.thresholds[best]);
        let sel = &sels[best];
        let sel_fixed = selected_channels(sets[tr[0]], &rel, p.min_bins);
        let ball = ZScoreNn::fit(
            &tr.iter()
                .map(|&i| feat(train, test, same, nt, i, true))
                .collect::<Vec<_>>(),
            &tr.iter().map(|&i| labels[i]).collect::<Vec<_>>(),
        )?;
        let preis_rows: Vec<Vec<f64>> = tr
            .iter()
            .map(|&i| feat(train, test, same, nt, i, false))
            .collect();
        let tr_labels: Vec<u32> = tr.iter().map(|&i| labels[i]).collect();
        let preis_nn = ZScoreNn::fit(&preis_rows, &tr_labels)?;
        let preis_nb = GaussianNb::fit(&preis_rows, &tr_labels)?;
        for &i in &te {
            let truth = labels[i];
            decisions += 1;
            let r = ranked(&tr, &labels, |j| cache.sum(i, j, sel));
            let hits = [
                vote(&r, Vote::Nearest)?,
                vote(&r, Vote::PaperTopClassesPlusOne)?,
                vote(
                    &r,
                    Vote::Majority {
                        k: proto.majority_k,
                    },
                )?,
                if sel_fixed.is_empty() {
                    u32::MAX
                } else {
                    ranked(&tr, &labels, |j| cache.sum(i, j, &sel_fixed))[0].0
                },
                ranked(&tr, &labels, |j| cache.sum(i, j, sel) / (lens[i] + lens[j]))[0].0,
                ranked(&tr, &labels, |j| {
                    sel.iter()
                        .map(|&c| {
                            resampled[i][c]
                                .iter()
                                .zip(&resampled[j][c])
                                .map(|(a, b)| (a - b) * (a - b))
                                .sum::<f64>()
                                .sqrt()
                        })
                        .sum()
                })[0]
                    .0,
                ranked(&tr, &labels, |j| raw_cache.sum(i, j, &raw_sel))[0].0,
                ball.predict(&feat(train, test, same, nt, i, true))?,
                preis_nb.predict(&feat(train, test, same, nt, i, false))?,
                preis_nn.predict(&feat(train, test, same, nt, i, false))?,
            ];
            for (c, h) in counts.iter_mut().zip(hits) {
                *c += usize::from(h == truth);
            }
            for (ti, s) in sels.iter().enumerate() {
                if s.is_empty() {
                    curve_valid[ti] = false;
                    continue;
                }
                let r = ranked(&tr, &labels, |j| cache.sum(i, j, s));
                curve_ok[ti] += usize::from(r[0].0 == truth);
            }
        }
    }
    let a = |c: usize| c as f64 / decisions as f64;
    Ok(CvReport {
        decisions,
        jra_nearest: a(counts[0]),
        jra_paper_vote: a(counts[1]),
        jra_majority: a(counts[2]),
        jra_fixed: a(counts[3]),
        jra_normalized: a(counts[4]),
        jra_resampled: a(counts[5]),
        raw_dtw: a(counts[6]),
        ball_nn: a(counts[7]),
        preis_nb: a(counts[8]),
        preis_nn: a(counts[9]),
        chosen_t,
        curve: proto
            .thresholds
            .iter()
            .zip(curve_ok.iter().zip(&curve_valid))
            .map(|(&t, (&ok, &v))| (t, if v { a(ok) } else { f64::NAN }))
            .collect(),
        relevance: first_rel.unwrap_or([[0.0; 25]; 25]),
    })
}

/// Features of combined index `i` (Ball when `ball`, else Preis).
fn feat(
    train: &PreparedWalks,
    test: &PreparedWalks,
    same: bool,
    nt: usize,
    i: usize,
    ball: bool,
) -> Vec<f64> {
    let (set, k) = if same || i < nt {
        (train, i)
    } else {
        (test, i - nt)
    };
    if ball {
        set.ball[k].clone()
    } else {
        set.preis[k].clone()
    }
}
