//! DICOM inputs that fuzzing found costly (FUZZING.md): each must now be refused at once,
//! as an error naming the file.

use std::path::Path;
use std::time::{Duration, Instant};

use wscg_math::{Error, Volume};

/// A deflated data set whose mutated stream inflates to an element declaring a value of
/// about a gigabyte: dicom-rs reserved and zero-filled it before reading (1.5 GB of memory
/// and over a second for a 4.6 KB file).
#[test]
fn deflated_file_declaring_a_huge_value_is_refused_before_allocating() {
    refused_at_once("fuzz_dicom_deflated_long_value.dcm");
}

/// An implicit VR file whose SamplesPerPixel (US) declares 257 bytes: the parser reads 128
/// numbers (256 bytes) and takes the next header one byte early, where it found a value of
/// 3.9 GB that it reserved and zero-filled (4 to 8 s and 3.8 GB of memory). The length walk
/// now steps over such values as the parser does and refuses that header.
#[test]
fn odd_length_number_value_does_not_hide_a_huge_value() {
    refused_at_once("fuzz_dicom_odd_length_number.dcm");
}

/// A deflated file whose mutated meta group leaves group 0002 before its declared group
/// length: dicom-rs reads meta elements (of any group) up to that length and starts
/// inflating there, where the stream declared a value of gigabytes (3 s and 3.6 GB before
/// failing); the length walk stopped at the first tag outside group 0002 and inflated from
/// the wrong byte. It now reads the meta group as the parser does.
#[test]
fn meta_group_is_walked_to_its_declared_length() {
    refused_at_once("fuzz_dicom_meta_group_length.dcm");
}

/// Reads `tests/data/<name>`: a format error naming the file, a length refused, within 2 s.
fn refused_at_once(name: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    let start = Instant::now();
    let err = Volume::read_dicom(&path).unwrap_err();
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "{:?}",
        start.elapsed()
    );
    assert!(matches!(err, Error::Format { .. }), "{err}");
    let text = err.to_string();
    assert!(text.contains(name) && text.contains("declares"), "{text}");
}

/// Files on which dicom-rs 0.10's pixel adapters index out of bounds (the JPEG 2000 adapter
/// writing a component past the frame, the RLE adapter reading a segment header past the
/// fragment): a format error naming the file, not a panic.
#[test]
fn pixel_adapter_panics_are_format_errors() {
    for name in [
        "fuzz_dicom_j2k_adapter_panic.dcm",
        "fuzz_dicom_rle_adapter_panic.dcm",
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name);
        let err = Volume::read_dicom(&path).unwrap_err();
        assert!(matches!(err, Error::Format { .. }), "{name}: {err}");
        assert!(err.to_string().contains(name), "{err}");
    }
}
