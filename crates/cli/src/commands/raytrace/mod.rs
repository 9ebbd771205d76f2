//! `wscg raytrace`: paper 07 (predictive rendering of metallic-flake paint) and paper 08
//! (`manylight`, in its own module).
//!
//! `paint` renders a plate of the given microstructure (command-line options or a JSON paint
//! description) for one eye or the stereo pair and writes display sRGB PNGs (for a pair also
//! side by side and as a red-cyan anaglyph), and on request XYZ and spectral OpenEXR files; `workshop` runs the virtual material workshop (the paper's
//! 13-run design scored by the virtual observer against a hidden reference) and fits the
//! response surface.

mod manylight;

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand, ValueEnum};
use wscg_doe::{ccd, decode, fit_quadratic, CcdAlpha, CcdFace};
use wscg_math::Result;
use wscg_raytrace::paint::{
    anaglyph, render_with_progress, score_runs, side_by_side, write_spectral_exr, write_xyz_exr,
    ColourMode, Condition, DiscLight, FlakeParams, FlakePlate, PaintDescription, PaintRenderParams,
    PhotonParams, Plate, PlateStack, Rect, StackModel, TiltDist, WorkshopParams, XyzImage,
};
use wscg_raytrace::spectral::XYZ_TO_SRGB;
use wscg_raytrace::stereo::{Eye, StereoRig};

use crate::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum RaytraceCommand {
    /// Render a metallic-paint plate (paper 07) for one eye or the stereo pair.
    Paint(PaintArgs),
    /// The virtual material workshop: score the 13-run design against a hidden reference and
    /// fit the response surface.
    Workshop(WorkshopArgs),
    /// Many-light rendering with adaptive importance caching (paper 08) on a built-in scene
    /// or an OBJ file, one method or the comparison of all.
    Manylight(manylight::ManyLightArgs),
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
    /// Lambertian albedo of the base (0: the paper's black base); a diffuse base also gets
    /// the flakes' caustics from a photon map, and the light it sends up that the coat and
    /// the flakes reflect back down (a white base under a clear coat renders near Y = 1).
    #[arg(long, default_value_t = 0.0)]
    base_albedo: f64,
    /// Photons for the caustics on a diffuse base (0: leave the caustics out).
    #[arg(long, default_value_t = 2_000_000)]
    photons: usize,
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
    /// Applies a paint description on top of the command-line values.
    fn with(&self, d: &PaintDescription) -> Result<(FlakeParams, PlateStack, u64)> {
        let mut f = self.flakes();
        let mut st = self.stack();
        d.apply(&mut f, &mut st)?;
        Ok((f, st, d.seed.unwrap_or(self.seed)))
    }

    fn flakes(&self) -> FlakeParams {
        FlakeParams::default()
            .radius_um(self.radius)
            .density(self.density)
            .tilt(TiltDist::HalfNormal {
                sigma_deg: self.tilt_deg,
            })
            .model(match self.model {
                ModelName::Boolean => StackModel::Boolean,
                ModelName::Deposit => StackModel::Deposit,
            })
    }

    fn stack(&self) -> PlateStack {
        PlateStack {
            binder_sigma_a_per_mm: self.absorption,
            base_albedo: self.base_albedo,
            ..PlateStack::default()
        }
    }

    fn settings(&self, colour: ColourMode) -> PaintRenderParams {
        PaintRenderParams::default()
            .spp(self.spp)
            .magnification(self.magnification)
            .region_mm(self.region.as_ref().map(|r| Rect {
                x0: r[0],
                y0: r[1],
                x1: r[2],
                y1: r[3],
            }))
            .colour(colour)
            .photons((self.photons > 0).then(|| PhotonParams::default().count(self.photons)))
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
    /// Paint description (JSON); its keys override the options above.
    #[arg(long)]
    paint: Option<PathBuf>,
    /// Also write the XYZ image as OpenEXR (OUT.exr, or OUT_left.exr and OUT_right.exr).
    #[arg(long)]
    exr: bool,
    /// Also write the radiance per wavelength as a multi-channel OpenEXR (OUT_spectral.exr).
    #[arg(long)]
    spectral: bool,
    /// Output PNG (for a pair: OUT_left.png, OUT_right.png, OUT_sbs.png side by side and
    /// OUT_anaglyph.png red-cyan).
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
        RaytraceCommand::Manylight(a) => manylight::run(&a),
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

/// `OUT` with `_suffix` and extension `ext`.
pub(super) fn sibling(out: &Path, suffix: &str, ext: &str) -> PathBuf {
    let stem = out.with_extension("");
    PathBuf::from(format!("{}{suffix}.{ext}", stem.to_string_lossy()))
}

fn paint(a: &PaintArgs) -> Result<()> {
    crate::commands::overwrite::check_file("out", &a.out, &a.paint)?;
    let p = &a.plate;
    let desc = match &a.paint {
        Some(path) => PaintDescription::read(path)?,
        None => PaintDescription::default(),
    };
    let (flakes, stack, seed) = p.with(&desc)?;
    let micro = FlakePlate::new(&flakes, stack.size_mm, seed)?;
    let plate = Plate::new(stack, Box::new(micro))?;
    let light = DiscLight::from_elevation(p.light_elevation, p.light_deg);
    let s = p
        .settings(if a.rgb {
            ColourMode::Rgb
        } else {
            ColourMode::Spectral
        })
        .keep_spectrum(a.spectral);
    let rig = StereoRig::default();
    let views: Vec<(Eye, &str)> = match a.eye {
        EyeName::Cyclopean => vec![(Eye::Cyclopean, "")],
        EyeName::Left => vec![(Eye::Left, "")],
        EyeName::Right => vec![(Eye::Right, "")],
        EyeName::Pair => vec![(Eye::Left, "_left"), (Eye::Right, "_right")],
    };
    let mut shown = Vec::new();
    for (eye, suffix) in views {
        let bars = Bars::new(&format!("{eye:?}"));
        let img = render_with_progress(&plate, &light, &rig, eye, &s, &bars)?;
        write_png(&img, a.exposure, &sibling(&a.out, suffix, "png"))?;
        if a.exr {
            write_xyz_exr(&img, sibling(&a.out, suffix, "exr"))?;
        }
        if a.spectral {
            write_spectral_exr(&img, sibling(&a.out, &format!("{suffix}_spectral"), "exr"))?;
        }
        shown.push(img.to_display(a.exposure, &XYZ_TO_SRGB)?);
    }
    if let [l, r] = shown.as_slice() {
        side_by_side(l, r)?.save(sibling(&a.out, "_sbs", "png"))?;
        anaglyph(l, r)?.save(sibling(&a.out, "_anaglyph", "png"))?;
        println!(
            "side by side and anaglyph written next to {}",
            a.out.display()
        );
    }
    Ok(())
}

fn workshop(a: &WorkshopArgs) -> Result<()> {
    const LOW: [f64; 2] = [15.0, 3.5];
    const HIGH: [f64; 2] = [45.0, 9.5];
    let design = ccd(2, CcdFace::Inscribed, CcdAlpha::Rotatable, 5)?;
    let physical = decode(&design, &LOW, &HIGH)?;
    let runs: Vec<(f64, f64)> = physical.row_iter().map(|r| (r[0], r[1])).collect();
    let cfg = WorkshopParams::default()
        .condition(match a.condition {
            ConditionName::Mono => Condition::Mono,
            ConditionName::Stereo => Condition::Stereo,
        })
        .settings((WorkshopParams::default().settings).spp(a.spp));
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
        wscg_math::io::atomic::write(path, csv)?;
    }
    Ok(())
}
