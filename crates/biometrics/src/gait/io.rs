//! Reading and writing skeleton streams: CSV rows `frame, joint, x, y, z` (joint as Kinect v2
//! name or index, as Kinect recording tools export them) and `.npy` arrays `(T, 25, 3)`.

use std::collections::BTreeMap;
use std::path::Path;

use wscg_math::io::csv;
use wscg_math::{Error, Result};

use super::recognizer::GaitRecognizer;
use super::skeleton::{Frame, Joint, SkeletonSeq, N_JOINTS};

/// Largest skeleton file accepted (256 MiB).
pub const MAX_SKELETON_BYTES: u64 = 256 << 20;

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
    /// and column); a frame rate that is not finite and positive.
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
/// (metres; an optional header row; `#` comments). Frames are sorted by their number and
/// must each hold all 25 joints.
///
/// Errors: unreadable file, a malformed row, a frame missing a joint (named), a duplicated
/// joint, NaN coordinates, fewer than 3 frames, `fps <= 0`.
pub fn read_skeleton_csv(path: impl AsRef<Path>, fps: f64) -> Result<SkeletonSeq> {
    let path = path.as_ref();
    let text = wscg_math::error::read_text_at_most(path, MAX_SKELETON_BYTES, "skeleton files")?;
    parse_skeleton_csv(&text, path, fps)
}

/// [`read_skeleton_csv`] of a file held in memory; `origin` names the file in errors.
pub fn parse_skeleton_csv(text: &str, origin: &Path, fps: f64) -> Result<SkeletonSeq> {
    let path = origin;
    let mut frames: BTreeMap<i64, [Option<[f64; 3]>; N_JOINTS]> = BTreeMap::new();
    for (i, row) in csv::records(text.as_bytes(), path, b',')?
        .iter()
        .enumerate()
    {
        let ln = row.line;
        let cols: Vec<&str> = row.split_fields(&[';', '\t']).collect();
        if cols.len() < 5 {
            return Err(format_err(
                path,
                format!("line {ln}: expected frame, joint, x, y, z"),
            ));
        }
        let Ok(frame) = cols[0].parse::<i64>() else {
            if i == 0 || frames.is_empty() {
                continue; // header row
            }
            return Err(format_err(
                path,
                format!("line {ln}: `{}` is not a frame number", cols[0]),
            ));
        };
        let joint =
            Joint::parse(cols[1]).map_err(|e| format_err(path, format!("line {ln}: {e}")))?;
        let mut p = [0.0; 3];
        for k in 0..3 {
            p[k] = cols[2 + k].parse::<f64>().map_err(|_| {
                format_err(
                    path,
                    format!("line {ln}: `{}` is not a number", cols[2 + k]),
                )
            })?;
        }
        let slot = &mut frames.entry(frame).or_insert([None; N_JOINTS])[joint.index()];
        if slot.is_some() {
            return Err(format_err(
                path,
                format!("line {ln}: frame {frame} lists {} twice", joint.name()),
            ));
        }
        *slot = Some(p);
    }
    let mut out: Vec<Frame> = Vec::with_capacity(frames.len());
    for (f, joints) in frames {
        let mut frame = [[0.0; 3]; N_JOINTS];
        for (j, p) in joints.iter().enumerate() {
            frame[j] = p.ok_or_else(|| {
                format_err(
                    path,
                    format!(
                        "frame {f} has no {} (a Kinect v2 skeleton has {N_JOINTS} joints)",
                        Joint::ALL[j].name()
                    ),
                )
            })?;
        }
        out.push(frame);
    }
    SkeletonSeq::new(fps, out)
}

/// Reads a `.npy` array of shape `(T, 25, 3)` (any float or integer dtype).
///
/// Errors: unreadable or malformed file, another shape, and everything
/// [`SkeletonSeq::from_flat`] checks.
pub fn read_skeleton_npy(path: impl AsRef<Path>, fps: f64) -> Result<SkeletonSeq> {
    let path = path.as_ref();
    let a = wscg_math::npy::read::<f64>(path)?;
    if a.shape.len() != 3 || a.shape[2] != 3 {
        return Err(Error::ShapeMismatch(format!(
            "{}: expected shape (T, 25, 3), got {:?}",
            path.display(),
            a.shape
        )));
    }
    SkeletonSeq::from_flat(fps, &a.data, a.shape[0], a.shape[1])
}

/// Reads a skeleton stream by extension: `.npy`, else CSV.
pub fn read_skeleton(path: impl AsRef<Path>, fps: f64) -> Result<SkeletonSeq> {
    let path = path.as_ref();
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
    {
        read_skeleton_npy(path, fps)
    } else {
        read_skeleton_csv(path, fps)
    }
}

/// Writes a skeleton CSV (header `frame,joint,x,y,z`, joints by name).
pub fn write_skeleton_csv(path: impl AsRef<Path>, s: &SkeletonSeq) -> Result<()> {
    let path = path.as_ref();
    let mut buf = String::from("frame,joint,x,y,z\n");
    for (t, f) in s.frames.iter().enumerate() {
        for (j, p) in f.iter().enumerate() {
            buf.push_str(&format!(
                "{t},{},{:.6},{:.6},{:.6}\n",
                Joint::ALL[j].name(),
                p[0],
                p[1],
                p[2]
            ));
        }
    }
    wscg_math::io::atomic::write(path, buf)
}

/// Writes a `.npy` array `(T, 25, 3)` of f64.
pub fn write_skeleton_npy(path: impl AsRef<Path>, s: &SkeletonSeq) -> Result<()> {
    wscg_math::npy::write_f64(path, &[s.len(), N_JOINTS, 3], &s.to_flat())
}
