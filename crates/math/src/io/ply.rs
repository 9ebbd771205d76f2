//! Stanford PLY meshes (ASCII, binary little and big endian): [`TriMesh::read_ply`] and
//! [`TriMesh::write_ply`], parsed with `ply-rs`. The binary payload is written here because
//! `ply-rs` 0.1.3 writes wrong list lengths in binary files. The element counts announced by a
//! header are checked against the size of the file before reading, so a hostile header cannot
//! make the reader allocate without bound.

use std::io::Write;
use std::path::Path;

use ply_rs::parser::Parser as PlyParser;
use ply_rs::ply::{
    Addable, ElementDef, Encoding, Header, Property, PropertyAccess, PropertyDef, PropertyType,
    ScalarType,
};
use ply_rs::writer::Writer as PlyWriter;

use crate::error::{read_file, Error, Result};
use crate::mesh::TriMesh;

impl TriMesh {
    /// Reads a Stanford PLY file (ASCII, binary little endian or binary big endian).
    ///
    /// - The `vertex` element must have scalar `x`, `y`, `z` properties (any numeric type).
    ///   Optional `nx`, `ny`, `nz` give normals; optional `red`, `green`, `blue` (or
    ///   `diffuse_red`, ...) give colours: `uchar` divided by 255, `ushort` by 65535, `float`
    ///   or `double` taken as `[0, 1]` values.
    /// - The `face` element must have an integer list property `vertex_indices` (or
    ///   `vertex_index`); polygons are split into a fan of triangles around their first corner.
    /// - Other elements and properties are skipped.
    ///
    /// Errors: the file cannot be read ([`Error::Io`]); a malformed header, element counts
    /// that the file is too small to hold, truncated or malformed data, missing `vertex` /
    /// `face` elements or `x`/`y`/`z`/`vertex_indices` properties, an index out of range, a
    /// face with fewer than three corners or a repeated vertex, a non-finite coordinate, a
    /// colour outside `[0, 1]`, or no vertices or no faces ([`Error::Format`] naming the
    /// path).
    pub fn read_ply(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_ply_bytes(&read_file(path)?, path)
    }

    /// [`TriMesh::read_ply`] of a file held in memory; `origin` names the file in errors.
    pub fn from_ply_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        // `ply-rs` is fed only headers that passed `check_ply_header_numbers`; the
        // catch_unwind is a second line of defence against a panic inside the parser.
        let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| parse_ply(bytes)))
            .unwrap_or_else(|_| Err("the PLY parser failed on malformed input".to_string()));
        parsed.map_err(|reason| Error::format(origin, reason))
    }

    /// Writes a Stanford PLY file with the given encoding: a `vertex` element with `double`
    /// `x y z` (and `nx ny nz` with normals, `uchar` `red green blue` with colours, rounded to
    /// the nearest multiple of 1/255), and a `face` element with a `list uchar int
    /// vertex_indices` property.
    ///
    /// Errors: an invalid mesh (see [`TriMesh::validate`]); a mesh without faces
    /// ([`Error::Empty`], as such a file could not be read back); more than `i32::MAX`
    /// vertices ([`Error::LimitExceeded`]); a failed write ([`Error::Io`]).
    pub fn write_ply(&self, path: impl AsRef<Path>, encoding: PlyEncoding) -> Result<()> {
        let path = path.as_ref();
        self.check_writable()?;
        if self.positions.len() > i32::MAX as usize {
            return Err(Error::LimitExceeded(format!(
                "PLY `int` vertex indices hold at most {} vertices, the mesh has {}",
                i32::MAX,
                self.positions.len()
            )));
        }
        super::atomic::write_with(path, |out| {
            self.write_ply_to(out, encoding)
                .map_err(|e| Error::io(path, e))
        })
    }

    fn write_ply_to(&self, out: &mut impl Write, encoding: PlyEncoding) -> std::io::Result<()> {
        let mut header = Header::new();
        header.encoding = match encoding {
            PlyEncoding::Ascii => Encoding::Ascii,
            PlyEncoding::BinaryLittleEndian => Encoding::BinaryLittleEndian,
        };
        header.comments.push("written by wscg-math".to_string());
        let scalar =
            |name: &str, t: ScalarType| PropertyDef::new(name.to_string(), PropertyType::Scalar(t));
        let mut vertex = ElementDef::new("vertex".to_string());
        vertex.count = self.positions.len();
        for name in ["x", "y", "z"] {
            vertex.properties.add(scalar(name, ScalarType::Double));
        }
        if self.normals.is_some() {
            for name in ["nx", "ny", "nz"] {
                vertex.properties.add(scalar(name, ScalarType::Double));
            }
        }
        if self.colors.is_some() {
            for name in ["red", "green", "blue"] {
                vertex.properties.add(scalar(name, ScalarType::UChar));
            }
        }
        header.elements.add(vertex);
        let mut face = ElementDef::new("face".to_string());
        face.count = self.faces.len();
        face.properties.add(PropertyDef::new(
            "vertex_indices".to_string(),
            PropertyType::List(ScalarType::UChar, ScalarType::Int),
        ));
        header.elements.add(face);
        PlyWriter::<PlySkip>::new().write_header(out, &header)?;

        let to_u8 = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
        let normals = self.normals.as_deref();
        let colors = self.colors.as_deref();
        match encoding {
            PlyEncoding::Ascii => {
                for (i, p) in self.positions.iter().enumerate() {
                    write!(out, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
                    if let Some(n) = normals {
                        let n = n[i];
                        write!(out, " {:?} {:?} {:?}", n[0], n[1], n[2])?;
                    }
                    if let Some(c) = colors {
                        let c = c[i];
                        write!(out, " {} {} {}", to_u8(c[0]), to_u8(c[1]), to_u8(c[2]))?;
                    }
                    writeln!(out)?;
                }
                for f in &self.faces {
                    writeln!(out, "3 {} {} {}", f[0], f[1], f[2])?;
                }
            }
            PlyEncoding::BinaryLittleEndian => {
                for (i, p) in self.positions.iter().enumerate() {
                    for v in p {
                        out.write_all(&v.to_le_bytes())?;
                    }
                    if let Some(n) = normals {
                        for v in n[i] {
                            out.write_all(&v.to_le_bytes())?;
                        }
                    }
                    if let Some(c) = colors {
                        let c = c[i];
                        out.write_all(&[to_u8(c[0]), to_u8(c[1]), to_u8(c[2])])?;
                    }
                }
                for f in &self.faces {
                    out.write_all(&[3u8])?;
                    for &i in f {
                        // Fits: the vertex count was checked against i32::MAX.
                        out.write_all(&(i as i32).to_le_bytes())?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Payload encoding of a PLY file written by [`TriMesh::write_ply`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PlyEncoding {
    /// Human-readable text.
    Ascii,
    /// Little-endian binary (compact and fast; the default).
    #[default]
    BinaryLittleEndian,
}

/// Element type for PLY elements we skip (and for the header writer): stores nothing.
struct PlySkip;

impl PropertyAccess for PlySkip {
    fn new() -> Self {
        PlySkip
    }
}

/// Slots of [`PlyVertex::values`].
const PLY_VERTEX_SLOTS: [&[&str]; 9] = [
    &["x"],
    &["y"],
    &["z"],
    &["nx"],
    &["ny"],
    &["nz"],
    &["red", "diffuse_red"],
    &["green", "diffuse_green"],
    &["blue", "diffuse_blue"],
];

/// One PLY vertex: x y z nx ny nz r g b as read (colours not yet scaled).
struct PlyVertex {
    values: [f64; 9],
}

fn scalar_to_f64(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex { values: [0.0; 9] }
    }
    fn set_property(&mut self, name: String, property: Property) {
        if let Some(slot) = PLY_VERTEX_SLOTS
            .iter()
            .position(|names| names.contains(&name.as_str()))
        {
            if let Some(v) = scalar_to_f64(&property) {
                self.values[slot] = v;
            }
        }
    }
}

/// One PLY face: its index list as read.
struct PlyFace {
    indices: Option<Property>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace { indices: None }
    }
    fn set_property(&mut self, name: String, property: Property) {
        if name == "vertex_indices" || name == "vertex_index" {
            self.indices = Some(property);
        }
    }
}

/// Appends the integer list `p` to `out` as `i64`.
fn list_to_i64(p: &Property, out: &mut Vec<i64>) -> std::result::Result<(), String> {
    out.clear();
    match p {
        Property::ListChar(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListUChar(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListShort(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListUShort(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListInt(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        Property::ListUInt(v) => out.extend(v.iter().map(|&x| i64::from(x))),
        _ => return Err("face vertex indices must be a list of integers".to_string()),
    }
    Ok(())
}

fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Checks the header lines of a PLY file (up to `end_header`) before `ply-rs` sees them:
/// the file must start with `ply`, and lines other than comments must not hold numbers of 20
/// or more digits (`ply-rs` 0.1.3 panics when an element count or version overflows `u64`).
fn check_ply_header_numbers(bytes: &[u8]) -> std::result::Result<(), String> {
    if !bytes.starts_with(b"ply") {
        return Err("not a PLY file (it does not start with `ply`)".to_string());
    }
    for line in bytes.split(|&b| b == b'\n') {
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        if line.starts_with(b"end_header") {
            return Ok(());
        }
        if line.starts_with(b"comment") || line.starts_with(b"obj_info") {
            continue;
        }
        let longest_digit_run = line
            .split(|b| !b.is_ascii_digit())
            .map(<[u8]>::len)
            .max()
            .unwrap_or(0);
        if longest_digit_run >= 20 {
            return Err(format!(
                "header line `{}` holds a number too large for this reader",
                String::from_utf8_lossy(&line[..line.len().min(80)])
            ));
        }
    }
    Err("the PLY header has no `end_header` line".to_string())
}

/// Checks that `payload_len` bytes can hold the elements the header announces: every element
/// needs at least its fixed-size part (binary) or two characters per property (ASCII), and at
/// least one byte.
fn check_ply_counts(header: &Header, payload_len: usize) -> std::result::Result<(), String> {
    let mut need = 0usize;
    for (name, e) in &header.elements {
        let per = match header.encoding {
            Encoding::Ascii => 2 * e.properties.len(),
            _ => e
                .properties
                .values()
                .map(|p| match &p.data_type {
                    PropertyType::Scalar(t) => scalar_size(t),
                    PropertyType::List(count_type, _) => scalar_size(count_type),
                })
                .sum(),
        }
        .max(1);
        need = e
            .count
            .checked_mul(per)
            .and_then(|b| need.checked_add(b))
            .ok_or_else(|| format!("the header announces an absurd number of `{name}` elements"))?;
    }
    // An ASCII file may lack the final newline.
    let slack = usize::from(header.encoding == Encoding::Ascii);
    if need > payload_len + slack {
        let counts: Vec<String> = header
            .elements
            .values()
            .map(|e| format!("{} {}", e.count, e.name))
            .collect();
        return Err(format!(
            "the header announces {} needing at least {need} bytes, but only {payload_len} \
             bytes follow the header (truncated file or corrupt header)",
            counts.join(", ")
        ));
    }
    Ok(())
}

/// Scale of a colour property of type `t` to `[0, 1]`.
fn color_scale(t: &PropertyType, name: &str) -> std::result::Result<f64, String> {
    match t {
        PropertyType::Scalar(ScalarType::UChar) => Ok(1.0 / 255.0),
        PropertyType::Scalar(ScalarType::UShort) => Ok(1.0 / 65535.0),
        PropertyType::Scalar(ScalarType::Float | ScalarType::Double) => Ok(1.0),
        other => Err(format!(
            "vertex colour property `{name}` has unsupported type {other:?} (expected uchar, \
             ushort, float or double)"
        )),
    }
}

/// Parses a PLY file held in memory; errors are reasons without the path.
fn parse_ply(bytes: &[u8]) -> std::result::Result<TriMesh, String> {
    check_ply_header_numbers(bytes)?;
    let mut reader: &[u8] = bytes;
    let header = PlyParser::<PlySkip>::new()
        .read_header(&mut reader)
        .map_err(|e| format!("invalid PLY header: {e}"))?;
    check_ply_counts(&header, reader.len())?;

    let vdef = header
        .elements
        .get("vertex")
        .ok_or("the file has no `vertex` element")?;
    for axis in ["x", "y", "z"] {
        match vdef.properties.get(axis) {
            Some(p) if matches!(p.data_type, PropertyType::Scalar(_)) => {}
            Some(_) => return Err(format!("vertex property `{axis}` must be a scalar")),
            None => return Err(format!("the `vertex` element has no `{axis}` property")),
        }
    }
    let has_scalar = |name: &str| {
        matches!(
            vdef.properties.get(name).map(|p| &p.data_type),
            Some(PropertyType::Scalar(_))
        )
    };
    let has_normals = ["nx", "ny", "nz"].iter().all(|n| has_scalar(n));
    let mut color_scales = [0.0f64; 3];
    let mut has_colors = true;
    for (k, slot) in PLY_VERTEX_SLOTS[6..].iter().enumerate() {
        match slot.iter().find_map(|n| vdef.properties.get(*n)) {
            Some(p) => color_scales[k] = color_scale(&p.data_type, &p.name)?,
            None => has_colors = false,
        }
    }
    let fdef = header
        .elements
        .get("face")
        .ok_or("the file has no `face` element")?;
    match ["vertex_indices", "vertex_index"]
        .iter()
        .find_map(|n| fdef.properties.get(*n))
    {
        Some(p) if matches!(p.data_type, PropertyType::List(..)) => {}
        Some(p) => return Err(format!("face property `{}` must be a list", p.name)),
        None => return Err("the `face` element has no `vertex_indices` list property".to_string()),
    }
    if vdef.count == 0 {
        return Err("the file has no vertices".to_string());
    }
    if fdef.count == 0 {
        return Err("the file has no faces".to_string());
    }
    if vdef.count > u32::MAX as usize {
        return Err(format!("more than {} vertices", u32::MAX));
    }

    let mut vertices: Vec<PlyVertex> = Vec::new();
    let mut raw_faces: Vec<PlyFace> = Vec::new();
    for (name, def) in &header.elements {
        let what = |e: std::io::Error| format!("cannot read the `{name}` elements: {e}");
        match name.as_str() {
            "vertex" => {
                vertices = PlyParser::<PlyVertex>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(what)?;
            }
            "face" => {
                raw_faces = PlyParser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(what)?;
            }
            _ => {
                PlyParser::<PlySkip>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(what)?;
            }
        }
    }

    let nv = vertices.len();
    let positions: Vec<[f64; 3]> = vertices
        .iter()
        .map(|v| [v.values[0], v.values[1], v.values[2]])
        .collect();
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(raw_faces.len());
    let mut list: Vec<i64> = Vec::new();
    for (k, f) in raw_faces.iter().enumerate() {
        let p = f
            .indices
            .as_ref()
            .ok_or_else(|| format!("face {k} has no vertex indices"))?;
        list_to_i64(p, &mut list)?;
        if list.len() < 3 {
            return Err(format!(
                "face {k} has {} vertices; a face needs at least 3",
                list.len()
            ));
        }
        if let Some(&i) = list.iter().find(|&&i| i < 0 || i >= nv as i64) {
            return Err(format!(
                "face {k} refers to vertex {i}, but the file has {nv} vertices"
            ));
        }
        let a = list[0] as u32;
        for w in list[1..].windows(2) {
            faces.push([a, w[0] as u32, w[1] as u32]);
        }
    }

    let mut mesh = TriMesh::new(positions, faces).map_err(|e| e.to_string())?;
    if has_normals {
        let normals = vertices
            .iter()
            .map(|v| [v.values[3], v.values[4], v.values[5]])
            .collect();
        mesh = mesh.with_normals(normals).map_err(|e| e.to_string())?;
    }
    if has_colors {
        let colors = vertices
            .iter()
            .map(|v| {
                let c = |k: usize| (v.values[6 + k] * color_scales[k]) as f32;
                [c(0), c(1), c(2)]
            })
            .collect();
        mesh = mesh.with_colors(colors).map_err(|e| e.to_string())?;
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_files::colors_for;

    fn assert_positions_eq(a: &[[f64; 3]], b: &[[f64; 3]]) {
        assert_eq!(a.len(), b.len());
        for (p, q) in a.iter().zip(b) {
            assert_eq!(p, q);
        }
    }

    #[test]
    fn ply_round_trip_ascii_and_binary() {
        let dir = tempfile::tempdir().unwrap();
        let mut m = TriMesh::icosphere(2, 0.9).unwrap();
        let n = m.num_vertices();
        m = m.with_colors(colors_for(n)).unwrap();
        m.compute_vertex_normals();
        for enc in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let path = dir.path().join(format!("sphere_{enc:?}.ply"));
            m.write_ply(&path, enc).unwrap();
            let back = TriMesh::read_ply(&path).unwrap();
            assert_positions_eq(&back.positions, &m.positions);
            assert_eq!(back.faces, m.faces);
            assert_eq!(back.normals, m.normals);
            let (c0, c1) = (m.colors.as_ref().unwrap(), back.colors.as_ref().unwrap());
            for (a, b) in c0.iter().zip(c1) {
                for k in 0..3 {
                    assert!((a[k] - b[k]).abs() <= 0.5 / 255.0 + 1e-6, "{a:?} {b:?}");
                }
            }
        }
        // Default write is binary; no normals or colours round trip as None.
        let plain = TriMesh::grid(3, 2, 1.0, 1.0).unwrap();
        let path = dir.path().join("grid.ply");
        plain.write(&path).unwrap();
        assert!(std::fs::read(&path)
            .unwrap()
            .windows(20)
            .any(|w| w == b"binary_little_endian"));
        assert_eq!(TriMesh::read(&path).unwrap(), plain);
    }

    #[test]
    fn ply_reader_handles_quads_floats_and_extra_elements() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("quad.ply");
        let text = "ply\n\
                    format ascii 1.0\n\
                    comment made by hand\n\
                    element vertex 4\n\
                    property float x\nproperty float y\nproperty float z\n\
                    property uchar red\nproperty uchar green\nproperty uchar blue\n\
                    property uchar alpha\n\
                    element face 1\n\
                    property list uchar uint vertex_index\n\
                    element edge 1\n\
                    property int vertex1\nproperty int vertex2\n\
                    end_header\n\
                    0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n0 1 0 51 51 51 255\n\
                    4 0 1 2 3\n\
                    0 1";
        std::fs::write(&path, text).unwrap();
        let m = TriMesh::read_ply(&path).unwrap();
        assert_eq!(m.positions[2], [1.0, 1.0, 0.0]);
        assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals, None);
        let c = m.colors.unwrap();
        assert_eq!(c[0], [1.0, 0.0, 0.0]);
        assert!((c[3][1] - 0.2).abs() < 1e-7);
    }

    #[test]
    fn ply_reader_reads_big_endian_binary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("be.ply");
        let mut bytes = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\n\
            property float x\nproperty float y\nproperty float z\n\
            property float nx\nproperty float ny\nproperty float nz\n\
            element face 1\nproperty list uchar short vertex_indices\nend_header\n"
            .to_vec();
        for p in [[0.0f32, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
            for v in p.iter().chain(&[0.0, 0.0, 1.0]) {
                bytes.extend_from_slice(&v.to_be_bytes());
            }
        }
        bytes.push(3);
        for i in [0i16, 1, 2] {
            bytes.extend_from_slice(&i.to_be_bytes());
        }
        std::fs::write(&path, &bytes).unwrap();
        let m = TriMesh::read(&path).unwrap();
        assert_eq!(
            m.positions,
            vec![[0.0; 3], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]
        );
        assert_eq!(m.faces, vec![[0, 1, 2]]);
        assert_eq!(m.normals, Some(vec![[0.0, 0.0, 1.0]; 3]));
        assert_eq!(m.colors, None);
        assert_eq!(m.total_area(), 2.0);
    }

    #[test]
    fn ply_reader_rejects_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        let m = TriMesh::icosphere(1, 1.0)
            .unwrap()
            .with_colors(colors_for(42))
            .unwrap();
        for enc in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let full = dir.path().join("full.ply");
            m.write_ply(&full, enc).unwrap();
            let bytes = std::fs::read(&full).unwrap();
            // Every truncation (in steps) fails cleanly with an error naming the path.
            let cut = dir.path().join("cut.ply");
            for len in (0..bytes.len() - 1).step_by(7) {
                std::fs::write(&cut, &bytes[..len]).unwrap();
                match TriMesh::read_ply(&cut) {
                    Err(Error::Format { path, .. }) => assert_eq!(path, cut),
                    other => panic!("{enc:?} truncated at {len}: {other:?}"),
                }
            }
            // Flipped bytes never panic.
            let mut s = 1u64;
            for _ in 0..200 {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let mut b = bytes.clone();
                let k = (s >> 33) as usize % b.len();
                b[k] ^= (s >> 20) as u8 | 1;
                std::fs::write(&cut, &b).unwrap();
                let _ = TriMesh::read_ply(&cut);
            }
        }
        let header =
            |body: &str| format!("ply\nformat binary_little_endian 1.0\n{body}end_header\n");
        let cases: Vec<(&str, Vec<u8>)> =
            vec![
            // A hostile header announcing 10^12 vertices in a ~200-byte file.
            (
                "huge_count",
                header(
                    "element vertex 1000000000000\nproperty double x\nproperty double y\n\
                     property double z\nelement face 1\nproperty list uchar int vertex_indices\n",
                )
                .into_bytes(),
            ),
            // Elements without properties take no bytes each.
            (
                "empty_elements",
                header("element junk 1000000000000000\n").into_bytes(),
            ),
            // A count that overflows u64 (ply-rs itself would panic on it).
            (
                "overflow",
                header("element vertex 123456789012345678901234567890\nproperty float x\n")
                    .into_bytes(),
            ),
            ("garbage", (0..300u32).map(|i| (i * 7919 % 251) as u8).collect()),
            ("not_ply", b"hello world\n".to_vec()),
            ("no_end_header", b"ply\nformat ascii 1.0\nelement vertex 3\n".to_vec()),
            (
                "no_faces",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 0\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0 0\n1 0 0\n0 1 0\n"
                    .to_vec(),
            ),
            (
                "no_face_element",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                    .to_vec(),
            ),
            (
                "index_out_of_range",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"
                    .to_vec(),
            ),
            (
                "negative_index",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"
                    .to_vec(),
            ),
            (
                "missing_z",
                b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  element face 1\nproperty list uchar int vertex_indices\n\
                  end_header\n0 0\n1 0\n0 1\n3 0 1 2\n"
                    .to_vec(),
            ),
        ];
        for (name, bytes) in cases {
            let path = dir.path().join(format!("{name}.ply"));
            std::fs::write(&path, &bytes).unwrap();
            let start = std::time::Instant::now();
            let e = TriMesh::read_ply(&path).unwrap_err();
            assert!(matches!(e, Error::Format { .. }), "{name}: {e}");
            assert!(start.elapsed().as_secs_f64() < 5.0, "{name} took too long");
        }
        let e = TriMesh::read_ply(dir.path().join("missing.ply")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
    }
}
