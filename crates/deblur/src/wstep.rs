//! The per-pixel w-subproblem of Krishnan & Fergus (paper eq. 8):
//! `w* = argmin_w |w|^alpha + beta/2 (w - v)^2`.
//!
//! - `alpha = 1`: soft thresholding at `1/beta`.
//! - `0 < alpha < 1` (the paper uses 1/2): for `v > 0` the stationarity function
//!   `g(w) = alpha w^(alpha-1) + beta (w - v)` is convex on `(0, v]`; when it has roots, the
//!   larger one is the local minimum (reached by Newton's method from `w = v`, monotonically)
//!   and is compared with `w = 0`. This covers the closed forms of the paper (the cubic for
//!   1/2, the quartic for 2/3) and every other exponent, without spurious roots.
//! - `1 < alpha <= 2`: the energy is convex; the unique root of `g` in `(0, v)` by safeguarded
//!   Newton.
//!
//! Odd symmetry gives `v < 0`.
//!
//! [`WStepTable`] tabulates the solution for one `(alpha, beta)` on the non-zero branch (exact
//! threshold, linear interpolation, the exact solver beyond the table), as KF's lookup tables.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Energy `|w|^alpha + beta/2 (w - v)^2`.
pub fn w_energy(w: f64, v: f64, alpha: f64, beta: f64) -> f64 {
    w.abs().powf(alpha) + 0.5 * beta * (w - v) * (w - v)
}

/// Exact minimiser of [`w_energy`] over `w` (ties resolve to 0). `alpha` in `(0, 2]`,
/// `beta > 0` (not checked here; the solvers validate their parameters).
pub fn w_exact(v: f64, alpha: f64, beta: f64) -> f64 {
    let a = v.abs();
    if a == 0.0 {
        return 0.0;
    }
    let w = if alpha == 1.0 {
        (a - 1.0 / beta).max(0.0)
    } else if alpha == 2.0 {
        beta * a / (2.0 + beta)
    } else if alpha < 1.0 {
        positive_branch_concave(a, alpha, beta)
    } else {
        convex_root(a, alpha, beta)
    };
    w.copysign(v)
}

/// `0 < alpha < 1`, `a > 0`.
fn positive_branch_concave(a: f64, alpha: f64, beta: f64) -> f64 {
    let g = |w: f64| alpha * w.powf(alpha - 1.0) + beta * (w - a);
    let dg = |w: f64| alpha * (alpha - 1.0) * w.powf(alpha - 2.0) + beta;
    // Minimum of the convex g.
    let w_min = (alpha * (1.0 - alpha) / beta).powf(1.0 / (2.0 - alpha));
    if w_min >= a || g(w_min) >= 0.0 {
        return 0.0;
    }
    let mut w = a;
    for _ in 0..100 {
        let step = g(w) / dg(w);
        let next = (w - step).max(w_min);
        if (w - next).abs() <= 1e-15 * a.max(1e-300) {
            w = next;
            break;
        }
        w = next;
    }
    if w_energy(w, a, alpha, beta) < w_energy(0.0, a, alpha, beta) {
        w
    } else {
        0.0
    }
}

/// `1 < alpha < 2`, `a > 0`: the root of the increasing `g` in `(0, a)`.
fn convex_root(a: f64, alpha: f64, beta: f64) -> f64 {
    let g = |w: f64| alpha * w.powf(alpha - 1.0) + beta * (w - a);
    let (mut lo, mut hi) = (0.0, a);
    let mut w = a * beta / (beta + 1.0);
    for _ in 0..200 {
        let gw = g(w);
        if gw > 0.0 {
            hi = w;
        } else {
            lo = w;
        }
        let d = alpha * (alpha - 1.0) * w.powf(alpha - 2.0) + beta;
        let mut next = w - gw / d;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - w).abs() <= 1e-15 * a {
            return next;
        }
        w = next;
    }
    w
}

/// Smallest `|v|` with a non-zero solution (0 for `alpha > 1`, `1/beta` for `alpha = 1`).
pub fn w_threshold(alpha: f64, beta: f64) -> f64 {
    if alpha > 1.0 {
        return 0.0;
    }
    if alpha == 1.0 {
        return 1.0 / beta;
    }
    // Bisection on the predicate "the solution is non-zero", which is monotone in |v|.
    let (mut lo, mut hi) = (0.0, 1.0);
    while w_exact(hi, alpha, beta) == 0.0 {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if w_exact(mid, alpha, beta) == 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-15 * hi {
            break;
        }
    }
    hi
}

/// Tables by the bits of `(alpha, beta)`.
type LutCache = HashMap<(u64, u64), Arc<WStepTable>>;

/// Lookup table of the w-step for one `(alpha, beta)`.
#[derive(Debug)]
pub struct WStepTable {
    alpha: f64,
    beta: f64,
    /// Smallest f32 at or above `threshold`: the f32 test `|v| >= threshold_f32` equals the
    /// exact one for every f32 input.
    threshold_f32: f32,
    inv_step: f32,
    table: Vec<f32>,
}

/// Samples of a [`WStepTable`] on `[threshold, threshold + SPAN]`.
const LUT_SAMPLES: usize = 16384;
/// Width of the tabulated range of `|v|`; intensities in `[0, 1]` give gradients below 1.
const LUT_SPAN: f64 = 2.0;

impl WStepTable {
    /// Builds the table (16384 exact solves).
    pub fn new(alpha: f64, beta: f64) -> Self {
        let threshold = w_threshold(alpha, beta);
        let step = LUT_SPAN / (LUT_SAMPLES - 1) as f64;
        let table = (0..LUT_SAMPLES)
            .map(|i| {
                let v = threshold + i as f64 * step;
                let w = w_exact(v, alpha, beta);
                // At the threshold itself the non-zero branch is the one to interpolate from.
                if i == 0 && w == 0.0 {
                    w_exact(v * (1.0 + 1e-12), alpha, beta)
                } else {
                    w
                }
            })
            .map(|w: f64| w as f32)
            .collect();
        let mut threshold_f32 = threshold as f32;
        if (threshold_f32 as f64) < threshold {
            threshold_f32 = threshold_f32.next_up();
        }
        WStepTable {
            alpha,
            beta,
            threshold_f32,
            inv_step: (1.0 / step) as f32,
            table,
        }
    }

    /// A shared table for `(alpha, beta)`, built on first use.
    pub fn shared(alpha: f64, beta: f64) -> Arc<WStepTable> {
        static CACHE: OnceLock<Mutex<LutCache>> = OnceLock::new();
        let key = (alpha.to_bits(), beta.to_bits());
        let cache = CACHE.get_or_init(Default::default);
        if let Some(l) = cache.lock().map(|c| c.get(&key).cloned()).ok().flatten() {
            return l;
        }
        let lut = Arc::new(WStepTable::new(alpha, beta));
        if let Ok(mut c) = cache.lock() {
            c.insert(key, lut.clone());
        }
        lut
    }

    /// Approximate minimiser for `v`.
    #[inline]
    pub fn eval(&self, v: f32) -> f32 {
        let a = v.abs();
        if a < self.threshold_f32 {
            return 0.0;
        }
        // `threshold_f32` exceeds the table's origin by less than one f32 ulp.
        let x = (a - self.threshold_f32) * self.inv_step;
        let i = x as usize;
        let w = match (self.table.get(i), self.table.get(i + 1)) {
            (Some(&lo), Some(&hi)) => lo + (x - i as f32) * (hi - lo),
            _ => w_exact(a as f64, self.alpha, self.beta) as f32,
        };
        w.copysign(v)
    }

    /// `beta` of the table.
    pub fn beta(&self) -> f64 {
        self.beta
    }
}
