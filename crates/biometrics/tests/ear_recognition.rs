//! Paper 14, the experiments on synthetic ears with exact occluder masks: occlusion estimate
//! (check 5), analytic shifts (check 6), recognition against the baseline (check 7, Figs.
//! 11-12), the degradation curve (check 8, Fig. 13) and the hair stress test (check 10).

use std::sync::OnceLock;

use wscg_biometrics::ear::protocol::{evaluate, Evaluation};
use wscg_biometrics::ear::synth::{
    self, translate_replicate, EarSet, EarSynthParams, OcclusionKind,
};
use wscg_biometrics::ear::{
    detect_occlusion, enroll, make_probe, rank, score, scores, EarParams, EarTemplate, Gallery,
    ScoreRule, SkinRule,
};

fn generate(n: usize, probes: usize, kind: OcclusionKind, seed: u64) -> EarSet {
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

/// 100 subjects, 8 probes each, non-skin colour occluders over 0-70 % of the blocks.
fn wide_set() -> &'static EarSet {
    static SET: OnceLock<EarSet> = OnceLock::new();
    SET.get_or_init(|| {
        generate(
            100,
            8,
            OcclusionKind::Colour {
                min_pct: 0.0,
                max_pct: 70.0,
            },
            1401,
        )
    })
}

/// 100 subjects, 3 probes each, colour occluders over 10-50 % of the blocks (check 7).
fn colour_set() -> &'static EarSet {
    static SET: OnceLock<EarSet> = OnceLock::new();
    SET.get_or_init(|| {
        generate(
            100,
            3,
            OcclusionKind::Colour {
                min_pct: 10.0,
                max_pct: 50.0,
            },
            1407,
        )
    })
}

fn print_cmc(title: &str, ev: &Evaluation) {
    println!("{title}: rejected {:.3}", ev.rejection_rate());
    for (rule, c) in ScoreRule::ALL.iter().zip(&ev.cmc) {
        println!(
            "  {:15} rank-1 {:.3}  rank-5 {:.3}  rank-10 {:.3}",
            rule.name(),
            c[0],
            c[4],
            c[9]
        );
    }
    let b = &ev.baseline_cmc;
    println!(
        "  {:15} rank-1 {:.3}  rank-5 {:.3}  rank-10 {:.3}",
        "baseline", b[0], b[4], b[9]
    );
}

/// Over the first 300 probes of the wide set under `p`: the mean |E - E_gt| in points, the
/// share within 7.5 points and the share whose reject decision (E > 60) agrees with the
/// truth.
fn occlusion_accuracy(p: &EarParams) -> (f64, f64, f64) {
    let probes = &wide_set().probes[..300];
    let (mut within, mut agree) = (0, 0);
    let mut err_sum = 0.0;
    for pr in probes {
        let rep = detect_occlusion(&pr.image.rgb, p).unwrap();
        let e = (rep.occluded_pct - pr.occluded_pct()).abs();
        err_sum += e;
        within += usize::from(e <= 7.5);
        agree += usize::from(rep.rejected == (pr.occluded_pct() > 60.0));
    }
    let n = probes.len() as f64;
    (err_sum / n, within as f64 / n, agree as f64 / n)
}

/// Check 5: on 300 probes with non-skin occluders over 0-70 % of the blocks, the estimated
/// occlusion is within 7.5 points (6 blocks) of the truth for >= 90 % of the probes, and the
/// reject decision (E > 60) agrees with the truth for >= 95 %. Measured with the paper's
/// marginal AND (the default): mean error 1.10 points, 99.7 % within, 100 % agreement. The
/// joint 95 % ellipse is printed beside it (4.08 points, 90.0 %, 98.7 %): it takes noisy
/// dark-grey occluders for skin.
#[test]
fn occlusion_estimate_matches_the_ground_truth_masks() {
    let joint = EarParams::default().skin_rule(SkinRule::joint());
    for (name, p) in [("marginal AND", EarParams::default()), ("joint", joint)] {
        let (err, within, agree) = occlusion_accuracy(&p);
        println!(
            "occlusion estimate ({name}): mean |E - E_gt| {err:.2} points, within 7.5: \
             {within:.3}, reject agreement {agree:.3}"
        );
    }
    let (_, within, agree) = occlusion_accuracy(&EarParams::default());
    assert!(within >= 0.90);
    assert!(agree >= 0.95);
}

/// Measurements of check 6 over 100 subjects x 8 directions.
struct ShiftStats {
    genuine_min: f64,
    genuine_mean: f64,
    mean_drop: f64,
    expected_shift_frac: f64,
    rank1: f64,
    rank1_no_shift: f64,
}

/// Probes that are the enrolment images moved by exactly one block (20 px on the canvas, 10
/// at 100 x 80) in each of the eight directions, the uncovered strip filled by edge
/// replication, matched against the 100 templates.
fn shift_stats() -> &'static ShiftStats {
    static STATS: OnceLock<ShiftStats> = OnceLock::new();
    STATS.get_or_init(|| {
        let set = generate(100, 0, OcclusionKind::None, 1406);
        let p = EarParams::default();
        let no_shift = p.clone().shifts(vec![(0, 0)]);
        let templates: Vec<EarTemplate> =
            set.enrol.iter().map(|im| enroll(im, &p).unwrap()).collect();
        let gallery = Gallery::new(&templates).unwrap();
        let (mut genuine_min, mut genuine_sum, mut drop_sum, mut n) =
            (f64::INFINITY, 0.0, 0.0, 0usize);
        let (mut textured, mut right_shift) = (0usize, 0usize);
        let (mut rank1, mut rank1_no_shift) = (0usize, 0usize);
        for (sid, img) in set.enrol.iter().enumerate() {
            let t = &templates[sid];
            for (k, &(dr, dc)) in p.shifts.iter().enumerate().skip(1) {
                // Content moved by (-dr, -dc) blocks: probe block (i, j) shows enrolled block
                // (i + dr, j + dc), the partner of shift B_k.
                let moved = translate_replicate(img, -20 * dr as i64, -20 * dc as i64);
                let probe = make_probe(&moved, &p).unwrap();
                let br = score(&probe, t, &p).unwrap();
                let sb = br.get(ScoreRule::BlockwiseMax);
                genuine_min = genuine_min.min(sb);
                genuine_sum += sb;
                let b0 = score(&probe, t, &no_shift)
                    .unwrap()
                    .get(ScoreRule::BlockwiseMax);
                drop_sum += sb - b0;
                n += 1;
                for (j, &b) in probe.index.iter().enumerate() {
                    let (row, col) = ((b / 8) as i32 + dr, (b % 8) as i32 + dc);
                    if !(0..10).contains(&row) || !(0..8).contains(&col) {
                        continue;
                    }
                    let src = t.block(row as usize * 8 + col as usize);
                    let mean = src.iter().sum::<f32>() / 25.0;
                    let sd = (src.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / 25.0).sqrt();
                    if sd > 0.05 {
                        textured += 1;
                        right_shift += usize::from(br.best_shift[j] == k);
                    }
                }
                let top = |q: &EarParams| rank(&scores(&probe, &gallery, q).unwrap())[0].0;
                rank1 += usize::from(top(&p) == sid);
                rank1_no_shift += usize::from(top(&no_shift) == sid);
            }
        }
        let stats = ShiftStats {
            genuine_min,
            genuine_mean: genuine_sum / n as f64,
            mean_drop: drop_sum / n as f64,
            expected_shift_frac: right_shift as f64 / textured as f64,
            rank1: rank1 as f64 / n as f64,
            rank1_no_shift: rank1_no_shift as f64 / n as f64,
        };
        println!(
            "shifted probes: genuine S_B min {:.4} mean {:.4}, mean drop without shifts {:.4}, \
             textured blocks with the expected shift {:.3}, rank-1 {:.3} (without shifts {:.3})",
            stats.genuine_min,
            stats.genuine_mean,
            stats.mean_drop,
            stats.expected_shift_frac,
            stats.rank1,
            stats.rank1_no_shift
        );
        stats
    })
}

/// Check 6: the textured blocks pick the expected shift (>= 80 %), rank-1 is 100 % over
/// 100 subjects x 8 directions, and without shifts the genuine score drops by >= 0.03 on
/// average.
#[test]
fn one_block_translations_are_recovered_by_the_shift_set() {
    let s = shift_stats();
    assert!(s.expected_shift_frac >= 0.80);
    assert_eq!(s.rank1, 1.0);
    assert!(s.mean_drop >= 0.03);
}

/// Check 6, the genuine score of every shifted probe >= 0.97. Not met: the blocks of the
/// replicated edge strip have no valid partner under the true shift, and the strip changes
/// the equalisation histogram. Measured: min 0.924, mean 0.969; 399 of the 800 probes are
/// under 0.97, the diagonal moves (17 strip blocks of 80) worst. Split by block: the blocks
/// with a partner score 0.987 on average under the true shift (0.936 on the worst probe,
/// the histogram change), the strip blocks 0.879 under their best shift.
#[test]
#[ignore = "not met: genuine S_B min 0.924 (mean 0.969) on one-block shifts, threshold 0.97"]
fn one_block_translations_keep_a_genuine_score_above_097() {
    let s = shift_stats();
    assert!(s.genuine_min >= 0.97, "min genuine S_B {}", s.genuine_min);
}

/// Check 7, calibration: the frozen generator gives the whole-ear baseline 85-95 % rank-1
/// on un-occluded probes of 100 subjects.
#[test]
fn generator_calibration_puts_the_clean_baseline_at_85_to_95_percent() {
    let set = generate(100, 3, OcclusionKind::None, 1405);
    let ev = evaluate(&set, &EarParams::default(), 10).unwrap();
    print_cmc("un-occluded probes", &ev);
    assert_eq!(ev.rejection_rate(), 0.0);
    let b1 = ev.baseline_cmc[0];
    assert!((0.85..=0.95).contains(&b1), "baseline rank-1 {b1}");
}

fn check7(ev: &Evaluation) {
    let s_b = ev.cmc_of(ScoreRule::BlockwiseMax);
    let s_m = ev.cmc_of(ScoreRule::OverallMax);
    let base = ev.baseline_cmc[0];
    assert!(
        s_b[0] >= base + 0.10,
        "S_B rank-1 {} vs baseline {}",
        s_b[0],
        base
    );
    assert!(s_b[9] >= 0.90, "S_B rank-10 {}", s_b[9]);
    assert!(s_b[0] >= s_m[0] - 0.02, "S_B {} vs S_m {}", s_b[0], s_m[0]);
}

/// Check 7 with equalisation on the detected skin (our variant, `equalize_on_skin`):
/// rank-1 of S_B >= baseline + 10 points, rank-10 >= 90 %, S_B >= S_m - 2 points. Measured:
/// S_B rank-1 0.933, rank-10 0.993, S_m 0.807, baseline 0.557.
#[test]
fn index_based_matching_beats_the_baseline_with_skin_equalisation() {
    let p = EarParams::default().equalize_on_skin(true);
    let ev = evaluate(colour_set(), &p, 10).unwrap();
    print_cmc("colour occluders 10-50 %, equalised on skin", &ev);
    check7(&ev);
}

/// Check 7 with the paper's literal pre-processing (the whole probe, occluder included, is
/// histogram-equalised before the occlusion is detected). Not met on the synthetic ears:
/// a large occluder shifts the equalised grey levels of the visible ear, so the kept blocks
/// no longer match their templates. Measured: S_B rank-1 0.467 vs baseline 0.557, rank-10
/// 0.743, S_m 0.643.
#[test]
#[ignore = "not met with whole-image equalisation: S_B rank-1 0.467 vs baseline 0.557 (see note)"]
fn index_based_matching_beats_the_baseline_as_printed() {
    let ev = evaluate(
        colour_set(),
        &EarParams::default().equalize_on_skin(false),
        10,
    )
    .unwrap();
    print_cmc("colour occluders 10-50 %, paper's pre-processing", &ev);
    check7(&ev);
}

/// The default pre-processing (equalised on the detected skin) on a held-out set: seed 2718,
/// other subjects and occluders than the set (seed 1407) the default was chosen on. Occluded
/// probes are identified at least as well as by the whole-ear baseline, which the paper's
/// whole-probe equalisation (`equalize_on_skin(false)`) does not achieve. Measured: block-wise
/// max rank-1 0.920, paper's pre-processing 0.557, baseline 0.577.
#[test]
fn default_preprocessing_beats_the_baseline_on_a_held_out_set() {
    let kind = OcclusionKind::Colour {
        min_pct: 10.0,
        max_pct: 50.0,
    };
    let set = generate(100, 3, kind, 2718);
    let default = evaluate(&set, &EarParams::default(), 10).unwrap();
    let paper = evaluate(&set, &EarParams::default().equalize_on_skin(false), 10).unwrap();
    print_cmc("held-out seed 2718, default (equalised on skin)", &default);
    print_cmc("held-out seed 2718, paper's pre-processing", &paper);
    let s_b = default.cmc_of(ScoreRule::BlockwiseMax)[0];
    let base = default.baseline_cmc[0];
    assert!(s_b >= base, "S_B rank-1 {s_b} vs baseline {base}");
    assert!(s_b > paper.cmc_of(ScoreRule::BlockwiseMax)[0]);
}

fn degradation(ev: &Evaluation, title: &str) -> Vec<f64> {
    let edges = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0];
    let bins = ev.degradation(ScoreRule::BlockwiseMax, &edges);
    println!("{title}");
    for (lo, hi, count, r1) in &bins {
        println!("  E in [{lo:>2}, {hi:>2}): {count:>3} probes, rank-1 {r1:.3}");
    }
    bins.iter().map(|b| b.3).collect()
}

/// Check 8: every probe with E > 60 % is reported as rejected, never ranked, under both
/// pre-processings.
#[test]
fn heavily_occluded_probes_are_rejected_never_ranked() {
    for eq_skin in [true, false] {
        let p = EarParams::default().equalize_on_skin(eq_skin);
        let ev = evaluate(wide_set(), &p, 10).unwrap();
        // The rejections follow the truth: the share rejected is within 3 points of the
        // share of probes with more than 60 % of their blocks occluded.
        let truly = wide_set()
            .probes
            .iter()
            .filter(|pr| pr.occluded_pct() > 60.0)
            .count() as f64
            / wide_set().probes.len() as f64;
        println!(
            "rejected {:.3}, truly over 60 %: {truly:.3}",
            ev.rejection_rate()
        );
        assert!(truly > 0.05);
        assert!((ev.rejection_rate() - truly).abs() <= 0.03);
        for o in &ev.outcomes {
            assert_eq!(o.rejected, o.estimated_pct > 60.0);
            if o.rejected {
                assert!(o.ranks.iter().all(|r| r.is_none()));
            }
        }
    }
}

/// Check 8 (Fig. 13): rank-1 per estimated-occlusion bin 0-10, ..., 50-60 % is
/// non-increasing within 3 points, under both pre-processings. Measured with the paper's
/// marginal AND: 0.986, 0.975, 0.932, 0.938, 0.935, 0.785 equalised on skin; 0.973, 0.847,
/// 0.583, 0.372, 0.130, 0.119 with the whole probe equalised. With the joint ellipse the
/// 0-10 % bin collected the probes whose dark-grey occluder was taken for skin, and the
/// curve rose from 0.763 to 0.917 (equalised on skin).
#[test]
fn rank1_degrades_with_occlusion() {
    for (eq_skin, title) in [
        (true, "equalised on skin"),
        (false, "paper's pre-processing"),
    ] {
        let p = EarParams::default().equalize_on_skin(eq_skin);
        let ev = evaluate(wide_set(), &p, 10).unwrap();
        println!(
            "rejected {:.3} of {}",
            ev.rejection_rate(),
            ev.outcomes.len()
        );
        let r1 = degradation(&ev, title);
        for w in r1.windows(2) {
            assert!(
                w[1] <= w[0] + 0.03,
                "{title}: rank-1 rises from {} to {}",
                w[0],
                w[1]
            );
        }
    }
}

/// Check 10 (reported, not gated on accuracy): dark-brown hair has skin chromaticity, so
/// without the luminance gate it is taken for skin. The report prints the occlusion-estimate
/// error with the gate off (paper) and at 35; the gate can only remove skin, so the
/// estimate never decreases with it.
#[test]
fn hair_stress_test_reports_both_luminance_gates() {
    for dark in [true, false] {
        let set = generate(40, 2, OcclusionKind::Hair { dark }, 1410 + dark as u64);
        let mut errs = [0.0f64; 2];
        let mut under = [0usize; 2];
        for pr in &set.probes {
            let mut est = [0.0; 2];
            for (k, gate) in [0u8, 35].into_iter().enumerate() {
                let p = EarParams::default().min_intensity(gate);
                est[k] = detect_occlusion(&pr.image.rgb, &p).unwrap().occluded_pct;
                errs[k] += (est[k] - pr.occluded_pct()).abs();
                under[k] += usize::from(est[k] + 7.5 < pr.occluded_pct());
            }
            assert!(est[1] >= est[0], "the gate lowered the estimate: {est:?}");
        }
        let n = set.probes.len() as f64;
        println!(
            "{} hair: mean |E - E_gt| {:.2} (no gate) vs {:.2} (gate 35); under-estimated by \
             more than 6 blocks: {} vs {} of {}",
            if dark { "dark-brown" } else { "blond" },
            errs[0] / n,
            errs[1] / n,
            under[0],
            under[1],
            set.probes.len()
        );
    }
}
