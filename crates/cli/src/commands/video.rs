//! `wscg video`: paper 06 (localized-search video completion) on the user's own frames.
//!
//! `complete` reads a folder of PNG/JPEG frames and a hole mask (one image for every frame,
//! or a folder with one image per frame; non-zero = hole), completes the hole and writes the
//! frames as PNG into `--out`. The input files are only read. `synth` writes a synthetic clip
//! with its mask and ground truth, to try the command on; `measure` compares a result with a
//! ground truth in the hole.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use wscg_math::Result;
use wscg_video::io::{read_frames, read_mask, read_video, write_frames};
use wscg_video::metrics::{flicker, psnr_masked, ssim_masked};
use wscg_video::synth;
use wscg_video::{
    complete_video_with, per_frame_patchmatch, wexler_complete, CompletionParams,
    LocalSearchParams, PatchSize, RefineParams, Video, WexlerParams,
};

use crate::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum VideoCommand {
    /// Remove the masked region from a folder of frames.
    Complete(CompleteArgs),
    /// Write a synthetic clip (frames, mask, ground truth) to a folder.
    Synth(SynthArgs),
    /// SSIM and PSNR in the hole against a ground truth, and flicker.
    Measure(MeasureArgs),
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MethodName {
    /// Localized-search completion (the paper).
    Localized,
    /// Wexler et al. 2007 (global search and voting at every level; slow at HD).
    Wexler,
    /// Image PatchMatch inpainting of each frame.
    PerFrame,
}

#[derive(Args, Debug)]
pub struct CompleteArgs {
    /// Folder of frames (.png/.jpg, in name order), or a video file when ffmpeg is installed;
    /// only read.
    frames: PathBuf,
    /// Hole mask: one image for all frames, or a folder of one image per frame.
    mask: PathBuf,
    /// Output folder for the completed frames (frame_00000.png, ...).
    #[arg(long)]
    out: PathBuf,
    /// Method.
    #[arg(long, value_enum, default_value_t = MethodName::Localized)]
    method: MethodName,
    /// Patch extents x, y, t (odd).
    #[arg(long, num_args = 3, default_values_t = [5, 5, 5])]
    patch: Vec<usize>,
    /// Width of stage 1's working resolution.
    #[arg(long, default_value_t = 480)]
    lowres_width: usize,
    /// Stage 2 refinement iterations (0: none).
    #[arg(long, default_value_t = 4)]
    refine_iters: usize,
    /// Stage 3 window widths (odd) of the first iterations; later ones keep the last.
    #[arg(long, num_args = 1.., default_values_t = [17, 13, 9, 5])]
    windows: Vec<usize>,
    /// Stage 3 frames searched on each side of the match's frame, per iteration like
    /// --windows (the last repeats); 0 is the paper's in-frame windows.
    #[arg(long, num_args = 1.., default_values_t = [0, 0, 0, 1])]
    temporal_radius: Vec<usize>,
    /// Stage 3 iterations at most (it stops earlier once the energy stops falling).
    #[arg(long, default_value_t = 16)]
    max_iterations: usize,
    /// Stage 3 candidate cubes per hole pixel at most over a level's iterations (the paper's
    /// "less than a thousand").
    #[arg(long, default_value_t = 1000)]
    max_candidates: usize,
    /// Random-search seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Stage 3 with the paper's windows only, without the neighbours' coherence candidates.
    #[arg(long)]
    no_propagate: bool,
    /// Search as the paper does, without the temporal candidates (the same position in the
    /// nearest frames where it is known, exact copies behind a moving object filmed by a
    /// static camera) in stages 1 and 3.
    #[arg(long)]
    no_temporal_candidates: bool,
    /// Stage 1 search.
    #[arg(long, value_enum, default_value_t = SearchName::Patchmatch)]
    search: SearchName,
    /// With --search pca-kdtree: stage 1's next-best sources kept per hole pixel, around
    /// which stage 3's first iteration also searches 3 x 3 windows (9 candidates each, out of
    /// --max-candidates); 0 is the paper's stage 3, which searches around the best match only.
    #[arg(long, default_value_t = LocalSearchParams::default().hypotheses)]
    hypotheses: usize,
    /// After each stage-3 iteration, a raster scan and its reverse in which each hole pixel
    /// tries the sources its already-scanned neighbours' matches imply (PatchMatch's
    /// propagation order): 4 candidates per pixel and iteration; 3.3 % lower energy on 19
    /// zoom clips, but serial.
    #[arg(long)]
    scan_propagation: bool,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SearchName {
    /// Space-time PatchMatch (memory: one match per hole pixel).
    Patchmatch,
    /// The paper's PCA + kd-tree index (memory: 96 bytes per source at the working size).
    PcaKdtree,
    /// Exact search over every source (small videos).
    Exact,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ClipKind {
    /// Static camera, a disc moving across the scene.
    Sprite,
    /// Camera panning under a static logo.
    Pan,
    /// Camera zooming, a disc hole moving.
    Zoom,
    /// Stripes and bricks with a permanent hole.
    Periodic,
}

#[derive(Args, Debug)]
pub struct SynthArgs {
    /// Output folder (gets frames/, mask.png or mask/, truth/).
    #[arg(long)]
    out: PathBuf,
    /// Clip kind.
    #[arg(long, value_enum, default_value_t = ClipKind::Pan)]
    kind: ClipKind,
    /// Frames.
    #[arg(long, default_value_t = 30)]
    frames: usize,
    /// Frame width.
    #[arg(long, default_value_t = 1280)]
    width: usize,
    /// Frame height.
    #[arg(long, default_value_t = 720)]
    height: usize,
    /// Seed of the texture.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

#[derive(Args, Debug)]
pub struct MeasureArgs {
    /// Folder of result frames.
    result: PathBuf,
    /// Folder of ground-truth frames.
    truth: PathBuf,
    /// Hole mask (image or folder).
    mask: PathBuf,
}

pub fn run(cmd: VideoCommand) -> Result<()> {
    match cmd {
        VideoCommand::Complete(a) => complete(a),
        VideoCommand::Synth(a) => synth_clip(a),
        VideoCommand::Measure(a) => measure(a),
    }
}

fn load(frames: &std::path::Path, mask: &std::path::Path) -> Result<(Video, wscg_video::Mask3)> {
    let v = read_video(frames)?;
    let m = read_mask(mask, v.frames, v.height, v.width)?;
    Ok((v, m))
}

fn complete(a: CompleteArgs) -> Result<()> {
    crate::commands::overwrite::check_folder("out", &a.out, [&a.frames, &a.mask])?;
    let (v, m) = load(&a.frames, &a.mask)?;
    let patch = PatchSize {
        px: a.patch[0],
        py: a.patch[1],
        pt: a.patch[2],
    };
    eprintln!(
        "{} frames of {} x {}, {} hole pixels ({:.2} %)",
        v.frames,
        v.width,
        v.height,
        m.count(),
        100.0 * m.count() as f64 / m.len_grid() as f64
    );
    let t = std::time::Instant::now();
    let out = match a.method {
        MethodName::Localized => {
            let mut cfg = CompletionParams::default();
            cfg.low.patch = patch;
            cfg.low.target_width = a.lowres_width;
            cfg.low.search = match a.search {
                SearchName::Patchmatch => wscg_video::SearchMethod::PatchMatch3D {
                    iters: 5,
                    seed: a.seed,
                },
                SearchName::PcaKdtree => wscg_video::SearchMethod::PcaKdTree(
                    wscg_video::PcaKdParams::default().seed(a.seed),
                ),
                SearchName::Exact => wscg_video::SearchMethod::Exact,
            };
            cfg.refine =
                (a.refine_iters > 0).then(|| RefineParams::default().iterations(a.refine_iters));
            cfg.local.windows = a.windows.clone();
            cfg.local.temporal_radius = a.temporal_radius.clone();
            cfg.local.max_iterations = a.max_iterations;
            cfg.local.max_candidates = a.max_candidates;
            cfg.local.propagate = !a.no_propagate;
            cfg.local.hypotheses = a.hypotheses;
            cfg.local.scan_propagation = a.scan_propagation;
            cfg.low.temporal_candidates = !a.no_temporal_candidates;
            cfg.local.temporal_candidates = !a.no_temporal_candidates;
            let c = complete_video_with(&v, &m, &cfg, &Bars::new("video"))?;
            eprintln!(
                "stage seconds: low resolution {:.2}, refinement {:.2}, localized search {:.2}",
                c.stats.seconds[0], c.stats.seconds[1], c.stats.seconds[2]
            );
            c.video
        }
        MethodName::Wexler => {
            let cfg = WexlerParams::default().patch(patch).seed(a.seed);
            wexler_complete(&v, &m, &cfg)?.video
        }
        MethodName::PerFrame => {
            let cfg = WexlerParams::default()
                .patch(PatchSize { pt: 1, ..patch })
                .seed(a.seed)
                .seed_per_frame(true);
            per_frame_patchmatch(&v, &m, &cfg)?
        }
    };
    let files = write_frames(&out, &a.out)?;
    println!(
        "{} frames written to {} in {:.1} s",
        files.len(),
        a.out.display(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}

fn synth_clip(a: SynthArgs) -> Result<()> {
    let (f, h, w, s) = (a.frames, a.height, a.width, a.seed);
    let k = w as f64 / 1280.0;
    let clip = match a.kind {
        ClipKind::Sprite => synth::sprite_clip(f, h, w, 60.0 * k, 10.0 * k, 0.0, s),
        ClipKind::Pan => {
            synth::pan_clip(f, h, w, 8.0, (90.0 * k) as usize, (120.0 * k) as usize, s)
        }
        ClipKind::Zoom => synth::zoom_clip(f, h, w, 1.003, 60.0 * k, 10.0 * k, s),
        ClipKind::Periodic => synth::periodic_clip(f, h, w, 24.0, (80.0 * k) as usize),
    }?;
    write_frames(&clip.observed, &a.out.join("frames"))?;
    write_frames(&clip.clean, &a.out.join("truth"))?;
    let masks = Video::new(
        f,
        h,
        w,
        1,
        clip.hole.to_bytes().iter().map(|&b| b * 255).collect(),
    )?;
    write_frames(&masks, &a.out.join("mask"))?;
    println!(
        "clip written to {}: frames/, mask/ and truth/ ({} hole pixels)",
        a.out.display(),
        clip.hole.count()
    );
    Ok(())
}

fn measure(a: MeasureArgs) -> Result<()> {
    let (r, m) = load(&a.result, &a.mask)?;
    let t = read_frames(&a.truth)?;
    println!("SSIM in the hole   {:.4}", ssim_masked(&r, &t, &m)?);
    println!("PSNR in the hole   {:.2} dB", psnr_masked(&r, &t, &m)?);
    if r.frames > 1 {
        println!("flicker            {:.3}", flicker(&r, &m)?);
    }
    Ok(())
}
