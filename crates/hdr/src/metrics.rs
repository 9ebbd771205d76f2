//! Quality measures of the multiscopic pipeline: log-radiance error, bad-pixel rates of a
//! field against true disparities, the coherence of a field, and the error of a recovered
//! camera response.

use wscg_math::{Error, Image, Result};

use crate::crf::Crf;
use crate::nnf::Nnf;

/// Largest `|ln f(z) - ln f_true(z / z_max)|` over the codes `codes` and every channel of
/// `crf`, with `truth` the true inverse response of the normalised code. With
/// `free_offset`, each channel's mean difference is removed first (a response known only up
/// to scale, as Debevec-Malik's).
pub fn response_log_error(
    crf: &Crf,
    truth: impl Fn(f64) -> f64,
    codes: std::ops::RangeInclusive<u16>,
    free_offset: bool,
) -> f64 {
    let zmax = crf.z_max() as f64;
    (0..crf.channels())
        .map(|c| {
            let d: Vec<f64> = codes
                .clone()
                .map(|z| (crf.inv(z, c) as f64).ln() - truth(z as f64 / zmax).ln())
                .collect();
            let off = if free_offset {
                d.iter().sum::<f64>() / d.len().max(1) as f64
            } else {
                0.0
            };
            d.iter().map(|v| (v - off).abs()).fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

/// `sqrt(mean((log2 est - log2 gt)^2))` over the pixel-channels where `mask` holds (all
/// when `None`; `mask` has one entry per pixel-channel). Non-positive estimates count as
/// the smallest positive `f32`.
///
/// Errors: shapes differ; mask of the wrong length; empty mask; non-positive truth.
pub fn rmse_log2(est: &Image<f32>, gt: &Image<f32>, mask: Option<&[bool]>) -> Result<f64> {
    if est.shape() != gt.shape() {
        return Err(Error::ShapeMismatch(format!(
            "estimate {:?} vs truth {:?}",
            est.shape(),
            gt.shape()
        )));
    }
    if let Some(m) = mask {
        if m.len() != gt.data().len() {
            return Err(Error::ShapeMismatch(format!(
                "mask has {} entries for {} pixel-channels",
                m.len(),
                gt.data().len()
            )));
        }
    }
    let (mut s, mut n) = (0f64, 0usize);
    for (i, (&e, &g)) in est.data().iter().zip(gt.data()).enumerate() {
        if mask.is_some_and(|m| !m[i]) {
            continue;
        }
        if g.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(Error::invalid("gt", "true radiance must be > 0"));
        }
        let e = if e > 0.0 { e } else { f32::MIN_POSITIVE };
        let d = (e as f64).log2() - (g as f64).log2();
        s += d * d;
        n += 1;
    }
    if n == 0 {
        return Err(Error::invalid("mask", "selects no pixels"));
    }
    Ok((s / n as f64).sqrt())
}

/// Fraction of pixels whose horizontal offset differs from `truth` by more than `k` pixels,
/// over pixels with a finite truth (NaN: unknown) where `mask` holds (one entry per pixel).
///
/// Errors: `truth` or `mask` of the wrong length; no pixel to rate.
pub fn bad_rate(nnf: &Nnf, truth: &[f32], k: f32, mask: Option<&[bool]>) -> Result<f64> {
    let n = nnf.width() * nnf.height();
    if truth.len() != n || mask.is_some_and(|m| m.len() != n) {
        return Err(Error::ShapeMismatch(format!(
            "the field has {n} pixels; truth has {} and the mask {:?}",
            truth.len(),
            mask.map(|m| m.len())
        )));
    }
    let (mut bad, mut cnt) = (0usize, 0usize);
    for i in 0..n {
        if !truth[i].is_finite() || mask.is_some_and(|m| !m[i]) {
            continue;
        }
        cnt += 1;
        if (nnf.off[i][0] as f32 - truth[i]).abs() > k || nnf.off[i][1] != 0 {
            bad += 1;
        }
    }
    if cnt == 0 {
        return Err(Error::invalid("truth", "no pixel with a known disparity"));
    }
    Ok(bad as f64 / cnt as f64)
}

/// Incoherence of a field: the fraction of pixels whose offset differs from the median of
/// their `3 x 3` neighbourhood (per component, clipped at the borders) by more than 1 px.
pub fn incoherence(nnf: &Nnf) -> f64 {
    let (h, w) = (nnf.height(), nnf.width());
    if h * w == 0 {
        return 0.0;
    }
    let mut bad = 0usize;
    let mut buf = Vec::with_capacity(9);
    for y in 0..h {
        for x in 0..w {
            let o = nnf.at(y, x);
            let mut off_median = false;
            for (comp, &oc) in o.iter().enumerate() {
                buf.clear();
                for yy in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                    for xx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                        buf.push(nnf.at(yy, xx)[comp]);
                    }
                }
                buf.sort_unstable();
                let m = buf[buf.len() / 2];
                off_median |= (oc - m).abs() > 1;
            }
            bad += usize::from(off_median);
        }
    }
    bad as f64 / (h * w) as f64
}

/// Which pixels of a synthetic view an evaluation covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Region {
    /// Surface points seen by every view.
    SeenByAll,
    /// Points seen by at least two views but not by all (the occluded bands).
    Occluded,
    /// Points seen by at least two views.
    SeenByTwo,
}

/// The evaluation mask of view `k` of a synthetic scene (one entry per pixel-channel): the
/// surface point lies in `region` and, in at least one view that sees it, the channel is
/// well exposed (`10 <= Z <= 245` of 255, scaled to the bit depth; noiseless codes).
pub fn evaluation_mask(scene: &crate::synth::SynthScene, k: usize, region: Region) -> Vec<bool> {
    let e = &scene.radiance[k];
    let (h, w, c) = e.shape();
    let n = scene.views.len() as u32;
    let zmax = scene.crf.z_max() as f64;
    let (lo, hi) = (10.0 / 255.0 * zmax, 245.0 / 255.0 * zmax);
    let mut mask = vec![false; h * w * c];
    for i in 0..h * w {
        let seen = scene.seen_by[k][i];
        let cnt = seen.count_ones();
        let inside = match region {
            Region::SeenByAll => cnt == n,
            Region::Occluded => (2..n).contains(&cnt),
            Region::SeenByTwo => cnt >= 2,
        };
        if !inside {
            continue;
        }
        for ch in 0..c {
            // The same radiance reaches every camera that sees the point.
            let v = e.data()[i * c + ch] as f64;
            mask[i * c + ch] = scene.times.iter().enumerate().any(|(j, &t)| {
                let z = scene.response.forward(v * t) * zmax;
                seen & (1 << j) != 0 && (lo..=hi).contains(&z)
            });
        }
    }
    mask
}
