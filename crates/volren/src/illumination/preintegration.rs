//! Pre-integrated classification (Engel, Kraus and Ertl 2001; the paper's section 3.1, spec
//! E7): for a segment of length `l` along which the scalar varies linearly from `s_f` to `s_b`,
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

/// Midpoint sub-steps used for a table entry whose endpoints are `bins` apart (E7 asks for
/// `K >= max(16, 4 |b - f|)`; six per transfer-function bin crossed keep a step transfer
/// function within 1e-3 of a 4096-step integration).
fn substeps(bins: usize) -> usize {
    (6 * bins).max(24)
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
    /// own grid (`n = tf.len()`). `O(n^2 K)`, parallel over rows. Errors: `ds` not finite and
    /// positive.
    pub fn build(tf: &TransferFunction, ds: f32) -> Result<Self> {
        if !(ds.is_finite() && ds > 0.0) {
            return Err(Error::invalid(
                "ds",
                format!("segment length must be finite and > 0, got {ds}"),
            ));
        }
        let n = tf.len();
        let den = (n - 1) as f32;
        let mut rgba = vec![[0f32; 4]; n * n];
        rgba.par_chunks_mut(n).enumerate().for_each(|(f, row)| {
            for (b, e) in row.iter_mut().enumerate() {
                let k = substeps(f.abs_diff(b));
                *e = integrate_segment(tf, f as f32 / den, b as f32 / den, ds, k);
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
