//! NTU RGB+D `.skeleton` files (Shahroudy, Liu, Ng and Wang, *NTU RGB+D: A Large Scale
//! Dataset for 3D Human Activity Analysis*, CVPR 2016): Kinect v2 skeletons of up to several
//! bodies per frame.
//!
//! Layout (whitespace-separated text): the frame count; per frame the body count; per body a
//! line of 10 values (`bodyID clipedEdges handLeftConfidence handLeftState
//! handRightConfidence handRightState isRestricted leanX leanY trackingState`), the joint
//! count (25), and per joint a line of 12 values (`x y z depthX depthY colorX colorY
//! orientationW orientationX orientationY orientationZ trackingState`); `x y z` are camera
//! coordinates in metres, joints in Kinect v2 `JointType` order, `trackingState` 2 = tracked,
//! 1 = inferred, 0 = not tracked.

use std::path::Path;

use wscg_math::{Error, Result};

use super::skeleton::{interpolate_missing, read_limited, Frame, SkeletonSeq, N_JOINTS};

/// Values of a body line.
const BODY_VALUES: usize = 10;
/// Values of a joint line.
const JOINT_VALUES: usize = 12;

/// Which body of a multi-body file becomes the walk.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BodyChoice {
    /// The body with the most tracked joints over all frames (ties: the first seen).
    #[default]
    MostTracked,
    /// The body with this `bodyID`.
    Id(u64),
}

impl BodyChoice {
    /// Parses `"most-tracked"` or a body id.
    pub fn parse(s: &str) -> Result<Self> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("most-tracked") || t.eq_ignore_ascii_case("most_tracked") {
            return Ok(Self::MostTracked);
        }
        t.parse::<u64>().map(Self::Id).map_err(|_| {
            Error::invalid(
                "body",
                format!("`{s}` is neither \"most-tracked\" nor a body id"),
            )
        })
    }
}

wscg_math::params! {
    /// How a walk is taken from an NTU RGB+D file.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct NtuParams {
        /// The body (most tracked by default).
        pub body: BodyChoice,
        /// Longest run of interior frames without the body that is interpolated (10);
        /// frames before its first and after its last appearance are dropped.
        pub max_gap: usize,
    }
}

impl Default for NtuParams {
    fn default() -> Self {
        Self {
            body: BodyChoice::MostTracked,
            max_gap: 10,
        }
    }
}

impl NtuParams {
    /// Never fails: every body choice and gap length is valid.
    pub fn validate(&self) -> Result<()> {
        Ok(())
    }
}

/// One body of an NTU file.
#[derive(Clone, Debug, PartialEq)]
pub struct NtuBody {
    /// The `bodyID`.
    pub id: u64,
    /// `(frame index, joint positions)` of the frames where the body appears, in order.
    pub frames: Vec<(usize, Frame)>,
    /// Number of tracked joints (`trackingState` 2) over all frames.
    pub tracked: usize,
}

/// Parses an NTU RGB+D `.skeleton` text into its bodies (in order of first appearance).
///
/// # Errors
/// [`Error::Format`] naming `origin`: a first value that is not a frame count, a count larger
/// than the values the text holds (refused before anything is allocated from it), a joint
/// count other than 25, a body listed twice in a frame, truncated text, trailing values, bad
/// or non-finite numbers.
pub fn parse_ntu(text: &str, origin: &Path) -> Result<Vec<NtuBody>> {
    let bad = |m: String| Error::format(origin, m);
    let tokens: Vec<&str> = text.split_whitespace().collect();
    let mut at = 0usize;
    let count = |what: &str, at: &mut usize| -> Result<usize> {
        let t = tokens
            .get(*at)
            .ok_or_else(|| bad(format!("truncated: {what} missing")))?;
        *at += 1;
        let n = t
            .parse::<usize>()
            .map_err(|_| bad(format!("`{t}` is not a {what}")))?;
        if n > tokens.len() - *at {
            return Err(bad(format!(
                "{what} {n} is more than the {} values left in the file",
                tokens.len() - *at
            )));
        }
        Ok(n)
    };
    let n_frames = count("frame count", &mut at)?;
    let mut bodies: Vec<NtuBody> = Vec::new();
    for f in 0..n_frames {
        let n_bodies = count("body count", &mut at)?;
        let per_body = 1 + BODY_VALUES + N_JOINTS * JOINT_VALUES;
        if n_bodies.saturating_mul(per_body) > tokens.len() - at {
            return Err(bad(format!(
                "frame {f}: {n_bodies} bodies need more values than the file holds"
            )));
        }
        let mut seen: Vec<u64> = Vec::with_capacity(n_bodies);
        for _ in 0..n_bodies {
            let line = tokens
                .get(at..at + BODY_VALUES)
                .ok_or_else(|| bad(format!("frame {f}: truncated body line")))?;
            at += BODY_VALUES;
            let id = line[0]
                .parse::<u64>()
                .map_err(|_| bad(format!("frame {f}: `{}` is not a body id", line[0])))?;
            if let Some(v) = line[1..].iter().find(|v| v.parse::<f64>().is_err()) {
                return Err(bad(format!("frame {f}, body {id}: bad number `{v}`")));
            }
            if seen.contains(&id) {
                return Err(bad(format!("frame {f} lists body {id} twice")));
            }
            seen.push(id);
            let n_joints = count("joint count", &mut at)?;
            if n_joints != N_JOINTS {
                return Err(bad(format!(
                    "frame {f}, body {id}: {n_joints} joints, an NTU skeleton has {N_JOINTS}"
                )));
            }
            let mut frame = [[0.0; 3]; N_JOINTS];
            let mut tracked = 0;
            for (j, p) in frame.iter_mut().enumerate() {
                let vals = tokens
                    .get(at..at + JOINT_VALUES)
                    .ok_or_else(|| bad(format!("frame {f}, body {id}: truncated joint {j}")))?;
                at += JOINT_VALUES;
                let num = |k: usize| -> Result<f64> {
                    vals[k]
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            bad(format!(
                                "frame {f}, body {id}, joint {j}: bad number `{}`",
                                vals[k]
                            ))
                        })
                };
                // Every value is a number; positions and the tracking state are finite.
                if let Some(v) = vals.iter().find(|v| v.parse::<f64>().is_err()) {
                    return Err(bad(format!(
                        "frame {f}, body {id}, joint {j}: bad number `{v}`"
                    )));
                }
                *p = [num(0)?, num(1)?, num(2)?];
                if num(11)? == 2.0 {
                    tracked += 1;
                }
            }
            let b = match bodies.iter().position(|b| b.id == id) {
                Some(i) => &mut bodies[i],
                None => {
                    bodies.push(NtuBody {
                        id,
                        frames: Vec::new(),
                        tracked: 0,
                    });
                    bodies.last_mut().ok_or_else(|| bad("no body".into()))?
                }
            };
            b.frames.push((f, frame));
            b.tracked += tracked;
        }
    }
    if at != tokens.len() {
        return Err(bad(format!(
            "{} values after the {n_frames} frames the header declares",
            tokens.len() - at
        )));
    }
    Ok(bodies)
}

/// The walk of one body of an NTU file: frames from its first to its last appearance, interior
/// absences of at most `p.max_gap` frames interpolated.
///
/// # Errors
/// The errors of [`parse_ntu`]; no body, or no body with the requested id (the error lists
/// the ids); a longer absence; fewer than 3 frames; `fps` not positive.
pub fn parse_ntu_skeleton(
    text: &str,
    origin: &Path,
    fps: f64,
    p: &NtuParams,
) -> Result<SkeletonSeq> {
    p.validate()?;
    let bodies = parse_ntu(text, origin)?;
    let body = match p.body {
        BodyChoice::MostTracked => bodies
            .iter()
            .reduce(|a, b| if b.tracked > a.tracked { b } else { a }),
        BodyChoice::Id(id) => bodies.iter().find(|b| b.id == id),
    }
    .ok_or_else(|| {
        let ids: Vec<String> = bodies.iter().map(|b| b.id.to_string()).collect();
        Error::format(
            origin,
            match p.body {
                BodyChoice::Id(id) => {
                    format!("no body {id}; the file's bodies are [{}]", ids.join(", "))
                }
                BodyChoice::MostTracked => "the file holds no body".to_string(),
            },
        )
    })?;
    // Absences are checked before the walk is allocated from the frame indices.
    for w in body.frames.windows(2) {
        let gap = w[1].0 - w[0].0 - 1;
        if gap > p.max_gap {
            return Err(Error::format(
                origin,
                format!(
                    "body {} is absent in frames {}..{} ({gap} frames); only absences of at \
                     most {} frames are interpolated (max_gap)",
                    body.id,
                    w[0].0 + 1,
                    w[1].0 - 1,
                    p.max_gap
                ),
            ));
        }
    }
    let (first, last) = match (body.frames.first(), body.frames.last()) {
        (Some(a), Some(b)) => (a.0, b.0),
        _ => {
            return Err(Error::format(
                origin,
                format!("body {} has no frame", body.id),
            ))
        }
    };
    let n = last + 1 - first;
    wscg_math::alloc::ensure_shape::<f64>("frames", &[n, N_JOINTS, 3])?;
    let mut flat = vec![f64::NAN; n * N_JOINTS * 3];
    for (f, fr) in &body.frames {
        let o = (f - first) * N_JOINTS * 3;
        for (j, p) in fr.iter().enumerate() {
            flat[o + 3 * j..o + 3 * j + 3].copy_from_slice(p);
        }
    }
    interpolate_missing(fps, &flat, n, N_JOINTS, p.max_gap)
        .map_err(|e| Error::format(origin, format!("body {}: {e}", body.id)))
}

/// Reads the walk of one body of an NTU RGB+D `.skeleton` file ([`parse_ntu_skeleton`]).
///
/// # Errors
/// I/O errors naming the path, files above 256 MiB, and the errors of
/// [`parse_ntu_skeleton`].
pub fn read_ntu(path: impl AsRef<Path>, fps: f64, p: &NtuParams) -> Result<SkeletonSeq> {
    let path = path.as_ref();
    let text = read_limited(path)?;
    parse_ntu_skeleton(&text, path, fps, p)
}

/// The bodies of an NTU RGB+D file: `(bodyID, frames present, tracked joints)`.
///
/// # Errors
/// As [`read_ntu`].
pub fn ntu_bodies(path: impl AsRef<Path>) -> Result<Vec<(u64, usize, usize)>> {
    let path = path.as_ref();
    let text = read_limited(path)?;
    Ok(parse_ntu(&text, path)?
        .iter()
        .map(|b| (b.id, b.frames.len(), b.tracked))
        .collect())
}
