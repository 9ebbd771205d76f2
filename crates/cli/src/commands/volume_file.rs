//! The one way every command reads, writes and places volumes: a reader that dispatches on the
//! path (NIfTI, `.npy`, DICOM file or folder, VTK `.vti`, headerless raw), a writer that keeps
//! the input's geometry, and the map of mesh vertices from grid to world millimetres.

use std::path::Path;

use wscg_math::io::RawType;
use wscg_math::mesh::TriMesh;
use wscg_math::volume::apply_affine;
use wscg_math::{Error, Result, Volume};
use wscg_volren::vti::read_vti;

/// How to read a headerless raw file: its dims `[nx, ny, nz]` and sample type.
#[derive(Clone, Copy, Debug)]
pub struct RawSpec {
    pub dims: [usize; 3],
    pub kind: RawType,
}

/// True for the extensions of headerless raw files (`.raw`, `.bin`).
pub fn is_raw_name(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("raw") || e.eq_ignore_ascii_case("bin"))
}

/// Reads a volume: `.vti` (VTK image data), a raw file when `raw` is given, otherwise
/// [`Volume::read`] (`.nii`, `.nii.gz`, `.npy`, a DICOM file or a folder of them). `spacing`
/// replaces the file's voxel size (a raw file's default is 1).
///
/// Errors: a raw name without `raw` ([`Error::InvalidArgument`] naming `raw_dims`); the
/// readers' errors.
pub fn read_volume(
    path: &Path,
    raw: Option<RawSpec>,
    spacing: Option<[f64; 3]>,
) -> Result<Volume<f32>> {
    let is_vti = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vti"));
    if is_vti {
        let v = read_vti(path)?;
        let mut vol = Volume::new(v.dims, v.spacing, v.values.to_f32())?;
        if let Some(s) = spacing {
            vol.set_spacing(s)?;
        }
        return Ok(vol);
    }
    match raw {
        Some(r) => Volume::read_raw(path, r.dims, spacing.unwrap_or([1.0; 3]), r.kind),
        None if is_raw_name(path) => Err(Error::invalid(
            "raw_dims",
            format!(
                "{} is a raw volume: give its dims x,y,z (--raw-dims)",
                path.display()
            ),
        )),
        None => Volume::read(path, spacing),
    }
}

/// Writes a volume derived from `input` (labels, a mask, a filtered volume) with `input`'s
/// geometry (spacing and affine), as `.nii` / `.nii.gz` (the affine as sform and qform) or
/// `.npy` (values only).
///
/// Errors: another extension ([`Error::UnsupportedFormat`]); dims other than `input`'s; I/O.
pub fn write_derived<U>(path: &Path, mut v: Volume<f32>, input: &Volume<U>) -> Result<()> {
    v.copy_geometry(input)?;
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

/// Moves a mesh from the grid coordinates of `v` (voxel index times spacing, as the
/// isosurface extractors place vertices) to world millimetres through `v`'s affine, RAS+
/// (see [`wscg_math::volume`]). Normals follow by the inverse transpose, and a mirroring
/// affine reverses the faces' winding so that they still face outwards. Returns the mesh
/// unchanged, and `false`, when `v` has no affine.
pub fn mesh_to_world<U>(mut mesh: TriMesh, v: &Volume<U>) -> Result<(TriMesh, bool)> {
    let Some(a) = v.affine() else {
        return Ok((mesh, false));
    };
    let s = v.spacing();
    for p in &mut mesh.positions {
        *p = apply_affine(&a, [p[0] / s[0], p[1] / s[1], p[2] / s[2]]);
    }
    // Linear part acting on grid coordinates: M = A3 diag(1/s).
    let m: [[f64; 3]; 3] = [0, 1, 2].map(|r| [0, 1, 2].map(|c| a[r][c] / s[c]));
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    if let Some(normals) = &mut mesh.normals {
        // Cofactor matrix = det * (M^-1)^T; the scale drops out with the normalisation.
        let cof = |r: usize, c: usize| {
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]
        };
        let sign = det.signum();
        for n in normals.iter_mut() {
            let t = [0, 1, 2].map(|r| sign * (0..3).map(|c| cof(r, c) * n[c]).sum::<f64>());
            let len = t.iter().map(|x| x * x).sum::<f64>().sqrt();
            *n = if len > 0.0 { t.map(|x| x / len) } else { *n };
        }
    }
    if det < 0.0 {
        for f in &mut mesh.faces {
            f.swap(1, 2);
        }
    }
    Ok((mesh, true))
}
