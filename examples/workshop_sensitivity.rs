//! Paper 07, virtual workshop: how strongly each design factor shows in the virtual
//! observer's features. Renders the hidden reference of acceptance check 10 (radius 26 µm,
//! density 7.3) and the plates 0.30 coded units away along each factor (radius ± 4.5 µm,
//! density ± 0.9), each with several microstructure seeds, and prints every feature's mean and
//! spread over the seeds (floored at 1e-3, as the observer's calibration does), and the
//! change across the window in units of that spread.
//!
//! `cargo run --release --example workshop_sensitivity -- [mono|stereo] [seeds]`

use wscg::raytrace::paint::observer::FEATURE_NAMES;
use wscg::raytrace::paint::{plate_features, Condition, VirtualObserver, WorkshopParams};

/// Half ranges of the coded factors (paper Table 1: radius 15-45 µm, density 3.5-9.5).
const HALF_RANGE: [f64; 2] = [15.0, 3.0];
const HIDDEN: [f64; 2] = [26.0, 7.3];
const WINDOW: f64 = 0.30;

fn main() -> wscg::math::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let condition = match args.get(1).map(String::as_str) {
        Some("stereo") => Condition::Stereo,
        _ => Condition::Mono,
    };
    let seeds: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(8).max(2);
    let cfg = WorkshopParams::default().condition(condition);
    // Log features of one plate over the seeds, per feature (mean, standard deviation): the
    // observer's own calibration, without the just-noticeable-difference floor.
    let stats = |radius: f64, density: f64| -> wscg::math::Result<Vec<(f64, f64)>> {
        let features = (0..seeds)
            .map(|s| plate_features(radius, density, 500 + s, &cfg))
            .collect::<wscg::math::Result<Vec<_>>>()?;
        let o = VirtualObserver::calibrate(&features, 0.0)?;
        Ok(o.mean_log.into_iter().zip(o.std_log).collect())
    };
    println!("{condition:?}, {seeds} seeds per plate; log features, mean ± sd over the seeds");
    for (factor, name) in ["radius (µm)", "density"].iter().enumerate() {
        let at = |coded: f64| {
            let mut p = HIDDEN;
            p[factor] += coded * HALF_RANGE[factor];
            p
        };
        let rows = [at(-WINDOW), at(0.0), at(WINDOW)];
        let feats = rows
            .iter()
            .map(|p| stats(p[0], p[1]))
            .collect::<wscg::math::Result<Vec<_>>>()?;
        println!(
            "\n{name}: {:.2} / {:.2} / {:.2}",
            rows[0][factor], rows[1][factor], rows[2][factor]
        );
        for (k, feature) in FEATURE_NAMES.iter().take(feats[0].len()).enumerate() {
            let [lo, mid, hi] = [feats[0][k], feats[1][k], feats[2][k]];
            let sd = ((lo.1.powi(2) + mid.1.powi(2) + hi.1.powi(2)) / 3.0).sqrt();
            let change = (hi.0 - lo.0) / sd;
            println!(
                "  {feature:<24} {:8.3} ± {:.3}  {:8.3} ± {:.3}  {:8.3} ± {:.3}   change {change:+6.2} sd",
                lo.0, lo.1, mid.0, mid.1, hi.0, hi.1
            );
        }
    }
    Ok(())
}
