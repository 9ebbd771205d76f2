//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters, where that method needs no data).
//!
//! `gait::synth::SubjectParams` has no `Default` (it is one synthetic person's gait, drawn by
//! the generator) and no `validate()`; it is not listed here.

use wscg_biometrics::data::{finger_veins, FingerVeinParams};
use wscg_biometrics::dtw::DtwParams;
use wscg_biometrics::ear::synth::EarSynthParams;
use wscg_biometrics::ear::{EarParams, SkinRule};
use wscg_biometrics::gait::synth::{NoiseParams, SessionParams};
use wscg_biometrics::gait::{CycleParams, GaitParams, HistSpec, UpAxis, Vote};
use wscg_biometrics::sfa::handpose::generate::{generate, HandposeSynthParams};
use wscg_biometrics::sfa::handpose::protocol::CompareParams;
use wscg_biometrics::sfa::isomap::IsomapParams;
use wscg_biometrics::sfa::{ClassObjective, ClassSfaParams};
use wscg_biometrics::subspace::{FdkecaParams, Kernel, ProtocolParams, Sigma};
use wscg_math::Result;

/// The field an `Error::InvalidArgument` names; panics on success or another error.
fn field<T>(r: Result<T>) -> &'static str {
    match r {
        Err(e) => e
            .argument()
            .unwrap_or_else(|| panic!("expected an invalid-argument error, got {e}")),
        Ok(_) => panic!("expected an invalid-argument error, got a result"),
    }
}

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    // subspace
    assert!(FdkecaParams::default().validate().is_ok());
    assert_eq!(
        field(FdkecaParams::default().n_components(Some(0)).validate()),
        "n_components"
    );
    let bad_kernel = Kernel::Gaussian {
        sigma: Sigma::Fixed(-1.0),
    };
    assert_eq!(
        field(FdkecaParams::default().kernel(bad_kernel).validate()),
        "sigma"
    );
    assert!(ProtocolParams::default().validate().is_ok());
    assert_eq!(
        field(ProtocolParams::default().max_dim(0).validate()),
        "max_dim"
    );
    assert_eq!(
        field(ProtocolParams::default().cv_folds(Some(1)).validate()),
        "cv_folds"
    );

    // gait
    assert!(CycleParams::default().validate().is_ok());
    assert_eq!(
        field(CycleParams::default().smooth_window(0).validate()),
        "smooth_window"
    );
    assert_eq!(
        field(CycleParams::default().min_step_s(f64::NAN).validate()),
        "min_step_s"
    );
    assert_eq!(
        field(CycleParams::default().min_prominence(-1.0).validate()),
        "min_prominence"
    );
    assert_eq!(
        field(
            CycleParams::default()
                .up(UpAxis::Vector([0.0; 3]))
                .validate()
        ),
        "up"
    );
    assert!(GaitParams::default().validate().is_ok());
    assert_eq!(
        field(GaitParams::default().min_bins(f64::INFINITY).validate()),
        "min_bins"
    );
    assert_eq!(
        field(
            GaitParams::default()
                .vote(Vote::Majority { k: 0 })
                .validate()
        ),
        "vote"
    );
    assert_eq!(
        field(
            GaitParams::default()
                .cycle(CycleParams::default().smooth_window(0))
                .validate()
        ),
        "smooth_window"
    );
    let hist = HistSpec {
        bin_deg: 0.0,
        ..HistSpec::default()
    };
    assert_eq!(
        field(GaitParams::default().hist(hist).validate()),
        "bin_deg"
    );
    assert!(NoiseParams::default().validate().is_ok());
    assert!(NoiseParams::none().validate().is_ok());
    assert_eq!(field(NoiseParams::default().rho(1.0).validate()), "rho");
    assert_eq!(
        field(NoiseParams::default().distal(-0.1).validate()),
        "distal"
    );
    assert!(SessionParams::default().validate().is_ok());
    assert_eq!(
        field(SessionParams::default().speed(0.0).validate()),
        "speed"
    );
    assert_eq!(field(SessionParams::default().fps(-30.0).validate()), "fps");
    assert_eq!(
        field(SessionParams::default().heading_deg(f64::NAN).validate()),
        "heading_deg"
    );
    assert_eq!(
        field(SessionParams::default().jitter_deg(-1.0).validate()),
        "jitter_deg"
    );
    assert_eq!(
        field(SessionParams::default().bone_bias(1.0).validate()),
        "bone_bias"
    );
    assert_eq!(
        field(
            SessionParams::default()
                .noise(NoiseParams::default().trunk(f64::NAN))
                .validate()
        ),
        "trunk"
    );

    // DTW: every value of every field is valid.
    assert!(DtwParams::default().validate().is_ok());
    assert!(DtwParams::default()
        .window(Some(0))
        .normalize(true)
        .validate()
        .is_ok());

    // sfa
    assert!(ClassSfaParams::default().validate().is_ok());
    assert_eq!(
        field(ClassSfaParams::default().pca_dims(0).validate()),
        "pca_dims"
    );
    assert_eq!(
        field(ClassSfaParams::default().m_per_class(0).validate()),
        "m_per_class"
    );
    assert_eq!(
        field(ClassSfaParams::default().shrinkage(-1.0).validate()),
        "shrinkage"
    );
    assert_eq!(
        field(ClassSfaParams::default().rank_tol(f64::NAN).validate()),
        "rank_tol"
    );
    assert_eq!(
        field(
            ClassSfaParams::default()
                .objective(ClassObjective::WithinMinusOutOfClass { gamma: -1.0 })
                .validate()
        ),
        "gamma"
    );
    assert!(IsomapParams::default().validate().is_ok());
    assert_eq!(
        field(IsomapParams::default().n_neighbors(0).validate()),
        "n_neighbors"
    );
    assert_eq!(
        field(IsomapParams::default().n_components(0).validate()),
        "n_components"
    );
    assert_eq!(
        field(IsomapParams::default().n_landmarks(Some(1)).validate()),
        "n_landmarks"
    );
    assert_eq!(
        field(IsomapParams::default().n_landmarks(Some(4)).validate()),
        "n_components"
    );
    assert!(CompareParams::default().validate().is_ok());
    assert_eq!(field(CompareParams::default().k(0).validate()), "k");
    assert_eq!(
        field(CompareParams::default().physical_per_class(0).validate()),
        "physical_per_class"
    );
    assert_eq!(
        field(
            CompareParams::default()
                .isomap_per_class(Some(0))
                .validate()
        ),
        "isomap_per_class"
    );
    assert_eq!(
        field(CompareParams::default().isomap_landmarks(1).validate()),
        "isomap_landmarks"
    );
    assert_eq!(
        field(
            CompareParams::default()
                .isomap(IsomapParams::default().n_neighbors(0))
                .validate()
        ),
        "n_neighbors"
    );
    assert_eq!(
        field(
            CompareParams::default()
                .sfa(ClassSfaParams::default().pca_dims(0))
                .validate()
        ),
        "pca_dims"
    );
    assert!(HandposeSynthParams::default().validate().is_ok());
    assert_eq!(
        field(HandposeSynthParams::default().n_per_class(0).validate()),
        "n_per_class"
    );
    assert_eq!(
        field(HandposeSynthParams::default().subjects(0).validate()),
        "subjects"
    );
    assert_eq!(
        field(HandposeSynthParams::default().width(31).validate()),
        "width"
    );
    assert_eq!(
        field(HandposeSynthParams::default().height(0).validate()),
        "height"
    );
    assert_eq!(
        field(generate(&HandposeSynthParams::default().subjects(0))),
        "subjects"
    );

    // data
    assert!(FingerVeinParams::default().validate().is_ok());
    assert_eq!(
        field(FingerVeinParams::default().subjects(0).validate()),
        "subjects"
    );
    assert_eq!(
        field(FingerVeinParams::default().samples(0).validate()),
        "samples"
    );
    assert_eq!(
        field(FingerVeinParams::default().size((0, 20)).validate()),
        "size"
    );
    assert_eq!(
        field(FingerVeinParams::default().canvas((5, 80)).validate()),
        "canvas"
    );
    assert_eq!(
        field(FingerVeinParams::default().blur(-1.0).validate()),
        "blur"
    );
    assert_eq!(
        field(finger_veins(&FingerVeinParams::default().noise(f64::NAN))),
        "noise"
    );

    // ear
    assert!(EarSynthParams::default().validate().is_ok());
    assert_eq!(
        field(EarSynthParams::default().height(15).validate()),
        "height"
    );
    assert_eq!(
        field(EarSynthParams::default().width(8).validate()),
        "width"
    );
    assert_eq!(
        field(EarSynthParams::default().noise_sigma(-3.0).validate()),
        "noise_sigma"
    );
    assert_eq!(
        field(EarSynthParams::default().gain((1.2, 1.0)).validate()),
        "gain"
    );
    assert!(EarParams::default().validate().is_ok());
    assert_eq!(field(EarParams::default().block(3).validate()), "block");
    assert_eq!(
        field(EarParams::default().block_skin_fraction(0.0).validate()),
        "block_skin_fraction"
    );
    assert_eq!(
        field(EarParams::default().close_radius(-1.0).validate()),
        "close_radius"
    );
    assert_eq!(
        field(
            EarParams::default()
                .skin_rule(SkinRule::joint().with_min_likelihood(2.0))
                .validate()
        ),
        "skin_rule"
    );
}
