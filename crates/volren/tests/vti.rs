//! The `.vti` reader on files written here in each encoding VTK uses: inline base64 with zlib
//! blocks (header and payload encoded separately, as VTK's writer does), appended raw data
//! with a 64-bit header, appended base64 cell data, ASCII; and malformed files.

use std::io::Write;

use base64::Engine;
use wscg_volren::vti::{parse_vti, read_vti, VtiValues};

fn b64(b: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(b)
}

fn zlib(b: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(b).unwrap();
    e.finish().unwrap()
}

/// zlib blocks of `block` bytes: (header words, concatenated compressed blocks).
fn blocks(raw: &[u8], block: usize) -> (Vec<u64>, Vec<u8>) {
    let chunks: Vec<&[u8]> = raw.chunks(block).collect();
    let comp: Vec<Vec<u8>> = chunks.iter().map(|c| zlib(c)).collect();
    let mut head = vec![
        chunks.len() as u64,
        block as u64,
        chunks.last().map_or(0, |c| c.len()) as u64,
    ];
    head.extend(comp.iter().map(|c| c.len() as u64));
    (head, comp.concat())
}

fn header_bytes(words: &[u64], wide: bool) -> Vec<u8> {
    words
        .iter()
        .flat_map(|&w| {
            if wide {
                w.to_le_bytes().to_vec()
            } else {
                (w as u32).to_le_bytes().to_vec()
            }
        })
        .collect()
}

fn file(header_type: &str, compressor: Option<&str>, extent: &str, body: &str) -> String {
    let comp = compressor.map_or(String::new(), |c| format!(" compressor=\"{c}\""));
    format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"{header_type}\"{comp}>\n  <ImageData WholeExtent=\"{extent}\" Origin=\"0 0 0\" Spacing=\"1 2 0.5\">\n{body}"
    )
}

#[test]
fn inline_binary_zlib_blocks() {
    let vals: Vec<u16> = (0..12u16).map(|v| v * 1000 + 7).collect();
    let raw: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
    let (head, payload) = blocks(&raw, 10);
    let text = format!(
        "{}<Piece Extent=\"0 2 0 1 0 1\"><PointData Scalars=\"s\">\n<DataArray type=\"UInt16\" Name=\"s\" format=\"binary\">\n  {}{}\n</DataArray></PointData></Piece></ImageData></VTKFile>\n",
        "",
        b64(&header_bytes(&head, false)),
        b64(&payload)
    );
    let xml = file(
        "UInt32",
        Some("vtkZLibDataCompressor"),
        "0 2 0 1 0 1",
        &text,
    );
    let img = parse_vti(xml.as_bytes()).unwrap();
    assert_eq!(img.dims, [3, 2, 2]);
    assert_eq!(img.spacing, [1.0, 2.0, 0.5]);
    assert_eq!(img.name, "s");
    assert_eq!(img.values, VtiValues::U16(vals));
}

#[test]
fn appended_raw_uint64_header_cell_data() {
    let vals: Vec<f32> = (0..8).map(|v| v as f32 * 0.25 - 1.0).collect();
    let raw: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut bytes = file(
        "UInt64",
        None,
        "0 2 0 2 0 2",
        "<Piece Extent=\"0 2 0 2 0 2\"><PointData></PointData><CellData Scalars=\"c\">\n<DataArray type=\"Float32\" Name=\"c\" format=\"appended\" offset=\"0\"/>\n</CellData></Piece></ImageData>\n<AppendedData encoding=\"raw\">\n _",
    )
    .into_bytes();
    bytes.extend_from_slice(&(raw.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&raw);
    bytes.extend_from_slice(b"\n</AppendedData></VTKFile>\n");
    let img = parse_vti(&bytes).unwrap();
    assert_eq!(img.dims, [2, 2, 2]);
    assert_eq!(img.values, VtiValues::F32(vals));
}

#[test]
fn appended_base64_zlib_int64_and_file_io() {
    let vals: Vec<i64> = (0..27).map(|v| v * v - 50).collect();
    let raw: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
    let (head, payload) = blocks(&raw, 64);
    let data = format!("{}{}", b64(&header_bytes(&head, false)), b64(&payload));
    let xml = file(
        "UInt32",
        Some("vtkZLibDataCompressor"),
        "0 2 0 2 0 2",
        &format!("<Piece Extent=\"0 2 0 2 0 2\"><PointData Scalars=\"f\">\n<DataArray type=\"Int64\" Name=\"f\" format=\"appended\" RangeMin=\"0\" offset=\"0\"/>\n</PointData></Piece></ImageData>\n<AppendedData encoding=\"base64\">\n _{data}\n</AppendedData></VTKFile>\n"),
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("f.vti");
    std::fs::write(&path, &xml).unwrap();
    let img = read_vti(&path).unwrap();
    assert_eq!(img.values, VtiValues::I64(vals.clone()));
    assert_eq!(img.values.to_f32()[26], 626.0);
    // Malformed content and missing files are errors, never panics.
    std::fs::write(&path, &xml[..xml.len() / 2]).unwrap();
    let e = read_vti(&path).unwrap_err().to_string();
    assert!(e.contains("cannot decode"), "{e}");
    assert!(read_vti(dir.path().join("missing.vti"))
        .unwrap_err()
        .to_string()
        .contains("cannot access"));
}

#[test]
fn ascii_and_malformed() {
    let xml = file(
        "UInt32",
        None,
        "0 1 0 0 0 0",
        "<Piece Extent=\"0 1 0 0 0 0\"><PointData><DataArray type=\"Float64\" Name=\"a\" format=\"ascii\">1.5 -2</DataArray></PointData></Piece></ImageData></VTKFile>",
    );
    let img = parse_vti(xml.as_bytes()).unwrap();
    assert_eq!(img.dims, [2, 1, 1]);
    assert_eq!(img.values, VtiValues::F64(vec![1.5, -2.0]));
    assert!(parse_vti(b"not xml at all").is_err());
    assert!(parse_vti(
        xml.replace("ImageData\" version", "PolyData\" version")
            .as_bytes()
    )
    .is_err());
    assert!(parse_vti(xml.replace("1.5 -2", "1.5").as_bytes()).is_err());
    // A corrupt zlib block.
    let raw = [1u8, 2, 3, 4];
    let (mut head, mut payload) = blocks(&raw, 4);
    payload[3] ^= 0xff;
    head[1] = 4;
    let text = format!(
        "<Piece><PointData><DataArray type=\"UInt8\" Name=\"b\" format=\"binary\">{}{}</DataArray></PointData></Piece></ImageData></VTKFile>",
        b64(&header_bytes(&head, false)),
        b64(&payload)
    );
    let xml = file(
        "UInt32",
        Some("vtkZLibDataCompressor"),
        "0 3 0 0 0 0",
        &text,
    );
    assert!(parse_vti(xml.as_bytes()).is_err());
}

/// Hostile headers: a padded first header block, absurd block counts and sizes are errors
/// (no panic, no giant allocation).
#[test]
fn hostile_headers_are_errors() {
    let wrap = |header_type: &str, data: String| {
        let text = format!(
            "<Piece><PointData><DataArray type=\"UInt8\" Name=\"b\" format=\"binary\">{data}</DataArray></PointData></Piece></ImageData></VTKFile>"
        );
        file(
            header_type,
            Some("vtkZLibDataCompressor"),
            "0 3 0 0 0 0",
            &text,
        )
    };
    let cases = [
        wrap("UInt32", "AAAAAAAAAAAAAA==".into()),
        wrap("UInt64", b64(&header_bytes(&[u64::MAX, 4, 4], true))),
        wrap("UInt64", b64(&header_bytes(&[1, 1 << 62, 0, 12], true))),
        wrap(
            "UInt32",
            b64(&header_bytes(&[2, u32::MAX as u64, 7, 12, 12], false)),
        ),
        wrap(
            "UInt32",
            b64(&header_bytes(&[1, 4, 4, u32::MAX as u64], false)),
        ),
    ];
    for xml in cases {
        assert!(parse_vti(xml.as_bytes()).is_err());
    }
}
