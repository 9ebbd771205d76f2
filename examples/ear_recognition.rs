//! Paper 14 on synthetic ears: enrol 50 subjects, identify colour-occluded probes with the
//! index-based matcher and with the whole-ear baseline, and print the CMC of every rule.
//!
//! `cargo run --release --example ear_recognition`

use wscg::biometrics::ear::protocol::evaluate;
use wscg::biometrics::ear::synth::{self, EarSynthParams, OcclusionKind};
use wscg::biometrics::ear::{EarParams, ScoreRule};

fn main() -> wscg::math::Result<()> {
    let p = EarParams::default();
    let set = synth::generate(
        50,
        2,
        OcclusionKind::Colour {
            min_pct: 10.0,
            max_pct: 50.0,
        },
        3,
        &EarSynthParams::default(),
        &p,
    )?;
    for (label, params) in [
        (
            "paper's pre-processing (whole probe equalised)",
            p.clone().equalize_on_skin(false),
        ),
        ("equalised on skin (default)", p.clone()),
    ] {
        let ev = evaluate(&set, &params, 10)?;
        println!(
            "{label}: {:.1} % of probes rejected",
            100.0 * ev.rejection_rate()
        );
        for (rule, c) in ScoreRule::ALL.iter().zip(&ev.cmc) {
            println!(
                "  {:15} rank-1 {:.3}  rank-10 {:.3}",
                rule.name(),
                c[0],
                c[9]
            );
        }
        println!(
            "  {:15} rank-1 {:.3}  rank-10 {:.3}",
            "baseline", ev.baseline_cmc[0], ev.baseline_cmc[9]
        );
    }
    Ok(())
}
