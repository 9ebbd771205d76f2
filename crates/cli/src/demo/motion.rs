//! Paper 16 demo: predictive walk-and-reach synthesis on the synthetic walker. The Fig. 4
//! comparison (anechoic demixing against PCA over the number of sources), the step-wise
//! qualities, the planner's intervals, and synthesized sequences for several goals and a goal
//! jump, drawn as stick-figure strips and written as BVH.

use std::path::Path;

use wscg_math::progress::Progress;
use wscg_math::{Image, Result};
use wscg_motion::anechoic::{fit_anechoic, AnechoicParams};
use wscg_motion::bvh::write_bvh;
use wscg_motion::matching::match_sources;
use wscg_motion::pca::pca_qualities;
use wscg_motion::skeleton::{bones, forward_kinematics, HIP_HEIGHT};
use wscg_motion::stats::fit_line;
use wscg_motion::stepwise::{fit_stepwise, StepwiseParams};
use wscg_motion::synthesizer::{Frame, MapKind, Synthesizer};
use wscg_motion::walker::{reach_walk, WalkerParams};
use wscg_motion::Action;

use super::figures::{line_plot, Series};
use super::{Demo, Figure, Report, Row};

/// Registration of this demo.
pub const DEMO: Demo = Demo {
    name: "motion",
    paper: "16",
    title: "Predictive walk-and-reach synthesis with learned dynamic primitives",
    run,
};

/// A side view (forward = x, up = y) of poses every `every` frames along the walk, with the
/// drawer front at `goal` marked as a vertical line.
pub fn stick_strip(frames: &[Frame], every: usize, goal: f64) -> Result<Image> {
    let b = bones();
    let mut series = Vec::new();
    let n = frames.len();
    for (f, fr) in frames
        .iter()
        .enumerate()
        .filter(|(f, _)| f % every.max(1) == 0 || *f + 1 == n)
    {
        let p = forward_kinematics(&fr.angles, [0.0, HIP_HEIGHT, fr.root_x]);
        let shade = 0.75 * (1.0 - f as f64 / n.max(1) as f64) as f32;
        let color = match fr.action {
            Action::Step => [0.1, 0.3 + 0.5 * shade, 0.9],
            Action::ShortStep => [0.9, 0.5 + 0.3 * shade, 0.1],
            Action::Reach => [0.8, 0.1, 0.2 + 0.5 * shade],
        };
        for &(a, c) in &b {
            series.push(Series {
                points: vec![(p[a][2], p[a][1]), (p[c][2], p[c][1])],
                color,
            });
        }
    }
    series.push(Series {
        points: vec![(goal, 0.0), (goal, 1.9)],
        color: [0.2, 0.2, 0.2],
    });
    let x_hi = goal + 0.5;
    let width = ((x_hi + 0.5) * 160.0).round() as usize;
    line_plot(
        &series,
        (330, width.clamp(200, 1600)),
        (-0.5, x_hi),
        (-0.05, 2.0),
        (&[0.0, 1.0, 2.0, 3.0, 4.0], &[0.0]),
    )
}

fn run(out: &Path, progress: &dyn Progress) -> Result<Report> {
    let mut rep = Report {
        summary:
            "A synthetic walker (17 joints, 51 exponential-map channels, 5 periodic ground-truth \
                  sources with delays shared over trials, weights smooth in step length and \
                  duration) stands in for the paper's motion capture. Sources are learned by \
                  anechoic demixing in a step-wise regression over the three actions, mapped onto \
                  Hopf oscillators, weights regressed by LWLR; the planner splits the goal \
                  distance and the online synthesizer blends actions at the leader's phase wrap."
                .into(),
        ..Default::default()
    };
    progress.begin("motion demo", 4);
    // Fig. 4: anechoic vs PCA on action-1's periodic part.
    let (_, truth) = reach_walk(&WalkerParams::default().noise(0.0).n_trials(10))?;
    let x = &truth.periodic[0];
    let qp = pca_qualities(x)?;
    let mut qa = Vec::new();
    for j in 1..=6 {
        let m = rep.time(&format!("fit_anechoic J={j} (10 restarts)"), || {
            fit_anechoic(x, &AnechoicParams::default().n_sources(j))
        })?;
        qa.push(m.q);
        rep.table.push(Row::new(
            format!("Q, J = {j}: anechoic (shared delays) / PCA"),
            format!("{:.4} / {:.4}", m.q, qp[j - 1]),
            "",
            "Fig. 4 ordering",
        ));
        if j == 3 {
            // The fitted sources against the walker's three generating ones (up to shift, sign
            // and scale).
            let sims: Vec<String> = match_sources(&m.sources, &truth.sources[..3])?
                .iter()
                .map(|s| format!("{:.4}", s.similarity))
                .collect();
            rep.table.push(Row::new(
                "J = 3: similarity of each generating source to its matched estimate",
                sims.join(" / "),
                "",
                "required: >= 0.95 (0.997 / 0.910 / 0.963 before the orbit-subspace start of run 1)",
            ));
        }
    }
    let pts = |q: &[f64]| {
        q.iter()
            .enumerate()
            .map(|(j, v)| ((j + 1) as f64, *v))
            .collect::<Vec<_>>()
    };
    line_plot(
        &[
            Series {
                points: pts(&qa),
                color: [0.1, 0.3, 0.9],
            },
            Series {
                points: pts(&qp[..6]),
                color: [0.9, 0.3, 0.1],
            },
        ],
        (300, 420),
        (1.0, 6.0),
        (0.4, 1.0),
        (&[2.0, 3.0, 4.0, 5.0], &[0.6, 0.8, 0.9, 0.95]),
    )?
    .save(out.join("fig4_quality.png"))?;
    rep.figures.push(Figure { file: "fig4_quality.png".into(), caption: "Q against the number of sources: anechoic demixing with shared delays (blue) and PCA (orange), noise-free action-1 data (paper Fig. 4)".into() });
    progress.advance(1);

    // Step-wise library on the 40-trial learning set.
    let (data, _) = reach_walk(&WalkerParams::default())?;
    let lib = rep.time("fit_stepwise, 40 trials", || {
        fit_stepwise(&data, &StepwiseParams::default())
    })?;
    rep.table.push(Row::new(
        "Q action 1 (s0 + 3 sources)",
        format!("{:.4}", lib.actions[0].q),
        "0.956",
        "paper Fig. 4 (mocap)",
    ));
    rep.table.push(Row::new(
        "Q all actions (s0 + 5 sources)",
        format!("{:.4}", lib.q_total),
        "0.967",
        "paper Fig. 4 (mocap)",
    ));
    progress.advance(1);

    // Human-like statistics (paper Fig. 2).
    let (human, _) = reach_walk(
        &WalkerParams::default()
            .n_trials(10)
            .human_like(true)
            .seed(3),
    )?;
    let l1: Vec<f64> = human.trials.iter().map(|t| t[0].step_length).collect();
    let l2: Vec<f64> = human.trials.iter().map(|t| t[1].step_length).collect();
    let f1 = fit_line(&human.distances, &l1)?;
    let f2 = fit_line(&human.distances, &l2)?;
    rep.table.push(Row::new(
        "first step vs distance: R2, p",
        format!("{:.2}, {:.3}", f1.r2, f1.p_value),
        "0.08, 0.429",
        "paper Fig. 2 (human)",
    ));
    rep.table.push(Row::new(
        "second step vs distance: R2, p",
        format!("{:.2}, {:.1e}", f2.r2, f2.p_value),
        "0.95, 1.4e-6",
        "paper Fig. 2 (human)",
    ));

    // Synthesis.
    let mut syn = Synthesizer::from_library(lib, MapKind::Lut(1024))?;
    for goal in [2.4, 2.9, 3.84, 4.62] {
        let s = rep.time(&format!("synthesis D = {goal} m at 120 fps"), || {
            syn.run(goal, 120.0, &[], 120.0)
        })?;
        let last = s.frames.last().map_or(0.0, |f| f.root_x);
        let steps = s
            .executed
            .iter()
            .filter(|a| a.action != Action::Reach)
            .count();
        rep.table.push(Row::new(
            format!("D = {goal} m: steps, final distance (m)"),
            format!("{steps}, {:.3}", goal - last),
            "0.60",
            "comfort distance",
        ));
        let file = format!("walk_{goal:.2}.png");
        stick_strip(&s.frames, 12, goal)?.save(out.join(&file))?;
        rep.figures.push(Figure {
            file: file.clone(),
            caption: format!(
                "goal {goal} m: poses every 0.1 s (blue step, orange shortened step, red reach)"
            ),
        });
        write_bvh(
            out.join(format!("walk_{goal:.2}.bvh")),
            &s.bvh_motion(1.0 / 120.0),
        )?;
    }
    progress.advance(1);
    let (base, jump) = syn.run_goal_jump(2.7, 3.5, 0.4, 120.0, 120.0)?;
    let last = jump.frames.last().map_or(0.0, |f| f.root_x);
    rep.table.push(Row::new(
        "goal jump 2.7 -> 3.5 m at 40 %: steps, final distance",
        format!(
            "{} -> {}, {:.3}",
            base.n_steps(),
            jump.n_steps(),
            3.5 - last
        ),
        "extra step, 0.60",
        "paper Fig. 10",
    ));
    stick_strip(&jump.frames, 12, 3.5)?.save(out.join("goal_jump.png"))?;
    rep.figures.push(Figure { file: "goal_jump.png".into(), caption: "the goal moves from 2.7 to 3.5 m at 40 % of the approach: a step is inserted (paper Fig. 10)".into() });
    progress.advance(1);
    Ok(rep)
}
