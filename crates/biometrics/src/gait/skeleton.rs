//! Kinect v2 skeleton streams: the 25 joints and a validated sequence of frames.

use serde::{Deserialize, Serialize};
use wscg_math::{Error, Result};

/// Number of joints of a Kinect v2 skeleton.
pub const N_JOINTS: usize = 25;

/// One frame: the 25 joint positions in metres (camera frame).
pub type Frame = [[f64; 3]; N_JOINTS];

/// The Kinect v2 joints, numbered as the SDK's `JointType`.
#[allow(missing_docs)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[repr(usize)]
pub enum Joint {
    SpineBase = 0,
    SpineMid = 1,
    Neck = 2,
    Head = 3,
    ShoulderLeft = 4,
    ElbowLeft = 5,
    WristLeft = 6,
    HandLeft = 7,
    ShoulderRight = 8,
    ElbowRight = 9,
    WristRight = 10,
    HandRight = 11,
    HipLeft = 12,
    KneeLeft = 13,
    AnkleLeft = 14,
    FootLeft = 15,
    HipRight = 16,
    KneeRight = 17,
    AnkleRight = 18,
    FootRight = 19,
    SpineShoulder = 20,
    HandTipLeft = 21,
    ThumbLeft = 22,
    HandTipRight = 23,
    ThumbRight = 24,
}

impl Joint {
    /// All joints in index order.
    pub const ALL: [Joint; N_JOINTS] = [
        Joint::SpineBase,
        Joint::SpineMid,
        Joint::Neck,
        Joint::Head,
        Joint::ShoulderLeft,
        Joint::ElbowLeft,
        Joint::WristLeft,
        Joint::HandLeft,
        Joint::ShoulderRight,
        Joint::ElbowRight,
        Joint::WristRight,
        Joint::HandRight,
        Joint::HipLeft,
        Joint::KneeLeft,
        Joint::AnkleLeft,
        Joint::FootLeft,
        Joint::HipRight,
        Joint::KneeRight,
        Joint::AnkleRight,
        Joint::FootRight,
        Joint::SpineShoulder,
        Joint::HandTipLeft,
        Joint::ThumbLeft,
        Joint::HandTipRight,
        Joint::ThumbRight,
    ];

    /// The joint's index (the SDK's `JointType` value).
    pub fn index(self) -> usize {
        self as usize
    }

    /// The joint with index `i`. Errors: `i >= 25`.
    pub fn from_index(i: usize) -> Result<Joint> {
        Joint::ALL.get(i).copied().ok_or_else(|| {
            Error::invalid("joint", format!("index {i} is out of range 0..{N_JOINTS}"))
        })
    }

    /// The SDK's name (`"SpineBase"`, `"AnkleLeft"`, ...).
    pub fn name(self) -> &'static str {
        JOINT_NAMES[self.index()]
    }

    /// The joint named `s` (SDK name, case-insensitive) or given by its index as text.
    pub fn parse(s: &str) -> Result<Joint> {
        let t = s.trim();
        if let Ok(i) = t.parse::<usize>() {
            return Joint::from_index(i);
        }
        JOINT_NAMES
            .iter()
            .position(|n| n.eq_ignore_ascii_case(t))
            .map(|i| Joint::ALL[i])
            .ok_or_else(|| {
                Error::invalid(
                    "joint",
                    format!("`{t}` is not a Kinect v2 joint name (SpineBase, AnkleLeft, ...)"),
                )
            })
    }
}

/// Names of the joints in index order.
pub const JOINT_NAMES: [&str; N_JOINTS] = [
    "SpineBase",
    "SpineMid",
    "Neck",
    "Head",
    "ShoulderLeft",
    "ElbowLeft",
    "WristLeft",
    "HandLeft",
    "ShoulderRight",
    "ElbowRight",
    "WristRight",
    "HandRight",
    "HipLeft",
    "KneeLeft",
    "AnkleLeft",
    "FootLeft",
    "HipRight",
    "KneeRight",
    "AnkleRight",
    "FootRight",
    "SpineShoulder",
    "HandTipLeft",
    "ThumbLeft",
    "HandTipRight",
    "ThumbRight",
];

/// A joint pair `(p1, p2)` with `p1 < p2`.
pub type Pair = (Joint, Joint);

/// A validated Kinect v2 skeleton stream.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SkeletonSeq {
    /// Frame rate in frames per second (Kinect v2: 30).
    pub fps: f64,
    /// Joint positions per frame, metres.
    pub frames: Vec<Frame>,
}

impl SkeletonSeq {
    /// A sequence from frames. Errors: `fps` not positive and finite, fewer than 3 frames, a
    /// NaN or infinite coordinate (the error names the frame and joint).
    pub fn new(fps: f64, frames: Vec<Frame>) -> Result<Self> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(Error::invalid(
                "fps",
                format!("must be positive, got {fps}"),
            ));
        }
        if frames.len() < 3 {
            return Err(Error::invalid(
                "frames",
                format!("a walk needs at least 3 frames, got {}", frames.len()),
            ));
        }
        for (t, f) in frames.iter().enumerate() {
            for (j, p) in f.iter().enumerate() {
                if p.iter().any(|v| !v.is_finite()) {
                    return Err(Error::invalid(
                        "frames",
                        format!(
                            "frame {t}, joint {j} ({}) has a NaN or infinite coordinate \
                             (interpolate_missing fills short gaps)",
                            JOINT_NAMES[j]
                        ),
                    ));
                }
            }
        }
        Ok(Self { fps, frames })
    }

    /// A sequence from a flat row-major `(T, J, 3)` array. Errors: `J != 25`, a length that is
    /// not `T * J * 3`, and everything [`Self::new`] checks.
    pub fn from_flat(fps: f64, data: &[f64], n_frames: usize, n_joints: usize) -> Result<Self> {
        if n_joints != N_JOINTS {
            return Err(Error::ShapeMismatch(format!(
                "a Kinect v2 skeleton has {N_JOINTS} joints, got {n_joints}"
            )));
        }
        if data.len() != n_frames * n_joints * 3 {
            return Err(Error::ShapeMismatch(format!(
                "{} values do not form ({n_frames}, {n_joints}, 3)",
                data.len()
            )));
        }
        let frames = data
            .chunks_exact(N_JOINTS * 3)
            .map(|c| std::array::from_fn(|j| [c[3 * j], c[3 * j + 1], c[3 * j + 2]]))
            .collect();
        Self::new(fps, frames)
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether the sequence has no frames (never true for a validated sequence).
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Position of joint `j` in frame `t`.
    pub fn at(&self, t: usize, j: Joint) -> [f64; 3] {
        self.frames[t][j.index()]
    }

    /// The frames as a flat row-major `(T, 25, 3)` array.
    pub fn to_flat(&self) -> Vec<f64> {
        self.frames.iter().flatten().flatten().copied().collect()
    }
}

/// Fills NaN/infinite coordinates of a `(T, 25, 3)` flat array by linear interpolation in time
/// over gaps of at most `max_gap` frames (per joint; a joint is missing in a frame when any of
/// its coordinates is not finite), then validates the result.
///
/// Errors: a gap longer than `max_gap` or touching the first or last frame, and everything
/// [`SkeletonSeq::from_flat`] checks.
pub fn interpolate_missing(
    fps: f64,
    data: &[f64],
    n_frames: usize,
    n_joints: usize,
    max_gap: usize,
) -> Result<SkeletonSeq> {
    if n_joints != N_JOINTS || data.len() != n_frames * n_joints * 3 {
        return SkeletonSeq::from_flat(fps, data, n_frames, n_joints);
    }
    let mut d = data.to_vec();
    let ok =
        |d: &[f64], t: usize, j: usize| (0..3).all(|k| d[(t * N_JOINTS + j) * 3 + k].is_finite());
    for j in 0..N_JOINTS {
        let mut t = 0;
        while t < n_frames {
            if ok(&d, t, j) {
                t += 1;
                continue;
            }
            let start = t;
            while t < n_frames && !ok(&d, t, j) {
                t += 1;
            }
            let len = t - start;
            if start == 0 || t == n_frames || len > max_gap {
                return Err(Error::invalid(
                    "frames",
                    format!(
                        "joint {j} ({}) is missing in frames {start}..{} ({len} frames); only \
                         interior gaps of at most {max_gap} frames are interpolated",
                        JOINT_NAMES[j],
                        t - 1
                    ),
                ));
            }
            let (a, b) = (start - 1, t);
            for s in start..t {
                let w = (s - a) as f64 / (b - a) as f64;
                for k in 0..3 {
                    let (va, vb) = (d[(a * N_JOINTS + j) * 3 + k], d[(b * N_JOINTS + j) * 3 + k]);
                    d[(s * N_JOINTS + j) * 3 + k] = va + w * (vb - va);
                }
            }
        }
    }
    SkeletonSeq::from_flat(fps, &d, n_frames, n_joints)
}
