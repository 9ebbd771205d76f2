//! The AFL++ harness of the file readers: `wscg-fuzz <target>` runs the reader of one target
//! (see `targets.rs`) on every input AFL++ gives it, in persistent mode. A panic that a
//! reader catches itself (the guards of the PLY parser and of the image decoders, which turn
//! a panic of a third-party decoder into an error) is not a finding; any other panic aborts,
//! which AFL++ records as a crash.
//!
//! Build and run (FUZZING.md has the details):
//! `cargo afl build --release` then
//! `cargo afl fuzz -i corpus/obj -o out/obj $CARGO_TARGET_DIR/release/wscg-fuzz obj`.

mod targets;

fn main() {
    let target = std::env::args().nth(1).unwrap_or_default();
    let known = targets::TARGETS.iter().chain(targets::READER_TARGETS);
    if !known.clone().any(|t| *t == target) {
        eprintln!(
            "usage: wscg-fuzz <target>; targets: {}",
            known.copied().collect::<Vec<_>>().join(", ")
        );
        std::process::exit(2);
    }
    // Shared state (the ROI target's client) is built before the fork server starts.
    targets::run(&target, &[]);
    afl::fuzz_nohook!(|data: &[u8]| {
        targets::run(&target, data);
    });
}
