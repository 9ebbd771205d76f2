//! `wscg hdr`: paper 13 (multiscopic HDR) on the user's own views.
//!
//! - `multiscopic`: views of a rectified horizontal camera array, one exposure each, to one
//!   HDR image per view (OpenEXR), with tone-mapped previews and the disparity maps.
//! - `merge`: an aligned exposure stack of one view to one HDR image.
//! - `calibrate`: the camera response (Debevec-Malik, or Mitsunaga-Nayar as the paper's
//!   RASCAL) from a static exposure stack.
//! - `simulate`: the layered five-camera scene with its ground truth, and static stacks of
//!   the central view and of a gradient chart for `calibrate`.
//!
//! Views are 8- or 16-bit PNG or TIFF (or 8-bit JPEG) holding the camera's codes. Exposure
//! times are given as a comma list or a text file with one time per line; without
//! `--times` they are read from each file's EXIF block (exposure time, and ISO and aperture
//! as a relative exposure when they differ between the files: `wscg_math::io::exif`), and
//! given times that disagree with the EXIF values by more than 10 % are warned about. Responses: `gamma2.2`,
//! `linear`, or a CSV table written by `calibrate` (one line per code, one column per
//! channel, `#` comments). Input files are only read.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use wscg_hdr::synth::{encode, gradient_target, layered_scene, SceneParams};
use wscg_hdr::tonemap::reinhard;
use wscg_hdr::{
    calibrate_debevec, calibrate_mitsunaga_nayar, merge_stack, multiscopic_hdr, Align, Crf,
    MitsunagaNayarParams, MultiscopicParams, PatchMatchParams, Synthesis,
};
use wscg_math::io::exif::resolve_exposure_times;
use wscg_math::{Error, Image, Result};

use super::deblur::read_times;
use crate::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum HdrCommand {
    /// One HDR image per view of a multi-exposure camera array (paper 13).
    Multiscopic(MultiscopicArgs),
    /// Merge an aligned exposure stack of one view into one HDR image.
    Merge(MergeArgs),
    /// Recover the camera response from a static exposure stack (Debevec-Malik).
    Calibrate(CalibrateArgs),
    /// Write the layered five-camera scene: views, times, response and ground truth.
    Simulate(SimulateArgs),
}

#[derive(Args, Debug)]
pub struct Exposures {
    /// Exposure times in seconds: "t1,t2,...", a text file with one per line, or a JSON
    /// file holding a list or {"exposure_times": [...]}. Default: each file's EXIF exposure
    /// (time x ISO / N^2 relative to the first file when ISO or aperture differ).
    #[arg(long, visible_alias = "exposures")]
    times: Option<String>,
    /// Camera response: gamma2.2, linear or a CSV table (see `calibrate`).
    #[arg(long, default_value = "gamma2.2")]
    crf: String,
}

#[derive(Args, Debug)]
pub struct MultiscopicArgs {
    /// Views, left to right (8- or 16-bit PNG or TIFF, or JPEG).
    #[arg(required = true, num_args = 2..)]
    views: Vec<PathBuf>,
    #[command(flatten)]
    exposures: Exposures,
    /// Largest |disparity| between any two views, pixels.
    #[arg(long, default_value_t = 64)]
    max_disparity: i32,
    /// Patch side (odd).
    #[arg(long, default_value_t = 7)]
    patch: usize,
    /// PatchMatch iterations per direction.
    #[arg(long, default_value_t = 2)]
    iterations: usize,
    /// Alignment: ours, pm2d, zncc or none.
    #[arg(long, default_value = "ours")]
    align: String,
    /// Synthesis: bds (the paper) or direct.
    #[arg(long, default_value = "bds")]
    synthesis: String,
    /// Views are ordered left to right: search one disparity sign per pair.
    #[arg(long)]
    ordered: bool,
    /// Fill the offsets of pixels clipped in the reference from their row, then each clipped
    /// region's from its outline in a shorter exposure, and vote radiance by weight (not in
    /// the paper, which leaves saturated reference areas unsolved).
    #[arg(long)]
    fill_saturated: bool,
    /// Drop the coherence term of the matching cost.
    #[arg(long)]
    no_coherence: bool,
    /// Seed of the random search.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output folder (hdr_NN.exr, preview_NN.png, disparity_R_S.png).
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Aligned exposures of one view (8- or 16-bit PNG or TIFF, or JPEG).
    #[arg(required = true)]
    images: Vec<PathBuf>,
    #[command(flatten)]
    exposures: Exposures,
    /// Output HDR image (.exr or .hdr).
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// Aligned exposures of a static scene (8- or 16-bit PNG or TIFF, or JPEG; 16-bit codes
    /// are reduced to 10 bits for `debevec` and the response interpolated back).
    #[arg(required = true, num_args = 2..)]
    images: Vec<PathBuf>,
    /// Exposure times in seconds: "t1,t2,..." or a text file with one per line. Default:
    /// each file's EXIF exposure.
    #[arg(long)]
    times: Option<String>,
    /// Method: `debevec` (Debevec-Malik, a smoothness prior; any static scene) or
    /// `mitsunaga-nayar` (the polynomial model of RASCAL, which the paper used; the exposure
    /// ratios are re-estimated, and the scene must cover the whole code range, as a chart or
    /// a gradient does).
    #[arg(long, value_enum, default_value_t = CalMethod::Debevec)]
    method: CalMethod,
    /// Sample pixels on a regular grid (default: 70 for debevec, 2000 for mitsunaga-nayar).
    #[arg(long)]
    samples: Option<usize>,
    /// Smoothness weight lambda (debevec).
    #[arg(long, default_value_t = 10.0)]
    lambda: f64,
    /// Polynomial degree (mitsunaga-nayar; default: chosen on held-out samples).
    #[arg(long)]
    degree: Option<usize>,
    /// Keep the ratios of the given times instead of re-estimating them (mitsunaga-nayar).
    #[arg(long)]
    fixed_ratios: bool,
    /// Output CSV table of f^-1 (one line per code, one column per channel).
    #[arg(long)]
    out: PathBuf,
}

/// Response calibration methods.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CalMethod {
    /// Debevec & Malik 1997.
    Debevec,
    /// Mitsunaga & Nayar 1999.
    MitsunagaNayar,
}

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Image height.
    #[arg(long, default_value_t = 160)]
    height: usize,
    /// Image width.
    #[arg(long, default_value_t = 256)]
    width: usize,
    /// Noise seed.
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(cmd: HdrCommand) -> Result<()> {
    match cmd {
        HdrCommand::Multiscopic(a) => multiscopic(a),
        HdrCommand::Merge(a) => {
            let inputs = a.images.iter().map(PathBuf::as_path);
            let exposures = a.exposures.times.iter().chain([&a.exposures.crf]);
            let exposures = exposures.map(Path::new);
            crate::commands::overwrite::check_file("out", &a.out, inputs.chain(exposures))?;
            let (images, bits) = load_views(&a.images)?;
            let times = times_of(&a.images, a.exposures.times.as_deref(), exposure_times)?;
            let crf = load_crf(&a.exposures.crf, bits, images[0].channels())?;
            let m = merge_stack(&images, &times, &[crf])?;
            m.hdr.save(&a.out)?;
            println!(
                "merged {} exposures into {} ({} pixels clipped in every exposure)",
                images.len(),
                a.out.display(),
                m.fallback_pixels
            );
            Ok(())
        }
        HdrCommand::Calibrate(a) => {
            let inputs = a.images.iter().map(PathBuf::as_path);
            let times = a.times.iter().map(Path::new);
            crate::commands::overwrite::check_file("out", &a.out, inputs.chain(times))?;
            let (images, bits) = load_views(&a.images)?;
            let times = times_of(&a.images, a.times.as_deref(), read_times)?;
            let crf = match a.method {
                CalMethod::Debevec => {
                    calibrate_debevec(&images, &times, bits, a.samples.unwrap_or(70), a.lambda)?
                }
                CalMethod::MitsunagaNayar => {
                    let p = MitsunagaNayarParams::default()
                        .degree(a.degree)
                        .samples(a.samples.unwrap_or(MitsunagaNayarParams::default().samples))
                        .refine_ratios(!a.fixed_ratios);
                    let fit = calibrate_mitsunaga_nayar(&images, &times, bits, &p)?;
                    for (c, ch) in fit.channels.iter().enumerate() {
                        let r: Vec<String> = ch.ratios.iter().map(|r| format!("{r:.4}")).collect();
                        println!(
                            "channel {c}: degree {}, exposure ratios {}, rms residual {:.2e}",
                            ch.coefficients.len() - 1,
                            r.join(" "),
                            ch.rms
                        );
                    }
                    fit.crf
                }
            };
            crf.write_csv(&a.out)?;
            println!(
                "response of {} codes x {} channels written to {}",
                crf.levels(),
                crf.channels(),
                a.out.display()
            );
            Ok(())
        }
        HdrCommand::Simulate(a) => simulate(a),
    }
}

/// The exposure times of the files `paths`: parsed from `spec` by `parse` when given (and
/// checked against the files' EXIF exposures, each disagreement a warning naming the file),
/// else read from the files' EXIF blocks.
fn times_of(
    paths: &[PathBuf],
    spec: Option<&str>,
    parse: fn(&str) -> Result<Vec<f64>>,
) -> Result<Vec<f64>> {
    let given = spec.map(parse).transpose()?;
    let resolved = resolve_exposure_times(paths, given.as_deref())?;
    if resolved.from_exif {
        let t: Vec<String> = resolved.times.iter().map(|t| format!("{t}")).collect();
        println!("exposure times from EXIF (s): {}", t.join(", "));
    }
    Ok(resolved.times)
}

/// Exposure times from a comma list, or a text or JSON file (`wscg_hdr::read_exposure_times`).
fn exposure_times(spec: &str) -> Result<Vec<f64>> {
    let p = Path::new(spec);
    if p.is_file() {
        wscg_hdr::read_exposure_times(p)
    } else {
        read_times(spec)
    }
}

/// Loads views as codes; all must share one bit depth.
fn load_views(paths: &[PathBuf]) -> Result<(Vec<Image<u16>>, u8)> {
    let mut out = Vec::with_capacity(paths.len());
    let mut depth = None;
    for p in paths {
        let (img, bits) = Image::load_codes(p)?;
        if depth.is_some_and(|d| d != bits) {
            return Err(Error::format(
                p,
                format!(
                    "is {bits}-bit but the first view is {}-bit",
                    depth.unwrap_or(0)
                ),
            ));
        }
        depth = Some(bits);
        out.push(img);
    }
    Ok((out, depth.unwrap_or(8)))
}

/// A response by name or from a CSV table.
fn load_crf(spec: &str, bits: u8, channels: usize) -> Result<Crf> {
    match spec {
        "gamma2.2" => Crf::gamma(2.2, bits, 1),
        "linear" => Crf::linear(bits, 1),
        path => {
            let p = Path::new(path);
            let crf = Crf::read_csv(p)?;
            let c = crf.channels();
            if c != 1 && c != channels {
                return Err(Error::format(
                    p,
                    format!("has {c} columns but the views have {channels} channels"),
                ));
            }
            Ok(crf)
        }
    }
}

fn multiscopic(a: MultiscopicArgs) -> Result<()> {
    let inputs = a.views.iter().map(PathBuf::as_path);
    let exposures = a.exposures.times.iter().chain([&a.exposures.crf]);
    let exposures = exposures.map(Path::new);
    crate::commands::overwrite::check_folder("out", &a.out, inputs.chain(exposures))?;
    let (views, bits) = load_views(&a.views)?;
    let times = times_of(&a.views, a.exposures.times.as_deref(), exposure_times)?;
    let crf = load_crf(&a.exposures.crf, bits, views[0].channels())?;
    let synthesis = match a.synthesis.as_str() {
        "bds" => Synthesis::Bds,
        "direct" => Synthesis::Direct,
        s => {
            return Err(Error::invalid(
                "synthesis",
                format!("unknown {s:?}; use bds or direct"),
            ))
        }
    };
    let p = MultiscopicParams::default()
        .pm(PatchMatchParams::default()
            .patch(a.patch)
            .iters(a.iterations)
            .d_min(-a.max_disparity)
            .d_max(a.max_disparity)
            .coherence(!a.no_coherence)
            .seed(a.seed))
        .align(Align::by_name(&a.align)?)
        .synthesis(synthesis)
        .ordered(a.ordered)
        .fill_saturated(a.fill_saturated);
    std::fs::create_dir_all(&a.out).map_err(|e| Error::io(&a.out, e))?;
    let out = multiscopic_hdr(&views, &times, &[crf], &p, &Bars::new("hdr"))?;
    for (k, hdr) in out.hdr.iter().enumerate() {
        hdr.save(a.out.join(format!("hdr_{k:02}.exr")))?;
        reinhard(hdr, 0.18)?.save(a.out.join(format!("preview_{k:02}.png")))?;
    }
    let m = a.max_disparity.max(1) as f32;
    for ((r, s), f) in &out.nnfs {
        if s.abs_diff(*r) == 1 {
            let d = f.dx_image().map(|v| (v.abs() / m).min(1.0));
            d.save(a.out.join(format!("disparity_{r}_{s}.png")))?;
        }
    }
    println!(
        "{} HDR views written to {} (pixels clipped in every sample per view: {:?})",
        out.hdr.len(),
        a.out.display(),
        out.fallback_pixels
    );
    Ok(())
}

fn simulate(a: SimulateArgs) -> Result<()> {
    let cfg = SceneParams::default().height(a.height).width(a.width);
    let sc = layered_scene(&cfg, a.seed)?;
    std::fs::create_dir_all(&a.out).map_err(|e| Error::io(&a.out, e))?;
    for (k, v) in sc.views.iter().enumerate() {
        v.map(|z| z as f32 / 255.0)
            .save(a.out.join(format!("view_{k:02}.png")))?;
        sc.radiance[k].save(a.out.join(format!("truth_{k:02}.exr")))?;
    }
    wscg_hdr::write_exposure_times(a.out.join("times.txt"), &sc.times)?;
    // A static stack of the central camera, one stop apart, for `calibrate` and `merge`.
    // The same camera on a gradient chart that covers every code (what Mitsunaga-Nayar's
    // polynomial needs), in chart/.
    let centre = sc.views.len() / 2;
    let cal_times: Vec<f64> = (0..7).map(|k| 0.004 * 2f64.powi(k)).collect();
    let chart = gradient_target(a.height, a.width)?;
    for (dir, radiance) in [("calibration", &sc.radiance[centre]), ("chart", &chart)] {
        let cal = a.out.join(dir);
        std::fs::create_dir_all(&cal).map_err(|e| Error::io(&cal, e))?;
        for (k, &t) in cal_times.iter().enumerate() {
            let v = encode(
                radiance,
                t,
                cfg.response,
                cfg.noise,
                8,
                a.seed + 100 + k as u64,
            )?;
            v.map(|z| z as f32 / 255.0)
                .save(cal.join(format!("exposure_{k:02}.png")))?;
        }
        wscg_hdr::write_exposure_times(cal.join("times.txt"), &cal_times)?;
    }
    sc.crf.write_csv(a.out.join("crf.csv"))?;
    let max_d =
        cfg.layers.iter().map(|l| l.disparity).fold(0.0, f64::max) * (sc.views.len() - 1) as f64;
    println!(
        "{} views of {} x {} written to {} (times.txt, crf.csv, truth_NN.exr, a static \
         stack of the central view in calibration/ and of a gradient chart in chart/); \
         largest disparity {:.1} px: use --max-disparity {}",
        sc.views.len(),
        a.height,
        a.width,
        a.out.display(),
        max_d,
        max_d.ceil() as i32 + 1
    );
    Ok(())
}
