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
use crate::vec3::{cross, dot, norm, try_normalize};
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
    /// Reads the series with this SeriesInstanceUID.
    pub fn series(mut self, uid: impl Into<String>) -> Self {
        self.series = Some(uid.into());
        self
    }

    /// Sets [`DicomParams::spacing_tolerance`].
    pub fn spacing_tolerance(mut self, tolerance: f64) -> Self {
        self.spacing_tolerance = tolerance;
        self
    }

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
        let slices = paths
            .iter()
            .map(|p| read_slice(p, &read_file(p)?))
            .collect::<Result<Vec<_>>>()?;
        assemble_series(slices, params)
    }

    /// Reads one DICOM Part 10 file held in memory (the bytes of a `.dcm` file, preamble
    /// included) as a volume; `origin` names it in errors. The in-memory form of
    /// [`Volume::read_dicom`] on one file, with the same errors.
    pub fn from_dicom_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        Self::from_dicom_series_bytes(&[(origin, bytes)], &DicomParams::default())
    }

    /// Reads the DICOM files held in memory, each with the name that identifies it in errors,
    /// as one series (any order): the in-memory form of [`Volume::read_dicom_files`], with
    /// the same checks and errors.
    pub fn from_dicom_series_bytes(files: &[(&Path, &[u8])], params: &DicomParams) -> Result<Self> {
        params.validate()?;
        if files.is_empty() {
            return Err(Error::Empty("DICOM files"));
        }
        let slices = files
            .iter()
            .map(|(path, bytes)| read_slice(path, bytes))
            .collect::<Result<Vec<_>>>()?;
        assemble_series(slices, params)
    }
}

/// Picks the series of `slices`, checks its geometry and decodes it.
fn assemble_series(mut slices: Vec<Slice>, params: &DicomParams) -> Result<Volume<f32>> {
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

/// The grid of a checked series: spacing, dims and the RAS+ affine (if known).
struct Geometry {
    dims: [usize; 3],
    spacing: [f64; 3],
    affine: Option<Affine>,
}

/// Parses one slice file, `bytes` the whole file, `path` its name in errors.
fn read_slice(path: &Path, bytes: &[u8]) -> Result<Slice> {
    if bytes.len() < 132 || &bytes[128..132] != b"DICM" {
        return Err(Error::format(
            path,
            "not a DICOM file (no \"DICM\" after the 128-byte preamble)",
        ));
    }
    // dicom-rs allocates each value at its declared length before reading it.
    super::dicom_lengths::check(&bytes[132..])
        .map_err(|reason| Error::format(path, format!("invalid DICOM file: {reason}")))?;
    let obj = OpenFileOptions::new()
        .read_preamble(ReadPreamble::Never)
        .from_reader(&bytes[128..])
        .map_err(|e| Error::format(path, format!("invalid DICOM file: {e}")))?;
    let text = |tag: Tag| -> Option<String> {
        obj.element_opt(tag)
            .ok()
            .flatten()
            .and_then(|e| e.to_str().ok())
            .map(|s| {
                s.trim_matches(|c: char| c == '\0' || c.is_whitespace())
                    .to_string()
            })
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
        orientation: floats(
            tags::IMAGE_ORIENTATION_PATIENT,
            6,
            "ImageOrientationPatient",
        )?
        .map(|v| [v[0], v[1], v[2], v[3], v[4], v[5]]),
        position: floats(tags::IMAGE_POSITION_PATIENT, 3, "ImagePositionPatient")?
            .map(|v| [v[0], v[1], v[2]]),
        obj,
    })
}

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    try_normalize(v, 1e-6)
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
        // Equal within `tol`, or both absent.
        let agree = |a: Option<&[f64]>, b: Option<&[f64]>, tol: f64| match (a, b) {
            (Some(a), Some(b)) => a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol),
            (None, None) => true,
            _ => false,
        };
        let checks = [
            (
                "pixel spacings (PixelSpacing)",
                first.pixel_spacing.as_ref().map(|v| &v[..]),
                s.pixel_spacing.as_ref().map(|v| &v[..]),
                1e-4 * first.pixel_spacing.map_or(1.0, |v| v[0].max(v[1])),
            ),
            (
                "orientations (ImageOrientationPatient)",
                first.orientation.as_ref().map(|v| &v[..]),
                s.orientation.as_ref().map(|v| &v[..]),
                1e-4,
            ),
        ];
        for (what, a, b, tol) in checks {
            if !agree(a, b, tol) {
                return Err(bad(format!(
                    "mixed {what}: {a:?} in {}, {b:?} in {}",
                    first.path.display(),
                    s.path.display()
                )));
            }
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
    let (Some(o), true) = (
        first.orientation,
        slices.iter().all(|s| s.position.is_some()),
    ) else {
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
    let dz = norm(k_step);
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

/// Refuses native (uncompressed) pixel data shorter than its declared rows x columns x
/// frames x BitsAllocated, before the decoder allocates for the declared size.
fn check_native_length(s: &Slice) -> Result<()> {
    let int = |tag: Tag| {
        s.obj
            .element_opt(tag)
            .ok()
            .flatten()
            .and_then(|e| e.to_int::<u32>().ok())
    };
    let bits = u128::from(int(tags::BITS_ALLOCATED).unwrap_or(16));
    let samples = (s.rows as u128) * (s.cols as u128) * (s.frames as u128);
    let need = (samples * bits).div_ceil(8);
    let have = s
        .obj
        .element_opt(tags::PIXEL_DATA)
        .ok()
        .flatten()
        .and_then(|e| e.header().len.get())
        .map_or(0, u128::from);
    if have < need {
        return Err(Error::format(
            &s.path,
            format!(
                "the pixel data holds {have} bytes; {} rows x {} columns x {} frames of {bits} \
                 bits need {need}",
                s.rows, s.cols, s.frames
            ),
        ));
    }
    Ok(())
}

/// Decodes the sorted slices into the volume (rescaled values).
fn decode_series(slices: &[Slice], g: Geometry) -> Result<Volume<f32>> {
    let n = voxel_count(g.dims)?;
    crate::alloc::ensure::<f32>("DICOM series", n)?;
    let mut data: Vec<f32> = crate::alloc::try_with_capacity("DICOM series", n)?;
    for s in slices {
        let ts_uid = s
            .obj
            .meta()
            .transfer_syntax()
            .trim_end_matches('\0')
            .to_string();
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
        if ts.is_some_and(|t| t.is_codec_free()) {
            check_native_length(s)?;
        }
        // dicom-rs's RLE and JPEG 2000 adapters index out of bounds on some malformed
        // fragments (FUZZING.md): a panic there is a format error naming the file.
        let raw: Vec<f64> = super::guarded(&s.path, "the DICOM pixel decoder", || {
            let decoded = s.obj.decode_pixel_data().map_err(|e| {
                Error::format(
                    &s.path,
                    format!("cannot decode the pixel data ({ts_uid}, {ts_name}): {e}"),
                )
            })?;
            decoded
                .to_vec_with_options(
                    &ConvertOptions::new().with_modality_lut(ModalityLutOption::None),
                )
                .map_err(|e| Error::format(&s.path, format!("cannot convert the pixel data: {e}")))
        })?;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// One explicit-VR little-endian element.
    fn elem(out: &mut Vec<u8>, group: u16, element: u16, vr: &[u8; 2], value: &[u8]) {
        let mut v = value.to_vec();
        if v.len() % 2 == 1 {
            v.push(if vr == b"UI" || vr == b"OB" { 0 } else { b' ' });
        }
        out.extend(group.to_le_bytes());
        out.extend(element.to_le_bytes());
        out.extend(vr);
        if matches!(vr, b"OB" | b"OW" | b"SQ" | b"UN" | b"UT") {
            out.extend([0, 0]);
            out.extend((v.len() as u32).to_le_bytes());
        } else {
            out.extend((v.len() as u16).to_le_bytes());
        }
        out.extend(v);
    }

    struct SliceSpec<'a> {
        series: &'a str,
        rows: u16,
        cols: u16,
        frames: Option<u32>,
        position: [f64; 3],
        orientation: [f64; 6],
        pixels: Vec<u16>,
    }

    /// A minimal CT slice file (explicit VR little endian), values `pixels * 2 - 1000` HU.
    /// The header of an explicit-VR little-endian element with a 4-byte length.
    fn elem_header(out: &mut Vec<u8>, group: u16, element: u16, vr: &[u8; 2], len: u32) {
        out.extend(group.to_le_bytes());
        out.extend(element.to_le_bytes());
        out.extend(vr);
        out.extend([0, 0]);
        out.extend(len.to_le_bytes());
    }

    fn slice_file(s: &SliceSpec) -> Vec<u8> {
        let ts = b"1.2.840.10008.1.2.1";
        let class = b"1.2.840.10008.5.1.4.1.1.2";
        let mut meta = Vec::new();
        elem(&mut meta, 2, 1, b"OB", &[0, 1]);
        elem(&mut meta, 2, 2, b"UI", class);
        elem(&mut meta, 2, 3, b"UI", b"1.2.3.4");
        elem(&mut meta, 2, 0x10, b"UI", ts);
        let mut out = vec![0u8; 128];
        out.extend(b"DICM");
        elem(&mut out, 2, 0, b"UL", &(meta.len() as u32).to_le_bytes());
        out.extend(meta);
        let ds = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x}"))
                .collect::<Vec<_>>()
                .join("\\")
                .into_bytes()
        };
        elem(&mut out, 8, 0x16, b"UI", class);
        elem(&mut out, 8, 0x18, b"UI", b"1.2.3.4");
        elem(&mut out, 8, 0x60, b"CS", b"CT");
        elem(&mut out, 0x20, 0x0E, b"UI", s.series.as_bytes());
        elem(&mut out, 0x20, 0x32, b"DS", &ds(&s.position));
        elem(&mut out, 0x20, 0x37, b"DS", &ds(&s.orientation));
        elem(&mut out, 0x28, 2, b"US", &1u16.to_le_bytes());
        elem(&mut out, 0x28, 4, b"CS", b"MONOCHROME2");
        if let Some(f) = s.frames {
            elem(&mut out, 0x28, 8, b"IS", f.to_string().as_bytes());
        }
        elem(&mut out, 0x28, 0x10, b"US", &s.rows.to_le_bytes());
        elem(&mut out, 0x28, 0x11, b"US", &s.cols.to_le_bytes());
        elem(&mut out, 0x28, 0x30, b"DS", b"0.5\\0.75");
        elem(&mut out, 0x28, 0x100, b"US", &16u16.to_le_bytes());
        elem(&mut out, 0x28, 0x101, b"US", &16u16.to_le_bytes());
        elem(&mut out, 0x28, 0x102, b"US", &15u16.to_le_bytes());
        elem(&mut out, 0x28, 0x103, b"US", &0u16.to_le_bytes());
        elem(&mut out, 0x28, 0x1052, b"DS", b"-1000");
        elem(&mut out, 0x28, 0x1053, b"DS", b"2");
        let px: Vec<u8> = s.pixels.iter().flat_map(|v| v.to_le_bytes()).collect();
        elem(&mut out, 0x7FE0, 0x10, b"OW", &px);
        out
    }

    const AXIAL: [f64; 6] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

    /// Writes `n` slices 2.5 mm apart (file names in reverse order of position); returns the
    /// folder and the stored pixels by slice.
    fn series(dir: &Path, n: usize, skip: Option<usize>) -> Vec<Vec<u16>> {
        std::fs::create_dir_all(dir).unwrap();
        (0..n)
            .map(|k| {
                let pixels: Vec<u16> = (0..12).map(|i| (100 * k + i) as u16).collect();
                if Some(k) != skip {
                    let spec = SliceSpec {
                        series: "1.2.826.0.1",
                        rows: 3,
                        cols: 4,
                        frames: None,
                        position: [-10.0, 20.0, 30.0 + 2.5 * k as f64],
                        orientation: AXIAL,
                        pixels: pixels.clone(),
                    };
                    std::fs::write(dir.join(format!("{}.dcm", n - k)), slice_file(&spec)).unwrap();
                }
                pixels
            })
            .collect()
    }

    #[test]
    fn a_folder_is_sorted_by_position_rescaled_and_placed_in_ras() {
        let dir = tempfile::tempdir().unwrap();
        let pixels = series(dir.path(), 4, None);
        let v = Volume::read_dicom(dir.path()).unwrap();
        assert_eq!(v.dims(), [4, 3, 4]);
        assert_eq!(v.spacing(), [0.75, 0.5, 2.5]);
        for (k, px) in pixels.iter().enumerate() {
            for (i, &p) in px.iter().enumerate() {
                assert_eq!(v.at(i % 4, i / 4, k), f32::from(p) * 2.0 - 1000.0);
            }
        }
        // LPS (-10, 20, 30) + i 0.75 x + j 0.5 y + k 2.5 z, x and y negated.
        let a = v.affine().unwrap();
        assert_eq!(
            a,
            [
                [-0.75, 0.0, 0.0, 10.0],
                [0.0, -0.5, 0.0, -20.0],
                [0.0, 0.0, 2.5, 30.0]
            ]
        );
        assert_eq!(Volume::read(dir.path(), None).unwrap(), v);
        let one = Volume::read(dir.path().join("1.dcm"), None).unwrap();
        assert_eq!(one.dims(), [4, 3, 1]);

        // The same files from memory, in another order, give the same volume.
        let names: Vec<PathBuf> = (1..=4)
            .map(|k| dir.path().join(format!("{k}.dcm")))
            .collect();
        let bytes: Vec<Vec<u8>> = names.iter().map(|p| std::fs::read(p).unwrap()).collect();
        let files: Vec<(&Path, &[u8])> = names
            .iter()
            .map(|p| p.as_path())
            .zip(bytes.iter().map(|b| b.as_slice()))
            .rev()
            .collect();
        let from_memory = Volume::from_dicom_series_bytes(&files, &DicomParams::default()).unwrap();
        assert_eq!(from_memory, v);
        assert_eq!(Volume::from_dicom_bytes(&bytes[0], &names[0]).unwrap(), one);
        // Errors name the given origin.
        let e = Volume::from_dicom_bytes(&bytes[0][..200], Path::new("memory.dcm")).unwrap_err();
        assert!(
            matches!(&e, Error::Format { path, .. } if path == Path::new("memory.dcm")),
            "{e}"
        );
        assert!(matches!(
            Volume::from_dicom_series_bytes(&[], &DicomParams::default()),
            Err(Error::Empty(_))
        ));
    }

    #[test]
    fn inconsistent_series_are_errors_naming_the_files() {
        let dir = tempfile::tempdir().unwrap();
        series(&dir.path().join("gap"), 5, Some(2));
        let e = Volume::read_dicom(dir.path().join("gap"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing slices") && e.contains("2.dcm"), "{e}");

        let two = dir.path().join("two");
        series(&two, 3, None);
        let other = SliceSpec {
            series: "9.9.9",
            rows: 3,
            cols: 4,
            frames: None,
            position: [0.0; 3],
            orientation: AXIAL,
            pixels: vec![0; 12],
        };
        std::fs::write(two.join("x.dcm"), slice_file(&other)).unwrap();
        let e = Volume::read_dicom(&two).unwrap_err().to_string();
        assert!(
            e.contains("2 series") && e.contains("9.9.9") && e.contains("1.2.826.0.1"),
            "{e}"
        );
        let p = DicomParams::default().series("9.9.9");
        assert_eq!(Volume::read_dicom_with(&two, &p).unwrap().dims(), [4, 3, 1]);

        let mixed = dir.path().join("mixed");
        series(&mixed, 3, None);
        let tilted = SliceSpec {
            series: "1.2.826.0.1",
            position: [-10.0, 20.0, 37.5],
            orientation: [1.0, 0.0, 0.0, 0.0, 0.8, 0.6],
            ..other
        };
        std::fs::write(mixed.join("t.dcm"), slice_file(&tilted)).unwrap();
        let e = Volume::read_dicom(&mixed).unwrap_err().to_string();
        assert!(e.contains("mixed orientations"), "{e}");
        assert!(matches!(
            Volume::read_dicom_with(&mixed, &p.spacing_tolerance(0.7)),
            Err(Error::InvalidArgument { .. })
        ));
    }

    #[test]
    fn bad_files_are_errors_and_huge_sizes_are_refused_before_decoding() {
        let dir = tempfile::tempdir().unwrap();
        let spec = SliceSpec {
            series: "1.2",
            rows: 3,
            cols: 4,
            frames: None,
            position: [0.0; 3],
            orientation: AXIAL,
            pixels: vec![7; 12],
        };
        let good = slice_file(&spec);
        let p = dir.path().join("f.dcm");
        for cut in [10, 131, 200, good.len() - 5] {
            std::fs::write(&p, &good[..cut]).unwrap();
            assert!(Volume::read_dicom(&p).is_err(), "cut at {cut}");
        }
        let mut magic = good.clone();
        magic[128..132].copy_from_slice(b"DICN");
        std::fs::write(&p, &magic).unwrap();
        let e = Volume::read_dicom(&p).unwrap_err().to_string();
        assert!(e.contains("DICM"), "{e}");
        // 65535 x 65535 pixels x 2^20 frames declared over 24 bytes of pixel data.
        let huge = SliceSpec {
            rows: u16::MAX,
            cols: u16::MAX,
            frames: Some(1 << 20),
            ..spec
        };
        std::fs::write(&p, slice_file(&huge)).unwrap();
        let e = Volume::read_dicom(&p).unwrap_err();
        assert!(
            matches!(e, Error::LimitExceeded(_) | Error::OutOfMemory { .. }),
            "{e}"
        );
        // More frames declared than the native pixel data holds: refused before decoding.
        let frames = SliceSpec {
            series: "1.2",
            rows: 3,
            cols: 4,
            frames: Some(100_000),
            position: [0.0; 3],
            orientation: AXIAL,
            pixels: vec![7; 12],
        };
        let e = Volume::from_dicom_bytes(&slice_file(&frames), Path::new("frames.dcm"));
        let e = e.unwrap_err().to_string();
        assert!(
            e.contains("the pixel data holds 24 bytes; 3 rows x 4 columns x 100000 frames"),
            "{e}"
        );
        // A value declared longer than the file (4 GB of pixel data in a 700-byte file; the
        // parser would reserve and zero-fill it before reading): refused at once.
        let mut long = good.clone();
        let at = long.len() - 24 - 4;
        long[at..at + 4].copy_from_slice(&0xF000_0000u32.to_le_bytes());
        let start = std::time::Instant::now();
        let e = Volume::from_dicom_bytes(&long, Path::new("long.dcm")).unwrap_err();
        assert!(start.elapsed().as_secs() < 2, "{:?}", start.elapsed());
        assert!(
            e.to_string()
                .contains("long.dcm: invalid DICOM file: element (7FE0,0010)")
                && e.to_string()
                    .contains("declares 4026531840 bytes, but only 24"),
            "{e}"
        );
        // The same in the file meta group: (0002,0001) OB, after (0002,0000) UL.
        let mut meta_long = good.clone();
        assert_eq!(&meta_long[144..150], &[2, 0, 1, 0, b'O', b'B']);
        meta_long[152..156].copy_from_slice(&0xFFFF_FF00u32.to_le_bytes());
        let e = Volume::from_dicom_bytes(&meta_long, Path::new("m.dcm")).unwrap_err();
        assert!(e.to_string().contains("(0002,0001) at byte 144"), "{e}");
        // Sequences nested 100 deep (undefined lengths): refused before the recursive parser.
        let mut deep = good[..good.len() - 24 - 12].to_vec();
        for _ in 0..100 {
            elem_header(&mut deep, 0x0008, 0x1115, b"SQ", u32::MAX); // a sequence
            deep.extend([0xFE, 0xFF, 0x00, 0xE0, 0xFF, 0xFF, 0xFF, 0xFF]); // an item
        }
        let e = Volume::from_dicom_bytes(&deep, Path::new("deep.dcm")).unwrap_err();
        assert!(e.to_string().contains("nested more than 64 deep"), "{e}");
        let empty = dir.path().join("empty");
        std::fs::create_dir(&empty).unwrap();
        std::fs::write(empty.join("notes.txt"), b"not dicom").unwrap();
        assert!(matches!(
            Volume::read_dicom(&empty),
            Err(Error::Format { .. })
        ));
    }
}
