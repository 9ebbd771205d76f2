//! Headerless (raw) volume files: voxels stored x fastest as one of the [`RawType`]s, read
//! with [`Volume::read_raw`] and written as little-endian `f32` by
//! [`Volume::write_raw_f32_le`].

use std::fs::File;
use std::io::BufReader;
use std::path::Path;
use std::str::FromStr;

use rayon::prelude::*;

use super::read_up_to;
use crate::error::{Error, Result};
use crate::volume::{check_spacing, voxel_count, Real, Volume};

/// Element type and byte order of a headerless (raw) volume file, for [`Volume::read_raw`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RawType {
    /// Unsigned 8-bit.
    U8,
    /// Unsigned 16-bit, little-endian.
    U16Le,
    /// Unsigned 16-bit, big-endian.
    U16Be,
    /// Signed 16-bit (two's complement), little-endian.
    I16Le,
    /// Signed 16-bit (two's complement), big-endian.
    I16Be,
    /// IEEE 754 32-bit float, little-endian.
    F32Le,
    /// IEEE 754 32-bit float, big-endian.
    F32Be,
}

impl RawType {
    /// Every raw type, in declaration order.
    pub const ALL: [RawType; 7] = [
        RawType::U8,
        RawType::U16Le,
        RawType::U16Be,
        RawType::I16Le,
        RawType::I16Be,
        RawType::F32Le,
        RawType::F32Be,
    ];

    /// Bytes per voxel (1, 2 or 4).
    pub fn bytes_per_voxel(self) -> usize {
        match self {
            RawType::U8 => 1,
            RawType::U16Le | RawType::U16Be | RawType::I16Le | RawType::I16Be => 2,
            RawType::F32Le | RawType::F32Be => 4,
        }
    }

    /// The lower-case name accepted by [`RawType::from_str`]: `u8`, `u16le`, `u16be`,
    /// `i16le`, `i16be`, `f32le`, `f32be`.
    pub fn name(self) -> &'static str {
        match self {
            RawType::U8 => "u8",
            RawType::U16Le => "u16le",
            RawType::U16Be => "u16be",
            RawType::I16Le => "i16le",
            RawType::I16Be => "i16be",
            RawType::F32Le => "f32le",
            RawType::F32Be => "f32be",
        }
    }

    /// Decodes one voxel from exactly `bytes_per_voxel()` bytes.
    #[inline]
    fn decode(self, b: &[u8]) -> f32 {
        match self {
            RawType::U8 => b[0] as f32,
            RawType::U16Le => u16::from_le_bytes([b[0], b[1]]) as f32,
            RawType::U16Be => u16::from_be_bytes([b[0], b[1]]) as f32,
            RawType::I16Le => i16::from_le_bytes([b[0], b[1]]) as f32,
            RawType::I16Be => i16::from_be_bytes([b[0], b[1]]) as f32,
            RawType::F32Le => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            RawType::F32Be => f32::from_be_bytes([b[0], b[1], b[2], b[3]]),
        }
    }
}

impl std::fmt::Display for RawType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for RawType {
    type Err = Error;

    /// Parses `u8`, `u16le`, `u16be`, `i16le`, `i16be`, `f32le`, `f32be` (case-insensitive).
    fn from_str(s: &str) -> Result<Self> {
        let lower = s.to_ascii_lowercase();
        RawType::ALL
            .into_iter()
            .find(|t| t.name() == lower)
            .ok_or_else(|| {
                Error::invalid(
                    "raw_type",
                    format!(
                        "{s:?} is not a valid raw type. Valid types are u8, u16le, u16be, \
                         i16le, i16be, f32le, f32be"
                    ),
                )
            })
    }
}

impl<T: Real> Volume<T> {
    /// Writes the voxels as headerless little-endian `f32`, x fastest (`nx * ny * nz * 4`
    /// bytes); read it back with [`Volume::read_raw`] and [`RawType::F32Le`].
    pub fn write_raw_f32_le(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let values = T::as_f32_slice(&self.data);
        let mut bytes = Vec::with_capacity(values.len() * 4);
        for v in values.iter() {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        super::atomic::write(path, bytes)
    }
}

/// The byte size of a raw volume, after checking `dims` and `spacing`.
fn raw_size(dims: [usize; 3], spacing: [f64; 3], raw_type: RawType) -> Result<u64> {
    let n = voxel_count(dims)?;
    check_spacing(spacing)?;
    Ok(n as u64 * raw_type.bytes_per_voxel() as u64)
}

/// The error of a raw file of `found` bytes where `expected` are needed.
fn raw_size_error(
    path: &Path,
    dims: [usize; 3],
    raw_type: RawType,
    expected: u64,
    found: u64,
) -> Error {
    if found < expected {
        Error::format(
            path,
            format!("truncated: expected {expected} bytes, found {found}"),
        )
    } else {
        Error::format(
            path,
            format!(
                "size mismatch: expected {expected} bytes ({dims:?} voxels of {raw_type}), \
                 found {found}"
            ),
        )
    }
}

impl Volume<f32> {
    /// Reads a headerless volume of `dims = [nx, ny, nz]` voxels stored x fastest as
    /// `raw_type`, with voxel size `spacing`; values are converted to `f32` unchanged (no
    /// rescaling).
    ///
    /// Errors: invalid `dims`/`spacing` (as [`Volume::new`]); a file whose size is not exactly
    /// `nx * ny * nz * bytes_per_voxel` ([`Error::Format`], "truncated: expected N bytes, found
    /// M" when too short); I/O failures.
    pub fn read_raw(
        path: impl AsRef<Path>,
        dims: [usize; 3],
        spacing: [f64; 3],
        raw_type: RawType,
    ) -> Result<Self> {
        let path = path.as_ref();
        let expected = raw_size(dims, spacing, raw_type)?;
        let file = File::open(path).map_err(|e| Error::io(path, e))?;
        let found = file.metadata().map_err(|e| Error::io(path, e))?.len();
        if found != expected {
            return Err(raw_size_error(path, dims, raw_type, expected, found));
        }
        let bytes = read_up_to(&mut BufReader::new(file), expected + 1, expected as usize)
            .map_err(|e| Error::io(path, e))?;
        Self::from_raw_bytes(&bytes, path, dims, spacing, raw_type)
    }

    /// [`Volume::read_raw`] of a file held in memory; `origin` names the file in errors.
    ///
    /// Errors: as [`Volume::read_raw`]; the size is checked before anything is allocated.
    pub fn from_raw_bytes(
        bytes: &[u8],
        origin: &Path,
        dims: [usize; 3],
        spacing: [f64; 3],
        raw_type: RawType,
    ) -> Result<Self> {
        let expected = raw_size(dims, spacing, raw_type)?;
        if bytes.len() as u64 != expected {
            return Err(raw_size_error(
                origin,
                dims,
                raw_type,
                expected,
                bytes.len() as u64,
            ));
        }
        let data: Vec<f32> = bytes
            .par_chunks_exact(raw_type.bytes_per_voxel())
            .map(|b| raw_type.decode(b))
            .collect();
        Volume::new(dims, spacing, data)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::tests::unique_volume;

    // ---------------------------------------------------------------- raw

    #[test]
    fn raw_bytes_in_memory_are_checked_against_the_dims() {
        let o = Path::new("mem.raw");
        let v = Volume::from_raw_bytes(&[1, 2, 3, 4], o, [2, 2, 1], [1.0; 3], RawType::U8).unwrap();
        assert_eq!(v.data, [1.0, 2.0, 3.0, 4.0]);
        let e = Volume::from_raw_bytes(&[1, 2, 3], o, [2, 2, 1], [1.0; 3], RawType::U8)
            .unwrap_err()
            .to_string();
        assert!(e.contains("mem.raw") && e.contains("truncated"), "{e}");
        let huge = [usize::MAX / 2, 2, 2];
        let e = Volume::from_raw_bytes(&[0; 8], o, huge, [1.0; 3], RawType::F32Le).unwrap_err();
        assert!(matches!(e, Error::LimitExceeded(_)), "{e}");
        assert!(Volume::from_raw_bytes(&[0; 5], o, [5, 1, 1], [0.0; 3], RawType::U8).is_err());
    }

    #[test]
    fn raw_reads_every_type_with_known_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let cases: [(RawType, Vec<u8>, [f32; 2]); 7] = [
            (RawType::U8, vec![7, 250], [7.0, 250.0]),
            (
                RawType::U16Le,
                vec![0x01, 0x02, 0xff, 0xff],
                [513.0, 65535.0],
            ),
            (
                RawType::U16Be,
                vec![0x01, 0x02, 0xff, 0xfe],
                [258.0, 65534.0],
            ),
            (RawType::I16Le, vec![0x01, 0x02, 0xfe, 0xff], [513.0, -2.0]),
            (
                RawType::I16Be,
                vec![0x01, 0x02, 0x80, 0x00],
                [258.0, -32768.0],
            ),
            (
                RawType::F32Le,
                [1.5f32.to_le_bytes(), (-2.25f32).to_le_bytes()].concat(),
                [1.5, -2.25],
            ),
            (
                RawType::F32Be,
                [1.5f32.to_be_bytes(), (-2.25f32).to_be_bytes()].concat(),
                [1.5, -2.25],
            ),
        ];
        for (t, bytes, want) in cases {
            assert_eq!(bytes.len(), 2 * t.bytes_per_voxel());
            let p = dir.path().join(format!("v_{t}.raw"));
            std::fs::write(&p, &bytes).unwrap();
            let v = Volume::read_raw(&p, [2, 1, 1], [1.0, 2.0, 3.0], t).unwrap();
            assert_eq!(v.data(), &want, "{t}");
            assert_eq!(v.spacing(), [1.0, 2.0, 3.0]);
            assert_eq!(t.name().parse::<RawType>().unwrap(), t);
            // Reader leaves the file alone.
            assert_eq!(std::fs::read(&p).unwrap(), bytes);
        }
        assert!("u32".parse::<RawType>().is_err());
    }

    #[test]
    fn raw_round_trip_and_size_errors() {
        let dir = tempfile::tempdir().unwrap();
        let v = unique_volume([0.5, 1.0, 2.0]);
        let p = dir.path().join("v.raw");
        v.write_raw_f32_le(&p).unwrap();
        assert_eq!(std::fs::metadata(&p).unwrap().len(), 60 * 4);
        let bytes = std::fs::read(&p).unwrap();
        // x fastest on disk: second value is voxel (1, 0, 0), fourth is (0, 1, 0).
        assert_eq!(f32::from_le_bytes(bytes[4..8].try_into().unwrap()), 1.0);
        assert_eq!(f32::from_le_bytes(bytes[12..16].try_into().unwrap()), 10.0);
        let back = Volume::read_raw(&p, [3, 4, 5], [0.5, 1.0, 2.0], RawType::F32Le).unwrap();
        assert_eq!(back, v);

        let short = dir.path().join("short.raw");
        std::fs::write(&short, &bytes[..100]).unwrap();
        let e = Volume::read_raw(&short, [3, 4, 5], [1.0; 3], RawType::F32Le).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, Error::Format { .. }), "{msg}");
        assert!(
            msg.contains("truncated: expected 240 bytes, found 100"),
            "{msg}"
        );
        assert!(msg.contains("short.raw"), "{msg}");
        // Too long is an error too.
        assert!(Volume::read_raw(&p, [3, 4, 4], [1.0; 3], RawType::F32Le).is_err());
        // Missing file.
        let e = Volume::read_raw(
            dir.path().join("nope.raw"),
            [1, 1, 1],
            [1.0; 3],
            RawType::U8,
        )
        .unwrap_err();
        assert!(matches!(e, Error::Io { .. }));
        assert!(Volume::read_raw(&p, [3, 4, 5], [f64::NAN, 1.0, 1.0], RawType::F32Le).is_err());
    }
}
