//! Fuzz targets of the readers that moved out of the command line into their crates: the
//! DoE study and runs tables, the motion step table, paint descriptions, camera files, camera
//! responses and exposure times, headerless raw volumes, SFA and gait model files, ear galleries and frame times. `targets::run` hands every target it does not know to [`run`].

use std::path::Path;

/// The targets of this file, by the name of their corpus folder.
pub const READER_TARGETS: &[&str] = &[
    "doe_study",
    "doe_runs",
    "motion_steps",
    "paint_json",
    "camera_json",
    "crf_csv",
    "exposure_times",
    "raw_volume",
    "sfa_model",
    "ear_gallery",
    "gait_model",
    "frame_times",
];

/// What separates `gallery.json` from `templates.npy` in an `ear_gallery` input.
pub const GALLERY_SEPARATOR: &[u8] = b"@@templates.npy@@";

/// Trials the `motion_steps` target reads a step table for.
pub const STEP_TRIALS: usize = 4;

/// The raw types by the byte that picks them in the `raw_volume` target.
const RAW_TYPES: [&str; 7] = ["u8", "u16le", "u16be", "i16le", "i16be", "f32le", "f32be"];

/// The header the `raw_volume` harness reads before the voxels: one byte for the raw type
/// (modulo 7), then `nx`, `ny`, `nz` as little-endian `u16` (so a declared size reaches
/// 2^48 voxels, far above the voxel limit).
pub const RAW_HEADER: usize = 7;

/// The `raw_volume` input of `dims` voxels of type `type_index` (see [`RAW_HEADER`]).
pub fn raw_input(type_index: u8, dims: [u16; 3], voxels: &[u8]) -> Vec<u8> {
    let mut out = vec![type_index];
    for d in dims {
        out.extend_from_slice(&d.to_le_bytes());
    }
    out.extend_from_slice(voxels);
    out
}

/// The relevance threshold of the gait seed's model (the paper's is 20 bins): only the
/// joint pairs whose angles spread over at least this many 1-degree bins are kept.
const GAIT_SEED_MIN_BINS: f64 = 25.0;

/// Runs the reader of `target` on `data`: `Some(accepted)`, or `None` for a target that is
/// not one of [`READER_TARGETS`].
pub fn run(target: &str, data: &[u8], origin: &Path) -> Option<bool> {
    Some(match target {
        "doe_study" => wscg_doe::parse_study(data, origin).is_ok(),
        // `parse_runs` reads the table through `parse_design`.
        "doe_runs" => wscg_doe::parse_runs(data, origin).is_ok(),
        "motion_steps" => wscg_motion::dataset_io::parse_steps(data, origin, STEP_TRIALS).is_ok(),
        "paint_json" => {
            wscg_raytrace::paint::PaintDescription::from_json_bytes(data, origin).is_ok()
        }
        "camera_json" => wscg_deblur::CameraFile::from_json_bytes(data, origin).is_ok(),
        "crf_csv" => wscg_hdr::Crf::from_csv_bytes(data, origin).is_ok(),
        "exposure_times" => {
            // The same bytes as a text file and as a JSON file.
            let text = wscg_hdr::files::parse_exposure_times_text(data, origin).is_ok();
            let json = wscg_hdr::files::parse_exposure_times_json(data, origin).is_ok();
            text || json
        }
        "raw_volume" => {
            if data.len() < RAW_HEADER {
                return Some(false);
            }
            let raw_type: wscg_math::io::RawType = RAW_TYPES[usize::from(data[0]) % 7]
                .parse()
                .expect("raw type name");
            let dim = |k: usize| usize::from(u16::from_le_bytes([data[k], data[k + 1]]));
            let dims = [dim(1), dim(3), dim(5)];
            wscg_math::Volume::from_raw_bytes(
                &data[RAW_HEADER..],
                origin,
                dims,
                [1.0, 0.5, 2.0],
                raw_type,
            )
            .is_ok()
        }
        "sfa_model" => match wscg_biometrics::sfa::SfaModelFile::from_json_bytes(data, origin) {
            // A model that reads must also score: two rows of its input width (bounded, so
            // a declared width is not an allocation).
            Ok(m) if m.model.input_dim() <= 1 << 12 => {
                let x = faer::Mat::from_fn(2, m.model.input_dim(), |i, j| (i + j) as f64);
                m.model.predict_scores(x.as_ref()).is_ok()
            }
            Ok(_) => true,
            Err(_) => false,
        },
        "ear_gallery" => {
            let cut = data
                .windows(GALLERY_SEPARATOR.len())
                .position(|w| w == GALLERY_SEPARATOR)
                .unwrap_or(data.len());
            let (json, rest) = data.split_at(cut);
            let npy_bytes = rest.get(GALLERY_SEPARATOR.len()..).unwrap_or_default();
            let templates_origin = Path::new("templates.npy");
            wscg_math::npy::from_bytes_with_limit::<f32>(npy_bytes, templates_origin, 1 << 24)
                .and_then(|t| {
                    wscg_biometrics::ear::EarGalleryFile::from_parts(
                        json,
                        origin,
                        t,
                        templates_origin,
                    )
                })
                .and_then(|g| g.gallery())
                .is_ok()
        }
        "gait_model" => match wscg_biometrics::gait::GaitModelFile::from_json_bytes(data, origin) {
            // A model that reads must also identify: a query of a short sequence per pair.
            Ok(m) if m.recognizer.pairs.len() <= 1 << 10 => {
                let q = vec![vec![0.25, 0.5, 1.0, 0.5]; m.recognizer.pairs.len()];
                m.recognizer.predict_selected(&q).is_ok()
            }
            Ok(_) => true,
            Err(_) => false,
        },
        "frame_times" => wscg_deblur::gyro::parse_frame_times(data, origin).is_ok(),
        _ => return None,
    })
}

/// Writes the seeds of these targets with the project's writers into `<corpus>/<target>/`
/// (`work` holds the files before they are copied).
pub fn write_seeds(corpus: &Path, work: &Path) {
    let keep = |target: &str, name: &str, from: &Path| {
        let dir = corpus.join(target);
        std::fs::create_dir_all(&dir).expect("corpus folder");
        std::fs::copy(from, dir.join(format!("seed_{name}"))).expect("copy seed");
    };

    // A study of 2 subjects x 2 conditions x 3 stimuli.
    let study = wscg_doe::Study {
        subjects: vec!["ann".into(), "bob".into()],
        conditions: vec!["mono".into(), "stereo".into()],
        stimuli: 3,
        scores: (0..12).map(|i| f64::from(i % 11) * 0.75).collect(),
    };
    let p = work.join("scores.csv");
    wscg_doe::write_study(&p, &study).expect("study");
    keep("doe_study", "scores.csv", &p);

    // The 9 runs of a two-factor faced design with a quadratic response.
    let x = wscg_doe::ccd_blocks(
        2,
        wscg_doe::CcdFace::Faced,
        wscg_doe::CcdAlpha::Rotatable,
        (1, 0),
    )
    .expect("design");
    let y: Vec<f64> = x
        .row_iter()
        .map(|r| 5.0 + r[0] - 0.5 * r[1] + 0.25 * r[0] * r[0])
        .collect();
    let p = work.join("runs.csv");
    wscg_doe::write_runs(&p, &x, &y).expect("runs");
    keep("doe_runs", "runs.csv", &p);

    // The step table of a small training folder of STEP_TRIALS trials.
    let action = |t: usize, a: usize| wscg_motion::TrialAction {
        angles: vec![0.1 * (t + a) as f64; 4],
        step_length: 0.5 + 0.05 * t as f64,
        duration: 1.0 + 0.1 * a as f64,
        root: Vec::new(),
    };
    let data = wscg_motion::Dataset {
        n_channels: 2,
        n_samples: 2,
        trials: (0..STEP_TRIALS)
            .map(|t| std::array::from_fn(|a| action(t, a)))
            .collect(),
        distances: Vec::new(),
    };
    let dir = work.join("walk");
    wscg_motion::write_dataset(&dir, &data).expect("dataset");
    keep("motion_steps", "steps.csv", &dir.join("steps.csv"));

    // Paint descriptions: the paper's reference paint, and one of every key.
    let mut paint = wscg_raytrace::paint::PaintDescription::default();
    paint.radius_um = Some(26.0);
    paint.density = Some(7.3);
    paint.seed = Some(1);
    let p = work.join("reference.json");
    paint.write(&p).expect("paint");
    keep("paint_json", "reference.json", &p);
    paint.tilt_deg = Some(8.0);
    paint.model = Some("deposit".into());
    paint.thickness_um = Some(0.5);
    paint.layer_um = Some(20.24);
    paint.binder_absorption_per_mm = Some(0.1);
    paint.binder_ior = Some(1.5);
    paint.base_albedo = Some(0.2);
    paint.coat_ior = Some(1.55);
    paint.coat_um = Some(40.0);
    let p = work.join("every_key.json");
    paint.write(&p).expect("paint");
    keep("paint_json", "every_key.json", &p);

    // A camera file of every key.
    let mut camera = wscg_deblur::CameraFile::default();
    camera.f = Some(720.0);
    camera.cx = Some(319.5);
    camera.cy = Some(239.5);
    camera.exposure = Some(0.03);
    camera.readout = Some(0.025);
    camera.delay = Some(-0.004);
    let p = work.join("camera.json");
    camera.write(&p).expect("camera");
    keep("camera_json", "camera.json", &p);

    // An 8-bit camera response and exposure times, as text and as JSON.
    let p = work.join("crf.csv");
    wscg_hdr::Crf::gamma(2.2, 8, 1)
        .expect("crf")
        .write_csv(&p)
        .expect("crf csv");
    keep("crf_csv", "gamma.csv", &p);
    let p = work.join("times.txt");
    wscg_hdr::write_exposure_times(&p, &[1.0 / 60.0, 1.0 / 15.0, 0.25]).expect("times");
    keep("exposure_times", "times.txt", &p);
    let dir = corpus.join("exposure_times");
    std::fs::write(
        dir.join("seed_times.json"),
        "{\"exposure_times\": [0.016666666666666666, 0.06666666666666667, 0.25]}\n",
    )
    .expect("seed");

    // SFA models (class-wise and global) fitted on 3 classes of 6 rows of 5 values.
    let x = faer::Mat::from_fn(18, 5, |i, j| ((i * 7 + j * 3) % 11) as f64 + (i / 6) as f64);
    let y: Vec<u32> = (0..18).map(|i| i as u32 / 6).collect();
    let cfg = wscg_biometrics::sfa::ClassSfaParams::default()
        .pca_dims(3)
        .m_per_class(2)
        .shrinkage(1e-3);
    let names: Vec<String> = ["open", "fist", "point"].map(String::from).to_vec();
    let class = wscg_biometrics::sfa::PerClassSfa::fit(x.as_ref(), &y, &cfg).expect("sfa");
    let global = wscg_biometrics::sfa::GlobalSfa::fit(
        x.as_ref(),
        &y,
        &cfg,
        wscg_biometrics::sfa::GlobalRule::Gaussian,
    )
    .expect("sfa");
    for (name, model) in [
        ("class.json", wscg_biometrics::sfa::FittedSfa::Class(class)),
        (
            "global.json",
            wscg_biometrics::sfa::FittedSfa::Global(global),
        ),
    ] {
        let p = work.join(name);
        wscg_biometrics::sfa::SfaModelFile::new(model, names.clone(), None, 1)
            .write(&p)
            .expect("sfa model");
        keep("sfa_model", name, &p);
    }

    // An ear gallery of 3 templates of 2 identities, 20 x 20 ears in 10-pixel blocks,
    // written by the project's writer, then joined as the harness reads it.
    let params = wscg_biometrics::ear::EarParams::default()
        .height(20)
        .width(20)
        .block(10);
    let per = params.blocks() * params.block_len();
    let gallery = wscg_biometrics::ear::EarGalleryFile::new(
        vec!["ann".into(), "bob".into()],
        vec![0, 0, 1],
        vec!["ann_1.png".into(), "ann_2.png".into(), "bob_1.png".into()],
        &params,
        (0..3 * per).map(|i| (i % 17) as f32 / 8.0).collect(),
    )
    .expect("gallery");
    let dir = work.join("gallery");
    gallery.write(&dir).expect("gallery folder");
    let mut input = std::fs::read(dir.join(wscg_biometrics::ear::GALLERY_JSON)).expect("json");
    input.extend_from_slice(GALLERY_SEPARATOR);
    input.extend(std::fs::read(dir.join(wscg_biometrics::ear::GALLERY_TEMPLATES)).expect("npy"));
    let corpus_dir = corpus.join("ear_gallery");
    std::fs::create_dir_all(&corpus_dir).expect("corpus folder");
    std::fs::write(corpus_dir.join("seed_gallery"), input).expect("seed");

    // A gait model fitted on two sessions of 2 synthetic walkers, keeping only the pairs of
    // the widest angle ranges: a small file (a few kB), so that each execution is quick,
    // with every part of the format present.
    let set = wscg_biometrics::gait::synth::walkers(
        2,
        2,
        &wscg_biometrics::gait::synth::SessionRanges::default(),
        5,
    )
    .expect("walkers");
    let rec = wscg_biometrics::gait::GaitRecognizer::fit(
        &set.walks,
        &set.labels,
        &wscg_biometrics::gait::GaitParams::default().min_bins(GAIT_SEED_MIN_BINS),
    )
    .expect("gait model");
    let p = work.join("gait.json");
    let ids = ["ann", "bob"].map(String::from).to_vec();
    wscg_biometrics::gait::GaitModelFile::new(30.0, ids, Vec::new(), rec)
        .write(&p)
        .expect("gait model file");
    keep("gait_model", "gait.json", &p);

    // Frame times as `wscg deblur frames` reads them.
    let dir = corpus.join("frame_times");
    std::fs::create_dir_all(&dir).expect("corpus folder");
    std::fs::write(
        dir.join("seed_times.txt"),
        "# frame start times (s)\n0.0\n0.033367\n0.066733\n0.1001\n",
    )
    .expect("seed");

    // A 3 x 2 x 2 float volume written by `write_raw_f32_le`, behind the harness's header.
    let v = wscg_math::Volume::new(
        [3, 2, 2],
        [1.0, 0.5, 2.0],
        (0..12).map(|i| i as f32 * 0.5 - 2.0).collect(),
    )
    .expect("volume");
    let p = work.join("v.raw");
    v.write_raw_f32_le(&p).expect("raw");
    let voxels = std::fs::read(&p).expect("raw bytes");
    let dir = corpus.join("raw_volume");
    std::fs::create_dir_all(&dir).expect("corpus folder");
    std::fs::write(dir.join("seed_f32le.raw"), raw_input(5, [3, 2, 2], &voxels)).expect("seed");
    std::fs::write(
        dir.join("seed_u16be.raw"),
        raw_input(2, [2, 2, 1], &[0, 1, 2, 3, 255, 254, 128, 0]),
    )
    .expect("seed");
}
