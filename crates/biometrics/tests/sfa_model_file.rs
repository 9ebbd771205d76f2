//! The SFA model file of `wscg biometrics sfa fit`: it round-trips, and a file whose model
//! is inconsistent is refused when read, naming the file, instead of failing later.

use std::path::Path;

use faer::Mat;
use wscg_biometrics::sfa::{
    ClassSfaParams, FittedSfa, GlobalRule, GlobalSfa, PerClassSfa, SfaModelFile,
};
use wscg_math::Error;

fn data() -> (Mat<f64>, Vec<u32>) {
    let x = Mat::from_fn(24, 6, |i, j| {
        ((i * 5 + j * 3) % 7) as f64 * 0.3 + (i / 8) as f64 * (j % 3) as f64
    });
    (x, (0..24).map(|i| i as u32 / 8).collect())
}

fn cfg() -> ClassSfaParams {
    ClassSfaParams::default()
        .pca_dims(4)
        .m_per_class(2)
        .shrinkage(1e-3)
}

fn names() -> Vec<String> {
    ["a", "b", "c"].map(String::from).to_vec()
}

#[test]
fn both_kinds_round_trip_with_identical_scores() {
    let (x, y) = data();
    let class = PerClassSfa::fit(x.as_ref(), &y, &cfg()).unwrap();
    let global = GlobalSfa::fit(x.as_ref(), &y, &cfg(), GlobalRule::Gaussian).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for model in [FittedSfa::Class(class), FittedSfa::Global(global)] {
        let path = dir.path().join("m.json");
        let (pred, scores) = model.predict_scores(x.as_ref()).unwrap();
        SfaModelFile::new(model, names(), Some((6, 9)), 3)
            .write(&path)
            .unwrap();
        let back = SfaModelFile::read(&path).unwrap();
        assert_eq!(
            (back.names, back.image_shape, back.downscale),
            (names(), Some((6, 9)), 3)
        );
        let (pred2, scores2) = back.model.predict_scores(x.as_ref()).unwrap();
        assert_eq!(pred, pred2);
        assert_eq!(scores, scores2);
    }
}

/// The text of a class-wise model file, as JSON.
fn class_file() -> serde_json::Value {
    let (x, y) = data();
    let model = FittedSfa::Class(PerClassSfa::fit(x.as_ref(), &y, &cfg()).unwrap());
    serde_json::from_str(
        &SfaModelFile::new(model, names(), None, 1)
            .to_json()
            .unwrap(),
    )
    .unwrap()
}

fn refused(v: &serde_json::Value, expect: &str) {
    let origin = Path::new("edited.json");
    let err = SfaModelFile::from_json_bytes(v.to_string().as_bytes(), origin).unwrap_err();
    assert!(matches!(err, Error::Format { .. }), "{err}");
    let text = err.to_string();
    assert!(
        text.contains("edited.json") && text.contains(expect),
        "{text}"
    );
}

#[test]
fn inconsistent_files_are_refused_naming_the_file() {
    let mut v = class_file();
    v["model"]["offsets"].as_array_mut().unwrap().pop();
    refused(&v, "offsets");

    let mut v = class_file();
    v["model"]["means"][1].as_array_mut().unwrap().pop();
    refused(&v, "means");

    let mut v = class_file();
    v["model"]["pca"]["components"][0]
        .as_array_mut()
        .unwrap()
        .pop();
    refused(&v, "axis 0");

    let mut v = class_file();
    v["model"]["classes"] = serde_json::json!([0, 2, 1]);
    refused(&v, "ascending");

    let mut v = class_file();
    v["names"] = serde_json::json!(["a", "b"]);
    refused(&v, "class label 2 has no name");

    let mut v = class_file();
    v["kind"] = serde_json::json!("local");
    refused(&v, "unknown model kind");

    let mut v = class_file();
    v["downscale"] = serde_json::json!(0);
    refused(&v, "downscaling factor is 0");

    let mut v = class_file();
    v["image_shape"] = serde_json::json!([4, 4]);
    refused(&v, "do not give the model's 6 inputs");

    let mut v = class_file();
    v["model"]["w"]["rows"] = serde_json::json!(1u64 << 40);
    refused(&v, "matrix");

    refused(&serde_json::json!([1, 2]), "not an SFA model");
}
