//! Wavefront OBJ + MTL scenes for the many-light renderer (paper 08), read with the
//! workspace's OBJ reader ([`wscg_math::io::obj`]).

use std::collections::HashMap;
use std::path::Path;

use wscg_math::io::obj::{MtlMaterial, ObjFile};
use wscg_math::{Error, Result};

use super::scene::{Rgb, Scene};

/// Albedo of the faces that use no material (or a material without `Kd`).
pub const DEFAULT_ALBEDO: Rgb = [0.8, 0.8, 0.8];

/// Loads a Wavefront OBJ file (and the MTL libraries it names with `mtllib`, relative to its
/// folder) as a [`Scene`], with [`ObjFile::read`] and [`ObjFile::read_materials`].
///
/// Polygons are triangulated as fans around their first corner, points and lines are
/// ignored, and the objects and groups of the file become one triangle list in file order
/// (sharing the file's vertices, read as `f64`). Each face takes its Lambertian albedo from
/// its material's diffuse colour `Kd` ([`DEFAULT_ALBEDO`], 0.8 grey, when the face has no
/// material, names a material that no library defines, or its material has no `Kd`; a
/// material defined twice takes its last definition) and its emitted radiance from the
/// material's `Ke` (none when absent). One number is a grey (`Kd 0.5` is `Kd 0.5 0.5 0.5`).
/// Other MTL statements (specular, textures, ...) are ignored. Emitters radiate from their
/// front side, the side from which the face's vertices run counter-clockwise. A scene without
/// emitters is accepted here (the renderer refuses it); degenerate triangles (a repeated
/// vertex, zero area) are skipped and counted in [`Scene::skipped_degenerate`]. The files are
/// only read, and only regular files are: an `mtllib` naming a device or a FIFO is refused.
///
/// Errors: [`Error::Io`] naming the file when the OBJ file or one of its MTL libraries
/// cannot be read; [`Error::Format`] naming the file and the line when it is malformed (a bad
/// number, a face index out of range, ...), naming the library, line and material when a
/// material's `Kd` lies outside `[0, 1]` or its `Ke` is negative or not finite, and naming the
/// OBJ file when the scene cannot be built from the file's content (no triangle; the reason
/// of [`Scene::from_triangles`] is quoted).
pub fn load_obj(path: &Path) -> Result<Scene> {
    let obj = ObjFile::read(path)?;
    let mut by_name: HashMap<&str, (Rgb, Rgb)> = HashMap::new();
    let libraries = obj.read_materials()?;
    for m in &libraries {
        by_name.insert(&m.name, material(m)?);
    }
    let shading = |used: &Option<u32>| {
        used.and_then(|k| obj.materials.get(k as usize))
            .and_then(|name| by_name.get(name.as_str()).copied())
            .unwrap_or((DEFAULT_ALBEDO, [0.0; 3]))
    };
    let (albedo, emission): (Vec<Rgb>, Vec<Rgb>) =
        obj.triangle_materials.iter().map(shading).unzip();
    for name in &obj.materials {
        if !by_name.contains_key(name.as_str()) {
            log::warn!(
                "{}: material `{name}` is defined by no library; its faces get the default \
                 albedo",
                path.display()
            );
        }
    }
    Scene::from_triangles(&obj.positions, &obj.triangles, &albedo, &emission)
        .map_err(|e| Error::format(path, e.to_string()))
}

/// The albedo and emission of an MTL material, checked.
fn material(m: &MtlMaterial) -> Result<(Rgb, Rgb)> {
    let bad = |what: String| {
        Error::format(
            &m.library,
            format!("material `{}` (line {}): {what}", m.name, m.line),
        )
    };
    let albedo = m.diffuse.unwrap_or(DEFAULT_ALBEDO);
    if albedo
        .iter()
        .any(|c| !(c.is_finite() && (0.0..=1.0).contains(c)))
    {
        return Err(bad(format!("Kd {albedo:?} must lie in [0, 1]")));
    }
    let emission = m.emission.unwrap_or([0.0; 3]);
    if emission.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
        return Err(bad(format!("Ke {emission:?} must be finite and >= 0")));
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
                assert_eq!(s.albedo(i), [0.1, 0.2, 0.3]);
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
            (
                "newmtl floor\nKd 0.5 zero 0.5\n",
                "scene.mtl: line 2: `zero`",
            ),
            ("# no material yet\nKd 0.5\n", "scene.mtl: line 2"),
        ] {
            let path = write(dir.path(), &[("scene.obj", OBJ), ("scene.mtl", mtl)]);
            let e = load_obj(&path).unwrap_err();
            assert!(matches!(e, Error::Format { .. }), "{e:?}");
            assert!(e.to_string().contains(what), "{e}");
        }
    }

    #[test]
    fn latin1_comments_and_names_load_and_bad_numbers_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        // Latin-1 text (a comment, an object and a material name) in both files.
        let latin1 = |text: &str| -> Vec<u8> {
            text.replace("lamp", "l\u{e4}mp")
                .chars()
                .map(|c| c as u8)
                .collect()
        };
        let path = dir.path().join("scene.obj");
        std::fs::write(&path, latin1(&format!("# mod\u{e8}le export\u{e9}\n{OBJ}"))).unwrap();
        let mtl = format!("# Mat\u{e9}riaux\n{MTL}");
        std::fs::write(dir.path().join("scene.mtl"), latin1(&mtl)).unwrap();
        let s = load_obj(&path).unwrap();
        assert_eq!(s.len(), 4);
        assert_eq!(s.emitters().len(), 2, "the Latin-1 material name matches");

        // A bad number names the file and the line (line 5: the comment, mtllib, o, v, v).
        let bad = OBJ.replace("v 1 0 -1", "v 1 0 -1,5");
        let path = write(dir.path(), &[("bad.obj", &bad), ("scene.mtl", MTL)]);
        let e = load_obj(&path).unwrap_err().to_string();
        assert!(
            e.contains("bad.obj") && e.contains("line 5: `-1,5` is not a number"),
            "{e}"
        );
        // A face index beyond the vertices names the line of the face.
        let far = OBJ.replace("f 5 6 7 8", "f 5 6 7 80");
        let path = write(dir.path(), &[("far.obj", &far), ("scene.mtl", MTL)]);
        let e = load_obj(&path).unwrap_err().to_string();
        assert!(
            e.contains("far.obj") && e.contains("line 16: vertex index 80"),
            "{e}"
        );
    }

    #[test]
    fn degenerate_triangles_are_counted_and_materials_may_be_missing() {
        let dir = tempfile::tempdir().unwrap();
        let obj = "mtllib scene.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n\
                   usemtl nowhere\nf 1 2 3\nf 1 2 4\nf 1 2 2\n";
        let path = write(dir.path(), &[("degenerate.obj", obj), ("scene.mtl", MTL)]);
        let s = load_obj(&path).unwrap();
        assert_eq!((s.len(), s.skipped_degenerate), (1, 2));
        assert_eq!(s.albedo(0), DEFAULT_ALBEDO);
    }

    #[test]
    #[cfg(unix)]
    fn a_material_library_that_is_a_fifo_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.mtl");
        let status = std::process::Command::new("mkfifo").arg(&fifo).status();
        if !status.is_ok_and(|s| s.success()) {
            return; // no mkfifo here
        }
        let path = dir.path().join("fifo.obj");
        std::fs::write(
            &path,
            "mtllib pipe.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        )
        .unwrap();
        let e = load_obj(&path).unwrap_err().to_string();
        assert!(e.contains("pipe.mtl") && e.contains("regular"), "{e}");
    }
}
