//! BVH export and import of the 17-joint skeleton, so that synthesized motion plays in any
//! animation tool (Blender, MotionBuilder, the `bvh` Python package, …).
//!
//! Rotations are written as `Zrotation Xrotation Yrotation` Euler angles in degrees (converted
//! from the exponential maps through quaternions); positions are in centimetres. The pelvis
//! walks along +z. The reader accepts any channel order and converts back to exponential maps.

use crate::skeleton::{
    end_site, expmap_to_quat, matrix_to_zxy, quat_to_expmap, unwrap_expmaps, HIP_HEIGHT, JOINTS,
    N_CHANNELS, N_JOINTS,
};
use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use std::fmt::Write as _;
use std::path::Path;
use wscg_math::error::{ensure_finite, ensure_nonempty};
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

/// Parses BVH text of this skeleton (joints matched by name, channels in any order).
///
/// # Errors
/// [`Error::Format`] naming `origin` for malformed text, unknown or missing joints, or frame
/// lines of the wrong length.
pub fn parse_bvh(text: &str, origin: &Path) -> Result<BvhMotion> {
    let bad = |m: String| Error::format(origin, m);
    let mut tokens = text.split_whitespace().peekable();
    // (joint index, channel names) in file order.
    let mut layout: Vec<(usize, Vec<String>)> = Vec::new();
    let mut current: Vec<Option<usize>> = Vec::new();
    let mut in_end = 0usize;
    loop {
        let t = tokens
            .next()
            .ok_or_else(|| bad("missing MOTION section".into()))?;
        match t {
            "HIERARCHY" => {}
            "ROOT" | "JOINT" => {
                let name = tokens
                    .next()
                    .ok_or_else(|| bad("joint without a name".into()))?;
                let idx = JOINTS
                    .iter()
                    .position(|j| j.0 == name)
                    .ok_or_else(|| bad(format!("unknown joint `{name}`")))?;
                current.push(Some(idx));
            }
            "End" => {
                tokens.next();
                in_end += 1;
                current.push(None);
            }
            "{" => {}
            "}" => {
                if let Some(None) = current.pop() {
                    in_end -= 1;
                }
            }
            "OFFSET" => {
                for _ in 0..3 {
                    tokens.next();
                }
            }
            "CHANNELS" => {
                let n: usize = tokens
                    .next()
                    .and_then(|v| v.parse().ok())
                    .ok_or_else(|| bad("bad CHANNELS count".into()))?;
                // At most the tokens the text holds, whatever count it declares.
                let names: Vec<String> = tokens.by_ref().take(n).map(str::to_string).collect();
                if names.len() != n || in_end > 0 {
                    return Err(bad("truncated CHANNELS line".into()));
                }
                let j = current
                    .last()
                    .copied()
                    .flatten()
                    .ok_or_else(|| bad("CHANNELS outside a joint".into()))?;
                layout.push((j, names));
            }
            "MOTION" => break,
            other => return Err(bad(format!("unexpected token `{other}` in HIERARCHY"))),
        }
    }
    let mut seen = [false; N_JOINTS];
    for (j, _) in &layout {
        seen[*j] = true;
    }
    if let Some(j) = seen.iter().position(|s| !s) {
        return Err(bad(format!("joint `{}` missing", JOINTS[j].0)));
    }
    let expect =
        |tokens: &mut std::iter::Peekable<std::str::SplitWhitespace>, word: &str| -> Result<()> {
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
    let per_frame: usize = layout.iter().map(|l| l.1.len()).sum();
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
    ensure_finite("motion", &values)?;
    let mut angles = Vec::with_capacity(n_frames);
    let mut root = Vec::with_capacity(n_frames);
    for f in 0..n_frames {
        let mut vals = values[f * per_frame..(f + 1) * per_frame].iter();
        let mut a = vec![0.0; N_CHANNELS];
        let mut pos = [0.0; 3];
        for (j, names) in &layout {
            let mut rot = Rotation3::identity();
            for name in names {
                let v = *vals.next().ok_or_else(|| bad("short frame".into()))?;
                match name.as_str() {
                    "Xposition" => pos[0] = v / UNITS_PER_METRE,
                    "Yposition" => pos[1] = v / UNITS_PER_METRE,
                    "Zposition" => pos[2] = v / UNITS_PER_METRE,
                    "Xrotation" => {
                        rot *= Rotation3::from_axis_angle(&Vector3::x_axis(), v.to_radians())
                    }
                    "Yrotation" => {
                        rot *= Rotation3::from_axis_angle(&Vector3::y_axis(), v.to_radians())
                    }
                    "Zrotation" => {
                        rot *= Rotation3::from_axis_angle(&Vector3::z_axis(), v.to_radians())
                    }
                    other => return Err(bad(format!("unknown channel `{other}`"))),
                }
            }
            let e = quat_to_expmap(&UnitQuaternion::from_rotation_matrix(&rot));
            a[3 * j..3 * j + 3].copy_from_slice(&e);
        }
        angles.push(a);
        root.push(pos);
    }
    // Continuous exponential maps over time, per joint.
    for j in 0..N_JOINTS {
        let mut seq: Vec<[f64; 3]> = angles
            .iter()
            .map(|a| [a[3 * j], a[3 * j + 1], a[3 * j + 2]])
            .collect();
        unwrap_expmaps(&mut seq);
        for (a, s) in angles.iter_mut().zip(seq) {
            a[3 * j..3 * j + 3].copy_from_slice(&s);
        }
    }
    Ok(BvhMotion {
        frame_time,
        angles,
        root,
    })
}

/// Reads a BVH file of this skeleton.
///
/// # Errors
/// I/O errors and the errors of [`parse_bvh`].
pub fn read_bvh(path: impl AsRef<Path>) -> Result<BvhMotion> {
    let path = path.as_ref();
    let bytes = wscg_math::error::read_file(path)?;
    let text = String::from_utf8(bytes).map_err(|_| Error::format(path, "not UTF-8 text"))?;
    parse_bvh(&text, path)
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
