//! What the command-line test binaries share.

use std::process::Command;

/// The `wscg` binary of this build.
pub fn wscg() -> Command {
    Command::new(env!("CARGO_BIN_EXE_wscg"))
}
