//! Comparing estimated sources with ground truth up to the model's gauge freedoms (circular
//! shift, sign and scale: eq. 1 is unchanged when a source is shifted, flipped or scaled and
//! its delays and weights compensate): the similarity of two periodic sources is
//! the largest |normalised circular cross-correlation| over all shifts, and sources are paired
//! by the assignment that maximises the summed similarity.

use crate::fourier::{trig_argmax, PeriodicSource};
use num_complex::Complex64;
use wscg_math::{Error, Result};

/// How an estimated source matches a true one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SourceMatch {
    /// Index of the estimated source.
    pub estimate: usize,
    /// |normalised cross-correlation| at the best shift, in `[0, 1]`.
    pub similarity: f64,
    /// `μ` (periods) with `estimate(t) ≈ sign · truth(t − μ)`.
    pub shift: f64,
    /// `+1` or `−1`.
    pub sign: f64,
}

/// Best shift and sign aligning `est` to `truth`: maximises
/// `ρ(μ) = <est, truth(· − μ)> / (‖est‖ ‖truth‖)` in absolute value.
pub fn align(est: &PeriodicSource, truth: &PeriodicSource) -> (f64, f64, f64) {
    let norm = est.rms() * truth.rms();
    if norm <= 0.0 {
        return (0.0, 0.0, 1.0);
    }
    // <e, t(· − μ)> / N = 2 Re Σ_k conj(e_k) t_k e^{−2πikμ}
    let k = est.n_harmonics().min(truth.n_harmonics());
    let g: Vec<Complex64> = (0..k)
        .map(|i| 2.0 * est.coeffs[i].conj() * truth.coeffs[i] / norm)
        .collect();
    let neg: Vec<Complex64> = g.iter().map(|v| -v).collect();
    let (mu_p, fp) = trig_argmax(&g);
    let (mu_n, fn_) = trig_argmax(&neg);
    if fp >= fn_ {
        (fp, mu_p, 1.0)
    } else {
        (fn_, mu_n, -1.0)
    }
}

/// Pairs every true source with a distinct estimated one, maximising the total similarity
/// (exhaustive over assignments, exact for the handful of sources of a decomposition).
///
/// # Errors
/// More true sources than estimates, or more than 8 sources.
pub fn match_sources(est: &[PeriodicSource], truth: &[PeriodicSource]) -> Result<Vec<SourceMatch>> {
    if truth.len() > est.len() {
        return Err(Error::invalid(
            "est",
            format!("{} estimates for {} true sources", est.len(), truth.len()),
        ));
    }
    if est.len() > 8 {
        return Err(Error::invalid(
            "est",
            "exhaustive matching supports at most 8 sources",
        ));
    }
    let sims: Vec<Vec<(f64, f64, f64)>> = truth
        .iter()
        .map(|t| est.iter().map(|e| align(e, t)).collect())
        .collect();
    let mut best: (f64, Vec<usize>) = (f64::NEG_INFINITY, Vec::new());
    let mut perm: Vec<usize> = Vec::with_capacity(truth.len());
    let mut used = vec![false; est.len()];
    fn search(
        t: usize,
        sims: &[Vec<(f64, f64, f64)>],
        used: &mut [bool],
        perm: &mut Vec<usize>,
        score: f64,
        best: &mut (f64, Vec<usize>),
    ) {
        if t == sims.len() {
            if score > best.0 {
                *best = (score, perm.clone());
            }
            return;
        }
        for e in 0..used.len() {
            if !used[e] {
                used[e] = true;
                perm.push(e);
                search(t + 1, sims, used, perm, score + sims[t][e].0, best);
                perm.pop();
                used[e] = false;
            }
        }
    }
    search(0, &sims, &mut used, &mut perm, 0.0, &mut best);
    Ok(best
        .1
        .iter()
        .enumerate()
        .map(|(t, &e)| {
            let (similarity, shift, sign) = sims[t][e];
            SourceMatch {
                estimate: e,
                similarity,
                shift,
                sign,
            }
        })
        .collect())
}
