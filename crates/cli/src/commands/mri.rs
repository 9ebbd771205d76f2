//! `wscg mri`: paper 11 (compressed-sensing MRI with a UDCT prior) on the user's own data.
//!
//! - `recon`: reconstruct an image from undersampled k-space (`.npy`, complex, un-shifted,
//!   unitary scaling) or from an image to simulate the measurement from (PNG/JPEG/EXR or a
//!   real `.npy`), with C-SALSA and the UDCT, FDCT, wavelet or identity prior, or with a baseline
//!   (zero-filled, FCSA, TVCMRI, WaTMRI). Writes the image as PNG (magnitude scaled to its
//!   peak), `.npy` (complex128) or NIfTI (`.nii`, `.nii.gz`: magnitude).
//! - `mask`: write a Cartesian or pseudo-radial sampling mask.
//! - `phantom`: write the analytic Shepp-Logan k-space (and its reference image).
//!
//! Mask files: `.npy` masks are un-shifted like the k-space (DC at [0, 0]); PNG masks are
//! centred (DC in the middle, as one draws them); nonzero means sampled. Input files are
//! only read.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use num_complex::Complex64;
use wscg_cs_mri::baselines::{self, CompositeParams};
use wscg_cs_mri::sparsifier::PriorParams;
use wscg_cs_mri::{
    choose_udct_scales, csalsa, masks, metrics, phantom, sparsifier, CsalsaParams, FdctParams,
    Finest, KSpace, Regularizer, ScaleChoiceParams, UdctParams,
};
use wscg_math::fft::{fftshift, ifftshift};
use wscg_math::progress::Progress;
use wscg_math::{npy, Error, Image, Result, Volume};

use crate::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum MriCommand {
    /// Reconstruct an image from undersampled k-space.
    Recon(Box<ReconArgs>),
    /// Write a sampling mask (PNG: centred; .npy: un-shifted).
    Mask(MaskArgs),
    /// Write the analytic Shepp-Logan k-space as a complex .npy.
    Phantom(PhantomArgs),
}

#[derive(Args, Debug)]
pub struct ReconArgs {
    /// k-space (.npy, complex, un-shifted, unitary scaling) or an image to simulate from.
    input: PathBuf,
    /// Sampling mask (.npy un-shifted, or PNG centred; nonzero = sampled).
    #[arg(long)]
    mask: PathBuf,
    /// Method: csalsa, fcsa, tvcmri, watmri or zero-filled.
    #[arg(long, default_value = "csalsa")]
    method: String,
    /// Prior of C-SALSA: udct, fdct (wrapping curvelets), lrsflct or mrsflct (sharp frequency
    /// localized contourlets, less or more redundant), db1 ... db8 or identity.
    #[arg(long, default_value = "udct")]
    prior: String,
    /// Regulariser of C-SALSA: l1 or tv.
    #[arg(long, default_value = "l1")]
    reg: String,
    /// Noise radius eps in k-space units (0: exact data consistency).
    #[arg(long, default_value_t = 0.0)]
    epsilon: f64,
    /// Iterations.
    #[arg(long, default_value_t = 70)]
    iters: usize,
    /// C-SALSA threshold on the unit-peak image (default 0.01 for udct, 0.02 for fdct and the
    /// SFLCTs, 0.04 otherwise).
    #[arg(long)]
    tau0: Option<f64>,
    /// UDCT wedges per scale, e.g. "6,6" (one scale: the paper's brain-image setting) or
    /// "6,6;6,6;6,6" (three scales), or "auto" (default): choose 1, 2 or 3 scales of 6,6
    /// wedges by hold-out validation on the measured samples, at the cost of 9 extra
    /// reconstructions (about 10x the time). More scales suit photographs and smooth
    /// anatomy; one scale suits images whose energy sits in a few sharp harmonics.
    #[arg(long, default_value = "auto")]
    wedges: String,
    /// FDCT scales, the coarse one included (default: ceil(log2(min size)) - 3).
    #[arg(long)]
    fdct_scales: Option<usize>,
    /// FDCT finest scale: wavelets or curvelets.
    #[arg(long, default_value = "wavelets")]
    fdct_finest: String,
    /// SFLCT directional levels per scale, coarsest first ("3,3,4": 8, 8 and 16 directions).
    #[arg(long, default_value = "3,3,4")]
    sflct_levels: String,
    /// TV weight a of the baselines (unit-peak images).
    #[arg(long, default_value_t = 0.001)]
    a: f64,
    /// Wavelet weight b of the baselines.
    #[arg(long, default_value_t = 0.035)]
    b: f64,
    /// Reference image (.npy or image) to report PSNR and RLNE against.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Output: .png (magnitude), .npy (complex128), .nii or .nii.gz (magnitude).
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct MaskArgs {
    /// Cartesian variable-density mask with this sampling rate (whole rows).
    #[arg(long, conflicts_with = "radial")]
    cartesian: Option<f64>,
    /// Pseudo-radial mask reaching at least this sampling rate.
    #[arg(long)]
    radial: Option<f64>,
    /// Size ROWSxCOLS.
    #[arg(long, default_value = "256x256")]
    size: String,
    /// Fully sampled centre fraction of the Cartesian mask.
    #[arg(long, default_value_t = 0.08)]
    center_frac: f64,
    /// Random seed of the Cartesian mask.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output .png (centred) or .npy (un-shifted).
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct PhantomArgs {
    /// Grid size n (n x n).
    #[arg(long, default_value_t = 256)]
    size: usize,
    /// Output k-space (.npy, complex128).
    #[arg(long)]
    out: PathBuf,
    /// Also write the reference image (inverse FFT of the full k-space) here (.npy or .png).
    #[arg(long)]
    reference: Option<PathBuf>,
}

fn ext(p: &Path) -> String {
    let name = p
        .file_name()
        .and_then(|s| s.to_str())
        .unwrap_or("")
        .to_lowercase();
    if name.ends_with(".nii.gz") {
        "nii.gz".into()
    } else {
        p.extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_lowercase()
    }
}

/// A 2-D complex array from a .npy file, or a grey image from an image file.
fn read_2d(path: &Path) -> Result<(usize, usize, Vec<Complex64>)> {
    if ext(path) == "npy" {
        let a = npy::read_complex(path)?;
        match a.shape[..] {
            [r, c] => Ok((r, c, a.data)),
            ref s => Err(Error::ShapeMismatch(format!(
                "{} holds an array of shape {s:?}; a 2-D array is needed",
                path.display()
            ))),
        }
    } else {
        let img = Image::load(path)?.to_gray();
        let (h, w, _) = img.shape();
        Ok((
            h,
            w,
            img.data()
                .iter()
                .map(|&v| Complex64::new(v as f64, 0.0))
                .collect(),
        ))
    }
}

fn read_mask(path: &Path, rows: usize, cols: usize) -> Result<Vec<bool>> {
    let (r, c, v) = read_2d(path)?;
    if (r, c) != (rows, cols) {
        return Err(Error::ShapeMismatch(format!(
            "the mask {} is {r} x {c} but the k-space is {rows} x {cols}",
            path.display()
        )));
    }
    let m: Vec<bool> = v.iter().map(|z| z.norm() > 0.0).collect();
    if ext(path) == "npy" {
        Ok(m)
    } else {
        ifftshift(&m, &[rows, cols])
    }
}

fn write_image(path: &Path, rows: usize, cols: usize, x: &[Complex64]) -> Result<()> {
    match ext(path).as_str() {
        "npy" => npy::write(path, &[rows, cols], x),
        "nii" | "nii.gz" => {
            // NIfTI volume of one slice: x = column (fastest), y = row, the image's own order.
            let data: Vec<f32> = x.iter().map(|v| v.norm() as f32).collect();
            Volume::new([cols, rows, 1], [1.0; 3], data)?.write_nifti(path)
        }
        _ => {
            let peak = x
                .iter()
                .map(|v| v.norm())
                .fold(0.0, f64::max)
                .max(f64::MIN_POSITIVE);
            Image::from_fn(rows, cols, |i, j| (x[i * cols + j].norm() / peak) as f32)?.save(path)
        }
    }
}

fn parse_size(s: &str) -> Result<(usize, usize)> {
    let bad = || Error::invalid("size", format!("{s:?} is not ROWSxCOLS"));
    let (a, b) = s.split_once('x').ok_or_else(bad)?;
    Ok((
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    ))
}

/// Parses "6,6;6,6" into wedge pairs.
pub fn parse_wedges(s: &str) -> Result<Vec<[usize; 2]>> {
    s.split(';')
        .map(|scale| {
            let v: Vec<usize> = scale
                .split(',')
                .map(|t| t.trim().parse::<usize>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| Error::invalid("wedges", format!("{s:?} is not like \"6,6;6,6\"")))?;
            match v[..] {
                [a, b] => Ok([a, b]),
                _ => Err(Error::invalid(
                    "wedges",
                    format!("{s:?}: each scale needs two counts"),
                )),
            }
        })
        .collect()
}

/// Parses SFLCT directional levels like "3,3,4".
pub fn parse_levels(s: &str) -> Result<Vec<usize>> {
    s.split(',')
        .map(|t| t.trim().parse::<usize>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| Error::invalid("sflct-levels", format!("{s:?} is not like \"3,3,4\"")))
}

pub fn run(cmd: MriCommand) -> Result<()> {
    match cmd {
        MriCommand::Recon(a) => recon(*a),
        MriCommand::Mask(a) => {
            let (rows, cols) = parse_size(&a.size)?;
            let (m, what) = match (a.cartesian, a.radial) {
                (Some(r), None) => (
                    masks::cartesian(rows, cols, r, a.center_frac, a.seed)?,
                    "Cartesian".to_string(),
                ),
                (None, Some(r)) => {
                    let (m, lines) = masks::pseudo_radial(rows, cols, r)?;
                    (m, format!("{lines}-line pseudo-radial"))
                }
                _ => {
                    return Err(Error::invalid(
                        "mask",
                        "give --cartesian RATE or --radial RATE",
                    ))
                }
            };
            if ext(&a.out) == "npy" {
                let v: Vec<u8> = m.iter().map(|&b| b as u8).collect();
                npy::write(&a.out, &[rows, cols], &v)?;
            } else {
                let c = fftshift(&m, &[rows, cols])?;
                Image::from_fn(rows, cols, |i, j| if c[i * cols + j] { 1.0 } else { 0.0 })?
                    .save(&a.out)?;
            }
            println!(
                "{what} mask, {:.2}% sampled; wrote {}",
                100.0 * masks::sampling_rate(&m),
                a.out.display()
            );
            Ok(())
        }
        MriCommand::Phantom(a) => {
            let k = phantom::shepp_logan_kspace(a.size)?;
            npy::write(&a.out, &[a.size, a.size], &k)?;
            println!("wrote {}", a.out.display());
            if let Some(r) = a.reference {
                write_image(&r, a.size, a.size, &phantom::shepp_logan_reference(a.size)?)?;
                println!("wrote {}", r.display());
            }
            Ok(())
        }
    }
}

fn recon(a: ReconArgs) -> Result<()> {
    let inputs = [Some(&a.input), Some(&a.mask), a.reference.as_ref()];
    crate::commands::overwrite::check_file("out", &a.out, inputs.into_iter().flatten())?;
    let (rows, cols, input) = read_2d(&a.input)?;
    let mask = read_mask(&a.mask, rows, cols)?;
    let is_kspace = ext(&a.input) == "npy" && input.iter().any(|v| v.im != 0.0);
    let data = if is_kspace {
        KSpace::new(rows, cols, input, mask)?
    } else {
        println!(
            "{} is an image: simulating its k-space on the mask",
            a.input.display()
        );
        KSpace::simulate(rows, cols, &input, mask)?
    };
    let bars = Bars::new("mri");
    let progress: &dyn Progress = &bars;
    let rec = match a.method.as_str() {
        "csalsa" => {
            let reg = match a.reg.as_str() {
                "l1" => Regularizer::default(),
                "tv" => Regularizer::Tv { inner_iters: 20 },
                o => return Err(Error::invalid("reg", format!("{o:?} is not l1 or tv"))),
            };
            let tau0 = a.tau0.unwrap_or(sparsifier::tuned_tau0(&a.prior));
            let p = CsalsaParams::default().max_iter(a.iters).tau0(tau0).epsilon(a.epsilon);
            let wedges = if a.wedges == "auto" {
                if a.prior == "udct" {
                    let c = ScaleChoiceParams::default();
                    let choice = choose_udct_scales(&data, reg, &p, &UdctParams::default(), &c)?;
                    println!("hold-out validation chose {} UDCT scales", choice.scales);
                    vec![[6, 6]; choice.scales]
                } else {
                    vec![[6, 6]]
                }
            } else {
                parse_wedges(&a.wedges)?
            };
            let cfg = PriorParams::default().udct(UdctParams::default().wedges(wedges)).fdct(FdctParams::default().scales(a.fdct_scales).finest(Finest::by_name(&a.fdct_finest)?)).sflct_levels(parse_levels(&a.sflct_levels)?).levels(4);
            let psi = sparsifier::by_name(&a.prior, rows, cols, &cfg)?;
            csalsa(&data, psi.as_ref(), reg, &p, None, progress)?
        }
        "zero-filled" => baselines::zero_filled(&data),
        m @ ("fcsa" | "tvcmri" | "watmri") => {
            let p = CompositeParams::default().a(a.a).b(a.b).group_weight(a.b).max_iter(a.iters);
            match m {
                "fcsa" => baselines::fcsa(&data, &p, None, progress)?,
                "tvcmri" => baselines::tvcmri(&data, &p, None, progress)?,
                _ => baselines::watmri(&data, &p, None, progress)?,
            }
        }
        o => {
            return Err(Error::invalid(
                "method",
                format!("{o:?} is not a valid method. Valid methods are csalsa, fcsa, tvcmri, watmri, zero-filled"),
            ))
        }
    };
    println!(
        "{} x {} at {:.2}% sampling, {} iterations; data residual {:.4e}",
        rows,
        cols,
        100.0 * data.rate(),
        rec.iters,
        data.residual(&rec.image)?
    );
    if let Some(r) = &a.reference {
        let (rr, rc, reference) = read_2d(r)?;
        if (rr, rc) != (rows, cols) {
            return Err(Error::ShapeMismatch(format!(
                "the reference is {rr} x {rc}, not {rows} x {cols}"
            )));
        }
        println!(
            "PSNR {:.2} dB, RLNE {:.4}",
            metrics::psnr(&reference, &rec.image)?,
            metrics::rlne(&reference, &rec.image)?
        );
    }
    write_image(&a.out, rows, cols, &rec.image)?;
    println!("wrote {}", a.out.display());
    Ok(())
}
