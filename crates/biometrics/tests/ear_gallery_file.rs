//! The ear gallery folder of `wscg biometrics ear enroll`: it round-trips, and a folder
//! whose two files disagree is refused naming the file at fault.

use wscg_biometrics::ear::{EarGalleryFile, EarParams, GALLERY_JSON, GALLERY_TEMPLATES};
use wscg_math::{npy, Error};

fn params() -> EarParams {
    EarParams::default().height(20).width(30).block(10)
}

fn gallery() -> EarGalleryFile {
    let p = params();
    let per = p.blocks() * p.block_len();
    assert_eq!(per, 6 * 25);
    EarGalleryFile::new(
        vec!["ann".into(), "bob".into()],
        vec![0, 1, 1],
        vec!["a.png".into(), "b1.png".into(), "b2.png".into()],
        &p,
        (0..3 * per).map(|i| (i % 13) as f32 * 0.1).collect(),
    )
    .unwrap()
}

#[test]
fn a_gallery_round_trips_and_refuses_other_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let g = gallery();
    g.write(dir.path()).unwrap();
    let back = EarGalleryFile::read(dir.path()).unwrap();
    assert_eq!(back, g);
    back.gallery().unwrap();
    back.check_params(&params()).unwrap();
    let err = back.check_params(&EarParams::default()).unwrap_err();
    assert!(err.to_string().contains("enrolled at 20 x 30"), "{err}");
}

#[test]
fn inconsistent_folders_are_refused_naming_the_file() {
    let refused = |edit: &dyn Fn(&std::path::Path), file: &str, expect: &str| {
        let dir = tempfile::tempdir().unwrap();
        gallery().write(dir.path()).unwrap();
        edit(dir.path());
        let err = EarGalleryFile::read(dir.path()).unwrap_err();
        assert!(matches!(err, Error::Format { .. }), "{err}");
        let text = err.to_string();
        assert!(text.contains(file) && text.contains(expect), "{text}");
    };
    refused(
        &|d| edit_json(d, |v| v["labels"] = serde_json::json!([0, 1, 2])),
        GALLERY_JSON,
        "label 2 has no identity",
    );
    refused(
        &|d| edit_json(d, |v| v["files"] = serde_json::json!(["a.png"])),
        GALLERY_JSON,
        "1 files for 3 templates",
    );
    refused(
        &|d| edit_json(d, |v| v["block"] = serde_json::json!(7)),
        GALLERY_JSON,
        "block",
    );
    refused(
        &|d| edit_json(d, |v| v["height"] = serde_json::json!(1u64 << 40)),
        GALLERY_JSON,
        "block",
    );
    refused(
        &|d| edit_json(d, |v| v["width"] = serde_json::json!(40)),
        GALLERY_TEMPLATES,
        "shape [3, 6, 25]",
    );
    refused(
        &|dir: &std::path::Path| {
            npy::write(
                dir.join(GALLERY_TEMPLATES),
                &[3, 6, 25],
                &vec![f32::NAN; 450],
            )
            .unwrap()
        },
        GALLERY_TEMPLATES,
        "not finite",
    );
    refused(
        &|dir: &std::path::Path| {
            std::fs::write(dir.join(GALLERY_JSON), "{\"identities\": 3}").unwrap()
        },
        GALLERY_JSON,
        "not a gallery",
    );
}

/// Rewrites the `gallery.json` of `dir` through `f`.
fn edit_json(dir: &std::path::Path, f: impl Fn(&mut serde_json::Value)) {
    let p = dir.join(GALLERY_JSON);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    f(&mut v);
    std::fs::write(&p, v.to_string()).unwrap();
}
