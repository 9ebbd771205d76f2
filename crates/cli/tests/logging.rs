//! `-v` / `-q` and the library's log records on standard error.

use std::path::Path;

use wscg_math::Volume;

mod common;
use common::wscg;

/// A 12^3 ball (value 1 inside radius 4) as NIfTI; `flip_x` makes the sform's x axis negative
/// (as in radiological-order scans), which the reader does not apply and says so.
fn ball(path: &Path, singular: bool) {
    let n = 12;
    let data: Vec<f32> = (0..n * n * n)
        .map(|i| {
            let (x, y, z) = (i % n, (i / n) % n, i / (n * n));
            let d2 = [x, y, z]
                .iter()
                .map(|&c| (c as f64 - 5.5).powi(2))
                .sum::<f64>();
            f32::from(d2 <= 16.0)
        })
        .collect();
    Volume::new([n, n, n], [1.0; 3], data)
        .unwrap()
        .write_nifti(path)
        .unwrap();
    if singular {
        // srow_x[0] is the float32 at byte 280 of a NIfTI-1 header, qform_code the int16 at
        // 252: a singular sform and no qform leave the volume without orientation.
        let mut bytes = std::fs::read(path).unwrap();
        bytes[280..284].copy_from_slice(&0.0f32.to_le_bytes());
        bytes[252..254].copy_from_slice(&0i16.to_le_bytes());
        std::fs::write(path, bytes).unwrap();
    }
}

fn extract(dir: &Path, input: &Path, flags: &[&str]) -> String {
    let out = wscg()
        .args(flags)
        .args([
            "isosurface",
            "extract",
            "--iso",
            "0.5",
            "--overwrite",
            "--out",
        ])
        .arg(dir.join("mesh.ply"))
        .arg(input)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn warnings_by_default_quiet_hides_them_verbose_adds_details() {
    let dir = tempfile::tempdir().unwrap();
    let flipped = dir.path().join("singular.nii");
    ball(&flipped, true);
    let plain = dir.path().join("plain.nii");
    ball(&plain, false);

    let stderr = extract(dir.path(), &flipped, &[]);
    assert!(
        stderr.contains("warning:")
            && stderr.contains("sform")
            && stderr.contains("no orientation"),
        "{stderr}"
    );
    assert!(!stderr.contains("debug"), "{stderr}");
    // A usable sform needs no warning.
    let stderr = extract(dir.path(), &plain, &[]);
    assert!(!stderr.contains("warning"), "{stderr}");

    let stderr = extract(dir.path(), &flipped, &["-q"]);
    assert!(stderr.is_empty(), "{stderr}");

    let stderr = extract(dir.path(), &plain, &["-vv"]);
    assert!(
        stderr.contains("debug [wscg_isosurface") && stderr.contains("marching cubes"),
        "{stderr}"
    );
    assert!(stderr.contains("debug [wscg_math"), "{stderr}");

    let out = wscg()
        .args(["-q", "-v", "isosurface", "extract", "--iso", "0.5", "--out"])
        .arg(dir.path().join("other.ply"))
        .arg(&plain)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot be used with"));
}
