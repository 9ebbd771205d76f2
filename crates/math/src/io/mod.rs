//! File formats, one module per format, each behind a cargo feature so that a crate compiles
//! only the codecs it reads and writes (the numerics of `wscg-math` need none of them):
//!
//! | module | formats | feature | adds |
//! |---|---|---|---|
//! | [`raster`] | 8/16-bit PNG, 8/16-bit TIFF, JPEG, OpenEXR, Radiance HDR (the `image` crate) | `io-image` | `Image::load`, `Image::save`, `Image::save_with_depth`, `Image::decode`, `Image::encode_jpeg`, `Image::<u16>::load_codes`, `Image::<u8>::load_u8` / `save_u8` |
//! | [`exif`] | EXIF exposure time, f-number and ISO of JPEG, TIFF and PNG files (`kamadak-exif`) | `io-image` | `exif::read_exif`, `exif::load_exif`, `exif::relative_exposures`, `exif::resolve_exposure_times` |
//! | [`npy`] | numpy `.npy` arrays of any dimension (`ndarray-npy`); also `wscg_math::npy` | `io-npy` | `npy::read`, `npy::read_complex`, `npy::write`, `npy::write_f64` |
//! | [`raw`] | headerless voxel dumps | `io-volume` | `Volume::read_raw`, `Volume::write_raw_f32_le` |
//! | [`nifti`] | NIfTI-1, `.nii` and `.nii.gz` (the `nifti` crate) | `io-volume` | `Volume::read_nifti`, `Volume::write_nifti` |
//! | [`npy`] | `.npy` volumes indexed `[z, y, x]` | `io-volume` | `Volume::read_npy`, `Volume::write_npy` |
//! | [`dicom`] | DICOM series: a file, a folder or a list of files (dicom-rs) | `io-dicom` | `Volume::read_dicom`, `Volume::read_dicom_with`, `Volume::read_dicom_files`, `Volume::from_dicom_bytes`, `Volume::from_dicom_series_bytes` |
//! | [`obj`] | Wavefront OBJ | `io-mesh` | `TriMesh::read_obj`, `TriMesh::write_obj` |
//! | [`ply`] | Stanford PLY, ASCII and binary (`ply-rs`) | `io-mesh` | `TriMesh::read_ply`, `TriMesh::write_ply` |
//! | [`csv`] | CSV tables (the `csv` crate, rows through serde) | `io-csv` | `csv::records`, `csv::table`, `csv::Row::deserialize` |
//!
//! Every writer goes through [`atomic`]: a temporary file in the destination's folder,
//! flushed, synced and renamed over the destination, every error returned, so a failed or
//! killed write never leaves a truncated file.
//!
//! `Volume::read` (`io-volume`) and `TriMesh::read` / `TriMesh::write` (`io-mesh`), defined
//! here, pick the format from the file extension.
//!
//! Readers never modify their input, bound every allocation by the size of the file or by a
//! documented limit (so a hostile header cannot make them allocate without bound), and report
//! every malformed, truncated or empty file as an error naming the path ([`Error::Format`];
//! [`Error::Io`] when the file cannot be read).
//!
//! [`Error::Format`]: crate::Error::Format
//! [`Error::Io`]: crate::Error::Io

pub mod atomic;
#[cfg(feature = "io-csv")]
pub mod csv;
#[cfg(feature = "io-dicom")]
pub mod dicom;
#[cfg(feature = "io-dicom")]
mod dicom_lengths;
#[cfg(feature = "io-image")]
pub mod exif;
#[cfg(feature = "io-volume")]
pub mod nifti;
#[cfg(feature = "io-npy")]
pub mod npy;
#[cfg(feature = "io-mesh")]
pub mod obj;
#[cfg(feature = "io-mesh")]
pub mod ply;
#[cfg(feature = "io-image")]
pub mod raster;
#[cfg(feature = "io-volume")]
pub mod raw;

#[cfg(feature = "io-mesh")]
pub use ply::PlyEncoding;
#[cfg(feature = "io-image")]
pub use raster::{
    max_image_pixels, set_max_image_pixels, PixelDepth, DEFAULT_MAX_IMAGE_PIXELS, MAX_DECODE_BYTES,
    MAX_DECODE_SIDE,
};
#[cfg(feature = "io-volume")]
pub use raw::RawType;
#[cfg(feature = "io-volume")]
pub(crate) use volume_files::{file_kind, read_up_to, FileKind};

/// Runs a step of a third-party decoder (`decoder` names it in the message), turning a panic
/// inside it into [`Error::Format`] naming `origin`: a second line of defence against
/// decoder bugs on malformed files (the JPEG decoder's progressive upsampler, dicom-rs's RLE
/// and JPEG 2000 adapters; FUZZING.md).
#[cfg(any(feature = "io-image", feature = "io-dicom"))]
pub(crate) fn guarded<T>(
    origin: &std::path::Path,
    decoder: &str,
    step: impl FnOnce() -> crate::Result<T>,
) -> crate::Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(step)).unwrap_or_else(|_| {
        Err(crate::Error::format(
            origin,
            format!("{decoder} failed on malformed data"),
        ))
    })
}

/// Volume files by extension, and what the volume readers share.
#[cfg(feature = "io-volume")]
mod volume_files {
    use std::io::{self, Read};
    use std::path::Path;

    use crate::error::{Error, Result};
    use crate::volume::{check_spacing, Volume};

    /// File kinds recognised by [`Volume::read`], from the (case-insensitive) file name.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub(crate) enum FileKind {
        Nii,
        NiiGz,
        Npy,
        /// A folder, a `.dcm` file or a file with a DICOM preamble.
        Dicom,
        Other,
    }

    pub(crate) fn file_kind(path: &Path) -> FileKind {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if name.ends_with(".nii.gz") {
            FileKind::NiiGz
        } else if name.ends_with(".nii") {
            FileKind::Nii
        } else if name.ends_with(".npy") {
            FileKind::Npy
        } else if name.ends_with(".dcm") || path.is_dir() || looks_like_dicom(path) {
            FileKind::Dicom
        } else {
            FileKind::Other
        }
    }

    #[cfg(feature = "io-dicom")]
    fn looks_like_dicom(path: &Path) -> bool {
        super::dicom::is_dicom_file(path)
    }

    #[cfg(not(feature = "io-dicom"))]
    fn looks_like_dicom(_: &Path) -> bool {
        false
    }

    /// Reads up to `n` bytes (fewer at end of stream) without trusting `n` for the allocation
    /// beyond `reserve`.
    pub(crate) fn read_up_to(
        reader: &mut impl Read,
        n: u64,
        reserve: usize,
    ) -> io::Result<Vec<u8>> {
        let mut buf = Vec::new();
        buf.try_reserve_exact(reserve)
            .map_err(|e| io::Error::new(io::ErrorKind::OutOfMemory, e.to_string()))?;
        reader.take(n).read_to_end(&mut buf)?;
        Ok(buf)
    }

    impl Volume<f32> {
        /// Reads a volume file, choosing the reader from the extension (case-insensitive):
        /// `.nii` and `.nii.gz` ([`Volume::read_nifti`]; `spacing`, when given, replaces the
        /// header's voxel size), `.npy` ([`Volume::read_npy`], array indexed `[z, y, x]`;
        /// `spacing` defaults to `[1, 1, 1]`), and, with the feature `io-dicom`, a DICOM file
        /// (`.dcm` or any name with a DICOM preamble) or a folder of them
        /// ([`Volume::read_dicom`]). A replaced spacing rescales the file's affine
        /// ([`Volume::set_spacing`]). Raw files carry no header and need [`Volume::read_raw`].
        ///
        /// Errors: [`Error::UnsupportedFormat`] for any other extension; the reader's errors.
        pub fn read(path: impl AsRef<Path>, spacing: Option<[f64; 3]>) -> Result<Self> {
            let path = path.as_ref();
            if let Some(s) = spacing {
                check_spacing(s)?;
            }
            match file_kind(path) {
                FileKind::Nii | FileKind::NiiGz | FileKind::Dicom => {
                    let mut vol = match file_kind(path) {
                        FileKind::Dicom => Self::read_dicom_file_or_folder(path)?,
                        _ => Self::read_nifti(path)?,
                    };
                    if let Some(s) = spacing {
                        vol.set_spacing(s)?;
                    }
                    Ok(vol)
                }
                FileKind::Npy => Self::read_npy(path, spacing.unwrap_or([1.0; 3])),
                FileKind::Other => {
                    let ext = path
                        .extension()
                        .map(|e| format!(".{}", e.to_string_lossy()))
                        .unwrap_or_else(|| "(none)".to_string());
                    Err(Error::UnsupportedFormat(format!(
                        "{}: extension {ext} is not a supported volume format. Supported formats \
                         are .nii, .nii.gz, .npy and DICOM files or folders (raw files need \
                         Volume::read_raw with dims and a RawType)",
                        path.display()
                    )))
                }
            }
        }
    }

    impl Volume<f32> {
        #[cfg(feature = "io-dicom")]
        fn read_dicom_file_or_folder(path: &Path) -> Result<Self> {
            Self::read_dicom(path)
        }

        #[cfg(not(feature = "io-dicom"))]
        fn read_dicom_file_or_folder(path: &Path) -> Result<Self> {
            Err(Error::UnsupportedFormat(format!(
                "{}: DICOM needs wscg-math's feature io-dicom",
                path.display()
            )))
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        #[test]
        fn read_dispatch_rejects_unknown_extensions() {
            let dir = tempfile::tempdir().unwrap();
            let p = dir.path().join("v.mhd");
            std::fs::write(&p, b"x").unwrap();
            let e = Volume::read(&p, None).unwrap_err();
            let msg = e.to_string();
            assert!(matches!(e, Error::UnsupportedFormat(_)));
            assert!(
                msg.contains(".mhd") && msg.contains(".nii.gz") && msg.contains(".npy"),
                "{msg}"
            );
            assert!(Volume::read(dir.path().join("v.nii"), None).is_err());
        }
    }
}

/// Mesh files by extension.
#[cfg(feature = "io-mesh")]
mod mesh_files {
    use std::path::Path;

    use super::PlyEncoding;
    use crate::error::{Error, Result};
    use crate::mesh::TriMesh;

    impl TriMesh {
        /// Reads an `.obj` or `.ply` file, chosen by the (case-insensitive) extension; see
        /// [`TriMesh::read_obj`] and [`TriMesh::read_ply`].
        ///
        /// Errors: another or no extension ([`Error::UnsupportedFormat`] naming it); otherwise as
        /// the reader.
        pub fn read(path: impl AsRef<Path>) -> Result<Self> {
            let path = path.as_ref();
            match MeshFormat::from_path(path)? {
                MeshFormat::Obj => TriMesh::read_obj(path),
                MeshFormat::Ply => TriMesh::read_ply(path),
            }
        }

        /// Writes an `.obj` or `.ply` file (PLY as binary little endian), chosen by the
        /// (case-insensitive) extension; see [`TriMesh::write_obj`] and [`TriMesh::write_ply`].
        ///
        /// Errors: another or no extension ([`Error::UnsupportedFormat`] naming it); otherwise as
        /// the writer.
        pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
            let path = path.as_ref();
            match MeshFormat::from_path(path)? {
                MeshFormat::Obj => self.write_obj(path),
                MeshFormat::Ply => self.write_ply(path, PlyEncoding::BinaryLittleEndian),
            }
        }

        /// Validation shared by the writers.
        pub(crate) fn check_writable(&self) -> Result<()> {
            self.validate()?;
            if self.faces.is_empty() {
                return Err(Error::Empty("faces"));
            }
            Ok(())
        }
    }

    /// Mesh file formats known to [`TriMesh::read`] and [`TriMesh::write`].
    enum MeshFormat {
        Obj,
        Ply,
    }

    impl MeshFormat {
        fn from_path(path: &Path) -> Result<Self> {
            let ext = path
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase());
            match ext.as_deref() {
                Some("obj") => Ok(MeshFormat::Obj),
                Some("ply") => Ok(MeshFormat::Ply),
                Some(other) => Err(Error::UnsupportedFormat(format!(
                    "mesh file extension `.{other}` of {}; supported: .obj, .ply",
                    path.display()
                ))),
                None => Err(Error::UnsupportedFormat(format!(
                    "mesh file {} has no extension; supported: .obj, .ply",
                    path.display()
                ))),
            }
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        #[test]
        fn dispatch_rejects_unknown_extensions_and_writers_reject_bad_meshes() {
            let dir = tempfile::tempdir().unwrap();
            let m = TriMesh::cube(1.0).unwrap();
            for name in ["mesh.stl", "mesh"] {
                let path = dir.path().join(name);
                assert!(matches!(m.write(&path), Err(Error::UnsupportedFormat(_))));
                std::fs::write(&path, b"solid").unwrap();
                let e = TriMesh::read(&path).unwrap_err();
                let names_ext = matches!(&e, Error::UnsupportedFormat(s) if s.contains("stl"));
                assert!(matches!(e, Error::UnsupportedFormat(_)), "{e}");
                assert_eq!(names_ext, name.ends_with("stl"), "{e}");
            }
            let empty = TriMesh::new(vec![[0.0; 3]], vec![]).unwrap();
            assert!(matches!(
                empty.write_obj(dir.path().join("e.obj")),
                Err(Error::Empty("faces"))
            ));
            assert!(matches!(
                empty.write_ply(dir.path().join("e.ply"), PlyEncoding::Ascii),
                Err(Error::Empty("faces"))
            ));
            let mut broken = m.clone();
            broken.faces[0] = [0, 1, 99];
            assert!(broken.write_obj(dir.path().join("b.obj")).is_err());
            assert!(matches!(
                m.write_obj(dir.path().join("no_such_dir").join("x.obj")),
                Err(Error::Io { .. })
            ));
        }
    }
}

/// Inputs shared by the tests of the format modules.
#[cfg(test)]
pub(crate) mod test_files {
    #[cfg(feature = "io-volume")]
    pub(crate) fn patch(bytes: &mut [u8], offset: usize, new: &[u8]) {
        bytes[offset..offset + new.len()].copy_from_slice(new);
    }

    /// Deterministic pseudo-random colours in [0, 1].
    #[cfg(feature = "io-mesh")]
    pub(crate) fn colors_for(n: usize) -> Vec<[f32; 3]> {
        let mut s = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n).map(|_| [next(), next(), next()]).collect()
    }
}
