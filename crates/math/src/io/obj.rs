//! Wavefront OBJ meshes and their MTL material libraries: the one OBJ reader of the
//! workspace.
//!
//! - [`ObjFile`] holds what the readers use from an OBJ file: the vertices (`v x y z
//!   [w | r g b]`, `vn`), the faces (`f` with `v`, `v/t`, `v//n`, `v/t/n` corners, negative =
//!   relative indices), triangulated as fans around their first corner, with each triangle's
//!   material (`usemtl`) and group or object (`g`, `o`), and the material libraries the file
//!   names (`mtllib`). [`TriMesh::read_obj`] builds a mesh from it, the many-light renderer of
//!   `wscg-raytrace` a scene (with [`ObjFile::read_materials`]).
//! - [`read_mtl`] / [`parse_mtl`] read the statements of an MTL library that the renderers
//!   use: `newmtl`, the diffuse colour `Kd` and the emitted radiance `Ke` (one number for a
//!   grey, or three); every other statement is ignored.
//!
//! Texture coordinates, smoothing groups, points, lines and every other statement are
//! ignored. Errors name the file and the line. Bytes that are not UTF-8 (a Latin-1 comment,
//! common in files from the field) are read as U+FFFD, so they only matter inside a
//! statement, where they make the statement's number or index invalid. Files are read whole
//! with [`read_file`] (regular files only, at most the memory limit), so an `mtllib` naming a
//! device or a FIFO is refused rather than read forever.
//!
//! The reader is a small one written here rather than the `tobj` crate: `tobj` 4 (without its
//! `use_f64` feature) parses coordinates as `f32`, renumbers vertices in order of first use,
//! drops vertices no face uses, and duplicates the vertices shared between `g`/`o` groups
//! (which opens closed meshes). This reader keeps the file's vertices, their order and their
//! `f64` values.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{read_file, Error, Result};
use crate::mesh::TriMesh;

impl TriMesh {
    /// Reads a Wavefront OBJ file (through [`ObjFile::read`]).
    ///
    /// - `v x y z`, `v x y z w` (divided by `w`) or `v x y z r g b` lines give the vertices in
    ///   file order. Colours are kept when every vertex has one; they are taken as `[0, 1]`
    ///   values, or as `0..=255` values (divided by 255) when any component exceeds 1.
    /// - `f` lines with three or more corners (`v`, `v/t`, `v//n` or `v/t/n`; 1-based, or
    ///   negative for relative to the latest vertex) give the faces; polygons are split into a
    ///   fan of triangles around their first corner.
    /// - Normals (`vn`) are kept when they are per vertex: every vertex's corners all name the
    ///   same normal (vertices no face uses get the zero vector), or no corner names one and
    ///   there are exactly as many `vn` as `v` lines. Per-corner normals are dropped.
    /// - Groups, objects, materials (`g`, `o`, `usemtl`, `mtllib`) are read by [`ObjFile`]
    ///   but not used by the mesh; everything else (`vt`, `s`, `l`, `p`, comments...) is
    ///   ignored; no other file is opened.
    ///
    /// Errors: the file cannot be read ([`Error::Io`]); a malformed number or index, an index
    /// of 0 or out of range, a face with fewer than three corners or a repeated vertex, a
    /// non-finite coordinate, colours on only some vertices, or no vertices or no faces
    /// ([`Error::Format`] naming the path, and the line for a statement).
    pub fn read_obj(path: impl AsRef<Path>) -> Result<Self> {
        ObjFile::read(path)?.into_mesh()
    }

    /// [`TriMesh::read_obj`] of a file held in memory; `origin` names the file in errors.
    pub fn from_obj_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        ObjFile::parse(bytes, origin)?.into_mesh()
    }

    /// Writes a Wavefront OBJ file: `v x y z` lines (followed by ` r g b` when the mesh has
    /// colours), `vn` lines when it has normals, then `f a b c` lines (`f a//a b//b c//c`
    /// with normals) with 1-based indices. Numbers are written in Rust's shortest round-trip
    /// form, so [`TriMesh::read_obj`] gives back the same `f64` positions and normals and the
    /// same `f32` colours.
    ///
    /// Errors: an invalid mesh (see [`TriMesh::validate`]); a mesh without faces
    /// ([`Error::Empty`], as such a file could not be read back); a failed write
    /// ([`Error::Io`]).
    pub fn write_obj(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        self.check_writable()?;
        super::atomic::write_with(path, |out| {
            self.write_obj_to(out).map_err(|e| Error::io(path, e))
        })
    }

    fn write_obj_to(&self, out: &mut impl Write) -> std::io::Result<()> {
        writeln!(out, "# written by wscg-math")?;
        writeln!(
            out,
            "# {} vertices, {} faces",
            self.positions.len(),
            self.faces.len()
        )?;
        match &self.colors {
            Some(colors) => {
                for (p, c) in self.positions.iter().zip(colors) {
                    writeln!(
                        out,
                        "v {:?} {:?} {:?} {:?} {:?} {:?}",
                        p[0], p[1], p[2], c[0], c[1], c[2]
                    )?;
                }
            }
            None => {
                for p in &self.positions {
                    writeln!(out, "v {:?} {:?} {:?}", p[0], p[1], p[2])?;
                }
            }
        }
        if let Some(normals) = &self.normals {
            for n in normals {
                writeln!(out, "vn {:?} {:?} {:?}", n[0], n[1], n[2])?;
            }
            for f in &self.faces {
                let (a, b, c) = (f[0] + 1, f[1] + 1, f[2] + 1);
                writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")?;
            }
        } else {
            for f in &self.faces {
                writeln!(out, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?;
            }
        }
        Ok(())
    }
}

/// What the readers of the workspace use from a Wavefront OBJ file (see the
/// [module documentation](self)): vertices in file order, faces as triangles (fans around
/// each polygon's first corner, in file order), and for each triangle its material and group.
///
/// Every face index is checked against the vertices and normals of the file; whether a
/// triangle repeats a vertex or has zero area is left to the user ([`TriMesh::new`] refuses
/// it, the many-light renderer skips and counts it).
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct ObjFile {
    /// The file the content was read from (the `origin` of [`ObjFile::parse`]).
    pub path: PathBuf,
    /// Vertex positions (`v`, divided by `w` when given), in file order.
    pub positions: Vec<[f64; 3]>,
    /// Vertex colours in `[0, 1]` (`v x y z r g b`; all divided by 255 when any component
    /// exceeds 1), when every vertex has one.
    pub colors: Option<Vec<[f32; 3]>>,
    /// Per-vertex normals, when the file's `vn` are per vertex (see [`TriMesh::read_obj`]).
    pub normals: Option<Vec<[f64; 3]>>,
    /// The triangles (0-based vertex indices).
    pub triangles: Vec<[u32; 3]>,
    /// Each triangle's material: an index into [`ObjFile::materials`], `None` before the
    /// first `usemtl` (or after a `usemtl` without a name).
    pub triangle_materials: Vec<Option<u32>>,
    /// The material names of the `usemtl` statements, in order of first use.
    pub materials: Vec<String>,
    /// Each triangle's group: an index into [`ObjFile::groups`], `None` before the first `g`
    /// or `o`.
    pub triangle_groups: Vec<Option<u32>>,
    /// The names of the `o` and `g` statements (the names of a `g` with several joined by a
    /// space), in order of first use.
    pub groups: Vec<String>,
    /// The material libraries named by `mtllib` statements (relative to the file's folder),
    /// in file order.
    pub mtllibs: Vec<String>,
    /// How many vertices have a colour (all or none for a mesh).
    colored: usize,
}

/// The statements of an MTL material that the renderers use.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct MtlMaterial {
    /// The name given by `newmtl`.
    pub name: String,
    /// The diffuse colour `Kd` (one number `g` is the grey `[g, g, g]`), unchecked.
    pub diffuse: Option<[f64; 3]>,
    /// The emitted radiance `Ke`, unchecked.
    pub emission: Option<[f64; 3]>,
    /// The library the material comes from (the `origin` of [`parse_mtl`]).
    pub library: PathBuf,
    /// The line of its `newmtl` statement.
    pub line: usize,
}

impl ObjFile {
    /// Reads and parses an OBJ file (regular files only, see [`read_file`]); no other file is
    /// opened.
    ///
    /// Errors: [`Error::Io`] when the file cannot be read; [`Error::Format`] naming the file
    /// (and the line, for a statement) for a malformed statement (a number or index that does
    /// not parse, an index of 0 or out of range, a face of fewer than three corners, a
    /// non-finite coordinate, a zero weight), a file without vertices or faces, or a face
    /// naming a normal that the file does not have.
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::parse(&read_file(path)?, path)
    }

    /// [`ObjFile::read`] of a file held in memory; `origin` names the file in errors.
    pub fn parse(bytes: &[u8], origin: &Path) -> Result<Self> {
        parse_obj(&String::from_utf8_lossy(bytes), origin)
            .map_err(|reason| Error::format(origin, reason))
    }

    /// Reads the material libraries of [`ObjFile::mtllibs`], relative to the folder of
    /// [`ObjFile::path`], with [`read_mtl`]: their materials in library and file order.
    ///
    /// Errors: those of [`read_mtl`], naming the library (a missing library is an
    /// [`Error::Io`]; a device, FIFO or folder is refused as not a regular file).
    pub fn read_materials(&self) -> Result<Vec<MtlMaterial>> {
        let dir = self.path.parent().unwrap_or_else(|| Path::new(""));
        let mut out = Vec::new();
        for name in &self.mtllibs {
            out.extend(read_mtl(dir.join(name))?);
        }
        Ok(out)
    }

    /// The mesh of the file: its vertices, triangles, and the colours and per-vertex normals
    /// when present.
    ///
    /// Errors ([`Error::Format`] naming the file): colours on only some vertices; a triangle
    /// that repeats a vertex or a non-finite coordinate (the reason of [`TriMesh::new`]).
    pub fn into_mesh(self) -> Result<TriMesh> {
        let path = self.path;
        let bad = |reason: String| Error::format(&path, reason);
        let nv = self.positions.len();
        if self.colored != 0 && self.colored != nv {
            return Err(bad(format!(
                "only {} of the {nv} vertices have a colour",
                self.colored
            )));
        }
        let mut mesh =
            TriMesh::new(self.positions, self.triangles).map_err(|e| bad(e.to_string()))?;
        if let Some(n) = self.normals {
            mesh = mesh.with_normals(n).map_err(|e| bad(e.to_string()))?;
        }
        if let Some(c) = self.colors {
            mesh = mesh.with_colors(c).map_err(|e| bad(e.to_string()))?;
        }
        Ok(mesh)
    }
}

/// Reads an MTL material library (regular files only, see [`read_file`]) with [`parse_mtl`].
pub fn read_mtl(path: impl AsRef<Path>) -> Result<Vec<MtlMaterial>> {
    let path = path.as_ref();
    parse_mtl(&read_file(path)?, path)
}

/// The materials of an MTL library held in memory, in file order; `origin` names the file in
/// errors. `newmtl`, `Kd` and `Ke` are read; every other statement is ignored.
///
/// Errors ([`Error::Format`] naming the file and the line): a `newmtl` without a name; a `Kd`
/// or `Ke` outside a material, of other than one or three numbers, or with a number that does
/// not parse.
pub fn parse_mtl(bytes: &[u8], origin: &Path) -> Result<Vec<MtlMaterial>> {
    let text = String::from_utf8_lossy(bytes);
    let mut materials: Vec<MtlMaterial> = Vec::new();
    for_each_statement(&text, |line, keyword, words| {
        match keyword {
            "newmtl" => {
                let name = words.collect::<Vec<_>>().join(" ");
                if name.is_empty() {
                    return Err(format!("line {line}: `newmtl` names no material"));
                }
                materials.push(MtlMaterial {
                    name,
                    diffuse: None,
                    emission: None,
                    library: origin.to_path_buf(),
                    line,
                });
            }
            "Kd" | "Ke" => {
                let vals = words
                    .map(|w| parse_f64(w, line))
                    .collect::<std::result::Result<Vec<f64>, String>>()?;
                let rgb = match vals[..] {
                    [g] => [g; 3],
                    [r, g, b] => [r, g, b],
                    _ => {
                        return Err(format!(
                            "line {line}: `{keyword}` needs 1 or 3 numbers, found {}",
                            vals.len()
                        ))
                    }
                };
                let Some(m) = materials.last_mut() else {
                    return Err(format!("line {line}: `{keyword}` before any `newmtl`"));
                };
                if keyword == "Kd" {
                    m.diffuse = Some(rgb);
                } else {
                    m.emission = Some(rgb);
                }
            }
            _ => {}
        }
        Ok(())
    })
    .map_err(|reason| Error::format(origin, reason))?;
    Ok(materials)
}

/// Calls `f(line, keyword, words)` for each statement of OBJ or MTL text: lines ending in a
/// backslash are joined to the next, `#` starts a comment, blank lines are skipped; `line` is
/// the 1-based number of the statement's first line.
fn for_each_statement(
    text: &str,
    mut f: impl FnMut(usize, &str, &mut dyn Iterator<Item = &str>) -> std::result::Result<(), String>,
) -> std::result::Result<(), String> {
    let mut joined = String::new();
    let mut line_no = 0usize;
    let mut lines = text.lines();
    while let Some(first) = lines.next() {
        line_no += 1;
        let start_line = line_no;
        joined.clear();
        joined.push_str(first);
        while joined.ends_with('\\') {
            joined.pop();
            joined.push(' ');
            match lines.next() {
                Some(next) => {
                    line_no += 1;
                    joined.push_str(next);
                }
                None => break,
            }
        }
        let content = match joined.find('#') {
            Some(k) => &joined[..k],
            None => &joined[..],
        };
        let mut words = content.split_whitespace();
        if let Some(keyword) = words.next() {
            f(start_line, keyword, &mut words)?;
        }
    }
    Ok(())
}

/// Resolves a 1-based or negative (relative to `count` items so far) OBJ index to 0-based.
/// Positive indices are checked against the final count after the whole file is read.
fn obj_index(tok: &str, count: usize, what: &str, line: usize) -> std::result::Result<u32, String> {
    let i: i64 = tok
        .parse()
        .map_err(|_| format!("line {line}: `{tok}` is not a valid {what} index"))?;
    let r = match i {
        0 => {
            return Err(format!(
                "line {line}: {what} index 0 is invalid (OBJ indices start at 1)"
            ))
        }
        i if i > 0 => i - 1,
        i => count as i64 + i,
    };
    if r < 0 || r >= i64::from(u32::MAX) {
        return Err(format!(
            "line {line}: {what} index {i} is out of range ({count} defined so far)"
        ));
    }
    Ok(r as u32)
}

fn parse_f64(tok: &str, line: usize) -> std::result::Result<f64, String> {
    tok.parse()
        .map_err(|_| format!("line {line}: `{tok}` is not a number"))
}

/// The index of `name` in `names`, added if new.
fn intern(names: &mut Vec<String>, name: String) -> std::result::Result<u32, String> {
    let k = match names.iter().position(|n| *n == name) {
        Some(k) => k,
        None => {
            names.push(name);
            names.len() - 1
        }
    };
    u32::try_from(k).map_err(|_| format!("more than {} names", u32::MAX))
}

/// The largest index of a kind the faces name, with the line naming it first.
#[derive(Default)]
struct MaxIndex(Option<(u32, usize)>);

impl MaxIndex {
    fn see(&mut self, index: u32, line: usize) {
        if self.0.is_none_or(|(m, _)| index > m) {
            self.0 = Some((index, line));
        }
    }

    fn check(&self, count: usize, what: &str) -> std::result::Result<(), String> {
        match self.0 {
            Some((m, line)) if m as usize >= count => Err(format!(
                "line {line}: {what} index {} is out of range (the file has {count})",
                u64::from(m) + 1
            )),
            _ => Ok(()),
        }
    }
}

/// Parses OBJ text; errors are reasons without the path.
fn parse_obj(text: &str, origin: &Path) -> std::result::Result<ObjFile, String> {
    let mut obj = ObjFile {
        path: origin.to_path_buf(),
        ..ObjFile::default()
    };
    let mut colors: Vec<[f32; 3]> = Vec::new(); // aligned with positions, zero when absent
    let mut normals: Vec<[f64; 3]> = Vec::new();
    // (vertex, normal) for every face corner that names a normal.
    let mut corner_normals: Vec<(u32, u32)> = Vec::new();
    let mut corner_without_normal = false;
    let mut corners: Vec<(u32, Option<u32>)> = Vec::new();
    let (mut max_vertex, mut max_normal) = (MaxIndex::default(), MaxIndex::default());
    let (mut material, mut group): (Option<u32>, Option<u32>) = (None, None);

    for_each_statement(text, |line, keyword, words| {
        match keyword {
            "v" => {
                let toks: Vec<&str> = words.collect();
                let xyz = |k: usize| parse_f64(toks[k], line);
                let (p, c) = match toks.len() {
                    3 => ([xyz(0)?, xyz(1)?, xyz(2)?], None),
                    4 => {
                        let w = xyz(3)?;
                        if w == 0.0 || !w.is_finite() {
                            return Err(format!("line {line}: vertex weight w = {w} is invalid"));
                        }
                        ([xyz(0)? / w, xyz(1)? / w, xyz(2)? / w], None)
                    }
                    6 => {
                        // Colours parse directly as f32, so written f32 values come back exactly.
                        let rgb = |k: usize| {
                            toks[k]
                                .parse::<f32>()
                                .map_err(|_| format!("line {line}: `{}` is not a number", toks[k]))
                        };
                        (
                            [xyz(0)?, xyz(1)?, xyz(2)?],
                            Some([rgb(3)?, rgb(4)?, rgb(5)?]),
                        )
                    }
                    n => {
                        return Err(format!(
                            "line {line}: a `v` line needs 3, 4 (x y z w) or 6 (x y z r g b) \
                             numbers, found {n}"
                        ))
                    }
                };
                if let Some(bad) = p.iter().find(|x| !x.is_finite()) {
                    return Err(format!(
                        "line {line}: vertex coordinate {bad} is not finite"
                    ));
                }
                if obj.positions.len() >= u32::MAX as usize {
                    return Err(format!("line {line}: more than {} vertices", u32::MAX));
                }
                obj.positions.push(p);
                match c {
                    Some(c) => {
                        colors.push(c);
                        obj.colored += 1;
                    }
                    None => colors.push([0.0; 3]),
                }
            }
            "vn" => {
                let vals = words
                    .map(|w| parse_f64(w, line))
                    .collect::<std::result::Result<Vec<f64>, String>>()?;
                if vals.len() != 3 {
                    return Err(format!(
                        "line {line}: a `vn` line needs 3 numbers, found {}",
                        vals.len()
                    ));
                }
                normals.push([vals[0], vals[1], vals[2]]);
            }
            "f" => {
                corners.clear();
                for w in words {
                    let mut parts = w.split('/');
                    let v = obj_index(
                        parts.next().unwrap_or(""),
                        obj.positions.len(),
                        "vertex",
                        line,
                    )?;
                    max_vertex.see(v, line);
                    let _texcoord = parts.next();
                    let n = match parts.next() {
                        Some(s) if !s.is_empty() => {
                            let n = obj_index(s, normals.len(), "normal", line)?;
                            max_normal.see(n, line);
                            Some(n)
                        }
                        _ => None,
                    };
                    if parts.next().is_some() {
                        return Err(format!("line {line}: malformed face corner `{w}`"));
                    }
                    corners.push((v, n));
                }
                if corners.len() < 3 {
                    return Err(format!(
                        "line {line}: a face needs at least 3 vertices, found {}",
                        corners.len()
                    ));
                }
                for &(v, n) in &corners {
                    match n {
                        Some(n) => corner_normals.push((v, n)),
                        None => corner_without_normal = true,
                    }
                }
                let a = corners[0].0;
                for k in 1..corners.len() - 1 {
                    obj.triangles.push([a, corners[k].0, corners[k + 1].0]);
                    obj.triangle_materials.push(material);
                    obj.triangle_groups.push(group);
                }
            }
            "usemtl" => {
                let name = words.collect::<Vec<_>>().join(" ");
                material = if name.is_empty() {
                    None
                } else {
                    Some(intern(&mut obj.materials, name)?)
                };
            }
            "o" | "g" => {
                let name = words.collect::<Vec<_>>().join(" ");
                group = Some(intern(&mut obj.groups, name)?);
            }
            "mtllib" => obj.mtllibs.extend(words.map(str::to_string)),
            _ => {}
        }
        Ok(())
    })?;

    if obj.positions.is_empty() {
        return Err("the file has no vertices (`v` lines)".to_string());
    }
    if obj.triangles.is_empty() {
        return Err("the file has no faces (`f` lines)".to_string());
    }
    max_vertex.check(obj.positions.len(), "vertex")?;
    max_normal.check(normals.len(), "normal")?;
    let nv = obj.positions.len();

    obj.normals = if !corner_normals.is_empty() && !corner_without_normal {
        const NONE: u32 = u32::MAX;
        let mut slot = vec![NONE; nv];
        let mut per_vertex = true;
        for &(v, n) in &corner_normals {
            let s = &mut slot[v as usize];
            if *s == NONE {
                *s = n;
            } else if *s != n && normals[*s as usize] != normals[n as usize] {
                per_vertex = false;
                break;
            }
        }
        per_vertex.then(|| {
            slot.iter()
                .map(|&s| {
                    if s == NONE {
                        [0.0; 3]
                    } else {
                        normals[s as usize]
                    }
                })
                .collect::<Vec<_>>()
        })
    } else if corner_normals.is_empty() && normals.len() == nv {
        Some(normals)
    } else {
        None
    };

    if obj.colored == nv {
        if colors.as_flattened().iter().any(|&c| c > 1.0) {
            for c in colors.as_flattened_mut() {
                *c /= 255.0;
            }
        }
        obj.colors = Some(colors);
    }
    Ok(obj)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::test_files::colors_for;

    #[test]
    fn obj_round_trip_preserves_everything() {
        let dir = tempfile::tempdir().unwrap();
        let mut m = TriMesh::icosphere(2, 1.3).unwrap();
        let n = m.num_vertices();
        m = m.with_colors(colors_for(n)).unwrap();
        m.compute_vertex_normals();
        let path = dir.path().join("sphere.obj");
        m.write_obj(&path).unwrap();
        let back = TriMesh::read_obj(&path).unwrap();
        assert_eq!(back, m);
        // Through the dispatcher, without normals or colours.
        let plain = TriMesh::cube(3.0).unwrap();
        let path = dir.path().join("cube.OBJ");
        plain.write(&path).unwrap();
        assert_eq!(TriMesh::read(&path).unwrap(), plain);
    }

    #[test]
    fn obj_reader_handles_polygons_relative_indices_groups_and_normals() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("quad.obj");
        let text = "# a unit square as one quad\n\
                    mtllib nothing.mtl\n\
                    o square\n\
                    v 0 0 0\nv 1 0 0\nv 1 1 0\r\nv 0 1 0\n\
                    vt 0 0\n\
                    vn 0 0 1\n\
                    g half\n\
                    usemtl none\n\
                    f -4/1/1 -3/1/1 \\\n  -2/1/1 -1/1/1 # trailing comment\n";
        std::fs::write(&path, text).unwrap();
        let m = TriMesh::read_obj(&path).unwrap();
        assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals, Some(vec![[0.0, 0.0, 1.0]; 4]));
        assert!((m.total_area() - 1.0).abs() < 1e-15);

        // A cube split over groups stays one closed mesh with shared vertices.
        let cube = TriMesh::cube(1.0).unwrap();
        let mut s = String::new();
        for p in &cube.positions {
            s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        for (k, f) in cube.faces.iter().enumerate() {
            s += &format!(
                "g side{}\nf {} {} {}\n",
                k / 2,
                f[0] + 1,
                f[1] + 1,
                f[2] + 1
            );
        }
        std::fs::write(&path, s).unwrap();
        let back = TriMesh::read_obj(&path).unwrap();
        assert_eq!(back, cube);
        assert!(back.is_closed());

        // 0-255 vertex colours are scaled; per-corner normals are dropped.
        std::fs::write(
            &path,
            "v 0 0 0 255 0 0\nv 1 0 0 0 255 0\nv 0 1 0 0 0 51\nv 1 1 0 0 0 0\n\
             vn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//1\nf 2//2 4//2 3//2\n",
        )
        .unwrap();
        let m = TriMesh::read_obj(&path).unwrap();
        assert_eq!(
            m.colors,
            Some(vec![
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 0.2],
                [0.0, 0.0, 0.0]
            ])
        );
        assert_eq!(m.normals, None);
        // Consistent per-vertex normal indices are kept; unused vertices get zero normals.
        std::fs::write(
            &path,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 9 9 9\nvn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//2\n",
        )
        .unwrap();
        let m = TriMesh::read_obj(&path).unwrap();
        assert_eq!(
            m.normals,
            Some(vec![
                [0.0, 0.0, 1.0],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, -1.0],
                [0.0; 3]
            ])
        );
    }

    #[test]
    fn obj_reader_rejects_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        let cases: &[(&str, &str)] = &[
            ("out_of_range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
            ("zero_index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
            (
                "relative_too_far",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
            ),
            ("repeated", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n"),
            ("two_corners", "v 0 0 0\nv 1 0 0\nf 1 2\n"),
            ("bad_number", "v 0 zero 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("non_finite", "v 0 inf 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("no_faces", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
            ("no_vertices", "# nothing\n"),
            ("empty", ""),
            ("some_colours", "v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            (
                "bad_normal",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n",
            ),
            ("w_zero", "v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
        ];
        for (name, text) in cases {
            let path = dir.path().join(format!("{name}.obj"));
            std::fs::write(&path, text).unwrap();
            let e = TriMesh::read_obj(&path).unwrap_err();
            match &e {
                Error::Format { path: p, .. } => assert_eq!(p, &path, "{name}"),
                other => panic!("{name}: unexpected {other:?}"),
            }
        }
        // Garbage bytes.
        let path = dir.path().join("garbage.obj");
        let garbage: Vec<u8> = (0..4096u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        std::fs::write(&path, &garbage).unwrap();
        assert!(matches!(
            TriMesh::read_obj(&path),
            Err(Error::Format { .. })
        ));
        // Missing file.
        let e = TriMesh::read_obj(dir.path().join("missing.obj")).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");
    }

    #[test]
    fn obj_file_keeps_groups_materials_and_libraries() {
        let text = "mtllib a.mtl b.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                    f 1 2 3\no first\nusemtl red\nf 1 2 3 4\ng side top\nusemtl blue\n\
                    f 1 3 4\nusemtl red\nf 2 3 4\nusemtl\nf 1 2 4\n";
        let obj = ObjFile::parse(text.as_bytes(), Path::new("m.obj")).unwrap();
        assert_eq!(obj.mtllibs, ["a.mtl", "b.mtl"]);
        assert_eq!(obj.materials, ["red", "blue"]);
        assert_eq!(obj.groups, ["first", "side top"]);
        assert_eq!(
            obj.triangles,
            [
                [0, 1, 2],
                [0, 1, 2],
                [0, 2, 3],
                [0, 2, 3],
                [1, 2, 3],
                [0, 1, 3]
            ]
        );
        let (r, b) = (Some(0), Some(1));
        assert_eq!(obj.triangle_materials, [None, r, r, b, r, None]);
        assert_eq!(
            obj.triangle_groups,
            [None, Some(0), Some(0), Some(1), Some(1), Some(1)]
        );
        assert_eq!(obj.path, Path::new("m.obj"));
    }

    #[test]
    fn latin1_comments_are_read_and_errors_name_the_file_and_line() {
        // "é" in Latin-1 (0xe9) in a comment and in a group name.
        let bytes = b"# export\xe9 par un logiciel\ng caf\xe9\nv 0 0 0\nv 1 0 0 # \xe9\n\
                      v 0 1 0\nf 1 2 3\n";
        let m = TriMesh::from_obj_bytes(bytes, Path::new("latin1.obj")).unwrap();
        assert_eq!(m.faces, vec![[0, 1, 2]]);
        // A Latin-1 byte inside a number is an error at its line.
        let bytes = b"# \xe9\nv 0 0 0\nv 1 0 0\nv 0 1\xe9 0\nf 1 2 3\n";
        let e = TriMesh::from_obj_bytes(bytes, Path::new("bad.obj")).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("bad.obj") && text.contains("line 4: `1\u{fffd}`"),
            "{text}"
        );
        for (obj, want) in [
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\n\n# x\nv 1 1 zero\nf 1 2 3\n",
                "line 6: `zero`",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\nf 1 2 3\n",
                "line 4: vertex index 9",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1/1/7 2 3\nvn 0 0 1\n",
                "line 5: normal",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e308 1 0 1e-308\nf 1 2 3\n",
                "line 4",
            ),
            (
                "v 0 0 0\nv 1 0 0 \\\n 5\nv 0 1 0\nf 1 2 3 x\n",
                "line 5: `x`",
            ),
        ] {
            let e = TriMesh::from_obj_bytes(obj.as_bytes(), Path::new("f.obj")).unwrap_err();
            let text = e.to_string();
            assert!(
                text.contains("f.obj") && text.contains(want),
                "{want}: {text}"
            );
        }
    }

    #[test]
    fn mtl_libraries_give_diffuse_and_emission() {
        let dir = tempfile::tempdir().unwrap();
        let mtl = b"# Mat\xe9riaux\nnewmtl floor\nKd 0.5 0.25 0.125\nNs 10\nmap_Kd a.png\n\
                    newmtl lamp shade\nKd 0.5\nKe 10 8 6\n";
        std::fs::write(dir.path().join("s.mtl"), mtl).unwrap();
        std::fs::write(
            dir.path().join("s.obj"),
            "mtllib s.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let obj = ObjFile::read(dir.path().join("s.obj")).unwrap();
        let m = obj.read_materials().unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(
            (m[0].name.as_str(), m[0].diffuse, m[0].emission, m[0].line),
            ("floor", Some([0.5, 0.25, 0.125]), None, 2)
        );
        assert_eq!(
            (m[1].name.as_str(), m[1].diffuse, m[1].emission, m[1].line),
            ("lamp shade", Some([0.5; 3]), Some([10.0, 8.0, 6.0]), 6)
        );
        assert_eq!(m[1].library, dir.path().join("s.mtl"));
        for (bad, want) in [
            (
                "newmtl a\nKd 1 2\n",
                "line 2: `Kd` needs 1 or 3 numbers, found 2",
            ),
            (
                "newmtl a\nKe\n",
                "line 2: `Ke` needs 1 or 3 numbers, found 0",
            ),
            ("newmtl a\n\nKd 1 x 1\n", "line 3: `x` is not a number"),
            ("Kd 1 1 1\n", "line 1: `Kd` before any `newmtl`"),
            ("newmtl\n", "line 1: `newmtl` names no material"),
        ] {
            let e = parse_mtl(bad.as_bytes(), Path::new("x.mtl")).unwrap_err();
            assert!(
                matches!(&e, Error::Format { path, reason } if path == Path::new("x.mtl") && reason == want),
                "{bad:?}: {e}"
            );
        }
    }

    #[test]
    #[cfg(unix)]
    fn material_libraries_that_never_end_are_refused_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let obj = dir.path().join("zero.obj");
        std::fs::write(
            &obj,
            "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let file = ObjFile::read(&obj).unwrap();
        let start = std::time::Instant::now();
        let e = file.read_materials().unwrap_err();
        assert!(
            start.elapsed().as_secs() < 5,
            "read for {:?}",
            start.elapsed()
        );
        let text = e.to_string();
        assert!(
            text.contains("/dev/zero") && text.contains("not a regular file"),
            "{text}"
        );
        // The mesh reader opens no other file.
        assert!(TriMesh::read_obj(&obj).is_ok());
        // A missing library is an I/O error naming it.
        std::fs::write(
            &obj,
            "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let e = ObjFile::read(&obj).unwrap().read_materials().unwrap_err();
        assert!(
            matches!(&e, Error::Io { path, .. } if path.ends_with("gone.mtl")),
            "{e}"
        );
    }
}
