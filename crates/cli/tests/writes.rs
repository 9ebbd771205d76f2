//! Outputs of the `wscg` binary: no command writes over its input without `--overwrite`, and
//! a write that fails (a full disk, simulated by a file-size limit) is an error naming the
//! file that leaves the previous file and no temporary file behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use wscg::math::image::Image;

mod common;
use common::wscg;

fn run(args: &[&str]) -> Output {
    wscg().args(args).output().unwrap()
}

fn ok(args: &[&str]) {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs `args` (which write over `input`) and checks the refusal: exit status 2, a message
/// naming the output and the input, the input unchanged. Returns the message.
fn refused(args: &[&str], output: &str, input: &Path) -> String {
    let before = snapshot(input);
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(err.contains("--overwrite"), "{err}");
    assert!(err.contains(output), "{err}");
    assert!(err.contains(s(input)), "{err}");
    assert_eq!(snapshot(input), before, "{args:?} modified its input");
    err
}

/// The bytes of a file, or of every file of a folder (sorted by name).
fn snapshot(p: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    if p.is_dir() {
        let mut v: Vec<_> = std::fs::read_dir(p)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|q| q.is_file())
            .map(|q| {
                let b = std::fs::read(&q).unwrap();
                (q, b)
            })
            .collect();
        v.sort();
        v
    } else {
        vec![(p.to_path_buf(), std::fs::read(p).unwrap())]
    }
}

fn small_mesh(dir: &Path) -> PathBuf {
    let p = dir.join("m.obj");
    wscg::meshfilter::synth::colored_cube(3)
        .unwrap()
        .write_obj(&p)
        .unwrap();
    p
}

#[test]
fn meshfilter_and_octree_refuse_to_write_over_the_input_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let m = small_mesh(dir.path());
    let ms = s(&m);
    let denoise = [
        "meshfilter",
        "denoise",
        "--iterations",
        "1",
        "--mesh",
        ms,
        "--out",
    ];
    refused(&[&denoise[..], &[ms]].concat(), ms, &m);
    // The same file under another name: `./m.obj` from the folder, and a hard link.
    let out = wscg()
        .current_dir(dir.path())
        .args([
            "meshfilter",
            "denoise",
            "--mesh",
            "m.obj",
            "--out",
            "./m.obj",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let link = dir.path().join("link.obj");
    std::fs::hard_link(&m, &link).unwrap();
    refused(&[&denoise[..], &[s(&link)]].concat(), s(&link), &m);
    let build = ["octree", "build", ms, "--depth", "3", "--out"];
    refused(&[&build[..], &[ms]].concat(), ms, &m);
    // Accepted with --overwrite (before or after the subcommand), replacing the file.
    let before = std::fs::read(&m).unwrap();
    ok(&[&denoise[..], &[ms, "--overwrite"]].concat());
    assert_ne!(std::fs::read(&m).unwrap(), before);
    let tree = dir.path().join("t.obj");
    std::fs::copy(&m, &tree).unwrap();
    ok(&[
        &["--overwrite"],
        &[
            "octree",
            "build",
            s(&tree),
            "--depth",
            "3",
            "--out",
            s(&tree),
        ][..],
    ]
    .concat());
    assert!(wscg::octree::HybridOctree::load(&tree).is_ok());
}

/// `wscg mri recon` of the k-space `k` with the mask `m`, up to `--out` (the output follows).
fn recon_args<'a>(k: &'a Path, m: &'a Path) -> [&'a str; 8] {
    [
        "mri",
        "recon",
        s(k),
        "--mask",
        s(m),
        "--method",
        "zero-filled",
        "--out",
    ]
}

/// A 32 x 32 k-space (`k.npy`) and a Cartesian mask (`mask.npy`) made by the CLI in `dir`.
fn mri_inputs(dir: &Path) -> (PathBuf, PathBuf) {
    let (k, m) = (dir.join("k.npy"), dir.join("mask.npy"));
    ok(&["mri", "phantom", "--size", "32", "--out", s(&k)]);
    ok(&[
        "mri",
        "mask",
        "--cartesian",
        "0.5",
        "--size",
        "32x32",
        "--out",
        s(&m),
    ]);
    (k, m)
}

#[test]
fn mri_recon_refuses_to_write_over_the_k_space_or_the_mask() {
    let dir = tempfile::tempdir().unwrap();
    let (k, m) = mri_inputs(dir.path());
    let recon = recon_args(&k, &m);
    refused(&[&recon[..], &[s(&k)]].concat(), s(&k), &k);
    refused(&[&recon[..], &[s(&m)]].concat(), s(&m), &m);
    ok(&[&recon[..], &[s(&k), "--overwrite"]].concat());
    assert!(wscg::math::npy::read_complex(&k).is_ok());
}

/// A small CT phantom (`ct.nii`, `seeds.nii`, ...) written by the CLI into `d`.
fn volseg_phantom(d: &Path) {
    ok(&[
        "volseg",
        "phantom",
        "--out",
        s(d),
        "--size",
        "24",
        "--fragments",
        "2",
    ]);
}

#[test]
fn volseg_split_refuses_to_write_over_the_ct() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    volseg_phantom(d);
    let (ct, seeds) = (d.join("ct.nii"), d.join("seeds.nii"));
    let split = ["volseg", "split", s(&ct), "--seeds", s(&seeds), "--out"];
    refused(&[&split[..], &[s(&ct)]].concat(), s(&ct), &ct);
    refused(&[&split[..], &[s(&seeds)]].concat(), s(&seeds), &seeds);
    // Meshes into the folder that holds the CT.
    refused(
        &[&split[..], &[s(&d.join("labels.nii")), "--meshes", s(d)]].concat(),
        s(d),
        &ct,
    );
    ok(&[&split[..], &[s(&ct), "--overwrite"]].concat());
}

#[test]
fn deblur_frames_refuses_to_write_into_the_frame_folder() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    std::fs::create_dir(&frames).unwrap();
    Image::from_fn(16, 16, |y, x| (x + y) as f32 / 32.0)
        .unwrap()
        .save(frames.join("frame_00.png"))
        .unwrap();
    let gyro = dir.path().join("gyro.csv");
    std::fs::write(&gyro, "t,wx,wy,wz\n0,0,0,0\n1,0,0,0\n").unwrap();
    let args = [
        "deblur",
        "frames",
        s(&frames),
        "--gyro",
        s(&gyro),
        "--f",
        "20",
        "--out",
    ];
    refused(&[&args[..], &[s(&frames)]].concat(), s(&frames), &frames);
    // A result file inside the frame folder, and a folder that contains the frames.
    refused(
        &[&args[..], &[s(&frames.join("r.png"))]].concat(),
        "r.png",
        &frames,
    );
    refused(
        &[&args[..], &[s(dir.path())]].concat(),
        s(dir.path()),
        &frames,
    );
    // With --overwrite the check passes (the run then fails on the missing frame times).
    let out = run(&[&args[..], &[s(&frames), "--overwrite"]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("--overwrite") && err.contains("times"),
        "{err}"
    );
}

#[test]
fn video_complete_refuses_to_write_into_the_frame_folder() {
    let dir = tempfile::tempdir().unwrap();
    let clip = dir.path().join("clip");
    ok(&[
        "video",
        "synth",
        "--out",
        s(&clip),
        "--kind",
        "pan",
        "--frames",
        "8",
        "--width",
        "64",
        "--height",
        "48",
    ]);
    let (frames, mask) = (clip.join("frames"), clip.join("mask"));
    let args = ["video", "complete", s(&frames), s(&mask), "--out"];
    refused(&[&args[..], &[s(&frames)]].concat(), s(&frames), &frames);
    refused(&[&args[..], &[s(&mask)]].concat(), s(&mask), &mask);
    refused(&[&args[..], &[s(&clip)]].concat(), s(&clip), &frames);
    ok(&[&args[..], &[s(&frames), "--overwrite"]].concat());
}

#[test]
fn math_refuses_to_write_over_the_input_unless_told() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.png");
    Image::from_fn(16, 16, |y, x| (x + y) as f32 / 32.0)
        .unwrap()
        .save(&a)
        .unwrap();
    refused(&["math", "blur", "--sigma", "1", s(&a), s(&a)], s(&a), &a);
    ok(&["math", "blur", "--sigma", "1", s(&a), s(&a), "--overwrite"]);
}

/// Runs `wscg ARGS` with writes limited to `blocks` 512-byte blocks per file (SIGXFSZ
/// ignored, so a write past the limit fails with EFBIG as on a full disk).
fn run_limited(blocks: u32, args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!(
            "trap '' XFSZ; ulimit -f {blocks} && exec \"$0\" \"$@\""
        ))
        .arg(env!("CARGO_BIN_EXE_wscg"))
        .args(args)
        .output()
        .unwrap()
}

/// Files of `dir` whose name marks an unfinished write.
fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("wscg_tmp")
        })
        .collect()
}

/// Every command that writes a file, run under a file-size limit: each exits with an error
/// naming the output, and the previous content of the output survives.
#[test]
fn a_full_disk_is_an_error_and_keeps_the_previous_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Inputs, written without a limit.
    let img = d.join("in.png");
    Image::from_fn(96, 96, |y, x| ((x * 7 + y * 13) % 17) as f32 / 16.0)
        .unwrap()
        .save(&img)
        .unwrap();
    let mesh = small_mesh(d);
    volseg_phantom(d);
    let ct = d.join("ct.nii");
    let (k, m) = mri_inputs(d);
    let old = b"previous content".to_vec();
    let cases: Vec<(&str, Vec<String>)> = vec![
        (
            "blur.png",
            vec!["math", "blur", "--sigma", "1", s(&img)]
                .into_iter()
                .map(String::from)
                .collect(),
        ),
        (
            "resize.png",
            ["math", "resize", "--height", "90", "--width", "90", s(&img)]
                .map(String::from)
                .to_vec(),
        ),
        (
            "spectrum.png",
            ["math", "spectrum", s(&img)].map(String::from).to_vec(),
        ),
        (
            "denoised.obj",
            [
                "meshfilter",
                "denoise",
                "--iterations",
                "1",
                "--mesh",
                s(&mesh),
                "--out",
            ]
            .map(String::from)
            .to_vec(),
        ),
        (
            "tree.oct",
            ["octree", "build", s(&mesh), "--depth", "3", "--out"]
                .map(String::from)
                .to_vec(),
        ),
        (
            "iso.ply",
            ["isosurface", "extract", s(&ct), "--iso", "300", "--out"]
                .map(String::from)
                .to_vec(),
        ),
        (
            "k2.npy",
            ["mri", "phantom", "--size", "32", "--out"]
                .map(String::from)
                .to_vec(),
        ),
        (
            "m2.npy",
            [
                "mri",
                "mask",
                "--cartesian",
                "0.5",
                "--size",
                "32x32",
                "--out",
            ]
            .map(String::from)
            .to_vec(),
        ),
        ("recon.npy", recon_args(&k, &m).map(String::from).to_vec()),
        (
            "labels.nii",
            [
                "volseg",
                "split",
                s(&ct),
                "--seeds",
                s(&d.join("seeds.nii")),
                "--out",
            ]
            .map(String::from)
            .to_vec(),
        ),
    ];
    let out_dir = d.join("out");
    std::fs::create_dir(&out_dir).unwrap();
    for (name, mut args) in cases {
        let target = out_dir.join(name);
        std::fs::write(&target, &old).unwrap();
        args.push(s(&target).to_string());
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = run_limited(1, &argv);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{argv:?} under a 512-byte limit: {err}"
        );
        assert!(err.contains(name), "{argv:?}: {err}");
        assert_eq!(
            std::fs::read(&target).unwrap(),
            old,
            "{argv:?} lost the old file"
        );
        assert!(
            temporaries(&out_dir).is_empty(),
            "{argv:?} left {:?}",
            temporaries(&out_dir)
        );
        // Without the limit the same command succeeds.
        ok(&argv);
        assert_ne!(std::fs::read(&target).unwrap(), old);
    }
}
