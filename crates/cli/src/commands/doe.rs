//! `wscg doe`: paper 07's study statistics on the user's own designs and scores.
//!
//! `design` prints a central composite design (coded, or physical with `--low/--high`) as
//! CSV; `fit` reads a CSV of runs (factor columns, then the response in the last column) and
//! prints the second-order response surface with PRESS, predicted R² and the canonical
//! analysis; `analyze` reads a perceptual study's scores (one row per subject, condition and
//! stimulus) and prints the paper's analysis: panel agreement, one response surface per
//! condition on the panel means, the repeated-measures ANOVA and Fisher's LSD.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use nalgebra::DMatrix;
use wscg_doe::{ccd_blocks, decode, fit_quadratic, CcdAlpha, CcdFace};
use wscg_math::{Error, Result};

#[derive(Subcommand, Debug)]
pub enum DoeCommand {
    /// Print a central composite design as CSV.
    #[command(alias = "ccd")]
    Design(CcdArgs),
    /// Fit a quadratic response surface to a CSV of runs.
    Fit(FitArgs),
    /// Analyse a study's scores: panel PCA, response surfaces, ANOVA, LSD.
    Analyze(AnalyzeArgs),
}

#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    /// CSV with a header `subject,condition,stimulus,score` (any order of rows; stimuli
    /// numbered from 0); only read. Every subject needs a score for every condition and
    /// stimulus.
    scores: PathBuf,
    /// CSV of the stimuli's factor levels in coded units (header, one row per stimulus, in
    /// stimulus order); default: the paper's 13-run inscribed design when there are 13
    /// stimuli.
    #[arg(long)]
    design: Option<PathBuf>,
    /// Significance level of Fisher's LSD.
    #[arg(long, default_value_t = 0.05)]
    alpha: f64,
}

#[derive(Args, Debug)]
pub struct CcdArgs {
    /// Number of factors.
    #[arg(long, default_value_t = 2)]
    k: usize,
    /// circumscribed, inscribed or faced.
    #[arg(long, default_value = "inscribed")]
    face: String,
    /// rotatable, orthogonal or a number.
    #[arg(long, default_value = "rotatable")]
    alpha: String,
    /// Centre points in the factorial and in the axial block.
    #[arg(long, num_args = 2, default_values_t = [3, 2])]
    center: Vec<usize>,
    /// Physical lower bounds, one per factor (with --high: print physical units).
    #[arg(long, num_args = 1.., allow_negative_numbers = true)]
    low: Option<Vec<f64>>,
    /// Physical upper bounds, one per factor.
    #[arg(long, num_args = 1.., allow_negative_numbers = true)]
    high: Option<Vec<f64>>,
}

#[derive(Args, Debug)]
pub struct FitArgs {
    /// CSV with a header line: factor columns (coded units) then the response; only read.
    csv: PathBuf,
    /// Leave out the interaction terms (the paper's model).
    #[arg(long)]
    no_interaction: bool,
}

/// Runs a `wscg doe` command.
pub fn run(cmd: DoeCommand) -> Result<()> {
    match cmd {
        DoeCommand::Design(a) => {
            let face: CcdFace = a.face.parse()?;
            let alpha: CcdAlpha = a.alpha.parse()?;
            let mut m = ccd_blocks(a.k, face, alpha, (a.center[0], a.center[1]))?;
            match (&a.low, &a.high) {
                (Some(lo), Some(hi)) => m = decode(&m, lo, hi)?,
                (None, None) => {}
                _ => return Err(Error::invalid("low/high", "give both --low and --high")),
            }
            let header: Vec<String> = (1..=a.k).map(|i| format!("x{i}")).collect();
            println!("{}", header.join(","));
            for r in m.row_iter() {
                let cells: Vec<String> = r.iter().map(|v| format!("{v}")).collect();
                println!("{}", cells.join(","));
            }
            Ok(())
        }
        DoeCommand::Fit(a) => {
            let (x, y) = wscg_doe::read_runs(&a.csv)?;
            let fit = fit_quadratic(&x, &y, !a.no_interaction)?;
            print_fit(&fit);
            Ok(())
        }
        DoeCommand::Analyze(a) => analyze(&a),
    }
}

fn analyze(a: &AnalyzeArgs) -> Result<()> {
    let st = wscg_doe::read_study(&a.scores)?;
    let (ns, nc, nk) = (st.subjects.len(), st.conditions.len(), st.stimuli);
    let design = match &a.design {
        Some(p) => wscg_doe::read_design(p)?,
        None if nk == 13 => ccd_blocks(2, CcdFace::Inscribed, CcdAlpha::Rotatable, (3, 2))?,
        None => {
            return Err(Error::invalid(
                "design",
                format!("{nk} stimuli: give their factor levels with --design"),
            ))
        }
    };
    if design.nrows() != nk {
        return Err(Error::ShapeMismatch(format!(
            "the design has {} rows for {nk} stimuli",
            design.nrows()
        )));
    }
    println!(
        "{ns} subjects, conditions {:?}, {nk} stimuli",
        st.conditions
    );
    for (ci, cname) in st.conditions.iter().enumerate() {
        // Subjects x stimuli for this condition.
        let m = DMatrix::from_fn(ns, nk, |s, k| st.scores[(s * nc + ci) * nk + k]);
        let means: Vec<f64> = (0..nk).map(|k| m.column(k).mean()).collect();
        let pca = wscg_doe::panel_pca(&m.transpose())?;
        let fit = fit_quadratic(&design, &means, false)?;
        let lsd = wscg_doe::lsd_pairs(&m, a.alpha)?;
        println!(
            "\n== condition {cname}: mean score {:.3}",
            means.iter().sum::<f64>() / nk as f64
        );
        println!(
            "panel PCA, first axis: {:.1} % of the variance",
            100.0 * pca[0]
        );
        print_fit(&fit);
        println!(
            "Fisher LSD {:.3} (alpha {}): {} of {} stimulus pairs separated",
            lsd.lsd,
            a.alpha,
            lsd.n_separated,
            nk * (nk - 1) / 2
        );
    }
    if nc >= 2 {
        let t = wscg_doe::rm_anova(&st.scores, ns, nc, nk)?;
        println!("\n== repeated-measures ANOVA (subjects random)");
        println!(
            "{:<20} {:>10} {:>6} {:>10} {:>10} {:>10}",
            "effect", "SS", "df", "F", "p", "p (GG)"
        );
        for e in &t.effects {
            println!(
                "{:<20} {:>10.3} {:>6} {:>10.3} {:>10.5} {:>10.5}",
                e.name, e.ss, e.df, e.f, e.p, e.p_gg
            );
        }
    }
    Ok(())
}

fn print_fit(fit: &wscg_doe::RsmFit) {
    println!(
        "{:<6} {:>10} {:>10} {:>8} {:>10}",
        "term", "coef", "se", "t", "p"
    );
    for i in 0..fit.coef.len() {
        println!(
            "{:<6} {:>10.4} {:>10.4} {:>8.3} {:>10.5}",
            fit.names[i], fit.coef[i], fit.se[i], fit.t[i], fit.p[i]
        );
    }
    println!(
        "R2 {:.4}  adj R2 {:.4}  pred R2 {:.4}  PRESS {:.4}",
        fit.r2, fit.r2_adj, fit.r2_pred, fit.press
    );
    if let Some(xs) = &fit.stationary {
        println!(
            "stationary point {xs:?}, canonical eigenvalues {:?}",
            fit.canonical_eigs
        );
    }
}
