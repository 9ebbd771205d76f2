//! Radiometric self-calibration by Mitsunaga & Nayar (CVPR 1999), the response model of
//! RASCAL, which the paper used for its 8-bit views (section 3). The inverse response is a
//! polynomial of the normalised code `M = Z / z_max`,
//!
//! `f(M) = sum_{n=0..N} c_n M^n`, with `f(1) = 1`,
//!
//! and consecutive exposures `q`, `q + 1` (sorted by time) of one pixel satisfy
//! `f(M_q) = R_q f(M_{q+1})` with the exposure ratio `R_q = t_q / t_{q+1}`. Given the ratios,
//! the coefficients minimise `sum_{q,p} [f(M_{p,q}) - R_q f(M_{p,q+1})]^2` (linear least
//! squares once `c_N = 1 - sum_{n<N} c_n` is substituted); given the coefficients, each ratio
//! is re-estimated. The two steps alternate from the ratios of the nominal exposure times
//! until the response moves less than `tol` at every code (or stops moving less), so the
//! intermediate exposure
//! times need only be approximate (RASCAL likewise starts from rough exposure values).
//!
//! Where we differ from the 1999 paper: a ratio is re-estimated as the median of the
//! per-pixel ratios `f(M_{p,q}) / f(M_{p,q+1})` rather than their mean, which dark pixels
//! (small `f(M_{p,q+1})`) make unstable; and the ratios are scaled after each update so
//! that their product stays that of the given times (the span of the shortest to the
//! longest exposure). Without that anchor the alternation drifts along
//! the exponential ambiguity (`f^g` with ratios `R^g` fits as well for every `g`; Grossberg &
//! Nayar 2003) towards ever steeper responses.

use faer::Mat;
use wscg_math::{dense, Error, Image, Result};

use crate::crf::{check_stack, monotone_channel, sample_grid, Crf};

wscg_math::params! {
    /// Parameters of [`calibrate_mitsunaga_nayar`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct MitsunagaNayarParams {
        /// Degree `N` of the polynomial; `None` picks it in `1..=max_degree` per channel by the
        /// error on held-out samples (every second sample fits, the others judge; the smallest
        /// degree within 25 % of the best error).
        pub degree: Option<usize>,
        /// Largest degree tried when `degree` is `None` (10).
        pub max_degree: usize,
        /// Sample pixels on a regular grid (2000; each gives one equation per pair of
        /// consecutive exposures in which both codes lie within 2-98 % of the range).
        pub samples: usize,
        /// Re-estimate the exposure ratios (the method's iteration, true), or keep the ratios of
        /// the given times (false).
        pub refine_ratios: bool,
        /// Convergence: the largest change of `f` over the codes between iterations (1e-7); the
        /// alternation also stops once that change has not shrunk for two iterations.
        pub tol: f64,
        /// Most iterations of the alternation (100).
        pub max_iter: usize,
    }
}

impl Default for MitsunagaNayarParams {
    fn default() -> Self {
        Self {
            degree: None,
            max_degree: 10,
            samples: 2000,
            refine_ratios: true,
            tol: 1e-7,
            max_iter: 100,
        }
    }
}

/// Fewest sample pairs with the brighter code in the upper half of the range.
pub const MIN_UPPER: usize = 10;

/// Largest polynomial degree accepted.
pub const MAX_DEGREE: usize = 10;

impl MitsunagaNayarParams {
    /// Errors: a degree or `max_degree` outside `1..=`[`MAX_DEGREE`], no samples, a
    /// non-positive or non-finite `tol`, no iterations.
    pub fn validate(&self) -> Result<()> {
        for (name, d) in [
            ("degree", self.degree.unwrap_or(1)),
            ("max_degree", self.max_degree),
        ] {
            if !(1..=MAX_DEGREE).contains(&d) {
                return Err(Error::invalid(
                    name,
                    format!("must be in 1..={MAX_DEGREE}, got {d}"),
                ));
            }
        }
        if self.samples == 0 {
            return Err(Error::invalid("samples", "must be >= 1"));
        }
        if !(self.tol.is_finite() && self.tol > 0.0) {
            return Err(Error::invalid(
                "tol",
                format!("must be finite and > 0, got {}", self.tol),
            ));
        }
        if self.max_iter == 0 {
            return Err(Error::invalid("max_iter", "must be >= 1"));
        }
        Ok(())
    }
}

/// One channel's fit.
#[derive(Clone, Debug, PartialEq)]
pub struct MitsunagaNayarChannel {
    /// `c_0 .. c_N` of `f(M)`, summing to 1.
    pub coefficients: Vec<f64>,
    /// Exposure ratios `t_q / t_{q+1}` of consecutive exposures in order of time, as
    /// estimated (the given times' ratios when not refined).
    pub ratios: Vec<f64>,
    /// Root mean square of the residuals `f(M_q) - R_q f(M_{q+1})` over the equations.
    pub rms: f64,
    /// Equations (sample pixel and exposure pair) the fit used.
    pub equations: usize,
    /// Alternations run.
    pub iterations: usize,
}

/// The result of [`calibrate_mitsunaga_nayar`].
#[derive(Clone, Debug, PartialEq)]
pub struct MitsunagaNayarFit {
    /// The inverse response table, `f(Z / z_max)` per code and channel (`f(z_max) = 1`).
    pub crf: Crf,
    /// Each channel's polynomial, ratios and residual.
    pub channels: Vec<MitsunagaNayarChannel>,
}

/// One equation's two normalised codes and the pair of exposures it belongs to.
#[derive(Clone, Copy)]
struct Obs {
    lo: f64,
    hi: f64,
    pair: usize,
}

/// `f(m)` of coefficients `c`.
fn poly(c: &[f64], m: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * m + k)
}

/// The coefficients of degree `n` minimising the residuals of `obs` under `ratios`, with
/// `f(1) = 1`.
fn solve(obs: &[Obs], ratios: &[f64], n: usize) -> Result<Vec<f64>> {
    let mut a = Mat::<f64>::zeros(obs.len(), n);
    let mut b = Mat::<f64>::zeros(obs.len(), 1);
    for (i, o) in obs.iter().enumerate() {
        let r = ratios[o.pair];
        let (lo_n, hi_n) = (o.lo.powi(n as i32), o.hi.powi(n as i32));
        let (mut pl, mut ph) = (1.0, 1.0);
        for k in 0..n {
            a[(i, k)] = (pl - lo_n) - r * (ph - hi_n);
            pl *= o.lo;
            ph *= o.hi;
        }
        b[(i, 0)] = -(lo_n - r * hi_n);
    }
    let x = dense::lstsq(a.as_ref(), b.as_ref(), None)?;
    let mut c: Vec<f64> = (0..n).map(|k| x[(k, 0)]).collect();
    c.push(1.0 - c.iter().sum::<f64>());
    Ok(c)
}

/// Root mean square residual of `obs` under `c` and `ratios`.
fn rms(obs: &[Obs], c: &[f64], ratios: &[f64]) -> f64 {
    let s: f64 = obs
        .iter()
        .map(|o| (poly(c, o.lo) - ratios[o.pair] * poly(c, o.hi)).powi(2))
        .sum();
    (s / obs.len().max(1) as f64).sqrt()
}

/// The alternation of coefficients and ratios at degree `n` from `ratios`.
fn fit(
    obs: &[Obs],
    mut ratios: Vec<f64>,
    n: usize,
    p: &MitsunagaNayarParams,
    levels: usize,
) -> Result<(Vec<f64>, Vec<f64>, usize)> {
    // The change of f is measured at every code, or at 1025 evenly spaced values for deeper
    // codes (a polynomial of degree <= 10 cannot hide between them).
    let grid = levels.min(1025);
    let span: f64 = ratios.iter().map(|r| r.ln()).sum();
    let mut c = solve(obs, &ratios, n)?;
    let mut it = 1;
    let (mut last, mut stalled) = (f64::INFINITY, 0);
    while it < p.max_iter {
        if p.refine_ratios {
            // Each R_q as the median of the per-equation ratios f(M_q) / f(M_{q+1}) (the
            // method's estimate, with the median for the mean, which dark pixels dominate),
            // then all scaled so that their product keeps the nominal span
            // t_first / t_last: f^g with ratios R^g fits exactly as well for any g (the
            // exponential ambiguity), and the span is what fixes g.
            let mut per_pair: Vec<Vec<f64>> = vec![Vec::new(); ratios.len()];
            for o in obs {
                let (a, b) = (poly(&c, o.lo), poly(&c, o.hi));
                if a > 0.0 && b > 0.0 {
                    per_pair[o.pair].push(a / b);
                }
            }
            for (r, v) in ratios.iter_mut().zip(per_pair.iter_mut()) {
                if !v.is_empty() {
                    let k = v.len() / 2;
                    *r = *v.select_nth_unstable_by(k, f64::total_cmp).1;
                }
            }
            let drift: f64 = ratios.iter().map(|r| r.ln()).sum::<f64>() - span;
            let k = (-drift / ratios.len() as f64).exp();
            ratios.iter_mut().for_each(|r| *r *= k);
        }
        let next = solve(obs, &ratios, n)?;
        it += 1;
        let moved = (0..grid)
            .map(|k| {
                let m = k as f64 / (grid - 1) as f64;
                (poly(&next, m) - poly(&c, m)).abs()
            })
            .fold(0.0, f64::max);
        c = next;
        // The median moves in steps of one pixel's ratio, so the alternation can settle into
        // a cycle of a few states instead of a fixed point: it also stops once the change
        // has not shrunk for two iterations.
        stalled = if moved < last { 0 } else { stalled + 1 };
        last = moved;
        if moved < p.tol || stalled >= 2 {
            break;
        }
    }
    Ok((c, ratios, it))
}

/// Recovers the inverse response of a `bits`-bit camera from a static stack of exposures
/// with (approximate) exposure times `times` by the method of Mitsunaga & Nayar (see the
/// module documentation), per channel. Returns the response table, `f(Z / z_max)` with
/// `f(z_max) = 1`, and each channel's polynomial, ratios and residual.
///
/// Errors: fewer than two exposures, shapes that differ, codes above `bits`, invalid
/// times or parameters, a channel with no sample unclipped in two consecutive exposures, or
/// a polynomial that decreases over the observed codes ("CRF calibration failed").
pub fn calibrate_mitsunaga_nayar(
    stack: &[Image<u16>],
    times: &[f64],
    bits: u8,
    p: &MitsunagaNayarParams,
) -> Result<MitsunagaNayarFit> {
    p.validate()?;
    let (levels, (h, w, ch)) = check_stack(stack, times, bits)?;
    let zmax = levels - 1;
    let pts = sample_grid(h, w, p.samples)?;
    let mut order: Vec<usize> = (0..stack.len()).collect();
    order.sort_by(|&i, &j| times[i].total_cmp(&times[j]));
    let nominal: Vec<f64> = order
        .windows(2)
        .map(|q| times[q[0]] / times[q[1]])
        .collect();
    if let Some(q) = order.windows(2).find(|q| times[q[0]] == times[q[1]]) {
        return Err(Error::invalid(
            "times",
            format!(
                "exposures {} and {} have the same time: the ratios need distinct times",
                q[0], q[1]
            ),
        ));
    }
    // Codes within 2 % of either end are left out: black-level noise and values clipped by
    // noise just below saturation break the equations.
    let (lo_code, hi_code) = (
        ((0.02 * zmax as f64).ceil() as usize).max(1),
        ((0.98 * zmax as f64).floor() as usize).min(zmax - 1),
    );
    let mut table = vec![0f32; levels * ch];
    let mut channels = Vec::with_capacity(ch);
    for c in 0..ch {
        let mut obs = Vec::new();
        let (mut zlo, mut zhi) = (usize::MAX, 0);
        for &(y, x) in &pts {
            for (pair, q) in order.windows(2).enumerate() {
                let (a, b) = (stack[q[0]].at(y, x, c), stack[q[1]].at(y, x, c));
                let ok = |z: u16| (z as usize) >= lo_code && (z as usize) <= hi_code;
                if ok(a) && ok(b) {
                    zlo = zlo.min(a.min(b) as usize);
                    zhi = zhi.max(a.max(b) as usize);
                    obs.push(Obs {
                        lo: a as f64 / zmax as f64,
                        hi: b as f64 / zmax as f64,
                        pair,
                    });
                }
            }
        }
        if obs.is_empty() {
            return Err(Error::Numerical(format!(
                "CRF calibration failed: channel {c} has no sample unclipped in two \
                 consecutive exposures"
            )));
        }
        // The equations are homogeneous in f: only f(1) = 1 fixes its scale, through the
        // pairs whose brighter code lies in the upper half. A stack without them (a dark
        // scene whose bright pixels all saturate) leaves the response undetermined.
        let upper = obs.iter().filter(|o| o.hi >= 0.5).count();
        if upper < MIN_UPPER.max(obs.len() / 50) {
            return Err(Error::Numerical(format!(
                "CRF calibration failed: channel {c} has {upper} of {} sample pairs with a \
                 code in the upper half of the range; the polynomial's scale is fixed at \
                 the top code, so the stack needs pixels across the whole range (at least \
                 2 %, and {MIN_UPPER}), as a calibration chart or a gradient gives",
                obs.len()
            )));
        }
        let values = |coef: &[f64]| -> Vec<f64> {
            (0..levels)
                .map(|z| poly(coef, z as f64 / zmax as f64))
                .collect()
        };
        let hint = "a lower polynomial degree";
        let (coef, ratios, iterations, v) = match p.degree {
            Some(n) => {
                let (coef, ratios, it) = fit(&obs, nominal.clone(), n, p, levels)?;
                let v = monotone_channel(&values(&coef), (zlo, zhi), c, hint)?;
                (coef, ratios, it, v)
            }
            None => {
                // Every second equation fits, the others judge. Among the degrees whose fit
                // to all equations increases over the observed codes, the smallest within
                // 25 % of the best held-out error wins (a parsimony rule: the held-out error
                // flattens out once the model fits, and higher degrees then only follow the
                // noise).
                let fit_set: Vec<Obs> = obs.iter().copied().step_by(2).collect();
                let test_set: Vec<Obs> = obs.iter().copied().skip(1).step_by(2).collect();
                let mut cands = Vec::with_capacity(p.max_degree);
                for n in 1..=p.max_degree {
                    let (cn, rn, _) = fit(&fit_set, nominal.clone(), n, p, levels)?;
                    let held_out = rms(&test_set, &cn, &rn);
                    let (coef, ratios, it) = fit(&obs, nominal.clone(), n, p, levels)?;
                    if let Ok(v) = monotone_channel(&values(&coef), (zlo, zhi), c, hint) {
                        cands.push((held_out, (coef, ratios, it, v)));
                    }
                }
                let best = cands.iter().map(|(e, _)| *e).fold(f64::INFINITY, f64::min);
                let Some(k) = cands.iter().position(|(e, _)| *e <= 1.25 * best) else {
                    return Err(Error::Numerical(format!(
                        "CRF calibration failed: no polynomial of degree 1..={} increases over \
                         the observed codes of channel {c}",
                        p.max_degree
                    )));
                };
                cands.swap_remove(k).1
            }
        };
        for (z, f) in v.iter().enumerate() {
            table[z * ch + c] = f.max(0.0) as f32;
        }
        channels.push(MitsunagaNayarChannel {
            rms: rms(&obs, &coef, &ratios),
            coefficients: coef,
            ratios,
            equations: obs.len(),
            iterations,
        });
    }
    Ok(MitsunagaNayarFit {
        crf: Crf::from_table(&table, levels, ch)?,
        channels,
    })
}
