//! Paper 08 on occlusion-heavy scenes: the similarity weights of eqs. (2)-(4) against their
//! ablation with uniform weights, and the measurement behind BENCHMARKS.md.

mod occluders;

use occluders::{lattice_room, slatted_room};
use wscg_math::image::Image;
use wscg_math::progress::NoProgress;
use wscg_raytrace::manylight::scenes::cornell_box;
use wscg_raytrace::manylight::*;

fn rmse(a: &Image<f32>, b: &Image<f32>) -> f64 {
    wscg_math::metrics::rmse(a.data(), b.data()).unwrap()
}

/// RMSE against the all-VPL reference of each method of `variants` (name, method, params)
/// over `runs` seeds starting at `seed0`, on shared VPLs and shading points.
fn sweep(
    scene: &Scene,
    cam: &Camera,
    base: &ManyLightParams,
    variants: &[(&str, Method, ManyLightParams)],
    seed0: u64,
    runs: u64,
) -> Vec<Vec<f64>> {
    let vpls = generate_vpls(scene, &base.vpl).unwrap();
    let g = trace_primary(scene, cam).unwrap();
    let reference = run_with(scene, &g, &vpls, Method::Reference, base, &NoProgress, 0.0)
        .unwrap()
        .image;
    eprintln!("{} VPLs, {} valid pixels", vpls.len(), g.valid());
    variants
        .iter()
        .map(|(name, m, p)| {
            let start = std::time::Instant::now();
            let e: Vec<f64> = (seed0..seed0 + runs)
                .map(|seed| {
                    let mut st = *p;
                    st.ic.seed = seed;
                    let o = run_with(scene, &g, &vpls, *m, &st, &NoProgress, 0.0).unwrap();
                    rmse(&o.image, &reference)
                })
                .collect();
            let (mean, med, max) = stats(&e);
            let per = start.elapsed().as_secs_f64() / runs as f64;
            eprintln!(
                "{name:<24} mean {mean:.5} median {med:.5} max {max:.5} ({per:.3} s a render)"
            );
            e
        })
        .collect()
}

fn stats(e: &[f64]) -> (f64, f64, f64) {
    let mut s = e.to_vec();
    s.sort_by(f64::total_cmp);
    let mean = s.iter().sum::<f64>() / s.len() as f64;
    (mean, s[s.len() / 2], s[s.len() - 1])
}

/// The weights are compared at the pixel centres (the estimators' own variance, against the
/// all-VPL sum there).
fn base(n_paths: usize, n_cache: usize, vpl_seed: u64) -> ManyLightParams {
    ManyLightParams::default()
        .vpl(
            VplParams::default()
                .n_paths(n_paths)
                .max_bounces(2)
                .seed(vpl_seed),
        )
        .ic(ImportanceCachingParams::default()
            .n_cache(n_cache)
            .filter(PixelFilter::Center))
}

/// The default weights (eqs. 2-4 blended with the uniform ones, defensive share 0.5) against
/// the ablation with uniform weights over 32 renders, both with the default near-VPL share:
/// not worse in mean and median RMSE.
fn assert_weights_not_worse(scene: &Scene, cam: &Camera, vpl_seed: u64, seed0: u64) {
    let n_cache = cam.width * cam.height / 100;
    let b = base(1000, n_cache, vpl_seed);
    assert_eq!(b.weights, Interp::paper().with_defensive(0.5));
    let variants = [
        ("adaptive (default)", Method::Adaptive, b),
        ("adaptive_uniform", Method::AdaptiveUniform, b),
    ];
    let e = sweep(scene, cam, &b, &variants, seed0, 32);
    let (a, u) = (stats(&e[0]), stats(&e[1]));
    assert!(a.0 <= u.0, "mean RMSE {} > {}", a.0, u.0);
    assert!(a.1 <= u.1, "median RMSE {} > {}", a.1, u.1);
}

/// The lattice room (not the scene the defensive share was chosen on; the near-VPL share was
/// chosen on its VPL seeds 1, 5 and 21 and the slats' seed 1, not on this VPL seed 11). Before the near-VPL share (VPL seed 11, seeds 0-31): default mean / median / max RMSE
/// 0.06772 / 0.06404 / 0.1314 against the ablation's 0.06487 / 0.06200 / 0.0846, 4 % worse,
/// from single bright pixels next to VPLs that no record's distribution favours.
#[test]
fn weights_not_worse_than_uniform_lattice() {
    let (scene, cam) = lattice_room(128, 96);
    assert_weights_not_worse(&scene, &cam, 11, 0);
}

/// The slatted room with other VPLs and other render seeds than those the shares were chosen
/// on.
#[test]
fn weights_not_worse_than_uniform_slats_second_seed() {
    let (scene, cam) = slatted_room(128, 96);
    assert_weights_not_worse(&scene, &cam, 23, 500);
}

/// The measurement of BENCHMARKS.md: `WSCG_SCENE` (`slats` or `lattice`), `WSCG_SIZE`
/// (`192x144`), `WSCG_RUNS` (48), `WSCG_SEED0` (0).
#[test]
#[ignore = "measurement; run with --ignored --nocapture"]
fn measure_weights_on_occluders() {
    let env = |k: &str, d: &str| std::env::var(k).unwrap_or_else(|_| d.to_string());
    let size = env("WSCG_SIZE", "192x144");
    let (w, h) = size.split_once('x').unwrap();
    let (w, h): (usize, usize) = (w.parse().unwrap(), h.parse().unwrap());
    let runs: u64 = env("WSCG_RUNS", "48").parse().unwrap();
    let seed0: u64 = env("WSCG_SEED0", "0").parse().unwrap();
    let (scene, cam) = match env("WSCG_SCENE", "slats").as_str() {
        "slats" => slatted_room(w, h),
        _ => lattice_room(w, h),
    };
    let b = base(1000, (w * h / 100).max(1), 1 + seed0);
    let mut variants = vec![
        ("adaptive_uniform", Method::AdaptiveUniform, b),
        (
            "adaptive paper",
            Method::Adaptive,
            b.weights(Interp::paper()),
        ),
    ];
    let cs = env("WSCG_DEFENSIVE", "0.5");
    let names: Vec<String> = cs.split(',').map(|c| format!("adaptive c={c}")).collect();
    for (c, name) in cs.split(',').zip(&names) {
        let w = Interp::paper().with_defensive(c.parse().unwrap());
        variants.push((name, Method::Adaptive, b.weights(w)));
    }
    let near = env("WSCG_NEAR", "");
    let near: Vec<(f64, usize)> = near
        .split(',')
        .filter(|t| !t.is_empty())
        .map(|t| {
            let (a, k) = t.split_once(':').unwrap_or((t, "16"));
            (a.parse().unwrap(), k.parse().unwrap())
        })
        .collect();
    let near_names: Vec<(String, String)> = near
        .iter()
        .map(|(a, k)| {
            (
                format!("uniform near {a}:{k}"),
                format!("adaptive near {a}:{k}"),
            )
        })
        .collect();
    for (&(a, k), (nu, na)) in near.iter().zip(&near_names) {
        let mut ic = b.ic;
        ic.near_share = a;
        ic.near_vpls = k;
        variants.push((nu, Method::AdaptiveUniform, b.ic(ic)));
        variants.push((na, Method::Adaptive, b.ic(ic)));
    }
    sweep(&scene, &cam, &b, &variants, seed0, runs);
}

#[test]
#[ignore = "writes the scenes' reference images to /tmp"]
fn write_occluder_references() {
    for (name, (scene, cam)) in [
        ("slats", slatted_room(192, 144)),
        ("lattice", lattice_room(192, 144)),
    ] {
        let b = base(1000, 276, 1);
        let o = run(&scene, &cam, Method::Reference, &b, &NoProgress).unwrap();
        eprintln!("{name}: {} VPLs", o.n_vpls);
        let d = to_display(&o.image, 1.0);
        let (h, w, _) = d.shape();
        let mut ppm = format!("P6 {w} {h} 255\n").into_bytes();
        ppm.extend(d.data().iter().map(|v| (v * 255.0).round() as u8));
        std::fs::write(format!("/tmp/ml_{name}.ppm"), ppm).unwrap();
    }
}

/// Share of the 16 x 16 blocks (whole blocks only) whose mean luminance in `img` lies within
/// `tol` (relative) of that in `reference`.
fn blocks_within(img: &Image<f32>, reference: &Image<f32>, tol: f64) -> (f64, f64) {
    let (h, w, _) = reference.shape();
    let lum = |im: &Image<f32>, y: usize, x: usize| -> f64 {
        let d = &im.data()[3 * (y * w + x)..3 * (y * w + x) + 3];
        0.2126 * d[0] as f64 + 0.7152 * d[1] as f64 + 0.0722 * d[2] as f64
    };
    let (mut ok, mut n, mut worst) = (0, 0, 0.0f64);
    for by in 0..h / 16 {
        for bx in 0..w / 16 {
            let (mut a, mut b) = (0.0, 0.0);
            for y in 16 * by..16 * (by + 1) {
                for x in 16 * bx..16 * (bx + 1) {
                    a += lum(img, y, x);
                    b += lum(reference, y, x);
                }
            }
            let rel = if b > 0.0 {
                (a / b - 1.0).abs()
            } else {
                a.abs()
            };
            worst = worst.max(rel);
            ok += usize::from(rel <= tol);
            n += 1;
        }
    }
    (ok as f64 / n as f64, worst)
}

/// Pixel filtering on the Cornell box (its small emitter and the blocks' silhouettes): the
/// box- and tent-filtered renders of the paper's method lie within 3 % of the brute-force
/// filtered all-VPL sum (64 sub-pixel positions per pixel) on at least 90 % of the
/// 16 x 16 blocks (measured: 97.9 % for both, worst block 4.3 % box, 5.5 % tent); one ray
/// through each pixel centre does not.
#[test]
fn pixel_filtered_renders_match_the_supersampled_reference() {
    let (scene, cam) = cornell_box(1, 128, 96).unwrap();
    // 128 VPL samples over 8 sub-pixel positions, so that the blocks' means are not noise.
    let s = base(150, 123, 5).ic(ImportanceCachingParams::default()
        .n_cache(123)
        .spp(128)
        .pixel_samples(8));
    assert_eq!(s.ic.filter, PixelFilter::Box);
    let vpls = generate_vpls(&scene, &s.vpl).unwrap();
    let g = trace_primary(&scene, &cam).unwrap();
    for filter in [PixelFilter::Box, PixelFilter::Tent] {
        let p = s.ic.filter(filter).pixel_samples(64).seed(99);
        let reference = render_reference_filtered(&scene, &g, &vpls, &p, &NoProgress).unwrap();
        let mut st = s;
        st.ic.filter = filter;
        let img = run_with(&scene, &g, &vpls, Method::Adaptive, &st, &NoProgress, 0.0)
            .unwrap()
            .image;
        let (share, worst) = blocks_within(&img, &reference, 0.03);
        let centre = {
            let mut sc = st;
            sc.ic.filter = PixelFilter::Center;
            run_with(&scene, &g, &vpls, Method::Adaptive, &sc, &NoProgress, 0.0)
                .unwrap()
                .image
        };
        let (share_c, worst_c) = blocks_within(&centre, &reference, 0.03);
        eprintln!(
            "{}: {:.1} % of blocks within 3 % (worst {:.2} %); pixel centres {:.1} % (worst {:.2} %)",
            filter.name(),
            100.0 * share,
            100.0 * worst,
            100.0 * share_c,
            100.0 * worst_c
        );
        assert!(share >= 0.9, "{}: {share}", filter.name());
        // Measured: 79 % of the blocks (worst 26-33 %) with one ray through each centre.
        assert!(share_c < 0.9, "{}: centres {share_c}", filter.name());
    }
}
