//! End-to-end tests of the `wscg` binary: gallery, demos and the math commands on files.

use std::path::Path;

use wscg::hdr::synth::{encode, gradient_target, Response};
use wscg::math::image::Image;

mod common;
use common::wscg;

/// Runs `wscg ARGS...`, asserts success and returns standard output.
fn wscg_ok<S: AsRef<std::ffi::OsStr> + std::fmt::Debug>(args: &[S]) -> String {
    let out = wscg().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
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
    for cmd in ["demo", "gallery", "math", "biometrics"] {
        assert!(text.contains(cmd), "{cmd} missing from --help:\n{text}");
    }
}

#[test]
fn gallery_writes_an_index_with_the_math_demo() {
    let dir = tempfile::tempdir().unwrap();
    let o = std::ffi::OsStr::new;
    wscg_ok(&[
        o("gallery"),
        o("--only"),
        o("math"),
        o("--out"),
        dir.path().as_os_str(),
    ]);
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
    assert!(String::from_utf8_lossy(&out.stderr).contains("give --overwrite"));
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

/// A gallery of synthetic finger veins: one folder per identity, `samples` PNGs each.
fn write_vein_gallery(root: &Path, subjects: usize, samples: usize) {
    use wscg::biometrics::data::{finger_veins, FingerVeinParams};
    let data = finger_veins(
        &FingerVeinParams::default()
            .subjects(subjects)
            .samples(samples)
            .seed(4),
    )
    .unwrap();
    for i in 0..data.x.nrows() {
        let dir = root.join(format!("person{:02}", data.labels[i]));
        std::fs::create_dir_all(&dir).unwrap();
        let px: Vec<f32> = (0..200)
            .map(|j| data.x[(i, j)].clamp(0.0, 1.0) as f32)
            .collect();
        Image::new(10, 20, 1, px)
            .unwrap()
            .save(dir.join(format!("{}.png", i % samples)))
            .unwrap();
    }
}

/// Runs `wscg biometrics fdkeca ARGS...`, asserts success and returns standard output.
fn fdkeca_ok(args: &[&std::ffi::OsStr]) -> String {
    let o = std::ffi::OsStr::new;
    let full: Vec<&std::ffi::OsStr> = [o("biometrics"), o("fdkeca")]
        .into_iter()
        .chain(args.iter().copied())
        .collect();
    wscg_ok(&full)
}

#[test]
fn biometrics_fit_identify_evaluate_and_axes() {
    let dir = tempfile::tempdir().unwrap();
    let gallery = dir.path().join("gallery");
    write_vein_gallery(&gallery, 8, 6);
    let model = dir.path().join("model.json");
    let os = |s: &'static str| std::ffi::OsStr::new(s);
    fdkeca_ok(&[
        os("fit"),
        os("--components"),
        os("30"),
        os("--gallery"),
        gallery.as_os_str(),
        os("--out"),
        model.as_os_str(),
    ]);
    // Every gallery image is identified as its own folder at distance 0.
    let one = gallery.join("person05").join("2.png");
    let folder = gallery.join("person03");
    let text = fdkeca_ok(&[
        os("identify"),
        os("--model"),
        model.as_os_str(),
        folder.as_os_str(),
        one.as_os_str(),
    ]);
    let lines: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(lines.len(), 7, "{text}");
    for (k, line) in lines.iter().enumerate() {
        let cells: Vec<&str> = line.split('\t').collect();
        let want = if k < 6 { "person03" } else { "person05" };
        assert_eq!(cells[1], want, "{line}");
        assert!(cells[2].parse::<f64>().unwrap() < 1e-6, "{line}");
    }
    let text = fdkeca_ok(&[
        os("evaluate"),
        os("--train-per-identity"),
        os("3"),
        os("--max-dim"),
        os("40"),
        os("--folds"),
        os("3"),
        os("--gallery"),
        gallery.as_os_str(),
    ]);
    for m in ["FDKECA", "PCA", "KPCA", "KECA"] {
        assert!(
            text.lines().any(|l| l.starts_with(m)),
            "{m} missing:\n{text}"
        );
    }
    let axes = dir.path().join("axes");
    fdkeca_ok(&[
        os("axes"),
        os("--count"),
        os("4"),
        os("--model"),
        model.as_os_str(),
        os("--out"),
        axes.as_os_str(),
    ]);
    let a = Image::load(axes.join("axis_004.png")).unwrap();
    assert_eq!(a.shape(), (10, 20, 1));
}

#[test]
fn biometrics_bad_input_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("junk.json");
    std::fs::write(&junk, "not json").unwrap();
    let d = dir.path();
    let argv = |items: &[&std::ffi::OsStr]| -> Vec<std::ffi::OsString> {
        items.iter().map(|s| s.to_os_string()).collect()
    };
    let (fit, identify, axes) = ("fit".as_ref(), "identify".as_ref(), "axes".as_ref());
    let (gallery, out, model) = ("--gallery".as_ref(), "--out".as_ref(), "--model".as_ref());
    let missing = d.join("missing");
    let m_json = d.join("m.json");
    let a_dir = d.join("a");
    let cases = [
        argv(&[fit, gallery, missing.as_os_str(), out, m_json.as_os_str()]),
        argv(&[fit, gallery, d.as_os_str(), out, m_json.as_os_str()]),
        argv(&[identify, model, junk.as_os_str(), d.as_os_str()]),
        argv(&[axes, model, junk.as_os_str(), out, a_dir.as_os_str()]),
    ];
    for args in cases {
        let out = wscg()
            .args(["biometrics", "fdkeca"])
            .args(&args)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("error"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert_eq!(
        std::fs::read_to_string(dir.path().join("junk.json")).unwrap(),
        "not json"
    );
}

#[test]
fn cloth_simulate_writes_frames_and_energy() {
    use wscg::math::TriMesh;
    let dir = tempfile::tempdir().unwrap();
    // A vertical 1 m x 1 m sheet in the x-y plane: the top row (highest y) is pinned.
    let mesh = TriMesh::grid(6, 6, 1.0, 1.0).unwrap();
    let path = dir.path().join("sheet.obj");
    mesh.write_obj(&path).unwrap();
    let before = std::fs::read(&path).unwrap();
    let out_dir = dir.path().join("frames");
    for material in ["fem", "links"] {
        let o = std::ffi::OsStr::new;
        wscg_ok(&[
            o("cloth"),
            o("simulate"),
            o("--frames"),
            o("20"),
            o("--material"),
            o(material),
            o("--mesh"),
            path.as_os_str(),
            o("--out"),
            out_dir.as_os_str(),
        ]);
        let last = TriMesh::read(out_dir.join("frame_0019.obj")).unwrap();
        assert_eq!(last.num_vertices(), mesh.num_vertices());
        // The sheet stretches under gravity: its bottom sinks, its pinned top stays.
        let low = |m: &TriMesh| m.positions.iter().map(|p| p[1]).fold(f64::MAX, f64::min);
        let high = |m: &TriMesh| m.positions.iter().map(|p| p[1]).fold(f64::MIN, f64::max);
        assert!(low(&last) < low(&mesh) - 1e-6, "{material}");
        assert!((high(&last) - high(&mesh)).abs() < 1e-12);
        let csv = std::fs::read_to_string(out_dir.join("energy.csv")).unwrap();
        assert_eq!(csv.lines().count(), 21);
    }
    assert_eq!(std::fs::read(&path).unwrap(), before, "input modified");
    let bad = wscg()
        .args(["cloth", "simulate", "--pin", "999", "--mesh"])
        .arg(&path)
        .arg("--out")
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("pin"));

    // A floor above the sheet's bottom row pushes it up to floor + thickness.
    let o = std::ffi::OsStr::new;
    let floor_dir = dir.path().join("floor");
    wscg_ok(&[
        o("cloth"),
        o("simulate"),
        o("--frames"),
        o("5"),
        o("--floor"),
        o("0.05"),
        o("--thickness"),
        o("0.01"),
        o("--sphere"),
        o("0.5,-3,0,0.2"),
        o("--mesh"),
        path.as_os_str(),
        o("--out"),
        floor_dir.as_os_str(),
    ]);
    let last = TriMesh::read(floor_dir.join("frame_0004.obj")).unwrap();
    let low = last.positions.iter().map(|p| p[1]).fold(f64::MAX, f64::min);
    assert!(low >= 0.06 - 1e-9, "{low}");
    for extra in [
        ["--sphere", "0,0,0,-1"],
        ["--collider", "/nonexistent/body.obj"],
        ["--thickness", "0"],
    ] {
        let bad = wscg()
            .args(["cloth", "simulate", "--frames", "2", "--mesh"])
            .arg(&path)
            .arg("--out")
            .arg(&floor_dir)
            .args(extra)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&bad.stderr);
        assert!(!bad.status.success(), "{extra:?}");
        assert!(!err.contains("panicked"), "{extra:?}: {err}");
    }
}

#[test]
fn volren_serve_and_view_a_roi() {
    use std::io::BufRead;
    let dir = tempfile::tempdir().unwrap();
    let vol = wscg::volren::phantoms::head([64, 64, 32], 3).unwrap();
    let npy = dir.path().join("head.npy");
    vol.map(|d| d as f32).write_npy(&npy).unwrap();
    let tf = dir.path().join("tf.json");
    std::fs::write(
        &tf,
        r#"{"canonical": 0, "tfs": [
            [[30, 0.9, 0.6, 0.5, 0.0], [60, 0.9, 0.6, 0.5, 0.05], [110, 0.9, 0.6, 0.5, 0.05],
             [120, 0.9, 0.6, 0.5, 0.0]],
            [[180, 1, 1, 0.9, 0.0], [255, 1, 1, 0.9, 0.8]]]}"#,
    )
    .unwrap();
    let before = std::fs::read(&npy).unwrap();
    // In-process server.
    let local = dir.path().join("local.png");
    let (v, t, o) = (
        npy.to_str().unwrap(),
        tf.to_str().unwrap(),
        local.to_str().unwrap(),
    );
    let out = wscg_ok(&[
        "volren",
        "roi-view",
        "--volume",
        v,
        "--tf",
        t,
        "--roi",
        "16:48,16:48,0:32",
        "--size",
        "48",
        "--out",
        o,
    ]);
    assert!(out.contains("ROI package"), "{out}");
    assert_eq!(
        wscg::math::Image::load(&local).unwrap().shape(),
        (48, 48, 3)
    );
    // A real server on a free port, one connection.
    let mut child = wscg()
        .args([
            "volren",
            "roi-serve",
            "--volume",
            v,
            "--tf",
            t,
            "--addr",
            "127.0.0.1:0",
        ])
        .args(["--connections", "1"])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let addr = line
        .trim()
        .strip_prefix("listening on ")
        .unwrap()
        .to_string();
    let remote = dir.path().join("remote.png");
    wscg_ok(&[
        "volren",
        "roi-view",
        "--server",
        &addr,
        "--roi",
        "16:48,16:48,0:32",
        "--size",
        "48",
        "--out",
        remote.to_str().unwrap(),
    ]);
    assert!(child.wait().unwrap().success());
    assert_eq!(
        wscg::math::Image::load(&remote).unwrap(),
        wscg::math::Image::load(&local).unwrap(),
        "served and local images differ"
    );
    assert_eq!(std::fs::read(&npy).unwrap(), before, "input modified");
    // Bad input: a malformed ROI, a ROI outside the volume, a broken TF file, no TF.
    std::fs::write(dir.path().join("bad.json"), "{\"tfs\": [[[10, 1, 1]]]}").unwrap();
    let bad_tf = dir.path().join("bad.json");
    for extra in [
        vec!["--tf", t, "--roi", "1:2:3"],
        vec!["--tf", t, "--roi", "200:300,0:10,0:10"],
        vec!["--tf", bad_tf.to_str().unwrap()],
        vec![],
    ] {
        let out = wscg()
            .args(["volren", "roi-view", "--volume", v, "--out", o])
            .args(&extra)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{extra:?}");
        assert!(
            err.contains("error") && !err.contains("panicked"),
            "{extra:?}: {err}"
        );
    }
}

#[test]
fn meshfilter_denoises_a_coloured_mesh() {
    use wscg::meshfilter::metrics::{mean_error, mean_vertex_distance};
    use wscg::meshfilter::synth::{add_noise, colored_cube, NOISE_SEED};
    let dir = tempfile::tempdir().unwrap();
    let clean = colored_cube(12).unwrap();
    let mvd = mean_vertex_distance(&clean).unwrap();
    let noisy = add_noise(&clean, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let input = dir.path().join("noisy.ply");
    noisy.write(&input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let noisy_me = mean_error(
        &wscg::math::TriMesh::read(&input).unwrap().positions,
        &clean.positions,
    )
    .unwrap();
    let read_back = wscg::math::TriMesh::read(&input).unwrap();
    let expected = |method: &str| -> Vec<[f64; 3]> {
        use wscg::meshfilter::{bmd, smoothing, JbmdParams};
        let m = &read_back;
        match method {
            "jbmd" => wscg::meshfilter::jbmd(
                m,
                &(JbmdParams::from_mvd(mean_vertex_distance(m).unwrap())).iterations(5),
            ),
            "bmd" => {
                let d = mean_vertex_distance(m).unwrap();
                bmd::bmd(
                    m,
                    &bmd::BmdParams::default()
                        .sigma_c(d)
                        .sigma_s(0.5 * d)
                        .iterations(5)
                        .volume_preserve(false),
                )
            }
            "laplacian" => smoothing::laplacian(m, 0.5, 5),
            "taubin" => smoothing::taubin(m, 0.5, -0.53, 5),
            _ => smoothing::hc_laplacian(m, 0.0, 0.5, 5),
        }
        .unwrap()
    };
    for method in ["jbmd", "bmd", "laplacian", "taubin", "hc"] {
        let out = dir.path().join(format!("{method}.ply"));
        let o = std::ffi::OsStr::new;
        wscg_ok(&[
            o("meshfilter"),
            o("denoise"),
            o("--mesh"),
            input.as_os_str(),
            o("--out"),
            out.as_os_str(),
            o("--method"),
            o(method),
            o("--iterations"),
            o("5"),
        ]);
        let got = wscg::math::TriMesh::read(&out).unwrap();
        assert_eq!(got.num_faces(), clean.num_faces());
        assert!(got.colors.is_some(), "{method}: colours dropped");
        // The command runs the library's method with the documented defaults.
        for (a, b) in got.positions.iter().zip(expected(method)) {
            assert!(
                (0..3).all(|k| (a[k] - b[k]).abs() < 1e-6),
                "{method}: {a:?} vs {b:?}"
            );
        }
        if method == "jbmd" {
            let me = mean_error(&got.positions, &clean.positions).unwrap();
            assert!(me < 0.7 * noisy_me, "{me} vs {noisy_me}");
        }
    }
    assert_eq!(std::fs::read(&input).unwrap(), before, "input modified");
    let bad = wscg()
        .args(["meshfilter", "denoise", "--mesh"])
        .arg(&input)
        .args(["--out", "/tmp/x.ply", "--k", "0"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && err.contains('k') && !err.contains("panicked"),
        "{err}"
    );
}

#[test]
fn sfa_generate_fit_predict_evaluate_match_the_library() {
    use wscg::biometrics::sfa::handpose::{downscale, generate, HandposeSynthParams};
    use wscg::biometrics::sfa::{ClassSfaParams, PerClassSfa};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let data_dir = d.join("hands");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    wscg_ok(&[
        "biometrics",
        "sfa",
        "generate",
        "--out",
        &s(&data_dir),
        "--n-per-class",
        "120",
        "--png",
        "2",
    ]);
    let (masks, labels) = (data_dir.join("masks.npy"), data_dir.join("labels.npy"));
    assert!(data_dir.join("png/OPEN").is_dir());
    let model = d.join("m.json");
    wscg_ok(&[
        "biometrics",
        "sfa",
        "fit",
        "--npy",
        &s(&masks),
        "--labels",
        &s(&labels),
        "--pca-dims",
        "8",
        "--m",
        "3",
        "--out",
        &s(&model),
    ]);
    let before = std::fs::read(&masks).unwrap();
    let out = wscg_ok(&[
        "biometrics",
        "sfa",
        "predict",
        "--model",
        &s(&model),
        "--npy",
        &s(&masks),
    ]);
    assert_eq!(std::fs::read(&masks).unwrap(), before, "input modified");
    // The same model through the library: generated frames, downscaled by 3.
    let data = generate(&HandposeSynthParams::default().n_per_class(120)).unwrap();
    let rows: Vec<f64> = (0..data.len())
        .flat_map(|i| downscale(data.mask(i).unwrap(), 3).unwrap().into_data())
        .collect();
    let x = wscg::biometrics::sfa::handpose::protocol::rows_to_mat(&rows, rows.len() / data.len());
    let cfg = ClassSfaParams::default().pca_dims(8).m_per_class(3);
    let lib = PerClassSfa::fit(x.as_ref(), &data.labels, &cfg).unwrap();
    let want = lib.predict(x.as_ref()).unwrap();
    let got: Vec<u32> = out
        .lines()
        .skip(1)
        .map(|l| l.split('\t').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(got, want);
    let eval = wscg_ok(&[
        "biometrics",
        "sfa",
        "evaluate",
        "--npy",
        &s(&masks),
        "--labels",
        &s(&labels),
        "--test-per-class",
        "20",
        "--augment-per-class",
        "20",
        "--pca-dims",
        "8",
        "--m",
        "3",
        "--methods",
        "sfa",
        "pca",
        "global",
        "--rotated",
    ]);
    assert!(
        eval.contains("Table 3: class-wise SFA") && eval.contains("Table 5"),
        "{eval}"
    );
    assert!(eval.contains("rotated by"), "{eval}");
    // Bad input: rows where images are expected, a missing file, too many functions.
    for args in [
        vec![
            "evaluate",
            "--npy",
            "missing.npy",
            "--labels",
            "missing.npy",
        ],
        vec![
            "fit",
            "--npy",
            &s(&masks),
            "--labels",
            &s(&labels),
            "--m",
            "1000",
            "--out",
            "x.json",
        ],
        vec!["predict", "--model", &s(&masks), "--npy", &s(&masks)],
        vec!["generate", "--out", &s(&d.join("g")), "--n-per-class", "0"],
    ] {
        let out = wscg()
            .args(["biometrics", "sfa"])
            .args(&args)
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("error") && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn video_synth_complete_measure() {
    let dir = tempfile::tempdir().unwrap();
    let clip = dir.path().join("clip");
    wscg_ok(&[
        "video",
        "synth",
        "--out",
        clip.to_str().unwrap(),
        "--kind",
        "pan",
        "--frames",
        "10",
        "--width",
        "160",
        "--height",
        "96",
    ]);
    let frames = clip.join("frames");
    let before: Vec<Vec<u8>> = (0..10)
        .map(|t| std::fs::read(frames.join(format!("frame_{t:05}.png"))).unwrap())
        .collect();
    let done = dir.path().join("done");
    wscg_ok(&[
        "video",
        "complete",
        frames.to_str().unwrap(),
        clip.join("mask").to_str().unwrap(),
        "--out",
        done.to_str().unwrap(),
    ]);
    // Inputs untouched, outputs complete and close to the ground truth in the hole.
    for (t, b) in before.iter().enumerate() {
        assert_eq!(
            &std::fs::read(frames.join(format!("frame_{t:05}.png"))).unwrap(),
            b
        );
    }
    let ssim_of = |done: &std::path::Path| {
        let report = wscg_ok(&[
            "video",
            "measure",
            done.to_str().unwrap(),
            clip.join("truth").to_str().unwrap(),
            clip.join("mask").to_str().unwrap(),
        ]);
        let ssim: f64 = report
            .lines()
            .next()
            .unwrap()
            .split_whitespace()
            .last()
            .unwrap()
            .parse()
            .unwrap();
        assert!(ssim > 0.9, "{report}");
    };
    ssim_of(&done);
    // Stage 3's optional raster-scan propagation.
    let scanned = dir.path().join("scanned");
    wscg_ok(&[
        "video",
        "complete",
        frames.to_str().unwrap(),
        clip.join("mask").to_str().unwrap(),
        "--scan-propagation",
        "--out",
        scanned.to_str().unwrap(),
    ]);
    ssim_of(&scanned);
    // A missing mask and a mask of the wrong size are clear errors.
    let out = wscg()
        .args([
            "video",
            "complete",
            frames.to_str().unwrap(),
            "nowhere.png",
            "--out",
        ])
        .arg(dir.path().join("x"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("nowhere.png"));
    let small = dir.path().join("small.png");
    Image::filled(8, 8, 1, 1.0f32)
        .unwrap()
        .save(&small)
        .unwrap();
    let out = wscg()
        .args([
            "video",
            "complete",
            frames.to_str().unwrap(),
            small.to_str().unwrap(),
            "--out",
        ])
        .arg(dir.path().join("y"))
        .output()
        .unwrap();
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("mask of 8 x 8"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A file that is not a video (decoded by ffmpeg when present) is a clear error either way.
    let not_video = dir.path().join("clip.mp4");
    std::fs::write(&not_video, b"not a video").unwrap();
    let out = wscg()
        .args([
            "video",
            "complete",
            not_video.to_str().unwrap(),
            small.to_str().unwrap(),
            "--out",
        ])
        .arg(dir.path().join("z"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("ffmpeg") && err.contains("clip.mp4"), "{err}");
}

#[test]
fn raytrace_paint_writes_a_stereo_pair_and_doe_fits_a_surface() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plate.png");
    let args = [
        "raytrace",
        "paint",
        "--eye",
        "pair",
        "--region",
        "-2",
        "-2",
        "2",
        "2",
        "--magnification",
        "4",
        "--spp",
        "4",
        "--light-elevation",
        "75",
        "--light-deg",
        "3",
        "--out",
    ];
    let mut a: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    a.push(out.display().to_string());
    let text = wscg_ok(&a);
    assert!(text.contains("flakes glinting directly"), "{text}");
    let l = Image::<f32>::load(dir.path().join("plate_left.png")).unwrap();
    let r = Image::<f32>::load(dir.path().join("plate_right.png")).unwrap();
    assert_eq!((l.height(), l.width()), (58, 58));
    // Same plate, different eyes: the glints differ in places.
    assert!(l.data().iter().any(|&v| v > 0.5));
    assert_ne!(l.data(), r.data());

    // A surface with a known minimum at (-0.25, 0.1) is recovered exactly.
    let design = wscg_ok(&["doe", "design"]);
    assert_eq!(design, wscg_ok(&["doe", "ccd"]));
    let mut csv = String::from("x1,x2,y\n");
    for line in design.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        let y = 2.0 + 4.0 * (v[0] + 0.25).powi(2) + (v[1] - 0.1).powi(2);
        csv.push_str(&format!("{},{},{y}\n", v[0], v[1]));
    }
    let path = dir.path().join("runs.csv");
    std::fs::write(&path, csv).unwrap();
    let fit = wscg_ok(&["doe", "fit", path.to_str().unwrap()]);
    assert!(fit.contains("R2 1.0000"), "{fit}");
    assert!(fit.contains("stationary point [-0.25"), "{fit}");
    // Unreadable input is a clear error, not a crash.
    let bad = wscg()
        .args(["doe", "fit", "/nonexistent/runs.csv"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("nonexistent"));
}

#[test]
fn raytrace_paint_reads_a_paint_description_and_writes_exr() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("paint.json");
    std::fs::write(
        &json,
        r#"{"radius_um": 26, "density": 0.7, "base_albedo": 0.5, "coat_um": 30}"#,
    )
    .unwrap();
    let before = std::fs::read(&json).unwrap();
    let render = |name: &str, photons: &str| {
        let out = dir.path().join(name);
        let a = [
            "raytrace",
            "paint",
            "--paint",
            json.to_str().unwrap(),
            "--region",
            "-1",
            "-1",
            "1",
            "1",
            "--magnification",
            "4",
            "--spp",
            "4",
            "--photons",
            photons,
            "--exr",
            "--spectral",
            "--out",
            out.to_str().unwrap(),
        ];
        wscg_ok(&a);
        out
    };
    let with = render("with.png", "200000");
    let without = render("without.png", "0");
    for stem in ["with", "without"] {
        for ext in [".png", ".exr", "_spectral.exr"] {
            assert!(
                dir.path().join(format!("{stem}{ext}")).is_file(),
                "{stem}{ext}"
            );
        }
    }
    // The diffuse base gets the flakes' caustics only with photons.
    let mean = |p: &std::path::Path| {
        let img = Image::<f32>::load(p).unwrap();
        img.data().iter().map(|&v| v as f64).sum::<f64>() / img.data().len() as f64
    };
    assert!(mean(&with) > mean(&without));
    assert_eq!(std::fs::read(&json).unwrap(), before);
    // An unknown key is named.
    std::fs::write(&json, r#"{"radius": 26}"#).unwrap();
    let bad = wscg()
        .args([
            "raytrace",
            "paint",
            "--paint",
            json.to_str().unwrap(),
            "--out",
        ])
        .arg(dir.path().join("x.png"))
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("radius"));
}

#[test]
fn raytrace_manylight_compares_the_methods_and_reads_obj() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cornell.exr");
    let text = wscg_ok(&[
        "raytrace",
        "manylight",
        "--scene",
        "cornell",
        "--width",
        "32",
        "--height",
        "24",
        "--vpl-paths",
        "100",
        "--n-cache",
        "20",
        "--compare",
        "--out",
        out.to_str().unwrap(),
    ]);
    for m in ["reference", "adaptive", "adaptive_uniform", "ic", "power"] {
        assert!(text.contains(m), "{text}");
        let f = dir.path().join(format!("cornell_{m}.exr"));
        let img = Image::<f32>::load(&f).unwrap();
        assert_eq!((img.height(), img.width()), (24, 32));
    }
    // A user OBJ: a floor under an emissive quad, rendered to PNG.
    let obj = dir.path().join("room.obj");
    std::fs::write(
        dir.path().join("room.mtl"),
        "newmtl lamp\nKd 0.5 0.5 0.5\nKe 4 4 4\nnewmtl floor\nKd 0.6 0.6 0.6\n",
    )
    .unwrap();
    std::fs::write(
        &obj,
        "mtllib room.mtl\nv -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\nv -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\nusemtl floor\nf 1 3 2\nf 1 4 3\nusemtl lamp\nf 5 6 7\nf 5 7 8\n",
    )
    .unwrap();
    let png = dir.path().join("room.png");
    let text = wscg_ok(&[
        "raytrace",
        "manylight",
        obj.to_str().unwrap(),
        "--eye",
        "0",
        "6",
        "-8",
        "--target",
        "0",
        "0",
        "0",
        "--width",
        "32",
        "--height",
        "24",
        "--vpl-paths",
        "50",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(text.contains("4 triangles (2 emitting)"), "{text}");
    let img = Image::<f32>::load(&png).unwrap();
    assert!(img.data().iter().any(|&v| v > 0.1));
    // Unreadable scene and bad parameters are clear errors.
    let bad = wscg()
        .args(["raytrace", "manylight", "/nonexistent/scene.obj", "--out"])
        .arg(dir.path().join("x.exr"))
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("scene.obj"));
    let bad = wscg()
        .args([
            "raytrace",
            "manylight",
            "--spp",
            "0",
            "--width",
            "8",
            "--height",
            "6",
            "--out",
        ])
        .arg(dir.path().join("x.exr"))
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("spp"));
    for (flag, value, named) in [
        ("--filter", "gauss", "filter"),
        ("--defensive", "2", "defensive"),
        ("--pixel-samples", "0", "pixel_samples"),
        ("--near-share", "1", "near_share"),
        ("--near-vpls", "0", "near_vpls"),
    ] {
        let bad = wscg()
            .args(["raytrace", "manylight", flag, value, "--width", "8"])
            .args(["--height", "6", "--out"])
            .arg(dir.path().join("x.exr"))
            .output()
            .unwrap();
        assert!(!bad.status.success());
        assert!(
            String::from_utf8_lossy(&bad.stderr).contains(named),
            "{flag}"
        );
    }
    // The paper's setting: its weights, one ray through each pixel centre.
    let paper = dir.path().join("paper.exr");
    wscg_ok(&[
        "raytrace",
        "manylight",
        "--width",
        "16",
        "--height",
        "12",
        "--vpl-paths",
        "50",
        "--defensive",
        "0",
        "--filter",
        "center",
        "--out",
        paper.to_str().unwrap(),
    ]);
    assert!(paper.exists());
}

#[test]
fn doe_analyze_reads_a_study_and_rejects_missing_cells() {
    // 6 subjects, two conditions, the paper's 13 stimuli; scores from the paper's Table 2
    // surfaces plus a subject offset and a small deterministic jitter.
    let design = wscg_ok(&["doe", "design"]);
    let runs: Vec<Vec<f64>> = design
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    let surfaces = [
        ("mono", [2.723, -0.590, -0.794, 6.003, 1.810]),
        ("stereo", [2.423, -0.730, -0.516, 5.323, 1.822]),
    ];
    let mut csv = String::from("subject,condition,stimulus,score\n");
    for s in 0..6 {
        for (name, b) in &surfaces {
            for (k, x) in runs.iter().enumerate() {
                let y = b[0] + b[1] * x[0] + b[2] * x[1] + b[3] * x[0] * x[0] + b[4] * x[1] * x[1];
                let jitter = 0.05 * (((s * 7 + k * 3) % 5) as f64 - 2.0);
                csv.push_str(&format!(
                    "s{s},{name},{k},{}\n",
                    y + 0.3 * s as f64 + jitter
                ));
            }
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scores.csv");
    std::fs::write(&path, &csv).unwrap();
    let out = wscg_ok(&["doe", "analyze", path.to_str().unwrap()]);
    assert!(out.contains("6 subjects"), "{out}");
    assert!(
        out.contains("condition mono") && out.contains("condition stereo"),
        "{out}"
    );
    assert!(out.contains("repeated-measures ANOVA"), "{out}");
    // The panel means carry the Table 2 surface (plus the mean subject offset 0.75):
    // b11 of the monoscopic fit is 6.003 up to the jitter.
    let mono = out.split("condition stereo").next().unwrap();
    let b11: f64 = mono
        .lines()
        .find(|l| l.starts_with("b11 "))
        .unwrap()
        .split_whitespace()
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    assert!((b11 - 6.003).abs() < 0.1, "{b11}");
    // Remove one score: the missing cell is named.
    let cut: String = csv
        .lines()
        .filter(|l| !l.starts_with("s3,stereo,7,"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&path, cut).unwrap();
    let bad = wscg()
        .args(["doe", "analyze", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("missing cell: subject s3, condition stereo, stimulus 7"),
        "{err}"
    );
}

#[test]
fn isosurface_extract_and_study_on_a_volume_with_missing_samples() {
    use wscg::isosurface::{fields, marching_cubes, random_dropouts, NormalMethod};
    use wscg::math::{TriMesh, Volume};
    let dir = tempfile::tempdir().unwrap();
    let (_, s) = fields::named("sphere", 32).unwrap();
    let mut values = s.values.clone();
    random_dropouts(&mut values, 0.05, 4).unwrap();
    // Missing samples marked by -999 in the file.
    let marked: Vec<f32> = values
        .iter()
        .map(|v| if v.is_nan() { -999.0 } else { *v })
        .collect();
    let vol = Volume::new(s.dims, [1.0, 1.0, 1.0], marked).unwrap();
    let path = dir.path().join("sphere.npy");
    vol.write_npy(&path).unwrap();
    let before = std::fs::read(&path).unwrap();
    let out = dir.path().join("mesh.ply");
    let text = wscg_ok(&[
        "isosurface",
        "extract",
        path.to_str().unwrap(),
        "--iso",
        "0",
        "--missing",
        "-999",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(text.contains("0 undefined"), "{text}");
    assert_eq!(std::fs::read(&path).unwrap(), before, "input untouched");
    let mesh = TriMesh::read(&out).unwrap();
    let g = wscg::isosurface::ScalarGrid::new(s.dims, &values).unwrap();
    let lib = marching_cubes(&g, 0.0, NormalMethod::spline()).unwrap();
    assert_eq!(mesh.num_vertices(), lib.vertices.len());
    assert_eq!(mesh.num_faces(), lib.triangles.len());
    assert_eq!(
        mesh.normals.as_ref().map(|n| n.len()),
        Some(lib.vertices.len())
    );
    let text = wscg_ok(&[
        "isosurface",
        "study",
        path.to_str().unwrap(),
        "--isovalues",
        "3",
    ]);
    assert!(text.contains("mean RMS over"), "{text}");
    // A bad normals name is refused with a message.
    let bad = wscg()
        .args([
            "isosurface",
            "extract",
            path.to_str().unwrap(),
            "--iso",
            "0",
        ])
        .args(["--normals", "sobel", "--out", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("sobel"));
}

#[test]
fn octree_build_info_render_on_a_mesh_file() {
    use wscg::math::TriMesh;
    use wscg::octree::{build, render, scenes, BuildParams, HybridOctree, Shading, TraceMode};
    let dir = tempfile::tempdir().unwrap();
    let mesh = scenes::blob(3).unwrap();
    let obj = dir.path().join("blob.obj");
    mesh.write_obj(&obj).unwrap();
    let before = std::fs::read(&obj).unwrap();
    let tree = dir.path().join("blob.oct");
    let text = wscg_ok(&[
        "octree",
        "build",
        obj.to_str().unwrap(),
        "--depth",
        "7",
        "--out",
        tree.to_str().unwrap(),
    ]);
    assert!(
        text.contains("early stop") && text.contains("memory (MB)"),
        "{text}"
    );
    assert_eq!(std::fs::read(&obj).unwrap(), before, "input untouched");
    // The saved tree is the library's tree of the mesh as read back from the file.
    let read = TriMesh::read(&obj).unwrap();
    let (lib, _) = build(&read, &BuildParams::default().max_depth(7)).unwrap();
    let saved = HybridOctree::load(&tree).unwrap();
    assert_eq!(saved, lib);
    let text = wscg_ok(&["octree", "info", tree.to_str().unwrap()]);
    assert!(
        text.contains(&format!("{} nodes", lib.nodes.len())),
        "{text}"
    );
    let png = dir.path().join("view.png");
    let text = wscg_ok(&[
        "octree",
        "render",
        tree.to_str().unwrap(),
        "--mode",
        "triangles",
        "--size",
        "64x48",
        "--camera",
        "1.5,-1.2,0.8,0,0,0",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(text.contains("triangle hits"), "{text}");
    let img = Image::load(&png).unwrap();
    assert_eq!(img.shape().0, 48);
    // The same picture from the library (8-bit PNG quantization aside).
    let cam = wscg::octree::Camera {
        eye: [1.5, -1.2, 0.8],
        target: [0.0; 3],
        up: [0.0, 0.0, 1.0],
        fov_y_deg: 45.0,
        width: 64,
        height: 48,
    };
    let light = scenes::default_light(&lib.cube);
    let (ours, _) = render(
        &lib,
        &cam,
        &light,
        &TraceMode::Triangles,
        &Shading::default(),
    )
    .unwrap();
    let diff = ours
        .data()
        .iter()
        .zip(img.data())
        .map(|(a, b)| (a.clamp(0.0, 1.0) - b).abs())
        .fold(0.0f32, f32::max);
    assert!(diff <= 1.0 / 255.0 + 1e-4, "max difference {diff}");
    let lod = dir.path().join("lod.png");
    wscg_ok(&[
        "octree",
        "render",
        tree.to_str().unwrap(),
        "--lod-map",
        "--size",
        "32x32",
        "--out",
        lod.to_str().unwrap(),
    ]);
    // A damaged tree file and a bad mode are errors with messages.
    let mut bytes = std::fs::read(&tree).unwrap();
    let n = bytes.len();
    bytes[n / 2] ^= 4;
    let bad = dir.path().join("bad.oct");
    std::fs::write(&bad, &bytes).unwrap();
    let out = wscg()
        .args(["octree", "info", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("checksum"));
    let out = wscg()
        .args([
            "octree",
            "render",
            tree.to_str().unwrap(),
            "--mode",
            "cones",
            "--out",
            png.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("cones"));
}

#[test]
fn mri_mask_phantom_recon_on_files() {
    use wscg::csmri::{
        csalsa, metrics, sparsifier, CsalsaParams, FdctParams, FdctSparsifier, Finest, KSpace,
        Regularizer, UdctParams, UdctSparsifier,
    };
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    // `wscg mri recon DIR/k --mask DIR/m` followed by `rest`.
    let recon = |k: &str, m: &str, rest: &[&str]| -> Vec<String> {
        let mut v = vec![
            "mri".to_string(),
            "recon".into(),
            p(k),
            "--mask".into(),
            p(m),
        ];
        v.extend(rest.iter().map(|s| s.to_string()));
        v
    };
    let text = wscg_ok(&[
        "mri",
        "mask",
        "--cartesian",
        "0.4",
        "--size",
        "64x64",
        "--out",
        &p("m.npy"),
    ]);
    assert!(text.contains("Cartesian"), "{text}");
    wscg_ok(&[
        "mri",
        "mask",
        "--cartesian",
        "0.4",
        "--size",
        "64x64",
        "--out",
        &p("m.png"),
    ]);
    let text = wscg_ok(&[
        "mri",
        "mask",
        "--radial",
        "0.3",
        "--size",
        "64x64",
        "--out",
        &p("r.png"),
    ]);
    assert!(text.contains("pseudo-radial"), "{text}");
    wscg_ok(&[
        "mri",
        "phantom",
        "--size",
        "64",
        "--out",
        &p("k.npy"),
        "--reference",
        &p("ref.npy"),
    ]);
    let before = std::fs::read(p("k.npy")).unwrap();
    // The centred PNG mask and the un-shifted .npy mask are the same mask.
    let a = wscg_ok(&recon(
        "k.npy",
        "m.npy",
        &[
            "--iters",
            "15",
            "--reference",
            &p("ref.npy"),
            "--out",
            &p("a.npy"),
        ],
    ));
    wscg_ok(&recon(
        "k.npy",
        "m.png",
        &["--iters", "15", "--out", &p("b.npy")],
    ));
    assert!(a.contains("PSNR"), "{a}");
    let xa = wscg::math::npy::read_complex(p("a.npy")).unwrap();
    let xb = wscg::math::npy::read_complex(p("b.npy")).unwrap();
    assert_eq!(xa.shape, vec![64, 64]);
    assert_eq!(xa.data, xb.data);
    assert_eq!(std::fs::read(p("k.npy")).unwrap(), before);
    // The same reconstruction as the library's.
    let k = wscg::math::npy::read_complex(p("k.npy")).unwrap();
    let m: Vec<bool> = wscg::math::npy::read::<f64>(p("m.npy"))
        .unwrap()
        .data
        .iter()
        .map(|&v| v != 0.0)
        .collect();
    let data = KSpace::new(64, 64, k.data, m).unwrap();
    // What the library gives for the same prior and iterations.
    let library = |psi: &dyn wscg::csmri::Sparsifier, max_iter: usize, tau0: f64| {
        let params = CsalsaParams::default().max_iter(max_iter).tau0(tau0);
        let noop = wscg::math::progress::NoProgress;
        csalsa(&data, psi, Regularizer::default(), &params, None, &noop)
            .unwrap()
            .image
    };
    let udct = UdctSparsifier::new(64, 64, &UdctParams::default()).unwrap();
    let want = library(&udct, 15, sparsifier::tuned_tau0("udct"));
    let diff = metrics::rlne(&want, &xa.data).unwrap();
    assert!(diff < 1e-12, "{diff}");
    // The FDCT prior (curvelets at the finest scale) at its tuned tau0.
    wscg_ok(&recon(
        "k.npy",
        "m.npy",
        &[
            "--prior",
            "fdct",
            "--fdct-finest",
            "curvelets",
            "--iters",
            "10",
            "--out",
            &p("fd.npy"),
        ],
    ));
    let fdct =
        FdctSparsifier::new(64, 64, &FdctParams::default().finest(Finest::Curvelets)).unwrap();
    let want = library(&fdct, 10, sparsifier::tuned_tau0("fdct"));
    let got = wscg::math::npy::read_complex(p("fd.npy")).unwrap();
    let diff = metrics::rlne(&want, &got.data).unwrap();
    assert!(diff < 1e-12, "{diff}");
    // The MRSFLCT prior with two scales at its tuned tau0.
    wscg_ok(&recon(
        "k.npy",
        "m.npy",
        &[
            "--prior",
            "mrsflct",
            "--sflct-levels",
            "2,3",
            "--iters",
            "8",
            "--out",
            &p("sf.npy"),
        ],
    ));
    let mr = sparsifier::by_name(
        "mrsflct",
        64,
        64,
        &sparsifier::PriorParams::default().sflct_levels(vec![2, 3]),
    )
    .unwrap();
    let want = library(mr.as_ref(), 8, sparsifier::tuned_tau0("mrsflct"));
    let got = wscg::math::npy::read_complex(p("sf.npy")).unwrap();
    let diff = metrics::rlne(&want, &got.data).unwrap();
    assert!(diff < 1e-12, "{diff}");
    // Baselines, NIfTI and PNG outputs.
    wscg_ok(&recon(
        "k.npy",
        "m.npy",
        &["--method", "fcsa", "--iters", "5", "--out", &p("f.nii.gz")],
    ));
    wscg_ok(&recon(
        "k.npy",
        "m.npy",
        &["--reg", "tv", "--iters", "5", "--out", &p("t.png")],
    ));
    assert!(Image::load(p("t.png")).is_ok());
    assert!(wscg::math::Volume::<f32>::read_nifti(p("f.nii.gz")).is_ok());
    // Bad input: wrong mask size, unknown method, unreadable k-space.
    wscg_ok(&[
        "mri",
        "mask",
        "--cartesian",
        "0.4",
        "--size",
        "32x32",
        "--out",
        &p("small.npy"),
    ]);
    for args in [
        recon("k.npy", "small.npy", &["--out", &p("x.npy")]),
        recon(
            "k.npy",
            "m.npy",
            &["--method", "sense", "--out", &p("x.npy")],
        ),
        recon("missing.npy", "m.npy", &["--out", &p("x.npy")]),
        recon(
            "k.npy",
            "m.npy",
            &[
                "--prior",
                "fdct",
                "--fdct-finest",
                "ridgelets",
                "--out",
                &p("x.npy"),
            ],
        ),
        recon(
            "k.npy",
            "m.npy",
            &[
                "--prior",
                "lrsflct",
                "--sflct-levels",
                "3,x",
                "--out",
                &p("x.npy"),
            ],
        ),
    ] {
        let out = wscg().args(&args).output().unwrap();
        assert!(!out.status.success(), "{args:?}");
        assert!(!String::from_utf8_lossy(&out.stderr).is_empty());
    }
}

#[test]
fn deblur_simulate_kernel_and_frames_on_files() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    // A sharp image to shake.
    wscg::deblur::synth::scene(96, 128, 3)
        .unwrap()
        .save(p("sharp_in.png"))
        .unwrap();
    let text = wscg_ok(&[
        "deblur",
        "simulate",
        &p("sharp_in.png"),
        "--frames",
        "3",
        "--seed",
        "4",
        "--out-dir",
        &p("burst"),
    ]);
    assert!(text.contains("wrote 3 frames"), "{text}");
    let gyro = p("burst/gyro.csv");
    let text = wscg_ok(&[
        "deblur",
        "kernel",
        "--gyro",
        &gyro,
        "--camera",
        &p("burst/camera.json"),
        "--time",
        "0.1",
        "--at",
        "64,48",
        "--width",
        "128",
        "--height",
        "96",
        "--out",
        &p("k.png"),
    ]);
    assert!(text.contains("blurriness"), "{text}");
    // One frame, files and flags.
    let frames: Vec<String> = (0..3)
        .map(|i| p(&format!("burst/frames/frame_{i:02}.png")))
        .collect();
    let mut args: Vec<String> = vec!["deblur".into(), "frames".into()];
    args.extend(frames.iter().cloned());
    args.extend(
        [
            "--gyro",
            &gyro,
            "--f",
            "600",
            "--delay",
            "0.015",
            "--times",
            &p("burst/frames/times.txt"),
            "--reference",
            &p("burst/sharp.png"),
            "--out",
            &p("out.png"),
        ]
        .map(String::from),
    );
    let text = wscg_ok(&args);
    let psnr = |line: &str| -> f64 {
        let l = text.lines().find(|l| l.starts_with(line)).unwrap();
        l.split("PSNR ")
            .nth(1)
            .unwrap()
            .split(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    assert!(psnr("result") > psnr("blurry input") + 1.0, "{text}");
    let out = Image::load(p("out.png")).unwrap();
    assert_eq!((out.height(), out.width()), (96, 128));
    // Every frame of the folder, camera file, times.txt found in the folder.
    let text = wscg_ok(&[
        "deblur",
        "frames",
        &p("burst/frames"),
        "--gyro",
        &gyro,
        "--camera",
        &p("burst/camera.json"),
        "--out",
        &p("sharp"),
    ]);
    assert_eq!(text.matches("wrote").count(), 3, "{text}");
    for i in 0..3 {
        let img = Image::load(p(&format!("sharp/frame_{i:02}.png"))).unwrap();
        assert_eq!((img.height(), img.width()), (96, 128));
    }
    // Bad input: missing gyro file, missing intrinsics, mismatched times, unknown method.
    let run_err = |args: &[&str]| -> String {
        let out = wscg().args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    assert!(run_err(&[
        "deblur",
        "frames",
        &frames[0],
        "--gyro",
        &p("nope.csv"),
        "--f",
        "600",
        "--times",
        "0.1",
        "--out",
        &p("x.png")
    ])
    .contains("nope.csv"));
    assert!(run_err(&[
        "deblur",
        "frames",
        &frames[0],
        "--gyro",
        &gyro,
        "--times",
        "0.1",
        "--out",
        &p("x.png")
    ])
    .contains("intrinsics missing"));
    assert!(run_err(&[
        "deblur",
        "frames",
        &frames[0],
        "--gyro",
        &gyro,
        "--f",
        "600",
        "--times",
        "0.1,0.2",
        "--out",
        &p("x.png")
    ])
    .contains("time stamps"));
    assert!(run_err(&[
        "deblur",
        "frames",
        &frames[0],
        "--gyro",
        &gyro,
        "--f",
        "600",
        "--out",
        &p("x.png")
    ])
    .contains("times missing"));
    assert!(run_err(&[
        "deblur",
        "frames",
        &frames[0],
        "--gyro",
        &gyro,
        "--f",
        "600",
        "--times",
        "0.1",
        "--method",
        "magic",
        "--out",
        &p("x.png")
    ])
    .contains("valid methods"));
}

#[test]
fn hdr_simulate_multiscopic_merge_and_calibrate_on_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let sim = d.join("sim");
    let out = wscg_ok(&[
        "hdr",
        "simulate",
        "--height",
        "64",
        "--width",
        "192",
        "--out",
        &s(&sim),
    ]);
    let max_disp = out
        .split("--max-disparity ")
        .nth(1)
        .expect("suggested range")
        .trim();
    assert_eq!(max_disp, "136");
    let views: Vec<String> = (0..5)
        .map(|k| s(&sim.join(format!("view_{k:02}.png"))))
        .collect();
    let times = s(&sim.join("times.txt"));
    let res = d.join("res");
    let mut args: Vec<String> = vec!["hdr".into(), "multiscopic".into()];
    args.extend(views.iter().cloned());
    args.extend(
        [
            "--times",
            &times,
            "--crf",
            &s(&sim.join("crf.csv")),
            "--max-disparity",
            max_disp,
            "--out",
            &s(&res),
        ]
        .map(String::from),
    );
    let text = wscg_ok(&args);
    assert!(text.contains("5 HDR views"), "{text}");
    for k in 0..5 {
        let hdr = Image::load(res.join(format!("hdr_{k:02}.exr"))).unwrap();
        let truth = Image::load(sim.join(format!("truth_{k:02}.exr"))).unwrap();
        assert_eq!(hdr.shape(), truth.shape());
        // Close to the truth in log radiance on average (the unaligned merge is ~1 stop off).
        let mean_log_err = hdr
            .data()
            .iter()
            .zip(truth.data())
            .map(|(a, b)| (a.max(1e-9).log2() - b.log2()).abs() as f64)
            .sum::<f64>()
            / hdr.data().len() as f64;
        eprintln!("view {k}: mean |log2 error| {mean_log_err:.3}");
        assert!(mean_log_err < 0.3, "view {k}: {mean_log_err}");
        Image::load(res.join(format!("preview_{k:02}.png"))).unwrap();
    }
    assert!(res.join("disparity_0_1.png").exists());
    // The static stack of the central view: calibrate a response, merge with it.
    let cal = sim.join("calibration");
    let stack: Vec<String> = (0..7)
        .map(|k| s(&cal.join(format!("exposure_{k:02}.png"))))
        .collect();
    let cal_times = s(&cal.join("times.txt"));
    let crf = d.join("crf.csv");
    let mut args: Vec<String> = vec!["hdr".into(), "calibrate".into()];
    args.extend(stack.iter().cloned());
    args.extend(["--times", &cal_times, "--out", &s(&crf)].map(String::from));
    wscg_ok(&args);
    let table = std::fs::read_to_string(&crf).unwrap();
    let rows: Vec<Vec<f64>> = table
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!((rows.len(), rows[0].len()), (256, 3));
    // The recovered shape is the simulator's gamma 2.2 (up to a scale): ln ratio of codes
    // 200 and 50 is 2.2 ln 4.
    let ratio = (rows[200][1] / rows[50][1]).ln();
    assert!((ratio - 2.2 * 4f64.ln()).abs() < 0.15, "{ratio}");
    // The chart's stack calibrates the same camera with Mitsunaga-Nayar: f = (Z / 255)^2.2
    // itself (no free scale), to within 0.02.
    let chart: Vec<String> = (0..7)
        .map(|k| s(&sim.join("chart").join(format!("exposure_{k:02}.png"))))
        .collect();
    let crf_mn = d.join("crf_mn.csv");
    let mut args: Vec<String> = vec!["hdr".into(), "calibrate".into()];
    args.extend(chart.iter().cloned());
    let chart_times = s(&sim.join("chart").join("times.txt"));
    let opts = [
        "--times",
        &chart_times,
        "--method",
        "mitsunaga-nayar",
        "--out",
        &s(&crf_mn),
    ];
    args.extend(opts.map(String::from));
    wscg_ok(&args);
    let mn: Vec<f64> = std::fs::read_to_string(&crf_mn)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    for z in (20..=240).step_by(20) {
        let want = (z as f64 / 255.0).powf(2.2);
        assert!((mn[z] - want).abs() < 0.02, "code {z}: {} vs {want}", mn[z]);
    }
    let merged = d.join("merged.exr");
    let mut args: Vec<String> = vec!["hdr".into(), "merge".into()];
    args.extend(stack.iter().cloned());
    args.extend(
        [
            "--times",
            &cal_times,
            "--crf",
            &s(&crf),
            "--out",
            &s(&merged),
        ]
        .map(String::from),
    );
    wscg_ok(&args);
    let m = Image::load(&merged).unwrap();
    let truth = Image::load(sim.join("truth_02.exr")).unwrap();
    assert_eq!(m.shape(), truth.shape());
    // Up to the response's unknown scale, the merge is the truth: the log ratio is flat.
    let logs: Vec<f64> = m
        .data()
        .iter()
        .zip(truth.data())
        .map(|(a, b)| (a.max(1e-12) / b) as f64)
        .map(f64::log2)
        .collect();
    let mean = logs.iter().sum::<f64>() / logs.len() as f64;
    let sd = (logs.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / logs.len() as f64).sqrt();
    assert!(sd < 0.1, "log2 ratio spread {sd}");
    // Bad input: one view, wrong time count, a float image, an unknown method.
    let bad = wscg()
        .args([
            "hdr",
            "multiscopic",
            &views[0],
            "--times",
            "0.1",
            "--out",
            &s(&res),
        ])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let bad = wscg()
        .args([
            "hdr",
            "multiscopic",
            &views[0],
            &views[1],
            "--times",
            "0.1",
            "--out",
            &s(&res),
        ])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("times"));
    let exr = s(&sim.join("truth_00.exr"));
    let bad = wscg()
        .args(["hdr", "merge", &exr, "--times", "0.1", "--out", &s(&merged)])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&bad.stderr).contains("integer codes"));
    let bad = wscg()
        .args([
            "hdr",
            "multiscopic",
            &views[0],
            &views[1],
            "--times",
            "0.1,0.2",
            "--align",
            "magic",
            "--out",
            &s(&res),
        ])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown method"));
    // Exposure times from JSON, through --exposures.
    let json = d.join("times.json");
    std::fs::write(&json, "{\"exposure_times\": [0.061, 0.061]}").unwrap();
    wscg_ok(&[
        "hdr",
        "merge",
        &views[2],
        &views[2],
        "--exposures",
        &s(&json),
        "--out",
        &s(&merged),
    ]);
    std::fs::write(&json, "[0.061, \"x\"]").unwrap();
    let bad = wscg()
        .args([
            "hdr",
            "merge",
            &views[2],
            &views[2],
            "--exposures",
            &s(&json),
            "--out",
            &s(&merged),
        ])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&bad.stderr).contains("exposure times"));
}

/// `wscg hdr calibrate --method mitsunaga-nayar` on PNG exposures of a gradient through a
/// gamma-2.2 camera, with intermediate times 10-12 % off: the table is the camera's
/// `(Z / 255)^2.2`, the estimated ratios are printed; a dark stack is refused with the reason.
#[test]
fn hdr_calibrate_mitsunaga_nayar_on_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let times: Vec<f64> = (0..6).map(|k| 0.004 * 2f64.powi(k)).collect();
    let chart = gradient_target(64, 96).unwrap();
    let mut files = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let codes = encode(&chart, t, Response::Gamma(2.2), 0.0, 8, k as u64).unwrap();
        let f = d.join(format!("e{k}.png"));
        codes.map(|z| z as f32 / 255.0).save(&f).unwrap();
        files.push(s(&f));
    }
    let nominal = "0.004,0.0088,0.0144,0.0368,0.0704,0.128";
    let crf = d.join("crf.csv");
    let mut args: Vec<String> = vec!["hdr".into(), "calibrate".into()];
    args.extend(files.iter().cloned());
    let opts = [
        "--method",
        "mitsunaga-nayar",
        "--times",
        nominal,
        "--out",
        &s(&crf),
    ];
    args.extend(opts.map(String::from));
    let out = wscg_ok(&args);
    assert!(out.contains("exposure ratios"), "{out}");
    let rows: Vec<f64> = std::fs::read_to_string(&crf)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(rows.len(), 256);
    for z in (20..=240).step_by(20) {
        let want = (z as f64 / 255.0).powf(2.2);
        assert!(
            (rows[z] - want).abs() < 0.02,
            "code {z}: {} vs {want}",
            rows[z]
        );
    }
    // A stack that never reaches the upper half of the codes.
    let dark: Vec<String> = (0..2)
        .map(|k| {
            let f = d.join(format!("dark{k}.png"));
            Image::from_fn(32, 32, |_, x| (0.05 + 0.002 * x as f32) * (k + 1) as f32)
                .unwrap()
                .save(&f)
                .unwrap();
            s(&f)
        })
        .collect();
    let out = wscg()
        .args([
            "hdr",
            "calibrate",
            &dark[0],
            &dark[1],
            "--method",
            "mitsunaga-nayar",
        ])
        .args([
            "--times",
            "0.01,0.02",
            "--samples",
            "100",
            "--out",
            &s(&crf),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("upper half"));
}

#[test]
fn hdr_demo_reports_the_methods_and_writes_its_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = wscg_ok(&["demo", "hdr", "--out", dir.path().to_str().unwrap()]);
    for row in ["unaligned merge", "original PatchMatch 2-D", "darkest view"] {
        assert!(out.contains(row), "{row} missing:\n{out}");
    }
    for f in ["views.png", "hdr.png", "fields.png"] {
        Image::load(dir.path().join(f)).unwrap();
    }
}

#[test]
fn ear_simulate_enroll_identify_and_detect_on_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    wscg_ok(&[
        "biometrics",
        "ear",
        "simulate",
        "--subjects",
        "6",
        "--probes",
        "1",
        "--out",
        &s(d),
    ]);
    let g = d.join("gallery");
    let out = wscg_ok(&[
        "biometrics",
        "ear",
        "enroll",
        &s(&d.join("enrol")),
        "--out",
        &s(&g),
    ]);
    assert!(out.contains("6 identities"), "{out}");
    let probe = d.join("probes").join("0002_0.png");
    let before = std::fs::read(&probe).unwrap();
    let masks = d.join("masks");
    let out = wscg_ok(&[
        "biometrics",
        "ear",
        "identify",
        "--gallery",
        &s(&g),
        &s(&probe),
        "--top",
        "3",
        "--masks",
        &s(&masks),
    ]);
    assert!(out.contains("occlusion"), "{out}");
    assert_eq!(
        out.lines()
            .filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit()))
            .count(),
        3
    );
    let mask = Image::load(masks.join("0002_0_mask.png")).unwrap();
    assert_eq!(mask.shape(), (100, 80, 1));
    assert_eq!(
        std::fs::read(&probe).unwrap(),
        before,
        "the probe file was modified"
    );
    let out = wscg_ok(&["biometrics", "ear", "detect", &s(&probe)]);
    assert_eq!(
        out.lines().filter(|l| l.trim().len() == 8).count(),
        10,
        "{out}"
    );
    // Either skin rule can be chosen, with its own threshold; a threshold outside (0, 1]
    // is refused by name.
    for rule in ["marginal-and", "joint"] {
        wscg_ok(&[
            "biometrics",
            "ear",
            "detect",
            &s(&probe),
            "--skin-rule",
            rule,
            "--min-likelihood",
            "0.1",
        ]);
    }
    let out = wscg()
        .args([
            "biometrics",
            "ear",
            "detect",
            &s(&probe),
            "--min-likelihood",
            "0",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("skin_rule"));
    // Bad input: a missing gallery, an unreadable probe.
    assert!(!wscg()
        .args([
            "biometrics",
            "ear",
            "identify",
            "--gallery",
            &s(&d.join("none")),
            &s(&probe)
        ])
        .output()
        .unwrap()
        .status
        .success());
    let junk = d.join("junk.png");
    std::fs::write(&junk, b"not an image").unwrap();
    let out = wscg()
        .args(["biometrics", "ear", "detect", &s(&junk)])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("junk.png"));
}

#[test]
fn ear_demo_reports_the_rules_and_the_baseline() {
    let dir = tempfile::tempdir().unwrap();
    let out = wscg_ok(&["demo", "ear", "--out", dir.path().to_str().unwrap()]);
    for row in [
        "blockwise-max",
        "whole-ear Haar baseline",
        "estimated occlusion",
    ] {
        assert!(out.contains(row), "{row} missing:\n{out}");
    }
    for f in ["cmc_paper.png", "cmc_skin.png", "probes.png"] {
        Image::load(dir.path().join(f)).unwrap();
    }
}

#[test]
fn volren_illum_renders_a_volume_file_like_the_library_and_runs_the_study() {
    use wscg::volren::illumination::{render, IlluminationParams, Light, Method, SliceCamera};
    let dir = tempfile::tempdir().unwrap();
    let field = wscg::volren::illumination::scenes::marschner_lobb(41).unwrap();
    let vol = wscg::math::Volume::new([41; 3], [1.0; 3], field.data().to_vec()).unwrap();
    let npy = dir.path().join("ml.npy");
    vol.write_npy(&npy).unwrap();
    let before = std::fs::read(&npy).unwrap();
    let out = dir.path().join("ml.png");
    let (v, o) = (npy.to_str().unwrap(), out.to_str().unwrap());
    let text = wscg_ok(&[
        "volren",
        "illum",
        "--volume",
        v,
        "--value-range",
        "0,1",
        "--tf",
        "marschner-lobb",
        "--method",
        "scs",
        "--slice-distance",
        "1.0",
        "--subsamples",
        "2",
        "--size",
        "48",
        "--out",
        o,
    ]);
    assert!(text.contains("scs"), "{text}");
    assert_eq!(
        std::fs::read(&npy).unwrap(),
        before,
        "the input was modified"
    );
    let png = Image::load(&out).unwrap();
    let cam = SliceCamera::orbit(&field, 30.0, 20.0, 48).unwrap();
    let tf = wscg::volren::illumination::scenes::marschner_lobb_tf();
    let lib = render(
        &field,
        &tf,
        &cam,
        &Light::default(),
        &Method::scs(1.0, 2),
        &IlluminationParams::default(),
    )
    .unwrap();
    let mut worst = 0f32;
    for y in 0..48 {
        for x in 0..48 {
            for c in 0..3 {
                worst = worst.max((png.at(y, x, c) - lib.image.at(y, x, c).clamp(0.0, 1.0)).abs());
            }
        }
    }
    assert!(
        worst <= 1.0 / 255.0 + 1e-6,
        "PNG differs from the library by {worst}"
    );
    let study = wscg_ok(&[
        "volren",
        "illum",
        "--phantom",
        "marschner-lobb",
        "--tf",
        "marschner-lobb",
        "--study",
        "--views",
        "1",
        "--size",
        "24",
    ]);
    assert!(
        study.contains("reference ICS(0.2)") && study.contains("pi-scs"),
        "{study}"
    );
    // Bad input: a clear error, no crash.
    let bad = wscg()
        .args([
            "volren",
            "illum",
            "--volume",
            "/nonexistent.vti",
            "--out",
            o,
        ])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("nonexistent"));
    let bad = wscg()
        .args([
            "volren",
            "illum",
            "--phantom",
            "marschner-lobb",
            "--slice-distance",
            "0",
            "--out",
            o,
        ])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&bad.stderr).contains("slice_distance"));
}

#[test]
fn motion_learns_user_data_and_synthesizes_bvh() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    let d = data.to_str().unwrap();
    wscg_ok(&["motion", "make-data", d, "--trials", "8", "--seed", "4"]);
    let before = std::fs::read(data.join("angles.npy")).unwrap();
    let model = dir.path().join("model");
    let text = wscg_ok(&[
        "motion",
        "learn",
        d,
        "--out",
        model.to_str().unwrap(),
        "--restarts",
        "2",
    ]);
    assert!(text.contains("action 2: Q = "), "{text}");
    let sources = wscg::math::npy::read::<f64>(model.join("sources.npy")).unwrap();
    assert_eq!(sources.shape, vec![5, 100]);
    let bvh = dir.path().join("walk.bvh");
    let npy = dir.path().join("walk.npy");
    let text = wscg_ok(&[
        "motion",
        "synth",
        "--goal",
        "2.7",
        "--change",
        "40%:3.5",
        "--data",
        d,
        "--out",
        bvh.to_str().unwrap(),
        "--npy",
        npy.to_str().unwrap(),
    ]);
    assert!(text.contains("final pelvis-to-goal distance 0.6"), "{text}");
    let motion = wscg::motion::bvh::read_bvh(&bvh).unwrap();
    let angles = wscg::math::npy::read::<f64>(&npy).unwrap();
    assert_eq!(angles.shape, vec![motion.angles.len(), 51]);
    let last = motion.root.last().unwrap();
    assert!(
        (3.5 - last[2] - 0.6).abs() < 0.02,
        "final pelvis z {}",
        last[2]
    );
    assert_eq!(
        std::fs::read(data.join("angles.npy")).unwrap(),
        before,
        "input modified"
    );
    let plan = wscg_ok(&["motion", "plan", "--goal", "2.7"]);
    assert!(
        plan.contains("Step\t0.8085") && plan.contains("ShortStep\t1.2915"),
        "{plan}"
    );
    // Bad input: a goal <= 0 and a missing folder are errors, not crashes.
    let out = wscg()
        .args([
            "motion",
            "synth",
            "--goal=0",
            "--out",
            bvh.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("goal"));
    let out = wscg()
        .args(["motion", "learn", "/nonexistent/motion-data"])
        .output()
        .unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("nonexistent"));
    let out = wscg()
        .args(["motion", "learn", d, "--delay-search", "4"])
        .output()
        .unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("delay_search"));
}

#[test]
fn field_bvh_files_and_kinect_v1_and_ntu_skeletons_are_read() {
    let dir = tempfile::tempdir().unwrap();
    // A BVH of the model's skeleton with one joint renamed: refused without a map (the
    // error names the joint), read with a JSON map, written as the model's BVH.
    let angles: Vec<Vec<f64>> = (0..3)
        .map(|t| (0..51).map(|c| 0.01 * (c + t) as f64).collect())
        .collect();
    let m = wscg::motion::bvh::motion_from_frames(angles, &[0.0, 0.01, 0.02], 0.01);
    let text = wscg::motion::bvh::to_bvh_string(&m)
        .unwrap()
        .replace("LeftKnee", "knee_l");
    let input = dir.path().join("field.bvh");
    std::fs::write(&input, &text).unwrap();
    let out_bvh = dir.path().join("model.bvh");
    let args = |map: &str| {
        vec![
            "motion".to_string(),
            "import-bvh".into(),
            input.to_str().unwrap().into(),
            "--joint-map".into(),
            map.into(),
            "--out".into(),
            out_bvh.to_str().unwrap().into(),
        ]
    };
    let out = wscg().args(args("model")).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("LeftKnee") && err.contains("field.bvh"),
        "{err}"
    );
    let map = dir.path().join("map.json");
    std::fs::write(&map, r#"{"LeftKnee": "knee_l"}"#).unwrap();
    let text = wscg_ok(&args(map.to_str().unwrap()));
    assert!(text.contains("17 joints, 3 frames"), "{text}");
    let back = wscg::motion::bvh::read_bvh(&out_bvh).unwrap();
    for (a, b) in m.angles.iter().zip(&back.angles) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-6, "{x} vs {y}");
        }
    }
    // Kinect v1 walkers, their gait cycle, and an NTU file with two bodies.
    let walks = dir.path().join("walks");
    wscg_ok(&[
        "biometrics",
        "gait",
        "simulate",
        "--out",
        walks.to_str().unwrap(),
        "--subjects",
        "1",
        "--sessions",
        "1",
        "--joints",
        "20",
    ]);
    let csv = walks.join("s00").join("walk_0.csv");
    assert!(std::fs::read_to_string(&csv)
        .unwrap()
        .contains(",HipCenter,"));
    let text = wscg_ok(&["biometrics", "gait", "cycle", csv.to_str().unwrap()]);
    assert!(text.contains("start "), "{text}");
    let walk = wscg::biometrics::gait::read_skeleton(&csv, 30.0).unwrap();
    let mut ntu = format!("{}\n", walk.len());
    for f in &walk.frames {
        ntu.push_str("2\n");
        for (id, state) in [(7u64, 1), (9, 2)] {
            ntu.push_str(&format!("{id} 0 1 1 1 1 0 0 0 2\n25\n"));
            for p in f {
                let p = if p[0].is_nan() { [0.0; 3] } else { *p };
                ntu.push_str(&format!(
                    "{} {} {} 1 1 1 1 1 0 0 0 {state}\n",
                    p[0], p[1], p[2]
                ));
            }
        }
    }
    let ntu_path = dir.path().join("S001C001P001R001A013.skeleton");
    std::fs::write(&ntu_path, ntu).unwrap();
    let n = ntu_path.to_str().unwrap();
    let most = wscg_ok(&["biometrics", "gait", "cycle", n]);
    let by_id = wscg_ok(&["biometrics", "gait", "cycle", n, "--body", "9"]);
    assert_eq!(most, by_id);
    let out = wscg()
        .args(["biometrics", "gait", "cycle", n, "--body", "8"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("[7, 9]"));
    let out = wscg()
        .args([
            "biometrics",
            "gait",
            "simulate",
            "--out",
            n,
            "--joints",
            "21",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
}

#[test]
fn gait_enrolls_identifies_and_classifies_ucr_files() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("walks");
    let d = data.to_str().unwrap();
    wscg_ok(&[
        "biometrics",
        "gait",
        "simulate",
        "--out",
        d,
        "--subjects",
        "5",
        "--sessions",
        "3",
        "--seed",
        "2",
    ]);
    // Gallery: walks 0 and 1 of each subject; probes: walk 2.
    let gallery = dir.path().join("gallery");
    let mut probes = Vec::new();
    for s in 0..5 {
        let sub = format!("s{s:02}");
        std::fs::create_dir_all(gallery.join(&sub)).unwrap();
        for k in 0..2 {
            let f = format!("walk_{k}.csv");
            std::fs::copy(data.join(&sub).join(&f), gallery.join(&sub).join(&f)).unwrap();
        }
        probes.push((sub.clone(), data.join(&sub).join("walk_2.csv")));
    }
    let before = std::fs::read(&probes[0].1).unwrap();
    let model = dir.path().join("gait.json");
    let text = wscg_ok(&[
        "biometrics",
        "gait",
        "enroll",
        gallery.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
        "--min-bins",
        "15",
    ]);
    assert!(text.contains("enrolled 10 walks of 5 identities"), "{text}");
    let mut args = vec![
        "biometrics".to_string(),
        "gait".into(),
        "identify".into(),
        "--model".into(),
    ];
    args.push(model.to_str().unwrap().into());
    args.extend(probes.iter().map(|p| p.1.to_str().unwrap().to_string()));
    let text = wscg_ok(&args);
    let ok = probes
        .iter()
        .filter(|(sub, file)| text.contains(&format!("{}: {sub} ", file.display())))
        .count();
    assert!(ok >= 4, "{ok}/5 identified:\n{text}");
    assert_eq!(
        std::fs::read(&probes[0].1).unwrap(),
        before,
        "input modified"
    );
    let text = wscg_ok(&["biometrics", "gait", "cycle", probes[0].1.to_str().unwrap()]);
    assert!(text.contains("first step Left"), "{text}");

    // UCR .ts files: two classes of shifted bumps; DTW 1-NN separates them.
    let ts = |name: &str, cases: &[(usize, &str)]| {
        let mut s = String::from("@problemName Bumps\n@timeStamps false\n@univariate true\n@classLabel true up down\n@data\n");
        for &(shift, label) in cases {
            let sign = if label == "up" { 1.0 } else { -1.0 };
            let v: Vec<String> = (0..30)
                .map(|i| {
                    format!(
                        "{}",
                        sign * (-((i as f64 - 8.0 - shift as f64).powi(2)) / 4.0).exp()
                    )
                })
                .collect();
            s.push_str(&format!("{}:{label}\n", v.join(",")));
        }
        let p = dir.path().join(name);
        std::fs::write(&p, s).unwrap();
        p
    };
    let train = ts("train.ts", &[(0, "up"), (2, "down")]);
    let test = ts("test.ts", &[(10, "up"), (12, "down"), (6, "up")]);
    // One channel: the dependent DTW is the same DTW.
    for mode in ["independent", "dependent"] {
        let (tr, te) = (train.to_str().unwrap(), test.to_str().unwrap());
        let text = wscg_ok(&["biometrics", "gait", "ucr", tr, te, "--multivariate", mode]);
        assert!(text.contains("3/3 correct, error 0.0000"), "{text}");
        assert!(
            text.to_lowercase().contains(&format!(", {mode})")),
            "{text}"
        );
    }

    // Bad input: a gallery without walks, a walk with 24 joints, a missing model.
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = wscg()
        .args([
            "biometrics",
            "gait",
            "enroll",
            empty.to_str().unwrap(),
            "--out",
            model.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no skeleton files"));
    let short = dir.path().join("short.npy");
    wscg::math::npy::write_f64(&short, &[40, 24, 3], &vec![0.5; 40 * 24 * 3]).unwrap();
    let out = wscg()
        .args([
            "biometrics",
            "gait",
            "identify",
            "--model",
            model.to_str().unwrap(),
            short.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("25 joints"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = wscg()
        .args([
            "biometrics",
            "gait",
            "identify",
            "--model",
            "/nonexistent/model.json",
            short.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let out = wscg()
        .args([
            "demo",
            "gait",
            "--out",
            dir.path().join("demo").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("Ball et al. 2012"));
    assert!(dir.path().join("demo").join("relevance.png").exists());
}

#[test]
fn volseg_splits_a_phantom_and_beats_the_baseline() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    wscg_ok(&[
        "volseg",
        "phantom",
        "--out",
        d,
        "--size",
        "64",
        "--fragments",
        "4",
        "--seed",
        "1",
    ]);
    let ct = dir.path().join("ct.nii");
    let before = std::fs::read(&ct).unwrap();
    let args = |out: &str, extra: &[&str]| {
        let mut v = vec![
            "volseg".to_string(),
            "split".into(),
            ct.to_str().unwrap().into(),
            "--seeds".into(),
            dir.path().join("seeds.nii").to_str().unwrap().into(),
            "--out".into(),
            dir.path().join(out).to_str().unwrap().into(),
            "--truth".into(),
            dir.path().join("truth.nii").to_str().unwrap().into(),
        ];
        v.extend(extra.iter().map(|s| s.to_string()));
        v
    };
    let dice = |text: &str| -> f64 {
        let line = text
            .lines()
            .find(|l| l.starts_with("multi-label Dice"))
            .unwrap();
        line.rsplit(' ').next().unwrap().parse().unwrap()
    };
    let rw = wscg_ok(&args("labels.nii", &[]));
    assert!(rw.contains("label 4: "), "{rw}");
    let ns = wscg_ok(&args("ns.npy", &["--baseline"]));
    assert!(dice(&rw) >= dice(&ns) + 0.05, "{rw}\n{ns}");
    let labels = wscg::math::Volume::read(dir.path().join("labels.nii"), None).unwrap();
    assert_eq!(labels.dims(), [64, 64, 64]);
    assert!(labels
        .data()
        .iter()
        .all(|&l| (0.0..=4.0).contains(&l) && l.fract() == 0.0));
    assert_eq!(std::fs::read(&ct).unwrap(), before, "input modified");
    // Bad input: seeds that are not labels, a missing file.
    let out = wscg()
        .args([
            "volseg",
            "split",
            ct.to_str().unwrap(),
            "--seeds",
            ct.to_str().unwrap(),
            "--out",
            "x.nii",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("labels must be integers"));
    let out = wscg()
        .args([
            "volseg",
            "split",
            "/nonexistent.nii",
            "--seeds",
            ct.to_str().unwrap(),
            "--out",
            "x.nii",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    // Strokes as JSON (one voxel of every seed label, radius 1) and one mesh per label: each
    // closed and enclosing about as much volume as its label has voxels.
    let seeds = wscg::math::Volume::read(dir.path().join("seeds.nii"), None).unwrap();
    let strokes: Vec<String> = (1..=4)
        .map(|l| {
            let i = seeds.data().iter().position(|&v| v == l as f32).unwrap();
            let (x, y, z) = (i % 64, (i / 64) % 64, i / 4096);
            format!(r#"{{"label": {l}, "points": [[{x}, {y}, {z}]], "radius": 1.5}}"#)
        })
        .collect();
    let json = dir.path().join("strokes.json");
    std::fs::write(&json, format!("[{}]", strokes.join(","))).unwrap();
    let meshes = dir.path().join("meshes");
    let out_labels = dir.path().join("from_strokes.nii");
    let text = wscg_ok(&[
        "volseg",
        "split",
        ct.to_str().unwrap(),
        "--strokes",
        json.to_str().unwrap(),
        "--out",
        out_labels.to_str().unwrap(),
        "--meshes",
        meshes.to_str().unwrap(),
        "--min-island",
        "20",
    ]);
    assert!(text.contains("wrote 4 meshes"), "{text}");
    let labels = wscg::math::Volume::read(&out_labels, None).unwrap();
    for l in 1..=4 {
        let m = wscg::math::mesh::TriMesh::read(meshes.join(format!("label_{l}.obj"))).unwrap();
        assert!(m.is_closed(), "label {l}");
        let count = labels.data().iter().filter(|&&v| v == l as f32).count() as f64;
        let vol = m.signed_volume().abs();
        assert!(
            (vol / count - 1.0).abs() < 0.2,
            "label {l}: {vol} vs {count}"
        );
    }
    std::fs::write(&json, "[{\"label\": 0, \"points\": [[1, 2, 3]]}]").unwrap();
    let out = wscg()
        .args(["volseg", "split", ct.to_str().unwrap(), "--strokes"])
        .arg(&json)
        .args(["--out", "x.nii"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("label must be >= 1"));
    // A stroke outside the volume, or one that covers no voxel centre, is refused by its
    // number and label (it used to drop that label silently).
    for (stroke, expected) in [
        (
            r#"{"label": 2, "points": [[10, 10, 64.5]]}"#,
            "stroke 1 (label 2) has the point",
        ),
        (
            r#"{"label": 2, "points": [[10, -1, 3]]}"#,
            "outside the volume",
        ),
        (
            r#"{"label": 2, "points": [[10.5, 10.5, 3], [4.5, 4, 3]], "radius": 0.4}"#,
            "covers no voxel",
        ),
        (r#"{"label": 2, "points": []}"#, "has no points"),
    ] {
        std::fs::write(&json, format!("[{}, {stroke}]", strokes[0])).unwrap();
        let out = wscg()
            .args(["volseg", "split", ct.to_str().unwrap(), "--strokes"])
            .arg(&json)
            .args(["--out", "x.nii"])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{stroke}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(expected) && err.contains("strokes.json"),
            "{stroke}: {err}"
        );
    }
    let demo = dir.path().join("demo");
    let text = wscg_ok(&["demo", "bonesplit", "--out", demo.to_str().unwrap()]);
    assert!(text.contains("DSC geodesic nearest seed"), "{text}");
    assert!(demo.join("slices.png").exists());
}

/// Sizes far beyond any machine's memory are refused with a message naming the argument:
/// an error exit, not an abort (a failed allocation kills the process with SIGABRT, 134).
#[test]
fn huge_sizes_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("small.png");
    write_test_image(&png, 0.0);
    let out = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let png = png.to_string_lossy().into_owned();
    // The arguments of a case, then `--out DIR/<file>` (or, for `make-data`, the folder as
    // a positional argument).
    let with_out = |args: &[&str], flag: Option<&str>, file: &str| -> Vec<String> {
        let mut v: Vec<String> = args.iter().map(|a| a.to_string()).collect();
        v.extend(flag.map(String::from));
        v.push(out(file));
        v
    };
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            with_out(
                &[
                    "mri",
                    "mask",
                    "--cartesian",
                    "0.4",
                    "--size",
                    "10000000x10000000",
                ],
                Some("--out"),
                "m.npy",
            ),
            "shape",
        ),
        (
            with_out(
                &[
                    "mri",
                    "mask",
                    "--radial",
                    "0.4",
                    "--size",
                    "10000000x10000000",
                ],
                Some("--out"),
                "r.npy",
            ),
            "shape",
        ),
        (
            with_out(&["math", "resize", &png], None, "big.png")
                .into_iter()
                .chain(["--height", "1000000", "--width", "1000000"].map(String::from))
                .collect(),
            "height, width",
        ),
        (
            with_out(&["math", "blur", &png], None, "blur.png")
                .into_iter()
                .chain(["--sigma", "1e12"].map(String::from))
                .collect(),
            "truncate * sigma",
        ),
        (
            with_out(
                &["volseg", "phantom", "--size", "100000"],
                Some("--out"),
                "vp",
            ),
            "dims",
        ),
        (
            with_out(
                &[
                    "hdr", "simulate", "--height", "1000000", "--width", "1000000",
                ],
                Some("--out"),
                "hs",
            ),
            "height, width",
        ),
        (
            with_out(
                &[
                    "raytrace",
                    "manylight",
                    "--width",
                    "1000000",
                    "--height",
                    "1000000",
                ],
                Some("--out"),
                "ml.png",
            ),
            "width, height",
        ),
        (
            with_out(
                &[
                    "video", "synth", "--frames", "1000000", "--height", "10000", "--width",
                    "10000",
                ],
                Some("--out"),
                "vs",
            ),
            "frames, height, width",
        ),
        (
            with_out(
                &["biometrics", "ear", "simulate", "--subjects", "10000000000"],
                Some("--out"),
                "es",
            ),
            "n_subjects",
        ),
        (
            with_out(
                &[
                    "biometrics",
                    "gait",
                    "simulate",
                    "--subjects",
                    "10000000000",
                ],
                Some("--out"),
                "gs",
            ),
            "n_subjects, n_sessions",
        ),
        (
            with_out(
                &["motion", "make-data", "--trials", "10000000000"],
                None,
                "md",
            ),
            "n_trials",
        ),
    ];
    for (args, name) in cases {
        let o = wscg().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {:?} {err}", o.status);
        assert!(
            err.contains("cannot allocate") && err.contains(&format!("`{name}`")),
            "{args:?}: {err}"
        );
    }
}

/// `wscg hdr calibrate` and `merge` on 16-bit TIFF exposures (a raw converter's output):
/// the response covers all 65536 codes and has the camera's gamma; without `--times`, files
/// without EXIF are an error naming the first such file.
#[test]
fn hdr_calibrate_and_merge_16_bit_tiffs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let radiance = gradient_target(48, 64).unwrap();
    let times: Vec<f64> = (0..6).map(|k| 0.004 * 2f64.powi(k)).collect();
    let mut stack = Vec::new();
    for (k, &t) in times.iter().enumerate() {
        let codes = encode(&radiance, t, Response::Gamma(2.2), 0.001, 16, 30 + k as u64).unwrap();
        let p = d.join(format!("exposure_{k}.tif"));
        codes
            .map(|z| z as f32 / 65535.0)
            .save_with_depth(&p, wscg_math::io::PixelDepth::U16)
            .unwrap();
        // The file holds the codes exactly.
        assert_eq!(Image::<u16>::load_codes(&p).unwrap(), (codes, 16));
        stack.push(s(&p));
    }
    let list: Vec<String> = times.iter().map(|t| t.to_string()).collect();
    let list = list.join(",");
    let crf = d.join("crf16.csv");
    let mut args: Vec<String> = vec!["hdr".into(), "calibrate".into()];
    args.extend(stack.iter().cloned());
    args.extend(["--times", &list, "--out", &s(&crf)].map(String::from));
    wscg_ok(&args);
    let rows: Vec<f64> = std::fs::read_to_string(&crf)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(rows.len(), 65536);
    // ln f^-1(4 z) - ln f^-1(z) = 2.2 ln 4 for a gamma-2.2 camera (the scale is free).
    let ratio = (rows[48000] / rows[12000]).ln();
    assert!((ratio - 2.2 * 4f64.ln()).abs() < 0.15, "{ratio}");
    let merged = d.join("merged16.exr");
    let mut args: Vec<String> = vec!["hdr".into(), "merge".into()];
    args.extend(stack.iter().cloned());
    args.extend(["--times", &list, "--crf", &s(&crf), "--out", &s(&merged)].map(String::from));
    wscg_ok(&args);
    assert_eq!(Image::load(&merged).unwrap().shape(), (48, 64, 3));
    // No --times and no EXIF in the files.
    let mut args: Vec<String> = vec!["hdr".into(), "merge".into()];
    args.extend(stack.iter().cloned());
    args.extend(["--out", &s(&merged)].map(String::from));
    let bad = wscg().args(&args).output().unwrap();
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("exposure_0.tif") && err.contains("give the exposure times"),
        "{err}"
    );
}
