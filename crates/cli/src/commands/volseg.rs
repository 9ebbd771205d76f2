//! `wscg volseg`: paper 18 (BoneSplit, random walks on the bone-only graph) on the user's own
//! CT volumes.
//!
//! - `split CT --seeds SEEDS --out LABELS`: CT in HU (`.nii`, `.nii.gz` or `.npy` `[z, y, x]`),
//!   seeds a label volume of the same shape (0 = none, 1..K = bones) or `--strokes S.json`, a
//!   list of `{"label": k, "points": [[x, y, z], ...], "radius": r}` balls (voxel units);
//!   writes the label volume (same format rules, float32 values 0..K), optionally one mesh per
//!   label (`--meshes DIR`, marching cubes of the label's indicator, `.obj` or `.ply`) and
//!   prints iterations and time per label.
//! - `phantom --out DIR`: the fractured-shell phantom as `ct.nii`, `truth.nii`, `seeds.nii`.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand, ValueEnum};
use wscg_isosurface::{extract, ScalarGrid};
use wscg_math::mesh::TriMesh;
use wscg_math::{Error, Result, Volume};

use crate::commands::volume_file::{mesh_to_world, read_volume, write_derived};
use wscg_volseg::{
    dice_multilabel, fractured_shell_phantom, gaussian_smooth3, nearest_seed_labels,
    remove_small_components, BoneGraph, PhantomParams, Precision, RandomWalkParams,
    RandomWalkSession, Solver,
};

#[derive(Subcommand, Debug)]
pub enum VolsegCommand {
    /// Separate the bones of a CT volume from seed strokes (random walks on the bone graph).
    Split(Box<SplitArgs>),
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
    /// CT volume in HU (.nii, .nii.gz, .npy, or a DICOM file or folder).
    ct: PathBuf,
    /// Seed label volume of the same shape (0 = none; any volume format).
    #[arg(long, required_unless_present = "strokes", conflicts_with = "strokes")]
    seeds: Option<PathBuf>,
    /// Seed strokes as JSON: `[{"label": 1, "points": [[x, y, z], ...], "radius": 2}, ...]`
    /// (voxel coordinates; radius defaults to 1).
    #[arg(long)]
    strokes: Option<PathBuf>,
    /// Output label volume (.nii, .nii.gz or .npy), with the CT's geometry (NIfTI: its affine).
    #[arg(long)]
    out: PathBuf,
    /// Bone threshold, HU.
    #[arg(long, default_value_t = 300.0)]
    t_bone: f64,
    /// Where --beta, --eps and --kappa come from when not given. default (1e4, 2e-3, 3e-5):
    /// DSC 0.956-0.979 on fractured-shell phantoms, ~2x the CG iterations of the paper's.
    /// paper (3000, 0.01, 1e-3, section 2.4): faster, but thin fractures leak and voxels
    /// far from every stroke follow the leak (DSC 0.75-0.92 on the same phantoms).
    #[arg(long, value_enum, default_value_t = PresetArg::Default)]
    preset: PresetArg,
    /// Weight sharpness beta (eq. 1) [default: the preset's, 1e4; paper 3000]. From ~1.5e4
    /// it cuts thin or noisy bone into pieces; lower it for CT much noisier than 30 HU.
    #[arg(long)]
    beta: Option<f64>,
    /// Constant added to every edge weight [default: the preset's, 2e-3; paper 0.01].
    #[arg(long)]
    eps: Option<f64>,
    /// Diagonal regulariser kappa [default: the preset's, 3e-5; paper 1e-3]. 0 is Grady's
    /// plain problem: as good with strokes inside the bone, but strokes on the surface
    /// can then let one label take most of the bone.
    #[arg(long)]
    kappa: Option<f64>,
    /// Relative residual of the conjugate gradients.
    #[arg(long, default_value_t = 3e-3)]
    tol: f64,
    /// Passes of the anisotropy-aware 3-tap Gaussian before the threshold.
    #[arg(long, default_value_t = 0)]
    smooth: u32,
    /// Divide intensity differences by the voxel spacing (scikit-image's weights).
    #[arg(long)]
    spacing_in_weights: bool,
    /// Solver layout.
    #[arg(long, value_enum, default_value_t = SolverArg::Block)]
    solver: SolverArg,
    /// f64 vectors instead of f32.
    #[arg(long)]
    f64: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// Relabel label islands smaller than this many voxels to their neighbours' label.
    #[arg(long, default_value_t = 0)]
    min_island: usize,
    /// Folder for one mesh per label (marching cubes of its indicator), in world millimetres
    /// (RAS+, the CT's affine) when the CT has one, else voxel index times spacing.
    #[arg(long)]
    meshes: Option<PathBuf>,
    /// Mesh format in --meshes.
    #[arg(long, default_value = "obj")]
    mesh_format: String,
    /// Geodesic nearest-seed labelling instead of random walks (baseline).
    #[arg(long)]
    baseline: bool,
    /// Ground-truth label volume: print the multi-label Dice of the result.
    #[arg(long)]
    truth: Option<PathBuf>,
}

/// `--preset` values.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum PresetArg {
    /// beta 1e4, eps 2e-3, kappa 3e-5.
    Default,
    /// The paper's beta 3000, eps 0.01, kappa 1e-3.
    Paper,
}

/// `--solver` values.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum SolverArg {
    /// All labels in one sweep over the graph.
    Block,
    /// One label after the other (the paper's CPU path).
    PerLabel,
    /// One label after the other without the Jacobi preconditioner.
    Cg,
}

/// Writes one mesh per non-zero label of `labels` into `dir` (`label_K.<format>`): marching
/// cubes at 0.5 of the label's indicator, cropped to its bounding box plus one voxel.
fn write_meshes(labels: &Volume<u16>, dir: &Path, format: &str) -> Result<usize> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let d = labels.dims();
    let k = labels.data().iter().copied().max().unwrap_or(0);
    let h = labels.spacing();
    let mut written = 0;
    // Bounding boxes of all labels in one pass over the volume.
    let mut boxes = vec![([usize::MAX; 3], [0usize; 3]); k as usize + 1];
    for (i, &v) in labels.data().iter().enumerate() {
        if v != 0 {
            let c = [i % d[0], (i / d[0]) % d[1], i / (d[0] * d[1])];
            let (lo, hi) = &mut boxes[v as usize];
            for a in 0..3 {
                lo[a] = lo[a].min(c[a]);
                hi[a] = hi[a].max(c[a]);
            }
        }
    }
    for l in 1..=k {
        let (lo, hi) = boxes[l as usize];
        if lo[0] == usize::MAX {
            continue;
        }
        // One voxel of zeros around the box closes the surface at the volume border.
        let size = [0, 1, 2].map(|a| hi[a] - lo[a] + 3);
        let mut f = vec![0f32; size[0] * size[1] * size[2]];
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    if labels.at(x, y, z) == l {
                        let (a, b, c) = (x - lo[0] + 1, y - lo[1] + 1, z - lo[2] + 1);
                        f[a + size[0] * (b + size[1] * c)] = 1.0;
                    }
                }
            }
        }
        let grid = ScalarGrid {
            dims: size,
            spacing: h.map(|s| s as f32),
            values: &f,
            side_hint: None,
        };
        let m = extract(&grid, 0.5).map_err(|e| Error::invalid("meshes", e.to_string()))?;
        let origin = [0, 1, 2].map(|a| (lo[a] as f64 - 1.0) * h[a]);
        let pos = m
            .vertices
            .iter()
            .map(|v| [0, 1, 2].map(|a| f64::from(v[a]) + origin[a]))
            .collect();
        let (mesh, _) = mesh_to_world(TriMesh::new(pos, m.triangles)?, labels);
        mesh.write(dir.join(format!("label_{l}.{format}")))?;
        written += 1;
    }
    Ok(written)
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
            let ph = fractured_shell_phantom(
                &PhantomParams::default()
                    .dims([size; 3])
                    .fragments(fragments)
                    .seed(seed),
            )?;
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
            let inputs = [
                Some(&a.ct),
                a.seeds.as_ref(),
                a.strokes.as_ref(),
                a.truth.as_ref(),
            ];
            let inputs: Vec<_> = inputs.into_iter().flatten().collect();
            crate::commands::overwrite::check_file("out", &a.out, &inputs)?;
            if let Some(dir) = &a.meshes {
                crate::commands::overwrite::check_folder("meshes", dir, &inputs)?;
            }
            let ct_file = read_volume(&a.ct, None, None)?;
            let mut ct = gaussian_smooth3(&ct_file, a.smooth)?;
            ct.copy_geometry(&ct_file)?;
            drop(ct_file);
            let seeds = match (&a.seeds, &a.strokes) {
                (Some(path), _) => {
                    let seeds_f = read_volume(path, None, None)?;
                    if seeds_f.dims() != ct.dims() {
                        return Err(Error::ShapeMismatch(format!(
                            "seeds are {:?}, the CT {:?}",
                            seeds_f.dims(),
                            ct.dims()
                        )));
                    }
                    Volume::new(ct.dims(), ct.spacing(), to_u16(&seeds_f, "seeds")?)?
                }
                (None, Some(path)) => {
                    wscg_volseg::edit::read_strokes(path, ct.dims(), ct.spacing())?
                }
                (None, None) => {
                    return Err(Error::invalid("seeds", "give --seeds or --strokes"));
                }
            };
            let (solver, jacobi) = match a.solver {
                SolverArg::Block => (Solver::Block, true),
                SolverArg::PerLabel => (Solver::PerLabel, true),
                SolverArg::Cg => (Solver::PerLabel, false),
            };
            let preset = match a.preset {
                PresetArg::Default => RandomWalkParams::default(),
                PresetArg::Paper => RandomWalkParams::paper(),
            };
            let p = preset
                .t_bone(a.t_bone)
                .beta(a.beta.unwrap_or(preset.beta))
                .eps(a.eps.unwrap_or(preset.eps))
                .kappa(a.kappa.unwrap_or(preset.kappa))
                .tol(a.tol)
                .spacing_in_weights(a.spacing_in_weights)
                .solver(solver)
                .jacobi(jacobi)
                .precision(if a.f64 {
                    Precision::F64
                } else {
                    Precision::F32
                })
                .threads(a.threads);
            let g = BoneGraph::build(&ct, &p)?;
            println!(
                "{} bone voxels, {} edges (threshold {} HU)",
                g.len(),
                g.edges(),
                p.t_bone
            );
            let mut s = RandomWalkSession::new(g, p)?;
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
                if r.unreached > 0 {
                    eprintln!(
                        "warning: {} bone voxels lie in components without any seed and stay 0",
                        r.unreached
                    );
                }
                s.labels()?.into_data()
            };
            let mut labels = Volume::new(ct.dims(), ct.spacing(), labels)?;
            labels.copy_geometry(&ct)?;
            if a.min_island > 0 {
                let n = remove_small_components(&mut labels, a.min_island);
                println!(
                    "relabelled {n} voxels of islands under {} voxels",
                    a.min_island
                );
            }
            if let Some(dir) = &a.meshes {
                let n = write_meshes(&labels, dir, &a.mesh_format)?;
                println!("wrote {n} meshes to {}", dir.display());
            }
            let labels = labels.into_data();
            if let Some(t) = &a.truth {
                let truth = to_u16(&read_volume(t, None, None)?, "truth")?;
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
            write_derived(&a.out, out, &ct)?;
            println!("wrote {}", a.out.display());
            Ok(())
        }
    }
}
