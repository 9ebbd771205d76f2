//! Multi-frame removal (checks 4, 5, 6) on generated scenes; the Python tests run the
//! Table-1 analogue on scikit-image's photographs.

use wscg_deblur::metrics::quality;
use wscg_deblur::synth::{self, BlurRenderParams, Burst, ShakeParams};
use wscg_deblur::{
    blurriness, deblur_frame, deblur_multiframe, render_kernel, FrameInput, GyroSample, GyroTrack,
    HyperLaplacianParams, Intrinsics, KernelParams, Method, MultiframeParams, Timing,
};
use wscg_math::progress::NoProgress;
use wscg_math::Image;

struct Scores {
    b: (f64, f64),
    w: (f64, f64),
    rl: (f64, f64),
    ks: (f64, f64),
    km3: (f64, f64),
    km5: (f64, f64),
}

fn table1(sharp: &Image<f32>, seed: u64) -> Scores {
    let (h, w) = (sharp.height(), sharp.width());
    let burst = Burst::default();
    let sb = synth::make_burst(
        sharp,
        &burst,
        &ShakeParams::default(),
        2,
        0.002,
        &BlurRenderParams::default(),
        seed,
    )
    .unwrap();
    let track = GyroTrack::from_camera_rates(&sb.measured).unwrap();
    let k = Intrinsics::centred(600.0, w, h);
    let opts = MultiframeParams::default().t_delay(burst.t_delay);
    let main = &sb.frames[2];
    let q = |img: &Image<f32>| quality(img, &sb.sharp_display, 16).unwrap();
    // Single-frame baselines (development-tuned parameters of Method::by_name).
    let run = |m: Method| q(&deblur_frame(main, &track, &k, &m, &opts).unwrap().0);
    let km = |radius| {
        deblur_multiframe(
            &sb.frames,
            2,
            &track,
            &k,
            &opts.radius(Some(radius)),
            &NoProgress,
        )
        .unwrap()
    };
    let km3 = km(1);
    assert_eq!(km3.used_frames, vec![1, 2, 3], "{:?}", km3.warnings);
    // The pipeline's single-frame stage is the single-frame method.
    let ks = deblur_frame(main, &track, &k, &Method::HyperLaplacian(opts.hl), &opts)
        .unwrap()
        .0;
    assert_eq!(ks.data(), km3.single.data());
    Scores {
        b: q(&main.image),
        w: run(Method::by_name("wiener").unwrap()),
        rl: run(Method::by_name("rl").unwrap()),
        ks: q(&km3.single),
        km3: q(&km3.image),
        km5: q(&km(2).image),
    }
}

#[test]
fn table1_analogue_orders_the_methods_as_the_paper() {
    let sharp = synth::scene(180, 240, 31).unwrap();
    let runs: Vec<Scores> = (0..3).map(|s| table1(&sharp, 100 + s)).collect();
    let mean = |f: &dyn Fn(&Scores) -> (f64, f64)| {
        let n = runs.len() as f64;
        (
            runs.iter().map(|r| f(r).0).sum::<f64>() / n,
            runs.iter().map(|r| f(r).1).sum::<f64>() / n,
        )
    };
    let (b, w, rl, ks, km3, km5) = (
        mean(&|r| r.b),
        mean(&|r| r.w),
        mean(&|r| r.rl),
        mean(&|r| r.ks),
        mean(&|r| r.km3),
        mean(&|r| r.km5),
    );
    for (name, v) in [
        ("B", b),
        ("W", w),
        ("RL", rl),
        ("KS", ks),
        ("KM3", km3),
        ("KM5", km5),
    ] {
        eprintln!("{name}: PSNR {:.3} SSIM {:.3}", v.0, v.1);
    }
    // KM >= KS + 0.5 dB (check 4) is checked on the photographs of the Python tests;
    // on this piecewise-flat scene KS alone already gains ~9 dB over B.
    assert!(km3.0 >= ks.0 - 1.0, "KM3 {} KS {}", km3.0, ks.0);
    assert!(km3.0 >= b.0 + 1.5, "KM3 {} B {}", km3.0, b.0);
    assert!(km3.1 >= b.1 + 0.03, "SSIM KM3 {} B {}", km3.1, b.1);
    // SSIM(W) < SSIM(RL) (check 4) is asserted on `coffee` in the Python tests; on this
    // scene, with the development-tuned NSR and iterations, the two are within 0.004. The
    // hyper-Laplacian prior beats both baselines here.
    assert!(
        ks.0 > w.0.max(rl.0) && ks.1 > w.1.max(rl.1),
        "KS {ks:?} W {w:?} RL {rl:?}"
    );
    assert!(km5.0 >= km3.0 - 0.1, "KM5 {} KM3 {}", km5.0, km3.0);
}

/// Check 5: under roll-dominant shake the blur varies over the frame, and the piecewise
/// KS beats one global kernel (the uniform-blur assumption of blind tools) by >= 1 dB.
#[test]
fn piecewise_kernels_beat_one_global_kernel_under_roll() {
    let sharp = synth::scene(180, 240, 41).unwrap();
    let (h, w) = (180, 240);
    let k = Intrinsics::centred(600.0, w, h);
    let burst = Burst {
        frames: 1,
        ..Default::default()
    };
    let (mut ks, mut gu) = (0.0, 0.0);
    let seeds = 3;
    for seed in 0..seeds {
        let ou = ShakeParams::default().std([0.1, 0.1, 1.0]);
        let sb = synth::make_burst(
            &sharp,
            &burst,
            &ou,
            0,
            0.002,
            &BlurRenderParams::default(),
            200 + seed,
        )
        .unwrap();
        let track = GyroTrack::from_camera_rates(&sb.measured).unwrap();
        let opts = MultiframeParams::default().t_delay(burst.t_delay);
        let q = |m: Method| {
            let img = deblur_frame(&sb.frames[0], &track, &k, &m, &opts)
                .unwrap()
                .0;
            quality(&img, &sb.sharp_display, 16).unwrap().0
        };
        let (a, b) = (
            q(Method::HyperLaplacian(HyperLaplacianParams::default())),
            q(Method::GlobalUniform(HyperLaplacianParams::default())),
        );
        eprintln!("seed {seed}: KS {a:.2} GU {b:.2}");
        ks += a / seeds as f64;
        gu += b / seeds as f64;
    }
    assert!(ks >= gu + 1.0, "KS {ks} GU {gu}");
}

/// Piecewise-constant camera rates: `(t0, t1, [wx, wy, wz])` intervals, zero elsewhere.
fn piecewise_gyro(parts: &[(f64, f64, [f64; 3])], t_end: f64) -> Vec<GyroSample> {
    (0..(t_end * 1000.0) as usize)
        .map(|i| {
            let t = i as f64 / 1000.0;
            let w = parts
                .iter()
                .find(|p| t >= p.0 && t < p.1)
                .map_or([0.0; 3], |p| p.2);
            GyroSample::new(t, w[0], w[1], w[2])
        })
        .collect()
}

/// Check 6: neighbour A is sharp on the left and blurry on the right (pitch and roll
/// cancel at x = -W/4), neighbour C the reverse; the weights follow the sharper neighbour.
/// A neighbour replaced by noise with a huge kernel gets a weight below 0.1 everywhere.
#[test]
fn weights_steer_to_the_sharper_neighbour_per_region() {
    let (h, w) = (180, 240);
    let k = Intrinsics::centred(600.0, w, h);
    let sharp = synth::scene(h, w, 51).unwrap();
    let times = [0.1, 0.1 + 1.0 / 30.0, 0.1 + 2.0 / 30.0];
    let (t_e, t_d) = (0.03, 0.0);
    let pitch = 0.3;
    let roll = pitch * 600.0 / (w as f64 / 4.0);
    let window = |i: usize| (times[i] - 0.002, times[i] + t_e + 0.002);
    let make = |roll_a: f64| {
        piecewise_gyro(
            &[
                (window(0).0, window(0).1, [pitch, 0.0, roll_a]),
                (window(1).0, window(1).1, [0.0, 0.25, 0.0]),
                (window(2).0, window(2).1, [pitch, 0.0, -roll_a]),
            ],
            0.4,
        )
    };
    // Pick the roll sign that makes frame 0 sharp on the left.
    let probe = |g: &[GyroSample]| {
        let tr = GyroTrack::from_camera_rates(g).unwrap();
        let tm = Timing {
            t_frame: times[0],
            t_exposure: t_e,
            t_readout: 0.0,
            t_delay: t_d,
            height: h,
        };
        blurriness(
            &render_kernel(
                &tr,
                &tm,
                &k,
                (k.cx - w as f64 / 4.0, k.cy),
                &KernelParams::default(),
            )
            .unwrap(),
        )
    };
    let gyro = if probe(&make(roll)) < probe(&make(-roll)) {
        make(roll)
    } else {
        make(-roll)
    };
    let track = GyroTrack::from_camera_rates(&gyro).unwrap();
    let world = times[1] + t_d;
    let frames: Vec<FrameInput> = (0..3)
        .map(|i| {
            let tm = Timing {
                t_frame: times[i],
                t_exposure: t_e,
                t_readout: 0.0,
                t_delay: t_d,
                height: h,
            };
            FrameInput {
                image: synth::render_blurred(
                    &sharp,
                    &track,
                    &tm,
                    &k,
                    world,
                    &BlurRenderParams::default(),
                    i as u64,
                )
                .unwrap(),
                t: times[i],
            }
        })
        .collect();
    let opts = MultiframeParams::default().t_exposure(t_e).t_delay(t_d);
    let out = deblur_multiframe(&frames, 1, &track, &k, &opts, &NoProgress).unwrap();
    assert_eq!(out.used_frames, vec![0, 1, 2], "{:?}", out.warnings);
    let (rows, cols) = (out.kernels.rows, out.kernels.cols);
    let (mut right, mut total) = (0, 0);
    for r in 0..rows {
        for c in 0..cols {
            let wt = &out.weights[(r * cols + c) * 3..][..3];
            assert_eq!(wt[1], 0.0);
            if wt[0] + wt[2] == 0.0 {
                continue;
            }
            assert!((wt[0] + wt[2] - 1.0).abs() < 1e-5);
            total += 1;
            let left = (c as f64 + 0.5) * 30.0 < w as f64 / 2.0;
            if (left && wt[0] > wt[2]) || (!left && wt[2] > wt[0]) {
                right += 1;
            }
        }
    }
    eprintln!("sharper neighbour preferred in {right} of {total} regions");
    assert!(
        total >= rows * cols / 2 && right as f64 >= 0.9 * total as f64,
        "{right}/{total}"
    );

    // Frame 2 replaced by noise with a huge blur.
    let mut noisy = frames.clone();
    noisy[2].image = Image::new(
        h,
        w,
        1,
        wscg_math::rng::uniform_vec(9, h * w, 0.0, 1.0)
            .unwrap()
            .iter()
            .map(|&v| v as f32)
            .collect(),
    )
    .unwrap();
    let big = piecewise_gyro(
        &[
            (window(0).0, window(0).1, [pitch, 0.0, roll]),
            (window(1).0, window(1).1, [0.0, 0.25, 0.0]),
            (window(2).0, window(2).1, [0.0, 2.5, 0.0]),
        ],
        0.4,
    );
    let out = deblur_multiframe(
        &noisy,
        1,
        &GyroTrack::from_camera_rates(&big).unwrap(),
        &k,
        &opts,
        &NoProgress,
    )
    .unwrap();
    let worst = (0..rows * cols)
        .map(|r| out.weights[r * 3 + 2])
        .fold(0f32, f32::max);
    eprintln!(
        "noise frame: largest weight {worst}, warnings {:?}",
        out.warnings
    );
    assert!(worst < 0.1, "{worst}");
}

/// Bad input of the pipeline is reported; when every neighbour fails alignment the result is
/// the single-frame one.
#[test]
fn multiframe_bad_input_and_all_neighbours_dropped() {
    let (h, w) = (90, 120);
    let sharp = synth::scene(h, w, 61).unwrap();
    let burst = Burst {
        frames: 3,
        ..Default::default()
    };
    let sb = synth::make_burst(
        &sharp,
        &burst,
        &ShakeParams::default(),
        1,
        0.002,
        &BlurRenderParams::default(),
        7,
    )
    .unwrap();
    let track = GyroTrack::from_camera_rates(&sb.measured).unwrap();
    let k = Intrinsics::centred(600.0, w, h);
    let opts = MultiframeParams::default().t_delay(burst.t_delay);
    let err = |frames: &[FrameInput], main: usize| {
        deblur_multiframe(frames, main, &track, &k, &opts, &NoProgress)
            .unwrap_err()
            .to_string()
    };
    assert!(err(&[], 0).contains("empty"));
    assert!(err(&sb.frames, 3).contains("out of range"));
    let mut odd = sb.frames.clone();
    odd[2].image = Image::filled(h, w + 1, 1, 0.5).unwrap();
    assert!(err(&odd, 1).contains("differ in size"));
    let mut nan = sb.frames.clone();
    nan[0].image.data_mut()[5] = f32::NAN;
    assert!(err(&nan, 1).contains("non-finite"));
    let late = opts.t_delay(5.0);
    let e = deblur_multiframe(&sb.frames, 1, &track, &k, &late, &NoProgress)
        .unwrap_err()
        .to_string();
    assert!(e.contains("gap"), "{e}");
    // Both neighbours replaced by noise: dropped with warnings, KM = KS.
    let mut noise = sb.frames.clone();
    for (i, f) in [0usize, 2].iter().enumerate() {
        noise[*f].image = Image::new(
            h,
            w,
            1,
            wscg_math::rng::uniform_vec(i as u64, h * w, 0.0, 1.0)
                .unwrap()
                .iter()
                .map(|&v| v as f32)
                .collect(),
        )
        .unwrap();
    }
    let out = deblur_multiframe(&noise, 1, &track, &k, &opts, &NoProgress).unwrap();
    assert_eq!(out.used_frames, vec![1]);
    assert_eq!(out.warnings.len(), 2, "{:?}", out.warnings);
    assert_eq!(out.image.data(), out.single.data());
    assert!(out.weights.iter().all(|&v| v == 0.0));
}
