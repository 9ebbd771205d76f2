//! Matching checks of paper 13 (acceptance check 3 and the unit behaviour behind
//! checks 4-6): epipolar PatchMatch recovers known shifts, stays on the scanline and in its
//! range, is deterministic, mirror-symmetric, and more coherent with the coherence term;
//! BDS voting reproduces a consistent shift exactly and leaves no holes; the baselines.

use wscg_hdr::metrics::{bad_rate, incoherence};
use wscg_hdr::synth::{albedo, layered_scene, SceneParams, SynthScene};
use wscg_hdr::{
    patchmatch, patchmatch_2d, to_radiance, vote_bds, warp_direct, zncc_stereo, PatchMatchParams,
    StereoParams,
};
use wscg_math::Image;

/// A 3-channel fractal texture sampled at columns shifted by `shift`.
fn texture(h: usize, w: usize, shift: f64) -> Image<f32> {
    let mut v = Vec::with_capacity(h * w * 3);
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                v.push(albedo(5, y as f64 + 0.5, x as f64 + 0.5 + shift, c) as f32);
            }
        }
    }
    Image::new(h, w, 3, v).unwrap()
}

/// A generated two-view scene of `height x width` exposed for `times`, and the radiance
/// images of its two views.
fn radiance_pair(
    height: usize,
    width: usize,
    times: [f64; 2],
    seed: u64,
) -> (Image<f32>, Image<f32>, SynthScene) {
    let cfg = SceneParams::default()
        .height(height)
        .width(width)
        .times(times.to_vec());
    let sc = layered_scene(&cfg, seed).unwrap();
    let a = to_radiance(&sc.views[0], &sc.crf, sc.times[0]).unwrap();
    let b = to_radiance(&sc.views[1], &sc.crf, sc.times[1]).unwrap();
    (a, b, sc)
}

fn params(d_min: i32, d_max: i32) -> PatchMatchParams {
    PatchMatchParams::default().d_min(d_min).d_max(d_max)
}

#[test]
fn epipolar_patchmatch_recovers_a_known_shift() {
    // B(x) = A(x + 9): the point at column x of A is at x - 9 in B.
    let (a, b) = (texture(48, 96, 0.0), texture(48, 96, 9.0));
    let f = patchmatch(&a, &b, &params(-20, 20)).unwrap();
    let (mut ok, mut n) = (0, 0);
    for y in 0..48 {
        for x in 12..96 {
            n += 1;
            ok += usize::from(f.at(y, x) == [-9, 0]);
        }
    }
    assert!(ok as f64 >= 0.99 * n as f64, "{ok} of {n} exact");
    // Matches are exact: the cost of an exact match is zero.
    assert_eq!(f.cost[20 * 96 + 50], 0.0);
    // Original PatchMatch finds it too, given iterations (2-D, so the search is harder).
    let g = patchmatch_2d(&a, &b, 7, 8, 3).unwrap();
    let good = (0..48 * 96)
        .filter(|&i| i % 96 >= 12 && g.off[i] == [-9, 0])
        .count();
    assert!(good as f64 >= 0.9 * n as f64, "PM-2D: {good} of {n}");
}

/// Without the coherence term a pixel's cost is the mean squared difference of its patch and
/// the patch its offset points to (eq. 3, over the offsets inside both images). Each pixel
/// keeps the distance of its current offset between visits, so a distance kept for the wrong
/// offset, or left from an early exit, shows here.
#[test]
fn costs_are_the_patch_distances_of_the_offsets() {
    // A sub-pixel shift: no exact matches, every cost positive.
    let (a, b) = (texture(40, 80, 0.0), texture(40, 80, 6.4));
    let p = params(-16, 16).coherence(false).iters(3);
    let f = patchmatch(&a, &b, &p).unwrap();
    let (h, w, half) = (40i32, 80i32, 3i32);
    let mut positive = 0;
    let at = |img: &Image<f32>, y: i32, x: i32, c: usize| {
        img.data()[((y * w + x) * 3) as usize + c] as f64
    };
    for y in 0..h {
        for x in 0..w {
            let [dx, dy] = f.at(y as usize, x as usize);
            let (mut s, mut n) = (0.0, 0.0);
            for oy in -half..=half {
                for ox in -half..=half {
                    let (ya, xa, yb, xb) = (y + oy, x + ox, y + oy + dy, x + ox + dx);
                    if ya < 0
                        || xa < 0
                        || ya >= h
                        || xa >= w
                        || yb < 0
                        || xb < 0
                        || yb >= h
                        || xb >= w
                    {
                        continue;
                    }
                    for c in 0..3 {
                        s += (at(&a, ya, xa, c) - at(&b, yb, xb, c)).powi(2);
                        n += 1.0;
                    }
                }
            }
            let cost = f.cost[(y * w + x) as usize] as f64;
            positive += usize::from(cost > 0.0);
            assert!(
                (cost - s / n).abs() <= 1e-5 * (s / n),
                "({y}, {x}): {cost} vs {}",
                s / n
            );
        }
    }
    assert!(
        positive >= (h * w) as usize * 9 / 10,
        "{positive} positive costs"
    );
}

#[test]
fn fields_stay_on_the_scanline_in_range_and_are_deterministic() {
    let (a, b, _) = radiance_pair(64, 112, [0.02, 0.08], 3);
    for (lo, hi) in [(-40, 0), (-25, 30), (5, 12)] {
        let p = params(lo, hi).seed(9);
        let f = patchmatch(&a, &b, &p).unwrap();
        for y in 0..64 {
            for x in 0..112 {
                let [dx, dy] = f.at(y, x);
                assert_eq!(dy, 0);
                let xb = x as i32 + dx;
                if (lo.max(-(x as i32))..=hi.min(111 - x as i32)).contains(&dx) {
                    assert!((0..112).contains(&xb));
                } else {
                    // Only where no disparity of the range lands inside B.
                    assert!(lo > 111 - x as i32 || hi < -(x as i32), "{x} {dx}");
                    assert!((lo..=hi).contains(&dx));
                }
            }
        }
        assert_eq!(f, patchmatch(&a, &b, &p).unwrap(), "same seed, same field");
    }
    // Another seed gives another (random) initialisation.
    let f1 = patchmatch(&a, &b, &params(-40, 40).iters(0).seed(1)).unwrap();
    let f2 = patchmatch(&a, &b, &params(-40, 40).iters(0).seed(2)).unwrap();
    assert_ne!(f1.off, f2.off);
}

/// A field's rows run on the pool's threads as a pipeline that must show every pixel the
/// neighbours of the sequential scan: the fields of 2, 3 and 5 threads (more threads than
/// cores too, so rows wait on rows that are descheduled) equal the one-thread field, which
/// is that scan, bit for bit; for the paper's matcher on the scanline and with a vertical
/// tolerance (2-D coherence), and for 2-D PatchMatch.
#[test]
fn fields_do_not_depend_on_the_thread_count() {
    let (a, b, _) = radiance_pair(72, 136, [0.02, 0.08], 4);
    let configs = [
        params(-50, 10).iters(5).seed(3),
        params(-30, 30).iters(4).v_tol(2).seed(4),
        PatchMatchParams::barnes(5, 3, 5),
    ];
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    for p in &configs {
        let one = pool(1).install(|| patchmatch(&a, &b, p).unwrap());
        for n in [2, 3, 5] {
            for _ in 0..3 {
                let f = pool(n).install(|| patchmatch(&a, &b, p).unwrap());
                assert!(f == one, "{n} threads: another field ({p:?})");
            }
        }
    }
}

#[test]
fn mirroring_both_views_and_the_range_changes_little() {
    let (a, b, sc) = radiance_pair(80, 144, [0.03, 0.12], 4);
    let truth: Vec<f32> = sc.disparity[0].data().iter().map(|d| -d).collect();
    let mirror = |im: &Image<f32>| {
        let (h, w, c) = im.shape();
        let mut v = Vec::with_capacity(h * w * c);
        for y in 0..h {
            for x in (0..w).rev() {
                v.extend_from_slice(im.pixel(y, x));
            }
        }
        Image::new(h, w, c, v).unwrap()
    };
    let f = patchmatch(&a, &b, &params(-40, 10)).unwrap();
    let g = patchmatch(&mirror(&a), &mirror(&b), &params(-10, 40)).unwrap();
    let truth_m: Vec<f32> = (0..80 * 144)
        .map(|i| -truth[(i / 144) * 144 + 143 - i % 144])
        .collect();
    let r1 = bad_rate(&f, &truth, 2.0, None).unwrap();
    let r2 = bad_rate(&g, &truth_m, 2.0, None).unwrap();
    eprintln!("bad-2 {r1:.4}, mirrored {r2:.4}");
    assert!((r1 - r2).abs() <= 0.01, "bad-2 {r1} vs mirrored {r2}");
}

#[test]
fn the_coherence_term_makes_fields_more_coherent() {
    let (a, b, sc) = radiance_pair(96, 160, [0.03, 0.12], 5);
    let truth: Vec<f32> = sc.disparity[0].data().iter().map(|d| -d).collect();
    let with = patchmatch(&a, &b, &params(-48, 48)).unwrap();
    let without = patchmatch(&a, &b, &params(-48, 48).coherence(false)).unwrap();
    let (iw, io) = (incoherence(&with), incoherence(&without));
    let (bw, bo) = (
        bad_rate(&with, &truth, 2.0, None).unwrap(),
        bad_rate(&without, &truth, 2.0, None).unwrap(),
    );
    eprintln!("incoherence {iw:.4} vs {io:.4} without the term; bad-2 {bw:.4} vs {bo:.4}");
    assert!(iw < io);
    assert!(bw <= bo + 0.01);
}

/// BDS voting (eq. 5) equals a direct evaluation of its two sums, pixel by pixel, on random
/// fields (reference-to-source offsets also point outside the source: those votes are
/// skipped), with a source of another size than the reference; the fields either change
/// offset at every pixel or hold it over runs of 1-8 pixels along a row (the coherent case
/// the voting groups).
#[test]
fn bds_voting_equals_the_direct_sums_of_eq_5() {
    use rand::Rng;
    use wscg_hdr::Nnf;
    let mut r = wscg_math::rng::seeded(11);
    let (hr, wr, hs, ws, c, half) = (13i64, 17i64, 11i64, 19i64, 2usize, 2i64);
    let src = Image::new(
        hs as usize,
        ws as usize,
        c,
        (0..hs * ws * c as i64)
            .map(|_| r.random_range(0.0f32..1.0))
            .collect(),
    )
    .unwrap();
    // Reference-to-source offsets may leave the source; source-to-reference matches stay
    // inside the reference, as PatchMatch's do.
    let mut field = |h: i64, w: i64, (to_h, to_w): (i64, i64), inside: bool, runs: bool| {
        let ok = |i: i64, o: [i32; 2]| {
            let (y, x) = (i / w + o[1] as i64, i % w + o[0] as i64);
            !inside || ((0..to_h).contains(&y) && (0..to_w).contains(&x))
        };
        let (mut cur, mut left) = ([0i32; 2], 0);
        let off = (0..h * w)
            .map(|i| {
                if !(runs && left > 0 && i % w != 0 && ok(i, cur)) {
                    cur = loop {
                        let o = [r.random_range(-6..7), r.random_range(-3..4)];
                        if ok(i, o) {
                            break o;
                        }
                    };
                    left = if runs { r.random_range(1..9) } else { 1 };
                }
                left -= 1;
                cur
            })
            .collect();
        Nnf::new(h as usize, w as usize, off, vec![0.0; (h * w) as usize]).unwrap()
    };
    for runs in [false, true] {
        let rs = field(hr, wr, (hs, ws), false, runs);
        let sr = field(hs, ws, (hr, wr), true, runs);
        let out = vote_bds(&src, &rs, &sr, 2 * half as usize + 1).unwrap();
        let inside = |y: i64, x: i64, h: i64, w: i64| (0..h).contains(&y) && (0..w).contains(&x);
        let px = |y: i64, x: i64| src.pixel(y as usize, x as usize);
        let (nr, ns) = ((hr * wr) as f64, (hs * ws) as f64);
        for py in 0..hr {
            for pxx in 0..wr {
                let (mut a1, mut a2) = (vec![0f64; c], vec![0f64; c]);
                let (mut n1, mut n2) = (0f64, 0f64);
                for qy in py - half..=py + half {
                    for qx in pxx - half..=pxx + half {
                        if !inside(qy, qx, hr, wr) {
                            continue;
                        }
                        let o = rs.at(qy as usize, qx as usize);
                        let (sy, sx) = (py + o[1] as i64, pxx + o[0] as i64);
                        if inside(sy, sx, hs, ws) {
                            for (a, &v) in a1.iter_mut().zip(px(sy, sx)) {
                                *a += v as f64;
                            }
                            n1 += 1.0;
                        }
                    }
                }
                for ty in 0..hs {
                    for tx in 0..ws {
                        let o = sr.at(ty as usize, tx as usize);
                        let (my, mx) = (ty + o[1] as i64, tx + o[0] as i64);
                        if !inside(my, mx, hr, wr)
                            || (py - my).abs() > half
                            || (pxx - mx).abs() > half
                        {
                            continue;
                        }
                        let (sy, sx) = (ty + py - my, tx + pxx - mx);
                        if inside(sy, sx, hs, ws) {
                            for (a, &v) in a2.iter_mut().zip(px(sy, sx)) {
                                *a += v as f64;
                            }
                            n2 += 1.0;
                        }
                    }
                }
                let den = n1 / nr + n2 / ns;
                let got = out.pixel(py as usize, pxx as usize);
                for k in 0..c {
                    let want = if den > 0.0 {
                        (a1[k] / nr + a2[k] / ns) / den
                    } else {
                        let o = rs.at(py as usize, pxx as usize);
                        let y = (py + o[1] as i64).clamp(0, hs - 1);
                        let x = (pxx + o[0] as i64).clamp(0, ws - 1);
                        px(y, x)[k] as f64
                    };
                    assert!(
                        (got[k] as f64 - want).abs() <= 1e-6,
                        "({py}, {pxx}, {k}): {} vs {want}",
                        got[k]
                    );
                }
            }
        }
    }
}

#[test]
fn bds_voting_reproduces_a_consistent_shift_and_has_no_holes() {
    let (h, w) = (40, 80);
    let (r, s) = (texture(h, w, 0.0), texture(h, w, 6.0));
    // Exact fields: r -> s is -6, s -> r is +6, clamped at the borders.
    let field = |d: i32| {
        let off = (0..h * w)
            .map(|i| [d.clamp(-((i % w) as i32), (w - 1 - i % w) as i32), 0])
            .collect();
        wscg_hdr::Nnf::new(h, w, off, vec![0.0; h * w]).unwrap()
    };
    let (rs, sr) = (field(-6), field(6));
    let t = vote_bds(&s, &rs, &sr, 7).unwrap();
    let d = warp_direct(&s, &rs).unwrap();
    assert!(t.data().iter().all(|v| v.is_finite()));
    for y in 0..h {
        for x in 12..w - 6 {
            for c in 0..3 {
                let want = r.pixel(y, x)[c];
                assert!((t.pixel(y, x)[c] - want).abs() < 1e-5, "BDS at {y} {x}");
                assert_eq!(d.pixel(y, x)[c], want, "warp at {y} {x}");
            }
        }
    }
    // Random fields: still every pixel voted, values within the source's range.
    let noise = |seed: u64| {
        let off = (0..h * w)
            .map(|i| {
                let x = (i % w) as i64;
                let v = ((i as u64 * 2654435761 + seed) % 21) as i64 - 10;
                [(x + v).clamp(0, w as i64 - 1) as i32 - x as i32, 0]
            })
            .collect();
        wscg_hdr::Nnf::new(h, w, off, vec![0.0; h * w]).unwrap()
    };
    let t = vote_bds(&s, &noise(1), &noise(2), 7).unwrap();
    let (lo, hi) = s
        .data()
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(t.data().iter().all(|&v| v >= lo - 1e-6 && v <= hi + 1e-6));
    // The same result on one thread.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| vote_bds(&s, &noise(1), &noise(2), 7).unwrap());
    assert_eq!(one, t);
}

#[test]
fn zncc_stereo_recovers_a_shift_under_an_exposure_change() {
    let (a, b) = (texture(48, 96, 0.0), texture(48, 96, 7.0));
    // Four times the exposure: ZNCC does not care about gain.
    let b4 = b.map(|v| 4.0 * v);
    let f = zncc_stereo(&a, &b4, &StereoParams::default().d_min(-16).d_max(16)).unwrap();
    let ok = (0..48 * 96)
        .filter(|&i| i % 96 >= 10 && f.off[i] == [-7, 0])
        .count();
    assert!(ok as f64 >= 0.98 * (48 * 86) as f64, "{ok}");
    // Pixels whose match would leave B are filled from the row, inside B.
    for y in 0..48 {
        for x in 0..96 {
            let xb = x as i32 + f.at(y, x)[0];
            assert!((0..96).contains(&xb));
        }
    }
}

#[test]
fn bad_matching_inputs_are_errors() {
    let a = texture(20, 30, 0.0);
    let b = texture(20, 30, 1.0);
    for patch in [4, 1, 21] {
        let p = params(-5, 5).patch(patch);
        let e = patchmatch(&a, &b, &p).unwrap_err().to_string();
        assert!(e.contains("patch"), "{e}");
    }
    let e = patchmatch(&a, &b, &params(-30, 5)).unwrap_err().to_string();
    assert!(e.contains("width"), "{e}");
    let e = patchmatch(&a, &b, &params(6, 5)).unwrap_err().to_string();
    assert!(e.contains("d_min"), "{e}");
    let grey = Image::filled(20, 30, 1, 0.5f32).unwrap();
    assert!(patchmatch(&a, &grey, &params(-5, 5)).is_err());
    let mut nan = a.clone();
    nan.set(3, 3, 0, f32::NAN);
    assert!(patchmatch(&nan, &b, &params(-5, 5)).is_err());
    assert!(zncc_stereo(&a, &b, &StereoParams::default().window(8)).is_err());
    assert!(
        zncc_stereo(&a, &b, &StereoParams::default()).is_err(),
        "64 >= width 30"
    );
    let neg = StereoParams::default().d_min(-5).d_max(5).lr_tol(-1);
    assert!(zncc_stereo(&a, &b, &neg).is_err());
    // Extreme ranges are errors, not overflows.
    assert!(patchmatch(&a, &b, &params(i32::MIN, 0)).is_err());
}

#[test]
fn the_weighted_cost_ablation_ignores_zero_weight_samples() {
    use wscg_hdr::patchmatch_weighted;
    let (a, b) = (texture(40, 80, 0.0), texture(40, 80, 5.0));
    let ones = |im: &Image<f32>| im.map(|_| 1.0f32);
    let p = params(-12, 12).weighted_cost(true);
    // Unit weights: the plain cost (summed in another order: ties may break otherwise).
    let plain = patchmatch(&a, &b, &params(-12, 12)).unwrap();
    let unit = patchmatch_weighted(&a, &b, &ones(&a), &ones(&b), &p).unwrap();
    let same = plain
        .off
        .iter()
        .zip(&unit.off)
        .filter(|(x, y)| x == y)
        .count();
    assert!(same as f64 >= 0.99 * (40 * 80) as f64, "{same}");
    // Garbage in the reference where its weights are zero (a "clipped" band) does not
    // drive the match: the field there still finds the shift from the rest of the patch.
    let mut bad = a.clone();
    let mut wa = ones(&a);
    for y in 0..40 {
        for x in 30..32 {
            for c in 0..3 {
                bad.set(y, x, c, 50.0);
                wa.set(y, x, c, 0.0);
            }
        }
    }
    let weighted = patchmatch_weighted(&bad, &b, &wa, &ones(&b), &p).unwrap();
    let unweighted = patchmatch(&bad, &b, &params(-12, 12)).unwrap();
    let exact = |f: &wscg_hdr::Nnf| {
        (0..40 * 80)
            .filter(|&i| (27..35).contains(&(i % 80)) && f.off[i] == [-5, 0])
            .count()
    };
    let (ew, eu) = (exact(&weighted), exact(&unweighted));
    eprintln!("band pixels with the exact shift: weighted {ew}, plain {eu} of 320");
    assert!(ew >= 300, "{ew}");
    assert!(ew > eu);
    // Without the flag the weights are ignored.
    let off = p.weighted_cost(false);
    assert_eq!(
        patchmatch_weighted(&bad, &b, &wa, &ones(&b), &off).unwrap(),
        unweighted
    );
    // Weights of another shape are an error.
    let small = Image::filled(10, 10, 3, 1.0f32).unwrap();
    assert!(patchmatch_weighted(&a, &b, &small, &ones(&b), &p).is_err());
}
