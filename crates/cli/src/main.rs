//! The `wscg` command line: each paper's method on the user's files, demos on built-in data,
//! and the gallery. Run `wscg --help`.

use std::process::ExitCode;

use clap::Parser;

mod commands;
mod demo;
mod gallery;
mod logging;
mod progress;

fn main() -> ExitCode {
    let args = commands::Cli::parse();
    match commands::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
