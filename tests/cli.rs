//! End-to-end tests of the `wscg` binary: gallery, demos and the math commands on files.

use std::path::Path;
use std::process::Command;

use wscg::math::image::Image;

fn wscg() -> Command {
    Command::new(env!("CARGO_BIN_EXE_wscg"))
}

fn write_test_image(path: &Path, shift: f32) {
    Image::from_fn(48, 64, |y, x| ((x + 2 * y) as f32 / 160.0 + shift).min(1.0))
        .unwrap()
        .save(path)
        .unwrap();
}

#[test]
fn help_lists_the_commands() {
    let out = wscg().arg("--help").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for cmd in ["demo", "gallery", "math"] {
        assert!(text.contains(cmd), "{cmd} missing from --help:\n{text}");
    }
}

#[test]
fn gallery_writes_an_index_with_the_math_demo() {
    let dir = tempfile::tempdir().unwrap();
    let out = wscg()
        .args(["gallery", "--only", "math", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    assert!(html.contains("id=\"math\""));
    assert!(html.contains("Parseval"));
    // Every picture the page links to exists and decodes.
    for part in html.split("<img src=\"").skip(1) {
        let file = &part[..part.find('"').unwrap()];
        Image::load(dir.path().join(file)).unwrap();
    }
}

#[test]
fn unknown_demo_is_a_clear_error() {
    let out = wscg().args(["demo", "no-such-demo"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no demo named") && err.contains("math"),
        "{err}"
    );
}

#[test]
fn metrics_command_reports_psnr_of_files() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.png"), dir.path().join("b.png"));
    write_test_image(&a, 0.0);
    write_test_image(&b, 0.0);
    let out = wscg()
        .args(["math", "metrics"])
        .arg(&a)
        .arg(&b)
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("psnr inf") && text.contains("ssim 1.000000"),
        "{text}"
    );
}

#[test]
fn file_commands_write_outputs_and_never_touch_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.png");
    write_test_image(&input, 0.1);
    let before = std::fs::read(&input).unwrap();
    let blurred = dir.path().join("blur.png");
    let st = wscg()
        .args(["math", "blur", "--sigma", "2"])
        .arg(&input)
        .arg(&blurred)
        .status()
        .unwrap();
    assert!(st.success());
    assert_eq!(Image::load(&blurred).unwrap().shape(), (48, 64, 1));
    let small = dir.path().join("small.png");
    let st = wscg()
        .args(["math", "resize", "--height", "12", "--width", "16"])
        .arg(&input)
        .arg(&small)
        .status()
        .unwrap();
    assert!(st.success());
    assert_eq!(Image::load(&small).unwrap().shape(), (12, 16, 1));
    // Writing over the input is refused.
    let out = wscg()
        .args(["math", "blur", "--sigma", "2"])
        .arg(&input)
        .arg(&input)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("overwrite the input"));
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

#[test]
fn bad_files_give_errors_not_crashes() {
    let dir = tempfile::tempdir().unwrap();
    let garbage = dir.path().join("garbage.png");
    std::fs::write(&garbage, b"not a png").unwrap();
    let missing = dir.path().join("missing.png");
    for (a, b) in [(&garbage, &garbage), (&missing, &missing)] {
        let out = wscg()
            .args(["math", "metrics"])
            .arg(a)
            .arg(b)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&out.stderr).starts_with("error: "));
    }
    let ok = dir.path().join("ok.png");
    write_test_image(&ok, 0.0);
    let other = dir.path().join("other.png");
    Image::filled(10, 10, 1, 0.5f32)
        .unwrap()
        .save(&other)
        .unwrap();
    let out = wscg()
        .args(["math", "metrics"])
        .arg(&ok)
        .arg(&other)
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("shape mismatch"));
    let out = wscg()
        .args(["math", "blur", "--sigma", "-1"])
        .arg(&ok)
        .arg(dir.path().join("x.png"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("sigma"));
}
