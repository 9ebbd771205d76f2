//! The one way every command reads, writes and places volumes: a reader that dispatches on the
//! path (NIfTI, `.npy`, DICOM file or folder, VTK `.vti`, headerless raw), a writer that keeps
//! the input's geometry, and the map of mesh vertices from grid to world millimetres.

use std::path::Path;

use wscg_math::io::RawType;
use wscg_math::mesh::TriMesh;
use wscg_math::vec3::{cross, dot, try_normalize};
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
pub fn mesh_to_world<U>(mut mesh: TriMesh, v: &Volume<U>) -> (TriMesh, bool) {
    let Some(a) = v.affine() else {
        return (mesh, false);
    };
    let s = v.spacing();
    for p in &mut mesh.positions {
        *p = apply_affine(&a, [p[0] / s[0], p[1] / s[1], p[2] / s[2]]);
    }
    // Linear part acting on grid coordinates: M = A3 diag(1/s).
    let m: [[f64; 3]; 3] = [0, 1, 2].map(|r| [0, 1, 2].map(|c| a[r][c] / s[c]));
    // (M^-1)^T = [m1 x m2; m2 x m0; m0 x m1] / det M (rows m0, m1, m2 of M); the scale
    // drops out with the normalisation, the sign does not.
    let det = dot(m[0], cross(m[1], m[2]));
    let cof = [0, 1, 2].map(|r| cross(m[(r + 1) % 3], m[(r + 2) % 3]));
    if let Some(normals) = &mut mesh.normals {
        for n in normals.iter_mut() {
            let t = [0, 1, 2].map(|r| det.signum() * dot(cof[r], *n));
            *n = try_normalize(t, 0.0).unwrap_or(*n);
        }
    }
    if det < 0.0 {
        for f in &mut mesh.faces {
            f.swap(1, 2);
        }
    }
    (mesh, true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mirroring_oblique_affine_moves_vertices_and_keeps_the_surface_outward() {
        // A unit cube in grid coordinates of a volume with spacing (2, 1, 0.5).
        let cube = TriMesh::cube(1.0).unwrap();
        let normals = cube.vertex_normals();
        let cube = cube.with_normals(normals).unwrap();
        let mut v = Volume::filled([4, 4, 4], [2.0, 1.0, 0.5], 0u8).unwrap();
        assert!(!mesh_to_world(cube.clone(), &v).1);
        let (c, s) = (0.6, 0.8);
        // x mirrored, then a rotation about z; origin (5, -3, 10).
        let a = [
            [-2.0 * c, -s, 0.0, 5.0],
            [-2.0 * s, c, 0.0, -3.0],
            [0.0, 0.0, 0.5, 10.0],
        ];
        v.set_affine(Some(a)).unwrap();
        let (w, placed) = mesh_to_world(cube.clone(), &v);
        assert!(placed);
        for (p, q) in cube.positions.iter().zip(&w.positions) {
            let want = apply_affine(&a, [p[0] / 2.0, p[1], p[2] / 0.5]);
            assert!((0..3).all(|k| (want[k] - q[k]).abs() < 1e-12));
        }
        // Grid to world is a rotation times a mirror with unit scale here: volume kept, the
        // winding still outward, and the normals those of the moved faces.
        assert!((w.signed_volume() - cube.signed_volume()).abs() < 1e-9);
        assert!(w.signed_volume() > 0.0);
        for (n, m) in w.normals.as_ref().unwrap().iter().zip(w.vertex_normals()) {
            assert!(dot(*n, m) > 0.999, "{n:?} {m:?}");
        }
    }
}
