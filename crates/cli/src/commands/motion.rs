//! `wscg motion`: paper 16 (predictive walk-and-reach synthesis) on the user's own data.
//!
//! Training data folder:
//! - `angles.npy`: joint angles of shape `[R, 3, I, N]` (trials, the three actions — normal
//!   step, shortened step, reach —, exponential-map channels, samples per time-normalised
//!   action);
//! - `steps.csv`: header `trial,action,step_length,duration`, one row per trial and action
//!   (`action` 1, 2 or 3; for the reach, `step_length` is the length of the step before it);
//! - `root.npy` (optional): pelvis forward travel since the action's start, `[R, 3, N]`.
//!
//! `wscg motion make-data DIR` writes the synthetic walker in this format. Synthesis writes BVH
//! (17-joint skeleton, 51 channels) and a stick-figure strip (PNG).

use std::path::PathBuf;

use crate::demo::motion::stick_strip;
use clap::{Args, Subcommand, ValueEnum};
use wscg_math::{npy, Error, Result};
use wscg_motion::anechoic::AnechoicParams;
use wscg_motion::bvh::{retarget, write_bvh, JointMap, RetargetParams};
use wscg_motion::bvh_file::read_bvh_file;
use wscg_motion::dataset::Dataset;
use wscg_motion::map::SvrMapParams;
use wscg_motion::skeleton::N_CHANNELS;
use wscg_motion::stepwise::{fit_stepwise, ActionLibrary, StepwiseParams};
use wscg_motion::synthesizer::{MapKind, Synthesizer};
use wscg_motion::walker::{reach_walk, WalkerParams};
use wscg_motion::Planner;
use wscg_motion::{read_dataset, write_dataset};

#[derive(Subcommand, Debug)]
pub enum MotionCommand {
    /// Write the synthetic walker's training set (angles.npy, steps.csv, root.npy) to DIR.
    MakeData(MakeDataArgs),
    /// Learn sources, delays and weights from a training folder; print Q per action and write
    /// sources.npy ([J, N]) and delays.npy ([I, J]) to --out.
    Learn(LearnArgs),
    /// Plan the steps for a goal distance.
    Plan {
        /// Pelvis-to-drawer distance (metres).
        #[arg(long)]
        goal: f64,
    },
    /// Learn (from --data, or the synthetic walker) and synthesize a walk-and-reach sequence.
    Synth(SynthArgs),
    /// Read a BVH file of any skeleton (CMU, Mixamo, or any names with --joint-map), map it
    /// onto the model's 17 joints and write it as the model's BVH (and optionally .npy).
    ImportBvh(ImportBvhArgs),
}

#[derive(Args, Debug)]
pub struct ImportBvhArgs {
    /// BVH file to read (only read).
    pub input: PathBuf,
    /// Joint map: `auto` (the model's names, then CMU's, then Mixamo's), `model`, `cmu`,
    /// `mixamo`, or a JSON file `{"model joint": "file joint", ...}`.
    #[arg(long, default_value = "auto")]
    pub joint_map: String,
    /// File units per metre (100: centimetres; 39.37: inches).
    #[arg(long, default_value_t = 100.0)]
    pub units_per_metre: f64,
    /// Output BVH of the model's skeleton.
    #[arg(long, default_value = "imported.bvh")]
    pub out: PathBuf,
    /// Also write the joint angles as .npy `[T, 51]`.
    #[arg(long)]
    pub npy: Option<PathBuf>,
}

/// The joint map named by `--joint-map` (`auto` is `None`).
fn joint_map(arg: &str) -> Result<Option<JointMap>> {
    match arg {
        "auto" => Ok(None),
        "model" | "cmu" | "mixamo" => JointMap::builtin(arg).map(Some),
        path => JointMap::read_json(path).map(Some),
    }
}

#[derive(Args, Debug)]
pub struct MakeDataArgs {
    /// Output folder.
    pub dir: PathBuf,
    /// Number of trials.
    #[arg(long, default_value_t = 40)]
    pub trials: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Noise as a fraction of each channel's RMS.
    #[arg(long, default_value_t = 0.01)]
    pub noise: f64,
}

#[derive(Args, Debug)]
pub struct LearnArgs {
    /// Training folder (angles.npy, steps.csv, optional root.npy); only read.
    pub data: PathBuf,
    /// Output folder for sources.npy and delays.npy.
    #[arg(long, default_value = "motion-model")]
    pub out: PathBuf,
    /// Demixing restarts.
    #[arg(long, default_value_t = 10)]
    pub restarts: usize,
    /// Grid points per period of the per-channel delay search after the demixing sweeps
    /// (0: off; otherwise 8-4096).
    #[arg(long, default_value_t = 128)]
    pub delay_search: usize,
}

/// State maps of the synthesizer.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MapName {
    /// Phase lookup table (fast).
    Lut,
    /// Fourier series at the oscillator angle.
    Fourier,
    /// ε-SVR, as in the paper.
    Svr,
}

#[derive(Args, Debug)]
pub struct SynthArgs {
    /// Initial pelvis-to-drawer distance (metres).
    #[arg(long)]
    pub goal: f64,
    /// Goal changes `TIME:DISTANCE` (seconds, metres); TIME may also be a fraction of the
    /// unchanged approach written as `40%`. Repeatable.
    #[arg(long = "change")]
    pub changes: Vec<String>,
    /// Training folder (default: the synthetic walker).
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Output BVH file.
    #[arg(long, default_value = "walk.bvh")]
    pub out: PathBuf,
    /// Also write the joint angles as .npy `[T, 51]`.
    #[arg(long)]
    pub npy: Option<PathBuf>,
    /// Also write a stick-figure strip (PNG).
    #[arg(long)]
    pub png: Option<PathBuf>,
    /// Frames per second.
    #[arg(long, default_value_t = 120.0)]
    pub fps: f64,
    /// State maps.
    #[arg(long, value_enum, default_value = "lut")]
    pub map: MapName,
}

fn learn(data: &Dataset, restarts: usize, delay_search: usize) -> Result<ActionLibrary> {
    let cfg = StepwiseParams::default().demix(
        AnechoicParams::default()
            .restarts(restarts)
            .delay_search(delay_search),
    );
    fit_stepwise(data, &cfg)
}

fn parse_change(s: &str, approach: Option<f64>) -> Result<(f64, f64)> {
    let bad = || {
        Error::invalid(
            "change",
            format!("expected TIME:DISTANCE or PERCENT%:DISTANCE, got `{s}`"),
        )
    };
    let (t, d) = s.split_once(':').ok_or_else(bad)?;
    let d: f64 = d.trim().parse().map_err(|_| bad())?;
    let t = match t.trim().strip_suffix('%') {
        Some(p) => p.trim().parse::<f64>().map_err(|_| bad())? / 100.0 * approach.unwrap_or(0.0),
        None => t.trim().parse().map_err(|_| bad())?,
    };
    Ok((t, d))
}

pub fn run(cmd: MotionCommand) -> Result<()> {
    match cmd {
        MotionCommand::MakeData(a) => {
            let (data, _) = reach_walk(
                &WalkerParams::default()
                    .n_trials(a.trials)
                    .seed(a.seed)
                    .noise(a.noise),
            )?;
            write_dataset(&a.dir, &data)?;
            println!(
                "wrote {} trials x 3 actions x {} channels x {} samples to {}",
                data.trials.len(),
                data.n_channels,
                data.n_samples,
                a.dir.display()
            );
            Ok(())
        }
        MotionCommand::Learn(a) => {
            crate::commands::overwrite::check_folder("out", &a.out, [&a.data])?;
            let data = read_dataset(&a.data)?;
            let lib = learn(&data, a.restarts, a.delay_search)?;
            for (k, f) in lib.actions.iter().enumerate() {
                println!(
                    "action {}: Q = {:.4} ({} sources + s0)",
                    k + 1,
                    f.q,
                    f.n_sources
                );
            }
            println!("all actions: Q = {:.4}", lib.q_total);
            std::fs::create_dir_all(&a.out).map_err(|e| Error::io(&a.out, e))?;
            let n = lib.n_samples;
            let src: Vec<f64> = lib.sources.iter().flat_map(|s| s.sample(n, 0.0)).collect();
            npy::write_f64(a.out.join("sources.npy"), &[lib.n_sources(), n], &src)?;
            npy::write_f64(
                a.out.join("delays.npy"),
                &[lib.n_channels, lib.n_sources()],
                &lib.delays,
            )?;
            println!("wrote sources.npy and delays.npy to {}", a.out.display());
            Ok(())
        }
        MotionCommand::Plan { goal } => {
            let plan = Planner::default().plan(goal)?;
            if plan.too_short {
                println!("goal {goal} m is too close for a step: reach only");
            }
            for p in &plan.actions {
                println!("{:?}\t{:.4} m", p.action, p.length);
            }
            if plan.violation > 0.0 {
                println!(
                    "(no plan fits the trained step ranges; largest violation {:.3} m)",
                    plan.violation
                );
            }
            Ok(())
        }
        MotionCommand::Synth(a) => {
            let outputs = [
                ("out", Some(&a.out)),
                ("npy", a.npy.as_ref()),
                ("png", a.png.as_ref()),
            ];
            for (arg, out) in outputs {
                if let Some(out) = out {
                    crate::commands::overwrite::check_file(arg, out, &a.data)?;
                }
            }
            let data = match &a.data {
                Some(d) => read_dataset(d)?,
                None => reach_walk(&WalkerParams::default())?.0,
            };
            let lib = learn(&data, 10, AnechoicParams::default().delay_search)?;
            if lib.n_channels != N_CHANNELS {
                return Err(Error::invalid(
                    "data",
                    format!(
                        "BVH export needs the 17-joint skeleton's {N_CHANNELS} channels, got {}",
                        lib.n_channels
                    ),
                ));
            }
            let map = match a.map {
                MapName::Lut => MapKind::Lut(1024),
                MapName::Fourier => MapKind::Fourier,
                MapName::Svr => MapKind::Svr(SvrMapParams::default()),
            };
            let mut syn = Synthesizer::from_library(lib, map)?;
            let approach = if a.changes.iter().any(|c| c.contains('%')) {
                syn.run(a.goal, a.fps, &[], 600.0)?.approach_time()
            } else {
                None
            };
            let changes: Vec<(f64, f64)> = a
                .changes
                .iter()
                .map(|c| parse_change(c, approach))
                .collect::<Result<_>>()?;
            let s = syn.run(a.goal, a.fps, &changes, 600.0)?;
            write_bvh(&a.out, &s.bvh_motion(1.0 / a.fps))?;
            if let Some(p) = &a.npy {
                let flat: Vec<f64> = s
                    .frames
                    .iter()
                    .flat_map(|f| f.angles.iter().copied())
                    .collect();
                npy::write_f64(p, &[s.frames.len(), N_CHANNELS], &flat)?;
            }
            let goal = changes.last().map_or(a.goal, |c| c.1);
            if let Some(p) = &a.png {
                stick_strip(&s.frames, (a.fps / 10.0).round().max(1.0) as usize, goal)?.save(p)?;
            }
            let last = s.frames.last().map_or(0.0, |f| f.root_x);
            let plan: Vec<String> = s
                .executed
                .iter()
                .map(|p| format!("{:?} {:.3}", p.action, p.length))
                .collect();
            println!("actions: {}", plan.join(", "));
            println!(
                "{} frames ({:.2} s), final pelvis-to-goal distance {:.3} m",
                s.frames.len(),
                s.frames.len() as f64 / a.fps,
                goal - last
            );
            println!("wrote {}", a.out.display());
            Ok(())
        }
        MotionCommand::ImportBvh(a) => {
            let file = read_bvh_file(&a.input)?;
            let orders: Vec<String> = file
                .joints
                .iter()
                .map(|j| j.rotation_order())
                .filter(|o| !o.is_empty())
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            println!(
                "{}: {} joints, {} frames at {:.2} fps, rotation orders {}",
                a.input.display(),
                file.joints.len(),
                file.frames.len(),
                1.0 / file.frame_time,
                orders.join(", ")
            );
            let p = RetargetParams::default()
                .joint_map(joint_map(&a.joint_map)?)
                .units_per_metre(a.units_per_metre);
            p.validate()?;
            let m = retarget(&file, &p).map_err(|e| Error::format(&a.input, e.to_string()))?;
            write_bvh(&a.out, &m)?;
            if let Some(p) = &a.npy {
                npy::write_f64(p, &[m.angles.len(), N_CHANNELS], &m.angles.concat())?;
            }
            println!("wrote {}", a.out.display());
            Ok(())
        }
    }
}
