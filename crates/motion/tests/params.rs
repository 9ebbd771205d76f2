//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters, where that method needs no data).

use wscg_math::Result;
use wscg_motion::map::SvrMapParams;
use wscg_motion::{
    reach_walk, AnechoicParams, MapKind, StepwiseParams, SynthesizerParams, WalkerParams,
};

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
    assert!(WalkerParams::default().validate().is_ok());
    assert_eq!(
        field(WalkerParams::default().n_trials(0).validate()),
        "n_trials"
    );
    assert_eq!(
        field(WalkerParams::default().n_samples(7).validate()),
        "n_samples"
    );
    assert_eq!(
        field(WalkerParams::default().noise(-0.1).validate()),
        "noise"
    );
    assert_eq!(
        field(WalkerParams::default().range1((1.0, 0.5)).validate()),
        "range1"
    );
    assert_eq!(
        field(WalkerParams::default().range2((0.0, 1.0)).validate()),
        "range2"
    );
    assert_eq!(
        field(reach_walk(&WalkerParams::default().n_samples(0))),
        "n_samples"
    );

    assert!(AnechoicParams::default().validate().is_ok());
    assert_eq!(
        field(AnechoicParams::default().n_sources(0).validate()),
        "n_sources"
    );
    assert_eq!(
        field(AnechoicParams::default().n_harmonics(0).validate()),
        "n_harmonics"
    );
    assert_eq!(
        field(AnechoicParams::default().max_iter(0).validate()),
        "max_iter"
    );
    assert_eq!(
        field(AnechoicParams::default().restarts(0).validate()),
        "restarts"
    );
    assert_eq!(
        field(AnechoicParams::default().delay_search(7).validate()),
        "delay_search"
    );
    assert!(AnechoicParams::default().delay_search(0).validate().is_ok());
    assert_eq!(
        field(AnechoicParams::default().tol(f64::NAN).validate()),
        "tol"
    );

    assert!(StepwiseParams::default().validate().is_ok());
    assert_eq!(
        field(StepwiseParams::default().n_sources_first(0).validate()),
        "n_sources_first"
    );
    assert_eq!(
        field(StepwiseParams::default().round_iter(0).validate()),
        "round_iter"
    );
    assert!(StepwiseParams::default()
        .rounds(0)
        .round_iter(0)
        .validate()
        .is_ok());
    assert_eq!(
        field(
            StepwiseParams::default()
                .demix(AnechoicParams::default().restarts(0))
                .validate()
        ),
        "restarts"
    );
    // The demixing's own source count is set per stage, so it is not checked.
    assert!(StepwiseParams::default()
        .demix(AnechoicParams::default().n_sources(0))
        .validate()
        .is_ok());

    assert!(SvrMapParams::default().validate().is_ok());
    assert_eq!(field(SvrMapParams::default().c(0.0).validate()), "c");
    assert_eq!(
        field(SvrMapParams::default().epsilon(-1.0).validate()),
        "epsilon"
    );
    assert_eq!(
        field(SvrMapParams::default().gamma(f64::INFINITY).validate()),
        "gamma"
    );
    assert_eq!(
        field(SvrMapParams::default().n_phases(0).validate()),
        "n_phases"
    );
    assert_eq!(
        field(SvrMapParams::default().radii(vec![]).validate()),
        "radii"
    );
    assert_eq!(
        field(SvrMapParams::default().radii(vec![1.0, -1.0]).validate()),
        "radii"
    );

    assert!(SynthesizerParams::default().validate().is_ok());
    assert_eq!(
        field(SynthesizerParams::default().beta(0.0).validate()),
        "beta"
    );
    assert_eq!(
        field(SynthesizerParams::default().coupling(-1.0).validate()),
        "coupling"
    );
    assert_eq!(
        field(SynthesizerParams::default().map(MapKind::Lut(2)).validate()),
        "map"
    );
    assert_eq!(
        field(
            SynthesizerParams::default()
                .map(MapKind::Svr(SvrMapParams::default().n_phases(0)))
                .validate()
        ),
        "n_phases"
    );
    assert_eq!(
        field(SynthesizerParams::default().bandwidth(Some(0.0)).validate()),
        "bandwidth"
    );
    assert!(SynthesizerParams::default()
        .bandwidth(Some(f64::INFINITY))
        .validate()
        .is_ok());
}
