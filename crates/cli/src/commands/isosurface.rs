//! `wscg isosurface`: paper 09 (sparse-grid marching cubes with tetrahedral-spline normals) on
//! the user's own volumes.
//!
//! - `extract`: marching cubes of one isovalue on a volume (NIfTI, `.npy`, or raw with
//!   `--raw-dims` and `--raw-type`) whose missing samples are NaN, a `--missing` marker value,
//!   or the non-zero voxels of a `--mask` volume; writes a PLY or OBJ mesh with the chosen
//!   vertex normals.
//! - `study`: the paper's Table 1/2 protocol on the volume: central differences on the full
//!   volume as the reference, spline and LSN normals on the sparsified volume, over evenly
//!   spaced isovalues.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use wscg_isosurface::study::{compare_with_full_cd, percentile_isovalues};
use wscg_isosurface::{marching_cubes, NormalMethod, ScalarGrid};
use wscg_math::io::RawType;
use wscg_math::{Error, Result, TriMesh, Volume};

use crate::commands::volume_file::{self, mesh_to_world, RawSpec};

#[derive(Subcommand, Debug)]
pub enum IsosurfaceCommand {
    /// Extract an isosurface with normals and write it as PLY or OBJ.
    Extract(ExtractArgs),
    /// The paper's accuracy study (spline vs LSN against full-volume central differences).
    Study(StudyArgs),
}

#[derive(Args, Debug)]
pub struct VolumeInput {
    /// Volume file (.nii, .nii.gz, .npy, .vti, a DICOM file or folder, or raw with
    /// --raw-dims); only read.
    volume: PathBuf,
    /// Dimensions x,y,z of a raw volume.
    #[arg(long, value_delimiter = ',')]
    raw_dims: Vec<usize>,
    /// Sample type of a raw volume (u8, i8, u16, i16, u32, i32, f32, f64; little-endian).
    #[arg(long, default_value = "u8")]
    raw_type: String,
    /// Sample spacing x,y,z (default: the NIfTI header's voxel size, else 1,1,1).
    #[arg(long, value_delimiter = ',')]
    spacing: Vec<f64>,
    /// Value marking a missing sample (besides NaN).
    #[arg(long, allow_negative_numbers = true)]
    missing: Option<f32>,
    /// A volume of the same size whose non-zero voxels are missing samples.
    #[arg(long)]
    mask: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct ExtractArgs {
    #[command(flatten)]
    input: VolumeInput,
    /// Isovalue (inside means value >= iso).
    #[arg(long, allow_negative_numbers = true)]
    iso: f32,
    /// Vertex normals: spline (the paper), lsn, central or none.
    #[arg(long, default_value = "spline")]
    normals: String,
    /// Output mesh (.ply or .obj): world millimetres (RAS+, the input's affine) when the input
    /// has one (NIfTI sform/qform, DICOM), else voxel index times spacing.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Args, Debug)]
pub struct StudyArgs {
    #[command(flatten)]
    input: VolumeInput,
    /// Number of isovalues, evenly spaced between the 5th and 95th percentiles.
    #[arg(long, default_value_t = 20)]
    isovalues: usize,
}

fn spacing_arg(s: &[f64]) -> Result<Option<[f64; 3]>> {
    match s {
        [] => Ok(None),
        [x, y, z] => Ok(Some([*x, *y, *z])),
        _ => Err(Error::invalid("spacing", "give three values x,y,z")),
    }
}

fn read_volume(a: &VolumeInput) -> Result<Volume<f32>> {
    let spacing = spacing_arg(&a.spacing)?;
    let raw = if a.raw_dims.is_empty() {
        None
    } else {
        let dims: [usize; 3] = a
            .raw_dims
            .clone()
            .try_into()
            .map_err(|_| Error::invalid("raw_dims", "a raw volume needs --raw-dims x,y,z"))?;
        Some(RawSpec {
            dims,
            kind: a.raw_type.parse::<RawType>()?,
        })
    };
    let read = |p: &Path| volume_file::read_volume(p, raw, spacing);
    let mut v = read(&a.volume)?;
    if let Some(m) = a.missing {
        for x in v.data_mut() {
            if *x == m {
                *x = f32::NAN;
            }
        }
    }
    if let Some(path) = &a.mask {
        let mask = read(path)?;
        if mask.dims() != v.dims() {
            return Err(Error::ShapeMismatch(format!(
                "mask {} has dims {:?} but the volume has {:?}",
                path.display(),
                mask.dims(),
                v.dims()
            )));
        }
        for (x, &m) in v.data_mut().iter_mut().zip(mask.data()) {
            if m != 0.0 {
                *x = f32::NAN;
            }
        }
    }
    Ok(v)
}

fn grid(v: &Volume<f32>) -> Result<ScalarGrid<'_>> {
    ScalarGrid::with_spacing(v.dims(), v.spacing().map(|s| s as f32), v.data())
}

pub fn run(cmd: IsosurfaceCommand) -> Result<()> {
    match cmd {
        IsosurfaceCommand::Extract(a) => {
            let inputs = [Some(&a.input.volume), a.input.mask.as_ref()];
            crate::commands::overwrite::check_file("out", &a.out, inputs.into_iter().flatten())?;
            let v = read_volume(&a.input)?;
            let method = NormalMethod::parse(&a.normals)?;
            let g = grid(&v)?;
            let mesh = marching_cubes(&g, a.iso, method)?;
            println!(
                "{} vertices, {} triangles; normals {}: {} undefined, {} from the fallback; {} \
                 cells skipped; {} missing samples",
                mesh.vertices.len(),
                mesh.triangles.len(),
                method.name(),
                mesh.stats.undefined,
                mesh.stats.fallback,
                mesh.stats.skipped_cells,
                g.missing_count()
            );
            let positions = mesh.vertices.iter().map(|p| p.map(|x| x as f64)).collect();
            let mut out = TriMesh::new(positions, mesh.triangles)?;
            if !mesh.normals.is_empty() {
                out =
                    out.with_normals(mesh.normals.iter().map(|n| n.map(|x| x as f64)).collect())?;
            }
            let (out, world) = mesh_to_world(out, &v);
            out.write(&a.out)?;
            if world {
                println!(
                    "wrote {} (vertices in world millimetres, RAS+: the input's affine)",
                    a.out.display()
                );
            } else {
                println!(
                    "wrote {} (vertices at voxel index times spacing: the input has no affine)",
                    a.out.display()
                );
            }
            Ok(())
        }
        IsosurfaceCommand::Study(a) => {
            let v = read_volume(&a.input)?;
            let isos = percentile_isovalues(v.data(), a.isovalues, 5.0, 95.0)?;
            println!(
                "{:>12} {:>9} {:>10} {:>10} {:>9} {:>9} {:>8}",
                "isovalue", "vertices", "spline", "LSN", "LSN zero", "CD def.", "kept"
            );
            let (mut ss, mut sl, mut k) = (0.0, 0.0, 0);
            for iso in isos {
                let c = compare_with_full_cd(v.view(), iso)?;
                println!(
                    "{iso:>12.4} {:>9} {:>10.4} {:>10.4} {:>9} {:>8.2}% {:>7.2}%",
                    c.vertices,
                    c.spline.rms,
                    c.lsn.rms,
                    c.lsn_undefined,
                    100.0 * c.cd_defined_on_sparse,
                    100.0 * c.kept_fraction
                );
                if c.spline.count > 0 && c.lsn.count > 0 {
                    ss += c.spline.rms;
                    sl += c.lsn.rms;
                    k += 1;
                }
            }
            if k > 0 {
                println!(
                    "mean RMS over {k} isovalues (rad, vs full-volume central differences): \
                     spline {:.4}, LSN {:.4}",
                    ss / k as f64,
                    sl / k as f64
                );
            }
            Ok(())
        }
    }
}
