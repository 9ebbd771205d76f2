//! Gyro-camera time-delay calibration (paper section 3.1): the mean image shift between
//! consecutive frames, measured by phase correlation, is compared with the shift the gyroscope
//! predicts for a candidate delay `t_d`; the delay that best matches the two curves wins.

use nalgebra::Vector3;
use num_complex::Complex64;
use wscg_math::fft::{fft2, Direction, Norm};
use wscg_math::{Error, Image, Result};

use crate::camera::{Intrinsics, Timing};
use crate::gyro::GyroTrack;
use crate::tiling::check_frame;

/// Translation `(dx, dy)` that takes `a` to `b` (`b(x) ~ a(x - d)`), by phase correlation
/// with a Hann window, refined to 1/20 px by an upsampled DFT around the peak.
///
/// Errors: images of different shapes, multi-channel, empty or non-finite.
pub fn phase_correlation(a: &Image<f32>, b: &Image<f32>) -> Result<(f64, f64)> {
    check_frame(a, "a")?;
    check_frame(b, "b")?;
    a.ensure_same_shape(b)?;
    let (h, w) = (a.height(), a.width());
    let hann = |i: usize, n: usize| {
        0.5 - 0.5 * (2.0 * std::f64::consts::PI * (i as f64 + 0.5) / n as f64).cos()
    };
    let prep = |img: &Image<f32>| -> Vec<Complex64> {
        let mean = img.data().iter().map(|&v| v as f64).sum::<f64>() / (h * w) as f64;
        img.data()
            .iter()
            .enumerate()
            .map(|(i, &v)| Complex64::new((v as f64 - mean) * hann(i / w, h) * hann(i % w, w), 0.0))
            .collect()
    };
    let (mut fa, mut fb) = (prep(a), prep(b));
    fft2(&mut fa, h, w, Direction::Forward, Norm::Backward)?;
    fft2(&mut fb, h, w, Direction::Forward, Norm::Backward)?;
    let mut r: Vec<Complex64> = fa
        .iter()
        .zip(&fb)
        .map(|(x, y)| {
            let c = x.conj() * y;
            let n = c.norm();
            if n > 1e-300 {
                c / n
            } else {
                Complex64::new(0.0, 0.0)
            }
        })
        .collect();
    let spec = r.clone();
    fft2(&mut r, h, w, Direction::Inverse, Norm::Backward)?;
    let (mut best, mut bi) = (f64::NEG_INFINITY, 0);
    for (i, c) in r.iter().enumerate() {
        if c.re > best {
            best = c.re;
            bi = i;
        }
    }
    let (py, px) = (bi / w, bi % w);
    let wrap = |d: usize, n: usize| {
        if 2 * d > n {
            d as f64 - n as f64
        } else {
            d as f64
        }
    };
    Ok(refine_peak(&spec, h, w, wrap(py, h), wrap(px, w)))
}

/// Sub-pixel peak of the correlation `c(y, x) = sum_uv R(u, v) e^{2 pi i (u y / h + v x / w)}`
/// on a grid of 1/20 px over +-1.5 px around the integer peak, by two matrix-multiply DFTs
/// (the upsampled-DFT refinement of Guizar-Sicairos et al. 2008). Returns `(dx, dy)`.
fn refine_peak(spec: &[Complex64], h: usize, w: usize, py: f64, px: f64) -> (f64, f64) {
    const UP: f64 = 20.0;
    let n = 61usize;
    let offs: Vec<f64> = (0..n).map(|i| (i as f64 - 30.0) / UP).collect();
    let freq = |k: usize, len: usize| {
        if 2 * k >= len {
            k as f64 - len as f64
        } else {
            k as f64
        }
    };
    let table = |len: usize, centre: f64| -> Vec<Complex64> {
        let mut t = Vec::with_capacity(len * n);
        for k in 0..len {
            let f = freq(k, len);
            for o in &offs {
                let ph = 2.0 * std::f64::consts::PI * f * (centre + o) / len as f64;
                t.push(Complex64::new(ph.cos(), ph.sin()));
            }
        }
        t
    };
    let (ex, ey) = (table(w, px), table(h, py));
    // a(u, j) = sum_v R(u, v) ex(v, j)
    let mut a = vec![Complex64::new(0.0, 0.0); h * n];
    for u in 0..h {
        let row = &spec[u * w..][..w];
        let out = &mut a[u * n..][..n];
        for (v, &rv) in row.iter().enumerate() {
            let e = &ex[v * n..][..n];
            for (o, &ev) in out.iter_mut().zip(e) {
                *o += rv * ev;
            }
        }
    }
    let mut c = vec![0f64; n * n];
    for i in 0..n {
        for j in 0..n {
            c[i * n + j] = (0..h).map(|u| (ey[u * n + i] * a[u * n + j]).re).sum();
        }
    }
    let bi = (0..n * n)
        .max_by(|&p, &q| c[p].total_cmp(&c[q]))
        .unwrap_or(0);
    let (bi, bj) = (bi / n, bi % n);
    // Parabola through the fine-grid neighbours.
    let vertex = |m: f64, z: f64, p: f64| {
        let d = m - 2.0 * z + p;
        if d < 0.0 {
            (0.5 * (m - p) / d).clamp(-0.5, 0.5)
        } else {
            0.0
        }
    };
    let fx = if bj > 0 && bj + 1 < n {
        vertex(c[bi * n + bj - 1], c[bi * n + bj], c[bi * n + bj + 1])
    } else {
        0.0
    };
    let fy = if bi > 0 && bi + 1 < n {
        vertex(c[(bi - 1) * n + bj], c[bi * n + bj], c[(bi + 1) * n + bj])
    } else {
        0.0
    };
    (px + offs[bj] + fx / UP, py + offs[bi] + fy / UP)
}

/// Image shift of the principal point from frame `a` to frame `b` predicted by the gyroscope
/// between their mid-exposure poses (mid-row, mid-exposure).
pub fn predicted_shift(
    track: &GyroTrack,
    a: &Timing,
    b: &Timing,
    k: &Intrinsics,
) -> Option<(f64, f64)> {
    let mid = |t: &Timing| t.reference() + 0.5 * t.t_exposure;
    let (ta, tb) = (mid(a), mid(b));
    let (lo, hi) = track.span();
    if ta < lo || tb < lo || ta > hi || tb > hi {
        return None;
    }
    // A world point on the principal ray of frame a, seen from the pose of frame b.
    let r = track.relative(tb, ta);
    k.project((r * Vector3::from(k.ray(k.cx, k.cy))).into())
        .map(|(x, y)| (x - k.cx, y - k.cy))
}

/// Estimates the gyro-camera delay `t_d` (paper section 3.1): for candidate delays on a grid
/// of `step` seconds in `range`, the gyro-predicted shifts between consecutive frames
/// (`frame_times[i] -> frame_times[i + 1]`, timing otherwise from `timing`) are compared with
/// the measured `image_shifts[i]` (e.g. from [`phase_correlation`]) by their squared
/// difference; the best candidate is refined by a parabola through its neighbours.
///
/// Errors: `image_shifts.len() != frame_times.len() - 1`, fewer than 3 frames, an empty or
/// reversed range, a non-positive step, no candidate delay with at least half of the frame
/// pairs inside the gyroscope trace.
pub fn estimate_time_delay(
    track: &GyroTrack,
    frame_times: &[f64],
    image_shifts: &[(f64, f64)],
    timing: &Timing,
    k: &Intrinsics,
    range: (f64, f64),
    step: f64,
) -> Result<f64> {
    if frame_times.len() < 3 {
        return Err(Error::invalid("frame_times", "need at least 3 frames"));
    }
    if image_shifts.len() + 1 != frame_times.len() {
        return Err(Error::ShapeMismatch(format!(
            "{} frames need {} shifts, got {}",
            frame_times.len(),
            frame_times.len() - 1,
            image_shifts.len()
        )));
    }
    if !(range.0.is_finite() && range.1.is_finite() && range.0 < range.1 && step > 0.0) {
        return Err(Error::invalid(
            "range",
            "need a finite range lo < hi and step > 0",
        ));
    }
    timing.validate()?;
    k.validate()?;
    let n = ((range.1 - range.0) / step).floor() as usize + 1;
    if n > 1_000_000 {
        return Err(Error::LimitExceeded(format!("{n} candidate delays")));
    }
    let cost = |d: f64| -> Option<f64> {
        let mut s = 0.0;
        let mut used = 0usize;
        for (i, m) in image_shifts.iter().enumerate() {
            let ta = Timing {
                t_frame: frame_times[i],
                t_delay: d,
                ..*timing
            };
            let tb = Timing {
                t_frame: frame_times[i + 1],
                t_delay: d,
                ..*timing
            };
            if let Some(p) = predicted_shift(track, &ta, &tb, k) {
                s += (p.0 - m.0).powi(2) + (p.1 - m.1).powi(2);
                used += 1;
            }
        }
        (2 * used >= image_shifts.len()).then(|| s / used as f64)
    };
    let costs: Vec<Option<f64>> = (0..n).map(|i| cost(range.0 + i as f64 * step)).collect();
    let (bi, bc) = costs
        .iter()
        .enumerate()
        .filter_map(|(i, c)| c.map(|c| (i, c)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or_else(|| {
            Error::invalid(
                "gyro",
                "the gyroscope trace does not cover the frames for any delay in the range",
            )
        })?;
    let mut d = range.0 + bi as f64 * step;
    if bi > 0 && bi + 1 < n {
        if let (Some(m), Some(p)) = (costs[bi - 1], costs[bi + 1]) {
            let den = m - 2.0 * bc + p;
            if den > 0.0 {
                d += step * (0.5 * (m - p) / den).clamp(-0.5, 0.5);
            }
        }
    }
    Ok(d)
}
