//! `wscg volseg`: paper 18 (BoneSplit, random walks on the bone-only graph) on the user's own
//! CT volumes.
//!
//! - `split CT --seeds SEEDS --out LABELS`: CT in HU (`.nii`, `.nii.gz` or `.npy` `[z, y, x]`),
//!   seeds a label volume of the same shape (0 = none, 1..K = bones); writes the label volume
//!   (same format rules, float32 values 0..K) and prints iterations and time per label.
//! - `phantom --out DIR`: the fractured-shell phantom as `ct.nii`, `truth.nii`, `seeds.nii`.

use std::path::PathBuf;

use clap::{Args, Subcommand};
use wscg_math::{Error, Result, Volume};
use wscg_volseg::{
    dice_multilabel, fractured_shell_phantom, nearest_seed_labels, BoneGraph, PhantomConfig,
    RwParams, RwSession,
};

#[derive(Subcommand, Debug)]
pub enum VolsegCommand {
    /// Separate the bones of a CT volume from seed strokes (random walks on the bone graph).
    Split(SplitArgs),
    /// Write the synthetic fractured-shell phantom (ct.nii, truth.nii, seeds.nii).
    Phantom {
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Side of the cubic volume, voxels.
        #[arg(long, default_value_t = 128)]
        size: usize,
        /// Number of fragments.
        #[arg(long, default_value_t = 6)]
        fragments: usize,
        /// Seed of the fragments, strokes and noise.
        #[arg(long, default_value_t = 0)]
        seed: u64,
    },
}

#[derive(Args, Debug)]
pub struct SplitArgs {
    /// CT volume in HU (.nii, .nii.gz, .npy).
    ct: PathBuf,
    /// Seed label volume of the same shape (0 = none).
    #[arg(long)]
    seeds: PathBuf,
    /// Output label volume (.nii, .nii.gz or .npy).
    #[arg(long)]
    out: PathBuf,
    /// Bone threshold, HU.
    #[arg(long, default_value_t = 300.0)]
    t_bone: f64,
    /// Weight sharpness beta (eq. 1).
    #[arg(long, default_value_t = 3000.0)]
    beta: f64,
    /// Constant added to every edge weight.
    #[arg(long, default_value_t = 0.01)]
    eps: f64,
    /// Diagonal regulariser kappa.
    #[arg(long, default_value_t = 1e-3)]
    kappa: f64,
    /// Relative residual of the conjugate gradients.
    #[arg(long, default_value_t = 3e-3)]
    tol: f64,
    /// Geodesic nearest-seed labelling instead of random walks (baseline).
    #[arg(long)]
    baseline: bool,
    /// Ground-truth label volume: print the multi-label Dice of the result.
    #[arg(long)]
    truth: Option<PathBuf>,
}

fn write(path: &std::path::Path, v: &Volume<f32>) -> Result<()> {
    let name = path.to_string_lossy().to_ascii_lowercase();
    if name.ends_with(".npy") {
        v.write_npy(path)
    } else if name.ends_with(".nii") || name.ends_with(".nii.gz") {
        v.write_nifti(path)
    } else {
        Err(Error::UnsupportedFormat(format!(
            "{}: write .nii, .nii.gz or .npy",
            path.display()
        )))
    }
}

fn to_u16(v: &Volume<f32>, name: &'static str) -> Result<Vec<u16>> {
    v.data()
        .iter()
        .map(|&x| {
            if (0.0..=65535.0).contains(&x) && x.fract() == 0.0 {
                Ok(x as u16)
            } else {
                Err(Error::invalid(
                    name,
                    format!("labels must be integers in 0..=65535, found {x}"),
                ))
            }
        })
        .collect()
}

/// Runs a `wscg volseg` command.
pub fn run(cmd: VolsegCommand) -> Result<()> {
    match cmd {
        VolsegCommand::Phantom {
            out,
            size,
            fragments,
            seed,
        } => {
            let ph = fractured_shell_phantom(&PhantomConfig {
                dims: [size; 3],
                fragments,
                seed,
                ..PhantomConfig::default()
            })?;
            std::fs::create_dir_all(&out).map_err(|e| Error::io(&out, e))?;
            let f = |v: &Volume<u16>| {
                Volume::new(
                    v.dims(),
                    v.spacing(),
                    v.data().iter().map(|&x| f32::from(x)).collect(),
                )
            };
            ph.ct.write_nifti(out.join("ct.nii"))?;
            f(&ph.truth)?.write_nifti(out.join("truth.nii"))?;
            f(&ph.seeds)?.write_nifti(out.join("seeds.nii"))?;
            let bone = ph.truth.data().iter().filter(|&&l| l != 0).count();
            println!("wrote ct.nii, truth.nii, seeds.nii ({size}^3, {fragments} fragments, {bone} bone voxels) to {}", out.display());
            Ok(())
        }
        VolsegCommand::Split(a) => {
            let ct = Volume::read(&a.ct, None)?;
            let seeds_f = Volume::read(&a.seeds, None)?;
            if seeds_f.dims() != ct.dims() {
                return Err(Error::ShapeMismatch(format!(
                    "seeds are {:?}, the CT {:?}",
                    seeds_f.dims(),
                    ct.dims()
                )));
            }
            let seeds = Volume::new(ct.dims(), ct.spacing(), to_u16(&seeds_f, "seeds")?)?;
            let p = RwParams {
                t_bone: a.t_bone,
                beta: a.beta,
                eps: a.eps,
                kappa: a.kappa,
                tol: a.tol,
                ..RwParams::default()
            };
            let g = BoneGraph::build(&ct, &p)?;
            println!(
                "{} bone voxels, {} edges (threshold {} HU)",
                g.len(),
                g.edges(),
                p.t_bone
            );
            let mut s = RwSession::new(g, p)?;
            let placed = s.set_seeds(&seeds)?;
            let total = seeds.data().iter().filter(|&&l| l != 0).count();
            if placed < total {
                eprintln!(
                    "warning: {} of {total} seed voxels are not bone and were ignored",
                    total - placed
                );
            }
            let labels: Vec<u16> = if a.baseline {
                let g = s.graph();
                let node_seeds: Vec<u16> = (0..g.len()).map(|i| seeds.data()[g.voxel(i)]).collect();
                if node_seeds.iter().all(|&l| l == 0) {
                    return Err(Error::invalid("seeds", "no seed lies on a bone voxel"));
                }
                let mut out = vec![0u16; ct.len()];
                for (i, l) in nearest_seed_labels(g, &node_seeds).into_iter().enumerate() {
                    out[g.voxel(i)] = l;
                }
                out
            } else {
                let r = s.solve(false)?;
                for (k, (it, sec)) in r.iterations.iter().zip(&r.seconds).enumerate() {
                    println!(
                        "label {}: {it} iterations, {sec:.3} s, residual {:.2e}",
                        k + 1,
                        r.residuals[k]
                    );
                }
                s.labels()?.into_data()
            };
            if let Some(t) = &a.truth {
                let truth = to_u16(&Volume::read(t, None)?, "truth")?;
                println!(
                    "multi-label Dice against {}: {:.4}",
                    t.display(),
                    dice_multilabel(&labels, &truth)?
                );
            }
            let out = Volume::new(
                ct.dims(),
                ct.spacing(),
                labels.iter().map(|&l| f32::from(l)).collect(),
            )?;
            write(&a.out, &out)?;
            println!("wrote {}", a.out.display());
            Ok(())
        }
    }
}
