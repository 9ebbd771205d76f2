//! Joint relative angles (paper 17, section 3.2, eq. 1).

use serde::{Deserialize, Serialize};
use wscg_math::vec3::{cross, dot, norm, sub};
use wscg_math::{Error, Result};

use super::cycle::GaitCycle;
use super::skeleton::{Joint, JointSet, Pair, SkeletonSeq, N_JOINTS};

/// Joint relative angle of `p1` and `p2` at the reference joint `r`, eq. 1:
/// `v1 = r − p1`, `v2 = p2 − r`, `Θ = arccos(v1·v2 / (‖v1‖ ‖v2‖))` in radians, `[0, π]`.
///
/// Computed as `atan2(‖v1 × v2‖, v1·v2)` (the same angle, accurate near 0 and π). `None` when
/// `p1` or `p2` is within 1e-9 m of `r` (the angle is undefined). Θ equals π minus the angle
/// `p1-r-p2`, and is invariant to rotation, translation and uniform scaling of the skeleton.
pub fn jra(p1: [f64; 3], p2: [f64; 3], r: [f64; 3]) -> Option<f64> {
    let v1 = sub(r, p1);
    let v2 = sub(p2, r);
    if norm(v1) < 1e-9 || norm(v2) < 1e-9 {
        return None;
    }
    Some(vector_angle(v1, v2))
}

/// Angle between two non-zero vectors, `atan2(‖a × b‖, a·b)`, radians in `[0, π]`.
pub fn vector_angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// All pairs `(p1, p2)`, `p1 < p2`, of joints other than `reference`: C(24, 2) = 276 pairs
/// (the paper counts C(25, 2) = 300 including the undefined pairs with the reference).
pub fn all_pairs(reference: Joint) -> Vec<Pair> {
    all_pairs_in(JointSet::KinectV2, reference)
}

/// All pairs `(p1, p2)`, `p1 < p2` (by Kinect v2 index), of the joints of `set` other than
/// `reference`: 276 for Kinect v2, C(19, 2) = 171 for the 20 joints of Kinect v1.
pub fn all_pairs_in(set: JointSet, reference: Joint) -> Vec<Pair> {
    let mut js: Vec<Joint> = set
        .joints()
        .iter()
        .copied()
        .filter(|&j| j != reference)
        .collect();
    js.sort();
    let mut out = Vec::with_capacity(js.len() * js.len() / 2);
    for (a, &p1) in js.iter().enumerate() {
        for &p2 in &js[a + 1..] {
            out.push((p1, p2));
        }
    }
    out
}

/// The JRA sequences of one gait sample: one sequence per pair over the frames of a cycle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JraSet {
    /// Reference joint (SpineBase in the paper).
    pub reference: Joint,
    /// The pairs, in [`all_pairs`] order unless built otherwise.
    pub pairs: Vec<Pair>,
    /// `seqs[k][t]`: angle of pair `k` in frame `cycle.start + t`, radians.
    pub seqs: Vec<Vec<f64>>,
}

impl JraSet {
    /// The sequences of `pairs`, in that order: the sample compared by the DTW kernel.
    /// Errors: a pair this set does not hold.
    pub fn select(&self, pairs: &[Pair]) -> Result<Vec<Vec<f64>>> {
        let mut index = [[usize::MAX; N_JOINTS]; N_JOINTS];
        for (k, &(a, b)) in self.pairs.iter().enumerate() {
            index[a.index()][b.index()] = k;
            index[b.index()][a.index()] = k;
        }
        pairs
            .iter()
            .map(|&(a, b)| {
                let k = index[a.index()][b.index()];
                if k == usize::MAX {
                    Err(Error::invalid(
                        "pairs",
                        format!("the JRA set has no pair ({}, {})", a.name(), b.name()),
                    ))
                } else {
                    Ok(self.seqs[k].clone())
                }
            })
            .collect()
    }

    /// Number of frames of the sequences.
    pub fn frames(&self) -> usize {
        self.seqs.first().map_or(0, Vec::len)
    }
}

/// JRA sequences of `pairs` over the frames `cycle.start..=cycle.end` of a walk (section 3.2).
/// Errors: a pair containing the reference joint or a joint twice, a joint (or the reference)
/// the walk's joint set does not hold, a cycle beyond the walk, a frame where a pair's joint
/// coincides with the reference.
pub fn jra_sequences(
    s: &SkeletonSeq,
    c: &GaitCycle,
    reference: Joint,
    pairs: &[Pair],
) -> Result<JraSet> {
    c.check_within(s)?;
    let set = s.joint_set;
    let absent = |j: Joint| {
        Error::invalid(
            "pairs",
            format!("the walk's joints ({set:?}) have no {}", j.name()),
        )
    };
    if !set.contains(reference) {
        return Err(absent(reference));
    }
    let mut seqs = Vec::with_capacity(pairs.len());
    for &(a, b) in pairs {
        if let Some(&j) = [a, b].iter().find(|&&j| !set.contains(j)) {
            return Err(absent(j));
        }
        if a == reference || b == reference || a == b {
            return Err(Error::invalid(
                "pairs",
                format!(
                    "({}, {}) has no joint relative angle at the reference {}",
                    a.name(),
                    b.name(),
                    reference.name()
                ),
            ));
        }
        let mut seq = Vec::with_capacity(c.len());
        for t in c.start..=c.end {
            let f = &s.frames[t];
            let th = jra(f[a.index()], f[b.index()], f[reference.index()]).ok_or_else(|| {
                Error::invalid(
                    "frames",
                    format!(
                        "frame {t}: joint {} or {} coincides with the reference",
                        a.name(),
                        b.name()
                    ),
                )
            })?;
            seq.push(th);
        }
        seqs.push(seq);
    }
    Ok(JraSet {
        reference,
        pairs: pairs.to_vec(),
        seqs,
    })
}

/// The JRA sequences of all pairs of the walk's joints ([`all_pairs_in`]: 276 for Kinect v2,
/// 171 for Kinect v1) over one cycle.
pub fn jra_matrix(s: &SkeletonSeq, c: &GaitCycle, reference: Joint) -> Result<JraSet> {
    jra_sequences(s, c, reference, &all_pairs_in(s.joint_set, reference))
}
