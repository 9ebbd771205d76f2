//! BVH export and import of the 17-joint skeleton, so that synthesized motion plays in any
//! animation tool (Blender, MotionBuilder, the `bvh` Python package, …).
//!
//! Rotations are written as `Zrotation Xrotation Yrotation` Euler angles in degrees (converted
//! from the exponential maps through quaternions); positions are in centimetres. The pelvis
//! walks along +z. The reader accepts any skeleton ([`crate::bvh_file`]: any hierarchy,
//! channel and rotation order) and maps it onto the model's 17 joints by joint names
//! ([`crate::retarget`]: the model's own, CMU, Mixamo or a user map).

use crate::bvh_file::parse_bvh_file;
pub use crate::retarget::{retarget, JointMap, RetargetParams};
use crate::skeleton::{
    end_site, expmap_to_quat, matrix_to_zxy, HIP_HEIGHT, JOINTS, N_CHANNELS, N_JOINTS,
};
use std::fmt::Write as _;
use std::path::Path;
use wscg_math::error::{ensure_finite, ensure_nonempty};
use wscg_math::{Error, Result};

pub use crate::bvh_file::{BvhMotion, UNITS_PER_METRE};

fn hierarchy(out: &mut String, j: usize, depth: usize) {
    let pad = "  ".repeat(depth);
    let (name, parent, off) = JOINTS[j];
    let kind = if parent.is_none() { "ROOT" } else { "JOINT" };
    let _ = writeln!(out, "{pad}{kind} {name}\n{pad}{{");
    let _ = writeln!(
        out,
        "{pad}  OFFSET {:.4} {:.4} {:.4}",
        off[0] * UNITS_PER_METRE,
        off[1] * UNITS_PER_METRE,
        off[2] * UNITS_PER_METRE
    );
    if parent.is_none() {
        let _ = writeln!(
            out,
            "{pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
        );
    } else {
        let _ = writeln!(out, "{pad}  CHANNELS 3 Zrotation Xrotation Yrotation");
    }
    for (c, (_, p, _)) in JOINTS.iter().enumerate() {
        if *p == Some(j) {
            hierarchy(out, c, depth + 1);
        }
    }
    if let Some(e) = end_site(j) {
        let _ = writeln!(
            out,
            "{pad}  End Site\n{pad}  {{\n{pad}    OFFSET {:.4} {:.4} {:.4}\n{pad}  }}",
            e[0] * UNITS_PER_METRE,
            e[1] * UNITS_PER_METRE,
            e[2] * UNITS_PER_METRE
        );
    }
    let _ = writeln!(out, "{pad}}}");
}

/// BVH text of a motion.
///
/// # Errors
/// No frames, frames without 51 channels, different numbers of angle and root frames,
/// non-finite values or a non-positive frame time.
pub fn to_bvh_string(motion: &BvhMotion) -> Result<String> {
    ensure_nonempty("frames", motion.angles.len())?;
    if motion.root.len() != motion.angles.len() {
        return Err(Error::ShapeMismatch(format!(
            "{} angle frames and {} root positions",
            motion.angles.len(),
            motion.root.len()
        )));
    }
    if !(motion.frame_time.is_finite() && motion.frame_time > 0.0) {
        return Err(Error::invalid(
            "frame_time",
            format!("must be finite and > 0, got {}", motion.frame_time),
        ));
    }
    for (f, a) in motion.angles.iter().enumerate() {
        if a.len() != N_CHANNELS {
            return Err(Error::ShapeMismatch(format!(
                "frame {f} has {} channels, expected {N_CHANNELS}",
                a.len()
            )));
        }
        ensure_finite("angles", a)?;
    }
    let flat: Vec<f64> = motion.root.iter().flatten().copied().collect();
    ensure_finite("root", &flat)?;
    let mut out = String::from("HIERARCHY\n");
    hierarchy(&mut out, 0, 0);
    let _ = writeln!(
        out,
        "MOTION\nFrames: {}\nFrame Time: {:.8}",
        motion.angles.len(),
        motion.frame_time
    );
    for (a, r) in motion.angles.iter().zip(&motion.root) {
        let mut vals: Vec<f64> = r.iter().map(|v| v * UNITS_PER_METRE).collect();
        for j in 0..N_JOINTS {
            let q = expmap_to_quat([a[3 * j], a[3 * j + 1], a[3 * j + 2]]);
            let (z, x, y) = matrix_to_zxy(q.to_rotation_matrix().matrix());
            vals.extend([z.to_degrees(), x.to_degrees(), y.to_degrees()]);
        }
        let line: Vec<String> = vals.iter().map(|v| format!("{v:.6}")).collect();
        let _ = writeln!(out, "{}", line.join(" "));
    }
    Ok(out)
}

/// Writes a motion as BVH.
///
/// # Errors
/// As [`to_bvh_string`], and I/O errors naming the path.
pub fn write_bvh(path: impl AsRef<Path>, motion: &BvhMotion) -> Result<()> {
    let path = path.as_ref();
    let text = to_bvh_string(motion)?;
    wscg_math::io::atomic::write(path, text)
}

/// A motion of synthesized frames (`angles`, pelvis forward positions along +z).
pub fn motion_from_frames(
    angles: Vec<Vec<f64>>,
    root_forward: &[f64],
    frame_time: f64,
) -> BvhMotion {
    let root = root_forward.iter().map(|&z| [0.0, HIP_HEIGHT, z]).collect();
    BvhMotion {
        frame_time,
        angles,
        root,
    }
}

/// Parses BVH text of any skeleton and maps it onto the model's 17 joints with the default
/// [`RetargetParams`] (the model's own names, then CMU's, then Mixamo's; centimetres). Files
/// written by [`write_bvh`] read back channel for channel.
///
/// # Errors
/// [`Error::Format`] naming `origin` for malformed text, model joints the file has no joint
/// for (all listed), or frame lines of the wrong length.
pub fn parse_bvh(text: &str, origin: &Path) -> Result<BvhMotion> {
    parse_bvh_with(text, origin, &RetargetParams::default())
}

/// [`parse_bvh`] with a joint map and units.
///
/// # Errors
/// As [`parse_bvh`]; invalid parameters.
pub fn parse_bvh_with(text: &str, origin: &Path, p: &RetargetParams) -> Result<BvhMotion> {
    p.validate()?;
    let file = parse_bvh_file(text, origin)?;
    retarget(&file, p).map_err(|e| Error::format(origin, e.to_string()))
}

/// Reads a BVH file of any skeleton onto the model's (as [`parse_bvh`]).
///
/// # Errors
/// I/O errors and the errors of [`parse_bvh`].
pub fn read_bvh(path: impl AsRef<Path>) -> Result<BvhMotion> {
    read_bvh_with(path, &RetargetParams::default())
}

/// [`read_bvh`] with a joint map and units.
///
/// # Errors
/// I/O errors and the errors of [`parse_bvh_with`].
pub fn read_bvh_with(path: impl AsRef<Path>, p: &RetargetParams) -> Result<BvhMotion> {
    let path = path.as_ref();
    let bytes = wscg_math::error::read_file(path)?;
    let text = String::from_utf8(bytes).map_err(|_| Error::format(path, "not UTF-8 text"))?;
    parse_bvh_with(&text, path, p)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_frames() -> String {
        let m = BvhMotion {
            frame_time: 1.0 / 120.0,
            angles: vec![vec![0.0; N_CHANNELS]; 2],
            root: vec![[0.0; 3]; 2],
        };
        to_bvh_string(&m).unwrap()
    }

    #[test]
    fn a_frame_count_that_overflows_the_values_is_an_error_naming_the_file() {
        let text = two_frames();
        assert!(parse_bvh(&text, Path::new("ok.bvh")).is_ok());
        // 54 channels per frame: (2^63 + 2) x 54 wraps to the 108 values the file holds.
        let per_frame = 6 + 3 * (N_JOINTS - 1);
        assert_eq!(per_frame, 54);
        for frames in ["9223372036854775810", "18446744073709551615", "3"] {
            let bad = text.replace("Frames: 2", &format!("Frames: {frames}"));
            let dir = tempfile::tempdir().unwrap();
            let p = dir.path().join("huge.bvh");
            std::fs::write(&p, bad).unwrap();
            let err = read_bvh(&p).unwrap_err();
            assert!(matches!(err, Error::Format { .. }), "{err}");
            assert!(err.to_string().contains("huge.bvh"), "{err}");
        }
    }

    #[test]
    fn huge_or_empty_channel_declarations_are_errors() {
        let text = two_frames();
        let huge = text.replacen("CHANNELS 3", "CHANNELS 18446744073709551615", 1);
        assert!(parse_bvh(&huge, Path::new("h.bvh")).is_err());
        let none = text
            .replace(
                "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
                "CHANNELS 0",
            )
            .replace("CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 0");
        let motion = none.find("MOTION").unwrap();
        let none = format!(
            "{}MOTION\nFrames: 1000000000000\nFrame Time: 0.01\n",
            &none[..motion]
        );
        let err = parse_bvh(&none, Path::new("none.bvh")).unwrap_err();
        assert!(err.to_string().contains("no channels"), "{err}");
    }
}
