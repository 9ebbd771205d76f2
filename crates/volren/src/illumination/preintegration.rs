//! Pre-integrated classification (Engel, Kraus and Ertl 2001; the paper's section 3.1, which
//! ignores lighting in the table): for a segment of length `l` along which the scalar varies
//! linearly from `s_f` to `s_b`,
//! the opacity `1 - exp(-int tau)` and the self-attenuated associated colour
//! `int c tau exp(-int tau)`, tabulated on an `n x n` grid of `(s_f, s_b)`.

use rayon::prelude::*;
use wscg_math::{Error, Result};

use super::classify::TransferFunction;

/// The 2-D pre-integration table of one transfer function and segment length.
#[derive(Clone, Debug)]
pub struct PreIntegrationTable {
    /// Grid size per axis (the transfer function's resolution).
    pub n: usize,
    /// Segment length `l` (world units).
    pub ds: f32,
    /// Entries `[C_r, C_g, C_b, alpha]`, row-major with the front value `s_f` as the row:
    /// entry `(f, b)` at `f * n + b`.
    pub rgba: Vec<[f32; 4]>,
}

/// Sub-steps per transfer-function bin crossed.
const SUB: usize = 6;

/// Bins from which `K = SUB |b - f|` (below, the 24-step minimum applies).
const MIN_GRID_BINS: usize = 4;

/// Midpoint sub-steps used for a table entry whose endpoints are `bins` apart (at least
/// `max(16, 4 |b - f|)`, so that a piecewise-constant transfer function is integrated
/// finely; six per transfer-function bin crossed keep a step transfer function within 1e-3
/// of a 4096-step integration).
fn substeps(bins: usize) -> usize {
    (SUB * bins).max(SUB * MIN_GRID_BINS)
}

/// Front-to-back composite of `k` midpoint sub-steps of the segment `s_f -> s_b` of length
/// `l` (exact for a transfer function constant on each sub-step).
pub fn integrate_segment(tf: &TransferFunction, sf: f32, sb: f32, l: f32, k: usize) -> [f32; 4] {
    let h = l as f64 / k as f64;
    let (mut c, mut trans) = ([0f64; 3], 1f64);
    for i in 0..k {
        let t = (i as f64 + 0.5) / k as f64;
        let s = sf as f64 + (sb as f64 - sf as f64) * t;
        let (rgb, tau) = tf.eval(s as f32);
        let a = -(-(tau as f64) * h).exp_m1();
        for ch in 0..3 {
            c[ch] += trans * a * rgb[ch] as f64;
        }
        trans *= 1.0 - a;
    }
    [c[0] as f32, c[1] as f32, c[2] as f32, (1.0 - trans) as f32]
}

impl PreIntegrationTable {
    /// Builds the table for segment length `ds > 0` (world units) on the transfer function's
    /// own grid (`n = tf.len()`). `O(n^2 K)` multiply-adds, parallel over rows. Errors: `ds`
    /// not finite and positive.
    pub fn build(tf: &TransferFunction, ds: f32) -> Result<Self> {
        if !(ds.is_finite() && ds > 0.0) {
            return Err(Error::invalid(
                "ds",
                format!("segment length must be finite and > 0, got {ds}"),
            ));
        }
        let n = tf.len();
        let den = (n - 1) as f32;
        // With K = 6 |b - f| sub-steps (|b - f| >= 4) every midpoint lies on the fine grid
        // s_j = (j + 1/2) / (6 (n - 1)), and the sub-step length l / K depends on |b - f| only:
        // the transfer function is read once per grid point and the sub-step opacities once per
        // distance, so an entry costs K multiply-adds instead of K evaluations and exponentials.
        let fine = SUB * (n - 1);
        let grid: Vec<([f32; 3], f32)> = (0..fine)
            .map(|j| tf.eval(((j as f64 + 0.5) / fine as f64) as f32))
            .collect();
        let alphas: Vec<Vec<f32>> = (0..n)
            .into_par_iter()
            .map(|d| {
                if d < MIN_GRID_BINS {
                    return Vec::new();
                }
                let h = ds as f64 / substeps(d) as f64;
                grid.iter()
                    .map(|&(_, tau)| -(-(tau as f64) * h).exp_m1() as f32)
                    .collect()
            })
            .collect();
        let mut rgba = vec![[0f32; 4]; n * n];
        rgba.par_chunks_mut(n).enumerate().for_each(|(f, row)| {
            for (b, e) in row.iter_mut().enumerate() {
                let d = f.abs_diff(b);
                if d < MIN_GRID_BINS {
                    *e = integrate_segment(tf, f as f32 / den, b as f32 / den, ds, substeps(d));
                    continue;
                }
                let a = &alphas[d];
                let (mut c, mut trans) = ([0f64; 3], 1f64);
                let mut step = |j: usize| {
                    let (rgb, aj) = (grid[j].0, a[j] as f64);
                    for ch in 0..3 {
                        c[ch] += trans * aj * rgb[ch] as f64;
                    }
                    trans *= 1.0 - aj;
                };
                if b > f {
                    (SUB * f..SUB * b).for_each(&mut step);
                } else {
                    (SUB * b..SUB * f).rev().for_each(&mut step);
                }
                *e = [c[0] as f32, c[1] as f32, c[2] as f32, (1.0 - trans) as f32];
            }
        });
        Ok(Self { n, ds, rgba })
    }

    /// Bilinear lookup at front value `sf` and back value `sb` in `[0, 1]`.
    #[inline]
    pub fn get(&self, sf: f32, sb: f32) -> [f32; 4] {
        let n = self.n;
        let den = (n - 1) as f32;
        let x = sf.clamp(0.0, 1.0) * den;
        let y = sb.clamp(0.0, 1.0) * den;
        let (i, j) = ((x as usize).min(n - 2), (y as usize).min(n - 2));
        let (tx, ty) = (x - i as f32, y - j as f32);
        let e = |a: usize, b: usize| self.rgba[a * n + b];
        let (e00, e01, e10, e11) = (e(i, j), e(i, j + 1), e(i + 1, j), e(i + 1, j + 1));
        std::array::from_fn(|c| {
            let lo = e00[c] + (e01[c] - e00[c]) * ty;
            let hi = e10[c] + (e11[c] - e10[c]) * ty;
            lo + (hi - lo) * tx
        })
    }
}
