//! EXIF exposure settings of photographs (JPEG, TIFF, PNG `eXIf`) through `kamadak-exif`:
//! the exposure time, f-number and ISO sensitivity that an exposure stack's radiometry needs
//! (Debevec & Malik 1997, section 2: the exposure `X = E * dt` of each photograph; paper 13,
//! section 3: each camera's exposure time).
//!
//! [`read_exif`] / [`load_exif`] give an [`ExifExposure`]; [`relative_exposures`] turns the
//! settings of a stack into the exposures the HDR merge divides by, and
//! [`resolve_exposure_times`] is what the HDR commands do with a list of files and optional
//! user-given times: the EXIF values when no times are given, and a [`TimeMismatch`] for each
//! given time that disagrees with the file by more than [`EXIF_TIME_TOLERANCE`].
//!
//! The relative exposure of image `i` is `t_i * (S_i / 100) / N_i^2` (exposure time `t`,
//! ISO `S`, f-number `N`: the sensor's exposure scales with the time and the gain and with
//! the aperture's area, `1 / N^2`), normalised to the first image:
//! `e_i = t_i * (S_i / S_0) * (N_0 / N_i)^2`, so the first image keeps its exposure time in
//! seconds and every other one is the time that would give the same exposure at the first
//! image's ISO and aperture. ISO and aperture enter only when every image gives them and they
//! differ between the images; otherwise the exposures are the exposure times alone.
//!
//! Parsing is bounded by the bytes given (`kamadak-exif` reads the EXIF block of a JPEG or
//! PNG, and the whole of a TIFF, which the caller already holds) and runs under
//! `catch_unwind`, so a malformed block is an error naming the file, never a panic.

use std::io::Cursor;
use std::path::Path;

use ::exif::{In, Tag, Value};

use crate::error::{read_file, Error, Result};

/// The relative difference between a given exposure time and the file's EXIF value above
/// which [`resolve_exposure_times`] reports a [`TimeMismatch`]: 10 %, above the rounding of
/// cameras' nominal times (1/125 s for 1/128 s is 2.4 %) and below a third of a stop (26 %).
pub const EXIF_TIME_TOLERANCE: f64 = 0.1;

/// The exposure settings a photograph's EXIF block records (each `None` when absent or
/// blank).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct ExifExposure {
    /// ExposureTime (tag 0x829A), seconds.
    pub exposure_time: Option<f64>,
    /// FNumber (tag 0x829D), the aperture's f-number `N`.
    pub f_number: Option<f64>,
    /// PhotographicSensitivity (ISOSpeedRatings, tag 0x8827), the ISO sensitivity.
    pub iso: Option<f64>,
}

impl ExifExposure {
    /// Settings with the given values (the struct is non-exhaustive).
    pub fn new(exposure_time: Option<f64>, f_number: Option<f64>, iso: Option<f64>) -> Self {
        Self {
            exposure_time,
            f_number,
            iso,
        }
    }
}

/// The first value of a numeric field, when positive and finite.
fn positive(exif: &::exif::Exif, tag: Tag) -> Option<f64> {
    let field = exif.get_field(tag, In::PRIMARY)?;
    let v = match &field.value {
        Value::Rational(r) => r.first().filter(|r| r.denom != 0).map(|r| r.to_f64()),
        Value::SRational(r) => r.first().filter(|r| r.denom != 0).map(|r| r.to_f64()),
        Value::Float(f) => f.first().map(|&v| f64::from(v)),
        Value::Double(f) => f.first().copied(),
        other => other.get_uint(0).map(f64::from),
    }?;
    (v.is_finite() && v > 0.0).then_some(v)
}

/// Reads the exposure settings of an image file held in memory (JPEG, TIFF, PNG, WebP or
/// HEIF container). `origin` names the source in error messages.
///
/// Errors: [`Error::Format`] naming `origin` when the file holds no EXIF block or a
/// malformed one. A block without the exposure tags gives `None` fields.
pub fn read_exif(bytes: &[u8], origin: &Path) -> Result<ExifExposure> {
    let parsed = std::panic::catch_unwind(|| {
        ::exif::Reader::new().read_from_container(&mut Cursor::new(bytes))
    })
    .map_err(|_| Error::format(origin, "the EXIF reader failed on malformed data"))?;
    let exif = parsed.map_err(|e| match e {
        ::exif::Error::NotFound(_) => Error::format(origin, "holds no EXIF block"),
        other => Error::format(origin, format!("malformed EXIF block: {other}")),
    })?;
    Ok(ExifExposure {
        exposure_time: positive(&exif, Tag::ExposureTime),
        f_number: positive(&exif, Tag::FNumber),
        iso: positive(&exif, Tag::PhotographicSensitivity),
    })
}

/// [`read_exif`] of a file (only read).
pub fn load_exif(path: impl AsRef<Path>) -> Result<ExifExposure> {
    let path = path.as_ref();
    read_exif(&read_file(path)?, path)
}

/// The values of `get` over `settings` when every image gives one and they are not all
/// equal (the factor they contribute to the relative exposure), else `None`.
fn varying(
    settings: &[ExifExposure],
    get: impl Fn(&ExifExposure) -> Option<f64>,
) -> Option<Vec<f64>> {
    let v: Vec<f64> = settings.iter().map(get).collect::<Option<_>>()?;
    v.iter().any(|&x| x != v[0]).then_some(v)
}

/// The relative exposures of a stack (see the module documentation): `t_i` when ISO and
/// aperture are the same in every image (or not given by all), else
/// `t_i * (S_i / S_0) * (N_0 / N_i)^2`. `None` when an image has no exposure time, with the
/// index of the first such image.
pub fn relative_exposures(settings: &[ExifExposure]) -> std::result::Result<Vec<f64>, usize> {
    let times: Vec<f64> = settings
        .iter()
        .enumerate()
        .map(|(i, s)| s.exposure_time.ok_or(i))
        .collect::<std::result::Result<_, _>>()?;
    let iso = varying(settings, |s| s.iso);
    let aperture = varying(settings, |s| s.f_number);
    Ok(times
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            let gain = iso.as_ref().map_or(1.0, |s| s[i] / s[0]);
            let area = aperture.as_ref().map_or(1.0, |n| (n[0] / n[i]).powi(2));
            t * gain * area
        })
        .collect())
}

/// A given exposure time that disagrees with the file's EXIF value (relative difference
/// above [`EXIF_TIME_TOLERANCE`]).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct TimeMismatch {
    /// Index of the image in the stack.
    pub index: usize,
    /// The given time, seconds.
    pub given: f64,
    /// The file's relative exposure (seconds; see [`relative_exposures`]).
    pub exif: f64,
    /// Says which file and both values.
    pub message: String,
}

/// The exposure times of a stack of image files and the disagreements found.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ResolvedTimes {
    /// One exposure per file, seconds: the given times, or the EXIF relative exposures.
    pub times: Vec<f64>,
    /// True when the times were read from EXIF.
    pub from_exif: bool,
    /// Given times that disagree with the files' EXIF values (empty when none were given).
    pub mismatches: Vec<TimeMismatch>,
}

/// The exposure times of the image files `paths` (files only read): `given` when it is
/// `Some` (one per file), checked against the files' EXIF relative exposures when every file
/// has one (each disagreement above [`EXIF_TIME_TOLERANCE`] is a [`TimeMismatch`], also
/// logged as a warning); else the EXIF relative exposures ([`relative_exposures`]).
///
/// Errors: `given` of another length than `paths`; without `given`, a file with no EXIF
/// block or no exposure time ([`Error::Format`] naming it and asking for the times).
pub fn resolve_exposure_times<P: AsRef<Path>>(
    paths: &[P],
    given: Option<&[f64]>,
) -> Result<ResolvedTimes> {
    let paths: Vec<&Path> = paths.iter().map(AsRef::as_ref).collect();
    if let Some(g) = given {
        if g.len() != paths.len() {
            return Err(Error::invalid(
                "times",
                format!("{} times for {} images", g.len(), paths.len()),
            ));
        }
    }
    let read: Vec<Result<ExifExposure>> = paths.iter().map(load_exif).collect();
    let Some(given) = given else {
        let settings = read
            .into_iter()
            .collect::<Result<Vec<_>>>()
            .map_err(|e| match e {
                Error::Format { path, reason } => Error::Format {
                    path,
                    reason: format!("{reason}; give the exposure times"),
                },
                other => other,
            })?;
        let times = relative_exposures(&settings).map_err(|i| {
            Error::format(
                paths[i],
                "has no EXIF exposure time; give the exposure times",
            )
        })?;
        return Ok(ResolvedTimes {
            times,
            from_exif: true,
            mismatches: Vec::new(),
        });
    };
    let settings: Option<Vec<ExifExposure>> = read.into_iter().map(|r| r.ok()).collect();
    let exif = settings.and_then(|s| relative_exposures(&s).ok());
    let mut mismatches = Vec::new();
    if let Some(exif) = exif {
        for (i, (&g, &e)) in given.iter().zip(&exif).enumerate() {
            if (g - e).abs() > EXIF_TIME_TOLERANCE * e {
                let message = format!(
                    "{}: the given exposure time {g} s differs from the EXIF exposure {e} s \
                     by more than {:.0} %",
                    paths[i].display(),
                    EXIF_TIME_TOLERANCE * 100.0
                );
                log::warn!("{message}");
                mismatches.push(TimeMismatch {
                    index: i,
                    given: g,
                    exif: e,
                    message,
                });
            }
        }
    }
    Ok(ResolvedTimes {
        times: given.to_vec(),
        from_exif: false,
        mismatches,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::image::tests::ramp;
    use crate::Image;

    /// A big-endian EXIF block (TIFF structure) with the Exif IFD holding ExposureTime
    /// `t = (num, den)`, FNumber `f` and ISO when given.
    pub(crate) fn exif_block(
        t: Option<(u32, u32)>,
        f: Option<(u32, u32)>,
        iso: Option<u16>,
    ) -> Vec<u8> {
        let mut entries: Vec<(u16, u16, [u8; 4])> = Vec::new();
        let mut rationals: Vec<(u32, u32)> = Vec::new();
        let n = [t.is_some(), f.is_some(), iso.is_some()]
            .iter()
            .filter(|&&b| b)
            .count();
        // header 8, IFD0 (2 + 12 + 4), Exif IFD (2 + 12 n + 4), then the rationals.
        let exif_at = 8 + 18;
        let data_at = exif_at + 2 + 12 * n + 4;
        for (tag, r) in [(0x829Au16, t), (0x829D, f)] {
            if let Some(r) = r {
                let at = (data_at + 8 * rationals.len()) as u32;
                entries.push((tag, 5, at.to_be_bytes()));
                rationals.push(r);
            }
        }
        if let Some(iso) = iso {
            let v = iso.to_be_bytes();
            entries.push((0x8827, 3, [v[0], v[1], 0, 0]));
        }
        let mut out = b"MM\0*".to_vec();
        out.extend(8u32.to_be_bytes());
        out.extend(1u16.to_be_bytes());
        out.extend(0x8769u16.to_be_bytes());
        out.extend(4u16.to_be_bytes());
        out.extend(1u32.to_be_bytes());
        out.extend((exif_at as u32).to_be_bytes());
        out.extend(0u32.to_be_bytes());
        out.extend((entries.len() as u16).to_be_bytes());
        for (tag, kind, value) in entries {
            out.extend(tag.to_be_bytes());
            out.extend(kind.to_be_bytes());
            out.extend(1u32.to_be_bytes());
            out.extend(value);
        }
        out.extend(0u32.to_be_bytes());
        for (a, b) in rationals {
            out.extend(a.to_be_bytes());
            out.extend(b.to_be_bytes());
        }
        out
    }

    /// A small JPEG carrying `block` in an APP1 `Exif` segment after its start-of-image.
    pub(crate) fn jpeg_with_exif(block: &[u8]) -> Vec<u8> {
        let jpeg = ramp(8, 8, 3).encode_jpeg(90).unwrap();
        let mut out = jpeg[..2].to_vec();
        out.extend([0xFF, 0xE1]);
        out.extend(((2 + 6 + block.len()) as u16).to_be_bytes());
        out.extend(b"Exif\0\0");
        out.extend(block);
        out.extend(&jpeg[2..]);
        out
    }

    #[test]
    fn exposure_fnumber_and_iso_are_read() {
        let jpeg = jpeg_with_exif(&exif_block(Some((1, 250)), Some((28, 10)), Some(400)));
        let e = read_exif(&jpeg, Path::new("a.jpg")).unwrap();
        assert_eq!(e, ExifExposure::new(Some(0.004), Some(2.8), Some(400.0)));
        // The image itself still decodes.
        assert_eq!(
            Image::decode(&jpeg, Path::new("a.jpg")).unwrap().shape(),
            (8, 8, 3)
        );
        // Only the time; a zero denominator is no value.
        let only_t = jpeg_with_exif(&exif_block(Some((1, 30)), None, None));
        let e = read_exif(&only_t, Path::new("b.jpg")).unwrap();
        assert_eq!(e, ExifExposure::new(Some(1.0 / 30.0), None, None));
        let zero = jpeg_with_exif(&exif_block(Some((1, 0)), None, None));
        assert_eq!(
            read_exif(&zero, Path::new("z.jpg")).unwrap().exposure_time,
            None
        );
        // A TIFF file's own IFD is read too.
        let tiff = exif_block(Some((2, 1)), None, Some(100));
        assert_eq!(
            read_exif(&tiff, Path::new("c.tif")).unwrap().exposure_time,
            Some(2.0)
        );
    }

    #[test]
    fn missing_and_malformed_exif_are_errors_naming_the_file() {
        let plain = ramp(8, 8, 3).encode_jpeg(90).unwrap();
        let e = read_exif(&plain, Path::new("plain.jpg")).unwrap_err();
        assert!(
            e.to_string().contains("plain.jpg") && e.to_string().contains("no EXIF"),
            "{e}"
        );
        let block = exif_block(Some((1, 250)), Some((28, 10)), Some(400));
        // Truncated block, wrong magic, an IFD offset past the end.
        let mut magic = block.clone();
        magic[3] = b'+';
        let mut offset = block.clone();
        offset[4..8].copy_from_slice(&60000u32.to_be_bytes());
        for (name, bad) in [
            ("cut.jpg", jpeg_with_exif(&block[..20])),
            ("magic.jpg", jpeg_with_exif(&magic)),
            ("offset.jpg", jpeg_with_exif(&offset)),
            ("garbage.bin", b"not an image".to_vec()),
            ("empty.jpg", Vec::new()),
        ] {
            let e = read_exif(&bad, Path::new(name)).unwrap_err();
            assert!(e.to_string().contains(name), "{e}");
        }
        // Every truncation of a whole file returns.
        let jpeg = jpeg_with_exif(&block);
        for cut in 0..jpeg.len().min(200) {
            let _ = read_exif(&jpeg[..cut], Path::new("t.jpg"));
        }
    }

    #[test]
    fn relative_exposure_uses_iso_and_aperture_only_when_they_vary() {
        let s = |t, n, iso| ExifExposure::new(Some(t), Some(n), Some(iso));
        // Same ISO and aperture: the times.
        let same = [s(0.01, 4.0, 100.0), s(0.04, 4.0, 100.0)];
        assert_eq!(relative_exposures(&same).unwrap(), vec![0.01, 0.04]);
        // ISO 400 at f/8 vs ISO 100 at f/4: gain 4, area 1/4 -> the same exposure as 0.02 s.
        let both = [s(0.01, 4.0, 100.0), s(0.02, 8.0, 400.0)];
        let r = relative_exposures(&both).unwrap();
        assert!((r[1] - 0.02).abs() < 1e-15 && r[0] == 0.01, "{r:?}");
        // ISO alone varies: 0.01 s at ISO 200 is 0.02 s at ISO 100.
        let iso = [s(0.01, 4.0, 100.0), s(0.01, 4.0, 200.0)];
        assert_eq!(relative_exposures(&iso).unwrap(), vec![0.01, 0.02]);
        // A setting some image lacks is left out.
        let partial = [
            s(0.01, 4.0, 100.0),
            ExifExposure::new(Some(0.03), None, Some(800.0)),
        ];
        assert_eq!(relative_exposures(&partial).unwrap(), vec![0.01, 0.24]);
        let no_time = [
            s(0.01, 4.0, 100.0),
            ExifExposure::new(None, Some(4.0), None),
        ];
        assert_eq!(relative_exposures(&no_time), Err(1));
    }

    #[test]
    fn times_come_from_exif_or_are_checked_against_it() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, bytes: Vec<u8>| {
            let p = dir.path().join(name);
            std::fs::write(&p, bytes).unwrap();
            p
        };
        let a = write(
            "a.jpg",
            jpeg_with_exif(&exif_block(Some((1, 100)), None, None)),
        );
        let b = write(
            "b.jpg",
            jpeg_with_exif(&exif_block(Some((1, 25)), None, None)),
        );
        let got = resolve_exposure_times(&[&a, &b], None).unwrap();
        assert_eq!(got.times, vec![0.01, 0.04]);
        assert!(got.from_exif && got.mismatches.is_empty());
        // Given times within the tolerance: no mismatch; beyond it: one naming the file.
        let ok = resolve_exposure_times(&[&a, &b], Some(&[0.0105, 0.04])).unwrap();
        assert!(ok.mismatches.is_empty() && !ok.from_exif);
        let off = resolve_exposure_times(&[&a, &b], Some(&[0.01, 0.08])).unwrap();
        assert_eq!(off.times, vec![0.01, 0.08]);
        assert_eq!(off.mismatches.len(), 1);
        assert_eq!((off.mismatches[0].index, off.mismatches[0].exif), (1, 0.04));
        assert!(off.mismatches[0].message.contains("b.jpg"));
        // No EXIF: given times are used as they are; without them, an error naming the file.
        let plain = write("plain.jpg", ramp(8, 8, 3).encode_jpeg(90).unwrap());
        let given = resolve_exposure_times(&[&a, &plain], Some(&[0.5, 1.0])).unwrap();
        assert!(given.mismatches.is_empty());
        let e = resolve_exposure_times(&[&a, &plain], None).unwrap_err();
        assert!(
            e.to_string().contains("plain.jpg") && e.to_string().contains("give the"),
            "{e}"
        );
        let no_t = write(
            "no_t.jpg",
            jpeg_with_exif(&exif_block(None, Some((4, 1)), None)),
        );
        let e = resolve_exposure_times(&[&a, &no_t], None).unwrap_err();
        assert!(e.to_string().contains("no_t.jpg"), "{e}");
        assert!(resolve_exposure_times(&[&a, &b], Some(&[0.01])).is_err());
    }
}
