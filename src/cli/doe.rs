//! `wscg doe`: paper 07's study statistics on the user's own designs and scores.
//!
//! `ccd` prints a central composite design (coded, or physical with `--low/--high`) as CSV;
//! `fit` reads a CSV of runs (factor columns, then the response in the last column) and
//! prints the second-order response surface with PRESS, predicted R² and the canonical
//! analysis.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use nalgebra::DMatrix;
use wscg_doe::{ccd_blocks, decode, fit_quadratic, CcdAlpha, CcdFace};
use wscg_math::{Error, Result};

#[derive(Subcommand, Debug)]
pub enum DoeCommand {
    /// Print a central composite design as CSV.
    Ccd(CcdArgs),
    /// Fit a quadratic response surface to a CSV of runs.
    Fit(FitArgs),
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
        DoeCommand::Ccd(a) => {
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
            let text = std::fs::read_to_string(&a.csv).map_err(|e| Error::io(&a.csv, e))?;
            let (x, y) = parse_runs(&text).map_err(|e| Error::format(&a.csv, e))?;
            let fit = fit_quadratic(&x, &y, !a.no_interaction)?;
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
            Ok(())
        }
    }
}

/// Factor matrix and responses of a CSV with a header line.
fn parse_runs(text: &str) -> std::result::Result<(DMatrix<f64>, Vec<f64>), String> {
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        if line.trim().is_empty() {
            continue;
        }
        let row = line
            .split(',')
            .map(|c| c.trim().parse::<f64>())
            .collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|e| format!("line {}: {e}", i + 1))?;
        if row.len() < 2 {
            return Err(format!(
                "line {}: need factor columns and a response",
                i + 1
            ));
        }
        if let Some(first) = rows.first() {
            if first.len() != row.len() {
                return Err(format!(
                    "line {}: {} columns, expected {}",
                    i + 1,
                    row.len(),
                    first.len()
                ));
            }
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err("no runs after the header line".into());
    }
    let k = rows[0].len() - 1;
    let x = DMatrix::from_fn(rows.len(), k, |r, c| rows[r][c]);
    let y = rows.iter().map(|r| r[k]).collect();
    Ok((x, y))
}
