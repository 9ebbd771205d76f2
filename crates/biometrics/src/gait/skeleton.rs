//! Kinect skeleton streams: the 25 joints of Kinect v2 (and of NTU RGB+D), the 20 joints of
//! Kinect v1 ([`JointSet`]), and a validated sequence of frames.
//!
//! Frames always hold 25 slots indexed by the Kinect v2 `JointType`; a Kinect v1 skeleton
//! fills the slots of its 20 joints (HipCenter → SpineBase, Spine → SpineMid, ShoulderCenter
//! → SpineShoulder, the limbs and head by name) and leaves Neck, HandTip and Thumb NaN.

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

    /// The joint named `s` (Kinect v2 or v1 SDK name, case-insensitive; v1's HipCenter, Spine
    /// and ShoulderCenter are SpineBase, SpineMid and SpineShoulder) or given by its Kinect v2
    /// index as text.
    pub fn parse(s: &str) -> Result<Joint> {
        let t = s.trim();
        if let Ok(i) = t.parse::<usize>() {
            return Joint::from_index(i);
        }
        let v1 = || {
            KINECT_V1_NAMES
                .iter()
                .position(|n| n.eq_ignore_ascii_case(t))
                .map(|i| KINECT_V1_JOINTS[i])
        };
        JOINT_NAMES
            .iter()
            .position(|n| n.eq_ignore_ascii_case(t))
            .map(|i| Joint::ALL[i])
            .or_else(v1)
            .ok_or_else(|| {
                Error::invalid(
                    "joint",
                    format!(
                        "`{t}` is not a Kinect joint name (v2: SpineBase, AnkleLeft, ...; v1: \
                         HipCenter, ShoulderCenter, ...)"
                    ),
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

/// Largest skeleton file accepted (256 MiB).
pub const MAX_SKELETON_BYTES: u64 = 256 << 20;

/// The text of a skeleton file, refusing files above [`MAX_SKELETON_BYTES`] before reading.
pub(crate) fn read_limited(path: &std::path::Path) -> Result<String> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.len() > MAX_SKELETON_BYTES {
        return Err(Error::LimitExceeded(format!(
            "{} is {} bytes; skeleton files above {MAX_SKELETON_BYTES} bytes are refused",
            path.display(),
            meta.len()
        )));
    }
    wscg_math::error::read_text(path)
}

/// The joints a skeleton stream holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum JointSet {
    /// Kinect v2 and NTU RGB+D: the 25 joints of [`Joint`].
    #[default]
    KinectV2,
    /// Kinect v1: 20 joints (no Neck, HandTip or Thumb joints).
    KinectV1,
}

/// The Kinect v1 joints in the SDK's `NUI_SKELETON_POSITION_INDEX` order, as the Kinect v2
/// joints that stand for them.
pub const KINECT_V1_JOINTS: [Joint; 20] = [
    Joint::SpineBase,
    Joint::SpineMid,
    Joint::SpineShoulder,
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
];

/// The Kinect v1 SDK's joint names, in [`KINECT_V1_JOINTS`] order.
pub const KINECT_V1_NAMES: [&str; 20] = [
    "HipCenter",
    "Spine",
    "ShoulderCenter",
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
];

impl JointSet {
    /// The joints of the set, in the SDK's index order of that Kinect version.
    pub fn joints(self) -> &'static [Joint] {
        match self {
            JointSet::KinectV2 => &Joint::ALL,
            JointSet::KinectV1 => &KINECT_V1_JOINTS,
        }
    }

    /// The SDK's joint names, in [`Self::joints`] order.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            JointSet::KinectV2 => &JOINT_NAMES,
            JointSet::KinectV1 => &KINECT_V1_NAMES,
        }
    }

    /// Number of joints (25 or 20).
    pub fn len(self) -> usize {
        self.joints().len()
    }

    /// Never true (a set has joints).
    pub fn is_empty(self) -> bool {
        false
    }

    /// Whether the set holds joint `j`.
    pub fn contains(self, j: Joint) -> bool {
        self == JointSet::KinectV2 || KINECT_V1_JOINTS.contains(&j)
    }

    /// The SDK name of `j` in this set (`"HipCenter"` for SpineBase in Kinect v1).
    pub fn name_of(self, j: Joint) -> &'static str {
        self.joints()
            .iter()
            .position(|&k| k == j)
            .map_or(j.name(), |i| self.names()[i])
    }

    /// The set with `n` joints (25 or 20). Errors: another count.
    pub fn for_count(n: usize) -> Result<Self> {
        match n {
            N_JOINTS => Ok(JointSet::KinectV2),
            20 => Ok(JointSet::KinectV1),
            _ => Err(Error::ShapeMismatch(format!(
                "a Kinect skeleton has 25 joints (v2) or 20 joints (v1), got {n}"
            ))),
        }
    }

    /// Parses `"v2"`/`"kinect_v2"`/`"25"` or `"v1"`/`"kinect_v1"`/`"20"`.
    pub fn parse(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "v2" | "kinect_v2" | "kinectv2" | "25" => Ok(JointSet::KinectV2),
            "v1" | "kinect_v1" | "kinectv1" | "20" => Ok(JointSet::KinectV1),
            _ => Err(Error::invalid(
                "joints",
                format!("`{s}` is not a joint set; use \"v2\" (25 joints) or \"v1\" (20)"),
            )),
        }
    }
}

/// A joint pair `(p1, p2)` with `p1 < p2`.
pub type Pair = (Joint, Joint);

/// A validated Kinect skeleton stream. Two streams are equal when their frame rates, joint
/// sets and the coordinates of the joints of the set are.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SkeletonSeq {
    /// Frame rate in frames per second (Kinect v2: 30).
    pub fps: f64,
    /// Joint positions per frame, metres, by Kinect v2 index (joints outside
    /// [`Self::joint_set`] are NaN).
    pub frames: Vec<Frame>,
    /// The joints the stream holds.
    #[serde(default)]
    pub joint_set: JointSet,
}

impl PartialEq for SkeletonSeq {
    fn eq(&self, other: &Self) -> bool {
        self.fps == other.fps
            && self.joint_set == other.joint_set
            && self.frames.len() == other.frames.len()
            && self.to_flat() == other.to_flat()
    }
}

impl SkeletonSeq {
    /// A Kinect v2 sequence from frames. Errors: `fps` not positive and finite, fewer than 3
    /// frames, a NaN or infinite coordinate (the error names the frame and joint).
    pub fn new(fps: f64, frames: Vec<Frame>) -> Result<Self> {
        Self::with_joints(fps, frames, JointSet::KinectV2)
    }

    /// A sequence of the joints `set` from frames indexed by Kinect v2 joint; the slots of
    /// joints outside `set` are ignored (set to NaN). Errors: as [`Self::new`], for the
    /// joints of `set`.
    pub fn with_joints(fps: f64, mut frames: Vec<Frame>, set: JointSet) -> Result<Self> {
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
        for (t, f) in frames.iter_mut().enumerate() {
            for (j, p) in f.iter_mut().enumerate() {
                let joint = Joint::ALL[j];
                if !set.contains(joint) {
                    *p = [f64::NAN; 3];
                } else if p.iter().any(|v| !v.is_finite()) {
                    return Err(Error::invalid(
                        "frames",
                        format!(
                            "frame {t}, joint {j} ({}) has a NaN or infinite coordinate \
                             (interpolate_missing fills short gaps)",
                            set.name_of(joint)
                        ),
                    ));
                }
            }
        }
        Ok(Self {
            fps,
            frames,
            joint_set: set,
        })
    }

    /// A sequence from a flat row-major `(T, J, 3)` array: `J = 25` joints in Kinect v2
    /// order, or `J = 20` in Kinect v1 order. Errors: another `J`, a length that is not
    /// `T * J * 3`, and everything [`Self::new`] checks.
    pub fn from_flat(fps: f64, data: &[f64], n_frames: usize, n_joints: usize) -> Result<Self> {
        let set = JointSet::for_count(n_joints)?;
        if Some(data.len()) != n_frames.checked_mul(n_joints * 3) {
            return Err(Error::ShapeMismatch(format!(
                "{} values do not form ({n_frames}, {n_joints}, 3)",
                data.len()
            )));
        }
        let frames = data
            .chunks_exact(n_joints * 3)
            .map(|c| {
                let mut f = [[f64::NAN; 3]; N_JOINTS];
                for (k, j) in set.joints().iter().enumerate() {
                    f[j.index()] = [c[3 * k], c[3 * k + 1], c[3 * k + 2]];
                }
                f
            })
            .collect();
        Self::with_joints(fps, frames, set)
    }

    /// The same walk with the joints of Kinect v1 only (Neck, HandTip and Thumb dropped).
    pub fn to_kinect_v1(&self) -> Self {
        let mut frames = self.frames.clone();
        for f in &mut frames {
            for (j, p) in f.iter_mut().enumerate() {
                if !JointSet::KinectV1.contains(Joint::ALL[j]) {
                    *p = [f64::NAN; 3];
                }
            }
        }
        Self {
            fps: self.fps,
            frames,
            joint_set: JointSet::KinectV1,
        }
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

    /// The frames as a flat row-major `(T, J, 3)` array of the joints of
    /// [`Self::joint_set`], in its order (`J` = 25 or 20).
    pub fn to_flat(&self) -> Vec<f64> {
        let js = self.joint_set.joints();
        self.frames
            .iter()
            .flat_map(|f| js.iter().flat_map(move |j| f[j.index()]))
            .collect()
    }
}

/// Fills NaN/infinite coordinates of a `(T, J, 3)` flat array (`J` = 25 Kinect v2 or 20
/// Kinect v1 joints) by linear interpolation in time over gaps of at most `max_gap` frames
/// (per joint; a joint is missing in a frame when any of its coordinates is not finite), then
/// validates the result.
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
    let Ok(set) = JointSet::for_count(n_joints) else {
        return SkeletonSeq::from_flat(fps, data, n_frames, n_joints);
    };
    if Some(data.len()) != n_frames.checked_mul(n_joints * 3) {
        return SkeletonSeq::from_flat(fps, data, n_frames, n_joints);
    }
    let mut d = data.to_vec();
    let nj = n_joints;
    let ok = |d: &[f64], t: usize, j: usize| (0..3).all(|k| d[(t * nj + j) * 3 + k].is_finite());
    for j in 0..nj {
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
                        set.names()[j],
                        t - 1
                    ),
                ));
            }
            let (a, b) = (start - 1, t);
            for s in start..t {
                let w = (s - a) as f64 / (b - a) as f64;
                for k in 0..3 {
                    let (va, vb) = (d[(a * nj + j) * 3 + k], d[(b * nj + j) * 3 + k]);
                    d[(s * nj + j) * 3 + k] = va + w * (vb - va);
                }
            }
        }
    }
    SkeletonSeq::from_flat(fps, &d, n_frames, n_joints)
}
