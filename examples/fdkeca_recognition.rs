//! Paper 01 in a few lines: fit FDKECA on synthetic finger veins, recognise held-out images
//! with the 1-NN rule, compare with PCA, and write the eigen-image view of the paper's
//! section 4 (the first 63 FDKECA axes of ten images of one subject, polynomial kernel of
//! degree 2) as PNG files.
//!
//! Run: `cargo run --release --example fdkeca_recognition [OUT_DIR]`

use faer::Mat;
use wscg::biometrics::data::{finger_veins, split_per_subject, FingerVeinParams};
use wscg::biometrics::subspace::{
    accuracy, Fdkeca, FdkecaParams, Gamma, Kernel, Metric, Pca, SubspaceClassifier,
};

fn main() -> wscg::math::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "fdkeca-example".into());
    std::fs::create_dir_all(&out).map_err(|e| wscg::math::Error::io(&out, e))?;

    // 200 subjects x 10 images of 10 x 20 pixels; 5 per subject train, 5 test.
    let data = finger_veins(&FingerVeinParams::default())?;
    let (tr, te) = split_per_subject(&data.labels, 5, 0)?;
    let pick = |idx: &[usize]| Mat::from_fn(idx.len(), 200, |i, j| data.x[(idx[i], j)]);
    let (xtr, xte) = (pick(&tr), pick(&te));
    let ytr: Vec<u32> = tr.iter().map(|&i| data.labels[i]).collect();
    let yte: Vec<u32> = te.iter().map(|&i| data.labels[i]).collect();

    let fd = Fdkeca::fit(
        xtr.as_ref(),
        &FdkecaParams::default().n_components(Some(60)),
    )?;
    println!(
        "FDKECA: sigma = {:.3} (median heuristic), Renyi estimate V = {:.4}",
        fd.kernel.sigma().unwrap_or(f64::NAN),
        fd.renyi_entropy_estimate()
    );
    let clf = SubspaceClassifier::new(fd, xtr.as_ref(), &ytr, Metric::Euclidean)?;
    let acc = accuracy(&clf.predict(xte.as_ref())?, &yte)?;
    println!(
        "FDKECA, 60 axes: {:.1} % of {} test images",
        100.0 * acc,
        yte.len()
    );
    let pca = Pca::fit(xtr.as_ref(), Some(60), false)?;
    let clf = SubspaceClassifier::new(pca, xtr.as_ref(), &ytr, Metric::Euclidean)?;
    let acc = accuracy(&clf.predict(xte.as_ref())?, &yte)?;
    println!("PCA,    60 axes: {:.1} %", 100.0 * acc);

    // Section 4: eigen-images of ten images of subject 0.
    let ten = Mat::from_fn(10, 200, |i, j| data.x[(i, j)]);
    let poly = Fdkeca::fit(
        ten.as_ref(),
        &FdkecaParams::default().kernel(Kernel::Polynomial {
            degree: 2,
            gamma: Gamma::InvDim,
            coef0: 1.0,
        }),
    )?;
    for (k, img) in poly.axis_images(63, 10, 20)?.iter().enumerate() {
        img.save(format!("{out}/fdkeca_axis_{:02}.png", k + 1))?;
    }
    println!("63 FDKECA eigen-images written to {out}/");
    Ok(())
}
