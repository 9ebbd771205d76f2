//! Command-line definitions and dispatch.

use std::path::PathBuf;

use crate::demo;
use crate::progress;
use clap::{Parser, Subcommand};
use wscg_math::{Error, Result};

mod biometrics;
mod cloth;
mod deblur;
mod doe;
mod hdr;
mod isosurface;
mod math;
mod meshfilter;
mod motion;
mod mri;
mod octree;
mod overwrite;
mod raytrace;
mod video;
mod volren;
mod volseg;
mod volume_file;

/// wscg: the methods of the Journal of WSCG vol. 23 papers on your own data.
#[derive(Parser, Debug)]
#[command(name = "wscg", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Allow an output to replace an input file (or to be written into an input folder);
    /// without it such a command is refused.
    #[arg(long, global = true)]
    overwrite: bool,
    /// More messages on standard error: -v the stages of each method, -vv solver details
    /// (iterations, residuals), -vvv everything. Default: warnings and errors.
    #[arg(short, long, action = clap::ArgAction::Count, global = true)]
    verbose: u8,
    /// Errors only on standard error: no warnings, no progress bars.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run one demo on built-in data (`wscg demo --list` names them).
    Demo {
        /// Demo name.
        name: Option<String>,
        /// Output folder for its pictures (default: wscg-demo-NAME).
        #[arg(long)]
        out: Option<PathBuf>,
        /// List the demos and exit.
        #[arg(long)]
        list: bool,
    },
    /// Run every demo and write an HTML report (DIR/index.html).
    Gallery {
        /// Output folder.
        #[arg(long, default_value = "gallery")]
        out: PathBuf,
        /// Run only these demos (repeatable).
        #[arg(long)]
        only: Vec<String>,
    },
    /// Biometrics on your own data (paper 01: FDKECA; paper 05: class-wise SFA; paper 14: ears;
    /// paper 17: Kinect gait).
    #[command(subcommand)]
    Biometrics(biometrics::BiometricsCommand),
    /// Cloth simulation with soft constraints (paper 02) on your own mesh.
    #[command(subcommand)]
    Cloth(cloth::ClothCommand),
    /// Mesh denoising (paper 04: joint bilateral with colour) on your own OBJ/PLY mesh.
    #[command(subcommand)]
    Meshfilter(meshfilter::MeshfilterCommand),
    /// Isosurfaces of sparse volumes with tetrahedral-spline normals (paper 09).
    #[command(subcommand)]
    Isosurface(isosurface::IsosurfaceCommand),
    /// The unified triangle/voxel octree (paper 10): build from OBJ/PLY, render, inspect.
    #[command(subcommand)]
    Octree(octree::OctreeCommand),
    /// Compressed-sensing MRI with a curvelet prior (paper 11): reconstruct, masks, phantom.
    #[command(subcommand)]
    Mri(mri::MriCommand),
    /// Gyroscope-driven multi-frame deblurring (paper 12): deblur, kernels, simulated bursts.
    #[command(subcommand)]
    Deblur(deblur::DeblurCommand),
    /// Multiscopic HDR (paper 13): HDR per view of a multi-exposure camera array, merge,
    /// response calibration, simulated camera arrays.
    #[command(subcommand)]
    Hdr(hdr::HdrCommand),
    /// Hybrid ROI visualisation of medical volumes (paper 03): serve and view; convolution-based
    /// volume illumination (paper 15): `illum`.
    #[command(subcommand)]
    Volren(volren::VolrenCommand),
    /// Video completion (paper 06: localized search) on your own frames.
    #[command(subcommand)]
    Video(video::VideoCommand),
    /// Metallic-flake paint rendering and the virtual material workshop (paper 07), many-light
    /// rendering with adaptive importance caching (paper 08).
    #[command(subcommand)]
    Raytrace(raytrace::RaytraceCommand),
    /// Designs and response surfaces of perceptual studies (paper 07's statistics).
    #[command(subcommand)]
    Doe(doe::DoeCommand),
    /// Bone separation in CT by random walks on the bone-only graph (paper 18): split, phantom.
    #[command(subcommand)]
    Volseg(volseg::VolsegCommand),
    /// Predictive walk-and-reach synthesis with learned dynamic primitives (paper 16): make-data,
    /// learn, plan, synth (BVH output).
    #[command(subcommand)]
    Motion(motion::MotionCommand),
    /// Shared numerics on image files: metrics, filtering, resizing, spectra.
    #[command(subcommand)]
    Math(math::MathCommand),
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> Result<()> {
    overwrite::allow(cli.overwrite);
    crate::logging::init(cli.verbose, cli.quiet);
    match cli.command {
        Command::Demo { name, out, list } => {
            if list || name.is_none() {
                for d in demo::registry() {
                    println!("{:<16} paper {:<3} {}", d.name, d.paper, d.title);
                }
                return Ok(());
            }
            let name = name.unwrap_or_default();
            let d = demo::find(&name).ok_or_else(|| unknown_demo(&name))?;
            let out = out.unwrap_or_else(|| PathBuf::from(format!("wscg-demo-{name}")));
            std::fs::create_dir_all(&out).map_err(|e| Error::io(&out, e))?;
            let report = (d.run)(&out, &progress::Bars::new(d.name))?;
            println!("{}\n", report.summary);
            for r in &report.table {
                println!(
                    "{:<52} ours {:<28} reference {:<12} {}",
                    r.quantity, r.ours, r.reference, r.note
                );
            }
            for (k, v) in &report.timings {
                println!("{k:<52} {v:.4}");
            }
            println!("\nfigures written to {}", out.display());
            Ok(())
        }
        Command::Gallery { out, only } => {
            let mut demos = demo::registry();
            if !only.is_empty() {
                for n in &only {
                    if demo::find(n).is_none() {
                        return Err(unknown_demo(n));
                    }
                }
                demos.retain(|d| only.iter().any(|n| n == d.name));
            }
            let entries =
                crate::gallery::run(&out, &demos, &|d| Box::new(progress::Bars::new(d.name)))?;
            let failed: Vec<_> = entries.iter().filter(|e| e.result.is_err()).collect();
            for e in &failed {
                if let Err(err) = &e.result {
                    eprintln!("demo {} failed: {err}", e.demo.name);
                }
            }
            println!("gallery written to {}", out.join("index.html").display());
            if failed.is_empty() {
                Ok(())
            } else {
                Err(Error::Numerical(format!("{} demo(s) failed", failed.len())))
            }
        }
        Command::Math(cmd) => math::run(cmd),
        Command::Motion(cmd) => motion::run(cmd),
        Command::Volseg(cmd) => volseg::run(cmd),
        Command::Biometrics(cmd) => biometrics::run(cmd),
        Command::Cloth(cmd) => cloth::run(cmd),
        Command::Volren(cmd) => volren::run(cmd),
        Command::Meshfilter(cmd) => meshfilter::run(cmd),
        Command::Isosurface(cmd) => isosurface::run(cmd),
        Command::Octree(cmd) => octree::run(cmd),
        Command::Mri(cmd) => mri::run(cmd),
        Command::Deblur(cmd) => deblur::run(cmd),
        Command::Hdr(cmd) => hdr::run(cmd),
        Command::Video(cmd) => video::run(cmd),
        Command::Raytrace(cmd) => raytrace::run(cmd),
        Command::Doe(cmd) => doe::run(cmd),
    }
}

fn unknown_demo(name: &str) -> Error {
    let names: Vec<_> = demo::registry().iter().map(|d| d.name).collect();
    Error::invalid(
        "name",
        format!("no demo named {name:?}; available: {}", names.join(", ")),
    )
}
