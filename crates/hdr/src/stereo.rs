//! The stereo-matching baseline (in the style of Bätz et al. 2014, the paper's Fig. 1b):
//! zero-mean normalised cross-correlation of grey radiance windows, winner-take-all over the
//! disparity range, a left-right consistency check, and invalid pixels filled from the
//! nearest valid disparity of their row on the background side.

use rayon::prelude::*;
use wscg_math::{Error, Image, Result};

use crate::nnf::Nnf;
use crate::pm::check_pair;

wscg_math::params! {
    /// Parameters of [`zncc_stereo`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct StereoParams {
        /// Window side (odd, `>= 3`).
        pub window: usize,
        /// Smallest horizontal offset `d` (pixel `x` of `A` matches `x + d` of `B`).
        pub d_min: i32,
        /// Largest horizontal offset.
        pub d_max: i32,
        /// Left-right consistency tolerance `|d_AB + d_BA| <= tol`.
        pub lr_tol: i32,
    }
}

impl Default for StereoParams {
    fn default() -> Self {
        Self {
            window: 9,
            d_min: -64,
            d_max: 64,
            lr_tol: 1,
        }
    }
}

impl StereoParams {
    /// Checks the ranges: `window` odd and `>= 3`, `d_min <= d_max`, `lr_tol >= 0` (the
    /// bounds set by the image size are checked by [`StereoParams::validate_for`]).
    pub fn validate(&self) -> Result<()> {
        if self.window < 3 || self.window.is_multiple_of(2) {
            return Err(Error::invalid(
                "window",
                format!("must be odd and >= 3, got {}", self.window),
            ));
        }
        if self.lr_tol < 0 {
            return Err(Error::invalid(
                "lr_tol",
                format!("must be >= 0, got {}", self.lr_tol),
            ));
        }
        if self.d_min > self.d_max {
            return Err(Error::invalid(
                "d_min",
                format!("d_min = {} > d_max = {}", self.d_min, self.d_max),
            ));
        }
        Ok(())
    }

    /// [`StereoParams::validate`], then the bounds for images of `(height, width)`: the
    /// window fits and every `|d|` is below the width.
    pub fn validate_for(&self, height: usize, width: usize) -> Result<()> {
        self.validate()?;
        if self.window > height.min(width) {
            return Err(Error::invalid(
                "window",
                format!(
                    "must be <= min(height, width) = {}, got {}",
                    height.min(width),
                    self.window
                ),
            ));
        }
        if self.d_min.unsigned_abs().max(self.d_max.unsigned_abs()) as usize >= width {
            return Err(Error::invalid(
                "max_disparity",
                format!("|disparity| must be < the image width {width}"),
            ));
        }
        Ok(())
    }
}

/// Grey image (channel mean), padded by `pad` replicated pixels on every side.
fn grey_padded(img: &Image<f32>, pad: usize) -> (Vec<f32>, usize) {
    let (h, w, c) = img.shape();
    let pw = w + 2 * pad;
    let mut out = vec![0f32; (h + 2 * pad) * pw];
    out.par_chunks_mut(pw).enumerate().for_each(|(py, row)| {
        let y = py.saturating_sub(pad).min(h - 1);
        for (px, o) in row.iter_mut().enumerate() {
            let x = px.saturating_sub(pad).min(w - 1);
            *o = img.pixel(y, x).iter().sum::<f32>() / c as f32;
        }
    });
    (out, pw)
}

/// Window mean and standard deviation at every pixel of a padded grey image.
fn window_stats(g: &[f32], pw: usize, h: usize, w: usize, half: usize) -> Vec<(f32, f32)> {
    let n = ((2 * half + 1) * (2 * half + 1)) as f64;
    let mut out = vec![(0f32, 0f32); h * w];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let (mut s, mut s2) = (0f64, 0f64);
            for r in y..=y + 2 * half {
                for &v in &g[r * pw + x..=r * pw + x + 2 * half] {
                    s += v as f64;
                    s2 += v as f64 * v as f64;
                }
            }
            let m = s / n;
            *o = (m as f32, (s2 / n - m * m).max(0.0).sqrt() as f32);
        }
    });
    out
}

/// Winner-take-all ZNCC disparity from `ga` to `gb` (padded greys): per pixel the `d` in
/// `[d_min, d_max]` (source centre inside `B`) of largest correlation, and `1 - zncc`.
#[allow(clippy::too_many_arguments)]
fn wta(
    ga: &[f32],
    gb: &[f32],
    sa: &[(f32, f32)],
    sb: &[(f32, f32)],
    pw: usize,
    h: usize,
    w: usize,
    half: usize,
    d_min: i32,
    d_max: i32,
) -> Vec<(i32, f32)> {
    let win = 2 * half + 1;
    let n = (win * win) as f32;
    let mut out = vec![(0i32, f32::INFINITY); h * w];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let mut col = vec![0f32; pw];
        for d in d_min..=d_max {
            let xlo = (-d).max(0) as usize;
            let xhi = (w as i32 - 1 - d).min(w as i32 - 1);
            if xhi < xlo as i32 {
                continue;
            }
            let xhi = xhi as usize;
            // Column sums of A * B(shifted) over the window rows, padded columns.
            for pc in xlo..=xhi + 2 * half {
                let pcb = (pc as i64 + d as i64) as usize;
                let mut s = 0f32;
                for r in y..y + win {
                    s += ga[r * pw + pc] * gb[r * pw + pcb];
                }
                col[pc] = s;
            }
            let mut acc: f32 = col[xlo..xlo + win].iter().sum();
            for x in xlo..=xhi {
                if x > xlo {
                    acc += col[x + 2 * half] - col[x - 1];
                }
                let (ma, da) = sa[y * w + x];
                let (mb, db) = sb[y * w + (x as i32 + d) as usize];
                let den = da * db;
                let z = if den > 1e-12 * (ma.abs() * mb.abs()).max(1e-30) {
                    (acc / n - ma * mb) / den
                } else {
                    0.0
                };
                let cost = 1.0 - z;
                if cost < row[x].1 {
                    row[x] = (d, cost);
                }
            }
        }
    });
    out
}

/// Disparity field from `a` to `b` by the ZNCC stereo baseline: winner-take-all in both
/// directions, pixels failing `|d_AB(x) + d_BA(x + d_AB(x))| <= lr_tol` replaced by the
/// nearer valid disparity of their row with the smaller `|d|` (the background side, where
/// occlusions live); a row without valid pixels keeps its winner-take-all values. Costs are
/// `1 - zncc` of the winner (before filling). Images must have the same shape.
///
/// Errors: shapes or channels differ; even or too large window; `d_min > d_max`;
/// `|d| >= width`; non-finite values.
pub fn zncc_stereo(a: &Image<f32>, b: &Image<f32>, p: &StereoParams) -> Result<Nnf> {
    p.validate()?;
    check_pair(a, b)?;
    if a.shape() != b.shape() {
        return Err(Error::ShapeMismatch(format!(
            "stereo views are {:?} and {:?}",
            a.shape(),
            b.shape()
        )));
    }
    let (h, w, _) = a.shape();
    p.validate_for(h, w)?;
    let half = p.window / 2;
    let (ga, pw) = grey_padded(a, half);
    let (gb, _) = grey_padded(b, half);
    let sa = window_stats(&ga, pw, h, w, half);
    let sb = window_stats(&gb, pw, h, w, half);
    let ab = wta(&ga, &gb, &sa, &sb, pw, h, w, half, p.d_min, p.d_max);
    let ba = wta(&gb, &ga, &sb, &sa, pw, h, w, half, -p.d_max, -p.d_min);
    let mut off = vec![[0i32; 2]; h * w];
    off.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let valid: Vec<bool> = (0..w)
            .map(|x| {
                let d = ab[y * w + x].0;
                let xb = x as i32 + d;
                (0..w as i32).contains(&xb) && (d + ba[y * w + xb as usize].0).abs() <= p.lr_tol
            })
            .collect();
        let any = valid.iter().any(|&v| v);
        // Nearest valid disparity to the left and to the right of every pixel.
        let mut left = vec![None; w];
        let mut last = None;
        for x in 0..w {
            if valid[x] {
                last = Some(ab[y * w + x].0);
            }
            left[x] = last;
        }
        let mut next = None;
        for x in (0..w).rev() {
            if valid[x] {
                next = Some(ab[y * w + x].0);
            }
            let d = if valid[x] || !any {
                ab[y * w + x].0
            } else {
                match (left[x], next) {
                    (Some(l), Some(r)) => {
                        if l.abs() <= r.abs() {
                            l
                        } else {
                            r
                        }
                    }
                    (Some(v), None) | (None, Some(v)) => v,
                    (None, None) => unreachable!("row has a valid pixel"),
                }
            };
            let d = d.clamp(-(x as i32), w as i32 - 1 - x as i32);
            row[x] = [d, 0];
        }
    });
    let cost = ab.iter().map(|v| v.1).collect();
    Nnf::new(h, w, off, cost)
}
