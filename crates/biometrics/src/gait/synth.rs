//! A synthetic Kinect v2 walker with known identities and gait cycles, standing in for the
//! paper's private skeleton database (20 people x 3 walks recorded at SMART Technologies).
//!
//! Subjects differ mainly in their dynamics (hip, knee, ankle and arm trajectories, pelvis and
//! trunk motion, cadence) and a little in their proportions (Winter's segment ratios x
//! (1 + N(0, 0.03)), heights 1.55-1.95 m). Sessions add what separates two recordings of one
//! person: a speed factor (a pure time warp of the cadence), 1° jitter of every angle
//! parameter, ±2 % bone-length bias (Kinect bone lengths are not constant), the heading and
//! position of the walk, the sensor pitch, and AR(1) noise in time (a common-mode translation
//! of the whole skeleton plus independent per-joint noise growing toward the extremities).
//! An optional 1 s "sit down" tail ends the walk as in the paper's videos.
//!
//! Body frame: x right, y up, z forward. The pelvis rotates about the vertical through
//! SpineBase and the shoulder girdle counter-rotates about the straight trunk axis, so the
//! pairs {SpineShoulder, SpineMid}, {ShoulderLeft, ShoulderRight} and {HipLeft, HipRight} have
//! constant joint relative angles without noise (the paper's narrow pairs of Fig. 5).

use std::f64::consts::{PI, TAU};

use rand::Rng as _;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use wscg_math::rng::{stream, Rng};
use wscg_math::vec3::{add, add_scaled, normalized_or_zero};
use wscg_math::{Error, Result};

use super::cycle::{ankle_distance, leg_crossings, up_vector, UpAxis};
use super::skeleton::{Frame, Joint, SkeletonSeq, N_JOINTS};

/// Segment lengths of a subject, metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segments {
    /// Hip to knee.
    pub thigh: f64,
    /// Knee to ankle.
    pub shank: f64,
    /// Ankle to Foot joint.
    pub foot: f64,
    /// Shoulder to elbow.
    pub upper_arm: f64,
    /// Elbow to wrist.
    pub forearm: f64,
    /// Wrist to hand tip.
    pub hand: f64,
    /// Distance between the hip joints.
    pub hip_width: f64,
    /// Distance between the shoulder joints.
    pub shoulder_width: f64,
    /// SpineBase to SpineShoulder.
    pub spine: f64,
    /// SpineShoulder to Neck.
    pub neck: f64,
    /// Neck to Head.
    pub head: f64,
}

impl Segments {
    /// Winter's ratios for height `h`.
    pub fn winter(h: f64) -> Self {
        Self {
            thigh: 0.245 * h,
            shank: 0.246 * h,
            foot: 0.152 * h,
            upper_arm: 0.186 * h,
            forearm: 0.146 * h,
            hand: 0.108 * h,
            hip_width: 0.191 * h,
            shoulder_width: 0.259 * h,
            spine: 0.288 * h,
            neck: 0.05 * h,
            head: 0.08 * h,
        }
    }

    fn as_array_mut(&mut self) -> [&mut f64; 11] {
        [
            &mut self.thigh,
            &mut self.shank,
            &mut self.foot,
            &mut self.upper_arm,
            &mut self.forearm,
            &mut self.hand,
            &mut self.hip_width,
            &mut self.shoulder_width,
            &mut self.spine,
            &mut self.neck,
            &mut self.head,
        ]
    }
}

wscg_math::params! {
    /// The fixed gait of one synthetic person. Angles in degrees.
    #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
    pub struct SubjectParams {
        /// Identity.
        pub id: u32,
        /// Body height, metres.
        pub height: f64,
        /// Segment lengths.
        pub seg: Segments,
        /// Steps per minute.
        pub cadence: f64,
        /// Hip flexion `h0 + h1 cos 2πφ + Σ_{k=2,3} (a_k cos 2πkφ + b_k sin 2πkφ)`:
        /// `[h0, h1, a2, b2, a3, b3]`.
        pub hip: [f64; 6],
        /// Knee flexion bump heights `[K1, K2]` of `K1 g(φ; 0.15, 0.08) + K2 g(φ; 0.72, 0.12)`.
        pub knee: [f64; 2],
        /// Ankle sinusoid amplitude.
        pub ankle_amp: f64,
        /// Ankle sinusoid phase, radians.
        pub ankle_phase: f64,
        /// Arm swing amplitude `A` of `β(φ) = −A cos 2πφ`.
        pub arm_swing: f64,
        /// Mean elbow flexion (a 5° swing is added).
        pub elbow: f64,
        /// Vertical pelvic bob amplitude, metres (twice per stride).
        pub bob: f64,
        /// Lateral sway amplitude, metres (once per stride).
        pub sway: f64,
        /// Pelvis rotation amplitude about the vertical.
        pub pelvis_rot: f64,
        /// Shoulder-girdle counter-rotation amplitude about the trunk axis.
        pub girdle_rot: f64,
        /// Forward trunk lean.
        pub lean: f64,
    }
}

wscg_math::params! {
    /// Noise of the simulated sensor: AR(1) in time with coefficient `rho`, standard deviations
    /// in metres.
    #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
    pub struct NoiseParams {
        /// AR(1) coefficient (0.7).
        pub rho: f64,
        /// Whole-skeleton translation (0.01).
        pub common: f64,
        /// Spine, hips, shoulders, neck, head (0.002).
        pub trunk: f64,
        /// Elbows, knees (0.005).
        pub middle: f64,
        /// Wrists, ankles (0.008).
        pub distal: f64,
        /// Hands, feet, hand tips, thumbs (0.012).
        pub extremity: f64,
    }
}

impl Default for NoiseParams {
    fn default() -> Self {
        Self {
            rho: 0.7,
            common: 0.01,
            trunk: 0.002,
            middle: 0.005,
            distal: 0.008,
            extremity: 0.012,
        }
    }
}

impl NoiseParams {
    /// No noise at all.
    pub fn none() -> Self {
        Self {
            rho: 0.0,
            common: 0.0,
            trunk: 0.0,
            middle: 0.0,
            distal: 0.0,
            extremity: 0.0,
        }
    }

    /// Errors: `rho` outside `[0, 1)`, a negative or non-finite standard deviation.
    pub fn validate(&self) -> Result<()> {
        if !(0.0..1.0).contains(&self.rho) {
            return Err(Error::invalid(
                "rho",
                format!("the AR(1) coefficient must lie in [0, 1), got {}", self.rho),
            ));
        }
        for (name, v) in [
            ("common", self.common),
            ("trunk", self.trunk),
            ("middle", self.middle),
            ("distal", self.distal),
            ("extremity", self.extremity),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("noise standard deviation must be finite and >= 0, got {v}"),
                ));
            }
        }
        Ok(())
    }

    fn joint_sigma(&self, j: usize) -> f64 {
        use Joint::*;
        match Joint::ALL[j] {
            ElbowLeft | ElbowRight | KneeLeft | KneeRight => self.middle,
            WristLeft | WristRight | AnkleLeft | AnkleRight => self.distal,
            HandLeft | HandRight | FootLeft | FootRight | HandTipLeft | HandTipRight
            | ThumbLeft | ThumbRight => self.extremity,
            _ => self.trunk,
        }
    }
}

wscg_math::params! {
    /// One recording of a subject.
    #[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
    pub struct SessionParams {
        /// Cadence multiplier (a pure time warp; default drawn in [0.9, 1.1]).
        pub speed: f64,
        /// Walking direction about the vertical, degrees; 0 walks straight at the sensor.
        pub heading_deg: f64,
        /// Sensor pitch, degrees.
        pub pitch_deg: f64,
        /// Walk midpoint, metres: lateral and depth offsets from (0, 3.2 m) in front of the sensor.
        pub offset: [f64; 2],
        /// Seconds of walking.
        pub walk_s: f64,
        /// Append a 1 s "sit down" tail.
        pub sit_tail: bool,
        /// Standard deviation of the per-session jitter of every angle parameter, degrees (1).
        pub jitter_deg: f64,
        /// Half-range of the per-session bone-length bias (0.02 = ±2 %).
        pub bone_bias: f64,
        /// Initial gait phase in [0, 1).
        pub phase0: f64,
        /// Frame rate (30).
        pub fps: f64,
        /// Sensor noise.
        pub noise: NoiseParams,
    }
}

impl Default for SessionParams {
    fn default() -> Self {
        Self {
            speed: 1.0,
            heading_deg: 0.0,
            pitch_deg: 0.0,
            offset: [0.0, 0.0],
            walk_s: 3.0,
            sit_tail: false,
            jitter_deg: 1.0,
            bone_bias: 0.02,
            phase0: 0.0,
            fps: 30.0,
            noise: NoiseParams::default(),
        }
    }
}

/// Ranges from which [`SessionParams::draw`] samples a session.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SessionRanges {
    /// Speed factor range ([0.9, 1.1]).
    pub speed: [f64; 2],
    /// Heading range, degrees ([-60, 60]).
    pub heading_deg: [f64; 2],
    /// Sensor pitch range, degrees ([-5, 5]).
    pub pitch_deg: [f64; 2],
    /// Walking time range, seconds ([2.5, 4]).
    pub walk_s: [f64; 2],
    /// Probability of a sit-down tail (0.5).
    pub sit_prob: f64,
    /// Range of the initial gait phase ([0, 1): any step may come first).
    pub phase0: [f64; 2],
}

impl Default for SessionRanges {
    fn default() -> Self {
        Self {
            speed: [0.9, 1.1],
            heading_deg: [-60.0, 60.0],
            pitch_deg: [-5.0, 5.0],
            walk_s: [2.5, 4.0],
            sit_prob: 0.5,
            phase0: [0.0, 1.0],
        }
    }
}

impl SessionParams {
    /// A session drawn from `ranges` with the default noise.
    pub fn draw(ranges: &SessionRanges, seed: u64) -> Self {
        let mut r = stream(seed, 0x5e55);
        let mut u = |lo: f64, hi: f64| if hi > lo { r.random_range(lo..hi) } else { lo };
        Self {
            speed: u(ranges.speed[0], ranges.speed[1]),
            heading_deg: u(ranges.heading_deg[0], ranges.heading_deg[1]),
            pitch_deg: u(ranges.pitch_deg[0], ranges.pitch_deg[1]),
            offset: [u(-0.5, 0.5), u(-0.5, 0.5)],
            walk_s: u(ranges.walk_s[0], ranges.walk_s[1]),
            sit_tail: u(0.0, 1.0) < ranges.sit_prob,
            phase0: u(ranges.phase0[0], ranges.phase0[1]),
            ..Self::default()
        }
    }

    /// Errors: a non-positive or non-finite `speed`, `walk_s` or `fps`; non-finite angles,
    /// offsets or phase; a negative `jitter_deg`; `bone_bias` outside `[0, 1)`; invalid noise
    /// (see [`NoiseParams::validate`]); more than 10^6 frames.
    pub fn validate(&self) -> Result<()> {
        let pos = |name: &'static str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::invalid(name, format!("must be positive, got {v}")))
            }
        };
        pos("speed", self.speed)?;
        pos("walk_s", self.walk_s)?;
        pos("fps", self.fps)?;
        for (name, v) in [
            ("heading_deg", self.heading_deg),
            ("pitch_deg", self.pitch_deg),
            ("offset", self.offset[0]),
            ("offset", self.offset[1]),
            ("phase0", self.phase0),
        ] {
            if !v.is_finite() {
                return Err(Error::invalid(name, format!("must be finite, got {v}")));
            }
        }
        if !(self.jitter_deg.is_finite() && self.jitter_deg >= 0.0) {
            return Err(Error::invalid(
                "jitter_deg",
                format!("must be finite and >= 0, got {}", self.jitter_deg),
            ));
        }
        if !(0.0..1.0).contains(&self.bone_bias) {
            return Err(Error::invalid(
                "bone_bias",
                format!(
                    "must lie in [0, 1) (bone lengths are scaled by 1 +- bone_bias), got {}",
                    self.bone_bias
                ),
            ));
        }
        self.noise.validate()?;
        if self.walk_s * self.fps > 1e6 {
            return Err(Error::invalid("walk_s", "more than 10^6 frames"));
        }
        Ok(())
    }
}

/// Ground truth of a synthetic walk.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WalkTruth {
    /// Subject identity.
    pub subject: u32,
    /// Frames where the legs cross (minima of the noise-free horizontal ankle distance) during
    /// the walking part.
    pub minima: Vec<usize>,
    /// Number of walking frames; a sit-down tail (if any) starts here.
    pub walk_frames: usize,
    /// The same walk without sensor noise.
    pub clean: SkeletonSeq,
}

/// `n` subjects drawn with `seed` (identities `0..n`).
pub fn subjects(n: usize, seed: u64) -> Vec<SubjectParams> {
    (0..n).map(|i| subject(i as u32, seed)).collect()
}

fn subject(id: u32, seed: u64) -> SubjectParams {
    let mut r = stream(seed, 1 + id as u64);
    let mut u = |lo: f64, hi: f64| r.random_range(lo..hi);
    let height = u(1.55, 1.95);
    let mut seg = Segments::winter(height);
    let mut rn = stream(seed, 0x1000_0000 + id as u64);
    for s in seg.as_array_mut() {
        let e: f64 = StandardNormal.sample(&mut rn);
        *s *= 1.0 + 0.03 * e;
    }
    let mut n = |sd: f64| -> f64 {
        let e: f64 = StandardNormal.sample(&mut rn);
        sd * e
    };
    let harm = [n(2.0), n(2.0), n(2.0), n(2.0)];
    let mut r = stream(seed, 0x2000_0000 + id as u64);
    let mut u = |lo: f64, hi: f64| r.random_range(lo..hi);
    SubjectParams {
        id,
        height,
        seg,
        cadence: u(95.0, 125.0),
        hip: [
            u(5.0, 12.0),
            u(16.0, 24.0),
            harm[0],
            harm[1],
            harm[2],
            harm[3],
        ],
        knee: [u(8.0, 20.0), u(55.0, 68.0)],
        ankle_amp: u(5.0, 12.0),
        ankle_phase: u(0.0, TAU),
        arm_swing: u(10.0, 30.0),
        elbow: u(10.0, 35.0),
        bob: u(0.01, 0.03),
        sway: u(0.01, 0.04),
        pelvis_rot: u(3.0, 8.0),
        girdle_rot: u(3.0, 8.0),
        lean: u(0.0, 8.0),
    }
}

/// Periodic Gaussian bump of `φ` around `centre` with width `w`.
fn bump(phi: f64, centre: f64, w: f64) -> f64 {
    let d = (phi - centre + 0.5).rem_euclid(1.0) - 0.5;
    (-d * d / (2.0 * w * w)).exp()
}

/// Rotation of `v` about the unit axis `k` by `a` radians (Rodrigues).
fn rotate(v: [f64; 3], k: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    let kv = wscg_math::vec3::cross(k, v);
    let kd = wscg_math::vec3::dot(k, v);
    [
        v[0] * c + kv[0] * s + k[0] * kd * (1.0 - c),
        v[1] * c + kv[1] * s + k[1] * kd * (1.0 - c),
        v[2] * c + kv[2] * s + k[2] * kd * (1.0 - c),
    ]
}

const Y: [f64; 3] = [0.0, 1.0, 0.0];

/// Joint angles of one leg or arm at one instant, radians.
struct LegPose {
    hip: f64,
    knee: f64,
    ankle: f64,
}

/// The per-frame state that the pose depends on.
struct Pose {
    /// SpineBase in the body frame.
    root: [f64; 3],
    right: LegPose,
    left: LegPose,
    /// Arm swing (right, left), radians.
    arm: [f64; 2],
    /// Elbow flexion (right, left), radians.
    elbow: [f64; 2],
    pelvis_rot: f64,
    girdle_rot: f64,
}

/// Session-specific subject parameters (jittered angles, biased bones).
struct Gait {
    p: SubjectParams,
}

impl Gait {
    fn leg(&self, phi: f64) -> LegPose {
        let h = &self.p.hip;
        let w = TAU * phi;
        let hip = h[0]
            + h[1] * w.cos()
            + h[2] * (2.0 * w).cos()
            + h[3] * (2.0 * w).sin()
            + h[4] * (3.0 * w).cos()
            + h[5] * (3.0 * w).sin();
        let knee = self.p.knee[0] * bump(phi, 0.15, 0.08) + self.p.knee[1] * bump(phi, 0.72, 0.12);
        let ankle = self.p.ankle_amp * (w + self.p.ankle_phase).sin();
        LegPose {
            hip: hip.to_radians(),
            knee: knee.to_radians(),
            ankle: ankle.to_radians(),
        }
    }

    fn pelvis_height(&self) -> f64 {
        let s = &self.p.seg;
        0.03 * self.p.height
            + (s.thigh + s.shank) * self.p.hip[0].to_radians().cos()
            + 0.04 * self.p.height
    }

    fn stride_length(&self) -> f64 {
        let s = &self.p.seg;
        let (h0, h1) = (self.p.hip[0].to_radians(), self.p.hip[1].to_radians());
        2.0 * (s.thigh + s.shank) * ((h0 + h1).sin() - (h0 - h1).sin())
    }

    fn walking(&self, phi: f64, strides: f64) -> Pose {
        let w = TAU * phi;
        let elbow = |ph: f64| (self.p.elbow + 5.0 * (TAU * ph).cos()).to_radians();
        Pose {
            root: [
                self.p.sway * w.sin(),
                self.pelvis_height() + self.p.bob * (2.0 * w).cos(),
                self.stride_length() * strides,
            ],
            right: self.leg(phi),
            left: self.leg(phi + 0.5),
            arm: [
                -self.p.arm_swing.to_radians() * w.cos(),
                self.p.arm_swing.to_radians() * w.cos(),
            ],
            elbow: [elbow(phi), elbow(phi + 0.5)],
            pelvis_rot: -self.p.pelvis_rot.to_radians() * w.cos(),
            girdle_rot: self.p.girdle_rot.to_radians() * w.cos(),
        }
    }

    /// Blend of the walking pose at the tail start toward sitting, `s` in [0, 1].
    fn sitting(&self, from: &Pose, s: f64) -> Pose {
        let e = s * s * (3.0 - 2.0 * s);
        let mix = |a: f64, b: f64| a + e * (b - a);
        let sit = |l: &LegPose| LegPose {
            hip: mix(l.hip, PI / 2.0),
            knee: mix(l.knee, PI / 2.0),
            ankle: mix(l.ankle, 0.0),
        };
        Pose {
            root: [from.root[0], from.root[1] - 0.45 * e, from.root[2]],
            right: sit(&from.right),
            left: sit(&from.left),
            arm: [mix(from.arm[0], 0.0), mix(from.arm[1], 0.0)],
            elbow: [mix(from.elbow[0], 0.3), mix(from.elbow[1], 0.3)],
            pelvis_rot: mix(from.pelvis_rot, 0.0),
            girdle_rot: mix(from.girdle_rot, 0.0),
        }
    }

    /// Joint positions in the body frame.
    fn frame(&self, q: &Pose) -> Frame {
        let s = &self.p.seg;
        let h = self.p.height;
        let mut f = [[0.0; 3]; N_JOINTS];
        let root = q.root;
        let set = |f: &mut Frame, j: Joint, p: [f64; 3]| f[j.index()] = p;
        set(&mut f, Joint::SpineBase, root);
        // Legs: a planar chain in the pelvis's sagittal plane, rotated with the pelvis about
        // the vertical through SpineBase.
        for (side, leg) in [(1.0, &q.right), (-1.0, &q.left)] {
            let rot = |v: [f64; 3]| rotate(v, Y, q.pelvis_rot);
            let hip = add(root, rot([side * s.hip_width / 2.0, -0.03 * h, 0.0]));
            let thigh = [0.0, -leg.hip.cos(), leg.hip.sin()];
            let knee = add_scaled(hip, s.thigh, rot(thigh));
            let b = leg.hip - leg.knee;
            let ankle = add_scaled(knee, s.shank, rot([0.0, -b.cos(), b.sin()]));
            let fa = b - leg.ankle;
            let foot = add_scaled(ankle, s.foot, rot([0.0, fa.sin(), fa.cos()]));
            let js = if side > 0.0 {
                [
                    Joint::HipRight,
                    Joint::KneeRight,
                    Joint::AnkleRight,
                    Joint::FootRight,
                ]
            } else {
                [
                    Joint::HipLeft,
                    Joint::KneeLeft,
                    Joint::AnkleLeft,
                    Joint::FootLeft,
                ]
            };
            for (j, p) in js.into_iter().zip([hip, knee, ankle, foot]) {
                set(&mut f, j, p);
            }
        }
        // Trunk: a straight axis leaning forward.
        let lean = self.p.lean.to_radians();
        let axis = [0.0, lean.cos(), lean.sin()];
        let sh = add_scaled(root, s.spine, axis);
        set(
            &mut f,
            Joint::SpineMid,
            add_scaled(root, 0.5 * s.spine, axis),
        );
        set(&mut f, Joint::SpineShoulder, sh);
        let neck = add_scaled(sh, s.neck, axis);
        set(&mut f, Joint::Neck, neck);
        set(&mut f, Joint::Head, add_scaled(neck, s.head, axis));
        // Shoulder girdle and arms, counter-rotating about the trunk axis.
        let g = |v: [f64; 3]| rotate(v, axis, q.girdle_rot);
        for (k, side) in [(0usize, 1.0), (1usize, -1.0)] {
            let shoulder = add(sh, g([side * s.shoulder_width / 2.0, 0.0, 0.0]));
            let (b, e) = (q.arm[k], q.arm[k] + q.elbow[k]);
            let upper = normalized_or_zero([side * 0.12, -b.cos(), b.sin()]);
            let fore = normalized_or_zero([side * 0.08, -e.cos(), e.sin()]);
            let elbow = add_scaled(shoulder, s.upper_arm, g(upper));
            let wrist = add_scaled(elbow, s.forearm, g(fore));
            let hand = add_scaled(wrist, 0.35 * s.hand, g(fore));
            let tip = add_scaled(wrist, s.hand, g(fore));
            let thumb = add_scaled(
                add_scaled(wrist, 0.45 * s.hand, g(fore)),
                0.03,
                g([-side, 0.0, 0.3]),
            );
            let js = if k == 0 {
                [
                    Joint::ShoulderRight,
                    Joint::ElbowRight,
                    Joint::WristRight,
                    Joint::HandRight,
                    Joint::HandTipRight,
                    Joint::ThumbRight,
                ]
            } else {
                [
                    Joint::ShoulderLeft,
                    Joint::ElbowLeft,
                    Joint::WristLeft,
                    Joint::HandLeft,
                    Joint::HandTipLeft,
                    Joint::ThumbLeft,
                ]
            };
            for (j, p) in js
                .into_iter()
                .zip([shoulder, elbow, wrist, hand, tip, thumb])
            {
                set(&mut f, j, p);
            }
        }
        f
    }
}

/// The subject as recorded in one session: angle jitter and bone-length bias applied.
fn session_subject(sp: &SubjectParams, ses: &SessionParams, rng: &mut Rng) -> SubjectParams {
    let mut p = *sp;
    let mut n = |sd: f64| -> f64 {
        let e: f64 = StandardNormal.sample(&mut *rng);
        sd * e
    };
    let j = ses.jitter_deg;
    for h in &mut p.hip {
        *h += n(j);
    }
    for k in &mut p.knee {
        *k += n(j);
    }
    p.ankle_amp += n(j);
    p.arm_swing += n(j);
    p.elbow += n(j);
    p.pelvis_rot += n(j);
    p.girdle_rot += n(j);
    p.lean += n(j);
    for s in p.seg.as_array_mut() {
        *s *= 1.0 + ses.bone_bias * rng.random_range(-1.0..=1.0);
    }
    p
}

/// Body frame to camera frame: heading about the vertical (0 = walking at the sensor), walk
/// midpoint in front of a sensor 1 m above the floor, then the sensor pitch.
struct Placement {
    heading: f64,
    pitch: f64,
    origin: [f64; 3],
}

impl Placement {
    fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        // Walking at the sensor: body +z maps to camera -z.
        let w = rotate(p, Y, PI + self.heading);
        let w = add(w, self.origin);
        rotate(w, [1.0, 0.0, 0.0], self.pitch)
    }
}

/// Generates one walk of `subject` recorded in `session` (noise seeded by `seed`), with its
/// ground truth.
///
/// Errors: non-positive speed, duration or frame rate, non-finite parameters, negative noise.
pub fn walk(
    subject: &SubjectParams,
    session: &SessionParams,
    seed: u64,
) -> Result<(SkeletonSeq, WalkTruth)> {
    session.validate()?;
    let mut rng = stream(seed, 0xa11 + subject.id as u64);
    let gait = Gait {
        p: session_subject(subject, session, &mut rng),
    };
    let fps = session.fps;
    let f_stride = gait.p.cadence * session.speed / 120.0;
    let walk_frames = (session.walk_s * fps).round().max(1.0) as usize;
    let tail_frames = if session.sit_tail {
        fps.round() as usize
    } else {
        0
    };
    let total = walk_frames + tail_frames;
    // Place the walk so that its midpoint is at the session offset.
    let half = gait.stride_length() * f_stride * session.walk_s / 2.0;
    let heading = session.heading_deg.to_radians();
    let mid = rotate([0.0, 0.0, half], Y, PI + heading);
    let place = Placement {
        heading,
        pitch: session.pitch_deg.to_radians(),
        origin: [
            session.offset[0] - mid[0],
            -1.0,
            3.2 + session.offset[1] - mid[2],
        ],
    };
    let mut clean = Vec::with_capacity(total);
    let mut last = None;
    for t in 0..total {
        let q = if t < walk_frames {
            let tau = t as f64 / fps;
            let strides = f_stride * tau;
            let q = gait.walking(session.phase0 + strides, strides);
            if t + 1 == walk_frames {
                last = Some(gait.walking(session.phase0 + strides, strides));
            }
            q
        } else {
            let from = last
                .as_ref()
                .unwrap_or_else(|| unreachable!("walk_frames >= 1"));
            let s = (t + 1 - walk_frames) as f64 / tail_frames as f64;
            gait.sitting(from, s)
        };
        let body = gait.frame(&q);
        let frame: Frame = std::array::from_fn(|j| place.apply(body[j]));
        clean.push(frame);
    }
    let noisy = add_noise(&clean, &session.noise, &mut rng);
    let clean = SkeletonSeq::new(fps, clean)?;
    let seq = SkeletonSeq::new(fps, noisy)?;
    let minima = true_crossings(&clean, walk_frames)?;
    Ok((
        seq,
        WalkTruth {
            subject: subject.id,
            minima,
            walk_frames,
            clean,
        },
    ))
}

/// Leg crossings of the noise-free walk: minima of the unsmoothed horizontal ankle distance
/// inside the walking frames (prominence 0.2 of its range, 0.25 s apart).
fn true_crossings(clean: &SkeletonSeq, walk_frames: usize) -> Result<Vec<usize>> {
    let u = up_vector(clean, UpAxis::Estimate)?;
    let d = ankle_distance(clean, u);
    let walk = &d[..walk_frames.min(d.len())];
    if walk.len() < 3 {
        return Ok(Vec::new());
    }
    let lo = walk.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = walk.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let gap = (0.25 * clean.fps).round().max(1.0) as usize;
    Ok(leg_crossings(walk, 0.2 * (hi - lo), gap))
}

/// AR(1) sensor noise: a common-mode translation plus per-joint noise, stationary variance.
fn add_noise(clean: &[Frame], n: &NoiseParams, rng: &mut Rng) -> Vec<Frame> {
    let innov = (1.0 - n.rho * n.rho).sqrt();
    let mut g = || -> f64 { StandardNormal.sample(&mut *rng) };
    let mut common = [g(), g(), g()];
    let mut per: Vec<[f64; 3]> = (0..N_JOINTS).map(|_| [g(), g(), g()]).collect();
    let mut out = Vec::with_capacity(clean.len());
    for (t, f) in clean.iter().enumerate() {
        if t > 0 {
            for c in &mut common {
                *c = n.rho * *c + innov * g();
            }
            for p in &mut per {
                for c in p.iter_mut() {
                    *c = n.rho * *c + innov * g();
                }
            }
        }
        let frame: Frame = std::array::from_fn(|j| {
            let s = n.joint_sigma(j);
            std::array::from_fn(|k| f[j][k] + n.common * common[k] + s * per[j][k])
        });
        out.push(frame);
    }
    out
}

/// A labelled set of synthetic walks: `n_subjects` people x `n_sessions` recordings.
#[derive(Clone, Debug)]
pub struct WalkSet {
    /// The subjects.
    pub subjects: Vec<SubjectParams>,
    /// The walks, subject-major (`subject * n_sessions + session`).
    pub walks: Vec<SkeletonSeq>,
    /// Ground truth of each walk.
    pub truth: Vec<WalkTruth>,
    /// Session parameters of each walk.
    pub sessions: Vec<SessionParams>,
    /// Subject label of each walk.
    pub labels: Vec<u32>,
    /// Session index of each walk.
    pub session_index: Vec<usize>,
}

impl WalkSet {
    /// The same walks as Kinect v1 skeletons (20 joints: SpineShoulder stands for
    /// ShoulderCenter, SpineBase for HipCenter, SpineMid for Spine; Neck, HandTip and Thumb
    /// dropped), with the same noise on the joints kept.
    pub fn to_kinect_v1(&self) -> WalkSet {
        let mut out = self.clone();
        for w in &mut out.walks {
            *w = w.to_kinect_v1();
        }
        for t in &mut out.truth {
            t.clean = t.clean.to_kinect_v1();
        }
        out
    }
}

/// The paper's protocol on synthetic people: `n_subjects` x `n_sessions` walks with sessions
/// drawn from `ranges` (subjects from `seed`, sessions and noise from `seed` and the walk).
pub fn walkers(
    n_subjects: usize,
    n_sessions: usize,
    ranges: &SessionRanges,
    seed: u64,
) -> Result<WalkSet> {
    // A walk of a few hundred frames of 25 joints (f64 x, y, z) and its noise-free copy:
    // 128 kB bound one walk from below, enough to refuse absurd counts before allocating.
    wscg_math::alloc::ensure_shape::<[u8; 1 << 17]>(
        "n_subjects, n_sessions",
        &[n_subjects, n_sessions],
    )?;
    let subjects = subjects(n_subjects, seed);
    let sessions: Vec<SessionParams> = (0..n_subjects * n_sessions)
        .map(|k| SessionParams::draw(ranges, seed.wrapping_mul(1_000_003).wrapping_add(k as u64)))
        .collect();
    walkers_with(&subjects, n_sessions, &sessions, seed)
}

/// Walks of `subjects` in the given sessions (`sessions[s * n_sessions + k]` is session `k` of
/// subject `s`); noise seeded by `seed` and the walk index.
pub fn walkers_with(
    subjects: &[SubjectParams],
    n_sessions: usize,
    sessions: &[SessionParams],
    seed: u64,
) -> Result<WalkSet> {
    if sessions.len() != subjects.len() * n_sessions {
        return Err(Error::ShapeMismatch(format!(
            "{} sessions for {} subjects x {n_sessions} sessions",
            sessions.len(),
            subjects.len()
        )));
    }
    let mut out = WalkSet {
        subjects: subjects.to_vec(),
        walks: Vec::new(),
        truth: Vec::new(),
        sessions: sessions.to_vec(),
        labels: Vec::new(),
        session_index: Vec::new(),
    };
    for (s, sub) in subjects.iter().enumerate() {
        for k in 0..n_sessions {
            let i = s * n_sessions + k;
            let (w, t) = walk(
                sub,
                &sessions[i],
                seed.wrapping_mul(7919).wrapping_add(i as u64),
            )?;
            out.walks.push(w);
            out.truth.push(t);
            out.labels.push(sub.id);
            out.session_index.push(k);
        }
    }
    Ok(out)
}
