//! NIfTI-1 single-file volumes, `.nii` and gzip-compressed `.nii.gz`:
//! [`Volume::read_nifti`] and [`Volume::write_nifti`].
//!
//! The reader checks every size the header declares against the file (or, compressed, against
//! the stream as it arrives) and against [`MAX_VOXELS`](crate::volume::MAX_VOXELS) before it allocates, so a hostile
//! header cannot make it allocate without bound.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

use ndarray::{ArrayView3, Ix3, ShapeBuilder};
use nifti::{IntoNdArray, NiftiError, NiftiHeader, NiftiType};

use super::{file_kind, read_up_to, FileKind};
use crate::error::{read_error, Error, Result};
use crate::vec3::{cross, dot};
use crate::volume::{check_affine, voxel_count, Affine, Real, Volume};

/// Largest NIfTI `vox_offset` (header plus extensions, in bytes) accepted from a file.
const MAX_NIFTI_VOX_OFFSET: u64 = 1 << 30;

/// Size of a NIfTI-1 header in bytes.
const NIFTI1_HEADER_BYTES: usize = 348;

/// Converts a header `f32` to the `f64` with the same shortest decimal form (0.7f32 -> 0.7),
/// so that spacings written as `f32` read back as the decimal the user gave.
fn f32_to_f64_decimal(v: f32) -> f64 {
    v.to_string().parse().unwrap_or(v as f64)
}

impl<T: Real> Volume<T> {
    /// Writes a single-file NIfTI-1 image with `f32` voxels (`datatype` FLOAT32), dims
    /// `[nx, ny, nz]`, `pixdim[1..4]` = spacing (units: mm), `scl_slope` 1, and the sform
    /// [`Volume::voxel_to_world`] (the volume's RAS+ affine, or `diag(spacing)` when none is
    /// known), with the matching qform unless the affine shears. The file is gzip-compressed
    /// when the name ends in `.gz`.
    ///
    /// Errors: a name that ends in neither `.nii` nor `.nii.gz` ([`Error::UnsupportedFormat`]),
    /// a dimension above 32767 (the NIfTI-1 limit, [`Error::LimitExceeded`]), I/O failures.
    pub fn write_nifti(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let kind = file_kind(path);
        let gz = match kind {
            FileKind::Nii => false,
            FileKind::NiiGz => true,
            _ => {
                return Err(Error::UnsupportedFormat(format!(
                    "cannot write {} as NIfTI: the name must end in .nii or .nii.gz",
                    path.display()
                )))
            }
        };
        if let Some(&d) = self.dims.iter().find(|&&d| d > i16::MAX as usize) {
            return Err(Error::LimitExceeded(format!(
                "cannot write {}: dimension {d} exceeds the NIfTI-1 limit of {}",
                path.display(),
                i16::MAX
            )));
        }
        let [sx, sy, sz] = self.spacing.map(|s| s as f32);
        // The sform is the volume's affine (RAS+ mm; diag(spacing) when none is known); the
        // qform the same rotation where it is one (NIfTI-1 method 2), absent for a shear.
        let m = self.voxel_to_world();
        let qform = affine_to_quaternion(&m);
        let (quatern, qfac) = qform.unwrap_or(([0.0; 3], 1.0));
        let header = NiftiHeader {
            pixdim: [qfac, sx, sy, sz, 1.0, 1.0, 1.0, 1.0],
            xyzt_units: 2, // NIFTI_UNITS_MM
            qform_code: if qform.is_some() { 1 } else { 0 },
            sform_code: 1,
            quatern_b: quatern[0],
            quatern_c: quatern[1],
            quatern_d: quatern[2],
            quatern_x: m[0][3] as f32,
            quatern_y: m[1][3] as f32,
            quatern_z: m[2][3] as f32,
            srow_x: m[0].map(|v| v as f32),
            srow_y: m[1].map(|v| v as f32),
            srow_z: m[2].map(|v| v as f32),
            ..NiftiHeader::default()
        };
        let values = T::as_f32_slice(&self.data);
        let [nx, ny, nz] = self.dims;
        // Logical shape [x, y, z] over x-fastest memory = Fortran order.
        let array = ArrayView3::from_shape((nx, ny, nz).f(), &values[..])
            .expect("volume invariant: data length equals nx * ny * nz");

        // The nifti writer rewrites file names with several dots: it writes a plain temporary
        // name in the same folder, which is then renamed.
        super::atomic::write_via_temp_path(path, if gz { "nii.gz" } else { "nii" }, |tmp| {
            match nifti::writer::WriterOptions::new(tmp)
                .reference_header(&header)
                .write_nifti(&array)
            {
                Ok(()) => Ok(()),
                Err(NiftiError::Io(e)) => Err(Error::io(path, e)),
                Err(e) => Err(Error::io(path, io::Error::other(e.to_string()))),
            }
        })
    }
}

impl Volume<f32> {
    /// Reads a single-file NIfTI-1 image (`.nii`, or gzip-compressed `.nii.gz`; compression
    /// is detected from the content).
    ///
    /// - Voxel values are converted to `f32` and scaled by `scl_slope` / `scl_inter` as the
    ///   NIfTI standard says (no scaling when `scl_slope` is 0 or not finite). Supported data
    ///   types: (u)int8/16/32/64, float32, float64.
    /// - `dims = dim[1..4]`; the image must be 3-D (`dim[0] = 3`, or more with every extra
    ///   dimension equal to 1, e.g. a 4-D image with one time point).
    /// - `spacing = |pixdim[1..4]|`, 1.0 where a pixdim is 0 or not finite. The voxels keep
    ///   the stored order: voxel `(x, y, z)` of the volume is voxel `(i, j, k) = (x, y, z)` of
    ///   the file, as `nibabel.load(path).get_fdata()[x, y, z]`.
    /// - [`Volume::affine`] is the header's voxel-to-world affine as nibabel's `img.affine`:
    ///   the sform when `sform_code > 0`, else the qform when `qform_code > 0`, else `None`
    ///   (nibabel then makes up a centred, x-flipped affine; wscg keeps `diag(spacing)`).
    ///
    /// Errors: [`Error::Io`] naming the path; [`Error::Format`] for a malformed or truncated
    /// file; [`Error::UnsupportedFormat`] for NIfTI-2, `.hdr/.img` pairs, other data types or
    /// non-3-D images; [`Error::LimitExceeded`] when the header declares more than
    /// [`MAX_VOXELS`](crate::volume::MAX_VOXELS) voxels. The declared size is checked against the file size (or, for
    /// gzip, against the decompressed stream as it arrives) before anything large is allocated.
    pub fn read_nifti(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        let file_len = file.metadata().map_err(|e| Error::io(path, e))?.len();
        read_nifti_buffered(path, BufReader::new(file), file_len)
    }

    /// [`Volume::read_nifti`] of a file held in memory (`.nii` or gzip-compressed, detected
    /// from the content); `origin` names the file in errors. Errors as
    /// [`Volume::read_nifti`].
    pub fn from_nifti_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        read_nifti_buffered(origin, bytes, bytes.len() as u64)
    }
}

/// Reads a NIfTI-1 file of `len` bytes from `buffered`, decompressing it when it starts with
/// the gzip magic.
fn read_nifti_buffered(path: &Path, mut buffered: impl BufRead, len: u64) -> Result<Volume<f32>> {
    let head = buffered.fill_buf().map_err(|e| Error::io(path, e))?;
    let gz = head.len() >= 2 && head[0] == 0x1f && head[1] == 0x8b;
    if gz {
        let mut reader = flate2::bufread::GzDecoder::new(buffered);
        read_nifti_stream(path, &mut reader, None)
    } else {
        read_nifti_stream(path, &mut buffered, Some(len))
    }
}

/// Reads a NIfTI-1 single-file stream (already decompressed). `file_len` is the size of an
/// uncompressed file, used to reject declared sizes the file cannot hold.
fn read_nifti_stream(
    path: &Path,
    reader: &mut impl Read,
    file_len: Option<u64>,
) -> Result<Volume<f32>> {
    // Header.
    let mut raw_header = [0u8; NIFTI1_HEADER_BYTES];
    let mut got = 0;
    while got < raw_header.len() {
        match reader.read(&mut raw_header[got..]) {
            Ok(0) => break,
            Ok(k) => got += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(read_error(path, e)),
        }
    }
    if got < raw_header.len() {
        return Err(Error::format(
            path,
            format!(
                "truncated: a NIfTI-1 header needs {} bytes, found {got}",
                raw_header.len()
            ),
        ));
    }
    let header = NiftiHeader::from_reader(&raw_header[..])
        .map_err(|e| Error::format(path, format!("invalid NIfTI-1 header: {e}")))?;
    if header.sizeof_hdr != NIFTI1_HEADER_BYTES as i32 {
        if header.sizeof_hdr == 540 || header.sizeof_hdr.swap_bytes() == 540 {
            return Err(Error::UnsupportedFormat(format!(
                "{}: a NIfTI-2 file; only NIfTI-1 is supported",
                path.display()
            )));
        }
        return Err(Error::format(
            path,
            format!("not a NIfTI-1 file (sizeof_hdr = {})", header.sizeof_hdr),
        ));
    }
    match &header.magic {
        b"n+1\0" => {}
        b"ni1\0" => {
            return Err(Error::UnsupportedFormat(format!(
                "{}: the header of a .hdr/.img pair; only single-file NIfTI (.nii, .nii.gz) is \
                 supported",
                path.display()
            )))
        }
        m => {
            return Err(Error::format(
                path,
                format!("not a NIfTI-1 file (magic {m:?}, expected \"n+1\\0\")"),
            ))
        }
    }

    // Dimensions.
    let dim = header.dim;
    let ndim = dim[0] as usize;
    if !(1..=7).contains(&ndim) {
        return Err(Error::format(
            path,
            format!("invalid dim[0] = {} (must be 1 to 7)", dim[0]),
        ));
    }
    if let Some(i) = (1..=ndim).find(|&i| dim[i] == 0 || dim[i] > i16::MAX as u16) {
        return Err(Error::format(
            path,
            format!("invalid dim[{i}] = {}", dim[i] as i16),
        ));
    }
    if ndim < 3 || dim[4..=ndim.max(3)].iter().any(|&d| d != 1) {
        return Err(Error::UnsupportedFormat(format!(
            "{}: a {ndim}-D NIfTI image of dims {:?}; only 3-D volumes are supported (extra \
             dimensions must be 1)",
            path.display(),
            &dim[1..=ndim]
        )));
    }
    let dims = [dim[1] as usize, dim[2] as usize, dim[3] as usize];
    let n = voxel_count(dims)?;

    // Data type.
    let datatype = header.data_type().ok();
    let datatype = match datatype {
        Some(
            t @ (NiftiType::Uint8
            | NiftiType::Int8
            | NiftiType::Uint16
            | NiftiType::Int16
            | NiftiType::Uint32
            | NiftiType::Int32
            | NiftiType::Uint64
            | NiftiType::Int64
            | NiftiType::Float32
            | NiftiType::Float64),
        ) => t,
        other => {
            let name = other
                .map(|t| format!("{t:?}"))
                .unwrap_or_else(|| format!("code {}", header.datatype));
            return Err(Error::UnsupportedFormat(format!(
                "{}: NIfTI datatype {name} is not supported (supported: uint8, int8, uint16, \
                 int16, uint32, int32, uint64, int64, float32, float64)",
                path.display()
            )));
        }
    };
    let nbytes = n as u64 * datatype.size_of() as u64;

    // Data offset and declared size against what the file can hold.
    let vox_offset = header.vox_offset;
    if !vox_offset.is_finite()
        || vox_offset < (NIFTI1_HEADER_BYTES as f32)
        || vox_offset as u64 > MAX_NIFTI_VOX_OFFSET
    {
        return Err(Error::format(
            path,
            format!("invalid vox_offset {vox_offset}"),
        ));
    }
    let vox_offset = vox_offset as u64;
    if let Some(len) = file_len {
        let needed = vox_offset + nbytes;
        if len < needed {
            return Err(Error::format(
                path,
                format!(
                    "truncated: header declares {dims:?} voxels of {datatype:?} at offset \
                     {vox_offset}, expected at least {needed} bytes, found {len}"
                ),
            ));
        }
    }

    // Skip extensions, then read exactly the voxel data.
    let skip = vox_offset - NIFTI1_HEADER_BYTES as u64;
    let skipped =
        io::copy(&mut reader.take(skip), &mut io::sink()).map_err(|e| read_error(path, e))?;
    if skipped != skip {
        return Err(Error::format(
            path,
            format!(
                "truncated: the stream ends inside the header extensions (vox_offset {vox_offset})"
            ),
        ));
    }
    // Reserve up front only what an uncompressed file has shown it holds; a compressed stream
    // grows the buffer as data actually arrives.
    let reserve = if file_len.is_some() {
        nbytes as usize
    } else {
        (nbytes as usize).min(64 << 20)
    };
    let raw = read_up_to(reader, nbytes, reserve).map_err(|e| read_error(path, e))?;
    if (raw.len() as u64) < nbytes {
        return Err(Error::format(
            path,
            format!(
                "truncated: expected {nbytes} bytes of voxel data, found {}",
                raw.len()
            ),
        ));
    }

    // Scaling as in the NIfTI standard: slope 0 (or not finite) means none.
    let slope = if header.scl_slope.is_finite() {
        header.scl_slope
    } else {
        0.0
    };
    let inter = if slope != 0.0 && header.scl_inter.is_finite() {
        header.scl_inter
    } else {
        0.0
    };
    let raw_dim = [3, dim[1], dim[2], dim[3], 1, 1, 1, 1];
    let volume = nifti::InMemNiftiVolume::from_raw_fields(
        raw_dim,
        datatype,
        slope,
        inter,
        raw,
        header.endianness,
    )
    .map_err(|e| Error::format(path, e.to_string()))?;
    let array = volume
        .into_ndarray::<f32>()
        .map_err(|e| Error::format(path, e.to_string()))?
        .into_dimensionality::<Ix3>()
        .map_err(|e| Error::format(path, e.to_string()))?;
    // `array` is indexed [x, y, z]; walking [z, y, x] in logical order gives x fastest.
    let zyx = array.permuted_axes([2, 1, 0]);
    let data: Vec<f32> = match zyx.as_slice() {
        Some(s) => s.to_vec(),
        None => zyx.iter().copied().collect(),
    };

    let spacing = [1, 2, 3].map(|i| {
        let p = header.pixdim[i];
        if p.is_finite() && p != 0.0 {
            f32_to_f64_decimal(p.abs())
        } else {
            1.0
        }
    });
    let affine = header_affine(&header);
    if affine.is_none() && (header.sform_code > 0 || header.qform_code > 0) {
        log::warn!(
            "{}: the header's sform and qform are not valid affines (singular or not finite); \
             the volume keeps no orientation",
            path.display()
        );
    }
    log::debug!(
        "read {}: {} x {} x {} voxels, spacing {:?} (x, y, z)",
        path.display(),
        dims[0],
        dims[1],
        dims[2],
        spacing
    );
    let mut vol = Volume::new(dims, spacing, data)?;
    vol.affine = affine;
    Ok(vol)
}

/// The header's voxel-to-world affine (RAS+, mm) as nibabel's `get_best_affine` picks it: the
/// sform when `sform_code > 0`, else the qform when `qform_code > 0` (NIfTI-1 method 2: the
/// quaternion rotation times `diag(pixdim[1], pixdim[2], qfac pixdim[3])` plus the offset),
/// else `None`. A transform that is not finite and invertible is skipped.
fn header_affine(h: &NiftiHeader) -> Option<Affine> {
    if h.sform_code > 0 {
        let rows = [h.srow_x, h.srow_y, h.srow_z].map(|r| r.map(f64::from));
        if check_affine(&rows).is_ok() {
            return Some(rows);
        }
    }
    if h.qform_code > 0 {
        let [mut b, mut c, mut d] = [h.quatern_b, h.quatern_c, h.quatern_d].map(f64::from);
        // As the NIfTI-1 reference code (nifti_quatern_to_mat44): a rotation by ~180 degrees
        // has a = 0, and (b, c, d), stored as float32, is renormalised rather than leaving a
        // of the order of the float32 rounding error.
        let a2 = 1.0 - (b * b + c * c + d * d);
        let a = if a2 < 1e-7 {
            let n = (b * b + c * c + d * d).sqrt();
            if n > 0.0 {
                [b, c, d] = [b / n, c / n, d / n];
            }
            0.0
        } else {
            a2.sqrt()
        };
        let r = [
            [
                a * a + b * b - c * c - d * d,
                2.0 * (b * c - a * d),
                2.0 * (b * d + a * c),
            ],
            [
                2.0 * (b * c + a * d),
                a * a + c * c - b * b - d * d,
                2.0 * (c * d - a * b),
            ],
            [
                2.0 * (b * d - a * c),
                2.0 * (c * d + a * b),
                a * a + d * d - c * c - b * b,
            ],
        ];
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let zooms = [
            f64::from(h.pixdim[1]),
            f64::from(h.pixdim[2]),
            qfac * f64::from(h.pixdim[3]),
        ];
        let offset = [h.quatern_x, h.quatern_y, h.quatern_z].map(f64::from);
        let mut m = [[0.0; 4]; 3];
        for row in 0..3 {
            for col in 0..3 {
                m[row][col] = r[row][col] * zooms[col];
            }
            m[row][3] = offset[row];
        }
        if check_affine(&m).is_ok() {
            return Some(m);
        }
    }
    None
}

/// The NIfTI-1 qform of an affine (the inverse of [`header_affine`]'s method 2):
/// `(quatern_b, quatern_c, quatern_d, qfac)`, or `None` when the columns are not orthogonal
/// (a sheared affine has no qform; the sform alone then carries it).
fn affine_to_quaternion(m: &Affine) -> Option<([f32; 3], f32)> {
    let norms = check_affine(m).ok()?;
    let mut r = [[0.0f64; 3]; 3];
    for row in 0..3 {
        for col in 0..3 {
            r[row][col] = m[row][col] / norms[col];
        }
    }
    let col_dot = |a: usize, b: usize| (0..3).map(|k| r[k][a] * r[k][b]).sum::<f64>();
    if col_dot(0, 1).abs() > 1e-4 || col_dot(0, 2).abs() > 1e-4 || col_dot(1, 2).abs() > 1e-4 {
        return None;
    }
    let det = dot(r[0], cross(r[1], r[2]));
    let qfac = if det < 0.0 {
        for row in &mut r {
            row[2] = -row[2];
        }
        -1.0
    } else {
        1.0
    };
    // Shepperd's method (the branch with the largest diagonal term), a >= 0 as NIfTI-1 wants.
    let t = r[0][0] + r[1][1] + r[2][2];
    let (a, b, c, d) = if t > 0.0 {
        let s = (t + 1.0).sqrt() * 2.0;
        (
            0.25 * s,
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
        )
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt() * 2.0;
        (
            (r[2][1] - r[1][2]) / s,
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
        )
    } else if r[1][1] > r[2][2] {
        let s = (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt() * 2.0;
        (
            (r[0][2] - r[2][0]) / s,
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
        )
    } else {
        let s = (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt() * 2.0;
        (
            (r[1][0] - r[0][1]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
        )
    };
    let sign = if a < 0.0 { -1.0 } else { 1.0 };
    Some(([b, c, d].map(|q| (sign * q) as f32), qfac))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_files::patch;
    use crate::volume::tests::unique_volume;

    // ---------------------------------------------------------------- NIfTI

    #[test]
    fn nifti_keeps_an_oblique_flipped_affine_in_sform_and_qform() {
        let dir = tempfile::tempdir().unwrap();
        let mut v = unique_volume([1.0; 3]);
        let (c, s) = (0.6f64, 0.8f64);
        // Rotation about z, then x mirrored (det < 0), voxel sizes 0.7, 1.25, 3.
        let a = [
            [-0.7 * c, -1.25 * s, 0.0, 12.5],
            [-0.7 * s, 1.25 * c, 0.0, -40.0],
            [0.0, 0.0, 3.0, 7.25],
        ];
        v.set_affine(Some(a)).unwrap();
        let sp = v.spacing();
        for (got, want) in sp.iter().zip([0.7, 1.25, 3.0]) {
            assert!((got - want).abs() < 1e-12);
        }
        let p = dir.path().join("o.nii");
        v.write_nifti(&p).unwrap();
        let back = Volume::read_nifti(&p).unwrap();
        let close = |x: &Affine, y: &Affine, tol: f64| {
            x.iter()
                .flatten()
                .zip(y.iter().flatten())
                .all(|(a, b)| (a - b).abs() < tol)
        };
        assert!(
            close(&back.affine().unwrap(), &a, 1e-5),
            "{:?}",
            back.affine()
        );
        // The qform alone (sform_code 0) gives the same affine.
        let mut bytes = std::fs::read(&p).unwrap();
        patch(&mut bytes, 254, &0i16.to_le_bytes());
        std::fs::write(&p, &bytes).unwrap();
        let q = Volume::read_nifti(&p).unwrap();
        assert!(close(&q.affine().unwrap(), &a, 1e-5), "{:?}", q.affine());
        // Neither: no affine; the grid's diagonal is what writers use.
        patch(&mut bytes, 252, &0i16.to_le_bytes());
        std::fs::write(&p, &bytes).unwrap();
        let none = Volume::read_nifti(&p).unwrap();
        assert_eq!(none.affine(), None);
        assert_eq!(none.voxel_to_world()[2][2], none.spacing()[2]);
        // A replaced spacing rescales the columns and keeps the origin.
        let mut r = back.clone();
        r.set_spacing([1.4, 1.25, 3.0]).unwrap();
        let ra = r.affine().unwrap();
        assert!(
            (ra[0][0] - 2.0 * a[0][0]).abs() < 1e-5 && ra[0][3] == back.affine().unwrap()[0][3]
        );
    }

    #[test]
    fn nifti_round_trip_preserves_values_dims_spacing_and_axis_order() {
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([0.7, 1.25, 3.0]);
        for name in ["vol.nii", "vol.nii.gz", "my.scan.v2.nii", "UPPER.NII.GZ"] {
            let p = dir.path().join(name);
            v.write_nifti(&p).unwrap();
            assert!(p.exists(), "{name}");
            let back = Volume::read_nifti(&p).unwrap();
            assert_eq!(back.dims(), [3, 4, 5], "{name}");
            assert_eq!(back.spacing(), [0.7, 1.25, 3.0], "{name}");
            assert_eq!(back.data(), v.data(), "{name}");
            assert_eq!(back.at(2, 1, 4), 412.0);
            let via_read = Volume::read(&p, None).unwrap();
            assert_eq!(via_read, back);
            let respaced = Volume::read(&p, Some([2.0; 3])).unwrap();
            assert_eq!(respaced.spacing(), [2.0; 3]);
        }
        // Only the requested files exist: no temporaries left, nothing renamed.
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            ["UPPER.NII.GZ", "my.scan.v2.nii", "vol.nii", "vol.nii.gz"]
        );
    }

    #[test]
    fn nifti_file_layout_matches_the_standard() {
        // Check the bytes on disk, not only our own round trip: dims at offset 40, pixdim at
        // 76, float32 datatype, x-fastest data from vox_offset 352.
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([0.5, 1.0, 2.0]);
        let p = dir.path().join("v.nii");
        v.write_nifti(&p).unwrap();
        let b = std::fs::read(&p).unwrap();
        let i16_at = |o: usize| i16::from_le_bytes([b[o], b[o + 1]]);
        let f32_at = |o: usize| f32::from_le_bytes(b[o..o + 4].try_into().unwrap());
        assert_eq!(i32::from_le_bytes(b[0..4].try_into().unwrap()), 348);
        assert_eq!(
            [i16_at(40), i16_at(42), i16_at(44), i16_at(46)],
            [3, 3, 4, 5]
        );
        assert_eq!(i16_at(70), 16); // NIFTI_TYPE_FLOAT32
        assert_eq!([f32_at(80), f32_at(84), f32_at(88)], [0.5, 1.0, 2.0]);
        assert_eq!(f32_at(108), 352.0);
        assert_eq!(&b[344..348], b"n+1\0");
        let data: Vec<f32> = b[352..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(data, v.data());
    }

    #[test]
    fn nifti_applies_scaling_integer_types_and_4d_with_one_frame() {
        let dir = tempfile::tempdir().unwrap();
        // int16 data written by the nifti crate, logical shape [x, y, z, t=1].
        let a = ndarray::Array4::from_shape_fn((3, 4, 5, 1), |(x, y, z, _)| {
            (x as i16) - 10 * (y as i16) + 100 * (z as i16)
        });
        let p = dir.path().join("i16.nii");
        nifti::writer::WriterOptions::new(&p)
            .write_nifti(&a)
            .unwrap();
        let v = Volume::read_nifti(&p).unwrap();
        assert_eq!(v.dims(), [3, 4, 5]);
        assert_eq!(v.at(2, 3, 4), (2 - 30 + 400) as f32);
        assert_eq!(v.at(1, 0, 0), 1.0);

        // Patch scl_slope = 2, scl_inter = 10 (offsets 112, 116).
        let mut b = std::fs::read(&p).unwrap();
        patch(&mut b, 112, &2.0f32.to_le_bytes());
        patch(&mut b, 116, &10.0f32.to_le_bytes());
        // pixdim[2] = 0 -> spacing 1; pixdim[3] = NaN -> spacing 1; pixdim[1] = -0.5 -> 0.5.
        patch(&mut b, 80, &(-0.5f32).to_le_bytes());
        patch(&mut b, 84, &0.0f32.to_le_bytes());
        patch(&mut b, 88, &f32::NAN.to_le_bytes());
        let q = dir.path().join("scaled.nii");
        std::fs::write(&q, &b).unwrap();
        let s = Volume::read_nifti(&q).unwrap();
        assert_eq!(s.at(2, 3, 4), 2.0 * 372.0 + 10.0);
        assert_eq!(s.spacing(), [0.5, 1.0, 1.0]);

        // A real 4-D series (t = 2) is refused.
        let a2 = ndarray::Array4::<f32>::zeros((3, 4, 5, 2));
        let p2 = dir.path().join("t2.nii");
        nifti::writer::WriterOptions::new(&p2)
            .write_nifti(&a2)
            .unwrap();
        assert!(matches!(
            Volume::read_nifti(&p2),
            Err(Error::UnsupportedFormat(_))
        ));
        // A 2-D image is refused.
        let a3 = ndarray::Array2::<f32>::zeros((3, 4));
        let p3 = dir.path().join("2d.nii");
        nifti::writer::WriterOptions::new(&p3)
            .write_nifti(&a3)
            .unwrap();
        assert!(Volume::read_nifti(&p3).is_err());
    }

    /// Minimal gzip (stored deflate blocks) so tests can compress without extra crates.
    fn gzip_stored(data: &[u8]) -> Vec<u8> {
        fn crc32(data: &[u8]) -> u32 {
            let mut c = 0xffff_ffffu32;
            for &b in data {
                c ^= b as u32;
                for _ in 0..8 {
                    c = if c & 1 != 0 {
                        (c >> 1) ^ 0xedb8_8320
                    } else {
                        c >> 1
                    };
                }
            }
            !c
        }
        let mut out = vec![0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 255];
        let chunks: Vec<&[u8]> = data.chunks(65535).collect();
        for (i, ch) in chunks.iter().enumerate() {
            out.push(u8::from(i + 1 == chunks.len()));
            let len = ch.len() as u16;
            out.extend_from_slice(&len.to_le_bytes());
            out.extend_from_slice(&(!len).to_le_bytes());
            out.extend_from_slice(ch);
        }
        out.extend_from_slice(&crc32(data).to_le_bytes());
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out
    }

    #[test]
    fn nifti_hostile_headers_fail_without_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("ok.nii");
        unique_volume([1.0; 3]).write_nifti(&p).unwrap();
        let good = std::fs::read(&p).unwrap();
        // Our gzip helper produces files the reader accepts.
        let gz_ok = dir.path().join("ok_gz.nii.gz");
        std::fs::write(&gz_ok, gzip_stored(&good)).unwrap();
        assert_eq!(
            Volume::read_nifti(&gz_ok).unwrap(),
            Volume::read_nifti(&p).unwrap()
        );

        // 10^12 voxels: over the limit.
        let mut huge = good.clone();
        for o in [42, 44, 46] {
            patch(&mut huge, o, &10_000i16.to_le_bytes());
        }
        // 10^8 voxels (400 MB): under the limit, but the file cannot hold it.
        let mut big = good.clone();
        for (o, d) in [(42, 1000i16), (44, 1000), (46, 100)] {
            patch(&mut big, o, &d.to_le_bytes());
        }
        for (name, bytes, limit) in [
            ("huge.nii", huge.clone(), true),
            ("huge.nii.gz", gzip_stored(&huge), true),
            ("big.nii", big.clone(), false),
            ("big.nii.gz", gzip_stored(&big), false),
        ] {
            let q = dir.path().join(name);
            std::fs::write(&q, &bytes).unwrap();
            let e = Volume::read_nifti(&q).unwrap_err();
            if limit {
                assert!(matches!(e, Error::LimitExceeded(_)), "{name}: {e}");
            } else {
                assert!(matches!(e, Error::Format { .. }), "{name}: {e}");
                assert!(e.to_string().contains(name), "{name}: {e}");
            }
        }

        // Truncated data, garbage, wrong datatype, hostile vox_offset, truncated gzip.
        let mut bad_type = good.clone();
        patch(&mut bad_type, 70, &128i16.to_le_bytes()); // RGB24
        let mut bad_offset = good.clone();
        patch(&mut bad_offset, 108, &1.0e30f32.to_le_bytes());
        let gz = gzip_stored(&good);
        let cases: Vec<(&str, Vec<u8>)> = vec![
            ("cut.nii", good[..good.len() - 1].to_vec()),
            ("cut_header.nii", good[..200].to_vec()),
            ("garbage.nii", b"this is not a nifti file at all".repeat(20)),
            ("empty.nii", Vec::new()),
            ("rgb.nii", bad_type),
            ("offset.nii", bad_offset),
            ("cut.nii.gz", gz[..gz.len() / 2].to_vec()),
        ];
        for (name, bytes) in cases {
            let q = dir.path().join(name);
            std::fs::write(&q, &bytes).unwrap();
            let e = Volume::read_nifti(&q).unwrap_err();
            assert!(e.is_io(), "{name}: {e}");
            assert!(e.to_string().contains(name), "{name}: {e}");
            // Readers leave inputs unchanged.
            assert_eq!(std::fs::read(&q).unwrap(), bytes);
        }
        let e = Volume::read_nifti(dir.path().join("missing.nii")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }));
        assert!(e.to_string().contains("missing.nii"));
    }

    #[test]
    fn nifti_writer_checks_the_name() {
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([1.0; 3]);
        assert!(matches!(
            v.write_nifti(dir.path().join("v.hdr")),
            Err(Error::UnsupportedFormat(_))
        ));
        assert!(matches!(
            v.write_nifti(dir.path().join("no_ext")),
            Err(Error::UnsupportedFormat(_))
        ));
        assert!(matches!(
            v.write_nifti(dir.path().join("missing_dir").join("v.nii")),
            Err(Error::Io { .. })
        ));
    }
}
