//! The synthetic walker: a seeded generator of walk-and-reach trials with known ground truth,
//! standing in for the paper's unpublished motion capture of the drawer task (§2.1).
//!
//! - 17 joints, 51 exponential-map channels, `N` samples per action.
//! - 5 periodic sources (3 in action 1, all 5 in actions 2 and 3), each with harmonics 1–3 of
//!   amplitudes (1, 0.4, 0.15) and random phases, at unit RMS; delays uniform on one period and
//!   shared by all trials.
//! - Weights and means are smooth nonlinear functions of the step parameters,
//!   `W = W₀ + W₁ u + W₂ v + W₃ u²` (`u`, `v`: step length and duration normalised to the
//!   trained ranges), and the non-periodic weights are large on the left-arm channels in
//!   actions 2 and 3 (the reaching arm).
//! - Learning set: `L₁ ~ U[0.670, 0.901]`, `L₂ ~ U[1.070, 1.439]` independent,
//!   `D = 0.6 + L₁ + L₂`. Human-like set (paper Fig. 2): `D ~ U[2.34, 2.94]`,
//!   `L₁ = 0.78 + N(0, 0.03²)` independent of `D`, `L₂ = D − 0.6 − L₁ + N(0, 0.01²)`.
//! - Durations `T = 0.45 + 0.5 L` s plus a 10 ms jitter (so that duration is an input of its
//!   own); the reach lasts `0.9 + 0.3 (L₂ − 1.25)` s plus jitter. Noise: a fraction of each
//!   channel's RMS (1 % by default).
//! - The pelvis advances by `L p(u)` over an action, `p(u) = u − 0.15 sin(2πu) / 2π`.

use crate::data::TrialSet;
use crate::dataset::{Dataset, TrialAction};
use crate::fourier::PeriodicSource;
use crate::skeleton::{is_arm_channel, is_left_arm_channel, is_leg_channel, N_CHANNELS};
use num_complex::Complex64;
use rand::Rng as _;
use rand_distr::{Distribution, Normal, StandardNormal};
use std::f64::consts::{PI, TAU};
use wscg_math::rng::Rng;
use wscg_math::{Error, Result};

wscg_math::params! {
    /// Parameters of [`reach_walk`].
    #[derive(Clone, Debug, PartialEq)]
    pub struct WalkerParams {
        /// Number of trials.
        pub n_trials: usize,
        /// Samples per action.
        pub n_samples: usize,
        /// Noise standard deviation as a fraction of each channel's RMS.
        pub noise: f64,
        /// Seed of the trial parameters and the noise.
        pub seed: u64,
        /// Seed of the ground-truth model (sources, delays, weight functions); trials drawn with
        /// different `seed` but the same `model_seed` come from the same "subject".
        pub model_seed: u64,
        /// Step-length range of action 1 (metres).
        pub range1: (f64, f64),
        /// Step-length range of action 2 (metres).
        pub range2: (f64, f64),
        /// Draw the human-like set of paper Fig. 2 instead of the learning set.
        pub human_like: bool,
    }
}

impl Default for WalkerParams {
    fn default() -> Self {
        Self {
            n_trials: 40,
            n_samples: 100,
            noise: 0.01,
            seed: 0,
            model_seed: 7,
            range1: (0.670, 0.901),
            range2: (1.070, 1.439),
            human_like: false,
        }
    }
}

impl WalkerParams {
    /// Errors: `n_trials == 0`, fewer than 8 samples per action, a negative or non-finite
    /// noise level, a step-length range that is not `0 < lo < hi`.
    pub fn validate(&self) -> Result<()> {
        if self.n_trials == 0 {
            return Err(Error::invalid("n_trials", "must be >= 1"));
        }
        if self.n_samples < 8 {
            return Err(Error::invalid(
                "n_samples",
                format!("must be >= 8, got {}", self.n_samples),
            ));
        }
        if !(self.noise.is_finite() && self.noise >= 0.0) {
            return Err(Error::invalid(
                "noise",
                format!("must be finite and >= 0, got {}", self.noise),
            ));
        }
        for (name, r) in [("range1", self.range1), ("range2", self.range2)] {
            if !(r.0.is_finite() && r.1.is_finite() && r.0 > 0.0 && r.1 > r.0) {
                return Err(Error::invalid(
                    name,
                    format!("must satisfy 0 < lo < hi, got ({}, {})", r.0, r.1),
                ));
            }
        }
        Ok(())
    }
}

/// Number of ground-truth periodic sources.
pub const N_SOURCES: usize = 5;
/// Periodic sources active in action 1.
pub const N_SOURCES_FIRST: usize = 3;

/// The generator's hidden model, for checking what a fit recovers.
#[derive(Clone, Debug)]
pub struct WalkerTruth {
    /// The 5 unit-RMS periodic sources.
    pub sources: Vec<PeriodicSource>,
    /// Delays `I × 5` (periods, in `[0, 1)`).
    pub delays: Vec<f64>,
    /// Noise-free periodic part `Σ_j W_ij s_j(t − τ_ij)` of each action, `R × I × N`.
    pub periodic: [TrialSet; 3],
    /// Periodic weights of each action, `R × I × 5`.
    pub weights: [Vec<f64>; 3],
    /// Means of each action, `R × I`.
    pub means: [Vec<f64>; 3],
    /// Non-periodic weights of each action, `R × I`.
    pub w0: [Vec<f64>; 3],
}

/// Ground-truth pelvis progress over an action, `p(u) = u − 0.15 sin(2πu) / 2π`.
pub fn true_progress(u: f64) -> f64 {
    u - 0.15 * (TAU * u).sin() / TAU
}

/// Smooth parameter dependence of one quantity: `base + a1 u + a2 v + a3 u²`.
#[derive(Clone, Copy)]
struct Poly {
    base: f64,
    a1: f64,
    a2: f64,
    a3: f64,
}

impl Poly {
    fn draw(rng: &mut Rng, sigma: f64) -> Self {
        let mut n = || -> f64 { StandardNormal.sample(&mut *rng) };
        Self {
            base: sigma * n(),
            a1: 0.4 * sigma * n(),
            a2: 0.1 * sigma * n(),
            a3: 0.5 * sigma * n(),
        }
    }
    fn at(&self, u: f64, v: f64) -> f64 {
        self.base + self.a1 * u + self.a2 * v + self.a3 * u * u
    }
}

/// Per-channel amplitude of the periodic weights: legs and hips move most, the arms swing, the
/// spine and head follow.
fn channel_sigma(i: usize) -> f64 {
    if is_leg_channel(i) {
        0.12
    } else if is_arm_channel(i) {
        0.08
    } else {
        0.04
    }
}

struct ActionModel {
    w: Vec<Poly>,  // I × 5
    m: Vec<Poly>,  // I
    w0: Vec<Poly>, // I
}

/// Draws the model of one action. Consecutive actions are continuous in posture, as recorded
/// motion is: the next action's weights are the previous action's plus a perturbation, and its
/// means start where the previous action ended (`m_q + w0_q = m_p − w0_p`, since `s₀` runs from
/// 1 to −1 over an action).
fn draw_action(rng: &mut Rng, action: usize, prev: Option<&ActionModel>) -> ActionModel {
    let n_active = if action == 0 {
        N_SOURCES_FIRST
    } else {
        N_SOURCES
    };
    let mut w = Vec::with_capacity(N_CHANNELS * N_SOURCES);
    for i in 0..N_CHANNELS {
        for j in 0..N_SOURCES {
            let mut p = Poly::draw(rng, channel_sigma(i));
            if let Some(pm) = prev {
                let before = pm.w[i * N_SOURCES + j].base;
                if before != 0.0 {
                    let e: f64 = StandardNormal.sample(&mut *rng);
                    p.base = before + 0.3 * channel_sigma(i) * e;
                }
            }
            w.push(if j < n_active {
                p
            } else {
                Poly {
                    base: 0.0,
                    a1: 0.0,
                    a2: 0.0,
                    a3: 0.0,
                }
            });
        }
    }
    let w0: Vec<Poly> = (0..N_CHANNELS)
        .map(|i| {
            if action > 0 && is_left_arm_channel(i) {
                // The reaching arm: a large, sign-random non-periodic excursion.
                let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
                let base = sign * (0.35 + 0.25 * rng.random::<f64>());
                Poly {
                    base,
                    a1: 0.2 * base,
                    a2: 0.02 * base,
                    a3: 0.1 * base,
                }
            } else {
                Poly::draw(rng, 0.03)
            }
        })
        .collect();
    let m = (0..N_CHANNELS)
        .map(|i| {
            let mut p = Poly::draw(rng, 0.15);
            if let Some(pm) = prev {
                let e: f64 = StandardNormal.sample(&mut *rng);
                p.base = pm.m[i].base - pm.w0[i].base - w0[i].base + 0.02 * e;
                p.a1 *= 0.3;
                p.a3 *= 0.3;
            }
            p
        })
        .collect();
    ActionModel { w, m, w0 }
}

fn draw_source(rng: &mut Rng) -> PeriodicSource {
    let amps = [1.0, 0.4, 0.15];
    let coeffs: Vec<Complex64> = amps
        .iter()
        .map(|a| Complex64::from_polar(0.5 * a, TAU * rng.random::<f64>()))
        .collect();
    let s = PeriodicSource::new(coeffs);
    let rms = s.rms();
    PeriodicSource::new(s.coeffs.iter().map(|c| c / rms).collect())
}

/// Generates a walk-and-reach training set and its ground truth.
///
/// # Errors
/// Fewer than 1 trial, fewer than 8 samples per action, a negative or non-finite noise level,
/// or empty step ranges.
pub fn reach_walk(cfg: &WalkerParams) -> Result<(Dataset, WalkerTruth)> {
    cfg.validate()?;
    let (r_n, i_n, n) = (cfg.n_trials, N_CHANNELS, cfg.n_samples);
    // Each trial holds I channels of three actions of n samples, and its clean copy.
    wscg_math::alloc::ensure_shape::<f64>("n_trials", &[r_n, i_n, n, 3, 2])?;
    let mut mrng = wscg_math::rng::seeded(cfg.model_seed);
    let sources: Vec<PeriodicSource> = (0..N_SOURCES).map(|_| draw_source(&mut mrng)).collect();
    let delays: Vec<f64> = (0..i_n * N_SOURCES).map(|_| mrng.random::<f64>()).collect();
    let mut models: Vec<ActionModel> = Vec::with_capacity(3);
    for a in 0..3 {
        let m = draw_action(&mut mrng, a, models.last());
        models.push(m);
    }
    // Delayed source samples, I × 5 × N.
    let shifted: Vec<Vec<f64>> = (0..i_n * N_SOURCES)
        .map(|d| sources[d % N_SOURCES].sample(n, delays[d]))
        .collect();

    let mut rng = wscg_math::rng::seeded(cfg.seed);
    let jitter = Normal::new(0.0, 0.01).map_err(|e| Error::Numerical(e.to_string()))?;
    let mid = |r: (f64, f64)| 0.5 * (r.0 + r.1);
    let half = |r: (f64, f64)| 0.5 * (r.1 - r.0);
    let mut trials = Vec::with_capacity(r_n);
    let mut distances = Vec::with_capacity(r_n);
    let mut periodic: [Vec<f64>; 3] = Default::default();
    let mut weights: [Vec<f64>; 3] = Default::default();
    let mut means: [Vec<f64>; 3] = Default::default();
    let mut w0s: [Vec<f64>; 3] = Default::default();
    for _ in 0..r_n {
        let (l1, l2, d) = if cfg.human_like {
            let d = 2.34 + 0.60 * rng.random::<f64>();
            let e1: f64 = StandardNormal.sample(&mut rng);
            let e2: f64 = StandardNormal.sample(&mut rng);
            let l1 = 0.78 + 0.03 * e1;
            let l2 = d - 0.6 - l1 + 0.01 * e2;
            (l1, l2, d)
        } else {
            let l1 = cfg.range1.0 + (cfg.range1.1 - cfg.range1.0) * rng.random::<f64>();
            let l2 = cfg.range2.0 + (cfg.range2.1 - cfg.range2.0) * rng.random::<f64>();
            (l1, l2, 0.6 + l1 + l2)
        };
        distances.push(d);
        let t1 = 0.45 + 0.5 * l1 + jitter.sample(&mut rng);
        let t2 = 0.45 + 0.5 * l2 + jitter.sample(&mut rng);
        let t3 = 0.9 + 0.3 * (l2 - 1.25) + jitter.sample(&mut rng);
        // (step parameter, duration, normalised u, normalised v, pelvis travel)
        let u1 = (l1 - mid(cfg.range1)) / half(cfg.range1);
        let u2 = (l2 - mid(cfg.range2)) / half(cfg.range2);
        let acts = [
            (
                l1,
                t1,
                u1,
                (t1 - 0.45 - 0.5 * mid(cfg.range1)) / (0.5 * half(cfg.range1)),
                l1,
            ),
            (
                l2,
                t2,
                u2,
                (t2 - 0.45 - 0.5 * mid(cfg.range2)) / (0.5 * half(cfg.range2)),
                l2,
            ),
            (
                l2,
                t3,
                u2,
                (t3 - 0.9 - 0.3 * (mid(cfg.range2) - 1.25)) / (0.3 * half(cfg.range2)),
                0.0,
            ),
        ];
        let mut trial: Vec<TrialAction> = Vec::with_capacity(3);
        for (a, &(p, dur, u, v, travel)) in acts.iter().enumerate() {
            let model = &models[a];
            let mut angles = vec![0.0; i_n * n];
            for i in 0..i_n {
                let m = model.m[i].at(u, v);
                let w0 = model.w0[i].at(u, v);
                let row = &mut angles[i * n..(i + 1) * n];
                let mut per = vec![0.0; n];
                for j in 0..N_SOURCES {
                    let w = model.w[i * N_SOURCES + j].at(u, v);
                    weights[a].push(w);
                    for (t, pv) in per.iter_mut().enumerate() {
                        *pv += w * shifted[i * N_SOURCES + j][t];
                    }
                }
                let clean: Vec<f64> = (0..n)
                    .map(|t| w0 * (PI * t as f64 / n as f64).cos() + per[t])
                    .collect();
                let mean_c = clean.iter().sum::<f64>() / n as f64;
                let rms =
                    (clean.iter().map(|c| (c - mean_c).powi(2)).sum::<f64>() / n as f64).sqrt();
                for (t, o) in row.iter_mut().enumerate() {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    *o = m + clean[t] + cfg.noise * rms * e;
                }
                periodic[a].extend_from_slice(&per);
                means[a].push(m);
                w0s[a].push(w0);
            }
            let root = (0..n)
                .map(|t| travel * true_progress(t as f64 / n as f64))
                .collect();
            trial.push(TrialAction {
                angles,
                step_length: p,
                duration: dur,
                root,
            });
        }
        let [a0, a1, a2]: [TrialAction; 3] = trial
            .try_into()
            .map_err(|_| Error::Numerical("trial assembly".into()))?;
        trials.push([a0, a1, a2]);
    }
    let mk = |v: Vec<f64>| TrialSet {
        n_trials: r_n,
        n_channels: i_n,
        n_samples: n,
        data: v,
    };
    let [p0, p1, p2] = periodic;
    let truth = WalkerTruth {
        sources,
        delays,
        periodic: [mk(p0), mk(p1), mk(p2)],
        weights,
        means,
        w0: w0s,
    };
    Ok((
        Dataset {
            n_channels: i_n,
            n_samples: n,
            trials,
            distances,
        },
        truth,
    ))
}
