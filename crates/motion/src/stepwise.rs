//! Step-wise regression over the three actions (paper §2.3, eq. 1):
//! `ξ_i^r(t) = m_i^r + w_i0^r s₀(t) + Σ_j w_ij^r s_j(t − τ_ij)`.
//!
//! - Action 1: per trial and channel, least squares on `[1, s₀]` gives the means and
//!   non-periodic weights; the residual is demixed into 3 periodic sources with shared delays;
//!   all weights are then refitted jointly (cheap, never lowers `Q`).
//! - Action 2: sources 1–3 and their delays are kept as they are; means and weights are
//!   refitted jointly, 2 new sources with shared delays are learned from the residual, and all
//!   weights are refitted jointly with the 5 sources.
//! - Action 3: all 5 sources with fixed delays; only means and weights are refitted.
//!
//! `Q` of an action is `1 − ‖ξ − ξ̂‖² / ‖ξ − m − w₀ s₀‖²`, the denominator being the data
//! after removing the means and the non-periodic part by the `[1, s₀]` least squares (paper
//! Fig. 4 caption).

use crate::anechoic::{fit_anechoic, refine_anechoic, AnechoicModel, AnechoicParams, DelayMode};
use crate::data::TrialSet;
use crate::dataset::Dataset;
use crate::fourier::PeriodicSource;
use crate::linalg::lstsq_columns;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use wscg_math::{Error, Result};

wscg_math::params! {
    /// Parameters of [`fit_stepwise`].
    #[derive(Clone, Debug, PartialEq)]
    pub struct StepwiseParams {
        /// Periodic sources of action 1 (the paper's 3).
        pub n_sources_first: usize,
        /// Sources added in action 2 (the paper's 2).
        pub n_sources_extra: usize,
        /// Demixing settings (the number of sources is set per stage).
        pub demix: AnechoicParams,
        /// Rounds of alternation between the joint least squares of means and weights and the
        /// demixing of the data without means and non-periodic part (0: the plain step-wise
        /// regression). The first `[1, s₀]` regression also absorbs the part of the periodic
        /// sources that correlates with `s₀`; alternating removes that bias.
        pub rounds: usize,
        /// ALS sweeps per alternation round.
        pub round_iter: usize,
    }
}

impl Default for StepwiseParams {
    fn default() -> Self {
        Self {
            n_sources_first: 3,
            n_sources_extra: 2,
            demix: AnechoicParams::default(),
            rounds: 8,
            round_iter: 60,
        }
    }
}

impl StepwiseParams {
    /// Errors: `n_sources_first == 0`, invalid demixing settings (their `n_sources` is set
    /// per stage and not checked; see [`AnechoicParams::validate`]), `round_iter == 0` with
    /// alternation rounds.
    pub fn validate(&self) -> Result<()> {
        if self.n_sources_first == 0 {
            return Err(Error::invalid("n_sources_first", "must be >= 1"));
        }
        AnechoicParams {
            n_sources: 1,
            ..self.demix.clone()
        }
        .validate()?;
        if self.rounds > 0 && self.round_iter == 0 {
            return Err(Error::invalid(
                "round_iter",
                format!("must be >= 1 with {} alternation rounds", self.rounds),
            ));
        }
        Ok(())
    }
}

/// The fit of one action: per-trial means and weights, and its quality.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActionFit {
    /// Means, `R × I`.
    pub means: Vec<f64>,
    /// Non-periodic weights, `R × I`.
    pub w0: Vec<f64>,
    /// Periodic weights, `R × I × J` (`J` = all library sources; unused ones are 0).
    pub weights: Vec<f64>,
    /// Number of sources the action uses.
    pub n_sources: usize,
    /// `Q` of the final joint fit.
    pub q: f64,
    /// `‖ξ − m − w₀ s₀‖²` (denominator of `Q`) and `‖ξ − ξ̂‖²`.
    pub energy: (f64, f64),
}

/// What [`fit_stepwise`] learns.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ActionLibrary {
    /// Channels `I`.
    pub n_channels: usize,
    /// Samples per action `N`.
    pub n_samples: usize,
    /// The periodic sources (unit RMS): action 1's, then those added in action 2.
    pub sources: Vec<PeriodicSource>,
    /// Shared delays `I × J` (periods).
    pub delays: Vec<f64>,
    /// Per-action fits.
    pub actions: [ActionFit; 3],
    /// Demixing of action 1's residual (3 sources).
    pub demix_first: AnechoicModel,
    /// Demixing of action 2's residual (the extra sources).
    pub demix_extra: AnechoicModel,
    /// `Q` of action 2 with only the first sources (before adding the extra ones).
    pub q_second_before_extra: f64,
    /// `Q` over all actions.
    pub q_total: f64,
    /// `(step parameter, duration)` of each trial, per action.
    pub params: [Vec<(f64, f64)>; 3],
    /// Normalised pelvis progress over an action at `u = m / N`, `m = 0..=N` (monotone, from 0
    /// to 1), averaged over the training steps.
    pub progress: Vec<f64>,
}

impl ActionLibrary {
    /// Number of periodic sources `J`.
    pub fn n_sources(&self) -> usize {
        self.sources.len()
    }

    /// The output vector of action `a`, trial `r`, for the weight regression:
    /// `[means (I), w0 (I), weights (I × J)]`.
    pub fn weight_vector(&self, a: usize, r: usize) -> Vec<f64> {
        let (i_n, j_n) = (self.n_channels, self.n_sources());
        let f = &self.actions[a];
        let mut v = Vec::with_capacity(i_n * (2 + j_n));
        v.extend_from_slice(&f.means[r * i_n..(r + 1) * i_n]);
        v.extend_from_slice(&f.w0[r * i_n..(r + 1) * i_n]);
        v.extend_from_slice(&f.weights[r * i_n * j_n..(r + 1) * i_n * j_n]);
        v
    }

    /// Pelvis progress `p(u)` for `u ∈ [0, 1]`, linearly interpolated.
    pub fn progress_at(&self, u: f64) -> f64 {
        let m = self.progress.len() - 1;
        let x = u.clamp(0.0, 1.0) * m as f64;
        let i = (x.floor() as usize).min(m - 1);
        let f = x - i as f64;
        self.progress[i] * (1.0 - f) + self.progress[i + 1] * f
    }

    /// The library as JSON (exact: floats round-trip).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::invalid("library", e.to_string()))
    }

    /// A library from [`Self::to_json`] output. Errors: not a library, or sizes that
    /// disagree (delays, per-action means and weights, step parameters, progress curve).
    pub fn from_json(s: &str) -> Result<Self> {
        let lib: Self = serde_json::from_str(s)
            .map_err(|e| Error::invalid("library", format!("not an action library: {e}")))?;
        lib.check_sizes()?;
        Ok(lib)
    }

    fn check_sizes(&self) -> Result<()> {
        let (i_n, j_n) = (self.n_channels, self.n_sources());
        let bad = |what: String| Err(Error::invalid("library", what));
        if i_n == 0 || j_n == 0 || self.n_samples == 0 {
            return bad(format!(
                "{i_n} channels, {j_n} sources, {} samples",
                self.n_samples
            ));
        }
        if self.sources.iter().any(|s| s.coeffs.is_empty()) {
            return bad("a source without harmonics".into());
        }
        if self.delays.len() != i_n * j_n {
            return bad(format!("{} delays for {i_n} x {j_n}", self.delays.len()));
        }
        for (a, (f, p)) in self.actions.iter().zip(&self.params).enumerate() {
            let r_n = p.len();
            if r_n == 0
                || f.means.len() != r_n * i_n
                || f.w0.len() != r_n * i_n
                || f.weights.len() != r_n * i_n * j_n
                || f.n_sources > j_n
            {
                return bad(format!("action {a}: sizes disagree with {r_n} trials"));
            }
        }
        if self.progress.len() < 2 {
            return bad(format!("{} progress samples", self.progress.len()));
        }
        Ok(())
    }
}

/// The non-periodic source sampled over one action: `s₀(t) = cos(π t / T)`.
pub fn nonperiodic_samples(n: usize) -> Vec<f64> {
    (0..n).map(|t| (PI * t as f64 / n as f64).cos()).collect()
}

/// Per (trial, channel) least squares of `[1, s₀, s_j(t − τ_ij)…]`: returns means, `w₀`,
/// weights (`R × I × J`, `J = shifted.len() / I`), the fitted model and the residual.
struct Refit {
    means: Vec<f64>,
    w0: Vec<f64>,
    weights: Vec<f64>,
    residual: TrialSet,
}

fn refit(x: &TrialSet, s0: &[f64], shifted: &[Vec<f64>], j_n: usize) -> Result<Refit> {
    let (r_n, i_n, n) = (x.n_trials, x.n_channels, x.n_samples);
    let ones = vec![1.0; n];
    let rows: Vec<(Vec<f64>, Vec<f64>)> = (0..r_n * i_n)
        .into_par_iter()
        .map(|ri| {
            let i = ri % i_n;
            let y = &x.data[ri * n..(ri + 1) * n];
            let mut cols: Vec<&[f64]> = vec![&ones, s0];
            for j in 0..j_n {
                cols.push(&shifted[i * j_n + j]);
            }
            let coef = lstsq_columns(&cols, y, 1e-12)?;
            let res: Vec<f64> = (0..n)
                .map(|t| y[t] - cols.iter().zip(&coef).map(|(c, b)| c[t] * b).sum::<f64>())
                .collect();
            Ok((coef, res))
        })
        .collect::<Result<_>>()?;
    let mut out = Refit {
        means: Vec::with_capacity(r_n * i_n),
        w0: Vec::with_capacity(r_n * i_n),
        weights: Vec::with_capacity(r_n * i_n * j_n),
        residual: x.zeros_like(),
    };
    for (ri, (coef, res)) in rows.into_iter().enumerate() {
        out.means.push(coef[0]);
        out.w0.push(coef[1]);
        out.weights.extend_from_slice(&coef[2..]);
        out.residual.data[ri * n..(ri + 1) * n].copy_from_slice(&res);
    }
    Ok(out)
}

/// Delayed samples `s_j(t − τ_ij)` for every channel and source (`I × J` vectors of `N`).
fn shifted_sources(
    sources: &[PeriodicSource],
    delays: &[f64],
    i_n: usize,
    n: usize,
) -> Vec<Vec<f64>> {
    let j_n = sources.len();
    (0..i_n * j_n)
        .map(|d| sources[d % j_n].sample(n, delays[d]))
        .collect()
}

/// `ξ − m − w₀ s₀ − Σ_{j < fixed} w_j s_j` of a joint fit: what the sources from `fixed` on
/// must explain.
fn strip(
    x: &TrialSet,
    s0: &[f64],
    fit: &Refit,
    sh: &[Vec<f64>],
    j_n: usize,
    fixed: usize,
) -> TrialSet {
    let (i_n, n) = (x.n_channels, x.n_samples);
    let mut out = x.clone();
    for (ri, row) in out.data.chunks_mut(n).enumerate() {
        let i = ri % i_n;
        for (t, v) in row.iter_mut().enumerate() {
            let mut model = fit.means[ri] + fit.w0[ri] * s0[t];
            for j in 0..fixed {
                model += fit.weights[ri * j_n + j] * sh[i * j_n + j][t];
            }
            *v -= model;
        }
    }
    out
}

/// Alternates the joint least squares of means and all weights with a refinement of the
/// sources from `fixed` on (and their delays) on the data stripped of everything else.
/// Returns the refined model of those sources and the final joint fit.
#[allow(clippy::too_many_arguments)]
fn alternate(
    x: &TrialSet,
    s0: &[f64],
    fixed_sources: &[PeriodicSource],
    fixed_delays: &[f64],
    mut model: AnechoicModel,
    cfg: &StepwiseParams,
) -> Result<(AnechoicModel, Refit, Vec<Vec<f64>>)> {
    let i_n = x.n_channels;
    let nf = fixed_sources.len();
    let j_n = nf + model.n_sources();
    let assemble = |m: &AnechoicModel| -> (Vec<PeriodicSource>, Vec<f64>) {
        let mut src = fixed_sources.to_vec();
        src.extend(m.sources.iter().cloned());
        let mut d = Vec::with_capacity(i_n * j_n);
        for i in 0..i_n {
            d.extend_from_slice(&fixed_delays[i * nf..(i + 1) * nf]);
            d.extend_from_slice(&m.delays[i * m.n_sources()..(i + 1) * m.n_sources()]);
        }
        (src, d)
    };
    let (src, d) = assemble(&model);
    let mut sh = shifted_sources(&src, &d, i_n, x.n_samples);
    let mut fit = refit(x, s0, &sh, j_n)?;
    let mut err = fit.residual.energy();
    for _ in 0..cfg.rounds {
        let target = strip(x, s0, &fit, &sh, j_n, nf);
        let mut start = model.clone();
        start.weights = fit
            .weights
            .chunks(j_n)
            .flat_map(|c| c[nf..].iter().copied())
            .collect();
        let refined = refine_anechoic(
            &target,
            &AnechoicParams {
                max_iter: cfg.round_iter,
                ..cfg.demix.clone()
            },
            &start,
        )?;
        let (src, d) = assemble(&refined);
        let sh_new = shifted_sources(&src, &d, i_n, x.n_samples);
        let fit_new = refit(x, s0, &sh_new, j_n)?;
        let e_new = fit_new.residual.energy();
        if e_new >= err {
            break;
        }
        let gain = (err - e_new) / err.max(f64::MIN_POSITIVE);
        model = refined;
        fit = fit_new;
        sh = sh_new;
        err = e_new;
        if gain < 1e-6 {
            break;
        }
    }
    Ok((model, fit, sh))
}

fn widen(weights: &[f64], j_from: usize, j_to: usize) -> Vec<f64> {
    weights
        .chunks(j_from)
        .flat_map(|c| {
            c.iter()
                .copied()
                .chain(std::iter::repeat_n(0.0, j_to - j_from))
        })
        .collect()
}

fn check_stepwise(data: &Dataset, cfg: &StepwiseParams) -> Result<()> {
    cfg.validate()?;
    data.validate()?;
    if data.trials.len() < 3 {
        return Err(Error::invalid(
            "trials",
            format!(
                "the weight regression of 2 step parameters needs at least 3 trials, got {}",
                data.trials.len()
            ),
        ));
    }
    Ok(())
}

/// Learns the sources, delays and per-trial weights of the three actions.
///
/// # Errors
/// An invalid dataset (see [`Dataset::validate`]), fewer than 3 trials, or a demixing error
/// (too many sources for the data, `n_harmonics ≥ N/2`).
pub fn fit_stepwise(data: &Dataset, cfg: &StepwiseParams) -> Result<ActionLibrary> {
    check_stepwise(data, cfg)?;
    let (i_n, n) = (data.n_channels, data.n_samples);
    let j1 = cfg.n_sources_first;
    let j_all = j1 + cfg.n_sources_extra;
    let s0 = nonperiodic_samples(n);
    let sets: Vec<TrialSet> = (0..3).map(|a| data.action_set(a)).collect::<Result<_>>()?;

    // Action 1.
    let base1 = refit(&sets[0], &s0, &[], 0)?;
    let den1 = base1.residual.energy();
    // With alternation rounds to follow, the first demixing only needs to find the basin: its
    // restarts are screened and the best is refined inside the rounds.
    let first_iter = if cfg.rounds > 0 {
        cfg.demix.screen_iter.min(cfg.demix.max_iter)
    } else {
        cfg.demix.max_iter
    };
    let demix1 = fit_anechoic(
        &base1.residual,
        &AnechoicParams {
            n_sources: j1,
            delays: DelayMode::Shared,
            max_iter: first_iter,
            ..cfg.demix.clone()
        },
    )?;
    let (demix_first, fit1, sh1) = alternate(&sets[0], &s0, &[], &[], demix1, cfg)?;
    let mut sources = demix_first.sources.clone();
    let mut delays: Vec<f64> = demix_first.delays.clone();

    // Action 2: the first sources as they are, then the extra ones from the residual.
    let base2 = refit(&sets[1], &s0, &[], 0)?;
    let den2 = base2.residual.energy();
    let fit2a = refit(&sets[1], &s0, &sh1, j1)?;
    let q_second_before_extra = 1.0 - fit2a.residual.energy() / den2;
    let (demix_extra, fit2) = if cfg.n_sources_extra > 0 {
        let extra = fit_anechoic(
            &fit2a.residual,
            &AnechoicParams {
                n_sources: cfg.n_sources_extra,
                delays: DelayMode::Shared,
                max_iter: first_iter,
                ..cfg.demix.clone()
            },
        )?;
        let (extra, fit2, _) = alternate(&sets[1], &s0, &sources, &delays, extra, cfg)?;
        sources.extend(extra.sources.iter().cloned());
        let mut all = Vec::with_capacity(i_n * j_all);
        for i in 0..i_n {
            all.extend_from_slice(&delays[i * j1..(i + 1) * j1]);
            all.extend_from_slice(
                &extra.delays[i * cfg.n_sources_extra..(i + 1) * cfg.n_sources_extra],
            );
        }
        delays = all;
        (extra, fit2)
    } else {
        (demix_first.clone(), refit(&sets[1], &s0, &sh1, j1)?)
    };
    let sh_all = shifted_sources(&sources, &delays, i_n, n);

    // Action 3: everything fixed but means and weights.
    let base3 = refit(&sets[2], &s0, &[], 0)?;
    let den3 = base3.residual.energy();
    let fit3 = refit(&sets[2], &s0, &sh_all, j_all)?;

    let mk = |f: Refit, j_used: usize, den: f64| {
        let num = f.residual.energy();
        ActionFit {
            means: f.means,
            w0: f.w0,
            weights: widen(&f.weights, j_used, j_all),
            n_sources: j_used,
            q: if den > 0.0 { 1.0 - num / den } else { 1.0 },
            energy: (den, num),
        }
    };
    let actions = [
        mk(fit1, j1, den1),
        mk(fit2, j_all, den2),
        mk(fit3, j_all, den3),
    ];
    let (den, num) = actions.iter().fold((0.0, 0.0), |acc, a| {
        (acc.0 + a.energy.0, acc.1 + a.energy.1)
    });
    Ok(ActionLibrary {
        n_channels: i_n,
        n_samples: n,
        sources,
        delays,
        q_total: if den > 0.0 { 1.0 - num / den } else { 1.0 },
        actions,
        demix_first,
        demix_extra,
        q_second_before_extra,
        params: [data.params(0), data.params(1), data.params(2)],
        progress: learn_progress(data),
    })
}

/// Average normalised pelvis progress of the walking actions, made monotone; `p(u) = u` when no
/// root curves are given.
fn learn_progress(data: &Dataset) -> Vec<f64> {
    let n = data.n_samples;
    let mut acc = vec![0.0; n + 1];
    let mut count = 0usize;
    for trial in &data.trials {
        for act in &trial[..2] {
            if act.root.len() == n && act.step_length > 0.0 {
                for (a, r) in acc.iter_mut().zip(&act.root) {
                    *a += (r - act.root[0]) / act.step_length;
                }
                acc[n] += 1.0;
                count += 1;
            }
        }
    }
    if count == 0 {
        return (0..=n).map(|t| t as f64 / n as f64).collect();
    }
    let mut p: Vec<f64> = acc.iter().map(|v| v / count as f64).collect();
    p[0] = 0.0;
    p[n] = 1.0;
    for t in 1..=n {
        p[t] = p[t].clamp(p[t - 1], 1.0);
    }
    p
}
