//! The recognition system around paper 01's methods: any-method models, reconstruction,
//! stored recognizers and the loaders for users' image folders and `.npy` files.

use std::path::Path;

use faer::Mat;
use wscg_biometrics::data::files::{load_identity_folder, read_npy_dataset};
use wscg_biometrics::data::{finger_veins, split_per_subject, FingerVeinParams};
use wscg_biometrics::subspace::*;
use wscg_math::{npy, Image};

fn veins(subjects: usize, samples: usize) -> wscg_biometrics::data::LabelledImages {
    finger_veins(
        &FingerVeinParams::default()
            .subjects(subjects)
            .samples(samples)
            .seed(3),
    )
    .unwrap()
}

#[test]
fn models_round_trip_through_json_and_truncate() {
    let data = veins(6, 6);
    for method in Method::table1(Some(30)) {
        let m = method.fit(data.x.as_ref()).unwrap();
        assert_eq!(m.name(), method.name());
        let back = Model::from_json(&m.to_json().unwrap()).unwrap();
        assert_eq!(back, m);
        let z = m.transform(data.x.as_ref()).unwrap();
        let t = m.truncated(5).unwrap();
        assert_eq!(t.n_components(), 5);
        let zt = t.transform(data.x.as_ref()).unwrap();
        for i in 0..z.nrows() {
            for j in 0..5 {
                assert!((z[(i, j)] - zt[(i, j)]).abs() <= 1e-12 * (1.0 + z[(i, j)].abs()));
            }
        }
        assert!(m.truncated(0).is_err());
        assert!(m.truncated(m.n_components() + 1).is_err());
    }
}

#[test]
fn linear_models_reconstruct_exactly_at_full_rank() {
    let data = veins(30, 4); // N = 120 < d = 200: PCA keeps 120 axes, FDKECA all 200.
    let x = data.x.as_ref();
    let fd = Fdkeca::fit(x, &FdkecaParams::default()).unwrap();
    let back = fd
        .inverse_transform(fd.transform(x).unwrap().as_ref())
        .unwrap();
    assert!((&back - x).norm_max() < 1e-10);
    assert!(Pca::fit(x, None, true).is_err());
    for whiten in [false, true] {
        let p = Pca::fit(x, Some(100), whiten).unwrap();
        // The centred data has rank N - 1 = 119; whitening needs nonzero variances.
        let full = Pca::fit(x, Some(119), whiten).unwrap();
        let rf = full
            .inverse_transform(full.transform(x).unwrap().as_ref())
            .unwrap();
        assert!((&rf - x).norm_max() < 1e-9, "whiten {whiten}");
        let r = p
            .inverse_transform(p.transform(x).unwrap().as_ref())
            .unwrap();
        assert!((&r - x).norm_max() > 1e-6);
    }
    // Reconstruction error shrinks as axes are added (eigenvalue order, linear kernel).
    let lin = Fdkeca::fit(
        x,
        &FdkecaParams::default()
            .kernel(Kernel::Linear)
            .ordering(Ordering::Eigenvalue),
    )
    .unwrap();
    let err = |l: usize| {
        let t = lin.truncated(l).unwrap();
        (t.inverse_transform(t.transform(x).unwrap().as_ref())
            .unwrap()
            - x)
            .norm_l2()
    };
    assert!(err(5) > err(20) && err(20) > err(80));
    let km = Model::KernelPca(KernelPca::fit(x, &Kernel::default(), Some(4)).unwrap());
    let z = km.transform(x).unwrap();
    assert!(km.inverse_transform(z.as_ref()).is_err());
    assert!(fd
        .inverse_transform(Mat::<f64>::zeros(2, 3).as_ref())
        .is_err());
}

#[test]
fn recognizer_identifies_saves_and_loads() {
    let data = veins(20, 6);
    let (tr, te) = split_per_subject(&data.labels, 3, 1).unwrap();
    let (xtr, xte) = (
        select_rows(data.x.as_ref(), &tr),
        select_rows(data.x.as_ref(), &te),
    );
    let ytr: Vec<u32> = tr.iter().map(|&i| data.labels[i]).collect();
    let yte: Vec<u32> = te.iter().map(|&i| data.labels[i]).collect();
    let names: Vec<String> = (0..20).map(|s| format!("subject-{s:02}")).collect();
    let method = Method::Fdkeca(FdkecaParams::default().n_components(Some(40)));
    let rec = Recognizer::fit(
        &method,
        xtr.as_ref(),
        &ytr,
        names.clone(),
        (10, 20),
        Metric::Euclidean,
    )
    .unwrap();
    let ids = rec.identify(xte.as_ref()).unwrap();
    // Identical to fitting, projecting and classifying by hand.
    let m = method.fit(xtr.as_ref()).unwrap();
    let direct = nn_classify(
        m.transform(xtr.as_ref()).unwrap().as_ref(),
        &ytr,
        m.transform(xte.as_ref()).unwrap().as_ref(),
        Metric::Euclidean,
    )
    .unwrap();
    assert_eq!(ids.iter().map(|id| id.label).collect::<Vec<_>>(), direct);
    let correct = ids
        .iter()
        .zip(&yte)
        .filter(|(id, &y)| id.label == y)
        .count();
    assert!(
        correct as f64 / yte.len() as f64 > 0.75,
        "{correct}/{}",
        yte.len()
    );
    assert!(ids.iter().all(|id| id.name == names[id.label as usize]));
    // A gallery image is its own nearest neighbour at distance 0.
    let own = rec.identify(xtr.as_ref()).unwrap();
    assert!(own
        .iter()
        .enumerate()
        .all(|(i, id)| id.gallery_index == i && id.distance < 1e-9));

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.json");
    rec.save(&path).unwrap();
    let back = Recognizer::load(&path).unwrap();
    assert_eq!(back.identify(xte.as_ref()).unwrap(), ids);

    // Bad files are errors naming the problem.
    std::fs::write(&path, "{\"format\": 3}").unwrap();
    assert!(Recognizer::load(&path).is_err());
    let mut other = rec.clone();
    other.version = 99;
    other.save(&path).unwrap();
    let e = Recognizer::load(&path).unwrap_err().to_string();
    assert!(e.contains("newer"), "{e}");
    assert!(Recognizer::load(dir.path().join("missing.json"))
        .unwrap_err()
        .is_io());
    assert!(Recognizer::fit(
        &method,
        xtr.as_ref(),
        &ytr,
        names[..3].to_vec(),
        (10, 20),
        Metric::Euclidean
    )
    .is_err());
    assert!(Recognizer::fit(
        &method,
        xtr.as_ref(),
        &ytr,
        names,
        (9, 20),
        Metric::Euclidean
    )
    .is_err());
}

fn save_grey(path: &Path, h: usize, w: usize, v: &[f64]) {
    Image::new(h, w, 1, v.iter().map(|&x| x as f32).collect())
        .unwrap()
        .save(path)
        .unwrap();
}

#[test]
fn identity_folders_and_npy_files_load() {
    let data = veins(3, 4);
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("gallery");
    for s in 0..3 {
        let sub = root.join(format!("id{s}"));
        std::fs::create_dir_all(&sub).unwrap();
        for k in 0..4 {
            let row: Vec<f64> = (0..200).map(|j| data.x[(s * 4 + k, j)]).collect();
            save_grey(&sub.join(format!("{k}.png")), 10, 20, &row);
        }
    }
    std::fs::write(root.join("notes.txt"), "not an image").unwrap();
    let g = load_identity_folder(&root, None).unwrap();
    assert_eq!(g.names, vec!["id0", "id1", "id2"]);
    assert_eq!(g.images.labels, vec![0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2]);
    assert_eq!((g.images.height, g.images.width), (10, 20));
    // PNG stores 8 bits: values agree to half a grey level.
    let clamp = |v: f64| v.clamp(0.0, 1.0);
    assert!((0..12).all(|i| (0..200)
        .all(|j| (g.images.x[(i, j)] - clamp(data.x[(i, j)])).abs() <= 0.5 / 255.0 + 1e-6)));
    let small = load_identity_folder(&root, Some((5, 10))).unwrap();
    assert_eq!(small.images.x.ncols(), 50);

    // Errors: missing folder, folder without identities, identity without images.
    assert!(load_identity_folder(&dir.path().join("none"), None)
        .unwrap_err()
        .is_io());
    let flat = dir.path().join("flat");
    std::fs::create_dir_all(&flat).unwrap();
    assert!(load_identity_folder(&flat, None).is_err());
    std::fs::create_dir_all(flat.join("empty")).unwrap();
    let e = load_identity_folder(&flat, None).unwrap_err().to_string();
    assert!(e.contains("no PNG/JPEG"), "{e}");
    std::fs::write(root.join("id0").join("broken.png"), b"\x89PNG garbage").unwrap();
    assert!(load_identity_folder(&root, None).is_err());

    // .npy: (n, h, w) stack with labels.
    let xp = dir.path().join("x.npy");
    let lp = dir.path().join("y.npy");
    let flat_x: Vec<f64> = (0..12)
        .flat_map(|i| (0..200).map(move |j| (i, j)))
        .map(|(i, j)| data.x[(i, j)])
        .collect();
    npy::write_f64(&xp, &[12, 10, 20], &flat_x).unwrap();
    let labels: Vec<f64> = [7.0, 7.0, 7.0, 7.0, 3.0, 3.0, 3.0, 3.0, 9.0, 9.0, 9.0, 9.0].to_vec();
    npy::write_f64(&lp, &[12], &labels).unwrap();
    let ds = read_npy_dataset(&xp, &lp).unwrap();
    assert_eq!(ds.images.x, data.x);
    assert_eq!((ds.images.height, ds.images.width), (10, 20));
    assert_eq!(ds.names, vec!["3", "7", "9"]);
    assert_eq!(ds.images.labels[..5], [1, 1, 1, 1, 0]);
    npy::write_f64(&lp, &[4], &labels[..4]).unwrap();
    assert!(read_npy_dataset(&xp, &lp).is_err());
    npy::write_f64(&lp, &[2], &[0.5, 1.0]).unwrap();
    assert!(read_npy_dataset(&xp, &lp).is_err());
    npy::write_f64(&xp, &[2, 3, 4, 5], &[0.0; 120]).unwrap();
    assert!(read_npy_dataset(&xp, &lp).is_err());
}
