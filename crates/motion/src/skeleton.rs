//! The 17-joint skeleton of the synthetic walker (paper §2.1: 17 joints with exponential-map
//! angles, 51 channels), exponential-map / quaternion conversions and forward kinematics.
//!
//! Axes: `y` up, `z` forward (walking direction), `x` to the character's left; lengths in metres.
//! Channel `3·joint + c` is component `c` of joint `joint`'s exponential map (rotation vector)
//! relative to its parent.

use nalgebra::{Matrix3, UnitQuaternion, Vector3};

/// Joint names, parents and rest offsets (from the parent joint).
pub const JOINTS: [(&str, Option<usize>, [f64; 3]); 17] = [
    ("Hips", None, [0.0, 0.0, 0.0]),
    ("Spine", Some(0), [0.0, 0.30, 0.0]),
    ("Head", Some(1), [0.0, 0.27, 0.0]),
    ("LeftCollar", Some(1), [0.04, 0.20, 0.0]),
    ("LeftShoulder", Some(3), [0.15, 0.0, 0.0]),
    ("LeftElbow", Some(4), [0.0, -0.28, 0.0]),
    ("LeftWrist", Some(5), [0.0, -0.25, 0.0]),
    ("RightCollar", Some(1), [-0.04, 0.20, 0.0]),
    ("RightShoulder", Some(7), [-0.15, 0.0, 0.0]),
    ("RightElbow", Some(8), [0.0, -0.28, 0.0]),
    ("RightWrist", Some(9), [0.0, -0.25, 0.0]),
    ("LeftHip", Some(0), [0.09, 0.0, 0.0]),
    ("LeftKnee", Some(11), [0.0, -0.43, 0.0]),
    ("LeftAnkle", Some(12), [0.0, -0.42, 0.0]),
    ("RightHip", Some(0), [-0.09, 0.0, 0.0]),
    ("RightKnee", Some(14), [0.0, -0.43, 0.0]),
    ("RightAnkle", Some(15), [0.0, -0.42, 0.0]),
];

/// End-site offsets of the joints that end a chain.
pub fn end_site(joint: usize) -> Option<[f64; 3]> {
    match JOINTS[joint].0 {
        "Head" => Some([0.0, 0.18, 0.0]),
        "LeftWrist" | "RightWrist" => Some([0.0, -0.08, 0.0]),
        "LeftAnkle" | "RightAnkle" => Some([0.0, -0.05, 0.13]),
        _ => None,
    }
}

/// Number of joints.
pub const N_JOINTS: usize = 17;
/// Number of exponential-map channels (`3 × 17`).
pub const N_CHANNELS: usize = 3 * N_JOINTS;
/// Height of the hips above the floor in the rest pose (metres).
pub const HIP_HEIGHT: f64 = 0.92;

/// Joints of the arms (collar, shoulder, elbow, wrist on both sides).
pub fn is_arm_joint(joint: usize) -> bool {
    (3..=10).contains(&joint)
}

/// Channels of the arms.
pub fn is_arm_channel(channel: usize) -> bool {
    is_arm_joint(channel / 3)
}

/// Channels of the left arm (the reaching arm of the synthetic drawer task).
pub fn is_left_arm_channel(channel: usize) -> bool {
    (3..=6).contains(&(channel / 3))
}

/// Channels of the hips and legs.
pub fn is_leg_channel(channel: usize) -> bool {
    let j = channel / 3;
    j == 0 || (11..=16).contains(&j)
}

/// Unit quaternion of an exponential map (rotation vector, radians).
pub fn expmap_to_quat(r: [f64; 3]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(Vector3::from(r))
}

/// Exponential map of a unit quaternion, from the hemisphere `w ≥ 0` (angle in `[0, π]`).
pub fn quat_to_expmap(q: &UnitQuaternion<f64>) -> [f64; 3] {
    let q = if q.w < 0.0 {
        UnitQuaternion::new_unchecked(-q.into_inner())
    } else {
        *q
    };
    let v = q.scaled_axis();
    [v.x, v.y, v.z]
}

/// Makes a sequence of exponential maps continuous: where a frame's rotation vector is closer to
/// its predecessor after the equivalent `r − 2π r/‖r‖` (or `+`) form, that form is used. This is
/// the q / −q hemisphere handling that must precede demixing: the joint angles are exponential
/// maps of unit quaternions (paper §2.2), and a 2π jump in a channel would pass for a source.
pub fn unwrap_expmaps(frames: &mut [[f64; 3]]) {
    for t in 1..frames.len() {
        let prev = Vector3::from(frames[t - 1]);
        let cur = Vector3::from(frames[t]);
        let th = cur.norm();
        if th < 1e-12 {
            continue;
        }
        let axis = cur / th;
        let mut best = cur;
        for m in [-2.0, -1.0, 1.0, 2.0] {
            let cand = axis * (th + m * std::f64::consts::TAU);
            if (cand - prev).norm() < (best - prev).norm() {
                best = cand;
            }
        }
        frames[t] = [best.x, best.y, best.z];
    }
}

/// Rotation matrix `Rz(z) Rx(x) Ry(y)` of BVH's `Zrotation Xrotation Yrotation` order (radians).
pub fn zxy_to_matrix(z: f64, x: f64, y: f64) -> Matrix3<f64> {
    let rz = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), z);
    let rx = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), x);
    let ry = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), y);
    (rz * rx * ry).into_inner()
}

/// `(z, x, y)` Euler angles (radians) with `Rz Rx Ry = m`.
pub fn matrix_to_zxy(m: &Matrix3<f64>) -> (f64, f64, f64) {
    let x = m[(2, 1)].clamp(-1.0, 1.0).asin();
    let y = (-m[(2, 0)]).atan2(m[(2, 2)]);
    let z = (-m[(0, 1)]).atan2(m[(1, 1)]);
    (z, x, y)
}

/// World positions of the 17 joints (and of the end sites, appended in joint order) for one
/// frame of 51 exponential-map channels with the hips at `root`.
pub fn forward_kinematics(angles: &[f64], root: [f64; 3]) -> Vec<[f64; 3]> {
    let mut rot: Vec<UnitQuaternion<f64>> = Vec::with_capacity(N_JOINTS);
    let mut pos: Vec<Vector3<f64>> = Vec::with_capacity(N_JOINTS);
    for (j, (_, parent, off)) in JOINTS.iter().enumerate() {
        let local = expmap_to_quat([angles[3 * j], angles[3 * j + 1], angles[3 * j + 2]]);
        match parent {
            None => {
                rot.push(local);
                pos.push(Vector3::from(root));
            }
            Some(p) => {
                pos.push(pos[*p] + rot[*p] * Vector3::from(*off));
                rot.push(rot[*p] * local);
            }
        }
    }
    let mut out: Vec<[f64; 3]> = pos.iter().map(|p| [p.x, p.y, p.z]).collect();
    for j in 0..N_JOINTS {
        if let Some(e) = end_site(j) {
            let p = pos[j] + rot[j] * Vector3::from(e);
            out.push([p.x, p.y, p.z]);
        }
    }
    out
}

/// Bones as (from, to) indices into [`forward_kinematics`]'s output, for stick figures.
pub fn bones() -> Vec<(usize, usize)> {
    let mut b: Vec<(usize, usize)> = JOINTS
        .iter()
        .enumerate()
        .filter_map(|(j, (_, p, _))| p.map(|p| (p, j)))
        .collect();
    let mut e = N_JOINTS;
    for j in 0..N_JOINTS {
        if end_site(j).is_some() {
            b.push((j, e));
            e += 1;
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expmap_round_trip_and_euler() {
        let r = [0.3, -0.7, 1.1];
        let q = expmap_to_quat(r);
        let back = quat_to_expmap(&UnitQuaternion::new_unchecked(-q.into_inner()));
        for c in 0..3 {
            assert!((back[c] - r[c]).abs() < 1e-12);
        }
        let m = q.to_rotation_matrix().into_inner();
        let (z, x, y) = matrix_to_zxy(&m);
        assert!((zxy_to_matrix(z, x, y) - m).norm() < 1e-12);
    }

    #[test]
    fn rest_pose_feet_on_floor() {
        let p = forward_kinematics(&[0.0; N_CHANNELS], [0.0, HIP_HEIGHT, 0.0]);
        assert!((p[13][1] - 0.07).abs() < 1e-12);
        assert_eq!(bones().len(), 16 + 5);
    }
}
