//! Wavefront OBJ meshes: [`TriMesh::read_obj`] and [`TriMesh::write_obj`].
//!
//! `v x y z [r g b]`, `vn`, and `f` lines (with `v`, `v/t`, `v//n`, `v/t/n` corners, negative
//! = relative indices) are read; polygons are triangulated as fans; groups, objects,
//! materials, texture coordinates and every other statement are ignored. The reader is a small
//! one written here rather than the `tobj` crate: `tobj` 4 (as configured in this workspace,
//! without its `use_f64` feature) parses coordinates as `f32`, renumbers vertices in order of
//! first use, drops vertices no face uses, and duplicates the vertices shared between `g`/`o`
//! groups (which opens closed meshes). This reader keeps the file's vertices, their order and
//! their `f64` values.

use std::io::Write;
use std::path::Path;

use crate::error::{read_file, Error, Result};
use crate::mesh::TriMesh;

impl TriMesh {
    /// Reads a Wavefront OBJ file.
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
    /// - Everything else (`vt`, `o`, `g`, `s`, `usemtl`, `mtllib`, `l`, `p`, comments...) is
    ///   ignored; no other file is opened.
    ///
    /// Errors: the file cannot be read ([`Error::Io`]); a malformed number or index, an index
    /// of 0 or out of range, a face with fewer than three corners or a repeated vertex, a
    /// non-finite coordinate, colours on only some vertices, or no vertices or no faces
    /// ([`Error::Format`] naming the path).
    pub fn read_obj(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_obj_bytes(&read_file(path)?, path)
    }

    /// [`TriMesh::read_obj`] of a file held in memory; `origin` names the file in errors.
    pub fn from_obj_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        let text = String::from_utf8_lossy(bytes);
        parse_obj(&text).map_err(|reason| Error::format(origin, reason))
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

/// Resolves a 1-based or negative (relative to `count` items so far) OBJ index to 0-based.
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

/// Parses OBJ text into a mesh; errors are reasons without the path.
fn parse_obj(text: &str) -> std::result::Result<TriMesh, String> {
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut colors: Vec<[f32; 3]> = Vec::new(); // aligned with positions, zero when absent
    let mut num_colored = 0usize;
    let mut normals: Vec<[f64; 3]> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    // (vertex, normal) for every face corner that names a normal.
    let mut corner_normals: Vec<(u32, u32)> = Vec::new();
    let mut corner_without_normal = false;
    let mut corners: Vec<(u32, Option<u32>)> = Vec::new();

    let mut joined = String::new();
    let mut line_no = 0usize;
    let mut lines = text.lines();
    loop {
        // Join lines ending in a backslash (line continuation).
        joined.clear();
        let Some(first) = lines.next() else { break };
        line_no += 1;
        let start_line = line_no;
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
        let Some(keyword) = words.next() else {
            continue;
        };
        let line = start_line;
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
                if positions.len() >= u32::MAX as usize {
                    return Err(format!("more than {} vertices", u32::MAX));
                }
                positions.push(p);
                match c {
                    Some(c) => {
                        colors.push(c);
                        num_colored += 1;
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
                    let v = obj_index(parts.next().unwrap_or(""), positions.len(), "vertex", line)?;
                    let _texcoord = parts.next();
                    let n = match parts.next() {
                        Some(s) if !s.is_empty() => {
                            Some(obj_index(s, normals.len(), "normal", line)?)
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
                    faces.push([a, corners[k].0, corners[k + 1].0]);
                }
            }
            _ => {}
        }
    }

    if positions.is_empty() {
        return Err("the file has no vertices (`v` lines)".to_string());
    }
    if faces.is_empty() {
        return Err("the file has no faces (`f` lines)".to_string());
    }
    let nv = positions.len();

    if let Some(&(_, n)) = corner_normals
        .iter()
        .find(|&&(_, n)| n as usize >= normals.len())
    {
        return Err(format!(
            "a face refers to normal {} but the file has {} `vn` lines",
            u64::from(n) + 1,
            normals.len()
        ));
    }
    let vertex_normals = if !corner_normals.is_empty() && !corner_without_normal {
        const NONE: u32 = u32::MAX;
        let mut slot = vec![NONE; nv];
        let mut per_vertex = true;
        for &(v, n) in &corner_normals {
            // Out-of-range vertices are reported by TriMesh::new below.
            let Some(s) = slot.get_mut(v as usize) else {
                continue;
            };
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

    let mut mesh = TriMesh::new(positions, faces).map_err(|e| e.to_string())?;
    if let Some(n) = vertex_normals {
        mesh = mesh.with_normals(n).map_err(|e| e.to_string())?;
    }
    if num_colored > 0 {
        if num_colored != nv {
            return Err(format!(
                "only {num_colored} of the {nv} vertices have a colour"
            ));
        }
        if colors.as_flattened().iter().any(|&c| c > 1.0) {
            for c in colors.as_flattened_mut() {
                *c /= 255.0;
            }
        }
        mesh = mesh.with_colors(colors).map_err(|e| e.to_string())?;
    }
    Ok(mesh)
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
}
