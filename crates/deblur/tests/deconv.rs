//! The Krishnan-Fergus solver (check 3), the baselines and the tiling (check 7).

use wscg_deblur::tiling::{convolve, convolve_piecewise};
use wscg_deblur::wstep::{w_energy, w_exact, WStepTable};
use wscg_deblur::{
    deblur_piecewise, deconv_hl, richardson_lucy, synth, wiener, HyperLaplacianParams, Kernel,
    KernelGrid, Method, Tiling,
};
use wscg_math::metrics::psnr;
use wscg_math::{rng, Image};

#[test]
fn w_step_matches_brute_force_minimisation() {
    let grid: Vec<f64> = (0..=10_000)
        .map(|i| -2.0 + 4.0 * i as f64 / 10_000.0)
        .collect();
    for alpha in [0.5, 2.0 / 3.0, 1.0] {
        for beta in [1.0, 2.0, 2.0 * 2f64.sqrt(), 8.0, 22.6, 64.0, 181.0, 256.0] {
            for i in 0..=200 {
                let v = -2.0 + 4.0 * i as f64 / 200.0;
                let w = w_exact(v, alpha, beta);
                let e = w_energy(w, v, alpha, beta);
                let brute = grid
                    .iter()
                    .map(|&g| w_energy(g, v, alpha, beta))
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    e <= brute + 1e-6,
                    "alpha {alpha} beta {beta} v {v}: {e} > {brute}"
                );
            }
        }
    }
}

#[test]
fn w_step_for_other_exponents_is_a_minimum() {
    for alpha in [0.3, 0.8, 1.3, 1.8, 2.0] {
        for beta in [0.7, 5.0, 100.0] {
            for i in 0..=100 {
                let v = -1.5 + 3.0 * i as f64 / 100.0;
                let w = w_exact(v, alpha, beta);
                let e = w_energy(w, v, alpha, beta);
                for d in [-1e-3, 1e-3, -0.1, 0.1] {
                    assert!(
                        e <= w_energy(w + d, v, alpha, beta) + 1e-12,
                        "alpha {alpha} beta {beta} v {v}"
                    );
                }
                assert!(e <= w_energy(0.0, v, alpha, beta) + 1e-12);
            }
        }
    }
}

#[test]
fn lookup_table_agrees_with_the_exact_solver() {
    for alpha in [0.5f64, 2.0 / 3.0, 1.0] {
        for &beta in &HyperLaplacianParams::default().betas() {
            let lut = WStepTable::new(alpha, beta as f64);
            for i in 0..=20_000 {
                let v = -3.0 + 6.0 * i as f64 / 20_000.0;
                let exact = w_exact(v as f32 as f64, alpha, beta as f64);
                let approx = lut.eval(v as f32) as f64;
                assert!(
                    (exact - approx).abs() < 1e-4,
                    "alpha {alpha} beta {beta} v {v}: {exact} vs {approx}"
                );
            }
        }
    }
}

fn noisy(img: &Image<f32>, sigma: f32, seed: u64) -> Image<f32> {
    let n = rng::normal_vec(seed, img.data().len(), 0.0, sigma as f64).unwrap();
    Image::new(
        img.height(),
        img.width(),
        1,
        img.data()
            .iter()
            .zip(&n)
            .map(|(v, e)| v + *e as f32)
            .collect(),
    )
    .unwrap()
}

fn score(a: &Image<f32>, truth: &Image<f32>, border: usize) -> f64 {
    let (h, w) = (a.height(), a.width());
    let crop = |img: &Image<f32>| -> Vec<f32> {
        (border..h - border)
            .flat_map(|y| (border..w - border).map(move |x| (y, x)))
            .map(|(y, x)| img.at(y, x, 0).clamp(0.0, 1.0))
            .collect()
    };
    psnr(&crop(a), &crop(truth), 1.0).unwrap()
}

/// Check 3 on a generated scene (the Python tests run it on scikit-image's `camera`):
/// the best KS over lambda in {500, 2000, 8000} against the best Wiener over five NSRs.
#[test]
fn krishnan_fergus_beats_blur_and_the_best_wiener_on_a_diagonal_line_blur() {
    let sharp = synth::scene(192, 192, 5).unwrap();
    let k = Kernel::line(15.0, std::f64::consts::FRAC_PI_4).unwrap();
    let blurred = noisy(&convolve(&sharp, &k).unwrap(), 0.005, 9);
    let b = score(&blurred, &sharp, 16);
    let ks = [500.0, 2000.0, 8000.0]
        .iter()
        .map(|&lambda| {
            score(
                &deconv_hl(
                    &blurred,
                    &k,
                    &HyperLaplacianParams::default().lambda(Some(lambda)),
                )
                .unwrap(),
                &sharp,
                16,
            )
        })
        .fold(f64::MIN, f64::max);
    let best_w = [0.001, 0.003, 0.01, 0.03, 0.1]
        .iter()
        .map(|&nsr| score(&wiener(&blurred, &k, nsr).unwrap(), &sharp, 16))
        .fold(f64::MIN, f64::max);
    let rl = score(&richardson_lucy(&blurred, &k, 30).unwrap(), &sharp, 16);
    eprintln!("B {b:.2} KS {ks:.2} W* {best_w:.2} RL {rl:.2}");
    assert!(ks >= b + 4.0, "KS {ks} vs B {b}");
    assert!(ks >= best_w + 1.0, "KS {ks} vs W {best_w}");
    assert!(rl > b, "RL {rl} vs B {b}");
}

/// Check 7: region-wise deblurring of an unblurred image returns it, and the regions
/// leave no seam: across region borders the piecewise result steps like the whole-frame
/// solve of the same problem.
#[test]
fn deblurring_an_unblurred_image_has_no_seams() {
    let sharp = synth::scene(150, 210, 2).unwrap();
    let grid = KernelGrid::uniform(Kernel::delta(), 210, 150, 30).unwrap();
    let tiling = Tiling::default();
    let p = HyperLaplacianParams::default();
    for (m, whole) in [
        (
            Method::HyperLaplacian(p),
            deconv_hl(&sharp, &Kernel::delta(), &p).unwrap(),
        ),
        (
            Method::Wiener { nsr: 1e-4 },
            wiener(&sharp, &Kernel::delta(), 1e-4).unwrap(),
        ),
        (
            Method::RichardsonLucy { iters: 5 },
            richardson_lucy(&sharp, &Kernel::delta(), 5).unwrap(),
        ),
    ] {
        let out = deblur_piecewise(&sharp, &grid, &m, &tiling).unwrap();
        let p = score(&out, &sharp, 0);
        let mut worst = 0f32;
        for y in 0..150 {
            for x in (30..210).step_by(30) {
                let d_out = out.at(y, x, 0) - out.at(y, x - 1, 0);
                let d_ref = whole.at(y, x, 0) - whole.at(y, x - 1, 0);
                worst = worst.max((d_out - d_ref).abs() * 255.0);
            }
        }
        for y in (30..150).step_by(30) {
            for x in 0..210 {
                let d_out = out.at(y, x, 0) - out.at(y - 1, x, 0);
                let d_ref = whole.at(y, x, 0) - whole.at(y - 1, x, 0);
                worst = worst.max((d_out - d_ref).abs() * 255.0);
            }
        }
        eprintln!("{m:?}: {p:.2} dB, worst border step {worst:.3}");
        assert!(p >= 45.0, "{m:?}: {p}");
        assert!(worst <= 1.0, "{m:?}: {worst}");
    }
}

#[test]
fn piecewise_convolution_with_one_kernel_is_the_global_convolution() {
    let img = synth::scene(120, 150, 4).unwrap();
    let k = Kernel::line(9.0, 0.7).unwrap();
    let grid = KernelGrid::uniform(k.clone(), 150, 120, 30).unwrap();
    let a = convolve_piecewise(&img, &grid, &Tiling::default()).unwrap();
    let b = convolve(&img, &k).unwrap();
    let max = a
        .data()
        .iter()
        .zip(b.data())
        .map(|(x, y)| (x - y).abs())
        .fold(0f32, f32::max);
    assert!(max < 1e-5, "{max}");
    // And it is a true convolution in the interior: brute force at a few pixels.
    for (y, x) in [(40usize, 50usize), (60, 75), (80, 100)] {
        let mut s = 0.0;
        for i in 0..k.size {
            for j in 0..k.size {
                let (dy, dx) = (
                    i as isize - k.origin.0 as isize,
                    j as isize - k.origin.1 as isize,
                );
                s += k.data[i * k.size + j]
                    * img.at((y as isize - dy) as usize, (x as isize - dx) as usize, 0);
            }
        }
        assert!((s - b.at(y, x, 0)).abs() < 1e-5);
    }
}

#[test]
fn solver_rejects_bad_parameters() {
    let img = synth::scene(40, 40, 1).unwrap();
    let k = Kernel::delta();
    for p in [
        HyperLaplacianParams::default().alpha(0.0),
        HyperLaplacianParams::default().alpha(2.5),
        HyperLaplacianParams::default().lambda(Some(-1.0)),
    ] {
        assert!(deconv_hl(&img, &k, &p).is_err());
    }
    let mut bad = img.clone();
    bad.data_mut()[7] = f32::NAN;
    assert!(deconv_hl(&bad, &k, &HyperLaplacianParams::default())
        .unwrap_err()
        .to_string()
        .contains("non-finite"));
    let rgb = Image::filled(10, 10, 3, 0.5f32).unwrap();
    assert!(deconv_hl(&rgb, &k, &HyperLaplacianParams::default())
        .unwrap_err()
        .to_string()
        .contains("single-channel"));
    assert!(wiener(&img, &k, 0.0).is_err());
    assert!(Method::by_name("magic")
        .unwrap_err()
        .to_string()
        .contains("valid methods"));
    assert!(Kernel::centred(4, vec![0.25; 16]).is_err());
}

/// Seams under real blur: a uniformly blurred image deblurred region by region has, across
/// region borders, the same gradient error as inside the regions (a seam would raise it).
#[test]
fn uniform_blur_deblurred_by_regions_has_no_seams() {
    let sharp = synth::scene(150, 210, 8).unwrap();
    let k = Kernel::line(9.0, 0.4).unwrap();
    let blurred = noisy(&convolve(&sharp, &k).unwrap(), 0.002, 3);
    let grid = KernelGrid::uniform(k.clone(), 210, 150, 30).unwrap();
    // The paper's fixed weight: this compares the tiling with the whole-image solve at equal
    // settings (the noise-aware weight, about 75 000 here, is larger and the regions' tapered
    // windows then lose more against the whole image).
    let p = HyperLaplacianParams::paper();
    let out = deblur_piecewise(
        &blurred,
        &grid,
        &Method::HyperLaplacian(p),
        &Tiling::default(),
    )
    .unwrap();
    let (mut border, mut nb, mut inside, mut ni) = (0.0, 0, 0.0, 0);
    for y in 16..134 {
        for x in 17..194 {
            let d = (((out.at(y, x, 0) - out.at(y, x - 1, 0))
                - (sharp.at(y, x, 0) - sharp.at(y, x - 1, 0)))
            .abs()
                * 255.0) as f64;
            if x % 30 == 0 {
                border += d;
                nb += 1;
            } else {
                inside += d;
                ni += 1;
            }
        }
    }
    let (border, inside) = (border / nb as f64, inside / ni as f64);
    let whole = deconv_hl(&blurred, &k, &p).unwrap();
    eprintln!("gradient error: border {border:.3}, inside {inside:.3}; piecewise {:.2} dB, whole {:.2} dB", score(&out, &sharp, 16), score(&whole, &sharp, 16));
    assert!(border <= 1.2 * inside, "{border} vs {inside}");
    assert!(score(&out, &sharp, 16) > score(&whole, &sharp, 16) - 0.5);
}

/// Frames whose size is not a multiple of the region size (last regions of 1 px, frames
/// smaller than one region) are deblurred without seams or gaps.
#[test]
fn frame_sizes_that_are_not_multiples_of_the_region_work() {
    for (h, w) in [(151usize, 211usize), (31, 61), (29, 17), (1, 40)] {
        let sharp = synth::scene(h, w, 3).unwrap();
        let grid = KernelGrid::uniform(Kernel::delta(), w, h, 30).unwrap();
        let out = deblur_piecewise(
            &sharp,
            &grid,
            &Method::Wiener { nsr: 1e-6 },
            &Tiling::default(),
        )
        .unwrap();
        let err = out
            .data()
            .iter()
            .zip(sharp.data())
            .map(|(a, b)| (a - b).abs())
            .fold(0f32, f32::max);
        assert!(err < 1e-4, "{h}x{w}: {err}");
    }
}
