//! Relevance of a joint pair: the number of histogram bins its JRA occupies over a gait
//! cycle (paper 17, section 3.3), the 25 x 25 relevance map (Fig. 8) and the selected pairs
//! (Fig. 10).

use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

use super::jra::JraSet;
use super::skeleton::{Joint, Pair, N_JOINTS};

/// Histogram layout, degrees. The paper does not give it; narrow pairs occupying "2 or 3
/// bins" and the best threshold of 20 bins over cycles of 30-40 frames imply fine bins:
/// default 1° bins on [0°, 180°].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HistSpec {
    /// Lower edge, degrees (0).
    pub lo_deg: f64,
    /// Upper edge, degrees (180).
    pub hi_deg: f64,
    /// Bin width, degrees (1).
    pub bin_deg: f64,
}

impl Default for HistSpec {
    fn default() -> Self {
        Self {
            lo_deg: 0.0,
            hi_deg: 180.0,
            bin_deg: 1.0,
        }
    }
}

impl HistSpec {
    /// Number of bins.
    pub fn bins(&self) -> usize {
        ((self.hi_deg - self.lo_deg) / self.bin_deg).ceil().max(1.0) as usize
    }

    /// Errors: non-finite edges, `hi <= lo`, `bin_deg <= 0`, more than 10^6 bins.
    pub fn validate(&self) -> Result<()> {
        if !(self.lo_deg.is_finite() && self.hi_deg.is_finite() && self.hi_deg > self.lo_deg) {
            return Err(Error::invalid(
                "hist",
                "needs finite edges with hi_deg > lo_deg",
            ));
        }
        if !(self.bin_deg.is_finite() && self.bin_deg > 0.0) {
            return Err(Error::invalid("bin_deg", "must be positive"));
        }
        if (self.hi_deg - self.lo_deg) / self.bin_deg > 1e6 {
            return Err(Error::invalid("bin_deg", "more than 10^6 bins"));
        }
        Ok(())
    }
}

/// Number of non-empty bins of the histogram of `theta_rad` (converted to degrees; values
/// outside the range fall into the edge bins).
pub fn occupied_bins(theta_rad: &[f64], h: &HistSpec) -> usize {
    let nb = h.bins();
    let mut used = vec![false; nb];
    for &t in theta_rad {
        let x = (t.to_degrees() - h.lo_deg) / h.bin_deg;
        let b = if x.is_nan() {
            0
        } else {
            (x.floor().max(0.0) as usize).min(nb - 1)
        };
        used[b] = true;
    }
    used.iter().filter(|&&u| u).count()
}

/// A symmetric 25 x 25 map indexed by joint.
pub type JointMap = [[f64; N_JOINTS]; N_JOINTS];

/// The relevance map: `R(i, j)` = mean over `samples` of the occupied bins of pair `(i, j)`;
/// symmetric, zero for pairs absent from the samples (the reference joint's row and column).
/// Errors: no samples, invalid histogram.
pub fn relevance_matrix(samples: &[&JraSet], h: &HistSpec) -> Result<JointMap> {
    h.validate()?;
    if samples.is_empty() {
        return Err(Error::Empty("samples"));
    }
    let mut r = [[0.0; N_JOINTS]; N_JOINTS];
    for s in samples {
        for (&(a, b), seq) in s.pairs.iter().zip(&s.seqs) {
            let v = occupied_bins(seq, h) as f64 / samples.len() as f64;
            r[a.index()][b.index()] += v;
            if a != b {
                r[b.index()][a.index()] += v;
            }
        }
    }
    Ok(r)
}

/// The pairs `i < j` with `R(i, j) >= min_bins` (the paper keeps pairs occupying at least
/// t = 20 bins). Errors: none selected (the message gives the largest relevance), `min_bins`
/// not finite.
pub fn select_pairs(rel: &JointMap, min_bins: f64) -> Result<Vec<Pair>> {
    if !min_bins.is_finite() {
        return Err(Error::invalid("min_bins", "must be finite"));
    }
    let mut out = Vec::new();
    let mut max = 0.0f64;
    for (i, row) in rel.iter().enumerate() {
        for (j, &r) in row.iter().enumerate().skip(i + 1) {
            max = max.max(r);
            if r >= min_bins && r > 0.0 {
                out.push((Joint::ALL[i], Joint::ALL[j]));
            }
        }
    }
    if out.is_empty() {
        return Err(Error::invalid(
            "min_bins",
            format!(
                "no joint pair occupies {min_bins} bins or more; the largest relevance is \
                 {max:.2}, choose a threshold at or below it"
            ),
        ));
    }
    Ok(out)
}
