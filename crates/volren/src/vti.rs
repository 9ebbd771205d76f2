//! Reader for VTK XML image data (`.vti`): the format of the volumes shipped with VTK-based
//! tools (for instance the frog tissue labels inside the `pyvista` wheel).
//!
//! Supported: one `ImageData` piece; the first `DataArray` of `PointData` (or of `CellData`
//! when there is no point array); inline `format="binary"` (base64) and `format="appended"`
//! with `encoding="base64"` or `"raw"`; `vtkZLibDataCompressor` or no compression; header
//! types `UInt32` and `UInt64`; little-endian integer and float scalars with one component.

use std::io::Read;
use std::path::Path;

use base64::Engine;
use wscg_math::{Error, Result};

/// Largest number of values accepted (guards against hostile headers).
const MAX_VALUES: usize = 1 << 31;

/// Largest number of compressed blocks accepted.
const MAX_BLOCKS: u64 = 1 << 24;

/// Values of a `.vti` array, in their stored type.
#[derive(Clone, Debug, PartialEq)]
pub enum VtiValues {
    /// `UInt8`.
    U8(Vec<u8>),
    /// `Int8`.
    I8(Vec<i8>),
    /// `UInt16`.
    U16(Vec<u16>),
    /// `Int16`.
    I16(Vec<i16>),
    /// `UInt32`.
    U32(Vec<u32>),
    /// `Int32`.
    I32(Vec<i32>),
    /// `Int64`.
    I64(Vec<i64>),
    /// `UInt64`.
    U64(Vec<u64>),
    /// `Float32`.
    F32(Vec<f32>),
    /// `Float64`.
    F64(Vec<f64>),
}

impl VtiValues {
    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            VtiValues::U8(v) => v.len(),
            VtiValues::I8(v) => v.len(),
            VtiValues::U16(v) => v.len(),
            VtiValues::I16(v) => v.len(),
            VtiValues::U32(v) => v.len(),
            VtiValues::I32(v) => v.len(),
            VtiValues::I64(v) => v.len(),
            VtiValues::U64(v) => v.len(),
            VtiValues::F32(v) => v.len(),
            VtiValues::F64(v) => v.len(),
        }
    }

    /// True if there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values converted to `f32`.
    pub fn to_f32(&self) -> Vec<f32> {
        match self {
            VtiValues::U8(v) => v.iter().map(|&x| x as f32).collect(),
            VtiValues::I8(v) => v.iter().map(|&x| x as f32).collect(),
            VtiValues::U16(v) => v.iter().map(|&x| x as f32).collect(),
            VtiValues::I16(v) => v.iter().map(|&x| x as f32).collect(),
            VtiValues::U32(v) => v.iter().map(|&x| x as f32).collect(),
            VtiValues::I32(v) => v.iter().map(|&x| x as f32).collect(),
            VtiValues::I64(v) => v.iter().map(|&x| x as f32).collect(),
            VtiValues::U64(v) => v.iter().map(|&x| x as f32).collect(),
            VtiValues::F32(v) => v.clone(),
            VtiValues::F64(v) => v.iter().map(|&x| x as f32).collect(),
        }
    }

    fn decode(ty: &str, bytes: &[u8], n: usize) -> Option<Self> {
        macro_rules! take {
            ($t:ty, $variant:ident) => {{
                let sz = std::mem::size_of::<$t>();
                if bytes.len() < n * sz {
                    return None;
                }
                VtiValues::$variant(
                    bytes[..n * sz]
                        .chunks_exact(sz)
                        .map(|c| <$t>::from_le_bytes(c.try_into().expect("chunk size")))
                        .collect(),
                )
            }};
        }
        Some(match ty {
            "UInt8" => take!(u8, U8),
            "Int8" => take!(i8, I8),
            "UInt16" => take!(u16, U16),
            "Int16" => take!(i16, I16),
            "UInt32" => take!(u32, U32),
            "Int32" => take!(i32, I32),
            "Int64" => take!(i64, I64),
            "UInt64" => take!(u64, U64),
            "Float32" => take!(f32, F32),
            "Float64" => take!(f64, F64),
            _ => return None,
        })
    }
}

/// A `.vti` volume: dims `[nx, ny, nz]` (`x` fastest), spacing, origin, array name and values.
#[derive(Clone, Debug, PartialEq)]
pub struct VtiImage {
    /// Samples per axis.
    pub dims: [usize; 3],
    /// Spacing per axis.
    pub spacing: [f64; 3],
    /// Position of the first sample.
    pub origin: [f64; 3],
    /// Name of the array read.
    pub name: String,
    /// The values, `x` fastest.
    pub values: VtiValues,
}

/// Value of attribute `name` in the tag text `tag`.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let mut rest = tag;
    let pat = format!("{name}=\"");
    loop {
        let i = rest.find(&pat)?;
        let before = rest[..i].chars().last();
        let start = i + pat.len();
        if before.is_none_or(|c| c.is_whitespace()) {
            let end = rest[start..].find('"')?;
            return Some(&rest[start..start + end]);
        }
        rest = &rest[start..];
    }
}

/// The text of the first tag `<name ...>` at or after `from`, and where it ends.
fn tag<'a>(text: &'a str, name: &str, from: usize) -> Option<(&'a str, usize)> {
    let pat = format!("<{name}");
    let mut pos = from;
    loop {
        let i = text[pos..].find(&pat)? + pos;
        let after = text[i + pat.len()..].chars().next()?;
        if after.is_whitespace() || after == '>' || after == '/' {
            let end = text[i..].find('>')? + i;
            return Some((&text[i..=end], end + 1));
        }
        pos = i + pat.len();
    }
}

fn numbers<T: std::str::FromStr>(s: &str) -> Option<Vec<T>> {
    s.split_whitespace().map(|t| t.parse().ok()).collect()
}

/// Reads a `.vti` file. Errors: unreadable file ([`Error::Io`]), malformed content or an
/// unsupported variant of the format ([`Error::Format`]).
pub fn read_vti(path: impl AsRef<Path>) -> Result<VtiImage> {
    let path = path.as_ref();
    let bytes = wscg_math::error::read_file(path)?;
    parse_vti(&bytes).map_err(|reason| Error::Format {
        path: path.to_path_buf(),
        reason,
    })
}

/// Parses the bytes of a `.vti` file (see [`read_vti`]).
pub fn parse_vti(bytes: &[u8]) -> std::result::Result<VtiImage, String> {
    // The XML part ends where raw appended data begins (after `<AppendedData ...>` and `_`).
    let xml_end = find(bytes, b"<AppendedData")
        .and_then(|i| find(&bytes[i..], b">").map(|j| i + j + 1))
        .unwrap_or(bytes.len());
    let text = std::str::from_utf8(&bytes[..xml_end]).map_err(|_| "the XML is not UTF-8")?;
    let (root, _) = tag(text, "VTKFile", 0).ok_or("no <VTKFile> element")?;
    if attr(root, "type") != Some("ImageData") {
        return Err(format!("type {:?} is not ImageData", attr(root, "type")));
    }
    if attr(root, "byte_order").is_some_and(|b| b != "LittleEndian") {
        return Err("big-endian files are not supported".into());
    }
    let header64 = match attr(root, "header_type").unwrap_or("UInt32") {
        "UInt32" => false,
        "UInt64" => true,
        h => return Err(format!("header type {h} is not supported")),
    };
    let zlib = match attr(root, "compressor") {
        None => false,
        Some("vtkZLibDataCompressor") => true,
        Some(c) => return Err(format!("compressor {c} is not supported")),
    };
    let (img, _) = tag(text, "ImageData", 0).ok_or("no <ImageData> element")?;
    let ext: Vec<i64> = attr(img, "WholeExtent")
        .and_then(numbers)
        .filter(|v: &Vec<i64>| v.len() == 6)
        .ok_or("missing or malformed WholeExtent")?;
    let spacing: Vec<f64> = attr(img, "Spacing")
        .map_or(Some(vec![1.0; 3]), numbers)
        .filter(|v| v.len() == 3)
        .ok_or("malformed Spacing")?;
    let origin: Vec<f64> = attr(img, "Origin")
        .map_or(Some(vec![0.0; 3]), numbers)
        .filter(|v| v.len() == 3)
        .ok_or("malformed Origin")?;
    let points: [usize; 3] =
        std::array::from_fn(|a| (ext[2 * a + 1] - ext[2 * a] + 1).max(0) as usize);
    // The first array of PointData, else of CellData.
    let section = |name: &str| -> Option<(usize, usize)> {
        let (_, start) = tag(text, name, 0)?;
        let end = text[start..]
            .find(&format!("</{name}>"))
            .map_or(text.len(), |e| e + start);
        Some((start, end))
    };
    let mut found = None;
    for (sec, cells) in [("PointData", false), ("CellData", true)] {
        if let Some((s, e)) = section(sec) {
            if let Some((t, after)) = tag(&text[..e], "DataArray", s) {
                found = Some((t, after, cells));
                break;
            }
        }
    }
    let (arr, arr_end, cells) = found.ok_or("no DataArray in PointData or CellData")?;
    let dims: [usize; 3] = if cells {
        points.map(|p| p.saturating_sub(1).max(1))
    } else {
        points
    };
    let n = dims
        .iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .filter(|&n| n <= MAX_VALUES && n > 0)
        .ok_or("the extent is empty or too large")?;
    if attr(arr, "NumberOfComponents").is_some_and(|c| c != "1") {
        return Err("only one-component arrays are supported".into());
    }
    let ty = attr(arr, "type").ok_or("DataArray without type")?;
    let name = attr(arr, "Name").unwrap_or("").to_string();
    let value_size = match ty {
        "UInt8" | "Int8" => 1,
        "UInt16" | "Int16" => 2,
        "UInt32" | "Int32" | "Float32" => 4,
        "Int64" | "UInt64" | "Float64" => 8,
        t => return Err(format!("array type {t} is not supported")),
    };
    let max_bytes = n * value_size;
    let raw = match attr(arr, "format").unwrap_or("ascii") {
        "binary" => {
            let end = text[arr_end..]
                .find("</DataArray>")
                .ok_or("unterminated DataArray")?
                + arr_end;
            let b64: Vec<u8> = text[arr_end..end]
                .bytes()
                .filter(|c| !c.is_ascii_whitespace())
                .collect();
            decode_base64_blocks(&b64, header64, zlib, max_bytes)?
        }
        "appended" => {
            let off: usize = attr(arr, "offset")
                .and_then(|o| o.trim().parse().ok())
                .ok_or("appended array without offset")?;
            let (ap, _) = tag(text, "AppendedData", 0).ok_or("no AppendedData")?;
            let start =
                find(&bytes[xml_end..], b"_").ok_or("AppendedData without '_'")? + xml_end + 1;
            let data = bytes.get(start + off..).ok_or("offset beyond the file")?;
            match attr(ap, "encoding").unwrap_or("raw") {
                "raw" => decode_raw_blocks(data, header64, zlib, max_bytes)?,
                "base64" => {
                    let b64: Vec<u8> = data
                        .iter()
                        .copied()
                        .take_while(|&c| c != b'<')
                        .filter(|c| !c.is_ascii_whitespace())
                        .collect();
                    decode_base64_blocks(&b64, header64, zlib, max_bytes)?
                }
                e => return Err(format!("appended encoding {e} is not supported")),
            }
        }
        "ascii" => {
            let end = text[arr_end..]
                .find("</DataArray>")
                .ok_or("unterminated DataArray")?
                + arr_end;
            let vals: Vec<f64> = numbers(&text[arr_end..end]).ok_or("malformed ascii values")?;
            if vals.len() < n {
                return Err(format!("{} ascii values for {n} samples", vals.len()));
            }
            vals[..n].iter().flat_map(|v| v.to_le_bytes()).collect()
        }
        f => return Err(format!("array format {f} is not supported")),
    };
    let ty = if matches!(attr(arr, "format"), Some("ascii") | None) {
        "Float64"
    } else {
        ty
    };
    let values = VtiValues::decode(ty, &raw, n).ok_or_else(|| {
        format!(
            "array of type {ty} holds {} bytes, {n} values needed",
            raw.len()
        )
    })?;
    Ok(VtiImage {
        dims,
        spacing: [spacing[0], spacing[1], spacing[2]],
        origin: [origin[0], origin[1], origin[2]],
        name,
        values,
    })
}

fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}

fn read_uints(bytes: &[u8], header64: bool) -> Vec<u64> {
    if header64 {
        bytes
            .chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().expect("8")))
            .collect()
    } else {
        bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().expect("4")) as u64)
            .collect()
    }
}

fn b64(s: &[u8]) -> std::result::Result<Vec<u8>, String> {
    base64::engine::general_purpose::STANDARD
        .decode(s)
        .map_err(|e| format!("bad base64: {e}"))
}

/// Inflates the compressed blocks described by `sizes` from `data`.
fn inflate(
    data: &[u8],
    sizes: &[u64],
    block: u64,
    last: u64,
) -> std::result::Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut pos = 0usize;
    for (i, &cs) in sizes.iter().enumerate() {
        let cs = usize::try_from(cs).map_err(|_| "compressed block size overflows")?;
        let end = pos
            .checked_add(cs)
            .ok_or("compressed block size overflows")?;
        let chunk = data
            .get(pos..end)
            .ok_or("compressed block beyond the data")?;
        let expect = if i + 1 == sizes.len() && last > 0 {
            last
        } else {
            block
        } as usize;
        let mut buf = Vec::with_capacity(expect);
        flate2::read::ZlibDecoder::new(chunk)
            .take(expect as u64 + 1)
            .read_to_end(&mut buf)
            .map_err(|e| format!("zlib: {e}"))?;
        if buf.len() != expect {
            return Err(format!(
                "block {i} inflates to {} bytes, {expect} expected",
                buf.len()
            ));
        }
        out.extend_from_slice(&buf);
        pos = end;
    }
    Ok(out)
}

/// Base64 data: the header and the payload may be encoded separately (VTK's writer) or as one
/// stream.
fn decode_base64_blocks(
    s: &[u8],
    header64: bool,
    zlib: bool,
    max_bytes: usize,
) -> std::result::Result<Vec<u8>, String> {
    let w = if header64 { 8 } else { 4 };
    let enc_len = |bytes: usize| bytes.div_ceil(3) * 4;
    let header_words = if zlib {
        let first = b64(s.get(..enc_len(3 * w)).ok_or("truncated header")?)?;
        block_words(first.get(..3 * w).ok_or("truncated header")?, header64)?
    } else {
        1
    };
    let hlen = enc_len(header_words * w);
    let head_chars = s.get(..hlen).ok_or("truncated header")?;
    let (header, payload) = if head_chars.contains(&b'=') || (header_words * w) % 3 == 0 {
        (b64(head_chars)?, b64(&s[hlen..])?)
    } else {
        let all = b64(s)?;
        let (h, p) = all.split_at((header_words * w).min(all.len()));
        (h.to_vec(), p.to_vec())
    };
    blocks(&header, &payload, header64, zlib, max_bytes)
}

/// Words of a compressed header (`3 + number of blocks`) from its first three words.
fn block_words(first: &[u8], header64: bool) -> std::result::Result<usize, String> {
    let nb = read_uints(first, header64)[0];
    if nb > MAX_BLOCKS {
        return Err(format!("{nb} compressed blocks (at most {MAX_BLOCKS})"));
    }
    Ok(3 + nb as usize)
}

fn decode_raw_blocks(
    data: &[u8],
    header64: bool,
    zlib: bool,
    max_bytes: usize,
) -> std::result::Result<Vec<u8>, String> {
    let w = if header64 { 8 } else { 4 };
    let header_words = if zlib {
        block_words(data.get(..3 * w).ok_or("truncated header")?, header64)?
    } else {
        1
    };
    let hb = header_words * w;
    let header = data.get(..hb).ok_or("truncated header")?;
    blocks(header, &data[hb..], header64, zlib, max_bytes)
}

/// The payload described by a header, at most `max_bytes` long (the array's size).
fn blocks(
    header: &[u8],
    payload: &[u8],
    header64: bool,
    zlib: bool,
    max_bytes: usize,
) -> std::result::Result<Vec<u8>, String> {
    let h = read_uints(header, header64);
    if zlib {
        if h.len() < 3 {
            return Err("truncated block table".into());
        }
        let (nb, block, last) = (h[0] as usize, h[1], h[2]);
        if h.len() < 3 + nb {
            return Err("truncated block table".into());
        }
        // Every block but the last is `block` bytes: the total must fit the array.
        let total = (nb.saturating_sub(1) as u128) * block as u128
            + if last > 0 {
                last as u128
            } else {
                block as u128
            } * (nb > 0) as u128;
        if total > max_bytes as u128 || block > max_bytes as u64 + 1 {
            return Err(format!(
                "the blocks hold {total} bytes, more than the {max_bytes} of the array"
            ));
        }
        inflate(payload, &h[3..3 + nb], block, last)
    } else {
        let n = *h.first().ok_or("missing size header")? as usize;
        payload
            .get(..n)
            .map(<[u8]>::to_vec)
            .ok_or_else(|| "truncated data".into())
    }
}
