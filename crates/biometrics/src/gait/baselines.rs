//! The baselines of paper 17's Table 1 and the ablations of our robustness checks.
//!
//! - Ball et al. 2012 ([`ball_features`]): {mean, std, max} over the cycle of six lower-body
//!   joint angles. Their two-page paper does not define the angles; our reading: hip = angle
//!   between the trunk (SpineMid − SpineBase) and the thigh (Knee − Hip); knee = angle at the
//!   knee between (Hip − Knee) and (Ankle − Knee); ankle = angle at the ankle between
//!   (Knee − Ankle) and (Foot − Ankle).
//! - Preis et al. 2012 ([`preis_features`]): 13 anthropometric and step features, each bone
//!   length the per-frame median over the cycle. Their best classifier was Naive Bayes
//!   ([`GaussianNb`]); 1-NN on z-scores ([`ZScoreNn`]) is reported beside it.
//! - Raw-coordinate DTW ([`raw_coordinate_sample`]): the same DTW kernel on SpineBase-relative
//!   joint coordinates (72 channels) instead of joint relative angles.
//! - Resampling ablation ([`resample`], [`euclidean_sum`]): every sequence resampled to a fixed
//!   length and compared by the sum of Euclidean distances instead of DTW.
//!
//! The feature definitions are kept here, in one place, so they can be corrected.

use wscg_math::vec3::{dist, dot, sub};
use wscg_math::{Error, Result};

use super::cycle::{ankle_distance, up_vector, GaitCycle, UpAxis};
use super::jra::vector_angle;
use super::skeleton::{Joint, SkeletonSeq, N_JOINTS};

/// Ball et al.'s 18 features: for the angles `[hip L, hip R, knee L, knee R, ankle L,
/// ankle R]` (radians), `[mean, std, max]` each, angle-major.
pub fn ball_features(s: &SkeletonSeq, c: &GaitCycle) -> Result<[f64; 18]> {
    c.check_within(s)?;
    use Joint::*;
    let legs = [
        (HipLeft, KneeLeft, AnkleLeft, FootLeft),
        (HipRight, KneeRight, AnkleRight, FootRight),
    ];
    let mut series: [Vec<f64>; 6] = Default::default();
    for t in c.start..=c.end {
        let f = &s.frames[t];
        let p = |j: Joint| f[j.index()];
        let trunk = sub(p(SpineMid), p(SpineBase));
        for (side, &(hip, knee, ankle, foot)) in legs.iter().enumerate() {
            series[side].push(vector_angle(trunk, sub(p(knee), p(hip))));
            series[2 + side].push(vector_angle(sub(p(hip), p(knee)), sub(p(ankle), p(knee))));
            series[4 + side].push(vector_angle(sub(p(knee), p(ankle)), sub(p(foot), p(ankle))));
        }
    }
    let mut out = [0.0; 18];
    for (a, x) in series.iter().enumerate() {
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let var = x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n;
        let max = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        out[3 * a] = mean;
        out[3 * a + 1] = var.sqrt();
        out[3 * a + 2] = max;
    }
    Ok(out)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Preis et al.'s 13 features, metres and metres per second: `[height, leg length, torso,
/// lower leg L, lower leg R, thigh L, thigh R, upper arm L, upper arm R, forearm L,
/// forearm R, step length, speed]`.
///
/// Height = Head→Neck→SpineShoulder→SpineMid→SpineBase plus the mean leg length; leg length =
/// mean of Hip→Knee→Ankle over both legs; step length = mean of the maxima of the horizontal
/// ankle distance in the two halves of the cycle; speed = horizontal SpineBase displacement
/// over the cycle divided by its duration. Bone lengths are per-frame medians over the cycle.
pub fn preis_features(s: &SkeletonSeq, c: &GaitCycle) -> Result<[f64; 13]> {
    c.check_within(s)?;
    use Joint::*;
    let path = |js: &[Joint]| -> f64 {
        median(
            (c.start..=c.end)
                .map(|t| {
                    js.windows(2)
                        .map(|w| dist(s.at(t, w[0]), s.at(t, w[1])))
                        .sum()
                })
                .collect(),
        )
    };
    let leg_l = path(&[HipLeft, KneeLeft, AnkleLeft]);
    let leg_r = path(&[HipRight, KneeRight, AnkleRight]);
    let leg = 0.5 * (leg_l + leg_r);
    // Kinect v1 has no Neck: the chain goes Head → ShoulderCenter there.
    let chain: Vec<Joint> = [Head, Neck, SpineShoulder, SpineMid, SpineBase]
        .into_iter()
        .filter(|&j| s.joint_set.contains(j))
        .collect();
    let upper_body = path(&chain);
    let u = up_vector(s, UpAxis::Estimate)?;
    let d = ankle_distance(s, u);
    let mid = c.mid.clamp(c.start + 1, c.end);
    let max_in = |a: usize, b: usize| d[a..=b].iter().copied().fold(0.0, f64::max);
    let step = 0.5 * (max_in(c.start, mid) + max_in(mid, c.end));
    let disp = sub(s.at(c.end, SpineBase), s.at(c.start, SpineBase));
    let h = dot(disp, u);
    let horiz = sub(disp, [h * u[0], h * u[1], h * u[2]]);
    let dur = (c.end - c.start) as f64 / s.fps;
    Ok([
        upper_body + leg,
        leg,
        path(&[SpineShoulder, SpineMid, SpineBase]),
        path(&[KneeLeft, AnkleLeft]),
        path(&[KneeRight, AnkleRight]),
        path(&[HipLeft, KneeLeft]),
        path(&[HipRight, KneeRight]),
        path(&[ShoulderLeft, ElbowLeft]),
        path(&[ShoulderRight, ElbowRight]),
        path(&[ElbowLeft, WristLeft]),
        path(&[ElbowRight, WristRight]),
        step,
        wscg_math::vec3::norm(horiz) / dur,
    ])
}

/// The raw-coordinate baseline sample: the sequences `x, y, z` of every joint of the walk's
/// set but SpineBase (72 for Kinect v2, 57 for Kinect v1), relative to SpineBase, over the
/// cycle (joints in Kinect v2 index order, channel `3 i + k` for the `i`-th joint).
pub fn raw_coordinate_sample(s: &SkeletonSeq, c: &GaitCycle) -> Result<Vec<Vec<f64>>> {
    c.check_within(s)?;
    let joints: Vec<usize> = (1..N_JOINTS)
        .filter(|&j| s.joint_set.contains(Joint::ALL[j]))
        .collect();
    let mut out: Vec<Vec<f64>> = (0..3 * joints.len())
        .map(|_| Vec::with_capacity(c.len()))
        .collect();
    for t in c.start..=c.end {
        let f = &s.frames[t];
        let r = f[Joint::SpineBase.index()];
        for (i, &j) in joints.iter().enumerate() {
            let v = sub(f[j], r);
            for k in 0..3 {
                out[3 * i + k].push(v[k]);
            }
        }
    }
    Ok(out)
}

/// Linear resampling of `x` (non-empty) to `n` samples over the same span.
pub fn resample(x: &[f64], n: usize) -> Vec<f64> {
    if x.len() == 1 || n == 1 {
        return vec![x[0]; n];
    }
    let scale = (x.len() - 1) as f64 / (n - 1) as f64;
    (0..n)
        .map(|i| {
            let p = i as f64 * scale;
            let k = (p.floor() as usize).min(x.len() - 2);
            let w = p - k as f64;
            x[k] + w * (x[k + 1] - x[k])
        })
        .collect()
}

/// The resampling ablation: `Σ_m ‖resample(a_m) − resample(b_m)‖₂` over the channels.
pub fn euclidean_sum(a: &[Vec<f64>], b: &[Vec<f64>], n: usize) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let (x, y) = (resample(x, n), resample(y, n));
            x.iter()
                .zip(&y)
                .map(|(p, q)| (p - q) * (p - q))
                .sum::<f64>()
                .sqrt()
        })
        .sum()
}

/// Checks a feature table: non-empty, equal row lengths, finite, labels matching.
fn check_table(x: &[Vec<f64>], labels: Option<&[u32]>) -> Result<usize> {
    if x.is_empty() {
        return Err(Error::Empty("features"));
    }
    let d = x[0].len();
    if d == 0 {
        return Err(Error::Empty("features"));
    }
    for (i, r) in x.iter().enumerate() {
        if r.len() != d {
            return Err(Error::ShapeMismatch(format!(
                "row {i} has {} features, row 0 has {d}",
                r.len()
            )));
        }
        if r.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid("features", format!("row {i} is not finite")));
        }
    }
    if let Some(l) = labels {
        if l.len() != x.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} labels for {} rows",
                l.len(),
                x.len()
            )));
        }
    }
    Ok(d)
}

/// 1-NN on z-scored features (mean and standard deviation of the training rows; a constant
/// feature keeps unit scale). Ties go to the first training row.
#[derive(Clone, Debug)]
pub struct ZScoreNn {
    mean: Vec<f64>,
    scale: Vec<f64>,
    rows: Vec<Vec<f64>>,
    labels: Vec<u32>,
}

impl ZScoreNn {
    /// Fits on `x` (one row per sample). Errors: empty, ragged or non-finite rows, label count.
    pub fn fit(x: &[Vec<f64>], labels: &[u32]) -> Result<Self> {
        let d = check_table(x, Some(labels))?;
        let n = x.len() as f64;
        let mean: Vec<f64> = (0..d)
            .map(|k| x.iter().map(|r| r[k]).sum::<f64>() / n)
            .collect();
        let scale: Vec<f64> = (0..d)
            .map(|k| {
                let v = x.iter().map(|r| (r[k] - mean[k]).powi(2)).sum::<f64>() / n;
                if v > 0.0 {
                    v.sqrt()
                } else {
                    1.0
                }
            })
            .collect();
        let mut out = Self {
            mean,
            scale,
            rows: Vec::new(),
            labels: labels.to_vec(),
        };
        out.rows = x.iter().map(|r| out.z(r)).collect();
        Ok(out)
    }

    fn z(&self, r: &[f64]) -> Vec<f64> {
        r.iter()
            .zip(&self.mean)
            .zip(&self.scale)
            .map(|((v, m), s)| (v - m) / s)
            .collect()
    }

    /// The label of the nearest training row. Errors: wrong length or non-finite row.
    pub fn predict(&self, x: &[f64]) -> Result<u32> {
        check_table(std::slice::from_ref(&x.to_vec()), None)?;
        if x.len() != self.mean.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} features, the classifier was fitted on {}",
                x.len(),
                self.mean.len()
            )));
        }
        let q = self.z(x);
        let mut best = (f64::INFINITY, 0u32);
        for (r, &l) in self.rows.iter().zip(&self.labels) {
            let d: f64 = r.iter().zip(&q).map(|(a, b)| (a - b) * (a - b)).sum();
            if d < best.0 {
                best = (d, l);
            }
        }
        Ok(best.1)
    }
}

/// Gaussian Naive Bayes (Preis et al.'s best classifier in Weka): per class and feature a
/// normal density, variances floored at `1e-9 x` the largest feature variance (as
/// scikit-learn's `var_smoothing`), class priors from the training counts.
#[derive(Clone, Debug)]
pub struct GaussianNb {
    classes: Vec<u32>,
    log_prior: Vec<f64>,
    mean: Vec<Vec<f64>>,
    var: Vec<Vec<f64>>,
}

impl GaussianNb {
    /// Fits on `x` (one row per sample). Errors as [`ZScoreNn::fit`].
    pub fn fit(x: &[Vec<f64>], labels: &[u32]) -> Result<Self> {
        let d = check_table(x, Some(labels))?;
        let n = x.len() as f64;
        let mut classes: Vec<u32> = labels.to_vec();
        classes.sort_unstable();
        classes.dedup();
        let all_mean: Vec<f64> = (0..d)
            .map(|k| x.iter().map(|r| r[k]).sum::<f64>() / n)
            .collect();
        let max_var = (0..d)
            .map(|k| x.iter().map(|r| (r[k] - all_mean[k]).powi(2)).sum::<f64>() / n)
            .fold(0.0, f64::max);
        let floor = 1e-9 * max_var.max(f64::MIN_POSITIVE);
        let mut out = Self {
            classes: classes.clone(),
            log_prior: Vec::new(),
            mean: Vec::new(),
            var: Vec::new(),
        };
        for &c in &classes {
            let rows: Vec<&Vec<f64>> = x
                .iter()
                .zip(labels)
                .filter(|(_, &l)| l == c)
                .map(|(r, _)| r)
                .collect();
            let m = rows.len() as f64;
            let mean: Vec<f64> = (0..d)
                .map(|k| rows.iter().map(|r| r[k]).sum::<f64>() / m)
                .collect();
            let var: Vec<f64> = (0..d)
                .map(|k| rows.iter().map(|r| (r[k] - mean[k]).powi(2)).sum::<f64>() / m + floor)
                .collect();
            out.log_prior.push((m / n).ln());
            out.mean.push(mean);
            out.var.push(var);
        }
        Ok(out)
    }

    /// The class of largest posterior. Errors: wrong length or non-finite row.
    pub fn predict(&self, x: &[f64]) -> Result<u32> {
        check_table(std::slice::from_ref(&x.to_vec()), None)?;
        if x.len() != self.mean[0].len() {
            return Err(Error::ShapeMismatch(format!(
                "{} features, the classifier was fitted on {}",
                x.len(),
                self.mean[0].len()
            )));
        }
        let mut best = (f64::NEG_INFINITY, self.classes[0]);
        for (c, &label) in self.classes.iter().enumerate() {
            let mut ll = self.log_prior[c];
            for ((v, m), s2) in x.iter().zip(&self.mean[c]).zip(&self.var[c]) {
                ll -= 0.5 * ((std::f64::consts::TAU * s2).ln() + (v - m) * (v - m) / s2);
            }
            if ll > best.0 {
                best = (ll, label);
            }
        }
        Ok(best.1)
    }
}
