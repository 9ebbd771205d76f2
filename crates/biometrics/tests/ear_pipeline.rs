//! Paper 14, the building blocks: Haar LL features (check 1), the skin model (check 4),
//! score rules and the fast gallery against the reference path, the baseline equivalence
//! (check 9), the reject threshold, CMC, and bad input. The OpenCV / PyWavelets /
//! scikit-image equalities of checks 1-3 are in `py/tests/test_ear.py`.

use wscg_biometrics::ear::synth::{self, EarSynthParams, OcclusionKind};
use wscg_biometrics::ear::{
    self, baseline_params, baseline_score, block_features, cmc, detect_occlusion, enroll,
    make_baseline_probe, make_probe, score, scores, EarParams, EarTemplate, Gallery,
    Identification, ScoreRule, SkinModel, SkinRule,
};
use wscg_math::image::Image;
use wscg_math::rng::seeded;
use wscg_math::wavelet::haar_ll;
use wscg_math::ImageView;

fn small_set(n: usize, probes: usize, kind: OcclusionKind, seed: u64) -> synth::EarSet {
    synth::generate(
        n,
        probes,
        kind,
        seed,
        &EarSynthParams::default(),
        &EarParams::default(),
    )
    .unwrap()
}

/// Check 1 (Rust side): block LLs are 2x2 sums / 2 and together form the LL of the whole
/// 100 x 80 plane.
#[test]
fn block_features_are_the_whole_image_haar_ll_rearranged() {
    let p = EarParams::default();
    let mut r = seeded(3);
    use rand::Rng;
    let plane: Vec<f64> = (0..100 * 80).map(|_| r.random::<f64>()).collect();
    let view = ImageView::plane(100, 80, &plane).unwrap();
    let feats = block_features(view, &p).unwrap();
    let ll = haar_ll(view).unwrap().into_data();
    assert_eq!(feats.len(), 80 * 25);
    for b in 0..80 {
        let (bi, bj) = (b / 8, b % 8);
        for u in 0..5 {
            for v in 0..5 {
                let want = ll[(bi * 5 + u) * 40 + bj * 5 + v];
                assert!((feats[b * 25 + u * 5 + v] as f64 - want).abs() < 1e-6);
                let (y, x) = (bi * 10 + 2 * u, bj * 10 + 2 * v);
                let direct = (plane[y * 80 + x]
                    + plane[y * 80 + x + 1]
                    + plane[(y + 1) * 80 + x]
                    + plane[(y + 1) * 80 + x + 1])
                    / 2.0;
                assert!((want - direct).abs() < 1e-12);
            }
        }
    }
}

/// Check 4: the ML fit recovers a known Gaussian, the joint 95 % rule keeps 95 +- 0.5 % of
/// its samples, and the Mahalanobis values of the built-in default model (mean (0.45, 0.32),
/// sigma_r = 0.04, sigma_g = 0.016) are reproduced to 0.01.
#[test]
fn skin_model_fit_threshold_and_reference_mahalanobis_values() {
    use rand_distr::{Distribution, Normal};
    let truth = SkinModel::new([0.43, 0.33], [[1.2e-3, 2.0e-4], [2.0e-4, 3.0e-4]]).unwrap();
    // Correlated samples: x = mean + L z with L the Cholesky factor of the covariance.
    let c = truth.cov;
    let l00 = c[0][0].sqrt();
    let l10 = c[1][0] / l00;
    let l11 = (c[1][1] - l10 * l10).sqrt();
    let mut r = seeded(11);
    let n01 = Normal::new(0.0, 1.0).unwrap();
    let pts: Vec<[f64; 2]> = (0..100_000)
        .map(|_| {
            let (z0, z1) = (n01.sample(&mut r), n01.sample(&mut r));
            [
                truth.mean[0] + l00 * z0,
                truth.mean[1] + l10 * z0 + l11 * z1,
            ]
        })
        .collect();
    let fit = SkinModel::fit_rg(&pts).unwrap();
    for k in 0..2 {
        assert!(
            (fit.mean[k] - truth.mean[k]).abs() < 1e-3,
            "mean {:?}",
            fit.mean
        );
    }
    for (a, b) in [(0, 0), (0, 1), (1, 1)] {
        let rel = (fit.cov[a][b] - truth.cov[a][b]).abs() / truth.cov[a][b].abs();
        assert!(
            rel < 0.03,
            "cov[{a}][{b}] {} vs {}",
            fit.cov[a][b],
            truth.cov[a][b]
        );
    }
    let skin = pts
        .iter()
        .filter(|p| truth.likelihood_rg(p[0], p[1]) >= 0.05)
        .count() as f64
        / pts.len() as f64;
    assert!((skin - 0.95).abs() <= 0.005, "classified skin {skin}");

    let m = SkinModel::default();
    let refs = [
        ((0.392, 0.337), 3.26),
        ((0.496, 0.336), 2.35),
        ((0.539, 0.325), 5.05),
        ((1.0 / 3.0, 1.0 / 3.0), 9.22),
        ((0.584, 0.259), 26.1),
        ((0.464, 0.309), 0.61),
        ((0.417, 0.354), 5.30),
    ];
    for ((r, g), want) in refs {
        let got = m.mahalanobis2_rg(r, g);
        assert!((got - want).abs() <= 0.01, "({r}, {g}): {got} vs {want}");
    }
    let gold = ear::chromaticity([212, 175, 55]).unwrap();
    assert!((m.mahalanobis2_rg(gold[0], gold[1]) - 23.6).abs() <= 0.05);
    // Decisions on these examples under the joint 95 % ellipse: skin tones in, grey /
    // orange / gold out.
    let rule = SkinRule::joint();
    assert!(rule.is_skin(&m, rgb_of(0.539, 0.325), 0));
    assert!(rule.is_skin(&m, rgb_of(0.45, 0.32), 0));
    assert!(!rule.is_skin(&m, [128, 128, 128], 0));
    assert!(!rule.is_skin(&m, [212, 175, 55], 0));
    assert!(!rule.is_skin(&m, [0, 0, 0], 0));
    // The luminance gate rejects dark skin-coloured hair.
    assert!(rule.is_skin(&m, [45, 30, 22], 0));
    assert!(!rule.is_skin(&m, [45, 30, 22], 35));
    // The literal marginal AND, the default: |z| <= 2 per channel. It keeps light and
    // medium skin and the mean, and drops the dark skin above (z_r = 2.2) and a neutral
    // grey pushed to z_r = -2.2, which the joint ellipse still takes.
    let and = SkinRule::marginal_and();
    assert_eq!(SkinRule::default(), and);
    for (r, g) in [(0.392, 0.337), (0.496, 0.336), (0.45, 0.32)] {
        assert!(and.is_skin(&m, rgb_of(r, g), 0), "({r}, {g})");
    }
    assert!(!and.is_skin(&m, rgb_of(0.539, 0.325), 0));
    let (grey_r, grey_g) = (m.mean[0] - 2.2 * m.cov[0][0].sqrt(), 1.0 / 3.0);
    assert!(m.mahalanobis2_rg(grey_r, grey_g) < 5.991);
    let (pr, _) = m.marginal_likelihoods_rg(grey_r, grey_g);
    assert!(pr < (-2.0f64).exp());
    let (sr, sg) = (m.cov[0][0].sqrt(), m.cov[1][1].sqrt());
    let at = |zr: f64, zg: f64| [m.mean[0] + zr * sr, m.mean[1] + zg * sg];
    let inside = at(1.9, 1.9);
    let outside = at(2.1, 0.0);
    let (pr, pg) = m.marginal_likelihoods_rg(inside[0], inside[1]);
    assert!(pr >= (-2.0f64).exp() && pg >= (-2.0f64).exp());
    let (pr, _) = m.marginal_likelihoods_rg(outside[0], outside[1]);
    assert!(pr < (-2.0f64).exp());
    assert!(and.validate().is_ok());
}

/// The fast block-major gallery gives the reference scores of every rule, and the
/// rules follow their definitions on the reference breakdown.
#[test]
fn gallery_scores_equal_the_reference_path_for_every_rule() {
    let set = small_set(
        12,
        1,
        OcclusionKind::Colour {
            min_pct: 10.0,
            max_pct: 50.0,
        },
        5,
    );
    let p = EarParams::default();
    let templates: Vec<EarTemplate> = set.enrol.iter().map(|im| enroll(im, &p).unwrap()).collect();
    let gallery = Gallery::new(&templates).unwrap();
    for pr in &set.probes {
        let probe = make_probe(&pr.image.rgb, &p).unwrap();
        assert!(!probe.is_empty());
        let one_pass = ear::scores_by_rule(&probe, &gallery, &p, &ScoreRule::ALL).unwrap();
        for rule in ScoreRule::ALL {
            assert_eq!(ScoreRule::ALL[rule.index()], rule);
            let pp = p.clone().score(rule);
            let fast = scores(&probe, &gallery, &pp).unwrap();
            assert_eq!(fast, one_pass[rule.index()]);
            for (g, t) in templates.iter().enumerate() {
                let br = score(&probe, t, &pp).unwrap();
                assert!(
                    (fast[g] - br.get(rule)).abs() < 1e-5,
                    "{rule:?}: {} vs {}",
                    fast[g],
                    br.get(rule)
                );
            }
        }
        // Definitions on one breakdown.
        let br = score(&probe, &templates[pr.subject], &p).unwrap();
        let m = probe.len();
        let ns = p.shifts.len();
        let d = |s: usize, j: usize| br.distances[s * m + j];
        let bmax: f64 = (0..m)
            .map(|j| {
                (0..ns)
                    .filter_map(|s| d(s, j))
                    .map(|v| 1.0 - v)
                    .fold(f64::MIN, f64::max)
            })
            .sum::<f64>()
            / m as f64;
        assert!((br.get(ScoreRule::BlockwiseMax) - bmax).abs() < 1e-6);
        let omax = br
            .per_shift
            .iter()
            .flatten()
            .fold(f64::MIN, |a, &b| a.max(b));
        assert!((br.get(ScoreRule::OverallMax) - omax).abs() < 1e-12);
        // S_0 is always defined; shift validity follows the grid border.
        assert!(br.per_shift[0].is_some());
        for (j, &b) in probe.index.iter().enumerate() {
            let (row, col) = (b / 8, b % 8);
            assert_eq!(d(1, j).is_some(), col + 1 < 8);
            assert_eq!(d(6, j).is_some(), row >= 1 && col >= 1);
            assert!(d(0, j).unwrap() <= 1.0);
        }
        assert!(br.get(ScoreRule::LiteralEq18) >= br.get(ScoreRule::BlockwiseMax));
    }
}

/// Check 9: the baseline equals the pipeline with every block, shift B0 and the overall
/// maximum, to 1e-6.
#[test]
fn baseline_equals_the_pipeline_with_all_blocks_one_shift_overall_max() {
    let set = small_set(
        6,
        2,
        OcclusionKind::Colour {
            min_pct: 20.0,
            max_pct: 40.0,
        },
        8,
    );
    let p = EarParams::default();
    let templates: Vec<EarTemplate> = set.enrol.iter().map(|im| enroll(im, &p).unwrap()).collect();
    let gallery = Gallery::new(&templates).unwrap();
    let bp = baseline_params(&p);
    for pr in &set.probes {
        let probe = make_baseline_probe(&pr.image.rgb, &p).unwrap();
        assert_eq!(probe.len(), 80);
        let fast = scores(&probe, &gallery, &bp).unwrap();
        for (g, t) in templates.iter().enumerate() {
            let direct = baseline_score(&probe, t, &p).unwrap();
            let pipe = score(&probe, t, &bp).unwrap().get(ScoreRule::OverallMax);
            assert!((direct - pipe).abs() < 1e-6, "{direct} vs {pipe}");
            assert!((direct - fast[g]).abs() < 1e-6);
        }
    }
    // The whole-ear probe of an enrolment image is its template.
    let probe = make_baseline_probe(&set.enrol[0], &p).unwrap();
    assert_eq!(probe.feats, templates[0].features());
    assert!((baseline_score(&probe, &templates[0], &p).unwrap() - 1.0).abs() < 1e-12);
}

/// An image at the normalised size whose top `rows` rows are blue and the rest skin.
fn half_blue(rows: usize) -> Image<u8> {
    let mut data = Vec::with_capacity(100 * 80 * 3);
    for y in 0..100 {
        for _ in 0..80 {
            data.extend_from_slice(if y < rows {
                &[40, 70, 180]
            } else {
                &[180, 128, 92]
            });
        }
    }
    Image::new(100, 80, 3, data).unwrap()
}

/// Step 12: exactly 60 % occluded (48 blocks) is accepted, one more block row is rejected;
/// a rejected probe is reported, never ranked.
#[test]
fn rejection_threshold_is_strictly_above_sixty_percent() {
    let p = EarParams::default();
    assert!(SkinModel::default().likelihood([180, 128, 92]) > 0.4);
    let at60 = detect_occlusion(&half_blue(60), &p).unwrap();
    assert_eq!(at60.block_unoccluded.iter().filter(|&&k| !k).count(), 48);
    assert!((at60.occluded_pct - 60.0).abs() < 1e-12);
    assert!(!at60.rejected);
    // 65 blue rows: block row 6 is exactly half skin, still un-occluded (fraction >= 0.5).
    assert!(!detect_occlusion(&half_blue(65), &p).unwrap().rejected);
    let at70 = detect_occlusion(&half_blue(66), &p).unwrap();
    assert!((at70.occluded_pct - 70.0).abs() < 1e-12);
    assert!(at70.rejected);
    let t = enroll(&half_blue(0), &p).unwrap();
    let gallery = Gallery::new(&[t]).unwrap();
    let probe = make_probe(&half_blue(66), &p).unwrap();
    assert!(probe.rejected());
    match ear::identify(&probe, &gallery, &p).unwrap() {
        Identification::Rejected { occluded_pct } => assert!((occluded_pct - 70.0).abs() < 1e-12),
        other => panic!("expected a rejection, got {other:?}"),
    }
    let lenient = p.clone().reject_above_pct(75.0);
    let probe = make_probe(&half_blue(66), &lenient).unwrap();
    assert_eq!(probe.index, (56..80).collect::<Vec<_>>());
    assert!(ear::identify(&probe, &gallery, &lenient)
        .unwrap()
        .ranking()
        .is_some());
}

#[test]
fn cmc_counts_accepted_probes_only() {
    let c = cmc(&[Some(0), Some(2), None, Some(1), Some(0)], 4).unwrap();
    assert_eq!(c, vec![0.5, 0.75, 1.0, 1.0]);
    assert!(cmc(&[None, None], 3).is_err());
    assert!(cmc(&[Some(0)], 0).is_err());
    let r = ear::rank(&[0.2, 0.9, 0.9, -1.0]);
    assert_eq!(r.iter().map(|x| x.0).collect::<Vec<_>>(), vec![1, 2, 0, 3]);
}

#[test]
fn bad_input_is_an_error_naming_the_problem() {
    let p = EarParams::default();
    let rgb = half_blue(0);
    let grey = Image::new(100, 80, 1, vec![100u8; 8000]).unwrap();
    let tiny = Image::new(1, 5, 3, vec![100u8; 15]).unwrap();
    let four = Image::new(10, 10, 4, vec![100u8; 400]).unwrap();
    let msg = |e: wscg_math::Error| e.to_string();
    assert!(msg(detect_occlusion(&grey, &p).unwrap_err()).contains("grey"));
    assert!(msg(enroll(&grey, &p).unwrap_err()).contains("gray_enrolment"));
    assert!(enroll(&grey, &p.clone().gray_enrolment(true)).is_ok());
    assert!(msg(make_probe(&tiny, &p).unwrap_err()).contains("2 x 2"));
    assert!(msg(enroll(&four, &p).unwrap_err()).contains("3 colour channels"));
    assert!(Image::<u8>::new(0, 5, 3, vec![]).is_err());
    for bad in [
        p.clone().block(12),
        p.clone().block(5),
        p.clone().block_skin_fraction(0.0),
        p.clone().block_skin_fraction(1.5),
        p.clone().shifts(vec![]),
        p.clone().close_radius(f64::NAN),
        p.clone().skin_model(SkinModel {
            mean: [0.45, 0.32],
            cov: [[1e-3, 2e-3], [2e-3, 1e-3]],
        }),
        p.clone().skin_model(SkinModel {
            mean: [f64::NAN, 0.32],
            cov: [[1e-3, 0.0], [0.0, 1e-3]],
        }),
        p.clone().skin_rule(SkinRule::Joint {
            min_likelihood: 0.0,
        }),
    ] {
        assert!(enroll(&rgb, &bad).is_err(), "{bad:?}");
        assert!(detect_occlusion(&rgb, &bad).is_err());
    }
    assert!(SkinModel::fit(&[[1, 2, 3]]).is_err());
    assert!(SkinModel::fit(&[[0, 0, 0]; 10]).is_err());
    assert!(EarTemplate::new(vec![0.0; 80 * 24], 80, 25).is_err());
    assert!(EarTemplate::new(vec![f32::NAN; 80 * 25], 80, 25).is_err());
    assert!(Gallery::new(&[]).is_err());
    let t = enroll(&rgb, &p).unwrap();
    let other = EarTemplate::new(vec![0.0; 40 * 25], 40, 25).unwrap();
    assert!(Gallery::new(&[t.clone(), other.clone()]).is_err());
    let probe = make_probe(&rgb, &p).unwrap();
    assert!(score(&probe, &other, &p).is_err());
    let g_other = Gallery::new(&[other]).unwrap();
    assert!(scores(&probe, &g_other, &p).is_err());
    assert!(Gallery::from_features(&[0.0; 10], 1, 80, 25).is_err());
    assert!(ScoreRule::parse("best").is_err());
    assert_eq!(
        ScoreRule::parse("overall_max").unwrap(),
        ScoreRule::OverallMax
    );
    assert!(synth::generate(0, 1, OcclusionKind::None, 1, &EarSynthParams::default(), &p).is_err());
    assert!(synth::generate(
        1,
        1,
        OcclusionKind::Colour {
            min_pct: 50.0,
            max_pct: 20.0
        },
        1,
        &EarSynthParams::default(),
        &p
    )
    .is_err());
}

/// An 8-bit RGB pixel of chromaticity about `(r, g)` and channel sum 450.
fn rgb_of(r: f64, g: f64) -> [u8; 3] {
    let s = 450.0;
    [(r * s) as u8, (g * s) as u8, ((1.0 - r - g) * s) as u8]
}
