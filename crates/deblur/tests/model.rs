//! Blur model (checks 2, 8, 9): the gyro kernels reproduce densely rendered blur, the
//! rolling-shutter rectification removes the shear, the time delay is recovered.

use wscg_deblur::synth::{self, BlurRenderParams, Burst, ShakeParams};
use wscg_deblur::tiling::convolve_piecewise;
use wscg_deblur::{
    estimate_time_delay, kernel_grid, phase_correlation, rectify_rolling_shutter, GyroSample,
    GyroTrack, Intrinsics, KernelGrid, KernelParams, Tiling, Timing,
};
use wscg_math::Image;

fn linear() -> BlurRenderParams {
    BlurRenderParams::default()
        .noise_sigma(0.0)
        .gamma(None)
        .quantise(false)
}

/// PSNR (range 1) over region interiors (4 px from region borders, 16 px from the frame edge).
fn interior_psnr(a: &Image<f32>, b: &Image<f32>, tile: usize) -> f64 {
    let (h, w) = (a.height(), a.width());
    let (mut se, mut n) = (0.0, 0);
    for y in 16..h - 16 {
        for x in 16..w - 16 {
            let (ry, rx) = (y % tile, x % tile);
            if ry < 4 || ry >= tile - 4 || rx < 4 || rx >= tile - 4 {
                continue;
            }
            se += ((a.at(y, x, 0) - b.at(y, x, 0)) as f64).powi(2);
            n += 1;
        }
    }
    10.0 * (n as f64 / se).log10()
}

#[test]
fn region_kernels_reproduce_dense_blur_and_flipped_kernels_do_not() {
    let (h, w) = (150, 180);
    let k = Intrinsics::centred(600.0, w, h);
    let sharp = synth::scene(h, w, 11).unwrap();
    let burst = Burst {
        frames: 1,
        ..Default::default()
    };
    let tiling = Tiling::default();
    let (mut worst, mut worst_gap) = (f64::MAX, f64::MAX);
    for seed in 0..20 {
        let samples =
            synth::ou_gyro(&ShakeParams::default().duration(burst.duration()), seed).unwrap();
        let track = GyroTrack::from_camera_rates(&samples).unwrap();
        let timing = burst.timing(0, h);
        let dense =
            synth::render_blurred(&sharp, &track, &timing, &k, timing.open(0.0), &linear(), 0)
                .unwrap();
        let grid = kernel_grid(&track, &timing, &k, w, h, 30, &KernelParams::default()).unwrap();
        let model = convolve_piecewise(&sharp, &grid, &tiling).unwrap();
        let flipped = KernelGrid {
            kernels: grid.kernels.iter().map(|k| k.flipped()).collect(),
            ..grid.clone()
        };
        let wrong = convolve_piecewise(&sharp, &flipped, &tiling).unwrap();
        let (good, bad) = (
            interior_psnr(&model, &dense, 30),
            interior_psnr(&wrong, &dense, 30),
        );
        let blur = interior_psnr(&sharp, &dense, 30);
        eprintln!("seed {seed}: model {good:.2} dB, flipped {bad:.2} dB, unblurred {blur:.2} dB, max radius {}", grid.max_radius());
        worst = worst.min(good);
        worst_gap = worst_gap.min(good - bad);
    }
    assert!(worst >= 35.0, "worst model PSNR {worst}");
    assert!(
        worst_gap >= 10.0,
        "worst gap to flipped kernels {worst_gap}"
    );
}

#[test]
fn rolling_shutter_shear_is_removed_by_rectification() {
    let (h, w) = (200, 240);
    let k = Intrinsics::centred(600.0, w, h);
    // A vertical bar on a dark background.
    let sharp = Image::from_fn(
        h,
        w,
        |_, x| if (115..125).contains(&x) { 0.9f32 } else { 0.1 },
    )
    .unwrap();
    let samples: Vec<GyroSample> = (0..400)
        .map(|i| GyroSample::new(i as f64 / 200.0, 0.0, 1.0, 0.0))
        .collect();
    let track = GyroTrack::from_camera_rates(&samples).unwrap();
    let timing = Timing {
        t_frame: 0.5,
        t_exposure: 1e-5,
        t_readout: 0.025,
        t_delay: 0.0,
        height: h,
    };
    let frame = synth::render_blurred(
        &sharp,
        &track,
        &timing,
        &k,
        timing.reference(),
        &linear(),
        0,
    )
    .unwrap();
    // Bar centre per row (intensity-weighted).
    let centre = |img: &Image<f32>, y: usize| -> f64 {
        let (mut s, mut m) = (0.0, 0.0);
        for x in 0..w {
            let v = (img.at(y, x, 0) - 0.1).max(0.0) as f64;
            s += v * x as f64;
            m += v;
        }
        s / m
    };
    let shear = |img: &Image<f32>| centre(img, h - 20) - centre(img, 20);
    let before = shear(&frame);
    // f * w * t_r over the rows 20..h-20.
    let expect = 600.0 * 1.0 * 0.025 * (h - 40) as f64 / h as f64;
    eprintln!("shear before {before:.3} px (expected magnitude {expect:.3})");
    assert!((before.abs() - expect).abs() < 0.5, "{before} vs {expect}");
    let rect = rectify_rolling_shutter(&frame, &track, &timing, &k).unwrap();
    let after = shear(&rect);
    eprintln!("shear after {after:.3} px");
    assert!(after.abs() < 0.5, "{after}");
}

#[test]
fn time_delay_is_recovered_from_ten_seconds_of_video() {
    let (h, w) = (96, 128);
    let k = Intrinsics::centred(300.0, w, h);
    let sharp = synth::scene(h, w, 21).unwrap();
    let burst = Burst {
        frames: 300,
        t0: 0.1,
        t_delay: 0.015,
        ..Default::default()
    };
    let samples = synth::ou_gyro(
        &ShakeParams::default()
            .duration(burst.duration())
            .std([0.3, 0.3, 0.05])
            .tau(0.1),
        5,
    )
    .unwrap();
    let track = GyroTrack::from_camera_rates(&samples).unwrap();
    let measured = synth::add_gyro_noise(&samples, 0.002, 6).unwrap();
    let measured_track = GyroTrack::from_camera_rates(&measured).unwrap();
    // Each consecutive pair is rendered with the world in the first frame's pose, so the
    // shake of ten seconds never leaves the scene.
    let opts = BlurRenderParams::default().min_steps(16);
    let render = |i: usize, world: f64, seed: u64| {
        synth::render_blurred(&sharp, &track, &burst.timing(i, h), &k, world, &opts, seed).unwrap()
    };
    let shifts: Vec<(f64, f64)> = (0..burst.frames - 1)
        .map(|i| {
            let world = burst.timing(i, h).reference();
            phase_correlation(
                &render(i, world, 2 * i as u64),
                &render(i + 1, world, 2 * i as u64 + 1),
            )
            .unwrap()
        })
        .collect();
    let timing = burst.timing(0, h);
    let est = estimate_time_delay(
        &measured_track,
        &burst.times(),
        &shifts,
        &timing,
        &k,
        (-0.05, 0.08),
        0.0005,
    )
    .unwrap();
    eprintln!("estimated delay {:.2} ms", est * 1e3);
    assert!((est - 0.015).abs() < 0.002, "{est}");
}

#[test]
fn phase_correlation_measures_known_shifts() {
    let a = synth::scene(100, 120, 3).unwrap();
    let b = Image::from_fn(100, 120, |y, x| {
        a.at((y + 100 - 3) % 100, (x + 120 - 7) % 120, 0)
    })
    .unwrap();
    let (dx, dy) = phase_correlation(&a, &b).unwrap();
    assert!(
        (dx - 7.0).abs() < 0.1 && (dy - 3.0).abs() < 0.1,
        "{dx} {dy}"
    );
}
