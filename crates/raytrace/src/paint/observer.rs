//! The virtual observer: an objective stand-in for the paper's 26 human observers, so that the
//! "virtual material workshop" loop (render, compare with the reference, fit a response
//! surface, read off the best microstructure) can be run and tested without people. It is our
//! addition (the paper's scores are human similarity judgements, 0 = identical to the
//! photograph ... 10 = different).
//!
//! Features of a rendered luminance image: glint density (connected groups of pixels brighter
//! than 4x the median, per mm²), mean luminance, the 99th percentile over the median, and the
//! mean glint area; for a stereo pair also the binocular overlap of the glinting flakes. The
//! distance between a candidate and the reference is the Euclidean norm of the differences of
//! the features' logarithms, each divided by its spread over renders of the reference with
//! different seeds (floored at a just-noticeable difference); the score is
//! `10 (1 - exp(-D / 3))`.

use wscg_math::{Error, ImageView, Result};

use super::render::XyzImage;

/// Sparkle statistics of one luminance image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlintStats {
    /// Connected glints (8-connected pixels above the threshold) per mm² of plate.
    pub glint_density_per_mm2: f64,
    /// Mean luminance.
    pub mean_y: f64,
    /// Median luminance.
    pub median_y: f64,
    /// 99th percentile over the median (infinite when the median is 0).
    pub y99_over_median: f64,
    /// Mean area of a glint (mm²); 0 without glints.
    pub mean_glint_area_mm2: f64,
    /// Mean of the glints' brightest pixels; 0 without glints.
    pub mean_glint_peak_y: f64,
    /// Number of glints.
    pub glints: usize,
    /// Luminance threshold used: 4x the median, or any positive luminance when the median is 0.
    pub threshold: f64,
}

/// Sparkle statistics of the single-channel luminance image `y` whose pixels are
/// `mm_per_px` wide on the plate.
///
/// Errors: more than one channel, a non-finite or negative luminance, a non-positive pixel
/// size.
pub fn glint_stats(y: ImageView<'_, f32>, mm_per_px: f64) -> Result<GlintStats> {
    y.ensure_plane("y")?;
    let (width, height, y) = (y.width(), y.height(), y.data());
    wscg_math::error::ensure_positive("mm_per_px", mm_per_px)?;
    if let Some(index) = y.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(Error::NonFinite { name: "y", index });
    }
    let mut sorted: Vec<f32> = y.to_vec();
    sorted.sort_unstable_by(f32::total_cmp);
    let q = |p: f64| {
        let k = ((sorted.len() - 1) as f64 * p).round() as usize;
        sorted[k] as f64
    };
    let median = q(0.5);
    let y99 = q(0.99);
    let mean = y.iter().map(|&v| v as f64).sum::<f64>() / y.len() as f64;
    let threshold = 4.0 * median;
    let (glints, pixels, peaks) = components(y, width, height, threshold as f32);
    let area_mm2 = (width * height) as f64 * mm_per_px * mm_per_px;
    Ok(GlintStats {
        glint_density_per_mm2: glints as f64 / area_mm2,
        mean_y: mean,
        median_y: median,
        y99_over_median: if median > 0.0 {
            y99 / median
        } else {
            f64::INFINITY
        },
        mean_glint_area_mm2: if glints > 0 {
            pixels as f64 / glints as f64 * mm_per_px * mm_per_px
        } else {
            0.0
        },
        mean_glint_peak_y: if glints > 0 {
            peaks / glints as f64
        } else {
            0.0
        },
        glints,
        threshold,
    })
}

/// Number of 8-connected groups of pixels above `threshold`, their total pixel count and the
/// sum of their peak values.
fn components(y: &[f32], w: usize, h: usize, threshold: f32) -> (usize, usize, f64) {
    let mut seen = vec![false; y.len()];
    let mut stack = Vec::new();
    let (mut groups, mut pixels, mut peaks) = (0, 0, 0.0);
    for start in 0..y.len() {
        if seen[start] || y[start] <= threshold {
            continue;
        }
        groups += 1;
        seen[start] = true;
        stack.push(start);
        let mut peak = 0.0f32;
        while let Some(p) = stack.pop() {
            pixels += 1;
            peak = peak.max(y[p]);
            let (px, py) = ((p % w) as isize, (p / w) as isize);
            for dy in -1..=1isize {
                for dx in -1..=1isize {
                    let (x, yy) = (px + dx, py + dy);
                    if x < 0 || yy < 0 || x >= w as isize || yy >= h as isize {
                        continue;
                    }
                    let q = yy as usize * w + x as usize;
                    if !seen[q] && y[q] > threshold {
                        seen[q] = true;
                        stack.push(q);
                    }
                }
            }
        }
        peaks += peak as f64;
    }
    (groups, pixels, peaks)
}

/// Binocular overlap of two sets of glinting flakes (sorted or not): `2 |L ∩ R| / (|L| + |R|)`
/// (the Dice coefficient); 0 when both are empty. With equal set sizes it is the fraction of
/// one eye's glints that the other eye sees too.
pub fn binocular_overlap(left_ids: &[u64], right_ids: &[u64]) -> f64 {
    if left_ids.is_empty() && right_ids.is_empty() {
        return 0.0;
    }
    let mut l = left_ids.to_vec();
    let mut r = right_ids.to_vec();
    l.sort_unstable();
    l.dedup();
    r.sort_unstable();
    r.dedup();
    let (mut i, mut j, mut common) = (0, 0, 0usize);
    while i < l.len() && j < r.len() {
        match l[i].cmp(&r[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                common += 1;
                i += 1;
                j += 1;
            }
        }
    }
    2.0 * common as f64 / (l.len() + r.len()) as f64
}

/// The viewing condition of the study.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Condition {
    /// The cyclopean image shown to both eyes.
    Mono,
    /// The left and right images of the off-axis rig.
    Stereo,
}

/// Names of the features [`features`] returns, in order.
pub const FEATURE_NAMES: [&str; 5] = [
    "glint density",
    "mean luminance",
    "mean glint peak / lamp",
    "mean glint area",
    "binocular overlap",
];

/// The observer's feature vector of a view: for [`Condition::Mono`] four sparkle statistics
/// of the cyclopean image (glint density, mean luminance, the glints' mean peak luminance
/// over the lamp's, the mean glint area); for [`Condition::Stereo`] their means over the
/// two eyes and the binocular overlap of the glinting flakes. Every feature is floored at a
/// tiny positive value so that its logarithm exists.
///
/// Sparkle contrast is measured by the glints' peak luminance rather than a percentile ratio
/// such as `Y99 / median`: with mirror flakes under a small lamp most pixels are black, the
/// median is 0 and the ratio is undefined, while the peak grows with the share of a pixel one
/// flake covers, a cue to the flake size.
///
/// Errors: a stereo condition without a right image, images of different sizes, bad
/// luminances ([`glint_stats`]).
pub fn features(first: &XyzImage, right: Option<&XyzImage>) -> Result<Vec<f64>> {
    let stats = |im: &XyzImage| glint_stats(im.luminance().view(), im.mm_per_px);
    let a = stats(first)?;
    let pack = |s: &GlintStats, lamp_y: f64| {
        [
            s.glint_density_per_mm2,
            s.mean_y,
            s.mean_glint_peak_y / lamp_y,
            s.mean_glint_area_mm2,
        ]
    };
    let floor = |v: f64| v.max(1e-9);
    match right {
        None => Ok(pack(&a, first.lamp_y).iter().map(|&v| floor(v)).collect()),
        Some(r) => {
            if (r.width, r.height) != (first.width, first.height) {
                return Err(Error::ShapeMismatch(format!(
                    "left image {} x {}, right image {} x {}",
                    first.width, first.height, r.width, r.height
                )));
            }
            let b = stats(r)?;
            let (pa, pb) = (pack(&a, first.lamp_y), pack(&b, r.lamp_y));
            let mut f: Vec<f64> = (0..4).map(|k| floor(0.5 * (pa[k] + pb[k]))).collect();
            f.push(floor(binocular_overlap(&first.glint_ids, &r.glint_ids)));
            Ok(f)
        }
    }
}

/// The virtual observer, calibrated on renders of the reference plate.
#[derive(Clone, Debug, PartialEq)]
pub struct VirtualObserver {
    /// Mean of the log features over the reference renders.
    pub mean_log: Vec<f64>,
    /// Scale of each log feature: its standard deviation over the reference renders, but at
    /// least the just-noticeable difference given to [`VirtualObserver::calibrate`].
    pub std_log: Vec<f64>,
}

/// Default just-noticeable difference of a feature, in log units (0.25: a change of about
/// 28 %; Weber fractions of numerosity and brightness judgements are 0.1-0.3).
pub const DEFAULT_JND_LOG: f64 = 0.25;

impl VirtualObserver {
    /// Calibrates on the feature vectors of at least two renders of the reference plate
    /// (different seeds). Each feature's scale is its spread over the references, floored at
    /// `jnd_log` (log units): the render noise of a 10 mm patch is far below what an observer
    /// notices, and scaling by the noise alone saturates every score near 10.
    ///
    /// Errors: fewer than two references, vectors of different lengths, non-positive or
    /// non-finite features, a negative or non-finite `jnd_log`.
    pub fn calibrate(references: &[Vec<f64>], jnd_log: f64) -> Result<Self> {
        if !(jnd_log.is_finite() && jnd_log >= 0.0) {
            return Err(Error::invalid(
                "jnd_log",
                format!("must be finite and >= 0, got {jnd_log}"),
            ));
        }
        if references.len() < 2 {
            return Err(Error::invalid(
                "references",
                format!(
                    "at least two reference renders are needed, got {}",
                    references.len()
                ),
            ));
        }
        let m = references[0].len();
        wscg_math::error::ensure_nonempty("references[0]", m)?;
        let logs = references
            .iter()
            .map(|f| log_features(f, m))
            .collect::<Result<Vec<_>>>()?;
        let n = logs.len() as f64;
        let mean_log: Vec<f64> = (0..m)
            .map(|k| logs.iter().map(|l| l[k]).sum::<f64>() / n)
            .collect();
        let std_log = (0..m)
            .map(|k| {
                let v = logs
                    .iter()
                    .map(|l| (l[k] - mean_log[k]).powi(2))
                    .sum::<f64>()
                    / (n - 1.0);
                v.sqrt().max(jnd_log).max(1e-3)
            })
            .collect();
        Ok(Self { mean_log, std_log })
    }

    /// `D = || (log f - mean log f_ref) / s ||_2`.
    ///
    /// Errors: a vector of another length, non-positive or non-finite features.
    pub fn distance(&self, f: &[f64]) -> Result<f64> {
        let l = log_features(f, self.mean_log.len())?;
        Ok(l.iter()
            .zip(&self.mean_log)
            .zip(&self.std_log)
            .map(|((a, b), s)| ((a - b) / s).powi(2))
            .sum::<f64>()
            .sqrt())
    }

    /// Similarity score on the paper's scale: `10 (1 - exp(-D / 3))`, 0 = identical.
    pub fn score(&self, f: &[f64]) -> Result<f64> {
        Ok(10.0 * (1.0 - (-self.distance(f)? / 3.0).exp()))
    }
}

fn log_features(f: &[f64], m: usize) -> Result<Vec<f64>> {
    if f.len() != m {
        return Err(Error::ShapeMismatch(format!(
            "feature vector of length {}, expected {m}",
            f.len()
        )));
    }
    f.iter()
        .enumerate()
        .map(|(i, &v)| {
            if v.is_finite() && v > 0.0 {
                Ok(v.ln())
            } else {
                Err(Error::invalid(
                    "features",
                    format!("feature {i} must be finite and > 0, got {v}"),
                ))
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glints_are_connected_groups_above_four_medians() {
        // 6 x 4 image, background 1, two glints: a 2-pixel diagonal pair and a single pixel.
        let mut y = vec![1.0f32; 24];
        y[0] = 10.0;
        y[7] = 9.0; // diagonal neighbour of 0: same glint
        y[5] = 4.5;
        let s = glint_stats(ImageView::plane(4, 6, &y).unwrap(), 0.5).unwrap();
        assert_eq!(s.glints, 2);
        assert!((s.glint_density_per_mm2 - 2.0 / 6.0).abs() < 1e-12);
        assert!((s.mean_glint_area_mm2 - 1.5 * 0.25).abs() < 1e-12);
        assert_eq!(s.median_y, 1.0);
        assert!(glint_stats(ImageView::new(4, 3, 2, &y).unwrap(), 0.5).is_err());
        assert!(glint_stats(ImageView::plane(1, 1, &[f32::NAN]).unwrap(), 0.5).is_err());
    }

    #[test]
    fn overlap_is_dice() {
        assert_eq!(binocular_overlap(&[1, 2, 3, 4], &[3, 4, 5, 6]), 0.5);
        assert_eq!(binocular_overlap(&[], &[]), 0.0);
        assert_eq!(binocular_overlap(&[7, 7, 8], &[8, 7]), 1.0);
    }

    #[test]
    fn observer_scores_zero_at_the_reference_mean() {
        let refs = vec![vec![1.0, 2.0], vec![1.2, 1.8], vec![0.9, 2.2]];
        let o = VirtualObserver::calibrate(&refs, 0.0).unwrap();
        let centre: Vec<f64> = o.mean_log.iter().map(|l| l.exp()).collect();
        assert!(o.score(&centre).unwrap().abs() < 1e-12);
        let far = o.score(&[10.0, 20.0]).unwrap();
        assert!(far > 9.0 && far < 10.0);
        assert!(o.distance(&[1.0]).is_err());
        assert!(VirtualObserver::calibrate(&refs[..1], 0.0).is_err());
    }
}
