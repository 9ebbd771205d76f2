//! DICOM series (dicom-rs: `dicom-object` and `dicom-pixeldata`): a file, a folder or a list
//! of files read as one [`Volume`] with its voxel-to-world affine.
//!
//! - Files are grouped by SeriesInstanceUID (0020,000E). Several series are an error listing
//!   them, unless [`DicomParams::series`] picks one.
//! - Slices are sorted along the slice normal `n = r x c` (`r`, `c` the row and column
//!   directions of ImageOrientationPatient (0020,0037)) by `n . p`, `p` their
//!   ImagePositionPatient (0020,0032); the file order does not matter.
//! - Values are the stored values times RescaleSlope (0028,1053) plus RescaleIntercept
//!   (0028,1052): Hounsfield units for CT.
//! - `spacing = [column spacing, row spacing, slice step]`: PixelSpacing (0028,0030) is
//!   (row spacing, column spacing); the slice step is measured from the positions.
//! - The affine maps `(i, j, k)` = (column, row, slice) to `p_0 + i dx r + j dy c + k (p_last -
//!   p_0) / (N - 1)` in the DICOM patient frame (LPS+), converted to RAS+ by negating x and y
//!   (see [`crate::volume`]).
//!
//! Errors, not guesses: missing slices (a gap of more than 1.5 slice steps), slices at the same
//! position, mixed orientations, sizes or pixel spacings, and slice steps that differ by more
//! than [`DicomParams::spacing_tolerance`] are refused with a message naming the files.
//!
//! Transfer syntaxes decoded: implicit and explicit VR little endian, explicit VR big endian,
//! deflated, RLE lossless, JPEG baseline / extended / lossless, JPEG 2000 (pure-Rust codecs
//! only). JPEG-LS and JPEG XL need C libraries and are refused with an
//! [`Error::UnsupportedFormat`] naming the transfer syntax.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;
use dicom_encoding::TransferSyntaxIndex;
use dicom_object::file::ReadPreamble;
use dicom_object::{DefaultDicomObject, OpenFileOptions, Tag};
use dicom_pixeldata::{ConvertOptions, ModalityLutOption, PixelDecoder};
use dicom_transfer_syntax_registry::TransferSyntaxRegistry;

use crate::error::{read_file, Error, Result};
use crate::volume::{check_affine, voxel_count, Affine, Volume};

/// How a DICOM series is read.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct DicomParams {
    /// The SeriesInstanceUID to read when the files hold several series (`None`: the files
    /// must hold exactly one).
    pub series: Option<String>,
    /// Largest difference between a slice step and the median step, as a fraction of the
    /// median (default 0.01). Steps between 1.5 and any larger multiple of the median are
    /// reported as missing slices.
    pub spacing_tolerance: f64,
}

impl Default for DicomParams {
    fn default() -> Self {
        DicomParams {
            series: None,
            spacing_tolerance: 0.01,
        }
    }
}

impl DicomParams {
    /// Errors: a `spacing_tolerance` outside `[0, 0.5)` ([`Error::InvalidArgument`]).
    pub fn validate(&self) -> Result<()> {
        if !(0.0..0.5).contains(&self.spacing_tolerance) {
            return Err(Error::invalid(
                "spacing_tolerance",
                format!("must be in [0, 0.5), got {}", self.spacing_tolerance),
            ));
        }
        Ok(())
    }
}

/// What a slice file says about its place in the series.
struct Slice {
    path: PathBuf,
    obj: DefaultDicomObject,
    series: String,
    description: String,
    rows: usize,
    cols: usize,
    frames: usize,
    pixel_spacing: Option<[f64; 2]>,
    orientation: Option<[f64; 6]>,
    position: Option<[f64; 3]>,
}

/// True when `path` starts with a DICOM Part 10 preamble (`DICM` at byte 128).
pub fn is_dicom_file(path: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 132];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && &head[128..] == b"DICM"
}

impl Volume<f32> {
    /// Reads a DICOM series from a file or a folder (every regular file in it that starts
    /// with a DICOM preamble; others are skipped), with [`DicomParams::default`]. See the
    /// [module documentation](self).
    pub fn read_dicom(path: impl AsRef<Path>) -> Result<Self> {
        Self::read_dicom_with(path, &DicomParams::default())
    }

    /// [`Volume::read_dicom`] with explicit parameters.
    pub fn read_dicom_with(path: impl AsRef<Path>, params: &DicomParams) -> Result<Self> {
        let path = path.as_ref();
        let files = if path.is_dir() {
            let mut files = Vec::new();
            let entries = std::fs::read_dir(path).map_err(|e| Error::io(path, e))?;
            for e in entries {
                let p = e.map_err(|e| Error::io(path, e))?.path();
                if p.is_file() && is_dicom_file(&p) {
                    files.push(p);
                } else {
                    log::debug!("{}: not a DICOM file, skipped", p.display());
                }
            }
            if files.is_empty() {
                return Err(Error::format(path, "the folder holds no DICOM file"));
            }
            files.sort();
            files
        } else {
            vec![path.to_path_buf()]
        };
        Self::read_dicom_files(&files, params)
    }

    /// Reads the given DICOM files as one series (any order). See the
    /// [module documentation](self).
    ///
    /// Errors: [`Error::Io`] for an unreadable file; [`Error::Format`] naming the file for
    /// one that is not DICOM, is truncated, or lacks what its place in the series needs;
    /// [`Error::UnsupportedFormat`] for colour images and transfer syntaxes without a decoder
    /// here (named); [`Error::InvalidArgument`] for several series or an inconsistent series
    /// (named slices); [`Error::LimitExceeded`] / [`Error::OutOfMemory`] for a declared size
    /// too large, before the pixels are decoded.
    pub fn read_dicom_files(paths: &[PathBuf], params: &DicomParams) -> Result<Self> {
        params.validate()?;
        if paths.is_empty() {
            return Err(Error::Empty("DICOM files"));
        }
        let mut slices = paths
            .iter()
            .map(|p| read_slice(p))
            .collect::<Result<Vec<_>>>()?;

        // One series.
        let mut series: BTreeMap<&str, (usize, &str)> = BTreeMap::new();
        for s in &slices {
            let e = series.entry(&s.series).or_insert((0, &s.description));
            e.0 += 1;
        }
        let chosen = match (&params.series, series.len()) {
            (Some(uid), _) if series.contains_key(uid.as_str()) => Some(uid.clone()),
            (None, 1) => None,
            (wanted, _) => {
                let list: Vec<String> = series
                    .iter()
                    .map(|(uid, (n, d))| format!("{uid} ({d:?}, {n} files)"))
                    .collect();
                let what = match wanted {
                    Some(uid) => format!("no file of series {uid}"),
                    None => format!("{} series", series.len()),
                };
                return Err(Error::invalid(
                    "series",
                    format!(
                        "the DICOM files hold {what}: {}; choose one by its SeriesInstanceUID",
                        list.join(", ")
                    ),
                ));
            }
        };
        if let Some(uid) = chosen {
            slices.retain(|s| s.series == uid);
        }
        let geometry = series_geometry(&mut slices, params)?;
        decode_series(&slices, geometry)
    }
}

/// The grid of a checked series: spacing, dims and the RAS+ affine (if known).
struct Geometry {
    dims: [usize; 3],
    spacing: [f64; 3],
    affine: Option<Affine>,
}

fn read_slice(path: &Path) -> Result<Slice> {
    let bytes = read_file(path)?;
    if bytes.len() < 132 || &bytes[128..132] != b"DICM" {
        return Err(Error::format(
            path,
            "not a DICOM file (no \"DICM\" after the 128-byte preamble)",
        ));
    }
    let obj = OpenFileOptions::new()
        .read_preamble(ReadPreamble::Never)
        .from_reader(&bytes[128..])
        .map_err(|e| Error::format(path, format!("invalid DICOM file: {e}")))?;
    let text = |tag: Tag| -> Option<String> {
        obj.element_opt(tag)
            .ok()
            .flatten()
            .and_then(|e| e.to_str().ok())
            .map(|s| s.trim_matches(|c: char| c == '\0' || c.is_whitespace()).to_string())
    };
    let floats = |tag: Tag, n: usize, name: &str| -> Result<Option<Vec<f64>>> {
        match obj.element_opt(tag).ok().flatten() {
            None => Ok(None),
            Some(e) => {
                let v = e
                    .to_multi_float64()
                    .map_err(|err| Error::format(path, format!("{name}: {err}")))?;
                if v.len() != n || v.iter().any(|x| !x.is_finite()) {
                    return Err(Error::format(
                        path,
                        format!("{name} must hold {n} finite numbers, got {v:?}"),
                    ));
                }
                Ok(Some(v))
            }
        }
    };
    let int = |tag: Tag, name: &str| -> Result<Option<usize>> {
        match obj.element_opt(tag).ok().flatten() {
            None => Ok(None),
            Some(e) => e
                .to_int::<u32>()
                .map(|v| Some(v as usize))
                .map_err(|err| Error::format(path, format!("{name}: {err}"))),
        }
    };
    let rows = int(tags::ROWS, "Rows")?
        .ok_or_else(|| Error::format(path, "no Rows (0028,0010): not an image"))?;
    let cols = int(tags::COLUMNS, "Columns")?
        .ok_or_else(|| Error::format(path, "no Columns (0028,0011): not an image"))?;
    let frames = match text(tags::NUMBER_OF_FRAMES) {
        None => 1,
        Some(s) if s.is_empty() => 1,
        Some(s) => s
            .parse::<usize>()
            .map_err(|_| Error::format(path, format!("NumberOfFrames {s:?} is not a count")))?,
    };
    if rows == 0 || cols == 0 || frames == 0 {
        return Err(Error::format(
            path,
            format!("empty image: {rows} rows, {cols} columns, {frames} frames"),
        ));
    }
    let spp = int(tags::SAMPLES_PER_PIXEL, "SamplesPerPixel")?.unwrap_or(1);
    let photometric = text(tags::PHOTOMETRIC_INTERPRETATION).unwrap_or_default();
    if spp != 1 || !photometric.starts_with("MONOCHROME") {
        return Err(Error::UnsupportedFormat(format!(
            "{}: a {photometric} image with {spp} samples per pixel; only greyscale \
             (MONOCHROME1/2) volumes are read",
            path.display()
        )));
    }
    let pixel_spacing = floats(tags::PIXEL_SPACING, 2, "PixelSpacing")?;
    if let Some(ps) = &pixel_spacing {
        if ps.iter().any(|&v| v <= 0.0) {
            return Err(Error::format(
                path,
                format!("PixelSpacing must be > 0, got {ps:?}"),
            ));
        }
    }
    Ok(Slice {
        path: path.to_path_buf(),
        series: text(tags::SERIES_INSTANCE_UID).unwrap_or_default(),
        description: text(tags::SERIES_DESCRIPTION).unwrap_or_default(),
        rows,
        cols,
        frames,
        pixel_spacing: pixel_spacing.map(|v| [v[0], v[1]]),
        orientation: floats(tags::IMAGE_ORIENTATION_PATIENT, 6, "ImageOrientationPatient")?
            .map(|v| [v[0], v[1], v[2], v[3], v[4], v[5]]),
        position: floats(tags::IMAGE_POSITION_PATIENT, 3, "ImagePositionPatient")?
            .map(|v| [v[0], v[1], v[2]]),
        obj,
    })
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = dot(v, v).sqrt();
    (n > 1e-6).then(|| v.map(|x| x / n))
}

/// Checks that the slices form one regular grid, sorts them along the slice normal and
/// returns the grid.
fn series_geometry(slices: &mut [Slice], params: &DicomParams) -> Result<Geometry> {
    let first = &slices[0];
    let bad = |msg: String| Error::invalid("series", msg);
    for s in slices.iter().skip(1) {
        if (s.rows, s.cols) != (first.rows, first.cols) {
            return Err(bad(format!(
                "mixed sizes: {} is {} x {} (columns x rows), {} is {} x {}",
                first.path.display(),
                first.cols,
                first.rows,
                s.path.display(),
                s.cols,
                s.rows
            )));
        }
        let close = |a: &[f64], b: &[f64], tol: f64| a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol);
        let same_spacing = match (&first.pixel_spacing, &s.pixel_spacing) {
            (Some(a), Some(b)) => close(a, b, 1e-4 * a[0].max(a[1])),
            (None, None) => true,
            _ => false,
        };
        if !same_spacing {
            return Err(bad(format!(
                "mixed pixel spacings: {:?} in {}, {:?} in {}",
                first.pixel_spacing,
                first.path.display(),
                s.pixel_spacing,
                s.path.display()
            )));
        }
        let same_orientation = match (&first.orientation, &s.orientation) {
            (Some(a), Some(b)) => close(a, b, 1e-4),
            (None, None) => true,
            _ => false,
        };
        if !same_orientation {
            return Err(bad(format!(
                "mixed orientations: ImageOrientationPatient {:?} in {}, {:?} in {}",
                first.orientation,
                first.path.display(),
                s.orientation,
                s.path.display()
            )));
        }
    }
    let [dy, dx] = first.pixel_spacing.unwrap_or([1.0, 1.0]);

    if slices.len() == 1 {
        // One file: a single slice, or the frames of a multi-frame image stacked along z.
        let s = &slices[0];
        let step = ["SpacingBetweenSlices", "SliceThickness"]
            .iter()
            .zip([tags::SPACING_BETWEEN_SLICES, tags::SLICE_THICKNESS])
            .find_map(|(_, tag)| {
                s.obj
                    .element_opt(tag)
                    .ok()
                    .flatten()
                    .and_then(|e| e.to_float64().ok())
                    .filter(|v| v.is_finite() && *v > 0.0)
            })
            .unwrap_or(1.0);
        let affine = match (&s.orientation, &s.position, s.frames) {
            (Some(o), Some(p), 1) => slice_affine(o, *p, [dx, dy], None, step)?,
            _ => None,
        };
        if s.frames > 1 {
            log::warn!(
                "{}: {} frames stacked along z with step {step} (SpacingBetweenSlices or \
                 SliceThickness); per-frame positions are not read, so the volume has no affine",
                s.path.display(),
                s.frames
            );
        }
        return Ok(Geometry {
            dims: [s.cols, s.rows, s.frames],
            spacing: [dx, dy, step],
            affine,
        });
    }

    if let Some(s) = slices.iter().find(|s| s.frames != 1) {
        return Err(bad(format!(
            "{} has {} frames; a series of several files must hold one slice each",
            s.path.display(),
            s.frames
        )));
    }
    let (Some(o), true) = (first.orientation, slices.iter().all(|s| s.position.is_some()))
    else {
        let s = slices
            .iter()
            .find(|s| s.orientation.is_none() || s.position.is_none())
            .unwrap_or(first);
        return Err(bad(format!(
            "{} lacks ImagePositionPatient or ImageOrientationPatient, so the slices cannot be \
             ordered",
            s.path.display()
        )));
    };
    let (first_path, cols, rows) = (first.path.display().to_string(), first.cols, first.rows);
    let normal = slice_normal(&o).ok_or_else(|| {
        bad(format!(
            "ImageOrientationPatient {o:?} of {first_path} has parallel or zero directions"
        ))
    })?;
    let pos = |s: &Slice| s.position.expect("checked above");
    slices.sort_by(|a, b| dot(pos(a), normal).total_cmp(&dot(pos(b), normal)));
    let d: Vec<f64> = slices.iter().map(|s| dot(pos(s), normal)).collect();
    let steps: Vec<f64> = d.windows(2).map(|w| w[1] - w[0]).collect();
    let mut sorted = steps.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let name = |i: usize| {
        format!(
            "{} (position {:.4} mm along the normal)",
            slices[i].path.display(),
            d[i]
        )
    };
    for (i, &step) in steps.iter().enumerate() {
        if step <= 1e-6 * median.max(1e-3) {
            return Err(bad(format!(
                "two slices at the same position: {} and {}",
                name(i),
                name(i + 1)
            )));
        }
    }
    for (i, &step) in steps.iter().enumerate() {
        if step > 1.5 * median {
            return Err(bad(format!(
                "missing slices: a gap of {step:.4} mm ({:.1} steps of {median:.4} mm) between \
                 {} and {}",
                step / median,
                name(i),
                name(i + 1)
            )));
        }
        if (step - median).abs() > params.spacing_tolerance * median {
            return Err(bad(format!(
                "non-uniform slice spacing: {step:.4} mm between {} and {}, {median:.4} mm \
                 elsewhere (tolerance {})",
                name(i),
                name(i + 1),
                params.spacing_tolerance
            )));
        }
    }
    let n = slices.len();
    let (p0, pl) = (pos(&slices[0]), pos(&slices[n - 1]));
    let k_step = [0, 1, 2].map(|a| (pl[a] - p0[a]) / (n - 1) as f64);
    let affine = slice_affine(&o, p0, [dx, dy], Some(k_step), median)?;
    let dz = dot(k_step, k_step).sqrt();
    Ok(Geometry {
        dims: [cols, rows, n],
        spacing: [dx, dy, dz],
        affine,
    })
}

/// The unit slice normal `r x c` of an ImageOrientationPatient.
fn slice_normal(o: &[f64; 6]) -> Option<[f64; 3]> {
    let r = unit([o[0], o[1], o[2]])?;
    let c = unit([o[3], o[4], o[5]])?;
    unit(cross(r, c))
}

/// The RAS+ affine of a slice stack: columns `dx r`, `dy c`, `k_step` (default `step` times
/// the normal), origin `p0`, with DICOM's LPS+ x and y negated.
fn slice_affine(
    o: &[f64; 6],
    p0: [f64; 3],
    [dx, dy]: [f64; 2],
    k_step: Option<[f64; 3]>,
    step: f64,
) -> Result<Option<Affine>> {
    let (Some(r), Some(c), Some(n)) = (
        unit([o[0], o[1], o[2]]),
        unit([o[3], o[4], o[5]]),
        slice_normal(o),
    ) else {
        return Ok(None);
    };
    let k = k_step.unwrap_or(n.map(|v| v * step));
    let mut a = [[0.0; 4]; 3];
    for row in 0..3 {
        let sign = if row < 2 { -1.0 } else { 1.0 };
        a[row] = [r[row] * dx, c[row] * dy, k[row], p0[row]].map(|v| sign * v);
    }
    check_affine(&a)?;
    Ok(Some(a))
}

/// Decodes the sorted slices into the volume (rescaled values).
fn decode_series(slices: &[Slice], g: Geometry) -> Result<Volume<f32>> {
    let n = voxel_count(g.dims)?;
    crate::alloc::ensure::<f32>("DICOM series", n)?;
    let mut data: Vec<f32> = crate::alloc::try_with_capacity("DICOM series", n)?;
    for s in slices {
        let ts_uid = s.obj.meta().transfer_syntax().trim_end_matches('\0').to_string();
        let ts = TransferSyntaxRegistry.get(&ts_uid);
        let ts_name = ts.map(|t| t.name()).unwrap_or("unknown transfer syntax");
        if !ts.is_some_and(|t| t.can_decode_all()) {
            return Err(Error::UnsupportedFormat(format!(
                "{}: transfer syntax {ts_uid} ({ts_name}) cannot be decoded here (supported: \
                 native little/big endian, deflated, RLE lossless, JPEG baseline/extended/\
                 lossless, JPEG 2000)",
                s.path.display()
            )));
        }
        crate::alloc::ensure::<f64>("DICOM slice", s.rows * s.cols * s.frames)?;
        let decoded = s.obj.decode_pixel_data().map_err(|e| {
            Error::format(
                &s.path,
                format!("cannot decode the pixel data ({ts_uid}, {ts_name}): {e}"),
            )
        })?;
        let raw: Vec<f64> = decoded
            .to_vec_with_options(&ConvertOptions::new().with_modality_lut(ModalityLutOption::None))
            .map_err(|e| Error::format(&s.path, format!("cannot convert the pixel data: {e}")))?;
        let want = s.rows * s.cols * s.frames;
        if raw.len() != want {
            return Err(Error::format(
                &s.path,
                format!("decoded {} pixel values, expected {want}", raw.len()),
            ));
        }
        let value = |tag: Tag, default: f64| {
            s.obj
                .element_opt(tag)
                .ok()
                .flatten()
                .and_then(|e| e.to_float64().ok())
                .filter(|v| v.is_finite())
                .unwrap_or(default)
        };
        let slope = value(tags::RESCALE_SLOPE, 1.0);
        let intercept = value(tags::RESCALE_INTERCEPT, 0.0);
        data.extend(raw.iter().map(|&v| (v * slope + intercept) as f32));
    }
    log::debug!(
        "read a DICOM series of {} files: {:?} voxels, spacing {:?}, affine {:?}",
        slices.len(),
        g.dims,
        g.spacing,
        g.affine
    );
    let mut vol = Volume::new(g.dims, g.spacing, data)?;
    vol.affine = g.affine;
    Ok(vol)
}
