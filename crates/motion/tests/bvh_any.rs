//! BVH files of other skeletons: hierarchies, channel and rotation orders written here, read
//! back joint for joint against forward kinematics computed independently here; mapping onto
//! the model's skeleton with the CMU, Mixamo and user maps; malformed files.

use std::path::Path;

use nalgebra::{Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use wscg_math::Error;
use wscg_motion::bvh::{parse_bvh, parse_bvh_with, to_bvh_string, BvhMotion};
use wscg_motion::bvh_file::{bvh_forward_kinematics, parse_bvh_file, read_bvh_file, Channel};
use wscg_motion::retarget::{retarget, JointMap, RetargetParams};
use wscg_motion::skeleton::{expmap_to_quat, forward_kinematics, JOINTS, N_CHANNELS};

/// A joint of a test skeleton: name, parent, offset, channel names, end site.
struct Spec {
    name: &'static str,
    parent: Option<usize>,
    offset: [f64; 3],
    channels: &'static [&'static str],
    end: Option<[f64; 3]>,
}

fn spec(
    name: &'static str,
    parent: Option<usize>,
    offset: [f64; 3],
    channels: &'static [&'static str],
    end: Option<[f64; 3]>,
) -> Spec {
    Spec {
        name,
        parent,
        offset,
        channels,
        end,
    }
}

fn hierarchy(out: &mut String, s: &[Spec], j: usize, depth: usize) {
    let pad = "\t".repeat(depth);
    let kind = if s[j].parent.is_none() {
        "ROOT"
    } else {
        "JOINT"
    };
    let o = s[j].offset;
    out.push_str(&format!(
        "{pad}{kind} {}\n{pad}{{\n{pad}\tOFFSET {} {} {}\n",
        s[j].name, o[0], o[1], o[2]
    ));
    if !s[j].channels.is_empty() {
        out.push_str(&format!(
            "{pad}\tCHANNELS {} {}\n",
            s[j].channels.len(),
            s[j].channels.join(" ")
        ));
    }
    for (c, child) in s.iter().enumerate() {
        if child.parent == Some(j) {
            hierarchy(out, s, c, depth + 1);
        }
    }
    if let Some(e) = s[j].end {
        out.push_str(&format!(
            "{pad}\tEnd Site\n{pad}\t{{\n{pad}\t\tOFFSET {} {} {}\n{pad}\t}}\n",
            e[0], e[1], e[2]
        ));
    }
    out.push_str(&format!("{pad}}}\n"));
}

/// BVH text of a skeleton and frames (values in file order).
fn bvh_text(s: &[Spec], frames: &[Vec<f64>], frame_time: f64) -> String {
    let mut out = String::from("HIERARCHY\n");
    hierarchy(&mut out, s, 0, 0);
    out.push_str(&format!(
        "MOTION\nFrames: {}\nFrame Time: {frame_time}\n",
        frames.len()
    ));
    for f in frames {
        let line: Vec<String> = f.iter().map(|v| format!("{v:.10}")).collect();
        out.push_str(&line.join(" "));
        out.push('\n');
    }
    out
}

/// Joint order of the file: depth-first as written.
fn file_order(s: &[Spec]) -> Vec<usize> {
    fn visit(s: &[Spec], j: usize, out: &mut Vec<usize>) {
        out.push(j);
        for (c, child) in s.iter().enumerate() {
            if child.parent == Some(j) {
                visit(s, c, out);
            }
        }
    }
    let mut out = Vec::new();
    visit(s, 0, &mut out);
    out
}

fn random_frames(s: &[Spec], n: usize, max_deg: f64, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let order = file_order(s);
    (0..n)
        .map(|_| {
            order
                .iter()
                .flat_map(|&j| s[j].channels.iter())
                .map(|c| {
                    if c.ends_with("position") {
                        rng.random_range(-50.0..50.0)
                    } else {
                        rng.random_range(-max_deg..max_deg)
                    }
                })
                .collect()
        })
        .collect()
}

/// Elementary rotation matrices written out (right-handed, angle in degrees).
fn elementary(axis: char, deg: f64) -> Matrix3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    match axis {
        'X' => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        'Y' => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        _ => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    }
}

/// Independent forward kinematics of one frame: world positions per spec joint.
fn reference_fk(s: &[Spec], frame: &[f64]) -> Vec<Vector3<f64>> {
    let mut vals = frame.iter();
    let mut rot = vec![Matrix3::identity(); s.len()];
    let mut pos = vec![Vector3::zeros(); s.len()];
    for j in file_order(s) {
        let mut local = Matrix3::identity();
        let mut t = Vector3::from(s[j].offset);
        for c in s[j].channels {
            let v = *vals.next().unwrap();
            let axis = c.chars().next().unwrap();
            if c.ends_with("position") {
                t[(axis as u8 - b'X') as usize] += v;
            } else {
                local *= elementary(axis, v);
            }
        }
        match s[j].parent {
            None => {
                rot[j] = local;
                pos[j] = t;
            }
            Some(p) => {
                rot[j] = rot[p] * local;
                pos[j] = pos[p] + rot[p] * t;
            }
        }
    }
    pos
}

fn odd_skeleton() -> Vec<Spec> {
    vec![
        spec(
            "root",
            None,
            [1.0, 2.0, 3.0],
            &[
                "Zposition",
                "Xposition",
                "Yposition",
                "Xrotation",
                "Yrotation",
                "Zrotation",
            ],
            None,
        ),
        spec(
            "a",
            Some(0),
            [0.0, 10.0, 0.0],
            &["Yrotation", "Xrotation", "Zrotation"],
            None,
        ),
        spec(
            "b",
            Some(1),
            [3.0, 7.0, -2.0],
            &["Xrotation", "Zrotation", "Yrotation"],
            Some([0.0, 4.0, 1.0]),
        ),
        spec("c", Some(0), [-5.0, 0.0, 2.0], &["Zrotation"], None),
        spec(
            "d",
            Some(3),
            [0.0, -8.0, 0.5],
            &[
                "Xposition",
                "Yposition",
                "Zposition",
                "Zrotation",
                "Yrotation",
                "Xrotation",
            ],
            Some([1.0, -1.0, 0.0]),
        ),
        spec("e", Some(1), [-2.0, 5.0, 0.0], &[], Some([0.0, 3.0, 0.0])),
    ]
}

#[test]
fn other_hierarchies_and_rotation_orders_read_back_joint_for_joint() {
    let s = odd_skeleton();
    let frames = random_frames(&s, 7, 170.0, 3);
    let text = bvh_text(&s, &frames, 1.0 / 60.0);
    let file = parse_bvh_file(&text, Path::new("odd.bvh")).unwrap();
    assert_eq!(file.joints.len(), 6);
    assert_eq!(file.frames.len(), 7);
    assert!((file.frame_time - 1.0 / 60.0).abs() < 1e-15);
    let order = file_order(&s);
    for (k, &j) in order.iter().enumerate() {
        assert_eq!(file.joints[k].name, s[j].name);
        assert_eq!(file.joints[k].offset, s[j].offset);
        let parent = s[j]
            .parent
            .map(|p| order.iter().position(|&o| o == p).unwrap());
        assert_eq!(file.joints[k].parent, parent);
        assert_eq!(
            file.joints[k].end_sites,
            s[j].end.into_iter().collect::<Vec<_>>()
        );
    }
    assert_eq!(file.joints[1].rotation_order(), "YXZ");
    assert_eq!(file.joints[0].channels[0], Channel::Zposition);
    let fk = bvh_forward_kinematics(&file);
    for (f, frame) in frames.iter().enumerate() {
        let want = reference_fk(&s, frame);
        for (k, &j) in order.iter().enumerate() {
            let got = Vector3::from(fk[f][k]);
            assert!(
                (got - want[j]).norm() < 1e-7,
                "frame {f} joint {}: {got:?} vs {:?}",
                s[j].name,
                want[j]
            );
        }
    }
}

/// A CMU-style skeleton in a T-pose (arms along ±x), in inches-like units (1 unit = 2.54 cm),
/// with the intermediate joints of the CMU conversions.
fn cmu_skeleton(prefix: &'static str) -> Vec<Spec> {
    let r6: &'static [&'static str] = &[
        "Xposition",
        "Yposition",
        "Zposition",
        "Zrotation",
        "Yrotation",
        "Xrotation",
    ];
    let r3: &'static [&'static str] = &["Zrotation", "Yrotation", "Xrotation"];
    let n = |s: &'static str| -> &'static str {
        if prefix.is_empty() {
            s
        } else {
            Box::leak(format!("{prefix}{s}").into_boxed_str())
        }
    };
    vec![
        spec(n("Hips"), None, [0.0, 0.0, 0.0], r6, None), // 0
        spec(n("LHipJoint"), Some(0), [0.0, 0.0, 0.0], r3, None), // 1
        spec(n("LeftUpLeg"), Some(1), [3.5, -1.0, 0.5], r3, None), // 2
        spec(n("LeftLeg"), Some(2), [0.0, -17.0, 0.0], r3, None), // 3
        spec(n("LeftFoot"), Some(3), [0.0, -16.5, 0.0], r3, None), // 4
        spec(
            n("LeftToeBase"),
            Some(4),
            [0.0, -2.0, 5.0],
            r3,
            Some([0.0, 0.0, 2.0]),
        ), // 5
        spec(n("RHipJoint"), Some(0), [0.0, 0.0, 0.0], r3, None), // 6
        spec(n("RightUpLeg"), Some(6), [-3.5, -1.0, 0.5], r3, None), // 7
        spec(n("RightLeg"), Some(7), [0.0, -17.0, 0.0], r3, None), // 8
        spec(n("RightFoot"), Some(8), [0.0, -16.5, 0.0], r3, None), // 9
        spec(
            n("RightToeBase"),
            Some(9),
            [0.0, -2.0, 5.0],
            r3,
            Some([0.0, 0.0, 2.0]),
        ), // 10
        spec(n("LowerBack"), Some(0), [0.0, 1.0, 0.0], r3, None), // 11
        spec(n("Spine"), Some(11), [0.0, 5.0, 0.0], r3, None), // 12
        spec(n("Spine1"), Some(12), [0.0, 6.0, 0.0], r3, None), // 13
        spec(n("Neck"), Some(13), [0.0, 8.0, 0.0], r3, None), // 14
        spec(n("Neck1"), Some(14), [0.0, 2.0, 0.0], r3, None), // 15
        spec(
            n("Head"),
            Some(15),
            [0.0, 2.5, 0.0],
            r3,
            Some([0.0, 4.0, 0.0]),
        ), // 16
        spec(n("LeftShoulder"), Some(13), [1.5, 7.0, 0.0], r3, None), // 17
        spec(n("LeftArm"), Some(17), [6.0, 0.0, 0.0], r3, None), // 18
        spec(n("LeftForeArm"), Some(18), [11.0, 0.0, 0.0], r3, None), // 19
        spec(n("LeftHand"), Some(19), [9.5, 0.0, 0.0], r3, None), // 20
        spec(
            n("LeftHandIndex1"),
            Some(20),
            [3.0, 0.0, 0.0],
            r3,
            Some([1.0, 0.0, 0.0]),
        ), // 21
        spec(n("RightShoulder"), Some(13), [-1.5, 7.0, 0.0], r3, None), // 22
        spec(n("RightArm"), Some(22), [-6.0, 0.0, 0.0], r3, None), // 23
        spec(n("RightForeArm"), Some(23), [-11.0, 0.0, 0.0], r3, None), // 24
        spec(
            n("RightHand"),
            Some(24),
            [-9.5, 0.0, 0.0],
            r3,
            Some([-3.0, 0.0, 0.0]),
        ), // 25
    ]
}

/// (model joint, model child, spec joint, spec child) of bones driven by one file bone.
const LIMBS: [(usize, usize, usize, usize); 8] = [
    (4, 5, 18, 19),
    (5, 6, 19, 20),
    (8, 9, 23, 24),
    (9, 10, 24, 25),
    (11, 12, 2, 3),
    (12, 13, 3, 4),
    (14, 15, 7, 8),
    (15, 16, 8, 9),
];

fn check_retarget(s: &[Spec], motion: &BvhMotion, frames: &[Vec<f64>], units: f64) {
    let order = file_order(s);
    for (f, frame) in frames.iter().enumerate() {
        let want = reference_fk(s, frame);
        let got = forward_kinematics(&motion.angles[f], motion.root[f]);
        // The pelvis position, converted to metres.
        let hips = want[0] / units;
        assert!((Vector3::from(motion.root[f]) - hips).norm() < 1e-9);
        for &(mj, mc, sj, sc) in &LIMBS {
            let dm = (Vector3::from(got[mc]) - Vector3::from(got[mj])).normalize();
            let ds = (want[sc] - want[sj]).normalize();
            assert!(
                (dm - ds).norm() < 1e-6,
                "frame {f}: model bone {}→{} points {dm:?}, file bone {}→{} {ds:?}",
                JOINTS[mj].0,
                JOINTS[mc].0,
                s[sj].name,
                s[sc].name
            );
        }
    }
    assert_eq!(order[0], 0);
}

#[test]
fn cmu_and_mixamo_skeletons_in_a_t_pose_drive_the_model_bone_for_bone() {
    for (prefix, map) in [
        ("", None),
        ("", Some(JointMap::cmu())),
        ("mixamorig:", Some(JointMap::mixamo())),
        ("mixamorig:", None),
    ] {
        let s = cmu_skeleton(prefix);
        let frames = random_frames(&s, 5, 60.0, 11);
        let text = bvh_text(&s, &frames, 1.0 / 120.0);
        let p = RetargetParams::default()
            .joint_map(map)
            .units_per_metre(100.0 / 2.54);
        let motion = parse_bvh_with(&text, Path::new("cmu.bvh"), &p).unwrap();
        assert_eq!(motion.angles.len(), 5);
        assert_eq!(motion.angles[0].len(), N_CHANNELS);
        check_retarget(&s, &motion, &frames, 100.0 / 2.54);
    }
    // Mixamo names without the prefix match the Mixamo map too.
    let s = cmu_skeleton("");
    let frames = random_frames(&s, 2, 60.0, 5);
    let file = parse_bvh_file(&bvh_text(&s, &frames, 0.01), Path::new("m.bvh")).unwrap();
    let m = retarget(
        &file,
        &RetargetParams::default().joint_map(Some(JointMap::mixamo())),
    )
    .unwrap();
    check_retarget(&s, &m, &frames, 100.0);
}

#[test]
fn a_user_map_from_json_renames_joints() {
    let mut s = cmu_skeleton("");
    let renames = [
        (2, "thigh_l"),
        (3, "calf_l"),
        (18, "upperarm_l"),
        (19, "lowerarm_l"),
    ];
    for (j, n) in renames {
        s[j].name = n;
    }
    let frames = random_frames(&s, 3, 45.0, 8);
    let text = bvh_text(&s, &frames, 0.01);
    // The CMU map misses the renamed joints and the error lists each of them.
    let err = parse_bvh_with(
        &text,
        Path::new("ue.bvh"),
        &RetargetParams::default().joint_map(Some(JointMap::cmu())),
    )
    .unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, Error::Format { .. }), "{msg}");
    for j in ["LeftHip", "LeftKnee", "LeftShoulder", "LeftElbow", "ue.bvh"] {
        assert!(msg.contains(j), "{msg}");
    }
    assert!(!msg.contains("RightKnee"), "{msg}");
    let mut map = JointMap::cmu();
    let user = JointMap::from_json(
        r#"{"LeftHip": "thigh_l", "LeftKnee": "calf_l", "LeftShoulder": "upperarm_l",
            "LeftElbow": "lowerarm_l"}"#,
    )
    .unwrap();
    for j in [4, 5, 11, 12] {
        map.candidates[j] = user.candidates[j].clone();
    }
    let m = parse_bvh_with(
        &text,
        Path::new("ue.bvh"),
        &RetargetParams::default().joint_map(Some(map)),
    )
    .unwrap();
    check_retarget(&s, &m, &frames, 100.0);
    let err = JointMap::from_json(r#"{"Knee": "calf_l"}"#).unwrap_err();
    assert!(err.to_string().contains("LeftKnee"), "{err}");
    assert!(JointMap::from_json("[1, 2]").is_err());
    assert!(JointMap::builtin("blender").is_err());
}

#[test]
fn the_models_own_files_read_back_channel_for_channel() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(1);
    let angles: Vec<Vec<f64>> = (0..4)
        .map(|_| {
            (0..N_CHANNELS)
                .map(|_| rng.random_range(-1.0..1.0))
                .collect()
        })
        .collect();
    let root = vec![[0.1, 0.9, 0.3]; 4];
    let m = BvhMotion {
        frame_time: 0.01,
        angles: angles.clone(),
        root: root.clone(),
    };
    let back = parse_bvh(&to_bvh_string(&m).unwrap(), Path::new("own.bvh")).unwrap();
    for (a, b) in angles.iter().zip(&back.angles) {
        for j in 0..JOINTS.len() {
            let qa = expmap_to_quat([a[3 * j], a[3 * j + 1], a[3 * j + 2]]);
            let qb = expmap_to_quat([b[3 * j], b[3 * j + 1], b[3 * j + 2]]);
            assert!(qa.angle_to(&qb) < 1e-6, "joint {j}");
        }
    }
    assert_eq!(back.root, root);
}

#[test]
fn malformed_files_are_errors_naming_the_file() {
    let s = odd_skeleton();
    let frames = random_frames(&s, 3, 90.0, 2);
    let text = bvh_text(&s, &frames, 0.02);
    assert!(parse_bvh_file(&text, Path::new("x.bvh")).is_ok());
    let motion = text.find("MOTION").unwrap();
    let cases: Vec<(&str, String)> = vec![
        ("truncated hierarchy", text[..motion / 2].to_string()),
        ("truncated motion", text[..text.len() - 20].to_string()),
        ("wrong magic", text.replacen("HIERARCHY", "HIERARCH", 1)),
        ("not BVH", "{\"frames\": []}".to_string()),
        ("frame count", text.replace("Frames: 3", "Frames: 4")),
        (
            "huge frame count",
            text.replace("Frames: 3", "Frames: 18446744073709551615"),
        ),
        (
            "wrapping frame count",
            text.replace("Frames: 3", "Frames: 9223372036854775810"),
        ),
        (
            "huge channel count",
            text.replacen("CHANNELS 3", "CHANNELS 4000000000", 1),
        ),
        (
            "unknown channel",
            text.replacen("Xrotation", "Wrotation", 1),
        ),
        (
            "bad offset",
            text.replacen("OFFSET 0 10 0", "OFFSET 0 ten 0", 1),
        ),
        ("duplicated joint", text.replacen("JOINT b", "JOINT a", 1)),
        ("unbalanced", text.replacen("}\n", "", 1)),
        (
            "zero frame time",
            text.replace("Frame Time: 0.02", "Frame Time: 0"),
        ),
        ("nan value", {
            let at = text.trim_end().rfind(' ').unwrap();
            format!("{}nan\n", &text[..at + 1])
        }),
    ];
    for (what, bad) in cases {
        let err = parse_bvh_file(&bad, Path::new("bad.bvh"));
        let err = err.expect_err(what);
        assert!(matches!(err, Error::Format { .. }), "{what}: {err}");
        assert!(err.to_string().contains("bad.bvh"), "{what}: {err}");
    }
    let dir = tempfile::tempdir().unwrap();
    assert!(read_bvh_file(dir.path().join("missing.bvh")).is_err());
    // A file of another skeleton without a map lists every model joint it lacks.
    let err = parse_bvh(&text, Path::new("odd.bvh")).unwrap_err();
    assert!(err.to_string().contains("17 model joint(s)"), "{err}");
}
