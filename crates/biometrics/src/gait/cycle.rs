//! Gait cycle detection from the ankle-to-ankle horizontal distance (paper 17, section 3.1).
//!
//! The legs are together twice per stride, so three consecutive minima of the horizontal
//! distance between the ankles are the start, middle and end of one gait cycle.

use serde::{Deserialize, Serialize};
use wscg_math::vec3::{cross, dot, norm, sub};
use wscg_math::{Error, Result};

use super::skeleton::{Joint, SkeletonSeq};

/// How the vertical direction is found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum UpAxis {
    /// `normalise(mean_t(SpineShoulder - SpineBase))`: works with a tilted sensor (default).
    #[default]
    Estimate,
    /// The camera's `+y` axis (a level sensor).
    Y,
    /// A given direction (normalised internally).
    Vector([f64; 3]),
}

/// Which cycle is returned when the walk holds several.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum CycleChoice {
    /// The first three consecutive minima (default).
    #[default]
    First,
    /// The triple with the most even halves, `min |(m2 - m1) - (m3 - m2)|` (first on ties).
    MostRegular,
}

/// Which leg steps forward in the first half of the returned cycle.
///
/// The paper accepts either order ("right foot forward ... left foot forward ... or vice
/// versa"). Two walks whose cycles start with different legs compare left-right mirrored
/// halves, which costs the DTW kernel much of its accuracy (on our synthetic walkers with a
/// random starting step: 68 % instead of 100 %), so by default the first cycle that starts
/// with the left step is taken (falling back to the first cycle when the walk holds only one
/// cycle, of the other order).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum StartLeg {
    /// Either leg (the paper's rule as printed).
    Any,
    /// The left foot moves forward first (default).
    #[default]
    Left,
    /// The right foot moves forward first.
    Right,
}

wscg_math::params! {
    /// Parameters of [`detect_gait_cycle`].
    #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
    pub struct CycleParams {
        /// Width of the centred moving average, frames (5: about 0.17 s at 30 fps; the paper
        /// smooths with a moving average of unstated width).
        pub smooth_window: usize,
        /// Smallest time between two minima, seconds (0.25).
        pub min_step_s: f64,
        /// Smallest prominence of a minimum as a fraction of the robust range `p95 - p5` of the
        /// smoothed distance (0.2).
        pub min_prominence: f64,
        /// Vertical direction.
        pub up: UpAxis,
        /// Which cycle to return.
        pub choice: CycleChoice,
        /// Which leg's step opens the cycle.
        pub start_leg: StartLeg,
    }
}

impl Default for CycleParams {
    fn default() -> Self {
        Self {
            smooth_window: 5,
            min_step_s: 0.25,
            min_prominence: 0.2,
            up: UpAxis::Estimate,
            choice: CycleChoice::First,
            start_leg: StartLeg::Left,
        }
    }
}

impl CycleParams {
    /// Errors: `smooth_window == 0`, a negative or non-finite `min_step_s` or
    /// `min_prominence`, a non-finite or zero `up` vector.
    pub fn validate(&self) -> Result<()> {
        if self.smooth_window == 0 {
            return Err(Error::invalid("smooth_window", "must be at least 1"));
        }
        if !(self.min_step_s.is_finite() && self.min_step_s >= 0.0) {
            return Err(Error::invalid("min_step_s", "must be finite and >= 0"));
        }
        if !(self.min_prominence.is_finite() && self.min_prominence >= 0.0) {
            return Err(Error::invalid("min_prominence", "must be finite and >= 0"));
        }
        if let UpAxis::Vector(v) = self.up {
            if !v.iter().all(|x| x.is_finite()) || norm(v) < 1e-12 {
                return Err(Error::invalid("up", "must be a finite non-zero vector"));
            }
        }
        Ok(())
    }
}

/// One detected gait cycle: frames `start..=end`, legs together at `start`, `mid` and `end`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaitCycle {
    /// First frame (first minimum).
    pub start: usize,
    /// Middle minimum (the other leg's step begins).
    pub mid: usize,
    /// Last frame (third minimum), inclusive.
    pub end: usize,
    /// The smoothed horizontal ankle distance of every frame, metres.
    pub ankle_dist: Vec<f64>,
    /// All accepted minima of the walk, frames.
    pub minima: Vec<usize>,
    /// The leg stepping forward in the first half (`None` when not determined).
    pub first_step: Option<StartLeg>,
}

impl GaitCycle {
    /// Number of frames of the cycle (`end - start + 1`).
    pub fn len(&self) -> usize {
        self.end - self.start + 1
    }

    /// Always false (a cycle has at least three frames).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Errors unless the cycle's frames lie inside the walk `s` with `start < end`.
    pub fn check_within(&self, s: &SkeletonSeq) -> Result<()> {
        if self.end >= s.len() || self.start >= self.end {
            return Err(Error::invalid(
                "cycle",
                format!(
                    "frames {}..={} are not inside the walk's {} frames",
                    self.start,
                    self.end,
                    s.len()
                ),
            ));
        }
        Ok(())
    }

    /// A cycle given by its three frames (for users who mark cycles by hand). Errors: not
    /// strictly increasing, or beyond the walk.
    pub fn from_frames(s: &SkeletonSeq, start: usize, mid: usize, end: usize) -> Result<Self> {
        if !(start < mid && mid < end) {
            return Err(Error::invalid(
                "cycle",
                format!("needs start < mid < end, got ({start}, {mid}, {end})"),
            ));
        }
        if end >= s.len() {
            return Err(Error::invalid(
                "cycle",
                format!("end frame {end} is beyond the walk's {} frames", s.len()),
            ));
        }
        Ok(Self {
            start,
            mid,
            end,
            ankle_dist: Vec::new(),
            minima: vec![start, mid, end],
            first_step: None,
        })
    }
}

/// The unit up vector of a walk.
pub fn up_vector(s: &SkeletonSeq, up: UpAxis) -> Result<[f64; 3]> {
    let v = match up {
        UpAxis::Y => return Ok([0.0, 1.0, 0.0]),
        UpAxis::Vector(v) => v,
        UpAxis::Estimate => {
            let mut m = [0.0; 3];
            for t in 0..s.len() {
                let d = sub(s.at(t, Joint::SpineShoulder), s.at(t, Joint::SpineBase));
                for k in 0..3 {
                    m[k] += d[k];
                }
            }
            m
        }
    };
    let n = norm(v);
    if n < 1e-12 {
        return Err(Error::invalid(
            "frames",
            "SpineShoulder coincides with SpineBase on average; the up direction cannot be \
             estimated (pass an explicit up axis)",
        ));
    }
    Ok([v[0] / n, v[1] / n, v[2] / n])
}

/// The horizontal ankle distance `d(t) = ‖Δ − (Δ·u) u‖`, `Δ = AnkleLeft − AnkleRight` (eq. G1).
pub fn ankle_distance(s: &SkeletonSeq, u: [f64; 3]) -> Vec<f64> {
    (0..s.len())
        .map(|t| {
            let d = sub(s.at(t, Joint::AnkleLeft), s.at(t, Joint::AnkleRight));
            let h = dot(d, u);
            norm([d[0] - h * u[0], d[1] - h * u[1], d[2] - h * u[2]])
        })
        .collect()
}

/// Centred moving average of width `w`, the window shrinking (symmetrically) at the ends.
pub fn moving_average(x: &[f64], w: usize) -> Vec<f64> {
    let half = w.max(1) / 2;
    let n = x.len();
    (0..n)
        .map(|t| {
            let h = half.min(t).min(n - 1 - t);
            let s: f64 = x[t - h..=t + h].iter().sum();
            s / (2 * h + 1) as f64
        })
        .collect()
}

/// Linear-interpolated percentile `q` in [0, 100] of `x` (non-empty).
fn percentile(x: &[f64], q: f64) -> f64 {
    let mut v = x.to_vec();
    v.sort_by(f64::total_cmp);
    let pos = q / 100.0 * (v.len() - 1) as f64;
    let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
    v[lo] + (pos - lo as f64) * (v[hi] - v[lo])
}

/// Topographic prominence of the valley at `t`: the lower of the two highest points between
/// `t` and the nearest lower sample on each side (or the signal's end), minus `x[t]`.
fn valley_prominence(x: &[f64], t: usize) -> f64 {
    let v = x[t];
    let mut left = v;
    for &y in x[..t].iter().rev() {
        if y < v {
            break;
        }
        left = left.max(y);
    }
    let mut right = v;
    for &y in &x[t + 1..] {
        if y < v {
            break;
        }
        right = right.max(y);
    }
    left.min(right) - v
}

/// The minima of `x` used as leg-crossing events: `x(t) <= x(t-1)` and `x(t) < x(t+1)`,
/// prominence at least `min_prominence`, and at least `min_gap` samples apart (the deeper of
/// two close minima is kept). Returned in increasing order.
pub fn leg_crossings(x: &[f64], min_prominence: f64, min_gap: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (1..x.len().saturating_sub(1))
        .filter(|&t| x[t] <= x[t - 1] && x[t] < x[t + 1])
        .filter(|&t| valley_prominence(x, t) >= min_prominence)
        .collect();
    // Deepest first; drop candidates within `min_gap` of a kept one.
    order.sort_by(|&a, &b| x[a].total_cmp(&x[b]).then(a.cmp(&b)));
    let mut kept: Vec<usize> = Vec::new();
    for t in order {
        if kept.iter().all(|&k| k.abs_diff(t) >= min_gap) {
            kept.push(t);
        }
    }
    kept.sort_unstable();
    kept
}

/// The leg ahead at the widest stance between the minima `a` and `b`: the one stepping
/// forward in that half cycle. "Ahead" is along the body's facing direction
/// `(HipRight − HipLeft) × up` (so a walk on a treadmill works too).
fn first_step(s: &SkeletonSeq, u: [f64; 3], d: &[f64], a: usize, b: usize) -> StartLeg {
    let t = (a..=b).max_by(|&i, &j| d[i].total_cmp(&d[j])).unwrap_or(a);
    let right = sub(s.at(t, Joint::HipRight), s.at(t, Joint::HipLeft));
    let facing = cross(right, u);
    let lead = sub(s.at(t, Joint::AnkleLeft), s.at(t, Joint::AnkleRight));
    if dot(lead, facing) >= 0.0 {
        StartLeg::Left
    } else {
        StartLeg::Right
    }
}

/// Detects one full gait cycle (section 3.1): horizontal ankle distance, moving average,
/// prominent and spaced minima, and three consecutive minima as start, middle and end (of
/// the order given by [`CycleParams::start_leg`]).
///
/// Errors: fewer than three minima (the walk is shorter than one gait cycle), bad parameters.
pub fn detect_gait_cycle(s: &SkeletonSeq, p: &CycleParams) -> Result<GaitCycle> {
    p.validate()?;
    let u = up_vector(s, p.up)?;
    let d = moving_average(&ankle_distance(s, u), p.smooth_window);
    let range = percentile(&d, 95.0) - percentile(&d, 5.0);
    let min_gap = (p.min_step_s * s.fps).round() as usize;
    let minima = leg_crossings(&d, p.min_prominence * range, min_gap.max(1));
    if minima.len() < 3 {
        return Err(Error::invalid(
            "walk",
            format!(
                "no full gait cycle: found {} leg-crossing minima of the ankle distance in {} \
                 frames, need 3 (the walk is shorter than one gait cycle)",
                minima.len(),
                s.len()
            ),
        ));
    }
    let legs: Vec<StartLeg> = (0..minima.len() - 2)
        .map(|k| first_step(s, u, &d, minima[k], minima[k + 1]))
        .collect();
    let mut cands: Vec<usize> = (0..minima.len() - 2)
        .filter(|&k| p.start_leg == StartLeg::Any || legs[k] == p.start_leg)
        .collect();
    if cands.is_empty() {
        cands = (0..minima.len() - 2).collect();
    }
    let k = match p.choice {
        CycleChoice::First => cands[0],
        CycleChoice::MostRegular => cands
            .iter()
            .copied()
            .min_by_key(|&k| (minima[k + 1] - minima[k]).abs_diff(minima[k + 2] - minima[k + 1]))
            .unwrap_or(cands[0]),
    };
    Ok(GaitCycle {
        start: minima[k],
        mid: minima[k + 1],
        end: minima[k + 2],
        ankle_dist: d,
        first_step: Some(legs[k]),
        minima,
    })
}
