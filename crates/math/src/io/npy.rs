//! numpy `.npy` files of any dimension and the common numeric dtypes.
//!
//! [`read`] accepts float32, float64, uint8, int8, uint16, int16, uint32, int32, uint64 and
//! int64 (either byte order, C or Fortran layout) and returns the values in C order
//! (last axis fastest) converted to `f32` or `f64`; [`read_complex`] reads complex128 and
//! complex64 arrays. [`write_f64`] writes a C-order float64
//! array. Malformed or truncated files are [`Error::Format`], other dtypes
//! [`Error::UnsupportedFormat`], never a panic.

use std::io;
use std::path::Path;

use ndarray::{ArrayD, ArrayViewD, IxDyn};
use ndarray_npy::npy::header::Header;
use ndarray_npy::{ReadNpyError, ReadNpyExt, ReadableElement, WriteNpyExt};

use crate::error::{read_error, read_file, Error, Result};

/// The dtype names [`read`] accepts, for error messages.
pub const SUPPORTED_DTYPES: &str =
    "float32, float64, uint8, int8, uint16, int16, uint32, int32, uint64 and int64";

/// An element type `.npy` values can be converted to.
pub trait NpyTarget: Copy {
    /// The value `v` in this type (rounded for `f32`).
    fn from_f64(v: f64) -> Self;
}

impl NpyTarget for f32 {
    fn from_f64(v: f64) -> Self {
        v as f32
    }
}

impl NpyTarget for f64 {
    fn from_f64(v: f64) -> Self {
        v
    }
}

/// An n-dimensional array read from a `.npy` file.
#[derive(Clone, Debug, PartialEq)]
pub struct NpyArray<T> {
    /// The array's shape, as numpy reports it.
    pub shape: Vec<usize>,
    /// The values in C order (last axis fastest).
    pub data: Vec<T>,
}

/// Largest element count [`read`] accepts (`2^33`).
pub const MAX_ELEMENTS: usize = 1 << 33;

/// Reads a `.npy` file, converting its values to `T`.
///
/// Errors: [`Error::Io`] when the file cannot be read, [`Error::Format`] for a malformed or
/// truncated file, [`Error::UnsupportedFormat`] for dtypes outside [`SUPPORTED_DTYPES`],
/// [`Error::LimitExceeded`] above [`MAX_ELEMENTS`] values.
pub fn read<T: NpyTarget>(path: impl AsRef<Path>) -> Result<NpyArray<T>> {
    read_with_limit(path, MAX_ELEMENTS)
}

/// [`read`] with a caller-chosen limit on the number of values, checked against the
/// declared shape before any data is decoded.
pub fn read_with_limit<T: NpyTarget>(path: impl AsRef<Path>, limit: usize) -> Result<NpyArray<T>> {
    let path = path.as_ref();
    from_bytes_with_limit(&read_file(path)?, path, limit)
}

/// [`read_with_limit`] of a file held in memory; `origin` names the file in errors.
pub fn from_bytes_with_limit<T: NpyTarget>(
    bytes: &[u8],
    origin: &Path,
    limit: usize,
) -> Result<NpyArray<T>> {
    let path = origin;
    let header = checked_header(path, bytes, limit)?;
    let data = values::<T>(path, bytes)?.ok_or_else(|| {
        Error::UnsupportedFormat(format!(
            "{}: .npy dtype {} is not supported. Supported dtypes are {SUPPORTED_DTYPES}",
            path.display(),
            header.type_descriptor
        ))
    })?;
    Ok(NpyArray {
        shape: header.shape,
        data,
    })
}

/// Reads a complex `.npy` file (complex128 or complex64); real dtypes are accepted too and
/// get a zero imaginary part. Errors as [`read`].
pub fn read_complex(path: impl AsRef<Path>) -> Result<NpyArray<num_complex::Complex64>> {
    let path = path.as_ref();
    complex_from_bytes(&read_file(path)?, path)
}

/// [`read_complex`] of a file held in memory; `origin` names the file in errors.
pub fn complex_from_bytes(bytes: &[u8], origin: &Path) -> Result<NpyArray<num_complex::Complex64>> {
    use num_complex::{Complex32, Complex64};
    let path = origin;
    let header = checked_header(path, bytes, MAX_ELEMENTS)?;
    let complex = |r: std::result::Result<ArrayD<Complex64>, ReadNpyError>| match r {
        Ok(a) => Some(Ok(a.iter().copied().collect::<Vec<_>>())),
        Err(ReadNpyError::WrongDescriptor(_)) => None,
        Err(ReadNpyError::Io(e)) => Some(Err(read_error(path, e))),
        Err(e) => Some(Err(Error::format(path, e.to_string()))),
    };
    let data = match complex(ArrayD::<Complex64>::read_npy(bytes)) {
        Some(r) => r?,
        None => match ArrayD::<Complex32>::read_npy(bytes) {
            Ok(a) => a
                .iter()
                .map(|v| Complex64::new(v.re as f64, v.im as f64))
                .collect(),
            Err(ReadNpyError::WrongDescriptor(_)) => {
                let real = from_bytes_with_limit::<f64>(bytes, path, MAX_ELEMENTS)?;
                real.data.iter().map(|&v| Complex64::new(v, 0.0)).collect()
            }
            Err(ReadNpyError::Io(e)) => return Err(read_error(path, e)),
            Err(e) => return Err(Error::format(path, e.to_string())),
        },
    };
    Ok(NpyArray {
        shape: header.shape,
        data,
    })
}

/// Writes `data` (C order) as a float64 `.npy` array of the given shape.
///
/// Errors: [`Error::ShapeMismatch`] when the shape does not hold `data.len()` values,
/// [`Error::Io`] when the file cannot be written.
pub fn write_f64(path: impl AsRef<Path>, shape: &[usize], data: &[f64]) -> Result<()> {
    write(path, shape, data)
}

/// Writes `data` (C order) as a `.npy` array of the given shape, in the dtype of `T`
/// (`u8`, `i64`, `f32`, `f64`, ...). Errors as [`write_f64`].
pub fn write<T: ndarray_npy::WritableElement>(
    path: impl AsRef<Path>,
    shape: &[usize],
    data: &[T],
) -> Result<()> {
    let path = path.as_ref();
    let view = ArrayViewD::from_shape(IxDyn(shape), data).map_err(|_| {
        Error::ShapeMismatch(format!(
            "{} values do not fill an array of shape {shape:?}",
            data.len()
        ))
    })?;
    crate::io::atomic::write_with(path, |out| {
        view.write_npy(out).map_err(|e| npy_write_error(path, e))
    })
}

/// An `ndarray-npy` write error as [`Error::Io`] naming `path`.
fn npy_write_error(path: &Path, e: ndarray_npy::WriteNpyError) -> Error {
    match e {
        ndarray_npy::WriteNpyError::Io(e) => Error::io(path, e),
        e => Error::io(path, io::Error::other(e.to_string())),
    }
}

/// Parses the header of a `.npy` file held in memory and checks the values it declares
/// against `limit` ([`Error::LimitExceeded`]) and against the data the file holds (at least
/// one byte a value), so the npy crate never allocates for more values than the file can
/// hold.
fn checked_header(path: &Path, bytes: &[u8], limit: usize) -> Result<Header> {
    let data_start = header_end(path, bytes)?;
    let header = Header::from_reader(&mut &bytes[..])
        .map_err(|e| Error::format(path, format!("invalid .npy header: {e}")))?;
    let count = header
        .shape
        .iter()
        .try_fold(1usize, |a, &b| a.checked_mul(b))
        .ok_or_else(|| Error::format(path, format!("shape {:?} overflows", header.shape)))?;
    if count > limit {
        return Err(Error::LimitExceeded(format!(
            "{}: shape {:?} holds {count} values, more than the limit of {limit}",
            path.display(),
            header.shape
        )));
    }
    let payload = bytes.len() - data_start;
    if count > payload {
        return Err(Error::format(
            path,
            format!(
                "truncated: shape {:?} needs at least {count} bytes of data, found {payload}",
                header.shape
            ),
        ));
    }
    Ok(header)
}

/// Deepest nesting of brackets in a `.npy` header: the dictionary, the shape tuple, and the
/// list and tuples of a structured dtype. The header parser of the npy crate takes time
/// exponential in the nesting depth, so deeper headers are refused before it runs.
const MAX_HEADER_NESTING: usize = 4;

/// Checks the `.npy` preamble and returns the offset of the array data; guards the header
/// length against the file size before the npy crate allocates it, and its bracket nesting
/// against [`MAX_HEADER_NESTING`].
fn header_end(path: &Path, bytes: &[u8]) -> Result<usize> {
    const MAGIC: &[u8] = b"\x93NUMPY";
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err(Error::format(
            path,
            "not a .npy file (missing \\x93NUMPY magic)",
        ));
    }
    let (len, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10usize),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        2 | 3 => return Err(Error::format(path, "truncated .npy header")),
        v => {
            return Err(Error::format(
                path,
                format!("unsupported .npy format version {v}"),
            ))
        }
    };
    let end = match start.checked_add(len) {
        Some(end) if end <= bytes.len() => end,
        _ => {
            return Err(Error::format(
                path,
                format!(
                    "truncated .npy header: declares {len} header bytes, file has {}",
                    bytes.len()
                ),
            ))
        }
    };
    let mut depth = 0usize;
    for &b in &bytes[start..end] {
        match b {
            b'{' | b'[' | b'(' => {
                depth += 1;
                if depth > MAX_HEADER_NESTING {
                    return Err(Error::format(
                        path,
                        format!(
                            "malformed .npy header: brackets nested deeper than \
                             {MAX_HEADER_NESTING}"
                        ),
                    ));
                }
            }
            b'}' | b']' | b')' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    Ok(end)
}

/// Decodes the data in C order, trying each supported element type; `Ok(None)` when the
/// dtype is none of them.
fn values<T: NpyTarget>(path: &Path, bytes: &[u8]) -> Result<Option<Vec<T>>> {
    fn attempt<A: ReadableElement + Copy, T: NpyTarget>(
        path: &Path,
        bytes: &[u8],
        conv: fn(A) -> f64,
    ) -> Option<Result<Vec<T>>> {
        match ArrayD::<A>::read_npy(bytes) {
            Ok(a) => Some(Ok(a.iter().map(|&v| T::from_f64(conv(v))).collect())),
            Err(ReadNpyError::WrongDescriptor(_)) => None,
            Err(ReadNpyError::Io(e)) => Some(Err(read_error(path, e))),
            Err(e) => Some(Err(Error::format(path, e.to_string()))),
        }
    }

    macro_rules! try_types {
        ($($t:ty),*) => {
            $(
                if let Some(r) = attempt::<$t, T>(path, bytes, |v| v as f64) {
                    return r.map(Some);
                }
            )*
        };
    }
    try_types!(f64, f32, u8, i8, u16, i16, u32, i32, u64, i64);
    Ok(None)
}

/// `.npy` volumes: arrays indexed `arr[z, y, x]`.
#[cfg(feature = "io-volume")]
mod volume_files {
    use std::path::Path;

    use ndarray::ArrayView3;

    use crate::error::{Error, Result};
    use crate::volume::{check_spacing, voxel_count, Real, Volume, MAX_VOXELS};

    impl<T: Real> Volume<T> {
        /// Writes a numpy `.npy` file holding an `f32` array of shape `(nz, ny, nx)` in C order,
        /// indexed `arr[z, y, x]` (so `np.load(path)[z, y, x] == vol.at(x, y, z)`).
        pub fn write_npy(&self, path: impl AsRef<Path>) -> Result<()> {
            use ndarray_npy::WriteNpyExt;
            let path = path.as_ref();
            let values = T::as_f32_slice(&self.data);
            let [nx, ny, nz] = self.dims;
            let array = ArrayView3::from_shape((nz, ny, nx), &values[..])
                .expect("volume invariant: data length equals nx * ny * nz");
            crate::io::atomic::write_with(path, |out| {
                array
                    .write_npy(out)
                    .map_err(|e| super::npy_write_error(path, e))
            })
        }
    }

    impl Volume<f32> {
        /// Reads a numpy `.npy` file holding a 3-D array **indexed `arr[z, y, x]`** (shape
        /// `(nz, ny, nx)`), the order in which Python users usually hold CT/MRI stacks; C and
        /// Fortran layouts are both read correctly, so `vol.at(x, y, z) == arr[z, y, x]`. An array
        /// ordered `(X, Y, Z)` in Python must be saved as `np.save(path, arr.transpose(2, 1, 0))`.
        ///
        /// Accepted dtypes (either byte order): float32, float64, uint8, int8, uint16, int16,
        /// uint32, int32, uint64, int64; values are converted to `f32` unchanged. `spacing` is the
        /// voxel size `[sx, sy, sz]` (a `.npy` file does not store one).
        ///
        /// Errors: [`Error::Io`]; [`Error::Format`] for a malformed or truncated file or an array
        /// that is not 3-D or has an empty axis; [`Error::UnsupportedFormat`] for other dtypes;
        /// [`Error::LimitExceeded`] above [`MAX_VOXELS`]; invalid `spacing` as [`Volume::new`].
        pub fn read_npy(path: impl AsRef<Path>, spacing: [f64; 3]) -> Result<Self> {
            let path = path.as_ref();
            Self::from_npy_bytes(&crate::error::read_file(path)?, path, spacing)
        }

        /// [`Volume::read_npy`] of a file held in memory; `origin` names the file in errors.
        pub fn from_npy_bytes(bytes: &[u8], origin: &Path, spacing: [f64; 3]) -> Result<Self> {
            let path = origin;
            check_spacing(spacing)?;
            let arr = super::from_bytes_with_limit::<f32>(bytes, path, MAX_VOXELS)?;
            let shape = &arr.shape;
            if shape.len() != 3 {
                return Err(Error::format(
                    path,
                    format!(
                        "expected a 3-D array indexed [z, y, x], found a {}-D array of shape {shape:?}",
                        shape.len()
                    ),
                ));
            }
            let dims = [shape[2], shape[1], shape[0]];
            if dims.contains(&0) {
                return Err(Error::format(
                    path,
                    format!("the array of shape {shape:?} has an empty axis"),
                ));
            }
            voxel_count(dims)?;
            Volume::new(dims, spacing, arr.data)
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;
        use crate::io::test_files::patch;
        use crate::volume::tests::unique_volume;
        use ndarray::{Array3, ShapeBuilder};
        use ndarray_npy::WriteNpyExt;

        // ---------------------------------------------------------------- npy

        #[test]
        fn npy_round_trip_uses_zyx_convention() {
            let dir = tempfile::tempdir().unwrap();
            let v = unique_volume([0.5, 1.0, 2.0]);
            let p = dir.path().join("v.npy");
            v.write_npy(&p).unwrap();
            let arr: Array3<f32> = ndarray_npy::read_npy(&p).unwrap();
            assert_eq!(arr.dim(), (5, 4, 3));
            for ((z, y, x), &a) in arr.indexed_iter() {
                assert_eq!(a, v.at(x, y, z));
            }
            let header = String::from_utf8_lossy(&std::fs::read(&p).unwrap()[..128]).into_owned();
            assert!(header.contains("(5, 4, 3)"), "{header}");
            assert!(header.contains("'fortran_order': False"), "{header}");
            let back = Volume::read_npy(&p, [0.5, 1.0, 2.0]).unwrap();
            assert_eq!(back, v);
            assert_eq!(Volume::read(&p, Some([0.5, 1.0, 2.0])).unwrap(), v);
            assert_eq!(Volume::read(&p, None).unwrap().spacing(), [1.0; 3]);
        }

        #[test]
        fn npy_reads_other_dtypes_and_fortran_order() {
            let dir = tempfile::tempdir().unwrap();
            let f = |z: usize, y: usize, x: usize| x + 10 * y + 100 * z;
            let want = unique_volume([1.0; 3]);
            let check = |name: &str, write: &dyn Fn(&Path)| {
                let p = dir.path().join(name);
                write(&p);
                assert_eq!(Volume::read_npy(&p, [1.0; 3]).unwrap(), want, "{name}");
            };
            check("f64.npy", &|p| {
                ndarray_npy::write_npy(
                    p,
                    &Array3::from_shape_fn((5, 4, 3), |(z, y, x)| f(z, y, x) as f64),
                )
                .unwrap()
            });
            check("u16.npy", &|p| {
                ndarray_npy::write_npy(
                    p,
                    &Array3::from_shape_fn((5, 4, 3), |(z, y, x)| f(z, y, x) as u16),
                )
                .unwrap()
            });
            check("i16_fortran.npy", &|p| {
                let a = Array3::from_shape_fn((5, 4, 3).f(), |(z, y, x)| f(z, y, x) as i16);
                ndarray_npy::write_npy(p, &a).unwrap()
            });
            let small = Volume::from_fn([3, 4, 5], [1.0; 3], |x, y, z| (x + 3 * y + 12 * z) as f32)
                .unwrap();
            let p = dir.path().join("u8.npy");
            let a = Array3::from_shape_fn((5, 4, 3), |(z, y, x)| (x + 3 * y + 12 * z) as u8);
            let mut file = std::fs::File::create(&p).unwrap();
            a.write_npy(&mut file).unwrap();
            drop(file);
            assert_eq!(Volume::read_npy(&p, [1.0; 3]).unwrap(), small);
        }

        #[test]
        fn npy_bad_files_are_errors() {
            let dir = tempfile::tempdir().unwrap();
            let p2 = dir.path().join("flat.npy");
            ndarray_npy::write_npy(&p2, &ndarray::Array2::<f32>::zeros((4, 5))).unwrap();
            let e = Volume::read_npy(&p2, [1.0; 3]).unwrap_err();
            assert!(e.to_string().contains("3-D"), "{e}");
            assert!(e.to_string().contains("flat.npy"), "{e}");

            let pb = dir.path().join("bool.npy");
            ndarray_npy::write_npy(&pb, &Array3::from_elem((2, 2, 2), true)).unwrap();
            assert!(matches!(
                Volume::read_npy(&pb, [1.0; 3]),
                Err(Error::UnsupportedFormat(_))
            ));

            let good = dir.path().join("good.npy");
            unique_volume([1.0; 3]).write_npy(&good).unwrap();
            let bytes = std::fs::read(&good).unwrap();
            let cut = dir.path().join("cut.npy");
            std::fs::write(&cut, &bytes[..bytes.len() - 3]).unwrap();
            assert!(matches!(
                Volume::read_npy(&cut, [1.0; 3]),
                Err(Error::Format { .. })
            ));
            // Hostile shapes in the header: an error before any allocation of that size.
            let start = bytes.windows(9).position(|w| w == b"(5, 4, 3)").unwrap();
            for (shape, limit) in [
                (&b"(99999, 999, 999)"[..], true),
                (b"(1000, 999, 100)", false),
            ] {
                let mut hb = bytes[..start].to_vec();
                hb.extend_from_slice(shape);
                hb.extend_from_slice(&bytes[start + 9..]);
                // Keep the declared header length right: drop as many padding spaces as added.
                let nl = hb.iter().position(|&c| c == b'\n').unwrap();
                hb.drain(nl - (shape.len() - 9)..nl);
                let hp = dir.path().join("hostile.npy");
                std::fs::write(&hp, &hb).unwrap();
                let e = Volume::read_npy(&hp, [1.0; 3]).unwrap_err();
                if limit {
                    assert!(matches!(e, Error::LimitExceeded(_)), "{e}");
                } else {
                    assert!(matches!(e, Error::Format { .. }), "{e}");
                    assert!(e.to_string().contains("truncated"), "{e}");
                }
            }
            // Header length field pointing past the end of the file.
            let mut lie = bytes.clone();
            patch(&mut lie, 8, &u16::MAX.to_le_bytes());
            let lp = dir.path().join("lie.npy");
            std::fs::write(&lp, &lie).unwrap();
            assert!(matches!(
                Volume::read_npy(&lp, [1.0; 3]),
                Err(Error::Format { .. })
            ));

            let garbage = dir.path().join("garbage.npy");
            std::fs::write(&garbage, b"not numpy").unwrap();
            assert!(matches!(
                Volume::read_npy(&garbage, [1.0; 3]),
                Err(Error::Format { .. })
            ));
            assert!(matches!(
                Volume::read_npy(dir.path().join("missing.npy"), [1.0; 3]),
                Err(Error::Io { .. })
            ));
            assert!(Volume::read_npy(&good, [0.0, 1.0, 1.0]).is_err());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.npy");
        let data: Vec<f64> = (0..24).map(|v| v as f64 * 0.5 - 3.0).collect();
        write_f64(&p, &[2, 3, 4], &data).unwrap();
        let a = read::<f64>(&p).unwrap();
        assert_eq!(a.shape, vec![2, 3, 4]);
        assert_eq!(a.data, data);
        assert!(matches!(
            write_f64(&p, &[5, 5], &data),
            Err(Error::ShapeMismatch(_))
        ));
        let bytes = std::fs::read(&p).unwrap();
        std::fs::write(&p, &bytes[..bytes.len() - 9]).unwrap();
        assert!(matches!(read::<f64>(&p), Err(Error::Format { .. })));
        std::fs::write(&p, b"not numpy").unwrap();
        assert!(matches!(read::<f32>(&p), Err(Error::Format { .. })));
        assert!(read::<f64>(dir.path().join("missing.npy"))
            .unwrap_err()
            .is_io());
    }

    #[test]
    fn complex_round_trip_and_real_promotion() {
        use num_complex::Complex64;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("c.npy");
        let data: Vec<Complex64> = (0..6)
            .map(|v| Complex64::new(v as f64, -(v as f64) / 2.0))
            .collect();
        write(&p, &[2, 3], &data).unwrap();
        let a = read_complex(&p).unwrap();
        assert_eq!((a.shape, a.data), (vec![2, 3], data));
        write_f64(&p, &[3], &[1.0, 2.0, 3.0]).unwrap();
        let b = read_complex(&p).unwrap();
        assert_eq!(b.data[2], Complex64::new(3.0, 0.0));
        std::fs::write(&p, b"junk").unwrap();
        assert!(matches!(read_complex(&p), Err(Error::Format { .. })));
    }

    /// A version-1 `.npy` file with the given header dictionary text (padded to a multiple
    /// of 64 bytes as numpy writes it) and data bytes.
    fn npy_bytes(dict: &str, data: &[u8]) -> Vec<u8> {
        let mut header = dict.to_string();
        while !(10 + header.len() + 1).is_multiple_of(64) {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend_from_slice(&(header.len() as u16).to_le_bytes());
        out.extend_from_slice(header.as_bytes());
        out.extend_from_slice(data);
        out
    }

    /// Found by fuzzing (FUZZING.md): a complex header declaring 4.4e9 values (below
    /// `MAX_ELEMENTS`) over a few bytes of data made the npy crate allocate 71 GB and abort.
    #[test]
    fn complex_shape_larger_than_the_data_is_refused_before_allocating() {
        let bytes = npy_bytes(
            "{'descr': '<c16', 'fortran_order': False, 'shape': (2, 2222222222), }",
            &[0u8; 32],
        );
        let err = complex_from_bytes(&bytes, Path::new("k.npy")).unwrap_err();
        assert!(matches!(err, Error::Format { .. }), "{err}");
        assert!(err.to_string().contains("truncated"), "{err}");
        let err = from_bytes_with_limit::<f64>(&bytes, Path::new("k.npy"), MAX_ELEMENTS);
        assert!(matches!(err, Err(Error::Format { .. })));
    }

    /// Found by fuzzing (FUZZING.md): nested braces in the header made the npy crate's
    /// header parser run for minutes (exponential in the depth).
    #[test]
    fn deeply_nested_headers_are_refused_quickly() {
        let dict = format!(
            "{}'descr': '<f8', 'fortran_order': False, 'shape': (2, 3)}}",
            "{".repeat(30)
        );
        let bytes = npy_bytes(&dict, &[0u8; 48]);
        for result in [
            complex_from_bytes(&bytes, Path::new("n.npy")).map(|_| ()),
            from_bytes_with_limit::<f32>(&bytes, Path::new("n.npy"), MAX_ELEMENTS).map(|_| ()),
        ] {
            let err = result.unwrap_err();
            assert!(err.to_string().contains("nested"), "{err}");
        }
        // The nesting numpy writes for structured dtypes is still read as far as the dtype.
        let structured = npy_bytes(
            "{'descr': [('a', '<f8', (2,))], 'fortran_order': False, 'shape': (1,), }",
            &[0u8; 16],
        );
        let err = from_bytes_with_limit::<f64>(&structured, Path::new("s.npy"), 10).unwrap_err();
        assert!(!err.to_string().contains("nested"), "{err}");
    }
}
