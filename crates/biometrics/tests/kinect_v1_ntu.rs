//! Kinect v1 (20 joints) and NTU RGB+D skeletons: files written here in the published
//! layouts, read back joint for joint; the gait method on 20-joint walkers beside 25 joints.

use std::fmt::Write as _;
use std::path::Path;

use wscg_biometrics::gait::protocol::{cross_validate, prepare, Protocol};
use wscg_biometrics::gait::synth::{walkers, SessionRanges, WalkSet};
use wscg_biometrics::gait::{
    all_pairs_in, gait_sample, interpolate_missing, ntu_bodies, parse_ntu_skeleton,
    parse_skeleton_csv, read_ntu, read_skeleton, write_skeleton_csv, write_skeleton_npy,
    BodyChoice, GaitParams, Joint, JointSet, NtuParams, SkeletonSeq, KINECT_V1_NAMES, N_JOINTS,
};
use wscg_math::Error;

fn v2_walk() -> SkeletonSeq {
    walkers(1, 1, &SessionRanges::default(), 5).unwrap().walks[0].clone()
}

#[test]
fn kinect_v1_csv_with_named_joints_reads_back_joint_for_joint() {
    let w = v2_walk();
    // The Kinect v1 SDK's names and index order, written here.
    let mut text = String::from("frame,joint,x,y,z\n");
    let v1_of_v2 = [
        Joint::SpineBase,
        Joint::SpineMid,
        Joint::SpineShoulder,
        Joint::Head,
        Joint::ShoulderLeft,
        Joint::ElbowLeft,
        Joint::WristLeft,
        Joint::HandLeft,
        Joint::ShoulderRight,
        Joint::ElbowRight,
        Joint::WristRight,
        Joint::HandRight,
        Joint::HipLeft,
        Joint::KneeLeft,
        Joint::AnkleLeft,
        Joint::FootLeft,
        Joint::HipRight,
        Joint::KneeRight,
        Joint::AnkleRight,
        Joint::FootRight,
    ];
    let names = [
        "HipCenter",
        "Spine",
        "ShoulderCenter",
        "Head",
        "ShoulderLeft",
        "ElbowLeft",
        "WristLeft",
        "HandLeft",
        "ShoulderRight",
        "ElbowRight",
        "WristRight",
        "HandRight",
        "HipLeft",
        "KneeLeft",
        "AnkleLeft",
        "FootLeft",
        "HipRight",
        "KneeRight",
        "AnkleRight",
        "FootRight",
    ];
    assert_eq!(names, KINECT_V1_NAMES);
    let mut by_index = String::new();
    for t in 0..w.len() {
        // Joints in reverse order: rows are matched by name, not position.
        for (k, (&j, name)) in v1_of_v2.iter().zip(names).enumerate().rev() {
            let p = w.at(t, j);
            writeln!(text, "{t},{name},{},{},{}", p[0], p[1], p[2]).unwrap();
            writeln!(by_index, "{t},{k},{},{},{}", p[0], p[1], p[2]).unwrap();
        }
    }
    for src in [&text, &by_index] {
        let s = parse_skeleton_csv(src, Path::new("v1.csv"), 30.0).unwrap();
        assert_eq!(s.joint_set, JointSet::KinectV1);
        assert_eq!(s.len(), w.len());
        for t in 0..w.len() {
            for j in v1_of_v2 {
                assert_eq!(s.at(t, j), w.at(t, j));
            }
            assert!(s.at(t, Joint::Neck)[0].is_nan());
        }
        assert_eq!(s.to_flat().len(), w.len() * 20 * 3);
    }
    // Written and read back (CSV and .npy keep 20 joints).
    let dir = tempfile::tempdir().unwrap();
    let v1 = w.to_kinect_v1();
    write_skeleton_csv(dir.path().join("w.csv"), &v1).unwrap();
    write_skeleton_npy(dir.path().join("w.npy"), &v1).unwrap();
    let csv = std::fs::read_to_string(dir.path().join("w.csv")).unwrap();
    assert!(csv.contains(",HipCenter,") && !csv.contains("Neck"));
    for f in ["w.csv", "w.npy"] {
        let back = read_skeleton(dir.path().join(f), 30.0).unwrap();
        assert_eq!(back.joint_set, JointSet::KinectV1, "{f}");
        for t in 0..w.len() {
            for j in v1_of_v2 {
                let (a, b) = (back.at(t, j), w.at(t, j));
                assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-6), "{f}");
            }
        }
    }
    // Flat (T, 20, 3) arrays and interpolation of gaps.
    let mut flat = v1.to_flat();
    let again = SkeletonSeq::from_flat(30.0, &flat, w.len(), 20).unwrap();
    assert_eq!(again, v1);
    flat[(5 * 20 + 14) * 3] = f64::NAN;
    let filled = interpolate_missing(30.0, &flat, w.len(), 20, 2).unwrap();
    let want = 0.5 * (w.at(4, Joint::AnkleLeft)[0] + w.at(6, Joint::AnkleLeft)[0]);
    assert!((filled.at(5, Joint::AnkleLeft)[0] - want).abs() < 1e-12);
    assert!(SkeletonSeq::from_flat(30.0, &flat[..60 * 3 - 1], 3, 20).is_err());
    assert!(SkeletonSeq::from_flat(30.0, &flat[..21 * 9], 9, 21).is_err());
}

#[test]
fn malformed_skeleton_csv_is_an_error_naming_the_file() {
    let w = v2_walk().to_kinect_v1();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("w.csv");
    write_skeleton_csv(&p, &w).unwrap();
    let text = std::fs::read_to_string(&p).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let cases = [
        ("missing joint", lines[..lines.len() - 1].join("\n")),
        ("truncated row", format!("{}\n5,HipCenter,1.0", text)),
        ("unknown joint", text.replacen(",Spine,", ",Spline,", 1)),
        (
            "duplicated joint",
            text.replacen(",Spine,", ",HipCenter,", 1),
        ),
        ("index out of range", text.replacen(",Spine,", ",20,", 1)),
    ];
    for (what, bad) in cases {
        let err = parse_skeleton_csv(&bad, Path::new("bad.csv"), 30.0).expect_err(what);
        assert!(err.to_string().contains("bad.csv"), "{what}: {err}");
    }
}

/// NTU RGB+D text of bodies `(id, frames present, positions offset)` over `n` frames.
fn ntu_text(w: &SkeletonSeq, bodies: &[(u64, Vec<usize>, f64, usize)], n: usize) -> String {
    let mut s = format!("{n}\n");
    for t in 0..n {
        let here: Vec<&(u64, Vec<usize>, f64, usize)> =
            bodies.iter().filter(|b| b.1.contains(&t)).collect();
        writeln!(s, "{}", here.len()).unwrap();
        for (id, _, shift, tracked) in here {
            writeln!(s, "{id} 0 1 1 1 1 0 0.01 -0.02 2").unwrap();
            writeln!(s, "25").unwrap();
            for (j, p) in w.frames[t % w.len()].iter().enumerate() {
                let state = if j < *tracked { 2 } else { 1 };
                writeln!(
                    s,
                    "{} {} {} 250.1 200.2 900.3 500.4 0.9 0.1 0.2 0.3 {state}",
                    p[0] + shift,
                    p[1],
                    p[2]
                )
                .unwrap();
            }
        }
    }
    s
}

#[test]
fn ntu_skeleton_files_pick_a_body_by_id_or_the_most_tracked() {
    let w = v2_walk();
    let n = 40;
    let all: Vec<usize> = (0..n).collect();
    let text = ntu_text(
        &w,
        &[
            (72057594037931101, (5..n).collect(), 3.0, 10),
            (72057594037931104, all.clone(), 0.0, 25),
        ],
        n,
    );
    let o = Path::new("S001C001P001R001A001.skeleton");
    let s = parse_ntu_skeleton(&text, o, 30.0, &NtuParams::default()).unwrap();
    assert_eq!(s.joint_set, JointSet::KinectV2);
    assert_eq!(s.len(), n);
    assert_eq!(s.frames[..], w.frames[..n]);
    let p = NtuParams::default().body(BodyChoice::Id(72057594037931101));
    let s = parse_ntu_skeleton(&text, o, 30.0, &p).unwrap();
    // Frames before the body's first appearance are dropped.
    assert_eq!(s.len(), n - 5);
    assert_eq!(s.frames[0][3][0], w.frames[5][3][0] + 3.0);
    let err = parse_ntu_skeleton(
        &text,
        o,
        30.0,
        &NtuParams::default().body(BodyChoice::Id(7)),
    )
    .unwrap_err();
    assert!(err.to_string().contains("72057594037931104"), "{err}");
    assert_eq!(
        BodyChoice::parse("most-tracked").unwrap(),
        BodyChoice::MostTracked
    );
    assert_eq!(BodyChoice::parse("12").unwrap(), BodyChoice::Id(12));
    assert!(BodyChoice::parse("first").is_err());
    // Interior absences: interpolated up to max_gap frames, refused beyond.
    let gappy: Vec<usize> = all
        .iter()
        .copied()
        .filter(|t| !(10..13).contains(t))
        .collect();
    let text = ntu_text(&w, &[(1, gappy, 0.0, 25)], n);
    let s = parse_ntu_skeleton(&text, o, 30.0, &NtuParams::default()).unwrap();
    let want = w.frames[9][0][0] + (w.frames[13][0][0] - w.frames[9][0][0]) * 0.5;
    assert!((s.frames[11][0][0] - want).abs() < 1e-12);
    let err = parse_ntu_skeleton(&text, o, 30.0, &NtuParams::default().max_gap(2)).unwrap_err();
    assert!(err.to_string().contains("absent"), "{err}");
    // From a file, by extension.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.skeleton");
    std::fs::write(&path, &text).unwrap();
    assert_eq!(read_skeleton(&path, 30.0).unwrap(), s);
    assert_eq!(read_ntu(&path, 30.0, &NtuParams::default()).unwrap(), s);
    assert_eq!(ntu_bodies(&path).unwrap(), vec![(1, n - 3, 25 * (n - 3))]);
}

#[test]
fn malformed_ntu_files_are_errors_naming_the_file() {
    let w = v2_walk();
    let text = ntu_text(&w, &[(1, (0..5).collect(), 0.0, 25)], 5);
    let o = Path::new("bad.skeleton");
    assert!(parse_ntu_skeleton(&text, o, 30.0, &NtuParams::default()).is_ok());
    let lines: Vec<&str> = text.lines().collect();
    let cases = vec![
        ("truncated", text[..text.len() / 2].to_string()),
        ("empty", String::new()),
        ("wrong magic", format!("HIERARCHY\n{text}")),
        ("trailing values", format!("{text}1 2 3\n")),
        ("frame count", text.replacen("5\n", "6\n", 1)),
        (
            "huge frame count",
            text.replacen("5\n", "18446744073709551615\n", 1),
        ),
        ("huge body count", {
            let mut l = lines.clone();
            l[1] = "4000000000000";
            l.join("\n")
        }),
        ("joint count", {
            let mut l = lines.clone();
            l[3] = "24";
            l.join("\n")
        }),
        ("bad number", text.replacen("250.1", "x", 1)),
        ("nan", {
            let mut l = lines.clone();
            let fixed = format!("nan{}", &l[4][l[4].find(' ').unwrap()..]);
            l[4] = &fixed;
            l.join("\n")
        }),
        ("body twice", {
            let mut l = lines.clone();
            l[1] = "2";
            let body: Vec<&str> = lines[2..4 + N_JOINTS].to_vec();
            let mut out = l[..4 + N_JOINTS].to_vec();
            out.extend(body);
            out.extend(&l[4 + N_JOINTS..]);
            out.join("\n")
        }),
    ];
    for (what, bad) in cases {
        let err = parse_ntu_skeleton(&bad, o, 30.0, &NtuParams::default()).expect_err(what);
        assert!(
            matches!(err, Error::Format { .. }) && err.to_string().contains("bad.skeleton"),
            "{what}: {err}"
        );
    }
}

fn accuracy(set: &WalkSet, proto: &Protocol) -> (usize, usize) {
    let prepared = prepare(&set.walks, &set.labels, &set.session_index, &proto.params).unwrap();
    let r = cross_validate(&prepared, None, proto).unwrap();
    (
        (r.jra_nearest * r.decisions as f64).round() as usize,
        r.decisions,
    )
}

#[test]
fn gait_recognition_on_20_joint_walkers_beside_25_joints() {
    let p = GaitParams::default();
    let set = walkers(4, 2, &SessionRanges::default(), 1).unwrap();
    let v1 = set.to_kinect_v1();
    let s = gait_sample(&v1.walks[0], &p).unwrap();
    assert_eq!(s.jra.pairs.len(), 171);
    assert_eq!(
        all_pairs_in(JointSet::KinectV1, Joint::SpineBase),
        s.jra.pairs
    );
    assert!(s
        .jra
        .pairs
        .iter()
        .all(|&(a, b)| a != Joint::Neck && b != Joint::Neck));
    // The cycle is the same as on 25 joints (it reads the ankles).
    assert_eq!(gait_sample(&set.walks[0], &p).unwrap().cycle, s.cycle);
    // A pair outside the walk's joints is an error naming the joint.
    let err = wscg_biometrics::gait::jra_sequences(
        &v1.walks[0],
        &s.cycle,
        Joint::SpineBase,
        &[(Joint::Neck, Joint::Head)],
    )
    .unwrap_err();
    assert!(err.to_string().contains("Neck"), "{err}");

    let proto = Protocol::default();
    let (mut c25, mut c20, mut total) = (0, 0, 0);
    for seed in 0..3 {
        let set = walkers(20, 3, &SessionRanges::default(), seed).unwrap();
        let (a, n) = accuracy(&set, &proto);
        let (b, _) = accuracy(&set.to_kinect_v1(), &proto);
        println!("seed {seed}: JRA+DTW 1-NN 25 joints {a}/{n}, 20 joints {b}/{n}");
        c25 += a;
        c20 += b;
        total += n;
    }
    println!(
        "JRA+DTW 1-NN over 3 seeds: 25 joints {c25}/{total} = {:.1} %, 20 joints {c20}/{total} = {:.1} %",
        100.0 * c25 as f64 / total as f64,
        100.0 * c20 as f64 / total as f64
    );
    // The 20 joints keep the legs, the trunk and the arms: at least 85 % on the same walkers.
    assert!(100 * c20 >= 85 * total, "{c20}/{total}");
}
