//! Paper 06, acceptance check 6 (the memory claim of section 3.4): a 1920 x 1080 x 60 pan
//! with a 5 % hole completes in place with a peak resident memory of at most twice the input
//! plus 300 MB. The peak (VmHWM) is per process, so this check has a test binary of its own.

use wscg_video::synth::pan_input;
use wscg_video::*;

/// Peak resident memory of this process (VmHWM, bytes).
fn peak_rss() -> usize {
    let s = std::fs::read_to_string("/proc/self/status").unwrap();
    let kb: usize = s
        .lines()
        .find(|l| l.starts_with("VmHWM"))
        .unwrap()
        .split_whitespace()
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    kb * 1024
}

#[test]
fn check6_memory_at_full_hd() {
    // 270 x 384 logo hole: 5.0 % of every frame; stage 1 uses PatchMatch3D (the default).
    let (mut v, hole) = pan_input(60, 1080, 1920, 8.0, 270, 384, 1).unwrap();
    let input = v.data.len();
    let mut cfg = CompletionParams::default();
    cfg.low.iters = vec![3, 2, 2];
    let (matches, _) =
        complete_in_place(&mut v, &hole, &cfg, &wscg_math::progress::NoProgress).unwrap();
    assert_eq!(matches.len(), hole.count());
    let peak = peak_rss();
    println!(
        "peak {} MB for an input of {} MB, {} hole pixels",
        peak >> 20,
        input >> 20,
        hole.count()
    );
    assert!(peak <= 2 * input + (300 << 20), "peak {} MB", peak >> 20);
}
