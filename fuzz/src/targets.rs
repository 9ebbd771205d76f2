//! The fuzz targets: one entry per file reader, each feeding arbitrary bytes to the reader's
//! in-memory entry point. A reader must return (`Ok` or `Err`) on every input and never
//! panic, abort, or allocate without bound.
//!
//! This file is shared by the coverage-guided harness (`fuzz/src/main.rs`, run under AFL++)
//! and by the deterministic pass over the committed corpora (`tests/fuzz_corpus.rs` of the
//! umbrella crate), so both exercise the readers the same way.

use std::path::Path;
use std::sync::OnceLock;

#[path = "dicom.rs"]
mod dicom;
// `raw_input` and `write_seeds` serve the seed writer only.
#[allow(dead_code)]
#[path = "readers.rs"]
pub mod readers;
pub use readers::READER_TARGETS;

/// Every target, by the name of its corpus folder (`fuzz/corpus/<name>`).
pub const TARGETS: &[&str] = &[
    "raster",
    "obj",
    "ply",
    "nifti",
    "npy",
    "vti",
    "bvh",
    "skeleton_csv",
    "ntu",
    "gyro_csv",
    "ts",
    "octree",
    "volren_static",
    "volren_roi",
    "tf_json",
    "strokes_json",
    "dicom",
];

/// The pixel limit the raster target decodes under (`wscg_math::io::set_max_image_pixels`):
/// large enough for every seed, small enough that a fuzzed header declaring a large image is
/// refused before it costs the fuzzer time.
pub const FUZZ_MAX_IMAGE_PIXELS: u64 = 1 << 20;

/// The name every reader gets as the file it reads from.
fn origin() -> &'static Path {
    Path::new("fuzz-input")
}

/// The text of a text format: the bytes when they are UTF-8, else their lossy decoding (the
/// path readers refuse non-UTF-8 before parsing; the parser itself is what is fuzzed).
fn text(data: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(data)
}

/// Replaces the CRC-32 in the last four bytes of `data` with the checksum of the rest, so the
/// fuzzer reaches the checks behind the checksum (`HybridOctree::from_bytes`).
fn with_trailing_crc(data: &[u8]) -> Vec<u8> {
    let mut out = data.to_vec();
    if out.len() >= 4 {
        let body = out.len() - 4;
        let crc = crc32fast::hash(&out[..body]);
        out[body..].copy_from_slice(&crc.to_le_bytes());
    }
    out
}

/// Rewrites the payload length and CRC-32 of a paper-03 package header (bytes 8..16 and
/// 16..20 of the 20-byte header) to match the payload, for the same reason.
fn with_package_header(data: &[u8]) -> Vec<u8> {
    let mut out = data.to_vec();
    if out.len() >= 20 {
        let payload_len = (out.len() - 20) as u64;
        let crc = crc32fast::hash(&out[20..]);
        out[8..16].copy_from_slice(&payload_len.to_le_bytes());
        out[16..20].copy_from_slice(&crc.to_le_bytes());
    }
    out
}

/// A small volume's hybrid server, the source of the static package the ROI target's client
/// is built from (the same volume as the `volren_*` seeds).
pub fn volren_server() -> &'static wscg_volren::HybridServer {
    static SERVER: OnceLock<wscg_volren::HybridServer> = OnceLock::new();
    SERVER.get_or_init(|| {
        let v = wscg_volren::phantoms::head([16, 16, 8], 3).expect("phantom");
        wscg_volren::HybridServer::new(
            &v,
            wscg_volren::phantoms::head_tfs(),
            0,
            wscg_volren::ServerParams::default(),
        )
        .expect("server")
    })
}

/// Runs the reader of `target` on `data`. Returns whether the reader accepted the input;
/// panics only for an unknown target name.
pub fn run(target: &str, data: &[u8]) -> bool {
    match target {
        "raster" => {
            wscg_math::io::set_max_image_pixels(Some(FUZZ_MAX_IMAGE_PIXELS));
            // The EXIF reader parses the same containers (JPEG, TIFF, PNG).
            let exif = wscg_math::io::exif::read_exif(data, origin()).is_ok();
            wscg_math::Image::<f32>::decode(data, origin()).is_ok() || exif
        }
        "obj" => {
            // The one OBJ reader (meshes and the many-light scenes) and its MTL reader.
            let mesh = wscg_math::TriMesh::from_obj_bytes(data, origin()).is_ok();
            let mtl = wscg_math::io::obj::parse_mtl(data, origin()).is_ok();
            mesh || mtl
        }
        "ply" => wscg_math::TriMesh::from_ply_bytes(data, origin()).is_ok(),
        "nifti" => wscg_math::Volume::from_nifti_bytes(data, origin()).is_ok(),
        "npy" => {
            // The volume reader (f32, 3-D) and the complex reader (its real fallback reads
            // f64) cover the element conversions of `npy::from_bytes_with_limit`.
            let volume = wscg_math::Volume::from_npy_bytes(data, origin(), [1.0; 3]).is_ok();
            let complex = wscg_math::npy::complex_from_bytes(data, origin()).is_ok();
            volume || complex
        }
        "vti" => wscg_volren::vti::parse_vti(data).is_ok(),
        "bvh" => wscg_motion::bvh::parse_bvh(&text(data), origin()).is_ok(),
        "skeleton_csv" => {
            wscg_biometrics::gait::parse_skeleton_csv(&text(data), origin(), 30.0).is_ok()
        }
        "ntu" => wscg_biometrics::gait::parse_ntu(&text(data), origin()).is_ok(),
        "gyro_csv" => wscg_deblur::gyro::parse_gyro_csv(data, origin()).is_ok(),
        "ts" => wscg_biometrics::dtw::ts_file::parse_ts(&text(data)).is_ok(),
        "octree" => {
            wscg_octree::HybridOctree::from_bytes(&with_trailing_crc(data), origin()).is_ok()
        }
        "volren_static" => {
            wscg_volren::HybridClient::from_static(&with_package_header(data)).is_ok()
        }
        "volren_roi" => {
            static CLIENT: OnceLock<wscg_volren::HybridClient> = OnceLock::new();
            let client = CLIENT.get_or_init(|| {
                wscg_volren::HybridClient::from_static(&volren_server().static_package())
                    .expect("client")
            });
            let mut client = client.clone();
            client.set_roi(&with_package_header(data)).is_ok()
        }
        "tf_json" => {
            // Both transfer-function files: the list of paper 03 and the points of paper 15.
            let list = wscg_volren::tf::parse_tf_list(data, origin()).is_ok();
            let points =
                wscg_volren::illumination::TransferFunction::from_json_bytes(data, origin(), 256)
                    .is_ok();
            list || points
        }
        "strokes_json" => wscg_volseg::paint_strokes(data, origin(), [8, 8, 8], [1.0; 3]).is_ok(),
        "dicom" => dicom::run(data),
        other => readers::run(other, data, origin()).unwrap_or_else(|| {
            panic!(
                "unknown fuzz target {other:?}; the targets are {TARGETS:?} and {READER_TARGETS:?}"
            )
        }),
    }
}
