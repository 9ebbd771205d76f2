//! The `dicom` target: `Volume::from_dicom_bytes` on one file, or
//! `Volume::from_dicom_series_bytes` on several, so that the series checks (grouping by
//! SeriesInstanceUID, sorting along the slice normal, spacing and gap checks) are fuzzed as
//! well as the parser and the pixel decoders.
//!
//! An input holding [`SEPARATOR`] is cut there into the files of one series (at most
//! [`MAX_FILES`]); the seeds include such a series, so the fuzzer starts with the marker.

use std::path::{Path, PathBuf};

/// The marker between the files of a series in one fuzz input.
pub const SEPARATOR: &[u8] = b"@@next-dicom-file@@";

/// The most files a fuzz input is cut into (the rest stays in the last file).
pub const MAX_FILES: usize = 8;

/// Cuts `data` at each [`SEPARATOR`] into at most [`MAX_FILES`] files.
pub fn split(data: &[u8]) -> Vec<&[u8]> {
    let mut parts = Vec::new();
    let mut rest = data;
    while parts.len() + 1 < MAX_FILES {
        match rest.windows(SEPARATOR.len()).position(|w| w == SEPARATOR) {
            Some(at) => {
                parts.push(&rest[..at]);
                rest = &rest[at + SEPARATOR.len()..];
            }
            None => break,
        }
    }
    parts.push(rest);
    parts
}

/// The memory limit the target reads under (`wscg_math::memory_limit::set_limit`): the
/// seeds need a few megabytes; a fuzzed header declaring a large image (which a compressed
/// transfer syntax may legitimately do over a few bytes) is refused before it costs the
/// fuzzer time and memory.
pub const FUZZ_MEMORY_LIMIT: u64 = 256 << 20;

/// Reads `data` as one DICOM file or, when it holds [`SEPARATOR`], as a series.
pub fn run(data: &[u8]) -> bool {
    wscg_math::memory_limit::set_limit(Some(FUZZ_MEMORY_LIMIT));
    let parts = split(data);
    if parts.len() == 1 {
        return wscg_math::Volume::from_dicom_bytes(data, Path::new("fuzz-input.dcm")).is_ok();
    }
    let names: Vec<PathBuf> = (0..parts.len())
        .map(|i| PathBuf::from(format!("fuzz-input-{i}.dcm")))
        .collect();
    let files: Vec<(&Path, &[u8])> = names.iter().map(|n| n.as_path()).zip(parts).collect();
    wscg_math::Volume::from_dicom_series_bytes(
        &files,
        &wscg_math::io::dicom::DicomParams::default(),
    )
    .is_ok()
}
