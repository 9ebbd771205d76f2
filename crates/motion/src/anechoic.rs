//! Anechoic demixing (paper eq. 1 without the non-periodic term, §2.3):
//!
//! ```text
//! x_i^r(t) ≈ Σ_{j=1..J} w_ij^r s_j(t − τ_ij)
//! ```
//!
//! with band-limited periodic sources, per-trial weights and delays that are shared across
//! trials (the paper's constraint, after CdEG13), free per trial (Omlor & Giese 2011) or zero
//! (the synchronous model). The fit is the Fourier-domain alternating least squares of
//! Chiovetto, d'Avella and Giese (FADA): in the DFT domain
//! `X_i^r(k) = Σ_j w_ij^r e^{−2πikτ_ij} c_jk` is linear in the source coefficients for fixed
//! weights and delays, and linear in the weights for fixed sources and delays; delays are
//! updated one at a time by maximising the exact least-squares gain, a trigonometric polynomial
//! in `τ`. Every step can only lower the residual, so `Q` never decreases.
//!
//! When the delays do not depend on the trial, the trials enter every step only through two
//! per-channel sums, `Σ_r w_rip w_riq` and `Σ_r w_rij x_ri` (`WeightStats`): the source step,
//! the delay step and the residual are then independent of the number of trials once these
//! are formed (once per sweep, in the weight step's pass).

use crate::data::TrialSet;
use crate::delay_search::ChannelDelays;
use crate::fourier::{
    delayed, harmonics_of_rows, phasors, re_dot, trig_argmax, wrap_half, PeriodicSource,
};
use crate::linalg::{solve_complex, solve_many_in_place};
use crate::orbit::orbit_sources;
use num_complex::Complex64;
use rand::Rng as _;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use wscg_math::{Error, Result};

/// How delays are constrained.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum DelayMode {
    /// One delay per (channel, source), equal over trials (the paper's model).
    Shared,
    /// One delay per (trial, channel, source) (the unconstrained anechoic model, OG11).
    PerTrial,
    /// All delays zero: the synchronous model with band-limited sources.
    Zero,
}

/// How a run is started.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Init {
    /// Sources from the top right singular vectors of the data, zero delays, least-squares
    /// weights (so the start is at least as good as PCA with the same number of components).
    Pca,
    /// Seeded random smooth sources and uniform random delays.
    Random,
    /// Sources added one at a time: each new source starts from the leading principal
    /// component of the current residual (delays 0), and the model with one more source is
    /// iterated before the next is added. The one-source problems have few poor optima, and each
    /// stage starts near a good fit of the previous one.
    Greedy,
    /// Sources and delays whose delayed copies span each channel's row space over the trials
    /// (see the `orbit` module): with delays shared over trials and trial-varying weights this
    /// lands next to the generating sources, where the ALS then converges. Needs delays,
    /// at least `J` trials and `J < 2K`; otherwise the run starts at random.
    Orbit,
}

wscg_math::params! {
    /// Parameters of [`fit_anechoic`] (defaults for paper 16: three periodic sources with delays
    /// shared over trials, as in its first action, §2.3; the rest are our choices).
    #[derive(Clone, Debug, PartialEq)]
    pub struct AnechoicParams {
        /// Number of periodic sources `J`.
        pub n_sources: usize,
        /// Harmonics `K` per source (band limit).
        pub n_harmonics: usize,
        /// Delay constraint.
        pub delays: DelayMode,
        /// Maximal number of ALS sweeps per run.
        pub max_iter: usize,
        /// Stop when one sweep changes `Q` by less than this.
        pub tol: f64,
        /// Number of runs; run 0 starts from [`Config::init`](AnechoicParams::init), run 1 from the
        /// orbit-subspace start ([`Init::Orbit`], where it applies and run 0 is not already one),
        /// the others from random starts. The best `Q` is kept.
        pub restarts: usize,
        /// Start of run 0.
        pub init: Init,
        /// Seed of the random starts.
        pub seed: u64,
        /// Sweeps every run gets before only the best one continues to `max_iter` (successive
        /// screening of the restarts; `max_iter` or more: every run goes the full length).
        pub screen_iter: usize,
        /// Grid points per period of the per-channel delay search run after the ALS, with shared
        /// delays and at least two sources ([`crate::delay_search`]; 0: off). Every channel's
        /// pairs of delays are searched on this grid with the sources held; channels where it
        /// finds a lower residual take the new delays and the ALS continues from there, so `Q`
        /// can only rise; repeated while channels move (at most 5 rounds). 0 or 8..=4096; 128.
        pub delay_search: usize,
    }
}

impl Default for AnechoicParams {
    fn default() -> Self {
        Self {
            n_sources: 3,
            n_harmonics: 8,
            delays: DelayMode::Shared,
            max_iter: 500,
            tol: 1e-9,
            restarts: 10,
            init: Init::Pca,
            seed: 0,
            screen_iter: 60,
            delay_search: 128,
        }
    }
}

impl AnechoicParams {
    /// Errors: `n_sources`, `n_harmonics`, `max_iter` or `restarts` zero, a `delay_search`
    /// grid other than 0 or 8..=4096 points, a negative or non-finite `tol`. The bounds that
    /// depend on the data (`n_harmonics < N/2`, `n_sources < min(I·R, N/2)`) are checked by
    /// [`fit_anechoic`].
    pub fn validate(&self) -> Result<()> {
        if self.n_sources == 0 {
            return Err(Error::invalid("n_sources", "must be >= 1, got 0"));
        }
        if self.n_harmonics == 0 {
            return Err(Error::invalid("n_harmonics", "must be >= 1, got 0"));
        }
        if self.max_iter == 0 {
            return Err(Error::invalid("max_iter", "must be >= 1"));
        }
        if self.restarts == 0 {
            return Err(Error::invalid("restarts", "must be >= 1"));
        }
        if self.delay_search != 0 && !(8..=4096).contains(&self.delay_search) {
            return Err(Error::invalid(
                "delay_search",
                format!(
                    "grid points per period must be 0 (off) or in 8..=4096, got {}",
                    self.delay_search
                ),
            ));
        }
        if !(self.tol.is_finite() && self.tol >= 0.0) {
            return Err(Error::invalid(
                "tol",
                format!("must be finite and >= 0, got {}", self.tol),
            ));
        }
        Ok(())
    }
}

/// A fitted anechoic model.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AnechoicModel {
    /// `R`.
    pub n_trials: usize,
    /// `I`.
    pub n_channels: usize,
    /// `N`.
    pub n_samples: usize,
    /// The `J` sources, each at unit RMS.
    pub sources: Vec<PeriodicSource>,
    /// Delay constraint of `delays`.
    pub delay_mode: DelayMode,
    /// Delays in periods, wrapped to `[-0.5, 0.5)`: `1 × I × J` for shared and zero delays,
    /// `R × I × J` per trial.
    pub delays: Vec<f64>,
    /// Weights, `R × I × J`.
    pub weights: Vec<f64>,
    /// Final quality `Q`.
    pub q: f64,
    /// `Q` at the start and after every sweep of the kept run (non-decreasing).
    pub q_history: Vec<f64>,
}

impl AnechoicModel {
    /// Number of sources `J`.
    pub fn n_sources(&self) -> usize {
        self.sources.len()
    }

    /// Delay of source `j` in channel `i` for trial `r` (periods).
    pub fn delay(&self, r: usize, i: usize, j: usize) -> f64 {
        let rr = if self.delay_mode == DelayMode::PerTrial {
            r
        } else {
            0
        };
        self.delays[(rr * self.n_channels + i) * self.sources.len() + j]
    }

    /// Weight of source `j` in channel `i` for trial `r`.
    pub fn weight(&self, r: usize, i: usize, j: usize) -> f64 {
        self.weights[(r * self.n_channels + i) * self.sources.len() + j]
    }

    /// The model's time-domain approximation of every trial.
    pub fn reconstruct(&self) -> TrialSet {
        let (r_n, i_n, n) = (self.n_trials, self.n_channels, self.n_samples);
        let k = self.sources.first().map_or(0, |s| s.n_harmonics());
        // e^{2πikm/N} for k = 1..=K (row per harmonic), m = 0..N.
        let basis: Vec<Complex64> = (1..=k)
            .flat_map(|h| {
                (0..n)
                    .map(move |m| Complex64::from_polar(1.0, TAU * ((h * m) % n) as f64 / n as f64))
            })
            .collect();
        let mut out = vec![0.0; r_n * i_n * n];
        out.par_chunks_mut(n).enumerate().for_each_init(
            || vec![Complex64::new(0.0, 0.0); 2 * k],
            |scratch, (ri, row)| {
                // The row's harmonics D_k = Σ_j w_j c_jk e^{−2πikτ_j}; then
                // x(t) = 2 Re Σ_k D_k e^{2πikt}.
                let (r, i) = (ri / i_n, ri % i_n);
                let (mixed, ph) = scratch.split_at_mut(k);
                mixed.fill(Complex64::new(0.0, 0.0));
                for (j, s) in self.sources.iter().enumerate() {
                    let w = self.weight(r, i, j);
                    phasors(self.delay(r, i, j), k, ph);
                    for ((d, &c), &p) in mixed.iter_mut().zip(&s.coeffs).zip(ph.iter()) {
                        *d += c * p * w;
                    }
                }
                for (d, e) in mixed.iter().zip(basis.chunks_exact(n.max(1))) {
                    for (v, z) in row.iter_mut().zip(e) {
                        *v += 2.0 * (d.re * z.re - d.im * z.im);
                    }
                }
            },
        );
        TrialSet {
            n_trials: r_n,
            n_channels: i_n,
            n_samples: n,
            data: out,
        }
    }
}

/// Validates the configuration against the data shape.
fn check_config(x: &TrialSet, cfg: &AnechoicParams) -> Result<()> {
    cfg.validate()?;
    let n = x.n_samples;
    if 2 * cfg.n_harmonics >= n {
        return Err(Error::invalid(
            "n_harmonics",
            format!(
                "must be in 1..{} (below N/2 for N = {n} samples), got {}",
                n.div_ceil(2),
                cfg.n_harmonics
            ),
        ));
    }
    let cap = (x.n_trials * x.n_channels).min(n / 2);
    if cfg.n_sources >= cap {
        return Err(Error::invalid(
            "n_sources",
            format!(
                "must be >= 1 and < min(I*R, N/2) = {cap}, got {}",
                cfg.n_sources
            ),
        ));
    }
    Ok(())
}

/// The data in the Fourier domain: harmonics `1..=K` of every row, plus the energy outside them.
struct Spectra {
    r: usize,
    i: usize,
    k: usize,
    n: usize,
    /// `R × I × K`.
    x: Vec<Complex64>,
    /// `‖X‖²_F`.
    total: f64,
    /// Energy of the data outside harmonics `±1..=K` (the mean included): no model can fit it.
    out_band: f64,
    /// `Σ |x_rik|²` over the in-band harmonics.
    in_band: f64,
}

impl Spectra {
    fn new(x: &TrialSet, k: usize) -> Result<Self> {
        let total = x.energy();
        if total <= 0.0 {
            return Err(Error::invalid("x", "all values are zero; nothing to demix"));
        }
        let n = x.n_samples;
        let xs = harmonics_of_rows(&x.data, n, k);
        let in_band: f64 = xs.iter().map(|c| c.norm_sqr()).sum();
        Ok(Self {
            r: x.n_trials,
            i: x.n_channels,
            k,
            n,
            x: xs,
            total,
            out_band: (total - 2.0 * n as f64 * in_band).max(0.0),
            in_band,
        })
    }

    /// `Q = 1 − ‖X − X̂‖²_F / ‖X‖²_F` from the squared residual of the in-band harmonics
    /// `1..=K` (Parseval: the error is that times `2N` plus the out-of-band energy).
    fn quality_of(&self, in_band: f64) -> f64 {
        1.0 - (self.out_band + 2.0 * self.n as f64 * in_band) / self.total
    }

    fn row(&self, r: usize, i: usize) -> &[Complex64] {
        let o = (r * self.i + i) * self.k;
        &self.x[o..o + self.k]
    }
}

/// Adds one row's weights `w` (`J`) and harmonics `x` (`K`) to a channel's
/// [`WeightStats`]: `w w^T` to `g` (`J × J`) and `w_j x` to row `j` of `acc` (`J × K`).
fn accumulate_stats(w: &[f64], x: &[Complex64], g: &mut [f64], acc: &mut [Complex64]) {
    let k = x.len();
    for ((gp, ap), &wp) in g
        .chunks_exact_mut(w.len())
        .zip(acc.chunks_exact_mut(k))
        .zip(w)
    {
        gp.iter_mut().zip(w).for_each(|(v, &wq)| *v += wp * wq);
        ap.iter_mut().zip(x).for_each(|(v, &xv)| *v += xv * wp);
    }
}

/// A channel's share of the squared in-band residual beyond its data energy `Σ_rk |x_rik|²`,
/// from its [`WeightStats`] (`g`: `J × J`, `wx`: `J × K`) and delayed sources `d` (`J × K`):
/// `−2 Σ_j Re ⟨wx_j, d_j⟩ + Σ_pq g_pq Re ⟨d_p, d_q⟩`.
fn channel_fit(g: &[f64], wx: &[Complex64], d: &[Complex64], k: usize) -> f64 {
    let j_n = d.len() / k;
    let mut model = 0.0;
    for p in 0..j_n {
        let dp = &d[p * k..(p + 1) * k];
        model += g[p * j_n + p] * re_dot(dp, dp);
        for q in p + 1..j_n {
            model += 2.0 * g[p * j_n + q] * re_dot(dp, &d[q * k..(q + 1) * k]);
        }
    }
    model - 2.0 * re_dot(wx, d)
}

/// Step (c) for one source: the delay maximising `F(τ) = Re Σ_k g_k c_k e^{−2πikτ}`, where
/// `g = Σ_r w_r conj(E_r)` collects the residuals `E_r` with the source added back (so the
/// least-squares optimum over `τ`), kept only when it beats `F` at the current delay `old`,
/// whose delayed source is `p_old`. `g` is overwritten.
fn best_delay(g: &mut [Complex64], c: &[Complex64], p_old: &[Complex64], old: f64) -> f64 {
    let f_old: f64 = g.iter().zip(p_old).map(|(a, b)| (a * b).re).sum();
    g.iter_mut().zip(c).for_each(|(v, &cv)| *v *= cv);
    let (cand, f_new) = trig_argmax(g);
    if f_new > f_old + 1e-15 * f_old.abs().max(1.0) {
        wrap_half(cand)
    } else {
        old
    }
}

/// Per-channel statistics of the weights, for delays that do not depend on the trial: the
/// weight Gram matrices `Σ_r w_rip w_riq` (`I × J × J`) and the weighted data
/// `Σ_r w_rij x_rik` (`I × J × K`). With them the source step and the quality of a state
/// need no pass over the trials.
struct WeightStats {
    gram: Vec<f64>,
    wx: Vec<Complex64>,
}

/// The state of one ALS run.
#[derive(Clone)]
struct State {
    j: usize,
    mode: DelayMode,
    /// `J × K` source coefficients.
    c: Vec<Complex64>,
    /// `Rd × I × J`.
    tau: Vec<f64>,
    /// `R × I × J`.
    w: Vec<f64>,
}

impl State {
    fn rd(&self, r: usize) -> usize {
        if self.mode == DelayMode::PerTrial {
            r
        } else {
            0
        }
    }

    /// `Rd × I × J × K` table of delay phasors.
    fn phase_table(&self, sp: &Spectra) -> Vec<Complex64> {
        let k = sp.k;
        let mut t = vec![Complex64::new(0.0, 0.0); self.tau.len() * k];
        for (d, chunk) in t.chunks_mut(k).enumerate() {
            phasors(self.tau[d], k, chunk);
        }
        t
    }

    /// `Rd × I × J × K` table of the delayed sources `e^{−2πikτ_ij} c_jk`.
    fn delayed_table(&self, sp: &Spectra) -> Vec<Complex64> {
        self.delay_sources(self.phase_table(sp), sp.k)
    }

    /// The [`State::delayed_table`] from this state's [`State::phase_table`] `t`.
    fn delay_sources(&self, mut t: Vec<Complex64>, k: usize) -> Vec<Complex64> {
        for (row, c) in t.chunks_mut(k).zip(self.c.chunks_exact(k).cycle()) {
            for (v, &cv) in row.iter_mut().zip(c) {
                *v *= cv;
            }
        }
        t
    }

    /// Residual harmonics `x_ri − Σ_j w_j e^{−2πikτ_ij} c_j` of trial `r`, channel `i`, written
    /// into `e` (length `K`), for the row's weights `w` (`J`) and the [`State::delayed_table`]
    /// `d`.
    fn residual_row(
        &self,
        sp: &Spectra,
        d: &[Complex64],
        w: &[f64],
        r: usize,
        i: usize,
        e: &mut [Complex64],
    ) {
        let (j_n, k) = (self.j, sp.k);
        e.copy_from_slice(sp.row(r, i));
        let d = &d[(self.rd(r) * sp.i + i) * j_n * k..][..j_n * k];
        for (&wj, dj) in w.iter().zip(d.chunks_exact(k)) {
            for (ev, &v) in e.iter_mut().zip(dj) {
                *ev -= v * wj;
            }
        }
    }

    /// The squared residual `Σ |X_rik − X̂_rik|²` of the in-band harmonics, row by row.
    fn in_band_residual(&self, sp: &Spectra) -> f64 {
        let ph = self.delayed_table(sp);
        (0..sp.r * sp.i)
            .into_par_iter()
            .map_init(
                || vec![Complex64::new(0.0, 0.0); sp.k],
                |e, ri| {
                    let (r, i) = (ri / sp.i, ri % sp.i);
                    let w = &self.w[ri * self.j..(ri + 1) * self.j];
                    self.residual_row(sp, &ph, w, r, i, e);
                    e.iter().map(|v| v.norm_sqr()).sum::<f64>()
                },
            )
            .sum()
    }

    /// `Q` of this state, with what a source step from it can reuse: its
    /// [`State::phase_table`] and, for delays shared over trials, its [`WeightStats`].
    fn assess(&self, sp: &Spectra) -> (f64, Vec<Complex64>, Option<WeightStats>) {
        let ph = self.phase_table(sp);
        if self.mode == DelayMode::PerTrial {
            return (sp.quality_of(self.in_band_residual(sp)), ph, None);
        }
        let st = self.weight_stats(sp);
        let e = self.shared_residual(sp, &self.delay_sources(ph.clone(), sp.k), &st);
        (sp.quality_of(e), ph, Some(st))
    }

    /// The [`WeightStats`] of this state's weights (delays shared over trials).
    fn weight_stats(&self, sp: &Spectra) -> WeightStats {
        let (j_n, k, i_n) = (self.j, sp.k, sp.i);
        let mut gram = vec![0.0; i_n * j_n * j_n];
        let mut wx = vec![Complex64::new(0.0, 0.0); i_n * j_n * k];
        gram.par_chunks_mut(j_n * j_n)
            .zip(wx.par_chunks_mut(j_n * k))
            .enumerate()
            .for_each(|(i, (g, acc))| {
                for r in 0..sp.r {
                    let w = &self.w[(r * i_n + i) * j_n..][..j_n];
                    accumulate_stats(w, sp.row(r, i), g, acc);
                }
            });
        WeightStats { gram, wx }
    }

    /// The squared in-band residual from the [`WeightStats`] `st` (delays shared over trials)
    /// and the [`State::delayed_table`] `dt` (`d_ij = e^{−2πikτ_ij} c_j`):
    /// `Σ_rik |x_rik|² − 2 Σ_ij Re ⟨Σ_r w_rij x_ri, d_ij⟩ + Σ_i Σ_pq (Σ_r w_rip w_riq) Re ⟨d_ip, d_iq⟩`.
    fn shared_residual(&self, sp: &Spectra, dt: &[Complex64], st: &WeightStats) -> f64 {
        let (j_n, k) = (self.j, sp.k);
        let fit: f64 = dt
            .chunks_exact(j_n * k)
            .zip(st.gram.chunks_exact(j_n * j_n))
            .zip(st.wx.chunks_exact(j_n * k))
            .map(|((d, g), wx)| channel_fit(g, wx, d, k))
            .sum();
        (sp.in_band + fit).max(0.0)
    }

    /// Step (a): for each harmonic, the complex `J × J` normal equations over all rows.
    ///
    /// With `a_j = w_rij e^{−2πikτ_ij}` the row's regressors, `H = Σ_ri a^H a` and
    /// `rhs = Σ_ri a^H x_rik`. When the delays do not depend on the trial, the sums over trials
    /// factor out of the phasors: `H_pq = Σ_i conj(p_ip) p_iq Σ_r w_rip w_riq` and
    /// `rhs_p = Σ_i conj(p_ip) Σ_r w_rip x_rik`, so only the per-channel [`WeightStats`]
    /// enter (`stats`, computed here when `None`).
    /// `ph` is the state's [`State::phase_table`].
    fn update_sources(
        &mut self,
        sp: &Spectra,
        ph: &[Complex64],
        stats: Option<&WeightStats>,
    ) -> Result<()> {
        let (j_n, k) = (self.j, sp.k);
        // Shared delays: all harmonics' systems at once from the statistics.
        let factored = (self.mode != DelayMode::PerTrial).then(|| match stats {
            Some(st) => self.shared_normal_equations(sp, ph, st),
            None => self.shared_normal_equations(sp, ph, &self.weight_stats(sp)),
        });
        // One small solve per harmonic. Even when each is only a few hundred multiply-adds,
        // running them in parallel keeps the pool's other thread awake for the weight step
        // that follows (measured 2-3 % faster per fit than one thread doing them all).
        let cols: Vec<Vec<Complex64>> = (0..k)
            .into_par_iter()
            .map(|kk| {
                let (h, rhs) = match &factored {
                    None => self.per_trial_normal_equations(sp, ph, kk),
                    Some((hs, rs)) => {
                        let h = (0..j_n * j_n)
                            .map(|pq| {
                                let (p, q) = (pq / j_n, pq % j_n);
                                if q >= p {
                                    hs[pq * k + kk]
                                } else {
                                    hs[(q * j_n + p) * k + kk].conj()
                                }
                            })
                            .collect();
                        (h, (0..j_n).map(|p| rs[p * k + kk]).collect())
                    }
                };
                solve_complex(&h, &rhs, j_n, 1e-12)
            })
            .collect::<Result<_>>()?;
        for (kk, col) in cols.iter().enumerate() {
            for (j, v) in col.iter().enumerate() {
                self.c[j * k + kk] = *v;
            }
        }
        Ok(())
    }

    /// The factored normal equations of step (a) for all harmonics at once, harmonic-minor
    /// so that the sums over channels run along contiguous phasor rows: the upper triangle
    /// of `H` (`J × J × K`) and `rhs` (`J × K`).
    fn shared_normal_equations(
        &self,
        sp: &Spectra,
        ph: &[Complex64],
        st: &WeightStats,
    ) -> (Vec<Complex64>, Vec<Complex64>) {
        let (j_n, k) = (self.j, sp.k);
        let zero = Complex64::new(0.0, 0.0);
        let mut hs = vec![zero; j_n * j_n * k];
        let mut rs = vec![zero; j_n * k];
        for ((p_i, g), wx) in ph
            .chunks_exact(j_n * k)
            .zip(st.gram.chunks_exact(j_n * j_n))
            .zip(st.wx.chunks_exact(j_n * k))
        {
            for p in 0..j_n {
                let pp = &p_i[p * k..(p + 1) * k];
                let rp = &mut rs[p * k..(p + 1) * k];
                for ((r, &a), &b) in rp.iter_mut().zip(pp).zip(&wx[p * k..(p + 1) * k]) {
                    *r += a.conj() * b;
                }
                for q in p..j_n {
                    let gpq = g[p * j_n + q];
                    let hpq = &mut hs[(p * j_n + q) * k..][..k];
                    for ((h, &a), &b) in hpq.iter_mut().zip(pp).zip(&p_i[q * k..(q + 1) * k]) {
                        *h += a.conj() * b * gpq;
                    }
                }
            }
        }
        (hs, rs)
    }

    /// The normal equations of step (a) for harmonic `kk`, row by row (delays per trial):
    /// `H` (`J × J`, Hermitian) and `rhs` (`J`).
    fn per_trial_normal_equations(
        &self,
        sp: &Spectra,
        ph: &[Complex64],
        kk: usize,
    ) -> (Vec<Complex64>, Vec<Complex64>) {
        let (j_n, k, i_n) = (self.j, sp.k, sp.i);
        let zero = Complex64::new(0.0, 0.0);
        let mut h = vec![zero; j_n * j_n];
        let mut rhs = vec![zero; j_n];
        let mut a = vec![zero; j_n];
        for r in 0..sp.r {
            for i in 0..i_n {
                let w = &self.w[(r * i_n + i) * j_n..][..j_n];
                let p = &ph[(r * i_n + i) * j_n * k + kk..];
                for (j, (aj, &wj)) in a.iter_mut().zip(w).enumerate() {
                    *aj = wj * p[j * k];
                }
                let xv = sp.row(r, i)[kk];
                for pi in 0..j_n {
                    let apc = a[pi].conj();
                    rhs[pi] += apc * xv;
                    for q in pi..j_n {
                        h[pi * j_n + q] += apc * a[q];
                    }
                }
            }
        }
        // H is Hermitian: only the upper triangle was accumulated.
        for pi in 0..j_n {
            for q in 0..pi {
                h[pi * j_n + q] = h[q * j_n + pi].conj();
            }
        }
        (h, rhs)
    }

    /// Step (b): for each (trial, channel), the real `J × J` least squares of the weights.
    /// `dt` is the state's [`State::delayed_table`].
    fn update_weights(&mut self, sp: &Spectra, dt: &[Complex64]) -> Result<()> {
        let (j_n, r_n) = (self.j, sp.r);
        let mut per_channel = vec![0.0; sp.i * r_n * j_n];
        per_channel
            .par_chunks_mut(r_n * j_n)
            .enumerate()
            .try_for_each_init(
                || vec![0.0; j_n * j_n],
                |g, (i, w)| self.channel_weights(sp, dt, i, w, g),
            )?;
        self.scatter_weights(sp, &per_channel);
        Ok(())
    }

    /// Steps (b) and (c) in one pass over the channels (each channel's delays need only its
    /// own new weights). Returns the squared residual of the in-band harmonics after the
    /// step (what [`State::in_band_residual`] would sum), or `None` with zero delays (weights
    /// only), and for shared delays the [`WeightStats`] of the new weights.
    /// `dt` is the state's [`State::delayed_table`].
    fn update_weights_and_delays(
        &mut self,
        sp: &Spectra,
        dt: &[Complex64],
    ) -> Result<(Option<f64>, Option<WeightStats>)> {
        if self.mode == DelayMode::Zero {
            self.update_weights(sp, dt)?;
            return Ok((None, None));
        }
        let (j_n, k, r_n, i_n) = (self.j, sp.k, sp.r, sp.i);
        let shared = self.mode == DelayMode::Shared;
        let n_groups = n_delay_rows(self.mode, r_n);
        // Per channel: weights (R × J), delays (Rd × J), the squared residual and, for shared
        // delays, the weight statistics.
        let mut new_w = vec![0.0; i_n * r_n * j_n];
        let mut new_tau = vec![0.0; i_n * n_groups * j_n];
        let mut residuals = vec![0.0; i_n];
        let zero = Complex64::new(0.0, 0.0);
        let mut stats = WeightStats {
            gram: vec![0.0; i_n * j_n * j_n],
            wx: vec![zero; i_n * j_n * k],
        };
        new_w
            .par_chunks_mut(r_n * j_n)
            .zip(new_tau.par_chunks_mut(n_groups * j_n))
            .zip(residuals.par_iter_mut())
            .zip(stats.gram.par_chunks_mut(j_n * j_n))
            .zip(stats.wx.par_chunks_mut(j_n * k))
            .enumerate()
            .try_for_each_init(
                || (vec![0.0; j_n * j_n], vec![zero; (r_n.max(j_n) + 2) * k]),
                |(g, scratch), (i, ((((w, taus), residual), gram), wx))| {
                    self.channel_weights(sp, dt, i, w, g)?;
                    *residual = if shared {
                        for (r, wr) in w.chunks_exact(j_n).enumerate() {
                            accumulate_stats(wr, sp.row(r, i), gram, wx);
                        }
                        self.channel_delays_shared(sp, dt, i, (gram, wx), taus, scratch)
                    } else {
                        self.channel_delays(sp, dt, i, w, taus, scratch)
                    };
                    Ok::<_, Error>(())
                },
            )?;
        self.scatter_weights(sp, &new_w);
        for (i, taus) in new_tau.chunks_exact(n_groups * j_n).enumerate() {
            for (rd, t) in taus.chunks_exact(j_n).enumerate() {
                self.tau[(rd * i_n + i) * j_n..][..j_n].copy_from_slice(t);
            }
        }
        let residual = if shared {
            // Each channel reported its fit term: add the data energy.
            (sp.in_band + residuals.iter().sum::<f64>()).max(0.0)
        } else {
            residuals.iter().sum()
        };
        Ok((Some(residual), shared.then_some(stats)))
    }

    /// Writes per-channel weights (`I × R × J`) into the state's `R × I × J` layout.
    fn scatter_weights(&mut self, sp: &Spectra, per_channel: &[f64]) {
        let j_n = self.j;
        for (i, w) in per_channel.chunks_exact(sp.r * j_n).enumerate() {
            for (r, wr) in w.chunks_exact(j_n).enumerate() {
                self.w[(r * sp.i + i) * j_n..][..j_n].copy_from_slice(wr);
            }
        }
    }

    /// Step (b) for channel `i`: its `R × J` weights (trial-major) into `w`. The normal matrix
    /// depends only on the channel's delayed sources, so trials sharing delays share one
    /// elimination. `g` is `J × J` scratch.
    fn channel_weights(
        &self,
        sp: &Spectra,
        dt: &[Complex64],
        i: usize,
        w: &mut [f64],
        g: &mut [f64],
    ) -> Result<()> {
        let (j_n, k, r_n, i_n) = (self.j, sp.k, sp.r, sp.i);
        // Trials sharing a delay row: one group, or one per trial.
        let size = r_n / n_delay_rows(self.mode, r_n);
        for (gi, wg) in w.chunks_exact_mut(size * j_n).enumerate() {
            // b_j = e^{−2πikτ_ij} c_j: source j as it appears in this group's rows.
            let b = &dt[(gi * i_n + i) * j_n * k..][..j_n * k];
            for p in 0..j_n {
                let bp = &b[p * k..(p + 1) * k];
                for q in p..j_n {
                    let v = re_dot(bp, &b[q * k..(q + 1) * k]);
                    g[p * j_n + q] = v;
                    g[q * j_n + p] = v;
                }
            }
            for (t, h) in wg.chunks_exact_mut(j_n).enumerate() {
                let xr = sp.row(gi * size + t, i);
                for (hp, bp) in h.iter_mut().zip(b.chunks_exact(k)) {
                    *hp = re_dot(xr, bp);
                }
            }
            solve_many_in_place(g, wg, j_n, 1e-12)?;
        }
        Ok(())
    }

    /// Step (c) for channel `i` with its weights `w` (`R × J`, trial-major): coordinate-wise
    /// delay updates, each the exact least-squares optimum over `τ` with the other delays
    /// fixed, accepted only when it lowers the residual. Writes the channel's `Rd × J` delays
    /// into `taus` and returns its squared in-band residual after the step. `scratch` holds
    /// `(R + 2) K` values.
    fn channel_delays(
        &self,
        sp: &Spectra,
        dt: &[Complex64],
        i: usize,
        w: &[f64],
        taus: &mut [f64],
        scratch: &mut [Complex64],
    ) -> f64 {
        let (j_n, k, r_n, i_n) = (self.j, sp.k, sp.r, sp.i);
        let per_trial = self.mode == DelayMode::PerTrial;
        let zero = Complex64::new(0.0, 0.0);
        let (res, rest) = scratch.split_at_mut(r_n * k);
        let (p, g) = rest.split_at_mut(k);
        for (r, e) in res.chunks_exact_mut(k).enumerate() {
            self.residual_row(sp, dt, &w[r * j_n..(r + 1) * j_n], r, i, e);
        }
        for (rd, t) in taus.chunks_exact_mut(j_n).enumerate() {
            t.copy_from_slice(&self.tau[(rd * i_n + i) * j_n..][..j_n]);
        }
        // Trial groups sharing a delay: one per trial, or all trials together.
        let group = |gi: usize| {
            if per_trial {
                gi..gi + 1
            } else {
                0..r_n
            }
        };
        for j in 0..j_n {
            let c = &self.c[j * k..(j + 1) * k];
            for gi in 0..n_delay_rows(self.mode, r_n) {
                let slot = gi * j_n + j;
                let old = taus[slot];
                // e^{-2πikτ} c at the current delay: the delayed-source table's row.
                let p_old = &dt[((gi * i_n + i) * j_n + j) * k..][..k];
                // Add source j back into the residual, E = res + w p, and collect
                // Σ_r w conj(E).
                g.fill(zero);
                for r in group(gi) {
                    let wj = w[r * j_n + j];
                    let e = &mut res[r * k..(r + 1) * k];
                    for ((ev, &pv), gv) in e.iter_mut().zip(p_old).zip(g.iter_mut()) {
                        *ev += pv * wj;
                        *gv += ev.conj() * wj;
                    }
                }
                let tau = best_delay(g, c, p_old, old);
                taus[slot] = tau;
                if tau == old {
                    p.copy_from_slice(p_old);
                } else {
                    delayed(tau, c, p);
                }
                for r in group(gi) {
                    let wj = w[r * j_n + j];
                    let e = &mut res[r * k..(r + 1) * k];
                    for (ev, &pv) in e.iter_mut().zip(p.iter()) {
                        *ev -= pv * wj;
                    }
                }
            }
        }
        res.iter().map(|v| v.norm_sqr()).sum::<f64>()
    }

    /// [`State::channel_delays`] for delays shared over trials, from the channel's
    /// [`WeightStats`] (`gram`, `wx`) instead of its rows: with source `j` added back,
    /// `Σ_r w_rj E_r = wx_j − Σ_{q≠j} gram_jq d_q`. Writes the channel's `J` delays into `taus`
    /// and returns its [`channel_fit`] after the step. `scratch` holds `(J + 1) K` values.
    fn channel_delays_shared(
        &self,
        sp: &Spectra,
        dt: &[Complex64],
        i: usize,
        (gram, wx): (&[f64], &[Complex64]),
        taus: &mut [f64],
        scratch: &mut [Complex64],
    ) -> f64 {
        let (j_n, k) = (self.j, sp.k);
        let (d, rest) = scratch.split_at_mut(j_n * k);
        let g = &mut rest[..k];
        d.copy_from_slice(&dt[i * j_n * k..(i + 1) * j_n * k]);
        taus.copy_from_slice(&self.tau[i * j_n..(i + 1) * j_n]);
        for j in 0..j_n {
            g.copy_from_slice(&wx[j * k..(j + 1) * k]);
            for q in (0..j_n).filter(|&q| q != j) {
                let gjq = gram[j * j_n + q];
                for (gv, &dv) in g.iter_mut().zip(&d[q * k..(q + 1) * k]) {
                    *gv -= dv * gjq;
                }
            }
            g.iter_mut().for_each(|v| *v = v.conj());
            let c = &self.c[j * k..(j + 1) * k];
            let dj = &mut d[j * k..(j + 1) * k];
            let old = taus[j];
            let tau = best_delay(g, c, dj, old);
            if tau != old {
                taus[j] = tau;
                delayed(tau, c, dj);
            }
        }
        channel_fit(gram, wx, d, k)
    }

    /// Gauge fixing (the model is unchanged): unit-RMS sources, positive weight sums, and each
    /// source shifted so that the |w|-weighted circular mean of its delays is zero.
    /// `stats`, the [`WeightStats`] of the weights, are rescaled with them.
    fn normalize(&mut self, sp: &Spectra, mut stats: Option<&mut WeightStats>) {
        let (j_n, k, r_n, i_n) = (self.j, sp.k, sp.r, sp.i);
        for j in 0..j_n {
            let c = &mut self.c[j * k..(j + 1) * k];
            let rms = (2.0 * c.iter().map(|v| v.norm_sqr()).sum::<f64>()).sqrt();
            if rms <= 0.0 || !rms.is_finite() {
                continue;
            }
            let sum: f64 = (0..r_n * i_n).map(|ri| self.w[ri * j_n + j]).sum();
            let scale = if sum < 0.0 { -rms } else { rms };
            c.iter_mut().for_each(|v| *v /= scale);
            for ri in 0..r_n * i_n {
                self.w[ri * j_n + j] *= scale;
            }
            if let Some(st) = stats.as_deref_mut() {
                // Row and column j of every Gram matrix, row j of the weighted data.
                for g in st.gram.chunks_exact_mut(j_n * j_n) {
                    g[j * j_n..(j + 1) * j_n]
                        .iter_mut()
                        .for_each(|v| *v *= scale);
                    g.iter_mut().skip(j).step_by(j_n).for_each(|v| *v *= scale);
                }
                for acc in st.wx.chunks_exact_mut(j_n * k) {
                    acc[j * k..(j + 1) * k].iter_mut().for_each(|v| *v *= scale);
                }
            }
            if self.mode == DelayMode::Zero {
                continue;
            }
            let rd_n = self.tau.len() / (i_n * j_n);
            let mut acc = Complex64::new(0.0, 0.0);
            for rd in 0..rd_n {
                for i in 0..i_n {
                    let a: f64 = if rd_n == 1 {
                        (0..r_n)
                            .map(|r| self.w[(r * i_n + i) * j_n + j].abs())
                            .sum()
                    } else {
                        self.w[(rd * i_n + i) * j_n + j].abs()
                    };
                    acc += Complex64::from_polar(a, TAU * self.tau[(rd * i_n + i) * j_n + j]);
                }
            }
            if acc.norm() <= 0.0 {
                continue;
            }
            let mu = acc.arg() / TAU;
            let shifted = PeriodicSource::new(c.to_vec()).shifted(mu);
            c.copy_from_slice(&shifted.coeffs);
            for rd in 0..rd_n {
                for i in 0..i_n {
                    let t = &mut self.tau[(rd * i_n + i) * j_n + j];
                    *t = wrap_half(*t - mu);
                }
            }
        }
    }

    /// `self + step · (self − prev)` in every parameter (delays along the shorter arc).
    fn extrapolate(&self, prev: &State, step: f64) -> State {
        let mut out = self.clone();
        for (o, (a, b)) in out.c.iter_mut().zip(self.c.iter().zip(&prev.c)) {
            *o = a + (a - b) * step;
        }
        for (o, (a, b)) in out.w.iter_mut().zip(self.w.iter().zip(&prev.w)) {
            *o = a + (a - b) * step;
        }
        if self.mode != DelayMode::Zero {
            for (o, (a, b)) in out.tau.iter_mut().zip(self.tau.iter().zip(&prev.tau)) {
                *o = wrap_half(a + wrap_half(a - b) * step);
            }
        }
        out
    }

    fn into_model(self, sp: &Spectra, q: f64, q_history: Vec<f64>) -> AnechoicModel {
        let k = sp.k;
        AnechoicModel {
            n_trials: sp.r,
            n_channels: sp.i,
            n_samples: sp.n,
            sources: (0..self.j)
                .map(|j| PeriodicSource::new(self.c[j * k..(j + 1) * k].to_vec()))
                .collect(),
            delay_mode: self.mode,
            delays: self.tau,
            weights: self.w,
            q,
            q_history,
        }
    }
}

/// Iterates ALS sweeps from `state` until `Q` changes by less than `tol`.
///
/// After every sweep the step from the previous iterate is extrapolated by a factor
/// `it^{1/3}` (the line search of Bro's ALS acceleration) and the extrapolated point is kept
/// only when it fits better, so `Q` stays non-decreasing while the slow "swamps" of plain ALS
/// are crossed in far fewer sweeps.
fn run(sp: &Spectra, cfg: &AnechoicParams, mut state: State) -> Result<(State, f64, Vec<f64>)> {
    let (mut q, mut ph, mut stats) = state.assess(sp);
    let mut hist = vec![q];
    for it in 0..cfg.max_iter {
        wscg_math::cancel::check()?;
        let before = state.clone();
        state.update_sources(sp, &ph, stats.as_ref())?;
        // The sources change the delayed-source table; the weights do not, so the weight and
        // delay steps share one.
        let dt = state.delay_sources(ph, sp.k);
        // The delay step leaves the residual and the new weights' statistics at hand; gauge
        // fixing does not change the model.
        let in_band;
        (in_band, stats) = state.update_weights_and_delays(sp, &dt)?;
        state.normalize(sp, stats.as_mut());
        // The next source step needs the phase table and statistics of the state it starts
        // from: the zero-delay weight step leaves them to `assess`, an accepted extrapolation
        // brings its own.
        let mut next_ph = None;
        let mut qn = match in_band {
            Some(e) => sp.quality_of(e),
            None => {
                let (q0, ph0, st0) = state.assess(sp);
                (next_ph, stats) = (Some(ph0), st0);
                q0
            }
        };
        if it >= 1 {
            let cand = state.extrapolate(&before, ((it + 1) as f64).cbrt());
            let (qc, ph_c, stats_c) = cand.assess(sp);
            if qc > qn {
                state = cand;
                qn = qc;
                (next_ph, stats) = (Some(ph_c), stats_c);
            }
        }
        ph = next_ph.unwrap_or_else(|| state.phase_table(sp));
        hist.push(qn);
        let done = (qn - q).abs() < cfg.tol;
        q = qn;
        if done {
            break;
        }
    }
    Ok((state, q, hist))
}

fn n_delay_rows(mode: DelayMode, r: usize) -> usize {
    if mode == DelayMode::PerTrial {
        r
    } else {
        1
    }
}

/// PCA start: the top-`J` right singular vectors of the `(R·I) × N` data as sources, taken
/// as the leading eigenvectors of the `N × N` Gram matrix (a few of them, not a full SVD).
fn pca_start(x: &TrialSet, sp: &Spectra, cfg: &AnechoicParams) -> Result<State> {
    let rows = x.n_trials * x.n_channels;
    let n = x.n_samples;
    let gram = wscg_math::dense::gram(
        wscg_math::dense::from_row_major(&x.data, rows, n).as_ref(),
        1.0,
    );
    let j_n = cfg.n_sources;
    let e = wscg_math::dense::eigh_largest(gram.as_ref(), j_n)?;
    let v: Vec<f64> = (0..j_n)
        .flat_map(|j| (0..n).map(move |m| (m, j)))
        .map(|(m, j)| e.vectors[(m, j)])
        .collect();
    let c = harmonics_of_rows(&v, n, sp.k);
    start_from(
        sp,
        cfg,
        c,
        vec![0.0; n_delay_rows(cfg.delays, sp.r) * sp.i * j_n],
    )
}

/// Greedy start (see [`Init::Greedy`]).
fn greedy_start(x: &TrialSet, sp: &Spectra, cfg: &AnechoicParams) -> Result<State> {
    let nd = n_delay_rows(cfg.delays, sp.r) * sp.i;
    let mut state: Option<State> = None;
    for j in 1..=cfg.n_sources {
        let residual = match &state {
            None => x.clone(),
            Some(s) => {
                let model = s.clone().into_model(sp, 0.0, Vec::new()).reconstruct();
                let mut r = x.clone();
                r.data
                    .iter_mut()
                    .zip(&model.data)
                    .for_each(|(a, b)| *a -= b);
                r
            }
        };
        let lead = pca_start(
            &residual,
            sp,
            &AnechoicParams {
                n_sources: 1,
                ..cfg.clone()
            },
        )?;
        let (mut c, mut tau) = match &state {
            None => (Vec::new(), vec![0.0; 0]),
            Some(s) => (s.c.clone(), s.tau.clone()),
        };
        c.extend_from_slice(&lead.c);
        // Delays `Rd × I × (j − 1)` widened to `Rd × I × j` with the new source at 0.
        let old_j = j - 1;
        let mut t = Vec::with_capacity(nd * j);
        for d in 0..nd {
            t.extend_from_slice(&tau[d * old_j..(d + 1) * old_j]);
            t.push(0.0);
        }
        tau = t;
        let stage_cfg = AnechoicParams {
            n_sources: j,
            ..cfg.clone()
        };
        let start = start_from(sp, &stage_cfg, c, tau)?;
        let (s, _, _) = run(
            sp,
            &AnechoicParams {
                max_iter: cfg.max_iter.min(100),
                ..stage_cfg
            },
            start,
        )?;
        state = Some(s);
    }
    state.ok_or_else(|| Error::invalid("n_sources", "must be >= 1"))
}

/// Orbit-subspace start (see [`Init::Orbit`]): the sources and shared delays of
/// [`crate::orbit::orbit_sources`], the same delays for every trial in per-trial mode, and
/// least-squares weights.
fn orbit_start(sp: &Spectra, cfg: &AnechoicParams) -> Result<State> {
    let rows = |r: usize, i: usize| sp.row(r, i);
    let (c, shared) = orbit_sources(&rows, (sp.r, sp.i, sp.k), cfg.n_sources, cfg.seed)?;
    let nd = n_delay_rows(cfg.delays, sp.r);
    let tau = (0..nd).flat_map(|_| shared.iter().copied()).collect();
    start_from(sp, cfg, c, tau)
}

/// Whether [`Init::Orbit`] applies: delays (shared or per trial), at least `J` trials, and
/// `J < 2K`.
fn orbit_applies(sp: &Spectra, cfg: &AnechoicParams) -> bool {
    cfg.delays != DelayMode::Zero && sp.r >= cfg.n_sources && cfg.n_sources < 2 * sp.k
}

/// Random start: smooth random sources (coefficients ∝ 1/k) and uniform delays.
fn random_start(sp: &Spectra, cfg: &AnechoicParams, stream: u64) -> Result<State> {
    let mut rng = wscg_math::rng::stream(cfg.seed, stream);
    let j_n = cfg.n_sources;
    let mut c = Vec::with_capacity(j_n * sp.k);
    for _ in 0..j_n {
        for kk in 0..sp.k {
            let re: f64 = StandardNormal.sample(&mut rng);
            let im: f64 = StandardNormal.sample(&mut rng);
            c.push(Complex64::new(re, im) / (kk + 1) as f64);
        }
    }
    let nd = n_delay_rows(cfg.delays, sp.r) * sp.i * j_n;
    let tau = if cfg.delays == DelayMode::Zero {
        vec![0.0; nd]
    } else {
        let shared: Vec<f64> = (0..sp.i * j_n).map(|_| rng.random::<f64>() - 0.5).collect();
        (0..nd).map(|d| shared[d % (sp.i * j_n)]).collect()
    };
    start_from(sp, cfg, c, tau)
}

fn start_from(
    sp: &Spectra,
    cfg: &AnechoicParams,
    c: Vec<Complex64>,
    tau: Vec<f64>,
) -> Result<State> {
    let mut s = State {
        j: cfg.n_sources,
        mode: cfg.delays,
        c,
        tau,
        w: vec![1.0; sp.r * sp.i * cfg.n_sources],
    };
    s.update_weights(sp, &s.delayed_table(sp))?;
    s.normalize(sp, None);
    Ok(s)
}

/// Fits the anechoic model to mean-free data `x` (`R × I × N`, one period per trial).
///
/// Run 0 starts from `cfg.init`, run 1 from the orbit-subspace start ([`Init::Orbit`]) where
/// it applies, the other runs from seeded random starts. Every run gets
/// `screen_iter` sweeps (in parallel); the one with the highest `Q` then continues up to
/// `max_iter` sweeps in total and is returned.
///
/// # Errors
/// Bad configuration (`n_sources` ≥ min(I·R, N/2), `n_harmonics` ≥ N/2, zero iterations or
/// restarts), all-zero data, or a numerical failure of a least-squares step.
pub fn fit_anechoic(x: &TrialSet, cfg: &AnechoicParams) -> Result<AnechoicModel> {
    check_config(x, cfg)?;
    // The sweeps are short: run the whole fit on a pool thread, so that their parallel steps
    // fork inside the pool instead of each waking it from outside.
    rayon::scope(|_| fit_checked(x, cfg))
}

fn fit_checked(x: &TrialSet, cfg: &AnechoicParams) -> Result<AnechoicModel> {
    let sp = Spectra::new(x, cfg.n_harmonics)?;
    let screen = AnechoicParams {
        max_iter: cfg.screen_iter.min(cfg.max_iter),
        ..cfg.clone()
    };
    let orbit = orbit_applies(&sp, cfg);
    let runs: Vec<(State, f64, Vec<f64>)> = (0..cfg.restarts)
        .into_par_iter()
        .map(|run_i| {
            let start = match (run_i, cfg.init) {
                (0, Init::Pca) => pca_start(x, &sp, cfg)?,
                (0, Init::Greedy) => greedy_start(x, &sp, cfg)?,
                (0, Init::Orbit) | (1, Init::Pca | Init::Greedy | Init::Random) if orbit => {
                    orbit_start(&sp, cfg)?
                }
                _ => random_start(&sp, cfg, run_i as u64)?,
            };
            run(&sp, &screen, start)
        })
        .collect::<Result<_>>()?;
    let (state, q, mut hist) = runs
        .into_iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or_else(|| Error::Numerical("no demixing run finished".into()))?;
    let used = hist.len() - 1;
    let converged = used < screen.max_iter;
    let (state, q) = if converged || used >= cfg.max_iter {
        (state, q)
    } else {
        let rest = AnechoicParams {
            max_iter: cfg.max_iter - used,
            ..cfg.clone()
        };
        let (state, q, more) = run(&sp, &rest, state)?;
        hist.extend_from_slice(&more[1..]);
        (state, q)
    };
    let (mut state, mut q) = (state, q);
    for _ in 0..SEARCH_ROUNDS {
        let before = q;
        (state, q) = search_delays(&sp, cfg, state, q, &mut hist)?;
        if q <= before {
            break;
        }
    }
    log::info!(
        "anechoic demixing: best of {} starts after {} iterations, quality Q = {q:.4}",
        cfg.restarts,
        hist.len() - 1
    );
    Ok(state.into_model(&sp, q, hist))
}

/// Rounds of [`search_delays`] at most: the ALS that follows a search moves the sources, which
/// can open better delays in other channels.
const SEARCH_ROUNDS: usize = 5;

/// The per-channel delay search after the ALS ([`AnechoicParams::delay_search`], shared delays
/// and two or more sources only): channels where [`crate::delay_search`] finds delays with a
/// lower residual take them, every weight is refitted, and the ALS continues from there. The
/// better of the two fits is kept, and the continued run's `Q` values join `hist`.
fn search_delays(
    sp: &Spectra,
    cfg: &AnechoicParams,
    state: State,
    q: f64,
    hist: &mut Vec<f64>,
) -> Result<(State, f64)> {
    if cfg.delay_search == 0 || state.mode != DelayMode::Shared || state.j < 2 {
        return Ok((state, q));
    }
    let j_n = state.j;
    let found: Vec<Option<Vec<f64>>> = (0..sp.i)
        .into_par_iter()
        .map(|i| {
            ChannelDelays::new(&state.c, sp.k, (0..sp.r).map(|r| sp.row(r, i)))
                .search(&state.tau[i * j_n..(i + 1) * j_n], cfg.delay_search)
                .map(|(t, _)| t)
        })
        .collect();
    if found.iter().all(Option::is_none) {
        return Ok((state, q));
    }
    let mut next = state.clone();
    for (i, t) in found.iter().enumerate() {
        if let Some(t) = t {
            next.tau[i * j_n..(i + 1) * j_n].copy_from_slice(t);
        }
    }
    let dt = next.delayed_table(sp);
    next.update_weights(sp, &dt)?;
    let (next, qn, more) = run(sp, cfg, next)?;
    if qn > q {
        hist.extend_from_slice(&more);
        Ok((next, qn))
    } else {
        Ok((state, q))
    }
}

/// Continues the ALS from an existing model, possibly under a looser delay constraint (zero →
/// shared → per trial): the start reproduces `start`'s fit exactly, so the result's `Q` is at
/// least `start.q` (nested models, as in the paper's Fig. 4 comparison of delays fixed across
/// trials with free ones). Uses `cfg.delays`, `max_iter` and `tol`; the
/// number of sources and harmonics come from `start`.
///
/// # Errors
/// Shape mismatch between `x` and `start`, or a tighter constraint than `start`'s.
pub fn refine_anechoic(
    x: &TrialSet,
    cfg: &AnechoicParams,
    start: &AnechoicModel,
) -> Result<AnechoicModel> {
    if (x.n_trials, x.n_channels, x.n_samples)
        != (start.n_trials, start.n_channels, start.n_samples)
    {
        return Err(Error::ShapeMismatch(
            "data and starting model differ in shape".into(),
        ));
    }
    let rank = |m: DelayMode| match m {
        DelayMode::Zero => 0,
        DelayMode::Shared => 1,
        DelayMode::PerTrial => 2,
    };
    if rank(cfg.delays) < rank(start.delay_mode) {
        return Err(Error::invalid(
            "delays",
            "cannot refine into a tighter delay constraint than the start's",
        ));
    }
    let k = start.sources.first().map_or(0, |s| s.n_harmonics());
    let cfg = AnechoicParams {
        n_sources: start.n_sources(),
        n_harmonics: k,
        ..cfg.clone()
    };
    check_config(x, &cfg)?;
    let sp = Spectra::new(x, k)?;
    let nd = n_delay_rows(cfg.delays, sp.r) * sp.i * cfg.n_sources;
    let tau: Vec<f64> = (0..nd)
        .map(|d| {
            let per = sp.i * cfg.n_sources;
            let (rd, rest) = (d / per, d % per);
            let (i, j) = (rest / cfg.n_sources, rest % cfg.n_sources);
            start.delay(rd, i, j)
        })
        .collect();
    let state = State {
        j: cfg.n_sources,
        mode: cfg.delays,
        c: start
            .sources
            .iter()
            .flat_map(|s| s.coeffs.iter().copied())
            .collect(),
        tau,
        w: start.weights.clone(),
    };
    let (state, q, hist) = run(&sp, &cfg, state)?;
    Ok(state.into_model(&sp, q, hist))
}

/// Least-squares weights of fixed sources and delays for new data of the same channel count
/// (`R' × I × J`), e.g. to apply a learned model to other trials.
///
/// # Errors
/// Channel or sample count differs from the model's.
pub fn refit_weights(model: &AnechoicModel, x: &TrialSet) -> Result<Vec<f64>> {
    if x.n_channels != model.n_channels || x.n_samples != model.n_samples {
        return Err(Error::ShapeMismatch(format!(
            "model has {} channels x {} samples, data {} x {}",
            model.n_channels, model.n_samples, x.n_channels, x.n_samples
        )));
    }
    if model.delay_mode == DelayMode::PerTrial && x.n_trials != model.n_trials {
        return Err(Error::ShapeMismatch(
            "per-trial delays need the same trials as the fit".into(),
        ));
    }
    let k = model.sources.first().map_or(1, |s| s.n_harmonics());
    let sp = Spectra::new(x, k)?;
    let mut s = State {
        j: model.n_sources(),
        mode: model.delay_mode,
        c: model
            .sources
            .iter()
            .flat_map(|s| s.coeffs.iter().copied())
            .collect(),
        tau: model.delays.clone(),
        w: vec![0.0; x.n_trials * x.n_channels * model.n_sources()],
    };
    s.update_weights(&sp, &s.delayed_table(&sp))?;
    Ok(s.w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic pseudo-random value in [−1, 1].
    fn val(n: usize) -> f64 {
        (n as f64 * 12.9898 + 0.5).sin()
    }

    /// Pseudo-random data of `R × I × N` samples and a state of `J` pseudo-random sources of `K`
    /// harmonics, delays (zero in [`DelayMode::Zero`]) and weights.
    fn random_problem(
        (r_n, i_n, n, j_n, k): (usize, usize, usize, usize, usize),
        mode: DelayMode,
    ) -> (Spectra, State) {
        let x = TrialSet::new(r_n, i_n, n, (0..r_n * i_n * n).map(val).collect()).unwrap();
        let rows = n_delay_rows(mode, r_n);
        let state = State {
            j: j_n,
            mode,
            c: (0..j_n * k)
                .map(|t| Complex64::new(val(1000 + t), val(2000 + t)))
                .collect(),
            tau: (0..rows * i_n * j_n)
                .map(|t| {
                    if mode == DelayMode::Zero {
                        0.0
                    } else {
                        0.5 * val(3000 + t)
                    }
                })
                .collect(),
            w: (0..r_n * i_n * j_n).map(|t| val(4000 + t)).collect(),
        };
        (Spectra::new(&x, k).unwrap(), state)
    }

    #[test]
    fn factored_source_step_equals_the_row_sums() {
        // R = 4 trials, I = 5 channels, N = 32, J = 2 sources, K = 3 harmonics.
        let r_n = 4;
        let (sp, shared) = random_problem((r_n, 5, 32, 2, 3), DelayMode::Shared);
        // The same delays repeated for every trial take the per-row path.
        let mut rows = State {
            mode: DelayMode::PerTrial,
            tau: shared.tau.repeat(r_n),
            ..shared.clone()
        };
        let mut factored = shared;
        factored
            .update_sources(&sp, &factored.phase_table(&sp), None)
            .unwrap();
        rows.update_sources(&sp, &rows.phase_table(&sp), None)
            .unwrap();
        for (a, b) in factored.c.iter().zip(&rows.c) {
            assert!((a - b).norm() < 1e-10 * b.norm().max(1.0), "{a} vs {b}");
        }
        // The step solved something: the sources moved from their start.
        assert!((factored.c[0] - Complex64::new(val(1000), val(2000))).norm() > 1e-3);
    }

    #[test]
    fn weight_statistics_give_the_residual_and_follow_the_gauge() {
        for mode in [DelayMode::Shared, DelayMode::Zero] {
            // R = 4, I = 5, N = 32, J = 3, K = 4.
            let (sp, mut s) = random_problem((4, 5, 32, 3, 4), mode);
            // The expanded residual equals the one summed row by row.
            let direct = s.in_band_residual(&sp);
            let (q, ph, st) = s.assess(&sp);
            let st = st.unwrap();
            // What the next source step reuses is this state's phase table.
            assert_eq!(ph, s.phase_table(&sp), "{mode:?}");
            let from_stats = s.shared_residual(&sp, &s.delayed_table(&sp), &st);
            assert!(
                (from_stats - direct).abs() <= 1e-12 * sp.in_band,
                "{mode:?}"
            );
            assert_eq!(q, sp.quality_of(from_stats));
            // Gauge fixing rescales the statistics with the weights.
            let mut st = st;
            s.normalize(&sp, Some(&mut st));
            let fresh = s.weight_stats(&sp);
            for (a, b) in st.gram.iter().zip(&fresh.gram) {
                assert!(
                    (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                    "{mode:?}: {a} vs {b}"
                );
            }
            for (a, b) in st.wx.iter().zip(&fresh.wx) {
                assert!(
                    (a - b).norm() <= 1e-12 * b.norm().max(1.0),
                    "{mode:?}: {a} vs {b}"
                );
            }
        }
    }

    #[test]
    fn shared_delay_step_from_statistics_equals_the_row_step() {
        let (r_n, i_n, j_n, k) = (4, 5, 3, 4);
        let (sp, s) = random_problem((r_n, i_n, 32, j_n, k), DelayMode::Shared);
        let dt = s.delayed_table(&sp);
        let zero = Complex64::new(0.0, 0.0);
        let mut moved = 0;
        for i in 0..i_n {
            let w: Vec<f64> = (0..r_n)
                .flat_map(|r| s.w[(r * i_n + i) * j_n..][..j_n].to_vec())
                .collect();
            let (mut gram, mut wx) = (vec![0.0; j_n * j_n], vec![zero; j_n * k]);
            for (r, wr) in w.chunks_exact(j_n).enumerate() {
                accumulate_stats(wr, sp.row(r, i), &mut gram, &mut wx);
            }
            let mut scratch = vec![zero; (r_n + 2) * k];
            let (mut by_rows, mut by_stats) = (vec![0.0; j_n], vec![0.0; j_n]);
            let residual = s.channel_delays(&sp, &dt, i, &w, &mut by_rows, &mut scratch);
            let fit =
                s.channel_delays_shared(&sp, &dt, i, (&gram, &wx), &mut by_stats, &mut scratch);
            for (a, b) in by_rows.iter().zip(&by_stats) {
                assert!((a - b).abs() < 1e-9, "channel {i}: {a} vs {b}");
            }
            moved += by_rows
                .iter()
                .zip(&s.tau[i * j_n..(i + 1) * j_n])
                .filter(|(a, b)| a != b)
                .count();
            let energy: f64 = (0..r_n)
                .flat_map(|r| sp.row(r, i).iter().map(|v| v.norm_sqr()))
                .sum();
            assert!(
                (energy + fit - residual).abs() < 1e-10 * energy,
                "channel {i}: {} vs {residual}",
                energy + fit
            );
        }
        assert!(moved > 0, "no delay moved: the comparison proved nothing");
    }

    #[test]
    fn fused_weight_and_delay_pass_reports_the_residual_it_leaves() {
        for mode in [DelayMode::Shared, DelayMode::PerTrial] {
            // R = 4, I = 5, N = 32, J = 2, K = 3.
            let (sp, start) = random_problem((4, 5, 32, 2, 3), mode);
            let dt = start.delayed_table(&sp);
            // The weight step alone, then the fused pass from the same state.
            let mut weights_only = start.clone();
            weights_only.update_weights(&sp, &dt).unwrap();
            let mut fused = start.clone();
            let (reported, stats) = fused.update_weights_and_delays(&sp, &dt).unwrap();
            let reported = reported.unwrap();
            // For shared delays the pass also returns the new weights' statistics.
            match stats {
                Some(st) => {
                    assert_eq!(mode, DelayMode::Shared);
                    let fresh = fused.weight_stats(&sp);
                    assert_eq!(st.gram, fresh.gram);
                    assert_eq!(st.wx, fresh.wx);
                }
                None => assert_eq!(mode, DelayMode::PerTrial),
            }
            // The delays see the new weights (and leave them), and the reported residual is
            // the new state's own, recomputed from scratch.
            assert_eq!(fused.w, weights_only.w, "{mode:?}");
            let actual = fused.in_band_residual(&sp);
            assert!(
                (reported - actual).abs() <= 1e-12 * actual,
                "{mode:?}: reported {reported}, actual {actual}"
            );
            // The delay step moved something and lowered the residual.
            assert_ne!(fused.tau, start.tau, "{mode:?}");
            assert!(actual < weights_only.in_band_residual(&sp), "{mode:?}");
        }
    }
}
