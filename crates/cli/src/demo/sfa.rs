//! Paper 05 demo: class-wise slow feature analysis against its four baselines on the synthetic
//! hand-pose set (5 poses, 3 subjects, 3000 frames per class, the paper's split and rotation
//! augmentation), in the layout of the paper's Tables 3-6, plus the rotation-robustness test.

use std::path::Path;

use wscg_biometrics::sfa::handpose::{
    compare, generate, rotation_robustness, split_protocol, CompareParams, HandposeSynthParams,
    Method, CLASS_NAMES,
};
use wscg_math::image::Image;
use wscg_math::progress::Progress;
use wscg_math::{Error, Result};

use super::figures::montage;
use super::{Demo, Figure, Report, Row};

/// Registration of this demo.
pub const DEMO: Demo = Demo {
    name: "sfa",
    paper: "05",
    title: "Class-wise slow feature analysis for hand-pose classification",
    run,
};

/// Diagonal means of the paper's Tables 3-6 (%), and the class-wise SFA's per-class row.
const PAPER: [(Method, f64); 4] = [
    (Method::ClassSfa, 97.34),
    (Method::KnnPhysical, 94.60),
    (Method::KnnPca, 82.34),
    (Method::KnnIsomap, 96.72),
];
const PAPER_SFA_PER_CLASS: [f64; 5] = [97.0, 96.7, 98.7, 97.6, 96.7];

fn run(out: &Path, progress: &dyn Progress) -> Result<Report> {
    let mut rep = Report::default();
    let data = rep.time("generate 15000 frames (s)", || {
        generate(&HandposeSynthParams::default())
    })?;
    let split = rep.time("split and augment (s)", || {
        split_protocol(&data, 300, 1000, 0)
    })?;
    // Four frames of each pose, one row per class.
    let mut tiles = Vec::new();
    for c in 0..5 {
        for k in 0..4 {
            let i = c * 3000 + k * 700;
            let m = data.mask(i).ok_or(Error::Empty("frame"))?;
            tiles.push(m.to_image().map(f32::from));
        }
    }
    montage(&tiles, 4, 1)?.save(out.join("hand_poses.png"))?;
    rep.figures.push(Figure {
        file: "hand_poses.png".into(),
        caption: "Synthetic time-of-flight hand poses (rows: FIST, FLAT, INDEX, OPEN, GRAB), \
                  segmented from a simulated amplitude image as in the paper's section 3.2.1"
            .into(),
    });
    progress.begin("methods", Method::ALL.len() as u64);
    let res = compare(
        &data,
        &split,
        &CompareParams::default(),
        &Method::ALL,
        |_| progress.advance(1),
    )?;
    progress.finish();
    // Confusion matrices as heat maps (white = 100 %), in the order of the tables.
    let heat: Vec<Image> = res
        .results
        .iter()
        .map(|r| Image::from_fn(5, 5, |i, j| (r.confusion[(i, j)] / 100.0) as f32))
        .collect::<Result<_>>()?;
    montage(&heat, heat.len(), 12)?.save(out.join("confusion.png"))?;
    rep.figures.push(Figure {
        file: "confusion.png".into(),
        caption: "Confusion matrices (row = true pose, white = 100 %): class-wise SFA, KNN on \
                  physical features, KNN on PCA-35, KNN on 9-D Isomap, full-data-set SFA"
            .into(),
    });
    wscg_math::io::atomic::write(out.join("tables.txt"), res.format_tables())?;
    for r in &res.results {
        let paper = PAPER
            .iter()
            .find(|p| p.0 == r.method)
            .map_or("-".to_string(), |p| format!("{:.2} %", p.1));
        rep.table.push(Row::new(
            format!("{}: diagonal mean", r.method.title()),
            format!("{:.2} %", r.mean()),
            paper,
            "synthetic hand poses, not the paper's recordings",
        ));
        rep.timings
            .push((format!("{} fit (s)", r.method.name()), r.fit_seconds));
        rep.timings.push((
            format!("{} predict 1500 (s)", r.method.name()),
            r.predict_seconds,
        ));
    }
    if let Some(sfa) = res.get(Method::ClassSfa) {
        for (c, (ours, paper)) in sfa.per_class().iter().zip(PAPER_SFA_PER_CLASS).enumerate() {
            rep.table.push(Row::new(
                format!("class-wise SFA, {}", CLASS_NAMES[c]),
                format!("{ours:.1} %"),
                format!("{paper:.1} %"),
                "paper: over 96 % for each class",
            ));
        }
    }
    // Rotation robustness: every test frame rotated by +-U(10, 20) degrees, with the model
    // the comparison fitted.
    let rot = rotation_robustness(
        data.mask_stack()?,
        &split,
        &CompareParams::default().sfa,
        res.class_sfa.as_ref(),
        false,
        1,
    )?;
    rep.table.push(Row::new(
        "class-wise SFA on test frames rotated by +-U(10, 20) degrees",
        format!("{:.2} %", rot.augmented.1),
        "invariance claimed",
        "trained with 1000 rotated copies per class",
    ));
    rep.summary = format!(
        "Paper 05 on synthetic hand poses ({} training rows with rotated copies, {} test \
         rows): class-wise SFA {:.2} % against KNN on physical features {:.2} %, PCA-35 {:.2} \
         %, Isomap {:.2} % and full-data-set SFA {:.2} % (tables.txt has the matrices).",
        res.n_train,
        res.n_test,
        res.get(Method::ClassSfa).map_or(f64::NAN, |r| r.mean()),
        res.get(Method::KnnPhysical).map_or(f64::NAN, |r| r.mean()),
        res.get(Method::KnnPca).map_or(f64::NAN, |r| r.mean()),
        res.get(Method::KnnIsomap).map_or(f64::NAN, |r| r.mean()),
        res.get(Method::GlobalSfa).map_or(f64::NAN, |r| r.mean()),
    );
    Ok(rep)
}
