//! `wscg raytrace`: paper 07 (predictive rendering of metallic-flake paint).
//!
//! `paint` renders a plate of the given microstructure for one eye or the stereo pair and
//! writes display sRGB PNGs; `workshop` runs the virtual material workshop (the paper's
//! 13-run design scored by the virtual observer against a hidden reference) and fits the
//! response surface.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand, ValueEnum};
use wscg_doe::{ccd, decode, fit_quadratic, CcdAlpha, CcdFace};
use wscg_math::{Error, Result};
use wscg_raytrace::paint::{
    render_with_progress, score_runs, ColourMode, Condition, DiscLight, FlakeParams, FlakePlate,
    Plate, PlateStack, Rect, RenderSettings, StackModel, TiltDist, WorkshopConfig, XyzImage,
};
use wscg_raytrace::spectral::XYZ_TO_SRGB;
use wscg_raytrace::stereo::{Eye, StereoRig};

use super::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum RaytraceCommand {
    /// Render a metallic-paint plate (paper 07) for one eye or the stereo pair.
    Paint(PaintArgs),
    /// The virtual material workshop: score the 13-run design against a hidden reference and
    /// fit the response surface.
    Workshop(WorkshopArgs),
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum EyeName {
    /// The monoscopic condition's eye, between the two.
    Cyclopean,
    /// Left eye.
    Left,
    /// Right eye.
    Right,
    /// Both eyes (OUT_left.png and OUT_right.png).
    Pair,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ModelName {
    /// Boolean model (flakes may cross).
    Boolean,
    /// Sequential deposit without interpenetration.
    Deposit,
}

/// The plate: microstructure, lamp and rendering options shared by the commands.
#[derive(Args, Debug)]
pub struct PlateArgs {
    /// Mean flake radius (µm).
    #[arg(long, default_value_t = 30.0)]
    radius: f64,
    /// Flake density: mean number of flakes above a point.
    #[arg(long, default_value_t = 6.5)]
    density: f64,
    /// Standard deviation of the (half-normal) flake tilt (degrees).
    #[arg(long, default_value_t = 8.0)]
    tilt_deg: f64,
    /// Height model of the flake layer.
    #[arg(long, value_enum, default_value_t = ModelName::Boolean)]
    model: ModelName,
    /// Binder absorption coefficient (1/mm).
    #[arg(long, default_value_t = 0.0)]
    absorption: f64,
    /// Lamp elevation above the plate (degrees).
    #[arg(long, default_value_t = 45.0)]
    light_elevation: f64,
    /// Lamp angular radius (degrees).
    #[arg(long, default_value_t = 1.0)]
    light_deg: f64,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Pixels per screen pixel of the 1:1 view (4: four times finer).
    #[arg(long, default_value_t = 1.0)]
    magnification: f64,
    /// Region of the plate to render, x0 y0 x1 y1 (mm, plate centre at 0, y up); default the
    /// whole 150 x 100 mm plate.
    #[arg(long, num_args = 4, allow_negative_numbers = true)]
    region: Option<Vec<f64>>,
    /// Microstructure seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

impl PlateArgs {
    fn flakes(&self) -> FlakeParams {
        FlakeParams {
            radius_um: self.radius,
            density: self.density,
            tilt: TiltDist::HalfNormal {
                sigma_deg: self.tilt_deg,
            },
            model: match self.model {
                ModelName::Boolean => StackModel::Boolean,
                ModelName::Deposit => StackModel::Deposit,
            },
            ..FlakeParams::default()
        }
    }

    fn stack(&self) -> PlateStack {
        PlateStack {
            binder_sigma_a_per_mm: self.absorption,
            ..PlateStack::default()
        }
    }

    fn settings(&self, colour: ColourMode) -> RenderSettings {
        RenderSettings {
            spp: self.spp,
            magnification: self.magnification,
            region_mm: self.region.as_ref().map(|r| Rect {
                x0: r[0],
                y0: r[1],
                x1: r[2],
                y1: r[3],
            }),
            colour,
            ..RenderSettings::default()
        }
    }
}

#[derive(Args, Debug)]
pub struct PaintArgs {
    #[command(flatten)]
    plate: PlateArgs,
    /// Eye.
    #[arg(long, value_enum, default_value_t = EyeName::Cyclopean)]
    eye: EyeName,
    /// Render three RGB bands instead of 81 wavelengths (the non-spectral baseline).
    #[arg(long)]
    rgb: bool,
    /// Exposure applied before the sRGB curve (glints clip at 1).
    #[arg(long, default_value_t = 1.0)]
    exposure: f64,
    /// Output PNG (OUT_left.png and OUT_right.png for a pair).
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct WorkshopArgs {
    /// Hidden reference: radius (µm) and density.
    #[arg(long, num_args = 2, default_values_t = [26.0, 7.3])]
    reference: Vec<f64>,
    /// Viewing condition.
    #[arg(long, value_enum, default_value_t = ConditionName::Stereo)]
    condition: ConditionName,
    /// Samples per pixel.
    #[arg(long, default_value_t = 64)]
    spp: u32,
    /// Seed of the renders.
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// CSV of the runs and their scores to write.
    #[arg(long)]
    csv: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ConditionName {
    /// Cyclopean image.
    Mono,
    /// Left and right images.
    Stereo,
}

/// Runs a `wscg raytrace` command.
pub fn run(cmd: RaytraceCommand) -> Result<()> {
    match cmd {
        RaytraceCommand::Paint(a) => paint(&a),
        RaytraceCommand::Workshop(a) => workshop(&a),
    }
}

fn write_png(img: &XyzImage, exposure: f64, path: &Path) -> Result<()> {
    img.to_display(exposure, &XYZ_TO_SRGB)?.save(path)?;
    let glints = img.glint_ids.len();
    println!(
        "{}: {} x {} px, {:.4} mm/px, {glints} flakes glinting directly",
        path.display(),
        img.width,
        img.height,
        img.mm_per_px
    );
    Ok(())
}

fn paint(a: &PaintArgs) -> Result<()> {
    let p = &a.plate;
    let stack = p.stack();
    let micro = FlakePlate::new(&p.flakes(), stack.size_mm, p.seed)?;
    let plate = Plate::new(stack, Box::new(micro))?;
    let light = DiscLight::from_elevation(p.light_elevation, p.light_deg);
    let s = p.settings(if a.rgb {
        ColourMode::Rgb
    } else {
        ColourMode::Spectral
    });
    let rig = StereoRig::default();
    let views: Vec<(Eye, PathBuf)> = match a.eye {
        EyeName::Cyclopean => vec![(Eye::Cyclopean, a.out.clone())],
        EyeName::Left => vec![(Eye::Left, a.out.clone())],
        EyeName::Right => vec![(Eye::Right, a.out.clone())],
        EyeName::Pair => {
            let stem = a.out.with_extension("");
            let name = |eye: &str| PathBuf::from(format!("{}_{eye}.png", stem.to_string_lossy()));
            vec![(Eye::Left, name("left")), (Eye::Right, name("right"))]
        }
    };
    for (eye, path) in views {
        let bars = Bars::new(&format!("{eye:?}"));
        let img = render_with_progress(&plate, &light, &rig, eye, &s, &bars)?;
        write_png(&img, a.exposure, &path)?;
    }
    Ok(())
}

fn workshop(a: &WorkshopArgs) -> Result<()> {
    const LOW: [f64; 2] = [15.0, 3.5];
    const HIGH: [f64; 2] = [45.0, 9.5];
    let design = ccd(2, CcdFace::Inscribed, CcdAlpha::Rotatable, 5)?;
    let physical = decode(&design, &LOW, &HIGH)?;
    let runs: Vec<(f64, f64)> = physical.row_iter().map(|r| (r[0], r[1])).collect();
    let cfg = WorkshopConfig {
        condition: match a.condition {
            ConditionName::Mono => Condition::Mono,
            ConditionName::Stereo => Condition::Stereo,
        },
        settings: RenderSettings {
            spp: a.spp,
            ..WorkshopConfig::default().settings
        },
        ..WorkshopConfig::default()
    };
    let reference = (a.reference[0], a.reference[1]);
    let ws = score_runs(reference, &runs, &cfg, a.seed, &Bars::new("workshop"))?;
    let fit = fit_quadratic(&design, &ws.scores, true)?;
    let mut csv = String::from("radius_um,density,score\n");
    println!("{:>10} {:>8} {:>6}", "radius", "density", "score");
    for ((r, d), s) in runs.iter().zip(&ws.scores) {
        println!("{r:>10.2} {d:>8.3} {s:>6.2}");
        csv.push_str(&format!("{r},{d},{s}\n"));
    }
    println!(
        "\nresponse surface (coded units): R2 {:.3}, R2 pred {:.3}, PRESS {:.3}",
        fit.r2, fit.r2_pred, fit.press
    );
    for (n, (c, p)) in fit.names.iter().zip(fit.coef.iter().zip(&fit.p)) {
        println!("  {n:<5} {c:>8.3}  p {p:.4}");
    }
    match &fit.stationary {
        Some(xs) => {
            let phys: Vec<f64> = (0..2)
                .map(|k| 0.5 * (LOW[k] + HIGH[k]) + 0.5 * (HIGH[k] - LOW[k]) * xs[k])
                .collect();
            let kind = if fit.canonical_eigs.iter().all(|&l| l > 0.0) {
                "minimum: the predicted best match"
            } else {
                "not a minimum"
            };
            println!(
                "stationary point: radius {:.2} µm, density {:.2} ({kind}); hidden reference: {:.2} µm, {:.2}",
                phys[0], phys[1], reference.0, reference.1
            );
        }
        None => println!("the surface has no stationary point"),
    }
    if let Some(path) = &a.csv {
        std::fs::write(path, csv).map_err(|e| Error::io(path, e))?;
    }
    Ok(())
}
