//! The Mitsunaga-Nayar calibration (RASCAL's model, which the paper used for its 8-bit
//! views), on a calibration gradient that spans every code: exact recovery of a polynomial
//! response from 16-bit codes, ratios re-estimated from wrong times, 8-bit gamma and
//! S-shaped cameras against the truth and Debevec-Malik, the dark scene it cannot calibrate,
//! bad input.

use wscg_hdr::metrics::response_log_error;
use wscg_hdr::synth::{encode, gradient_target, layered_scene, Response, SceneParams};
use wscg_hdr::{
    calibrate_debevec, calibrate_mitsunaga_nayar, Crf, MitsunagaNayarFit, MitsunagaNayarParams,
};
use wscg_math::Image;

fn gradient() -> Image<f32> {
    gradient_target(96, 128).unwrap()
}

/// `n` exposures of `e` one stop apart through `response`.
fn stack(
    e: &Image<f32>,
    response: Response,
    n: i32,
    bits: u8,
    noise: f64,
) -> (Vec<Image<u16>>, Vec<f64>) {
    let times: Vec<f64> = (0..n).map(|k| 0.004 * 2f64.powi(k)).collect();
    let imgs = times
        .iter()
        .enumerate()
        .map(|(k, &t)| encode(e, t, response, noise, bits, 7 + k as u64).unwrap())
        .collect();
    (imgs, times)
}

/// Largest `|f(z) - f_true(z)|` over codes `lo..=hi` of every channel.
fn worst(crf: &Crf, truth: Response, lo: u16, hi: u16) -> f64 {
    let zmax = crf.z_max() as f64;
    let mut w = 0f64;
    for c in 0..crf.channels() {
        for z in lo..=hi {
            let d = crf.inv(z, c) as f64 - truth.inverse(z as f64 / zmax);
            w = w.max(d.abs());
        }
    }
    w
}

fn largest_ratio_error(fit: &MitsunagaNayarFit, want: f64) -> f64 {
    fit.channels
        .iter()
        .flat_map(|c| c.ratios.iter())
        .map(|r| (r / want - 1.0).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_cubic_response_is_recovered_from_fine_codes() {
    // 16-bit codes: the quantisation (8e-6 of the range) no longer hides the model.
    let truth = Response::Cubic([0.3, 0.2, 0.5]);
    let (imgs, times) = stack(&gradient(), truth, 7, 16, 0.0);
    for (degree, refine_ratios) in [(Some(3), false), (None, false), (Some(3), true)] {
        let p = MitsunagaNayarParams::default()
            .degree(degree)
            .refine_ratios(refine_ratios);
        let fit = calibrate_mitsunaga_nayar(&imgs, &times, 16, &p).unwrap();
        let err = worst(&fit.crf, truth, 0, u16::MAX);
        let rerr = largest_ratio_error(&fit, 0.5);
        eprintln!(
            "cubic, degree {degree:?} -> {}, refined {refine_ratios}: max |f - f_true| = \
             {err:.2e}, ratios within {rerr:.1e}",
            fit.channels[0].coefficients.len() - 1
        );
        assert!(err <= 1e-4, "{err}");
        assert!(rerr <= 1e-3, "{rerr}");
        for ch in &fit.channels {
            assert!((ch.coefficients.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert_eq!(ch.coefficients.len(), 4, "degree of {degree:?}");
        }
    }
}

#[test]
fn the_exposure_ratios_are_recovered_from_wrong_times() {
    let truth = Response::Cubic([0.3, 0.2, 0.5]);
    let (imgs, times) = stack(&gradient(), truth, 7, 16, 0.0);
    // The intermediate times 10-15 % off, as nominal shutter values can be; the span from
    // the shortest to the longest exposure is right (it fixes the exponential ambiguity).
    let wrong: Vec<f64> = times
        .iter()
        .zip([1.0, 1.12, 0.9, 1.15, 0.88, 1.1, 1.0])
        .map(|(t, k)| t * k)
        .collect();
    let fixed = MitsunagaNayarParams::default()
        .degree(Some(3))
        .refine_ratios(false);
    let refined = fixed.refine_ratios(true);
    // With the wrong ratios kept, the cubic cannot fit: far off, or not even increasing.
    let eb = calibrate_mitsunaga_nayar(&imgs, &wrong, 16, &fixed)
        .map_or(f64::INFINITY, |bad| worst(&bad.crf, truth, 0, u16::MAX));
    let good = calibrate_mitsunaga_nayar(&imgs, &wrong, 16, &refined).unwrap();
    let eg = worst(&good.crf, truth, 0, u16::MAX);
    let rerr = largest_ratio_error(&good, 0.5);
    eprintln!(
        "wrong times: max |f - f_true| {eb:.2e} with their ratios, {eg:.2e} refined in {} \
         iterations (ratios within {rerr:.1e} of 0.5)",
        good.channels[0].iterations
    );
    assert!(eg <= 1e-4, "{eg}");
    assert!(eb > 0.01, "{eb}");
    assert!(rerr <= 1e-3, "{rerr}");
}

#[test]
fn eight_bit_gamma_and_s_shaped_cameras_are_calibrated() {
    for (truth, limit) in [(Response::Gamma(2.2), 0.01), (Response::SCurve(3.0), 0.05)] {
        let (imgs, times) = stack(&gradient(), truth, 7, 8, 0.001);
        let fit =
            calibrate_mitsunaga_nayar(&imgs, &times, 8, &MitsunagaNayarParams::default()).unwrap();
        let dm = calibrate_debevec(&imgs, &times, 8, 70, 10.0).unwrap();
        let e_mn = worst(&fit.crf, truth, 5, 250);
        // Both in the measure of the Debevec-Malik test: max |ln f - ln f_true| over codes
        // 20..235, Debevec-Malik's free offset removed.
        let l_mn = response_log_error(&fit.crf, |m| truth.inverse(m), 20..=235, false);
        let l_dm = response_log_error(&dm, |m| truth.inverse(m), 20..=235, true);
        eprintln!(
            "{truth:?}: degrees {:?}, max |f - f_true| over codes 5..250 {e_mn:.4}; max |ln f - \
             ln f_true| over 20..235 {l_mn:.4} (Debevec-Malik {l_dm:.4}); ratios within {:.1e}",
            fit.channels
                .iter()
                .map(|c| c.coefficients.len() - 1)
                .collect::<Vec<_>>(),
            largest_ratio_error(&fit, 0.5)
        );
        assert!(e_mn <= limit, "{truth:?}: {e_mn}");
        assert!(largest_ratio_error(&fit, 0.5) <= 0.01);
    }
}

#[test]
fn a_dark_scene_is_refused_with_the_reason() {
    // The layered scene: 1-2 % of its pixels reach the upper half of the codes before they
    // saturate, so f(1) = 1 cannot fix the polynomial's scale.
    let cfg = SceneParams::default().height(96).width(128);
    let e = layered_scene(&cfg, 1).unwrap().radiance[2].clone();
    let (imgs, times) = stack(&e, Response::Gamma(2.2), 7, 8, 0.001);
    let err =
        calibrate_mitsunaga_nayar(&imgs, &times, 8, &MitsunagaNayarParams::default()).unwrap_err();
    assert!(err.to_string().contains("upper half"), "{err}");
}

#[test]
fn bad_inputs_are_errors() {
    let (imgs, times) = stack(&gradient(), Response::Gamma(2.2), 3, 8, 0.0);
    let p = MitsunagaNayarParams::default();
    assert!(calibrate_mitsunaga_nayar(&imgs, &times, 8, &p).is_ok());
    assert!(calibrate_mitsunaga_nayar(&imgs[..1], &times[..1], 8, &p).is_err());
    assert!(calibrate_mitsunaga_nayar(&imgs, &times[..2], 8, &p).is_err());
    assert!(calibrate_mitsunaga_nayar(&imgs, &[0.1, 0.1, 0.2], 8, &p).is_err());
    assert!(calibrate_mitsunaga_nayar(&imgs, &[0.1, f64::NAN, 0.2], 8, &p).is_err());
    assert!(calibrate_mitsunaga_nayar(&imgs, &times, 4, &p).is_err());
    assert!(calibrate_mitsunaga_nayar(&imgs, &times, 17, &p).is_err());
    for bad in [
        p.degree(Some(0)),
        p.max_degree(11),
        p.samples(0),
        p.tol(0.0),
        p.max_iter(0),
    ] {
        assert!(calibrate_mitsunaga_nayar(&imgs, &times, 8, &bad).is_err());
    }
    // All black: no equation.
    let black = Image::new(8, 8, 1, vec![0u16; 64]).unwrap();
    let few = p.samples(16);
    let e = calibrate_mitsunaga_nayar(&[black.clone(), black.clone()], &[0.1, 0.2], 8, &few);
    assert!(e
        .unwrap_err()
        .to_string()
        .contains("CRF calibration failed"));
    let other = Image::new(8, 9, 1, vec![0u16; 72]).unwrap();
    assert!(calibrate_mitsunaga_nayar(&[black, other], &[0.1, 0.2], 8, &p).is_err());
}
