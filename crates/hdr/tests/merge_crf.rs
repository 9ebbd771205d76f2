//! Acceptance checks 1 and 2 of paper 13: merge exactness, Khan weights, the
//! fallback of clipped pixels, and Debevec-Malik calibration of an S-shaped response.

use wscg_hdr::merge::{merge, MergeInput, Merged};
use wscg_hdr::metrics::rmse_log2;
use wscg_hdr::radiance::{to_samples, to_samples_float};
use wscg_hdr::synth::{encode, layered_scene, Response, SceneParams};
use wscg_hdr::ViewSamples;
use wscg_hdr::{calibrate_debevec, khan_weight, merge_stack, Crf};
use wscg_math::Image;

/// The central view's true radiance of the default scene, 5 exposures.
fn stack_truth() -> (Image<f32>, Vec<f64>) {
    let cfg = SceneParams::default().height(96).width(128);
    let sc = layered_scene(&cfg, 1).unwrap();
    (sc.radiance[2].clone(), cfg.times.clone())
}

/// The general merge of converted samples with their times.
fn merge_samples(samples: &[ViewSamples], times: &[f64]) -> Merged {
    let inputs: Vec<MergeInput> = samples
        .iter()
        .zip(times)
        .map(|(s, &t)| MergeInput {
            samples: s,
            time: t,
        })
        .collect();
    merge(&inputs).unwrap()
}

#[test]
fn khan_weights_vanish_at_the_ends_and_are_one_in_the_middle() {
    assert_eq!(khan_weight(0.0, 255.0), 0.0);
    assert_eq!(khan_weight(255.0, 255.0), 0.0);
    assert_eq!(khan_weight(127.5, 255.0), 1.0);
    assert_eq!(khan_weight(1023.0, 1023.0), 0.0);
    // Eq. 7 at a few codes.
    for z in [3.0f32, 40.0, 200.0, 250.0] {
        let want = 1.0 - (2.0 * z as f64 / 255.0 - 1.0).powi(12);
        assert!((khan_weight(z, 255.0) as f64 - want).abs() < 1e-6);
    }
}

#[test]
fn merging_an_unquantised_noise_free_stack_inverts_exactly() {
    let (e, times) = stack_truth();
    let g = Response::Gamma(2.2);
    // Unquantised signal levels through the true response.
    let crf = g.crf(16, 1).unwrap();
    let samples: Vec<_> = times
        .iter()
        .map(|&t| {
            let lv = e.map(|v| g.forward(v as f64 * t) as f32);
            to_samples_float(&lv, &crf, t).unwrap()
        })
        .collect();
    let m = merge_samples(&samples, &times);
    assert!(m.hdr.data().iter().all(|v| v.is_finite()));
    let err = rmse_log2(&m.hdr, &e, None).unwrap();
    eprintln!("noise-free stack: RMSE log2 {err:.2e}");
    assert!(err <= 1e-4, "noise-free RMSE log2 {err}");
}

#[test]
fn merging_a_noisy_8_bit_stack_is_accurate_where_some_exposure_is_good() {
    let (e, times) = stack_truth();
    let g = Response::Gamma(2.2);
    let views: Vec<Image<u16>> = times
        .iter()
        .enumerate()
        .map(|(k, &t)| encode(&e, t, g, 0.002, 8, 40 + k as u64).unwrap())
        .collect();
    let crf = Crf::gamma(2.2, 8, 1).unwrap();
    let m = merge_stack(&views, &times, std::slice::from_ref(&crf)).unwrap();
    // The table-driven stack merge is the general merge of the converted samples, exactly.
    let samples: Vec<_> = views
        .iter()
        .zip(&times)
        .map(|(v, &t)| to_samples(v, &crf, t).unwrap())
        .collect();
    assert_eq!(merge_samples(&samples, &times), m);
    assert!(m.hdr.data().iter().all(|v| v.is_finite()));
    let mask: Vec<bool> = (0..e.data().len())
        .map(|i| views.iter().any(|v| (10..=245).contains(&v.data()[i])))
        .collect();
    let err = rmse_log2(&m.hdr, &e, Some(&mask)).unwrap();
    eprintln!("8-bit noisy stack: RMSE log2 {err:.4}");
    assert!(err <= 0.05, "8-bit RMSE log2 {err}");
    // The single longest exposure alone is far worse (the merge is doing the work).
    let one = merge_stack(&views[4..], &times[4..], &[Crf::gamma(2.2, 8, 1).unwrap()]).unwrap();
    assert!(rmse_log2(&one.hdr, &e, Some(&mask)).unwrap() > 4.0 * err);
}

#[test]
fn clipped_pixels_take_the_shortest_or_longest_exposure() {
    let crf = Crf::gamma(2.2, 8, 1).unwrap();
    let times = [0.01, 0.1, 1.0];
    let white = Image::filled(2, 3, 1, 255u16).unwrap();
    let black = Image::filled(2, 3, 1, 0u16).unwrap();
    let m = merge_stack(
        &[white.clone(), white.clone(), white],
        &times,
        std::slice::from_ref(&crf),
    )
    .unwrap();
    assert_eq!(m.fallback_pixels, 6);
    // f^-1(255) / shortest time: the lower bound of the true radiance.
    assert!(m.hdr.data().iter().all(|&v| (v - 100.0).abs() < 1e-3));
    let m = merge_stack(
        &[black.clone(), black.clone(), black],
        &times,
        std::slice::from_ref(&crf),
    )
    .unwrap();
    assert_eq!(m.fallback_pixels, 6);
    assert!(m.hdr.data().iter().all(|&v| v == 0.0));
    // One usable sample is enough: no fallback.
    let mid = Image::filled(2, 3, 1, 128u16).unwrap();
    let white = Image::filled(2, 3, 1, 255u16).unwrap();
    let m = merge_stack(
        &[mid, white.clone(), white],
        &times,
        std::slice::from_ref(&crf),
    )
    .unwrap();
    assert_eq!(m.fallback_pixels, 0);
    let want = crf.inv(128, 0) / 0.01;
    assert!(m.hdr.data().iter().all(|&v| (v - want).abs() < 1e-3 * want));
}

/// Checks that every channel of `crf` has the shape of the camera response `s` at the codes
/// `zs`: `ln f^-1` within `tol` of the truth once the additive constant (the exposure scale,
/// which is not identifiable) is removed.
fn assert_response_shape(crf: &Crf, s: Response, zs: &[u16], tol: f64) {
    let zmax = (crf.levels() - 1) as f64;
    for c in 0..crf.channels() {
        let g = |z: u16| (crf.inv(z, c) as f64).ln();
        let t = |z: u16| s.inverse(z as f64 / zmax).ln();
        let off = zs.iter().map(|&z| g(z) - t(z)).sum::<f64>() / zs.len() as f64;
        let worst = zs
            .iter()
            .map(|&z| (g(z) - t(z) - off).abs())
            .fold(0.0, f64::max);
        eprintln!("calibration, channel {c}: max |g - ln f^-1| = {worst:.4}");
        assert!(worst <= tol, "channel {c}: max |g - ln f^-1| = {worst}");
    }
}

/// The scene of [`stack_truth`] through an S-curve camera of `bits` bits: seven exposures
/// one stop apart, spanning the scene's range.
fn s_curve_stack(bits: u8) -> (Image<f32>, Response, Vec<f64>, Vec<Image<u16>>) {
    let (e, _) = stack_truth();
    let s = Response::SCurve(3.0);
    let times: Vec<f64> = (0..7).map(|k| 0.004 * 2f64.powi(k)).collect();
    let stack = times
        .iter()
        .enumerate()
        .map(|(k, &t)| encode(&e, t, s, 0.001, bits, 7 + k as u64).unwrap())
        .collect();
    (e, s, times, stack)
}

#[test]
fn debevec_recovers_an_s_shaped_response() {
    let (e, s, times, stack) = s_curve_stack(8);
    let crf = calibrate_debevec(&stack, &times, 8, 70, 10.0).unwrap();
    assert_eq!(crf.channels(), 3);
    let zs: Vec<u16> = (20..=235).collect();
    assert_response_shape(&crf, s, &zs, 0.05);
    // A gamma camera is not mistaken for the S-curve: its recovered shape differs.
    let g22 = Response::Gamma(2.2);
    let other: Vec<Image<u16>> = times
        .iter()
        .enumerate()
        .map(|(k, &t)| encode(&e, t, g22, 0.001, 8, 7 + k as u64).unwrap())
        .collect();
    let crf2 = calibrate_debevec(&other, &times, 8, 70, 10.0).unwrap();
    let d = |z: u16| (crf2.inv(z, 0) as f64).ln() - (crf.inv(z, 0) as f64).ln();
    assert!((d(40) - d(220)).abs() > 0.3);
}

/// 16-bit views (a raw converter's TIFFs): the codes are reduced to 10 bits for the solve
/// and the response comes back over all 65536 codes, matching the camera's, and merging the
/// stack with it recovers the radiance.
#[test]
fn debevec_calibrates_16_bit_stacks_over_every_code() {
    let (e, s, times, stack) = s_curve_stack(16);
    let crf = calibrate_debevec(&stack, &times, 16, 70, 10.0).unwrap();
    assert_eq!((crf.levels(), crf.channels()), (65536, 3));
    let zs: Vec<u16> = (20..=235).map(|k| k * 257 + 100).collect();
    assert_response_shape(&crf, s, &zs, 0.05);
    for c in 0..3 {
        // Interpolated between the bins: non-decreasing over every code.
        assert!((1..=65535u16).all(|z| crf.inv(z, c) >= crf.inv(z - 1, c)));
    }
    let m = merge_stack(&stack, &times, std::slice::from_ref(&crf)).unwrap();
    // Up to the unidentifiable scale: compare log radiance after removing the mean offset.
    let pairs: Vec<(f64, f64)> = m
        .hdr
        .data()
        .iter()
        .zip(e.data())
        .filter(|(&a, &b)| a > 0.0 && b > 0.0)
        .map(|(&a, &b)| ((a as f64).ln(), (b as f64).ln()))
        .collect();
    assert!(pairs.len() > e.data().len() * 9 / 10);
    let off = pairs.iter().map(|(a, b)| a - b).sum::<f64>() / pairs.len() as f64;
    let rms = (pairs
        .iter()
        .map(|(a, b)| (a - b - off).powi(2))
        .sum::<f64>()
        / pairs.len() as f64)
        .sqrt();
    assert!(rms < 0.1, "rms log radiance error {rms}");
}

#[test]
fn bad_inputs_are_errors() {
    let crf = Crf::gamma(2.2, 8, 1).unwrap();
    let img = Image::filled(4, 4, 3, 10u16).unwrap();
    // Times: count, sign, finiteness.
    assert!(merge_stack(
        std::slice::from_ref(&img),
        &[0.1, 0.2],
        std::slice::from_ref(&crf)
    )
    .is_err());
    assert!(merge_stack(
        std::slice::from_ref(&img),
        &[0.0],
        std::slice::from_ref(&crf)
    )
    .is_err());
    assert!(merge_stack(
        std::slice::from_ref(&img),
        &[f64::NAN],
        std::slice::from_ref(&crf)
    )
    .is_err());
    // Shapes differ.
    let small = Image::filled(3, 4, 3, 10u16).unwrap();
    assert!(merge_stack(
        &[img.clone(), small],
        &[0.1, 0.2],
        std::slice::from_ref(&crf)
    )
    .is_err());
    // Codes beyond the table: a 10-bit view with an 8-bit response.
    let ten = Image::filled(4, 4, 3, 1000u16).unwrap();
    let e = to_samples(&ten, &crf, 0.1).unwrap_err().to_string();
    assert!(e.contains("bit depth"), "{e}");
    // Tables: wrong length, non-monotone, negative, zero levels.
    assert!(Crf::from_table(&[0.0, 0.5], 3, 1).is_err());
    let e = Crf::from_table(&[0.0, 0.6, 0.5, 1.0], 4, 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("monotone"), "{e}");
    assert!(Crf::from_table(&[-0.1, 0.5, 1.0], 3, 1).is_err());
    assert!(Crf::from_table(&[0.0, 0.0], 2, 1).is_err());
    // A 3-channel table does not fit a 1-channel view.
    let t3 = Crf::gamma(2.2, 8, 3).unwrap();
    assert!(to_samples(&Image::filled(2, 2, 1, 5u16).unwrap(), &t3, 0.1).is_err());
    // Calibration: one exposure, lambda, codes above the bit depth.
    assert!(calibrate_debevec(std::slice::from_ref(&img), &[0.1], 8, 70, 10.0).is_err());
    assert!(calibrate_debevec(&[img.clone(), img.clone()], &[0.1, 0.2], 8, 4, -1.0).is_err());
    assert!(calibrate_debevec(&[ten.clone(), ten], &[0.1, 0.2], 8, 4, 10.0).is_err());
    assert!(calibrate_debevec(&[img.clone(), img.clone()], &[0.1, 0.2], 17, 4, 10.0).is_err());
    // Float levels outside [0, 1].
    let lv = Image::filled(2, 2, 1, 1.5f32).unwrap();
    assert!(to_samples_float(&lv, &crf, 0.1).is_err());
}
