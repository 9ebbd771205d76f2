//! `wscg biometrics gait ...`: paper 17 (Kinect gait recognition with joint relative angles
//! and a DTW kernel) on the user's own skeleton recordings.
//!
//! Skeleton files: CSV rows `frame, joint, x, y, z` (joint as Kinect v2 or Kinect v1 name or
//! index, metres), `.npy` arrays `(T, 25, 3)` or `(T, 20, 3)`, or NTU RGB+D `.skeleton` files
//! (`--body` picks the body: the most tracked by default, or a body id).
//!
//! - `enroll GALLERY --out MODEL.json`: `GALLERY` holds one sub-folder of walks per identity
//!   (the folder name is the identity), or files named `<identity>_<anything>.csv|npy`.
//!   Detects each walk's gait cycle, selects the relevant joint pairs and stores the model.
//! - `identify --model MODEL.json WALK...`: the identity and the ranked training walks.
//! - `cycle WALK...`: the detected gait cycle of each walk.
//! - `ucr TRAIN.ts TEST.ts`: 1-NN DTW (on multivariate sets the DTW kernel, or the dependent
//!   DTW with `--multivariate dependent`) on UCR/UEA
//!   `.ts` files, the check that pins our DTW to the archive's published error rates.
//! - `simulate --out DIR`: synthetic Kinect walkers in the layout `enroll` reads.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand, ValueEnum};
use rayon::prelude::*;
use wscg_biometrics::dtw::{nearest, ts_file::read_ts, DtwParams, LocalCost, Multivariate};
use wscg_biometrics::gait::cycle::StartLeg;
use wscg_biometrics::gait::io::{
    read_skeleton_with, write_skeleton_csv, write_skeleton_npy, GaitModelFile,
};
use wscg_biometrics::gait::ntu::{BodyChoice, NtuParams};
use wscg_biometrics::gait::synth::{walkers, SessionRanges};
use wscg_biometrics::gait::{
    detect_gait_cycle, gait_sample, GaitParams, GaitRecognizer, JointSet, SkeletonSeq, Vote,
};
use wscg_math::{Error, Result};

#[derive(Subcommand, Debug)]
pub enum GaitCommand {
    /// Build a recognizer from a gallery of walks (one sub-folder per identity).
    Enroll {
        /// Gallery folder.
        gallery: PathBuf,
        /// Model file to write (JSON).
        #[arg(long)]
        out: PathBuf,
        #[command(flatten)]
        params: GaitArgs,
    },
    /// Identify walks with an enrolled model.
    Identify {
        /// Model written by `enroll`.
        #[arg(long)]
        model: PathBuf,
        /// Skeleton files (.csv, .npy or NTU .skeleton).
        #[arg(required = true)]
        walks: Vec<PathBuf>,
        /// Ranked training walks printed per walk.
        #[arg(long, default_value_t = 5)]
        top: usize,
        #[command(flatten)]
        body: BodyArgs,
    },
    /// Print the detected gait cycle (start, middle, end frames) of walks.
    Cycle {
        /// Skeleton files (.csv, .npy or NTU .skeleton).
        #[arg(required = true)]
        walks: Vec<PathBuf>,
        /// Frame rate of the recordings.
        #[arg(long, default_value_t = 30.0)]
        fps: f64,
        /// Which leg opens the cycle.
        #[arg(long, value_enum, default_value_t = LegArg::Left)]
        start_leg: LegArg,
        #[command(flatten)]
        body: BodyArgs,
    },
    /// 1-NN classification of a UCR/UEA test set by DTW (multivariate: the DTW kernel, or the
    /// dependent DTW with `--multivariate dependent`).
    Ucr {
        /// Training set (.ts).
        train: PathBuf,
        /// Test set (.ts).
        test: PathBuf,
        /// Local cost (the archive's published rates use squared).
        #[arg(long, value_enum, default_value_t = CostArg::Squared)]
        cost: CostArg,
        /// Sakoe-Chiba band half-width (samples); full grid when absent.
        #[arg(long)]
        window: Option<usize>,
        /// Multivariate DTW: `independent` (each channel warps on its own, distances summed:
        /// the DTW kernel of eq. 6, DTW_I) or `dependent` (one warp path, cost between whole
        /// frames: DTW_D, the UEA archive's usual 1-NN baseline). Same O(n m channels) cost;
        /// dependent needs every channel of a case to have one length.
        #[arg(long, value_enum, default_value_t = MultivariateArg::Independent)]
        multivariate: MultivariateArg,
    },
    /// Write synthetic walks: DIR/<subject>/walk_<k>.csv and DIR/truth.csv.
    Simulate {
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Subjects.
        #[arg(long, default_value_t = 20)]
        subjects: usize,
        /// Walks per subject.
        #[arg(long, default_value_t = 3)]
        sessions: usize,
        /// Seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// File format.
        #[arg(long, value_enum, default_value_t = FormatArg::Csv)]
        format: FormatArg,
        /// Joints per skeleton: 25 (Kinect v2) or 20 (Kinect v1 names, without Neck, HandTip
        /// and Thumb).
        #[arg(long, default_value_t = 25)]
        joints: usize,
    },
}

/// The body taken from NTU RGB+D `.skeleton` files.
#[derive(Args, Debug, Clone)]
pub struct BodyArgs {
    /// Body of NTU RGB+D .skeleton files: `most-tracked` or a body id.
    #[arg(long, default_value = "most-tracked")]
    body: String,
}

impl BodyArgs {
    fn read(&self, path: &Path, fps: f64) -> Result<SkeletonSeq> {
        let ntu = NtuParams::default().body(BodyChoice::parse(&self.body)?);
        read_skeleton_with(path, fps, &ntu)
    }
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum LegArg {
    /// The left foot steps forward first (default).
    Left,
    /// The right foot steps forward first.
    Right,
    /// Either (the paper's rule as printed).
    Any,
}

impl From<LegArg> for StartLeg {
    fn from(l: LegArg) -> Self {
        match l {
            LegArg::Left => StartLeg::Left,
            LegArg::Right => StartLeg::Right,
            LegArg::Any => StartLeg::Any,
        }
    }
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum CostArg {
    /// |a - b| (the paper's).
    Abs,
    /// (a - b)^2 (UCR/UEA, dtaidistance).
    Squared,
}

impl From<CostArg> for LocalCost {
    fn from(c: CostArg) -> Self {
        match c {
            CostArg::Abs => LocalCost::Abs,
            CostArg::Squared => LocalCost::Squared,
        }
    }
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MultivariateArg {
    /// Per-channel DTW, summed (eq. 6; DTW_I).
    Independent,
    /// One warp path for all channels (DTW_D).
    Dependent,
}

impl From<MultivariateArg> for Multivariate {
    fn from(m: MultivariateArg) -> Self {
        match m {
            MultivariateArg::Independent => Multivariate::Independent,
            MultivariateArg::Dependent => Multivariate::Dependent,
        }
    }
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormatArg {
    /// frame,joint,x,y,z rows.
    Csv,
    /// (T, J, 3) float64 (J = 25 or 20 joints).
    Npy,
}

/// Pipeline options of `enroll`.
#[derive(Args, Debug, Clone)]
pub struct GaitArgs {
    /// Frame rate of the recordings.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Relevance threshold t: keep joint pairs occupying at least this many histogram bins.
    #[arg(long, default_value_t = 20.0)]
    min_bins: f64,
    /// Histogram bin width, degrees.
    #[arg(long, default_value_t = 1.0)]
    bin_deg: f64,
    /// Vote: nearest, paper (top #classes + 1) or majority:K.
    #[arg(long, default_value = "nearest")]
    vote: String,
    /// Local cost of the DTW.
    #[arg(long, value_enum, default_value_t = CostArg::Abs)]
    cost: CostArg,
    /// Sakoe-Chiba band half-width (samples); full grid when absent.
    #[arg(long)]
    window: Option<usize>,
    /// Which leg opens the gait cycle.
    #[arg(long, value_enum, default_value_t = LegArg::Left)]
    start_leg: LegArg,
    #[command(flatten)]
    body: BodyArgs,
}

impl GaitArgs {
    fn params(&self) -> Result<GaitParams> {
        let mut p = GaitParams::default()
            .min_bins(self.min_bins)
            .vote(Vote::parse(&self.vote)?);
        p.hist.bin_deg = self.bin_deg;
        p.hist.validate()?;
        p.dtw = DtwParams::default()
            .cost(self.cost.into())
            .window(self.window)
            .normalize(false);
        p.cycle.start_leg = self.start_leg.into();
        Ok(p)
    }
}

fn is_skeleton_file(p: &Path) -> bool {
    p.is_file()
        && p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
            ["csv", "npy", "skeleton"]
                .iter()
                .any(|x| e.eq_ignore_ascii_case(x))
        })
}

fn sorted_entries(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map_err(|e| Error::io(dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    v.sort();
    Ok(v)
}

/// Walk files of a gallery with their identity names.
fn gallery_files(root: &Path) -> Result<Vec<(String, PathBuf)>> {
    let mut out = Vec::new();
    for p in sorted_entries(root)? {
        if p.is_dir() {
            let id = p
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            for f in sorted_entries(&p)?
                .into_iter()
                .filter(|f| is_skeleton_file(f))
            {
                out.push((id.clone(), f));
            }
        } else if is_skeleton_file(&p) {
            let stem = p
                .file_stem()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let id = stem.split('_').next().unwrap_or(&stem).to_string();
            out.push((id, p));
        }
    }
    if out.is_empty() {
        return Err(Error::invalid(
            "gallery",
            format!(
                "{} holds no skeleton files (.csv or .npy) in identity sub-folders or named \
                 <identity>_<k>.csv",
                root.display()
            ),
        ));
    }
    Ok(out)
}

/// Runs a `wscg biometrics gait` command.
pub fn run(cmd: GaitCommand) -> Result<()> {
    match cmd {
        GaitCommand::Enroll {
            gallery,
            out,
            params,
        } => {
            crate::commands::overwrite::check_file("out", &out, [&gallery])?;
            let p = params.params()?;
            let files = gallery_files(&gallery)?;
            let mut identities: Vec<String> = files.iter().map(|f| f.0.clone()).collect();
            identities.sort();
            identities.dedup();
            let mut samples = Vec::new();
            let mut labels = Vec::new();
            for (id, f) in &files {
                let walk = params.body.read(f, params.fps)?;
                let s = gait_sample(&walk, &p)
                    .map_err(|e| Error::invalid("gallery", format!("{}: {e}", f.display())))?;
                samples.push(s.jra);
                labels.push(identities.iter().position(|i| i == id).unwrap_or(0) as u32);
            }
            let rec = GaitRecognizer::fit_samples(&samples, &labels, &p)?;
            println!(
                "enrolled {} walks of {} identities; {} of {} joint pairs selected (t = {})",
                samples.len(),
                identities.len(),
                rec.pairs.len(),
                samples.iter().map(|s| s.pairs.len()).max().unwrap_or(0),
                p.min_bins
            );
            let files = files.iter().map(|f| f.1.display().to_string()).collect();
            GaitModelFile::new(params.fps, identities, files, rec).write(&out)?;
            println!("wrote {}", out.display());
            Ok(())
        }
        GaitCommand::Identify {
            model,
            walks,
            top,
            body,
        } => {
            let m = GaitModelFile::read(&model)?;
            for w in &walks {
                let seq = body.read(w, m.fps)?;
                let pr = m.recognizer.predict(&seq)?;
                let name = |l: u32| {
                    m.identities
                        .get(l as usize)
                        .cloned()
                        .unwrap_or_else(|| l.to_string())
                };
                let c = pr.cycle.as_ref();
                println!(
                    "{}: {} (cycle frames {}..={})",
                    w.display(),
                    name(pr.label),
                    c.map_or(0, |c| c.start),
                    c.map_or(0, |c| c.end)
                );
                for (rank, (i, l, d)) in pr.ranked.iter().take(top).enumerate() {
                    let file = m.files.get(*i).map_or("", String::as_str);
                    println!(
                        "  {:>3}. {:<20} delta {:>12.4}  {file}",
                        rank + 1,
                        name(*l),
                        d
                    );
                }
            }
            Ok(())
        }
        GaitCommand::Cycle {
            walks,
            fps,
            start_leg,
            body,
        } => {
            let mut p = GaitParams::default().cycle;
            p.start_leg = start_leg.into();
            for w in &walks {
                let seq = body.read(w, fps)?;
                let c = detect_gait_cycle(&seq, &p)?;
                println!(
                    "{}: start {} mid {} end {} ({} frames, {:.2} s; first step {:?}; minima {:?})",
                    w.display(),
                    c.start,
                    c.mid,
                    c.end,
                    c.len(),
                    (c.end - c.start) as f64 / fps,
                    c.first_step.unwrap_or(StartLeg::Any),
                    c.minima
                );
            }
            Ok(())
        }
        GaitCommand::Ucr {
            train,
            test,
            cost,
            window,
            multivariate,
        } => {
            let (tr, te) = (read_ts(&train)?, read_ts(&test)?);
            let p = DtwParams::default()
                .cost(cost.into())
                .window(window)
                .normalize(false)
                .multivariate(multivariate.into());
            let (ltr, lte) = (tr.labels.clone(), te.labels.clone());
            if ltr.is_empty() || lte.is_empty() {
                return Err(Error::invalid("ts", "both files need class labels"));
            }
            // One 1-NN search (with early abandoning) per test case, in parallel.
            let correct: usize = te
                .series
                .par_iter()
                .zip(lte.par_iter())
                .map(|(q, l)| nearest(q, &tr.series, &p).map(|(k, _)| usize::from(&ltr[k] == l)))
                .collect::<Result<Vec<usize>>>()?
                .into_iter()
                .sum();
            println!(
                "{}: 1-NN DTW ({cost:?} cost, window {window:?}, {multivariate:?}): {correct}/{} \
                 correct, error {:.4}",
                if te.problem.is_empty() {
                    "test"
                } else {
                    &te.problem
                },
                lte.len(),
                1.0 - correct as f64 / lte.len() as f64
            );
            Ok(())
        }
        GaitCommand::Simulate {
            out,
            subjects,
            sessions,
            seed,
            format,
            joints,
        } => {
            if subjects == 0 || sessions == 0 {
                return Err(Error::invalid(
                    "subjects",
                    "needs at least one subject and one session",
                ));
            }
            let set = walkers(subjects, sessions, &SessionRanges::default(), seed)?;
            let set = match JointSet::for_count(joints) {
                Ok(JointSet::KinectV1) => set.to_kinect_v1(),
                Ok(JointSet::KinectV2) => set,
                Err(_) => {
                    return Err(Error::invalid(
                        "joints",
                        format!("must be 25 (Kinect v2) or 20 (Kinect v1), got {joints}"),
                    ))
                }
            };
            std::fs::create_dir_all(&out).map_err(|e| Error::io(&out, e))?;
            let mut truth =
                String::from("subject,walk,file,speed,heading_deg,walk_frames,minima\n");
            for (i, (w, t)) in set.walks.iter().zip(&set.truth).enumerate() {
                let dir = out.join(format!("s{:02}", t.subject));
                std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
                let k = set.session_index[i];
                let file = match format {
                    FormatArg::Csv => dir.join(format!("walk_{k}.csv")),
                    FormatArg::Npy => dir.join(format!("walk_{k}.npy")),
                };
                save(&file, w, format)?;
                let s = &set.sessions[i];
                let minima: Vec<String> = t.minima.iter().map(usize::to_string).collect();
                truth.push_str(&format!(
                    "s{:02},{k},{},{:.3},{:.1},{},{}\n",
                    t.subject,
                    file.display(),
                    s.speed,
                    s.heading_deg,
                    t.walk_frames,
                    minima.join(" ")
                ));
            }
            let tp = out.join("truth.csv");
            wscg_math::io::atomic::write(&tp, truth)?;
            println!(
                "wrote {} walks of {subjects} subjects to {}",
                set.walks.len(),
                out.display()
            );
            Ok(())
        }
    }
}

fn save(path: &Path, w: &SkeletonSeq, format: FormatArg) -> Result<()> {
    match format {
        FormatArg::Csv => write_skeleton_csv(path, w),
        FormatArg::Npy => write_skeleton_npy(path, w),
    }
}
