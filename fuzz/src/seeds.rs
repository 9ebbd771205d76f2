//! Writes the generated seed files of the fuzz corpora with the project's own writers:
//! `wscg-fuzz-seeds <corpus folder>` (normally `fuzz/corpus`). The hand-written seeds (VTI,
//! `.ts`, gyroscope CSV, and the malformed ones) are committed beside them.

use std::path::{Path, PathBuf};

use wscg_math::{Image, PlyEncoding, TriMesh, Volume};

#[allow(dead_code)]
mod targets;

fn tmp(dir: &Path, name: &str) -> PathBuf {
    dir.join(name)
}

/// Copies a file written by a project writer to `<corpus>/<target>/seed_<name>`.
fn keep(corpus: &Path, target: &str, name: &str, from: &Path) {
    let dir = corpus.join(target);
    std::fs::create_dir_all(&dir).expect("corpus folder");
    std::fs::copy(from, dir.join(format!("seed_{name}"))).expect("copy seed");
}

/// Writes `bytes` to `<corpus>/<target>/seed_<name>`.
fn put(corpus: &Path, target: &str, name: &str, bytes: &[u8]) {
    let dir = corpus.join(target);
    std::fs::create_dir_all(&dir).expect("corpus folder");
    std::fs::write(dir.join(format!("seed_{name}")), bytes).expect("write seed");
}

fn main() {
    let corpus = PathBuf::from(
        std::env::args()
            .nth(1)
            .expect("usage: wscg-fuzz-seeds <corpus>"),
    );
    let work = std::env::temp_dir().join(format!("wscg-fuzz-seeds-{}", std::process::id()));
    std::fs::create_dir_all(&work).expect("temp folder");

    // Raster: one file per format and channel count.
    let grey = Image::<f32>::from_fn(6, 5, |y, x| (y * 5 + x) as f32 / 30.0).expect("image");
    let rgb =
        Image::<f32>::new(4, 3, 3, (0..36).map(|i| (i % 7) as f32 / 7.0).collect()).expect("image");
    for (name, img) in [
        ("grey.png", &grey),
        ("rgb.png", &rgb),
        ("grey.jpg", &grey),
        ("rgb.jpg", &rgb),
        ("rgb.exr", &rgb),
        ("rgb.hdr", &rgb),
    ] {
        let p = tmp(&work, name);
        img.save(&p).expect("save image");
        keep(&corpus, "raster", name, &p);
    }
    let p = tmp(&work, "grey16.png");
    grey.save_with_depth(&p, wscg_math::io::PixelDepth::U16)
        .expect("save 16-bit");
    keep(&corpus, "raster", "grey16.png", &p);
    for (name, img) in [("grey.tif", &grey), ("rgb16.tif", &rgb)] {
        let depth = if name.contains("16") {
            wscg_math::io::PixelDepth::U16
        } else {
            wscg_math::io::PixelDepth::U8
        };
        let p = tmp(&work, name);
        img.save_with_depth(&p, depth).expect("save TIFF");
        keep(&corpus, "raster", name, &p);
    }

    // Meshes: a tetrahedron, with and without normals and colours.
    let positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let faces = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let plain = TriMesh::new(positions, faces).expect("mesh");
    let mut rich = plain.clone();
    rich.normals = Some(vec![[0.0, 0.0, 1.0]; 4]);
    rich.colors = Some(vec![[1.0, 0.5, 0.0]; 4]);
    for (stem, mesh) in [("plain", &plain), ("rich", &rich)] {
        let p = tmp(&work, &format!("{stem}.obj"));
        mesh.write_obj(&p).expect("obj");
        keep(&corpus, "obj", &format!("{stem}.obj"), &p);
        for (enc, tag) in [
            (PlyEncoding::Ascii, "ascii"),
            (PlyEncoding::BinaryLittleEndian, "binary"),
        ] {
            let name = format!("{stem}_{tag}.ply");
            let p = tmp(&work, &name);
            mesh.write_ply(&p, enc).expect("ply");
            keep(&corpus, "ply", &name, &p);
        }
    }

    // Volumes: NIfTI (plain and gzip) and .npy.
    let vol = Volume::<f32>::from_fn([3, 4, 2], [1.0, 0.5, 2.0], |x, y, z| {
        (x + 3 * y + 12 * z) as f32
    })
    .expect("volume");
    for name in ["vol.nii", "vol.nii.gz"] {
        let p = tmp(&work, name);
        vol.write_nifti(&p).expect("nifti");
        keep(&corpus, "nifti", name, &p);
    }
    let p = tmp(&work, "vol.npy");
    vol.write_npy(&p).expect("npy");
    keep(&corpus, "npy", "vol_f32.npy", &p);
    let p = tmp(&work, "matrix.npy");
    wscg_math::npy::write_f64(&p, &[2, 3], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).expect("npy");
    keep(&corpus, "npy", "matrix_f64.npy", &p);
    let p = tmp(&work, "complex.npy");
    let values: Vec<num_complex::Complex64> = (0..4)
        .map(|k| num_complex::Complex64::new(k as f64, -(k as f64)))
        .collect();
    wscg_math::npy::write(&p, &[2, 2], &values).expect("npy");
    keep(&corpus, "npy", "complex128.npy", &p);
    let p = tmp(&work, "bytes.npy");
    wscg_math::npy::write(&p, &[2, 2, 2], &[1u8, 2, 3, 4, 5, 6, 7, 8]).expect("npy");
    keep(&corpus, "npy", "vol_u8.npy", &p);

    // BVH: two frames of the motion skeleton.
    let motion = wscg_motion::bvh::motion_from_frames(
        vec![vec![0.1; wscg_motion::skeleton::N_CHANNELS]; 2],
        &[0.0, 0.05],
        1.0 / 120.0,
    );
    let text = wscg_motion::bvh::to_bvh_string(&motion).expect("bvh");
    put(&corpus, "bvh", "two_frames.bvh", text.as_bytes());

    // NTU RGB+D: three frames of one body.
    let mut ntu = String::from("3\n");
    for t in 0..3 {
        ntu.push_str("1\n72057594037931101 0 1 1 1 1 0 0.01 -0.02 2\n25\n");
        for j in 0..25 {
            ntu.push_str(&format!(
                "{} {} 3 250.5 200.5 900.5 500.5 1 0 0 0 2\n",
                0.01 * j as f64,
                0.05 * j as f64 + 0.01 * t as f64
            ));
        }
    }
    put(&corpus, "ntu", "one_body.skeleton", ntu.as_bytes());

    // Skeleton CSV: three frames of 25 joints.
    let flat: Vec<f64> = (0..3 * 25 * 3).map(|i| (i % 11) as f64 * 0.1).collect();
    let seq = wscg_biometrics::gait::SkeletonSeq::from_flat(30.0, &flat, 3, 25).expect("skeleton");
    let p = tmp(&work, "walk.csv");
    wscg_biometrics::gait::write_skeleton_csv(&p, &seq).expect("csv");
    keep(&corpus, "skeleton_csv", "walk.csv", &p);

    // Octree: the exact-square scene, shallow.
    let (mesh, cube) = wscg_octree::scenes::exact_square().expect("scene");
    let params = wscg_octree::BuildParams::default()
        .max_depth(3)
        .domain(Some(cube));
    let (tree, _) = wscg_octree::build(&mesh, &params).expect("octree");
    put(&corpus, "octree", "square.oct", &tree.to_bytes());

    // Paper-03 packages of the volume the ROI target's client is built from.
    let server = targets::volren_server();
    put(
        &corpus,
        "volren_static",
        "head.pkg",
        &server.static_package(),
    );
    for (name, min, max) in [
        ("corner.roi", [0, 0, 0], [8, 8, 4]),
        ("whole.roi", [0, 0, 0], [16, 16, 8]),
    ] {
        let pkg = server.roi_package(min, max).expect("roi");
        put(&corpus, "volren_roi", name, &pkg);
    }

    targets::readers::write_seeds(&corpus, &work);

    std::fs::remove_dir_all(&work).ok();
}
