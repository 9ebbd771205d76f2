//! Paper 05 end to end: generate the synthetic hand-pose set (5 poses, 3 subjects, 3000 frames
//! per class), split it as the paper does (300 test frames per class, 1000 rotated training
//! copies per class), train the class-wise SFA and its four baselines, and print the confusion
//! matrices in the layout of the paper's Tables 3-6; then the rotation-robustness test.
//!
//! Run: `cargo run --release --example sfa_handpose [FRAMES_PER_CLASS [METHODS]]`, METHODS a
//! comma-separated list of `sfa,physical,pca,isomap,global` (default: all).

use wscg::biometrics::sfa::handpose::{
    compare, generate, rotation_robustness, split_protocol, CompareParams, HandposeSynthParams,
    Method,
};

fn main() -> wscg::math::Result<()> {
    let n_per_class = std::env::args()
        .nth(1)
        .map(|s| s.parse::<usize>())
        .transpose()
        .map_err(|e| wscg::math::Error::invalid("FRAMES_PER_CLASS", e.to_string()))?
        .unwrap_or(3000);
    let t = std::time::Instant::now();
    let data = generate(&HandposeSynthParams::default().n_per_class(n_per_class))?;
    let test = (n_per_class / 10).max(1);
    let split = split_protocol(&data, test, n_per_class / 3, 0)?;
    println!(
        "{} frames generated and split in {:.1} s: {} training rows, {} test rows",
        data.len(),
        t.elapsed().as_secs_f64(),
        split.train_y.len(),
        split.test_y.len()
    );
    let cfg = CompareParams::default();
    let methods: Vec<Method> = match std::env::args().nth(2) {
        Some(list) => list
            .split(',')
            .map(Method::parse)
            .collect::<Result<_, _>>()?,
        None => Method::ALL.to_vec(),
    };
    let res = compare(&data, &split, &cfg, &methods, |m| {
        eprintln!("running {}", m.title())
    })?;
    print!("{}", res.format_tables());

    // Rotation robustness: every test frame rotated by +-U(10, 20) degrees, for the model
    // trained with the rotated copies and for one trained on the original frames only.
    let rot = rotation_robustness(
        data.mask_stack()?,
        &split,
        &cfg.sfa,
        res.class_sfa.as_ref(),
        true,
        1,
    )?;
    for (name, acc) in [("with", Some(rot.augmented)), ("without", rot.unaugmented)] {
        if let Some((plain, rotated)) = acc {
            println!(
                "class-wise SFA {name} augmentation: {plain:.2} % on the test frames, \
                 {rotated:.2} % rotated (drop {:.2} pp)",
                plain - rotated
            );
        }
    }
    Ok(())
}
