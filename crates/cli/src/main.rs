//! The `wscg` command line: each paper's method on the user's files, demos on built-in data,
//! and the gallery. Run `wscg --help`.

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches};

mod commands;
mod demo;
mod finite;
mod gallery;
mod logging;
mod progress;

fn main() -> ExitCode {
    wscg_math::faer_par::fix_faer_parallelism();
    let matches = finite::finite_floats(commands::Cli::command()).get_matches();
    let args = match commands::Cli::from_arg_matches(&matches) {
        Ok(a) => a,
        Err(e) => e.exit(),
    };
    match commands::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
