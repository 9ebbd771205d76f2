//! Kernel rendering (check 1 and 2b) and gyro integration.

use nalgebra::{Rotation3, Vector3};
use wscg_deblur::{
    blurriness, render_kernel, GyroSample, GyroTrack, Intrinsics, KernelParams, Timing,
};

fn constant_rate(w: [f64; 3], rate: f64, duration: f64) -> Vec<GyroSample> {
    let n = (duration * rate) as usize + 1;
    (0..n)
        .map(|i| GyroSample::new(i as f64 / rate, w[0], w[1], w[2]))
        .collect()
}

fn timing() -> Timing {
    Timing {
        t_frame: 0.1,
        t_exposure: 1.0 / 30.0,
        t_readout: 0.0,
        t_delay: 0.0,
        height: 480,
    }
}

const K: Intrinsics = Intrinsics {
    f: 600.0,
    cx: 360.0,
    cy: 240.0,
};

/// A uniform segment of length L splatted bilinearly has variance L^2/12 + 1/6 along it
/// (the bilinear splat adds E[f(1-f)] = 1/6 for positions uniform over whole pixels).
fn segment_length(var: f64) -> f64 {
    (12.0 * (var - 1.0 / 6.0)).sqrt()
}

#[test]
fn pure_yaw_kernel_is_a_horizontal_segment_of_six_pixels() {
    let track = GyroTrack::from_camera_rates(&constant_rate([0.0, 0.3, 0.0], 200.0, 1.0)).unwrap();
    let k = render_kernel(
        &track,
        &timing(),
        &K,
        (K.cx, K.cy),
        &KernelParams::default(),
    )
    .unwrap();
    let sum: f64 = k.data.iter().map(|&v| v as f64).sum();
    assert!((sum - 1.0).abs() < 1e-6, "sum {sum}");
    assert!(k.data.iter().all(|&v| v >= 0.0));
    let (mx, my) = k.centroid();
    let (vx, vy, _) = k.moments();
    let extent = 600.0 * (0.3f64 / 30.0).tan();
    // Positive yaw moves the image towards -x: centroid at -extent/2.
    assert!((mx + extent / 2.0).abs() < 0.05, "centroid {mx}");
    assert!(my.abs() < 0.05 && vy.sqrt() < 0.05, "vertical {my} {vy}");
    let len = segment_length(vx);
    assert!((len - 6.0).abs() < 0.1, "extent {len}");
    assert!(
        ((vx - 1.0 / 6.0).sqrt() - 1.732).abs() < 0.03,
        "std {}",
        (vx - 1.0 / 6.0).sqrt()
    );
    assert_eq!(k.origin, (k.size / 2, k.size / 2));
    assert!((blurriness(&k) - vx.sqrt()).abs() < 0.05);
}

#[test]
fn pure_roll_kernel_is_a_vertical_arc_of_six_pixels() {
    let track = GyroTrack::from_camera_rates(&constant_rate([0.0, 0.0, 0.6], 200.0, 1.0)).unwrap();
    let k = render_kernel(
        &track,
        &timing(),
        &K,
        (K.cx + 300.0, K.cy),
        &KernelParams::default(),
    )
    .unwrap();
    let (mx, my) = k.centroid();
    let (vx, vy, _) = k.moments();
    // Roll by theta moves a point at radius 300 along a circle: arc 300 * 0.6 / 30 = 6 px.
    let len = segment_length(vy);
    assert!((len - 6.0).abs() < 0.1, "extent {len}");
    assert!(vx < 0.2, "horizontal variance {vx}");
    assert!(
        mx.abs() < 0.1 && (my.abs() - 3.0).abs() < 0.05,
        "centroid {mx} {my}"
    );
}

#[test]
fn camera_imu_rotation_permutes_the_axes() {
    let w = [0.2, -0.35, 0.5];
    let samples = constant_rate(w, 200.0, 1.0);
    let reference = GyroTrack::from_camera_rates(&samples).unwrap();
    // IMU axes (a, b, c) = camera (y, z, x): camera = R * imu with R a cyclic permutation.
    let r = Rotation3::from_matrix_unchecked(nalgebra::Matrix3::new(
        0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0,
    ));
    let imu: Vec<GyroSample> = samples
        .iter()
        .map(|s| GyroSample {
            t: s.t,
            w: (r.inverse() * Vector3::from(s.w)).into(),
        })
        .collect();
    let permuted = GyroTrack::new(&imu, r, [0.0; 3]).unwrap();
    for p in [(10.0, 20.0), (K.cx, K.cy), (700.0, 470.0)] {
        let a = render_kernel(&reference, &timing(), &K, p, &KernelParams::default()).unwrap();
        let b = render_kernel(&permuted, &timing(), &K, p, &KernelParams::default()).unwrap();
        assert!(a.l1_distance(&b) < 1e-5, "{}", a.l1_distance(&b));
    }
    // Without the rotation the kernels differ.
    let wrong = GyroTrack::new(&imu, Rotation3::identity(), [0.0; 3]).unwrap();
    let a = render_kernel(
        &reference,
        &timing(),
        &K,
        (K.cx, K.cy),
        &KernelParams::default(),
    )
    .unwrap();
    let b = render_kernel(
        &wrong,
        &timing(),
        &K,
        (K.cx, K.cy),
        &KernelParams::default(),
    )
    .unwrap();
    assert!(a.l1_distance(&b) > 0.5);
}

#[test]
fn adaptive_steps_match_a_fine_fixed_sampling() {
    let samples = wscg_deblur::synth::ou_gyro(
        &wscg_deblur::synth::ShakeParams::default().std([0.6, 0.6, 0.4]),
        3,
    )
    .unwrap();
    let track = GyroTrack::from_camera_rates(&samples).unwrap();
    for p in [(0.0, 0.0), (K.cx, K.cy), (719.0, 479.0), (100.0, 400.0)] {
        let a = render_kernel(&track, &timing(), &K, p, &KernelParams::default()).unwrap();
        let b = render_kernel(&track, &timing(), &K, p, &KernelParams::fixed(1024)).unwrap();
        assert!(a.l1_distance(&b) < 0.02, "{}", a.l1_distance(&b));
        assert!(blurriness(&a) > 1.0);
    }
}

#[test]
fn slerp_integration_is_exact_for_constant_rates() {
    let track = GyroTrack::from_camera_rates(&constant_rate([0.3, -0.2, 0.7], 200.0, 1.0)).unwrap();
    let w = Vector3::new(0.3, -0.2, 0.7);
    for t in [0.0123, 0.5, 0.77777] {
        let expect = nalgebra::UnitQuaternion::from_scaled_axis(w * t);
        assert!(track.orientation(t).angle_to(&expect) < 1e-12);
    }
    let rel = track.relative(0.2, 0.3);
    let expect = nalgebra::Rotation3::from_scaled_axis(w * 0.1);
    assert!(
        (rel.matrix() - expect.matrix()).norm() < 1e-9,
        "{}",
        (rel.matrix() - expect.matrix()).norm()
    );
}

#[test]
fn bad_input_is_reported() {
    let good = constant_rate([0.0, 0.3, 0.0], 200.0, 1.0);
    let mut unsorted = good.clone();
    unsorted.swap(3, 4);
    let e = GyroTrack::from_camera_rates(&unsorted)
        .unwrap_err()
        .to_string();
    assert!(e.contains("strictly increasing"), "{e}");
    let mut dup = good.clone();
    dup[5].t = dup[4].t;
    assert!(GyroTrack::from_camera_rates(&dup).is_err());
    let mut nan = good.clone();
    nan[2].w[0] = f64::NAN;
    assert!(GyroTrack::from_camera_rates(&nan)
        .unwrap_err()
        .to_string()
        .contains("non-finite"));
    assert!(GyroTrack::from_camera_rates(&good[..1]).is_err());
    let track = GyroTrack::from_camera_rates(&good).unwrap();
    let late = Timing {
        t_frame: 0.99,
        ..timing()
    };
    let e = render_kernel(&track, &late, &K, (K.cx, K.cy), &KernelParams::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("cover") && e.contains("gap"), "{e}");
    for bad in [
        Timing {
            t_exposure: 0.0,
            ..timing()
        },
        Timing {
            t_readout: -0.01,
            ..timing()
        },
    ] {
        assert!(render_kernel(&track, &bad, &K, (K.cx, K.cy), &KernelParams::default()).is_err());
    }
    let bad_k = Intrinsics { f: 0.0, ..K };
    assert!(render_kernel(
        &track,
        &timing(),
        &bad_k,
        (K.cx, K.cy),
        &KernelParams::default()
    )
    .unwrap_err()
    .to_string()
    .contains("focal"));
    let fast = GyroTrack::from_camera_rates(&constant_rate([0.0, 9.0, 0.0], 200.0, 1.0)).unwrap();
    let e = render_kernel(&fast, &timing(), &K, (K.cx, K.cy), &KernelParams::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("blur too large for tiling"), "{e}");
}
