//! Any BVH skeleton: the parsed hierarchy (joint names, parents, offsets, channel lists and
//! rotation orders, end sites), the motion, and forward kinematics on it.
//!
//! BVH conventions followed (Meredith and Maddock, *Motion capture file formats explained*,
//! 2001, section 3): a joint's local transform is the translation `OFFSET + (Xposition,
//! Yposition, Zposition)` followed by the rotations of its channels composed in the order they
//! are listed (`CHANNELS 3 Zrotation Xrotation Yrotation` is `Rz · Rx · Ry`), angles in degrees;
//! world transforms are the products along the chain from the root.

use nalgebra::{UnitQuaternion, Vector3};
use std::path::Path;
use wscg_math::error::ensure_finite;
use wscg_math::{Error, Result};

/// Metres to BVH units (centimetres).
pub const UNITS_PER_METRE: f64 = 100.0;

/// A motion read from or written to BVH.
#[derive(Clone, Debug, PartialEq)]
pub struct BvhMotion {
    /// Seconds per frame.
    pub frame_time: f64,
    /// 51 exponential-map channels per frame.
    pub angles: Vec<Vec<f64>>,
    /// Pelvis position per frame (metres).
    pub root: Vec<[f64; 3]>,
}

/// One channel of a BVH joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Translation along x (file units).
    Xposition,
    /// Translation along y.
    Yposition,
    /// Translation along z.
    Zposition,
    /// Rotation about x, degrees.
    Xrotation,
    /// Rotation about y, degrees.
    Yrotation,
    /// Rotation about z, degrees.
    Zrotation,
}

impl Channel {
    /// The channel named `s` (`Xposition` … `Zrotation`, case-insensitive).
    pub fn parse(s: &str) -> Option<Self> {
        const ALL: [(&str, Channel); 6] = [
            ("xposition", Channel::Xposition),
            ("yposition", Channel::Yposition),
            ("zposition", Channel::Zposition),
            ("xrotation", Channel::Xrotation),
            ("yrotation", Channel::Yrotation),
            ("zrotation", Channel::Zrotation),
        ];
        ALL.iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(s))
            .map(|(_, c)| *c)
    }

    /// The channel's BVH name.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }

    /// The axis index (0 = x, 1 = y, 2 = z) and whether the channel is a rotation.
    pub fn axis(self) -> (usize, bool) {
        match self {
            Channel::Xposition => (0, false),
            Channel::Yposition => (1, false),
            Channel::Zposition => (2, false),
            Channel::Xrotation => (0, true),
            Channel::Yrotation => (1, true),
            Channel::Zrotation => (2, true),
        }
    }
}

/// One joint of a BVH hierarchy.
#[derive(Clone, Debug, PartialEq)]
pub struct BvhJoint {
    /// The joint's name as written in the file.
    pub name: String,
    /// Index of the parent joint (`None` for a root).
    pub parent: Option<usize>,
    /// Rest offset from the parent joint (file units).
    pub offset: [f64; 3],
    /// Channels in file order.
    pub channels: Vec<Channel>,
    /// Offsets of the joint's end sites (file units).
    pub end_sites: Vec<[f64; 3]>,
}

impl BvhJoint {
    /// Rotation order as the axes of the rotation channels in file order (`"ZXY"`; empty for
    /// a joint without rotation channels).
    pub fn rotation_order(&self) -> String {
        self.channels
            .iter()
            .filter(|c| c.axis().1)
            .map(|c| ["X", "Y", "Z"][c.axis().0])
            .collect()
    }
}

/// A parsed BVH file of any skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct BvhFile {
    /// Joints in file order (a parent precedes its children).
    pub joints: Vec<BvhJoint>,
    /// Seconds per frame.
    pub frame_time: f64,
    /// Channel values per frame, joints and channels in file order (positions in file units,
    /// rotations in degrees).
    pub frames: Vec<Vec<f64>>,
}

/// World transform of one joint: rotation and position (file units).
pub type Pose = (UnitQuaternion<f64>, Vector3<f64>);

impl BvhFile {
    /// Number of channels of one frame.
    pub fn n_channels(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }

    /// Index of the joint named `name` (exact match).
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Indices of the children of joint `j`.
    pub fn children(&self, j: usize) -> Vec<usize> {
        (0..self.joints.len())
            .filter(|&c| self.joints[c].parent == Some(j))
            .collect()
    }

    /// World rotation and position of every joint in frame `frame` (`None`: the rest pose,
    /// every channel zero).
    ///
    /// # Errors
    /// A frame index beyond the motion.
    pub fn world_poses(&self, frame: Option<usize>) -> Result<Vec<Pose>> {
        let values = match frame {
            None => None,
            Some(f) => Some(self.frames.get(f).ok_or_else(|| {
                Error::invalid(
                    "frame",
                    format!("{f} is beyond the {} frames", self.frames.len()),
                )
            })?),
        };
        let mut out: Vec<Pose> = Vec::with_capacity(self.joints.len());
        let mut k = 0;
        for j in &self.joints {
            let mut t = Vector3::from(j.offset);
            let mut r = UnitQuaternion::identity();
            for c in &j.channels {
                let v = values.map_or(0.0, |vals| vals[k]);
                k += 1;
                let (axis, rotation) = c.axis();
                if rotation {
                    let a = match axis {
                        0 => Vector3::x_axis(),
                        1 => Vector3::y_axis(),
                        _ => Vector3::z_axis(),
                    };
                    r *= UnitQuaternion::from_axis_angle(&a, v.to_radians());
                } else {
                    t[axis] += v;
                }
            }
            out.push(match j.parent {
                None => (r, t),
                Some(p) => (out[p].0 * r, out[p].1 + out[p].0 * t),
            });
        }
        Ok(out)
    }
}

/// World positions of every joint of `file` in every frame, `[frame][joint]`, file units
/// (forward kinematics of the hierarchy; module documentation gives the conventions).
pub fn bvh_forward_kinematics(file: &BvhFile) -> Vec<Vec<[f64; 3]>> {
    (0..file.frames.len())
        .map(|f| {
            file.world_poses(Some(f))
                .map(|poses| poses.iter().map(|(_, p)| [p.x, p.y, p.z]).collect())
                .unwrap_or_default()
        })
        .collect()
}

fn number<'a>(
    tokens: &mut impl Iterator<Item = &'a str>,
    what: &str,
    bad: &impl Fn(String) -> Error,
) -> Result<f64> {
    let t = tokens
        .next()
        .ok_or_else(|| bad(format!("truncated {what}")))?;
    t.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| bad(format!("bad number `{t}` in {what}")))
}

/// Parses BVH text of any skeleton.
///
/// # Errors
/// [`Error::Format`] naming `origin` for text that does not start with `HIERARCHY`, malformed
/// or truncated joints, unknown channels, duplicated joint names, a frame count that does not
/// match the values the text holds (checked before anything is allocated from it), a
/// non-positive frame time or non-finite values.
pub fn parse_bvh_file(text: &str, origin: &Path) -> Result<BvhFile> {
    let bad = |m: String| Error::format(origin, m);
    let mut tokens = text.split_whitespace();
    if tokens.next() != Some("HIERARCHY") {
        return Err(bad(
            "not a BVH file: it does not start with HIERARCHY".into()
        ));
    }
    let mut joints: Vec<BvhJoint> = Vec::new();
    // Open blocks: Some(joint) or None for an end site; `pending` is the block whose `{` comes.
    let mut stack: Vec<Option<usize>> = Vec::new();
    let mut pending: Option<Option<usize>> = None;
    loop {
        let t = tokens
            .next()
            .ok_or_else(|| bad("missing MOTION section".into()))?;
        match t {
            "ROOT" | "JOINT" => {
                let name = tokens
                    .next()
                    .ok_or_else(|| bad("joint without a name".into()))?;
                let parent = stack.last().copied().flatten();
                if t == "ROOT" && !stack.is_empty() {
                    return Err(bad(format!("ROOT `{name}` inside a joint")));
                }
                if t == "JOINT" && parent.is_none() {
                    return Err(bad(format!("JOINT `{name}` outside a joint")));
                }
                if stack.last() == Some(&None) {
                    return Err(bad(format!("joint `{name}` inside an End Site")));
                }
                if joints.iter().any(|j| j.name == name) {
                    return Err(bad(format!("joint `{name}` is declared twice")));
                }
                joints.push(BvhJoint {
                    name: name.to_string(),
                    parent,
                    offset: [0.0; 3],
                    channels: Vec::new(),
                    end_sites: Vec::new(),
                });
                pending = Some(Some(joints.len() - 1));
            }
            "End" => {
                if tokens.next() != Some("Site") {
                    return Err(bad("`End` not followed by `Site`".into()));
                }
                let j = stack
                    .last()
                    .copied()
                    .flatten()
                    .ok_or_else(|| bad("End Site outside a joint".into()))?;
                joints[j].end_sites.push([0.0; 3]);
                pending = Some(None);
            }
            "{" => {
                stack.push(
                    pending
                        .take()
                        .ok_or_else(|| bad("`{` without a joint".into()))?,
                );
            }
            "}" => {
                stack.pop().ok_or_else(|| bad("unbalanced `}`".into()))?;
            }
            "OFFSET" => {
                let mut off = [0.0; 3];
                for o in &mut off {
                    *o = number(&mut tokens, "OFFSET", &bad)?;
                }
                match stack.last() {
                    Some(Some(j)) => joints[*j].offset = off,
                    Some(None) => {
                        let j = stack
                            .iter()
                            .rev()
                            .find_map(|s| *s)
                            .ok_or_else(|| bad("End Site outside a joint".into()))?;
                        if let Some(e) = joints[j].end_sites.last_mut() {
                            *e = off;
                        }
                    }
                    None => return Err(bad("OFFSET outside a joint".into())),
                }
            }
            "CHANNELS" => {
                let n: usize = tokens
                    .next()
                    .and_then(|v| v.parse().ok())
                    .ok_or_else(|| bad("bad CHANNELS count".into()))?;
                if n > 6 {
                    return Err(bad(format!("CHANNELS {n}: a joint has at most 6 channels")));
                }
                let j = stack
                    .last()
                    .copied()
                    .flatten()
                    .ok_or_else(|| bad("CHANNELS outside a joint".into()))?;
                let mut chans = Vec::with_capacity(n);
                for _ in 0..n {
                    let name = tokens
                        .next()
                        .ok_or_else(|| bad("truncated CHANNELS line".into()))?;
                    let c = Channel::parse(name)
                        .ok_or_else(|| bad(format!("unknown channel `{name}`")))?;
                    chans.push(c);
                }
                joints[j].channels = chans;
            }
            "MOTION" => break,
            other => return Err(bad(format!("unexpected token `{other}` in HIERARCHY"))),
        }
    }
    if !stack.is_empty() || pending.is_some() {
        return Err(bad("unbalanced braces in HIERARCHY".into()));
    }
    if joints.is_empty() {
        return Err(bad("the HIERARCHY declares no joint".into()));
    }
    let expect = |tokens: &mut std::str::SplitWhitespace, word: &str| -> Result<()> {
        match tokens.next() {
            Some(w) if w == word => Ok(()),
            other => Err(Error::format(
                origin,
                format!("expected `{word}`, found {other:?}"),
            )),
        }
    };
    expect(&mut tokens, "Frames:")?;
    let n_frames: usize = tokens
        .next()
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| bad("bad frame count".into()))?;
    expect(&mut tokens, "Frame")?;
    expect(&mut tokens, "Time:")?;
    let frame_time: f64 = tokens
        .next()
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| bad("bad frame time".into()))?;
    if !(frame_time.is_finite() && frame_time > 0.0) {
        return Err(bad(format!("frame time must be > 0, got {frame_time}")));
    }
    let per_frame: usize = joints.iter().map(|j| j.channels.len()).sum();
    if per_frame == 0 {
        return Err(bad("the HIERARCHY declares no channels".into()));
    }
    // A declared count is checked against the values the text holds before anything is
    // allocated from it: `Frames: 1e18` overflows `frames x channels`.
    let expected = n_frames.checked_mul(per_frame).ok_or_else(|| {
        bad(format!(
            "{n_frames} frames of {per_frame} channels is more values than any file can hold"
        ))
    })?;
    let values: Vec<f64> = tokens
        .map(|v| {
            v.parse::<f64>()
                .map_err(|_| bad(format!("bad number `{v}`")))
        })
        .collect::<Result<_>>()?;
    if values.len() != expected {
        return Err(bad(format!(
            "{} motion values for {n_frames} frames of {per_frame} channels",
            values.len()
        )));
    }
    ensure_finite("motion", &values).map_err(|e| bad(e.to_string()))?;
    let frames = values
        .chunks_exact(per_frame)
        .map(<[f64]>::to_vec)
        .collect();
    Ok(BvhFile {
        joints,
        frame_time,
        frames,
    })
}

/// Reads a BVH file of any skeleton.
///
/// # Errors
/// I/O errors naming the path, text that is not UTF-8, and the errors of [`parse_bvh_file`].
pub fn read_bvh_file(path: impl AsRef<Path>) -> Result<BvhFile> {
    let path = path.as_ref();
    let bytes = wscg_math::error::read_file(path)?;
    let text = String::from_utf8(bytes).map_err(|_| Error::format(path, "not UTF-8 text"))?;
    parse_bvh_file(&text, path)
}
