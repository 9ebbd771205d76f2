//! `wscg volren illum`: paper 15 (convolution-based volume illumination) on the user's own
//! volume: renders one image with ICS, SCS, PI-ICS, PI-SCS or a ray-casting baseline, or runs
//! the paper's slice-distance study (`--study`).
//!
//! Volumes: `.vti` (VTK XML image data), `.nii`/`.nii.gz`, `.npy` (`[z, y, x]`), or `.raw`
//! bytes with `--raw-dims`; values are mapped from `--value-range` (default: the data's min
//! and max) to [0, 1], or treated as tissue labels with `--labels`. Transfer functions: a
//! preset (`tissue`, `skin`, `marschner-lobb`) or a JSON file `[[s, r, g, b, a], ...]` with `s`,
//! colours and opacity (per voxel of length) in [0, 1].

use std::path::{Path, PathBuf};

use crate::commands::volume_file::read_volume;
use clap::{Args, ValueEnum};
use wscg_math::{Error, Result, VolumeView};
use wscg_volren::illumination::scenes::{
    labels_to_field, marschner_lobb, marschner_lobb_tf, skin_tf, tissue_tf,
};
use wscg_volren::illumination::study::{grid, sweep, AliasCriterion};
use wscg_volren::illumination::{
    render, IlluminationParams, Kernel, Light, LightAtten, LightBorder, Method, Phong, ScalarField,
    SliceCamera, TransferFunction,
};

use crate::progress::Bars;
use wscg_math::progress::Progress;

/// Rendering method names.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MethodName {
    /// Instant convolution shadows.
    Ics,
    /// Supersampled convolution shadows (needs --subsamples > 0).
    Scs,
    /// Pre-integrated ICS.
    PiIcs,
    /// Pre-integrated SCS.
    PiScs,
    /// Emission-absorption ray casting.
    Raycast,
    /// Blinn-Phong ray casting.
    Phong,
    /// Ray casting with shadow rays (slow; validation).
    ShadowRays,
}

/// Light kernel names.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum KernelName {
    /// Variance-additive Gaussian (--spread).
    Gaussian,
    /// No blur (hard shadows).
    Delta,
    /// Directional-occlusion cone (--tan-half).
    Disk,
}

/// What the propagated light meets outside the volume's box.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum BorderName {
    /// Empty: light passes round an occluder short of the box's sides and a blurring kernel
    /// carries light from outside in under its edges.
    Open,
    /// Opaque beyond every face not turned towards the light: light enters only through the
    /// faces turned towards it.
    Closed,
}

#[derive(Args, Debug)]
pub struct IllumArgs {
    /// Volume file (.vti, .nii, .nii.gz, .npy, a DICOM file or folder, or .raw with
    /// --raw-dims); only read.
    #[arg(long, conflicts_with = "phantom")]
    volume: Option<PathBuf>,
    /// Built-in volume instead of a file: marschner-lobb (41^3).
    #[arg(long)]
    phantom: Option<String>,
    /// Dimensions x,y,z of a .raw volume of unsigned bytes.
    #[arg(long, value_delimiter = ',')]
    raw_dims: Vec<usize>,
    /// Voxel spacing x,y,z (overrides the file's).
    #[arg(long, value_delimiter = ',')]
    spacing: Vec<f64>,
    /// Value range lo,hi mapped to [0, 1] (default: the data's min and max).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    value_range: Vec<f32>,
    /// Treat the values as tissue labels (0 = background) and blur them into densities.
    #[arg(long)]
    labels: bool,
    /// Transfer function: `tissue`, `skin`, `marschner-lobb` or a JSON file [[s, r, g, b, a], ...].
    #[arg(long, default_value = "tissue")]
    tf: String,
    /// Rendering method.
    #[arg(long, value_enum, default_value_t = MethodName::Scs)]
    method: MethodName,
    /// Slice distance (ICS family) or sample step (ray casters), in voxels.
    #[arg(long, default_value_t = 0.8)]
    slice_distance: f32,
    /// Tissue sub-samples per slice (SCS, PI-SCS).
    #[arg(long, default_value_t = 3)]
    subsamples: u32,
    /// Attenuate the light by the slice sample only (default: every tissue sample).
    #[arg(long)]
    slice_only_attenuation: bool,
    /// Light kernel.
    #[arg(long, value_enum, default_value_t = KernelName::Gaussian)]
    kernel: KernelName,
    /// Gaussian spread D (voxels): variance 2 D per unit depth.
    #[arg(long, default_value_t = 0.5)]
    spread: f32,
    /// Tangent of the cone half angle of the disk kernel.
    #[arg(long, default_value_t = 0.5)]
    tan_half: f32,
    /// Direction towards the light in view coordinates x,y,z (x right, y up, z to the viewer).
    #[arg(
        long,
        value_delimiter = ',',
        allow_hyphen_values = true,
        default_value = "0,0,1"
    )]
    light_dir: Vec<f64>,
    /// Ambient term in [0, 1].
    #[arg(long, default_value_t = 0.0)]
    ambient: f32,
    /// Background colour r,g,b in [0, 1].
    #[arg(long, value_delimiter = ',', default_value = "0,0,0")]
    background: Vec<f32>,
    /// Outside of the volume's box for the propagated light: open (empty, light leaks round
    /// an occluder that stops short of the sides) or closed (opaque beyond the faces not
    /// turned towards the light).
    #[arg(long, value_enum, default_value_t = BorderName::Open)]
    border: BorderName,
    /// Image side in pixels.
    #[arg(long, default_value_t = 512)]
    size: usize,
    /// Camera azimuth around the volume's z axis (degrees).
    #[arg(long, default_value_t = 30.0, allow_hyphen_values = true)]
    azimuth: f64,
    /// Camera elevation (degrees).
    #[arg(long, default_value_t = 20.0, allow_hyphen_values = true)]
    elevation: f64,
    /// Output image (.png); required unless --study.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Run the study: ICS, SCS and PI-SCS over slice distances 0.2..2.0 and 0..=5 sub-samples
    /// against ICS(0.2), timed over --views orbit views.
    #[arg(long)]
    study: bool,
    /// Views of the study (orbit, evenly spaced azimuths).
    #[arg(long, default_value_t = 4)]
    views: usize,
}

fn triple<T: Copy>(v: &[T], name: &'static str) -> Result<[T; 3]> {
    v.try_into().map_err(|_| {
        Error::invalid(
            name,
            format!("needs 3 comma-separated values, got {}", v.len()),
        )
    })
}

/// Loads the volume as a normalised field.
fn load_field(a: &IllumArgs) -> Result<ScalarField> {
    if let Some(p) = &a.phantom {
        return match p.as_str() {
            "marschner-lobb" => marschner_lobb(41),
            other => Err(Error::invalid(
                "phantom",
                format!("unknown phantom {other:?}; use marschner-lobb"),
            )),
        };
    }
    let path = a
        .volume
        .as_ref()
        .ok_or_else(|| Error::invalid("volume", "give --volume FILE or --phantom NAME"))?;
    let (dims, spacing, data) = read_any(path, &a.raw_dims)?;
    let spacing = if a.spacing.is_empty() {
        spacing
    } else {
        triple(&a.spacing, "spacing")?
    };
    if a.labels {
        if data
            .iter()
            .any(|&v| !(0.0..=255.0).contains(&v) || v.fract() != 0.0)
        {
            return Err(Error::invalid(
                "labels",
                "label volumes must hold integers in 0..=255",
            ));
        }
        let labels: Vec<u8> = data.iter().map(|&v| v as u8).collect();
        return labels_to_field(VolumeView::new(dims, spacing, &labels)?, 1.0);
    }
    let (lo, hi) = if a.value_range.is_empty() {
        data.iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            })
    } else {
        let r = &a.value_range;
        if r.len() != 2 {
            return Err(Error::invalid("value_range", "needs lo,hi"));
        }
        (r[0], r[1])
    };
    let hi = if hi > lo { hi } else { lo + 1.0 };
    ScalarField::from_f32_range(VolumeView::new(dims, spacing, &data)?, lo, hi)
}

/// Reads a volume file: dims, spacing, values.
fn read_any(path: &Path, raw_dims: &[usize]) -> Result<([usize; 3], [f64; 3], Vec<f32>)> {
    let v = read_volume(path, super::u8_raw(raw_dims)?, None)?;
    Ok((v.dims(), v.spacing(), v.into_data()))
}

/// A preset or a JSON transfer function.
fn load_tf(spec: &str) -> Result<TransferFunction> {
    match spec {
        "tissue" => return Ok(tissue_tf()),
        "skin" => return Ok(skin_tf()),
        "marschner-lobb" => return Ok(marschner_lobb_tf()),
        _ => {}
    }
    TransferFunction::read_json(Path::new(spec), 256)
}

fn method_of(a: &IllumArgs) -> Method {
    let atten = if a.slice_only_attenuation {
        LightAtten::SliceOnly
    } else {
        LightAtten::Segment
    };
    let ics = |m: u32, pi: bool| Method::Ics {
        slice: a.slice_distance,
        subsamples: m,
        preintegrated: pi,
        light_atten: atten,
    };
    match a.method {
        MethodName::Ics => ics(0, false),
        MethodName::Scs => ics(a.subsamples, false),
        MethodName::PiIcs => ics(0, true),
        MethodName::PiScs => ics(a.subsamples, true),
        MethodName::Raycast => Method::RaycastEa {
            step: a.slice_distance,
        },
        MethodName::Phong => Method::RaycastPhong {
            step: a.slice_distance,
            phong: Phong::default(),
        },
        MethodName::ShadowRays => Method::ShadowRays {
            step: a.slice_distance,
        },
    }
}

/// Runs `wscg volren illum`.
pub fn run(a: IllumArgs) -> Result<()> {
    if let Some(out) = &a.out {
        let inputs = [a.volume.as_deref(), Some(std::path::Path::new(&a.tf))];
        crate::commands::overwrite::check_file("out", out, inputs.into_iter().flatten())?;
    }
    let field = load_field(&a)?;
    let tf = load_tf(&a.tf)?;
    let light = Light {
        dir_view: triple(&a.light_dir, "light_dir")?,
        ambient: a.ambient,
        kernel: match a.kernel {
            KernelName::Gaussian => Kernel::Gaussian { spread: a.spread },
            KernelName::Delta => Kernel::Delta,
            KernelName::Disk => Kernel::Disk {
                tan_half: a.tan_half,
            },
        },
    };
    let settings = IlluminationParams::default()
        .background(triple(&a.background, "background")?)
        .border(match a.border {
            BorderName::Open => LightBorder::Open,
            BorderName::Closed => LightBorder::Closed,
        });
    if a.study {
        if a.views == 0 {
            return Err(Error::invalid("views", "needs at least one view"));
        }
        let views = (0..a.views)
            .map(|k| {
                SliceCamera::orbit(
                    &field,
                    a.azimuth + 360.0 * k as f64 / a.views as f64,
                    a.elevation,
                    a.size,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let distances: Vec<f32> = (2..=20).step_by(2).map(|k| k as f32 / 10.0).collect();
        let configs = grid(&distances, 5);
        let bars = Bars::new("illum study");
        bars.begin("configurations", configs.len() as u64);
        let st = sweep(
            &field,
            &tf,
            &views,
            &light,
            &settings,
            &Method::ics(0.2),
            &Method::ics(0.1),
            &configs,
            &AliasCriterion::default(),
            |_, _| bars.advance(1),
        )?;
        bars.finish();
        println!(
            "reference ICS(0.2): {:.1} ms/frame",
            1e3 * st.reference_seconds
        );
        println!(
            "{:<8} {:>5} {:>3} {:>10} {:>10} {:>10} alias-free",
            "method", "ds", "m", "MAD", "energy", "ms/frame"
        );
        for e in &st.entries {
            let (ds, m) = match e.method {
                Method::Ics {
                    slice, subsamples, ..
                } => (slice, subsamples),
                _ => (0.0, 0),
            };
            println!(
                "{:<8} {:>5.1} {:>3} {:>10.5} {:>10.3e} {:>10.1} {}",
                e.method.name(),
                ds,
                m,
                e.mad,
                e.energy,
                1e3 * e.seconds,
                if e.alias_free { "yes" } else { "no" }
            );
        }
        let best_ics = st.fastest(|m| m.name() == "ics");
        let best_other = st.fastest(|m| m.name() != "ics");
        if let (Some(b), Some(o)) = (best_ics, best_other) {
            println!(
                "fastest alias-free ICS: {:.1} ms; fastest alias-free {}: {:.1} ms; speed-up {:.2}x",
                1e3 * b.seconds,
                o.method.name(),
                1e3 * o.seconds,
                b.seconds / o.seconds
            );
        }
        return Ok(());
    }
    let out = a
        .out
        .as_ref()
        .ok_or_else(|| Error::invalid("out", "--out FILE.png is required"))?;
    let cam = SliceCamera::orbit(&field, a.azimuth, a.elevation, a.size)?;
    let method = method_of(&a);
    let t0 = std::time::Instant::now();
    let r = render(&field, &tf, &cam, &light, &method, &settings)?;
    let secs = t0.elapsed().as_secs_f64();
    wscg_volren::render::rgb(&r.image)?.save(out)?;
    println!(
        "{} ({} slices) {:.1} ms; image written to {}",
        method.name(),
        r.slices,
        1e3 * secs,
        out.display()
    );
    Ok(())
}
