//! Mapping a BVH motion of any skeleton onto the 17-joint skeleton of the model (paper §2.1).
//!
//! Every model joint takes the world rotation of the file joint it is mapped to, corrected by
//! a constant rest-pose alignment: the rotation that turns the model's rest bone directions
//! (towards its children, or its end site) into the file's rest directions towards the joints
//! mapped onto those children. Intermediate file joints (CMU's `LHipJoint`, `LowerBack`,
//! Mixamo's `Spine1`, …) are thus folded into their neighbours, and a file in a T-pose drives
//! the model's arms-down rest skeleton correctly. The local rotation of a model joint is
//! `G(parent)⁻¹ G(joint)`, returned as exponential maps; the pelvis position is the world
//! position of the joint mapped onto `Hips`.

use std::collections::BTreeMap;
use std::path::Path;

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use wscg_math::{Error, Result};

use crate::bvh_file::{BvhFile, BvhMotion, UNITS_PER_METRE};
use crate::skeleton::{end_site, quat_to_expmap, unwrap_expmaps, JOINTS, N_CHANNELS, N_JOINTS};

/// Rest directions closer than this (radians) are taken as equal: the alignment is exactly
/// the identity, so the model's own files read back channel for channel.
const SAME_DIRECTION: f64 = 1e-4;

/// A joint-name map: for each of the 17 model joints, the file joint names tried in order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct JointMap {
    /// Map name (`"model"`, `"cmu"`, `"mixamo"`, `"user"`).
    pub name: String,
    /// Candidates per model joint, in [`JOINTS`] order.
    pub candidates: Vec<Vec<String>>,
}

fn table(name: &str, rows: [&[&str]; N_JOINTS]) -> JointMap {
    JointMap {
        name: name.into(),
        candidates: rows
            .iter()
            .map(|r| r.iter().map(|s| (*s).to_string()).collect())
            .collect(),
    }
}

impl JointMap {
    /// The model's own joint names (files written by [`crate::bvh::write_bvh`]).
    pub fn model() -> Self {
        JointMap {
            name: "model".into(),
            candidates: JOINTS.iter().map(|j| vec![j.0.to_string()]).collect(),
        }
    }

    /// CMU motion-capture database names (the BVH conversions: `Hips`, `LowerBack`, `Spine`,
    /// `Spine1`, `Neck`, `Neck1`, `Head`, `LeftShoulder` (clavicle), `LeftArm`,
    /// `LeftForeArm`, `LeftHand`, `LHipJoint`, `LeftUpLeg`, `LeftLeg`, `LeftFoot`, …).
    pub fn cmu() -> Self {
        table(
            "cmu",
            [
                &["Hips"],
                &["Spine1", "Spine"],
                &["Neck1", "Neck", "Head"],
                &["LeftShoulder"],
                &["LeftArm"],
                &["LeftForeArm"],
                &["LeftHand"],
                &["RightShoulder"],
                &["RightArm"],
                &["RightForeArm"],
                &["RightHand"],
                &["LeftUpLeg"],
                &["LeftLeg"],
                &["LeftFoot"],
                &["RightUpLeg"],
                &["RightLeg"],
                &["RightFoot"],
            ],
        )
    }

    /// Mixamo names (`mixamorig:Hips`, `mixamorig:Spine2`, `mixamorig:LeftArm`, …); the
    /// `mixamorig:` prefix (or any `namespace:` prefix) is optional in the file.
    pub fn mixamo() -> Self {
        table(
            "mixamo",
            [
                &["Hips"],
                &["Spine2", "Spine1", "Spine"],
                &["Neck", "Head"],
                &["LeftShoulder"],
                &["LeftArm"],
                &["LeftForeArm"],
                &["LeftHand"],
                &["RightShoulder"],
                &["RightArm"],
                &["RightForeArm"],
                &["RightHand"],
                &["LeftUpLeg"],
                &["LeftLeg"],
                &["LeftFoot"],
                &["RightUpLeg"],
                &["RightLeg"],
                &["RightFoot"],
            ],
        )
    }

    /// A built-in map by name: `"model"`, `"cmu"` or `"mixamo"`.
    ///
    /// # Errors
    /// Another name.
    pub fn builtin(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().as_str() {
            "model" => Ok(Self::model()),
            "cmu" => Ok(Self::cmu()),
            "mixamo" => Ok(Self::mixamo()),
            _ => Err(Error::invalid(
                "joint_map",
                format!(
                    "`{name}` is not a built-in joint map; the built-in maps are \"model\", \
                     \"cmu\" and \"mixamo\" (or give a JSON file)"
                ),
            )),
        }
    }

    /// A user map from `(model joint, file joint)` pairs; model joints left out keep their
    /// own names as the only candidate.
    ///
    /// # Errors
    /// A model joint name that is not one of the 17 (the error lists them).
    pub fn from_pairs<'a>(pairs: impl IntoIterator<Item = (&'a str, &'a str)>) -> Result<Self> {
        let mut map = Self::model();
        map.name = "user".into();
        for (model, file) in pairs {
            let j = JOINTS.iter().position(|j| j.0 == model).ok_or_else(|| {
                let names: Vec<&str> = JOINTS.iter().map(|j| j.0).collect();
                Error::invalid(
                    "joint_map",
                    format!(
                        "`{model}` is not a joint of the model; its joints are {}",
                        names.join(", ")
                    ),
                )
            })?;
            map.candidates[j] = vec![file.to_string()];
        }
        Ok(map)
    }

    /// A user map from a JSON object `{"model joint": "file joint", …}`.
    ///
    /// # Errors
    /// Not a JSON object of strings, and the errors of [`Self::from_pairs`].
    pub fn from_json(text: &str) -> Result<Self> {
        let m: BTreeMap<String, String> = serde_json::from_str(text).map_err(|e| {
            Error::invalid(
                "joint_map",
                format!("expected a JSON object {{\"model joint\": \"file joint\"}}: {e}"),
            )
        })?;
        Self::from_pairs(m.iter().map(|(a, b)| (a.as_str(), b.as_str())))
    }

    /// A user map read from a JSON file.
    ///
    /// # Errors
    /// I/O errors naming the path, and the errors of [`Self::from_json`] (naming the path).
    pub fn read_json(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = wscg_math::error::read_text(path)?;
        Self::from_json(&text).map_err(|e| Error::format(path, e.to_string()))
    }

    /// The file joint of each model joint, or the model joints that have none (with the names
    /// tried).
    pub fn resolve(&self, file: &BvhFile) -> std::result::Result<[usize; N_JOINTS], Vec<String>> {
        let find = |name: &str| {
            file.joint_index(name).or_else(|| {
                file.joints
                    .iter()
                    .position(|j| j.name.rsplit(':').next() == Some(name))
            })
        };
        let mut out = [0usize; N_JOINTS];
        let mut missing = Vec::new();
        for (j, cands) in self.candidates.iter().enumerate() {
            match cands.iter().find_map(|c| find(c.as_str())) {
                Some(i) => out[j] = i,
                None => missing.push(format!("{} (tried {})", JOINTS[j].0, cands.join(", "))),
            }
        }
        if missing.is_empty() {
            Ok(out)
        } else {
            Err(missing)
        }
    }
}

wscg_math::params! {
    /// How a BVH file of any skeleton is mapped onto the model's skeleton.
    #[derive(Clone, Debug, PartialEq)]
    pub struct RetargetParams {
        /// The joint map; `None` tries the model's names, then CMU's, then Mixamo's.
        pub joint_map: Option<JointMap>,
        /// File units per metre (100: centimetres).
        pub units_per_metre: f64,
    }
}

impl Default for RetargetParams {
    fn default() -> Self {
        Self {
            joint_map: None,
            units_per_metre: UNITS_PER_METRE,
        }
    }
}

impl RetargetParams {
    /// Errors: `units_per_metre` not finite and positive, a map without 17 entries.
    pub fn validate(&self) -> Result<()> {
        if !(self.units_per_metre.is_finite() && self.units_per_metre > 0.0) {
            return Err(Error::invalid(
                "units_per_metre",
                format!("must be finite and > 0, got {}", self.units_per_metre),
            ));
        }
        if let Some(m) = &self.joint_map {
            if m.candidates.len() != N_JOINTS {
                return Err(Error::invalid(
                    "joint_map",
                    format!("needs {N_JOINTS} entries, got {}", m.candidates.len()),
                ));
            }
        }
        Ok(())
    }
}

/// The rotation taking the unit directions `from[i]` onto `to[i]` in the least-squares sense
/// (Kabsch); one direction: the smallest such rotation.
fn align(from: &[Vector3<f64>], to: &[Vector3<f64>]) -> UnitQuaternion<f64> {
    if from.len() == 1 {
        return UnitQuaternion::rotation_between(&from[0], &to[0]).unwrap_or_else(|| {
            // Opposite directions: half a turn about any axis normal to them.
            let n = from[0].cross(&Vector3::x());
            let n = if n.norm() < 1e-6 {
                from[0].cross(&Vector3::y())
            } else {
                n
            };
            UnitQuaternion::from_scaled_axis(n.normalize() * std::f64::consts::PI)
        });
    }
    let mut h = Matrix3::zeros();
    for (a, b) in from.iter().zip(to) {
        h += b * a.transpose();
    }
    let svd = h.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return UnitQuaternion::identity();
    };
    let d = (u * vt).determinant().signum();
    let r = u * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * vt;
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r))
}

/// The rest-pose alignment of each model joint (module documentation).
fn alignments(file: &BvhFile, map: &[usize; N_JOINTS]) -> Result<Vec<UnitQuaternion<f64>>> {
    let rest = file.world_poses(None)?;
    let mut out = Vec::with_capacity(N_JOINTS);
    for (j, &mj) in map.iter().enumerate() {
        let here = rest[mj].1;
        let mut from = Vec::new();
        let mut to = Vec::new();
        for (c, (_, parent, off)) in JOINTS.iter().enumerate() {
            if *parent == Some(j) {
                from.push(Vector3::from(*off));
                to.push(rest[map[c]].1 - here);
            }
        }
        if from.is_empty() {
            if let Some(e) = end_site(j) {
                let src = file.joints[mj]
                    .end_sites
                    .first()
                    .copied()
                    .or_else(|| file.children(mj).first().map(|&c| file.joints[c].offset));
                if let Some(s) = src {
                    from.push(Vector3::from(e));
                    to.push(Vector3::from(s));
                }
            }
        }
        let (from, to): (Vec<_>, Vec<_>) = from
            .iter()
            .zip(&to)
            .filter(|(a, b)| a.norm() > 1e-12 && b.norm() > 1e-12)
            .map(|(a, b)| (a.normalize(), b.normalize()))
            .unzip();
        let same = from
            .iter()
            .zip(&to)
            .all(|(a, b)| a.cross(b).norm().atan2(a.dot(b)) < SAME_DIRECTION);
        out.push(if from.is_empty() || same {
            UnitQuaternion::identity()
        } else {
            align(&from, &to)
        });
    }
    Ok(out)
}

/// Maps a BVH motion of any skeleton onto the model's 17-joint skeleton (module
/// documentation).
///
/// # Errors
/// Invalid parameters; model joints the map finds no file joint for (the error lists every
/// one with the names tried); a file without frames.
pub fn retarget(file: &BvhFile, p: &RetargetParams) -> Result<BvhMotion> {
    p.validate()?;
    if file.frames.is_empty() {
        return Err(Error::Empty("frames"));
    }
    let map = match &p.joint_map {
        Some(m) => m.resolve(file),
        None => {
            let tries = [JointMap::model(), JointMap::cmu(), JointMap::mixamo()];
            let results: Vec<_> = tries.iter().map(|m| m.resolve(file)).collect();
            results
                .iter()
                .find(|r| r.is_ok())
                .cloned()
                .unwrap_or_else(|| {
                    results
                        .into_iter()
                        .min_by_key(|r| r.as_ref().err().map_or(0, Vec::len))
                        .unwrap_or(Err(Vec::new()))
                })
        }
    }
    .map_err(|missing| {
        Error::invalid(
            "joint_map",
            format!(
                "no joint of the file maps onto {} model joint(s): {}; give a joint map \
                 (\"cmu\", \"mixamo\" or a JSON object {{\"model joint\": \"file joint\"}})",
                missing.len(),
                missing.join("; ")
            ),
        )
    })?;
    let align = alignments(file, &map)?;
    let mut angles = Vec::with_capacity(file.frames.len());
    let mut root = Vec::with_capacity(file.frames.len());
    for f in 0..file.frames.len() {
        let poses = file.world_poses(Some(f))?;
        let global: Vec<UnitQuaternion<f64>> =
            (0..N_JOINTS).map(|j| poses[map[j]].0 * align[j]).collect();
        let mut a = vec![0.0; N_CHANNELS];
        for (j, (_, parent, _)) in JOINTS.iter().enumerate() {
            let local = match parent {
                None => global[j],
                Some(p) => global[*p].inverse() * global[j],
            };
            a[3 * j..3 * j + 3].copy_from_slice(&quat_to_expmap(&local));
        }
        angles.push(a);
        let r = poses[map[0]].1 / p.units_per_metre;
        root.push([r.x, r.y, r.z]);
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
        frame_time: file.frame_time,
        angles,
        root,
    })
}
