//! Wavefront OBJ + MTL scenes for the many-light renderer (paper 08), read with `tobj`.

use std::cell::RefCell;
use std::io::Cursor;
use std::panic::AssertUnwindSafe;
use std::path::Path;

use wscg_math::{Error, Result};

use super::scene::{Rgb, Scene};

/// Albedo of the faces that use no material (or a material without `Kd`).
pub const DEFAULT_ALBEDO: Rgb = [0.8, 0.8, 0.8];

/// Loads a Wavefront OBJ file (and the MTL libraries it names with `mtllib`, relative to its
/// folder) as a [`Scene`].
///
/// Polygons are triangulated (as fans, by `tobj`), points and lines are ignored, and the
/// objects and groups of the file become one triangle list in file order. Each face takes its
/// Lambertian albedo from its material's diffuse colour `Kd` ([`DEFAULT_ALBEDO`], 0.8 grey,
/// when the face has no material, names a material that no library defines, or its material
/// has no `Kd`) and its emitted radiance from the material's `Ke` (none when absent). Other
/// MTL statements (specular, textures, ...) are ignored. Emitters radiate from their front
/// side, the side from which the face's vertices run counter-clockwise. Coordinates are read
/// as `f32` (tobj's default). A scene without emitters is accepted here (the renderer refuses
/// it); degenerate triangles are skipped and counted in [`Scene::skipped_degenerate`]. The
/// files are only read.
///
/// Errors: [`Error::Io`] naming the file when the OBJ file or one of its MTL libraries
/// cannot be read; [`Error::Format`] naming the file when it is malformed (a bad number, a
/// face index out of range, not UTF-8, ...), when a material's `Kd` lies outside `[0, 1]` or
/// its `Ke` is negative or not finite (named with the material), or when the scene cannot be
/// built from the file's content (no triangle, a non-finite vertex; the reason of
/// [`Scene::from_triangles`] is quoted).
pub fn load_obj(path: &Path) -> Result<Scene> {
    let bytes = wscg_math::error::read_file(path)?;
    let dir = path.parent().unwrap_or_else(|| Path::new(""));
    let mtl_error: RefCell<Option<Error>> = RefCell::new(None);
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let record = |e: Error, code: tobj::LoadError| {
        mtl_error.borrow_mut().get_or_insert(e);
        code
    };
    let parse = || {
        tobj::load_obj_buf(&mut Cursor::new(&bytes), &options, |name| {
            let mtl = dir.join(name);
            let text = mtl_text(path, &mtl, name)
                .map_err(|e| record(e, tobj::LoadError::MaterialParseError))?;
            tobj::load_mtl_buf(&mut text.as_bytes())
                .map_err(|e| record(Error::format(&mtl, e.to_string()), e))
        })
    };
    // tobj 4.0 panics on some malformed lines (a colour of fewer than three numbers, which
    // `expand_colours` rules out beforehand); any other such panic becomes a format error.
    let loaded = std::panic::catch_unwind(AssertUnwindSafe(parse)).map_err(|_| {
        Error::format(
            path,
            "the OBJ/MTL parser (tobj) failed on malformed content",
        )
    })?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, materials) = loaded.map_err(|e| Error::format(path, e.to_string()))?;
    let materials = materials.map_err(|e| Error::format(path, e.to_string()))?;
    let mats = materials
        .iter()
        .map(|m| material(path, m))
        .collect::<Result<Vec<_>>>()?;

    let mut vertices = Vec::new();
    let (mut faces, mut albedo, mut emission) = (Vec::new(), Vec::new(), Vec::new());
    for model in &models {
        let mesh = &model.mesh;
        let base = u32::try_from(vertices.len())
            .map_err(|_| Error::format(path, "more than 2^32 vertices"))?;
        vertices.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]),
        );
        let (a, e) = mesh
            .material_id
            .and_then(|i| mats.get(i).copied())
            .unwrap_or((DEFAULT_ALBEDO, [0.0; 3]));
        for f in mesh.indices.chunks_exact(3) {
            faces.push([base + f[0], base + f[1], base + f[2]]);
            albedo.push(a);
            emission.push(e);
        }
    }
    Scene::from_triangles(&vertices, &faces, &albedo, &emission)
        .map_err(|e| Error::format(path, e.to_string()))
}

/// The text of the material library `name` named by the OBJ file `obj` (found at `mtl`,
/// relative to the OBJ file's folder), its colours written out by [`expand_colours`].
fn mtl_text(obj: &Path, mtl: &Path, name: &Path) -> Result<String> {
    if name.as_os_str().is_empty() {
        return Err(Error::format(obj, "`mtllib` names no file"));
    }
    let bytes = wscg_math::error::read_file(mtl)?;
    expand_colours(mtl, &bytes)
}

/// The MTL text with every one-number colour (`Kd 0.5`, which the MTL format reads as
/// `Kd 0.5 0.5 0.5`) written out as three numbers; a colour of zero or two numbers is an
/// error (tobj would panic on it).
fn expand_colours(mtl: &Path, bytes: &[u8]) -> Result<String> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| Error::format(mtl, format!("not UTF-8 text: {e}")))?;
    let mut out = String::with_capacity(text.len() + 64);
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) => {
                let vals: Vec<&str> = words.collect();
                match vals[..] {
                    [v] => out.push_str(&format!("{key} {v} {v} {v}")),
                    [] | [_, _] => {
                        return Err(Error::format(
                            mtl,
                            format!("line {}: `{key}` needs 1 or 3 numbers", n + 1),
                        ))
                    }
                    _ => out.push_str(line),
                }
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    Ok(out)
}

/// The albedo and emission of an MTL material, checked.
fn material(path: &Path, m: &tobj::Material) -> Result<(Rgb, Rgb)> {
    let rgb = |c: [f32; 3]| c.map(f64::from);
    let albedo = m.diffuse.map_or(DEFAULT_ALBEDO, rgb);
    if albedo
        .iter()
        .any(|c| !(c.is_finite() && (0.0..=1.0).contains(c)))
    {
        return Err(Error::format(
            path,
            format!("material `{}`: Kd {albedo:?} must lie in [0, 1]", m.name),
        ));
    }
    let emission = m.emissive.map_or([0.0; 3], rgb);
    if emission.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
        return Err(Error::format(
            path,
            format!(
                "material `{}`: Ke {emission:?} must be finite and >= 0",
                m.name
            ),
        ));
    }
    Ok((albedo, emission))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    const MTL: &str = "\
newmtl floor
Kd 0.5 0.25 0.125
newmtl lamp
Kd 0.1 0.2 0.3
Ke 10 8 6
";

    /// A 2 x 2 floor quad at y = 0 facing up and a 1 x 1 emissive quad at y = 1 facing down.
    const OBJ: &str = "\
# test scene
mtllib scene.mtl
o floor
v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
usemtl floor
f 1 4 3 2
o lamp
v -0.5 1 -0.5
v 0.5 1 -0.5
v 0.5 1 0.5
v -0.5 1 0.5
usemtl lamp
f 5 6 7 8
";

    fn write(dir: &Path, files: &[(&str, &str)]) -> PathBuf {
        for (name, text) in files {
            std::fs::write(dir.join(name), text).unwrap();
        }
        dir.join(files[0].0)
    }

    #[test]
    fn loads_quads_with_albedo_and_emission() {
        let dir = tempfile::tempdir().unwrap();
        let path = write(dir.path(), &[("scene.obj", OBJ), ("scene.mtl", MTL)]);
        let before = std::fs::read(&path).unwrap();
        let s = load_obj(&path).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), before);
        assert_eq!(s.len(), 4);
        assert_eq!(s.emitters().len(), 2);
        let mut area = [0.0; 2];
        for (i, t) in s.triangles().iter().enumerate() {
            let i = i as u32;
            if s.emitters().contains(&i) {
                assert_eq!(s.emission(i), [10.0, 8.0, 6.0]);
                assert_eq!(s.albedo(i), [0.1f32 as f64, 0.2f32 as f64, 0.3f32 as f64]);
                assert!(t.normal[1] < -0.999, "the lamp faces down");
                area[1] += t.area;
            } else {
                assert_eq!(s.emission(i), [0.0; 3]);
                assert_eq!(s.albedo(i), [0.5, 0.25, 0.125]);
                assert!(t.normal[1] > 0.999, "the floor faces up");
                area[0] += t.area;
            }
        }
        assert!((area[0] - 4.0).abs() < 1e-6 && (area[1] - 1.0).abs() < 1e-6);
    }

    #[test]
    fn faces_without_material_are_grey_and_emitters_are_optional() {
        let dir = tempfile::tempdir().unwrap();
        let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4 5\n";
        let path = write(dir.path(), &[("plain.obj", obj)]);
        let s = load_obj(&path).unwrap();
        assert_eq!(s.len(), 3);
        assert!(s.emitters().is_empty());
        assert!((0..3).all(|i| s.albedo(i) == DEFAULT_ALBEDO && s.emission(i) == [0.0; 3]));
    }

    #[test]
    fn unreadable_files_are_io_errors_naming_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("nowhere.obj");
        let e = load_obj(&missing).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e:?}");
        assert!(e.to_string().contains("nowhere.obj"), "{e}");
        // A folder is not a file.
        assert!(matches!(load_obj(dir.path()), Err(Error::Io { .. })));
        // A missing material library is an I/O error naming it.
        let path = write(dir.path(), &[("scene.obj", OBJ)]);
        let e = load_obj(&path).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e:?}");
        assert!(e.to_string().contains("scene.mtl"), "{e}");
    }

    #[test]
    fn malformed_files_are_format_errors_naming_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let cases = [
            ("bad_number.obj", "v 0 0 zero\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("out_of_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
            ("no_faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
            ("nan.obj", "v 0 0 NaN\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("empty.obj", ""),
        ];
        for (name, text) in cases {
            let path = write(dir.path(), &[(name, text)]);
            let e = load_obj(&path).unwrap_err();
            assert!(matches!(e, Error::Format { .. }), "{name}: {e:?}");
            assert!(e.to_string().contains(name), "{e}");
        }
        let path = dir.path().join("binary.obj");
        std::fs::write(&path, [0xff, 0xfe, b'v', b' ', 0x80, b'\n']).unwrap();
        assert!(matches!(load_obj(&path), Err(Error::Format { .. })));
    }

    #[test]
    fn one_number_colours_are_grey() {
        let dir = tempfile::tempdir().unwrap();
        let mtl = "newmtl floor\nKd 0.25\n\nnewmtl lamp\n  Ke 4\n";
        let path = write(dir.path(), &[("scene.obj", OBJ), ("scene.mtl", mtl)]);
        let s = load_obj(&path).unwrap();
        assert_eq!(s.emitters().len(), 2);
        for i in 0..4 {
            if s.emitters().contains(&i) {
                assert_eq!((s.albedo(i), s.emission(i)), (DEFAULT_ALBEDO, [4.0; 3]));
            } else {
                assert_eq!((s.albedo(i), s.emission(i)), ([0.25; 3], [0.0; 3]));
            }
        }
    }

    #[test]
    #[cfg(unix)]
    fn a_material_library_that_never_ends_is_refused() {
        // `/dev/zero` would be read until memory runs out: only regular files are read.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("zero.obj");
        std::fs::write(
            &path,
            "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let e = load_obj(&path).unwrap_err();
        assert!(
            e.to_string().contains("/dev/zero") && e.to_string().contains("regular"),
            "{e}"
        );
    }

    /// Odd and hostile lines give a scene or an error, never a panic.
    #[test]
    fn odd_lines_never_panic() {
        let dir = tempfile::tempdir().unwrap();
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        for (k, extra) in [
            "f 0 1 2",
            "f 1",
            "f 1 2",
            "f",
            "f -9 1 2",
            "f 1/2/3 2 3",
            "f 1//9 2 3",
            "v",
            "v 1",
            "v 1 2 3 0",
            "v 1 2 3 4 5",
            "vn 1",
            "vt",
            "o",
            "g",
            "usemtl",
            "usemtl nothing",
            "mtllib",
            "newmtl",
            "l 1 2",
            "p 1",
            "f 1 2 3 4 5 6 7",
            "s off",
            "\u{feff}v 1 2 3",
        ]
        .iter()
        .enumerate()
        {
            let path = dir.path().join(format!("odd{k}.obj"));
            std::fs::write(&path, format!("{tri}{extra}\nf 1 2 3\n")).unwrap();
            match load_obj(&path) {
                Ok(s) => assert!(!s.is_empty()),
                Err(e) => assert!(e.to_string().contains(&format!("odd{k}")), "{extra}: {e}"),
            }
        }
    }

    #[test]
    fn bad_materials_are_errors_naming_them() {
        let dir = tempfile::tempdir().unwrap();
        for (mtl, what) in [
            (
                "newmtl floor\nKd 1.5 0.5 0.5\nnewmtl lamp\nKe 1 1 1\n",
                "floor",
            ),
            (
                "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKe -1 1 1\n",
                "lamp",
            ),
            ("newmtl floor\nKd 0.5 0.5\n", "scene.mtl: line 2"),
            ("newmtl floor\nKe\n", "scene.mtl: line 2"),
            ("newmtl floor\nKd 0.5 zero 0.5\n", "scene.mtl"),
        ] {
            let path = write(dir.path(), &[("scene.obj", OBJ), ("scene.mtl", mtl)]);
            let e = load_obj(&path).unwrap_err();
            assert!(matches!(e, Error::Format { .. }), "{e:?}");
            assert!(e.to_string().contains(what), "{e}");
        }
    }
}
