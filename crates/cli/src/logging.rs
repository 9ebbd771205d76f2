//! Messages of the library crates on standard error, at the level `-v` / `-q` choose.
//!
//! The crates log through the `log` facade (solver convergence, pipeline stages, files whose
//! orientation is not applied, ...). By default the command line shows warnings; `-v` adds
//! the stages of each method (info), `-vv` solver details (debug), `-vvv` everything; `-q`
//! shows errors only and hides the progress bars. The environment variable `WSCG_LOG`
//! (`env_logger` syntax, for instance `wscg_volseg=debug`) refines the choice.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

use log::{Level, LevelFilter};

static QUIET: AtomicBool = AtomicBool::new(false);

/// Whether `-q` was given (the progress bars stay hidden).
pub fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// The level of wscg's records for `-v` given `verbose` times, or `-q`.
pub fn level(verbose: u8, quiet: bool) -> LevelFilter {
    if quiet {
        return LevelFilter::Error;
    }
    match verbose {
        0 => LevelFilter::Warn,
        1 => LevelFilter::Info,
        2 => LevelFilter::Debug,
        _ => LevelFilter::Trace,
    }
}

/// Installs the logger on standard error (once, at start-up).
pub fn init(verbose: u8, quiet: bool) {
    QUIET.store(quiet, Ordering::Relaxed);
    let detailed = verbose >= 2;
    let _ = env_logger::Builder::new()
        .filter_level(LevelFilter::Off)
        .filter_module("wscg", level(verbose, quiet))
        .parse_env("WSCG_LOG")
        .format(move |buf, record| {
            let word = match record.level() {
                Level::Error => "error",
                Level::Warn => "warning",
                Level::Info => "info",
                Level::Debug => "debug",
                Level::Trace => "trace",
            };
            if detailed {
                writeln!(buf, "{word} [{}]: {}", record.target(), record.args())
            } else {
                writeln!(buf, "{word}: {}", record.args())
            }
        })
        .try_init();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_choose_the_level() {
        assert_eq!(level(0, false), LevelFilter::Warn);
        assert_eq!(level(1, false), LevelFilter::Info);
        assert_eq!(level(2, false), LevelFilter::Debug);
        assert_eq!(level(7, false), LevelFilter::Trace);
        assert_eq!(level(0, true), LevelFilter::Error);
    }
}
