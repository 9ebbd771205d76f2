//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters, where that method needs no data).

use wscg_deblur::multiframe::AlignMode;
use wscg_deblur::synth::{ou_gyro, BlurRenderParams, ShakeParams};
use wscg_deblur::{
    AlignParams, Gamma, HyperLaplacianParams, KernelParams, MultiframeParams, Tiling,
};
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
    assert!(AlignParams::default().validate().is_ok());
    assert!(AlignParams::default().iterations([0; 3]).validate().is_ok());
    assert_eq!(field(AlignParams::default().levels(0).validate()), "levels");
    assert_eq!(field(AlignParams::default().eps(-1.0).validate()), "eps");

    assert!(ShakeParams::default().validate().is_ok());
    assert_eq!(field(ShakeParams::default().rate(0.0).validate()), "rate");
    assert_eq!(
        field(ShakeParams::default().tau(f64::NAN).validate()),
        "tau"
    );
    assert_eq!(
        field(ShakeParams::default().duration(-1.0).validate()),
        "duration"
    );
    assert_eq!(
        field(ShakeParams::default().std([0.1, -0.1, 0.1]).validate()),
        "std"
    );
    assert_eq!(
        field(ShakeParams::default().t0(f64::INFINITY).validate()),
        "t0"
    );
    assert_eq!(field(ou_gyro(&ShakeParams::default().tau(0.0), 1)), "tau");

    assert!(BlurRenderParams::default().validate().is_ok());
    assert_eq!(
        field(BlurRenderParams::default().min_steps(0).validate()),
        "min_steps"
    );
    assert_eq!(
        field(BlurRenderParams::default().noise_sigma(-0.1).validate()),
        "noise_sigma"
    );
    assert_eq!(
        field(
            BlurRenderParams::default()
                .gamma(Some(Gamma(0.0)))
                .validate()
        ),
        "gamma"
    );

    assert!(HyperLaplacianParams::default().validate().is_ok());
    assert_eq!(
        field(HyperLaplacianParams::default().lambda(0.0).validate()),
        "lambda"
    );
    assert_eq!(
        field(HyperLaplacianParams::default().alpha(2.5).validate()),
        "alpha"
    );
    assert_eq!(
        field(HyperLaplacianParams::default().beta0(0.0).validate()),
        "beta0"
    );
    assert_eq!(
        field(HyperLaplacianParams::default().beta_rate(1.0).validate()),
        "beta_rate"
    );
    assert_eq!(
        field(
            HyperLaplacianParams::default()
                .beta_max(f32::INFINITY)
                .validate()
        ),
        "beta_max"
    );
    assert_eq!(
        field(HyperLaplacianParams::default().inner(0).validate()),
        "inner"
    );

    assert!(KernelParams::default().validate().is_ok());
    assert!(KernelParams::fixed(8).validate().is_ok());
    assert_eq!(
        field(KernelParams::default().min_steps(0).validate()),
        "min_steps"
    );
    assert_eq!(
        field(KernelParams::default().max_steps(16).validate()),
        "max_steps"
    );
    assert_eq!(
        field(KernelParams::default().max_step_px(0.0).validate()),
        "max_step_px"
    );
    assert_eq!(
        field(KernelParams::default().threshold(1.0).validate()),
        "threshold"
    );
    assert_eq!(
        field(KernelParams::default().max_size(0).validate()),
        "max_size"
    );

    assert!(MultiframeParams::default().validate().is_ok());
    assert_eq!(
        field(MultiframeParams::default().t_exposure(0.0).validate()),
        "t_exposure"
    );
    assert_eq!(
        field(MultiframeParams::default().t_readout(-1.0).validate()),
        "t_readout"
    );
    assert_eq!(field(MultiframeParams::default().mu(-1.0).validate()), "mu");
    assert_eq!(
        field(MultiframeParams::default().min_ncc(f64::NAN).validate()),
        "min_ncc"
    );
    assert_eq!(
        field(
            MultiframeParams::default()
                .tiling(Tiling {
                    tile: 0,
                    ..Tiling::default()
                })
                .validate()
        ),
        "tile"
    );
    assert_eq!(
        field(
            MultiframeParams::default()
                .hl(HyperLaplacianParams::default().inner(0))
                .validate()
        ),
        "inner"
    );
    assert_eq!(
        field(
            MultiframeParams::default()
                .kernel(KernelParams::default().max_size(0))
                .validate()
        ),
        "max_size"
    );
    assert_eq!(
        field(
            MultiframeParams::default()
                .align(AlignMode::Ecc(AlignParams::default().levels(0)))
                .validate()
        ),
        "levels"
    );
}
