//! Paper 14 demo: occlusion detection and index-based ear recognition on synthetic ears
//! with exact occluder masks (the WPUT database is not redistributable): CMC curves of the
//! four score rules and the whole-ear baseline (Figs. 11-12), rank-1 per estimated
//! occlusion (Fig. 13), the occlusion estimate against the truth, and detected masks.

use std::path::Path;

use wscg_biometrics::ear::protocol::{evaluate, Evaluation};
use wscg_biometrics::ear::synth::{self, EarSet, EarSynthParams, OcclusionKind};
use wscg_biometrics::ear::{detect_occlusion, normalise, EarParams, ScoreRule};
use wscg_math::progress::Progress;
use wscg_math::{Image, Result};

use super::figures::{line_plot, montage, Series};
use super::{Demo, Figure, Report, Row};

/// Registration of this demo.
pub const DEMO: Demo = Demo {
    name: "ear",
    paper: "14",
    title: "Occlusion detection and index-based ear recognition",
    run,
};

const COLORS: [[f32; 3]; 6] = [
    [0.85, 0.1, 0.1],
    [0.1, 0.3, 0.85],
    [0.1, 0.6, 0.2],
    [0.95, 0.55, 0.0],
    [0.6, 0.2, 0.7],
    [0.2, 0.2, 0.2],
];

fn to_f32(img: &Image<u8>) -> Image {
    img.map(|v| v as f32 / 255.0)
}

/// Rows and CMC figure of one evaluation.
fn cmc_section(
    out: &Path,
    rep: &mut Report,
    ev: &Evaluation,
    label: &str,
    file: &str,
) -> Result<()> {
    let paper = [73.0, 65.0, 57.0, 51.0];
    for (k, rule) in ScoreRule::ALL.iter().enumerate() {
        rep.table.push(Row::new(
            format!("{label}: rank-1 %, {}", rule.name()),
            format!("{:.1}", 100.0 * ev.cmc[k][0]),
            paper.get(k).map_or(String::new(), |v| format!("{v:.0}")),
            if k < 4 {
                "Fig. 11 (WPUT)"
            } else {
                "eq. 18 as printed"
            },
        ));
    }
    rep.table.push(Row::new(
        format!("{label}: rank-1 %, whole-ear Haar baseline"),
        format!("{:.1}", 100.0 * ev.baseline_cmc[0]),
        "60",
        "Fig. 12 (WPUT)",
    ));
    rep.table.push(Row::new(
        format!("{label}: rank-10 %, block-wise max"),
        format!("{:.1}", 100.0 * ev.cmc_of(ScoreRule::BlockwiseMax)[9]),
        "91",
        "Fig. 12 (WPUT)",
    ));
    let mut series: Vec<Series> = ev
        .cmc
        .iter()
        .take(4)
        .zip(COLORS)
        .map(|(c, color)| Series {
            points: c
                .iter()
                .enumerate()
                .map(|(r, &v)| ((r + 1) as f64, v))
                .collect(),
            color,
        })
        .collect();
    series.push(Series {
        points: ev
            .baseline_cmc
            .iter()
            .enumerate()
            .map(|(r, &v)| ((r + 1) as f64, v))
            .collect(),
        color: COLORS[5],
    });
    line_plot(
        &series,
        (300, 420),
        (1.0, 10.0),
        (0.0, 1.0),
        (&[2.0, 4.0, 6.0, 8.0], &[0.2, 0.4, 0.6, 0.8]),
    )?
    .save(out.join(file))?;
    rep.figures.push(Figure {
        file: file.into(),
        caption: format!(
            "{label}: CMC, rank 1 to 10 (grid every 2) against identification rate (0 to 1, \
             grid every 0.2). Red block-wise max, blue overall max, green block-wise mean, \
             orange overall mean, black the whole-ear Haar baseline."
        ),
    });
    Ok(())
}

fn run(out: &Path, progress: &dyn Progress) -> Result<Report> {
    std::fs::create_dir_all(out).map_err(|e| wscg_math::Error::io(out, e))?;
    let mut rep = Report::default();
    let cfg = EarSynthParams::default();
    // The paper's whole-probe equalisation next to the default (equalised on the skin).
    let skin_eq = EarParams::default();
    let p = skin_eq.clone().equalize_on_skin(false);
    progress.begin("synthetic ears", 2);
    let gen = |kind, seed| synth::generate(100, 3, kind, seed, &cfg, &p);
    let colour: EarSet = rep.time("generate 100 subjects + 300 occluded probes", || {
        gen(
            OcclusionKind::Colour {
                min_pct: 10.0,
                max_pct: 50.0,
            },
            1407,
        )
    })?;
    progress.advance(1);
    let wide: EarSet = gen(
        OcclusionKind::Colour {
            min_pct: 0.0,
            max_pct: 70.0,
        },
        1401,
    )?;
    progress.advance(1);
    progress.begin("identification", 3);
    let ev_paper = rep.time("identify 300 probes, all rules + baseline", || {
        evaluate(&colour, &p, 10)
    })?;
    progress.advance(1);
    let ev_skin = evaluate(&colour, &skin_eq, 10)?;
    progress.advance(1);
    let ev_wide = evaluate(&wide, &skin_eq, 10)?;
    progress.advance(1);
    cmc_section(
        out,
        &mut rep,
        &ev_paper,
        "occluders 10-50 %, paper's pre-processing (equalize_on_skin off)",
        "cmc_paper.png",
    )?;
    cmc_section(
        out,
        &mut rep,
        &ev_skin,
        "occluders 10-50 %, equalised on skin (default)",
        "cmc_skin.png",
    )?;
    let fig13 = [
        (0.0, 10.0, "85 (at ~10 %)"),
        (20.0, 30.0, ""),
        (30.0, 40.0, "~80 (at 30 %)"),
        (50.0, 60.0, "67 (at 50 %)"),
    ];
    let bins = ev_wide.degradation(
        ScoreRule::BlockwiseMax,
        &[0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0],
    );
    for (lo, hi, n, r1) in bins {
        let reference = fig13.iter().find(|f| f.0 == lo).map_or("", |f| f.2);
        rep.table.push(Row::new(
            format!("rank-1 % at estimated occlusion {lo:.0}-{hi:.0} %"),
            format!("{:.1} ({n} probes)", 100.0 * r1),
            reference,
            "Fig. 13 (WPUT); equalised on skin",
        ));
    }
    rep.table.push(Row::new(
        "probes rejected (E > 60 %), occluders 0-70 %",
        format!("{:.1} %", 100.0 * ev_wide.rejection_rate()),
        "",
        "reacquire; never ranked",
    ));
    let errs: Vec<f64> = ev_wide
        .outcomes
        .iter()
        .filter_map(|o| o.true_pct.map(|t| (o.estimated_pct - t).abs()))
        .collect();
    let within = errs.iter().filter(|&&e| e <= 7.5).count() as f64 / errs.len() as f64;
    rep.table.push(Row::new(
        "occlusion estimate within 7.5 points of the truth",
        format!("{:.1} %", 100.0 * within),
        ">= 90 %",
        "synthetic occluders with known extent; mean error shown in the summary",
    ));

    // Probes and their detected skin masks at the normalised size.
    let mut tiles = Vec::new();
    for pr in colour.probes.iter().step_by(50).take(6) {
        let small = normalise(&pr.image.rgb, &p)?;
        let rep_o = detect_occlusion(&pr.image.rgb, &p)?;
        tiles.push(to_f32(&small));
        let mask = rep_o.skin_mask.map(|v| v as f32);
        let mut rgb = Vec::with_capacity(mask.data().len() * 3);
        for (i, &m) in mask.data().iter().enumerate() {
            let block = (i / p.width / p.block) * (p.width / p.block) + (i % p.width) / p.block;
            let keep = rep_o.block_unoccluded[block];
            rgb.extend_from_slice(&[
                m,
                if keep { m } else { 0.5 * m },
                if keep { m } else { 0.3 },
            ]);
        }
        tiles.push(Image::new(p.height, p.width, 3, rgb)?);
    }
    montage(&tiles, 4, 2)?.save(out.join("probes.png"))?;
    rep.figures.push(Figure {
        file: "probes.png".into(),
        caption: "Occluded probes (normalised to 100 x 80) and their detected skin masks after \
                  closing and hole filling; occluded blocks tinted"
            .into(),
    });
    let mean_err = errs.iter().sum::<f64>() / errs.len() as f64;
    rep.summary = format!(
        "100 synthetic subjects, one clean enrolment each, 3 independent probe captures each \
         with a non-skin colour occluder over 10-50 % of the blocks (and a second set over \
         0-70 % for the degradation curve). Identification against the 100 templates with the \
         nine one-block shifts; CMC over accepted probes. Mean occlusion-estimate error {:.2} \
         points. The paper equalises the whole probe before detecting the occlusion; on these \
         ears the occluder then shifts the grey levels of the visible ear and the index-based \
         match loses to the whole-ear baseline. The default equalises each probe on its \
         detected skin instead (equalize_on_skin, on by default; off is the paper's); both \
         cost one histogram pass, so the two CMCs are shown at equal cost.",
        mean_err
    );
    Ok(rep)
}
