//! Quality measures of a completion (paper 06, section 4): SSIM restricted to the missing
//! region (the paper's 0.9063 on "Old town cross"), PSNR over the hole, and temporal flicker.

use rayon::prelude::*;
use wscg_math::metrics::{ssim_map_plane, SsimParams};
use wscg_math::{Error, ImageView, Result};

use crate::video::{Mask3, Video};

/// The SSIM parameters of the paper's measure: Wang et al. 2004, Gaussian window of sigma 1.5
/// (11 x 11), `K1 = 0.01`, `K2 = 0.03`, data range 255.
pub fn ssim_params() -> SsimParams {
    SsimParams::default().data_range(255.0)
}

fn check(a: &Video, b: &Video, hole: &Mask3) -> Result<usize> {
    a.check_same(b)?;
    a.check_mask(hole)?;
    let n = hole.count();
    if n == 0 {
        return Err(Error::invalid(
            "mask",
            "the mask is empty: nothing to measure",
        ));
    }
    Ok(n)
}

/// Mean SSIM over the hole pixels: per frame and channel the full-frame SSIM map, averaged over
/// channels, then over the hole pixels at least the window radius (5) from the frame border
/// (the region scikit-image averages; with an all-true mask this is
/// `skimage.metrics.structural_similarity(..., gaussian_weights=True, sigma=1.5,
/// use_sample_covariance=False, data_range=255)`). A hole lying entirely in the border band
/// is averaged as it is.
///
/// Errors: shapes differ, empty mask, frames smaller than the window.
pub fn ssim_masked(a: &Video, b: &Video, hole: &Mask3) -> Result<f64> {
    check(a, b, hole)?;
    let p = ssim_params();
    let r = (p.truncate * p.sigma + 0.5) as usize;
    let (h, w, c) = (a.height, a.width, a.channels);
    let per_frame: Vec<(f64, usize, f64, usize)> = (0..a.frames)
        .into_par_iter()
        .map(|t| {
            if !hole.frame_any(t) {
                return Ok((0.0, 0, 0.0, 0));
            }
            let mut mean_map = vec![0.0; h * w];
            for k in 0..c {
                let plane = |v: &Video| -> Vec<f64> {
                    v.frame(t)
                        .iter()
                        .skip(k)
                        .step_by(c)
                        .map(|&x| x as f64)
                        .collect()
                };
                let (pa, pb) = (plane(a), plane(b));
                let map = ssim_map_plane(
                    ImageView::plane(h, w, &pa)?,
                    ImageView::plane(h, w, &pb)?,
                    &p,
                )?;
                for (m, v) in mean_map.iter_mut().zip(map.data()) {
                    *m += v / c as f64;
                }
            }
            let (mut inner, mut ni, mut all, mut na) = (0.0, 0, 0.0, 0);
            for y in 0..h {
                for x in 0..w {
                    if hole.contains([t as u32, y as u32, x as u32]) {
                        let v = mean_map[y * w + x];
                        all += v;
                        na += 1;
                        if y >= r && x >= r && y + r < h && x + r < w {
                            inner += v;
                            ni += 1;
                        }
                    }
                }
            }
            Ok((inner, ni, all, na))
        })
        .collect::<Result<_>>()?;
    let (inner, ni, all, na) = per_frame.iter().fold((0.0, 0, 0.0, 0), |s, v| {
        (s.0 + v.0, s.1 + v.1, s.2 + v.2, s.3 + v.3)
    });
    Ok(if ni > 0 {
        inner / ni as f64
    } else {
        all / na as f64
    })
}

/// PSNR (dB, data range 255) over the hole pixels and channels; infinite when equal there.
///
/// Errors: shapes differ, empty mask.
pub fn psnr_masked(a: &Video, b: &Video, hole: &Mask3) -> Result<f64> {
    let n = check(a, b, hole)?;
    let sse: f64 = hole
        .points()
        .par_iter()
        .map(|&p| {
            a.pixel(p)
                .iter()
                .zip(b.pixel(p))
                .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
                .sum::<f64>()
        })
        .sum();
    let mse = sse / (n * a.channels) as f64;
    Ok(if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    })
}

/// Temporal flicker: the mean absolute change `|V_{t+1} - V_t|` (grey levels, averaged over
/// channels) over the pixel positions in the hole at `t` or `t + 1`, over all consecutive
/// frame pairs. 0 for a static completion of a static scene.
///
/// Errors: mask shape, empty mask, a single frame.
pub fn flicker(v: &Video, hole: &Mask3) -> Result<f64> {
    v.check_mask(hole)?;
    if v.frames < 2 {
        return Err(Error::invalid("video", "flicker needs at least 2 frames"));
    }
    let (h, w, c) = (v.height, v.width, v.channels);
    let (sum, n) = (0..v.frames - 1)
        .into_par_iter()
        .map(|t| {
            let (mut s, mut n) = (0.0f64, 0usize);
            for y in 0..h {
                for x in 0..w {
                    let (p, q) = (
                        [t as u32, y as u32, x as u32],
                        [t as u32 + 1, y as u32, x as u32],
                    );
                    if hole.contains(p) || hole.contains(q) {
                        s += v
                            .pixel(p)
                            .iter()
                            .zip(v.pixel(q))
                            .map(|(&a, &b)| (a as f64 - b as f64).abs())
                            .sum::<f64>()
                            / c as f64;
                        n += 1;
                    }
                }
            }
            (s, n)
        })
        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    if n == 0 {
        return Err(Error::invalid(
            "mask",
            "the mask is empty: nothing to measure",
        ));
    }
    Ok(sum / n as f64)
}
