//! Paper 17 on synthetic Kinect walkers: 20 people x 3 walks, 3-fold cross-validation of the
//! joint-relative-angle + DTW kernel method against the Ball and Preis baselines (Table 1)
//! and the accuracy-versus-threshold curve (Fig. 9).
//!
//! `cargo run --release --example gait_recognition [seed]`

use wscg::biometrics::gait::protocol::{cross_validate, prepare, Protocol};
use wscg::biometrics::gait::synth::{walkers, SessionRanges};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let seed: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(0);
    let set = walkers(20, 3, &SessionRanges::default(), seed)?;
    let proto = Protocol::default();
    let prepared = prepare(&set.walks, &set.labels, &set.session_index, &proto.params)?;
    let r = cross_validate(&prepared, None, &proto)?;
    println!(
        "20 subjects x 3 walks, 3-fold CV, seed {seed} ({} decisions)",
        r.decisions
    );
    println!("{:<44} {:>8}", "method", "accuracy");
    let rows = [
        ("JRA + DTW kernel, 1-NN (t from training)", r.jra_nearest),
        ("JRA + DTW kernel, paper vote (top N+1)", r.jra_paper_vote),
        ("JRA + DTW kernel, majority of 3", r.jra_majority),
        ("JRA + DTW kernel, 1-NN, t = 20", r.jra_fixed),
        ("JRA + length-normalised DTW, 1-NN", r.jra_normalized),
        ("JRA resampled to 32 + Euclidean sum", r.jra_resampled),
        ("raw joint coordinates + DTW kernel", r.raw_dtw),
        ("Ball et al. 2012 (z-score 1-NN)", r.ball_nn),
        ("Preis et al. 2012 (Naive Bayes)", r.preis_nb),
        ("Preis et al. 2012 (z-score 1-NN)", r.preis_nn),
    ];
    for (name, acc) in rows {
        println!("{name:<44} {:>7.1}%", 100.0 * acc);
    }
    println!("thresholds chosen on the training folds: {:?}", r.chosen_t);
    println!("accuracy vs threshold t (Fig. 9):");
    for (t, a) in &r.curve {
        println!("  t = {t:>4}: {:>5.1}%", 100.0 * a);
    }
    Ok(())
}
