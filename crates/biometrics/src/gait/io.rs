//! Reading and writing skeleton streams: CSV rows `frame, joint, x, y, z` (joint as Kinect v2
//! or Kinect v1 name or index, as Kinect recording tools export them), `.npy` arrays
//! `(T, 25, 3)` or `(T, 20, 3)`, and NTU RGB+D `.skeleton` files ([`super::ntu`]).

use std::collections::BTreeMap;
use std::path::Path;

use wscg_math::{Error, Result};

use super::ntu::{read_ntu, NtuParams};
use super::recognizer::GaitRecognizer;
use super::skeleton::{read_limited, Frame, Joint, JointSet, SkeletonSeq, N_JOINTS};

pub use super::skeleton::MAX_SKELETON_BYTES;

fn format_err(path: &Path, reason: String) -> Error {
    Error::Format {
        path: path.to_path_buf(),
        reason,
    }
}

/// Largest gait model file read (256 MiB, as skeleton files).
pub const MAX_MODEL_BYTES: u64 = 256 << 20;

/// A gait model file (JSON): the fitted recognizer with the name of each identity label, the
/// skeleton files it was enrolled from and the frame rate of the walks it identifies.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[non_exhaustive]
pub struct GaitModelFile {
    /// Frame rate of the walks (frames per second, > 0).
    pub fps: f64,
    /// Identity name of each label.
    pub identities: Vec<String>,
    /// The enrolled skeleton files.
    pub files: Vec<String>,
    /// The fitted recognizer.
    pub recognizer: GaitRecognizer,
}

impl GaitModelFile {
    /// A model file of `recognizer` fitted at `fps` on `files`, labels named by `identities`.
    pub fn new(
        fps: f64,
        identities: Vec<String>,
        files: Vec<String>,
        recognizer: GaitRecognizer,
    ) -> Self {
        GaitModelFile {
            fps,
            identities,
            files,
            recognizer,
        }
    }

    /// Reads a model file written by [`GaitModelFile::write`] (see
    /// [`GaitModelFile::from_json_bytes`]).
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = wscg_math::error::read_file_at_most(path, MAX_MODEL_BYTES, "gait models")?;
        Self::from_json_bytes(&bytes, path)
    }

    /// Parses a model file held in memory; `origin` names the file in errors.
    ///
    /// Errors ([`Error::Format`] naming `origin`): not the JSON of a gait model (with the line
    /// and column); a frame rate that is not finite and positive; a recognizer that
    /// [`GaitRecognizer::check_shapes`] refuses; a label without an identity.
    pub fn from_json_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        let m: Self = serde_json::from_slice(bytes).map_err(|e| {
            format_err(
                origin,
                format!("not a gait model written by `wscg biometrics gait enroll`: {e}"),
            )
        })?;
        if !(m.fps.is_finite() && m.fps > 0.0) {
            return Err(format_err(
                origin,
                format!("frame rate {} is not > 0", m.fps),
            ));
        }
        m.recognizer
            .check_shapes()
            .map_err(|e| format_err(origin, e.to_string()))?;
        if let Some(&l) = m
            .recognizer
            .labels
            .iter()
            .find(|&&l| l as usize >= m.identities.len())
        {
            return Err(format_err(origin, format!("label {l} has no identity")));
        }
        Ok(m)
    }

    /// Writes the model file as JSON (atomically).
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let text =
            serde_json::to_string(self).map_err(|e| Error::invalid("model", e.to_string()))?;
        wscg_math::io::atomic::write(path, text)
    }
}

/// Reads a skeleton CSV: one row per frame and joint, columns `frame, joint, x, y, z`
/// (metres; an optional header row; `#` comments). Joints are Kinect v2 or Kinect v1 SDK
/// names, or indices (0-24 for Kinect v2, 0-19 in Kinect v1 order when no index exceeds 19).
/// The file is a Kinect v1 stream when it names no Neck, HandTip or Thumb joint (and its
/// indices stay below 20). Frames are sorted by their number and must each hold every joint
/// of the set.
///
/// Errors: unreadable file, a malformed row, a frame missing a joint (named), a duplicated
/// joint, NaN coordinates, fewer than 3 frames, `fps <= 0`.
pub fn read_skeleton_csv(path: impl AsRef<Path>, fps: f64) -> Result<SkeletonSeq> {
    let path = path.as_ref();
    let text = read_limited(path)?;
    parse_skeleton_csv(&text, path, fps)
}

/// [`read_skeleton_csv`] of a file held in memory; `origin` names the file in errors.
pub fn parse_skeleton_csv(text: &str, origin: &Path, fps: f64) -> Result<SkeletonSeq> {
    let path = origin;
    // (line, frame, joint column, point)
    let mut rows: Vec<(usize, i64, &str, [f64; 3])> = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = line.split([',', ';', '\t']).map(str::trim).collect();
        if cols.len() < 5 {
            return Err(format_err(
                path,
                format!("line {}: expected frame, joint, x, y, z", ln + 1),
            ));
        }
        let Ok(frame) = cols[0].parse::<i64>() else {
            if ln == 0 || rows.is_empty() {
                continue; // header row
            }
            return Err(format_err(
                path,
                format!("line {}: `{}` is not a frame number", ln + 1, cols[0]),
            ));
        };
        let mut p = [0.0; 3];
        for k in 0..3 {
            p[k] = cols[2 + k].parse::<f64>().map_err(|_| {
                format_err(
                    path,
                    format!("line {}: `{}` is not a number", ln + 1, cols[2 + k]),
                )
            })?;
        }
        rows.push((ln + 1, frame, cols[1], p));
    }
    let v2_only = |c: &str| match c.parse::<usize>() {
        Ok(i) => i >= 20,
        Err(_) => Joint::parse(c).is_ok_and(|j| !JointSet::KinectV1.contains(j)),
    };
    let v1_name = |c: &str| {
        ["HipCenter", "Spine", "ShoulderCenter"]
            .iter()
            .any(|n| n.eq_ignore_ascii_case(c))
    };
    let numeric = |c: &str| c.parse::<usize>().is_ok();
    let frames_of = |set: JointSet| -> Result<Vec<Frame>> {
        let mut frames: BTreeMap<i64, [Option<[f64; 3]>; N_JOINTS]> = BTreeMap::new();
        for &(ln, frame, col, p) in &rows {
            let joint = match col.parse::<usize>() {
                Ok(i) => set.joints().get(i).copied().ok_or_else(|| {
                    Error::invalid(
                        "joint",
                        format!("index {i} is out of range 0..{}", set.len()),
                    )
                }),
                Err(_) => Joint::parse(col),
            }
            .map_err(|e| format_err(path, format!("line {ln}: {e}")))?;
            let slot = &mut frames.entry(frame).or_insert([None; N_JOINTS])[joint.index()];
            if slot.is_some() {
                return Err(format_err(
                    path,
                    format!(
                        "line {ln}: frame {frame} lists {} twice",
                        set.name_of(joint)
                    ),
                ));
            }
            *slot = Some(p);
        }
        let mut out: Vec<Frame> = Vec::with_capacity(frames.len());
        for (f, joints) in frames {
            let mut frame = [[f64::NAN; 3]; N_JOINTS];
            for &j in set.joints() {
                frame[j.index()] = joints[j.index()].ok_or_else(|| {
                    format_err(
                        path,
                        format!(
                            "frame {f} has no {} (a {set:?} skeleton has {} joints)",
                            set.name_of(j),
                            set.len()
                        ),
                    )
                })?;
            }
            out.push(frame);
        }
        Ok(out)
    };
    // Kinect v2 when a row names a joint Kinect v1 lacks; Kinect v1 when a row uses a v1-only
    // name or all joints are indices below 20; otherwise (shared names only) Kinect v1 when
    // every frame holds its 20 joints.
    let (set, frames) = if rows.iter().any(|r| v2_only(r.2)) {
        (JointSet::KinectV2, frames_of(JointSet::KinectV2)?)
    } else if rows.iter().any(|r| v1_name(r.2)) || rows.iter().all(|r| numeric(r.2)) {
        (JointSet::KinectV1, frames_of(JointSet::KinectV1)?)
    } else {
        match frames_of(JointSet::KinectV1) {
            Ok(f) => (JointSet::KinectV1, f),
            Err(_) => (JointSet::KinectV2, frames_of(JointSet::KinectV2)?),
        }
    };
    SkeletonSeq::with_joints(fps, frames, set)
}

/// Reads a `.npy` array of shape `(T, 25, 3)` (Kinect v2) or `(T, 20, 3)` (Kinect v1), any
/// float or integer dtype.
///
/// Errors: unreadable or malformed file, another shape, and everything
/// [`SkeletonSeq::from_flat`] checks.
pub fn read_skeleton_npy(path: impl AsRef<Path>, fps: f64) -> Result<SkeletonSeq> {
    let path = path.as_ref();
    let a = wscg_math::npy::read::<f64>(path)?;
    if a.shape.len() != 3 || a.shape[2] != 3 {
        return Err(Error::ShapeMismatch(format!(
            "{}: expected shape (T, 25, 3) or (T, 20, 3), got {:?}",
            path.display(),
            a.shape
        )));
    }
    SkeletonSeq::from_flat(fps, &a.data, a.shape[0], a.shape[1])
}

/// Reads a skeleton stream by extension: `.npy`, `.skeleton` (NTU RGB+D, the most tracked
/// body), else CSV.
pub fn read_skeleton(path: impl AsRef<Path>, fps: f64) -> Result<SkeletonSeq> {
    read_skeleton_with(path, fps, &NtuParams::default())
}

/// [`read_skeleton`] with the body choice of NTU RGB+D files.
pub fn read_skeleton_with(
    path: impl AsRef<Path>,
    fps: f64,
    ntu: &NtuParams,
) -> Result<SkeletonSeq> {
    let path = path.as_ref();
    let ext = |x: &str| path.extension().is_some_and(|e| e.eq_ignore_ascii_case(x));
    if ext("npy") {
        read_skeleton_npy(path, fps)
    } else if ext("skeleton") {
        read_ntu(path, fps, ntu)
    } else {
        read_skeleton_csv(path, fps)
    }
}

/// Writes a skeleton CSV (header `frame,joint,x,y,z`, joints by the SDK names of the
/// stream's Kinect version).
pub fn write_skeleton_csv(path: impl AsRef<Path>, s: &SkeletonSeq) -> Result<()> {
    let path = path.as_ref();
    let set = s.joint_set;
    let mut buf = String::from("frame,joint,x,y,z\n");
    for (t, f) in s.frames.iter().enumerate() {
        for (&j, name) in set.joints().iter().zip(set.names()) {
            let p = f[j.index()];
            buf.push_str(&format!("{t},{name},{:.6},{:.6},{:.6}\n", p[0], p[1], p[2]));
        }
    }
    wscg_math::io::atomic::write(path, buf)
}

/// Writes a `.npy` array `(T, J, 3)` of f64 (`J` = 25, or 20 for a Kinect v1 stream).
pub fn write_skeleton_npy(path: impl AsRef<Path>, s: &SkeletonSeq) -> Result<()> {
    wscg_math::npy::write_f64(path, &[s.len(), s.joint_set.len(), 3], &s.to_flat())
}
