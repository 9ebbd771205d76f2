//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_hdr::synth::{layered_scene, SceneParams};
use wscg_hdr::{
    calibrate_mitsunaga_nayar, multiscopic_hdr, patchmatch, zncc_stereo, Align,
    MitsunagaNayarParams, MultiscopicParams, PatchMatchParams, StereoParams,
};
use wscg_math::progress::NoProgress;
use wscg_math::{Image, Result};

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
    let pm = PatchMatchParams::default;
    assert!(pm().validate().is_ok());
    assert!(PatchMatchParams::barnes(7, 2, 0).validate().is_ok());
    assert_eq!(field(pm().patch(6).validate()), "patch");
    assert_eq!(field(pm().patch(1).validate()), "patch");
    assert_eq!(field(pm().d_min(5).d_max(3).validate()), "d_min");
    assert_eq!(field(pm().v_tol(-1).validate()), "v_tol");
    assert_eq!(field(pm().alpha(1.0).validate()), "alpha");
    assert_eq!(field(pm().c_min(0.0).validate()), "c_min");
    // The bounds the image size sets.
    assert!(pm().validate_for(100, 200).is_ok());
    assert_eq!(field(pm().validate_for(100, 64)), "max_disparity");
    assert_eq!(field(pm().v_tol(8).validate_for(8, 200)), "v_tol");
    assert_eq!(field(pm().validate_for(5, 200)), "patch");

    let st = StereoParams::default;
    assert!(st().validate().is_ok());
    assert_eq!(field(st().window(8).validate()), "window");
    assert_eq!(field(st().lr_tol(-1).validate()), "lr_tol");
    assert_eq!(field(st().d_min(5).d_max(3).validate()), "d_min");
    assert_eq!(field(st().validate_for(100, 64)), "max_disparity");
    assert_eq!(field(st().validate_for(5, 200)), "window");

    let ms = MultiscopicParams::default;
    assert!(ms().validate().is_ok());
    assert_eq!(field(ms().pm(pm().alpha(0.0)).validate()), "alpha");
    assert!(ms()
        .align(Align::None)
        .pm(pm().alpha(0.0))
        .validate()
        .is_ok());
    assert_eq!(
        field(ms().align(Align::Zncc).zncc_window(4).validate()),
        "zncc_window"
    );

    let mn = MitsunagaNayarParams::default;
    assert!(mn().validate().is_ok());
    assert_eq!(field(mn().degree(Some(0)).validate()), "degree");
    assert_eq!(field(mn().max_degree(11).validate()), "max_degree");
    assert_eq!(field(mn().samples(0).validate()), "samples");
    assert_eq!(field(mn().tol(f64::NAN).validate()), "tol");
    assert_eq!(field(mn().max_iter(0).validate()), "max_iter");

    let sc = SceneParams::default;
    assert!(sc().validate().is_ok());
    assert_eq!(field(sc().times(vec![0.01]).validate()), "times");
    assert_eq!(field(sc().times(vec![0.01, -1.0]).validate()), "times");
    assert_eq!(field(sc().layers(Vec::new()).validate()), "layers");
    assert_eq!(field(sc().height(4).validate()), "height");
    assert_eq!(field(sc().width(7).validate()), "width");
    assert_eq!(field(sc().noise(-0.1).validate()), "noise");
    assert_eq!(field(sc().emitter_peak(0.5).validate()), "emitter_peak");
    assert_eq!(field(sc().bits(0).validate()), "bits");

    // The methods check their parameters before their data.
    let img = Image::<f32>::filled(1, 1, 1, 0.5).unwrap();
    assert_eq!(field(patchmatch(&img, &img, &pm().patch(4))), "patch");
    assert_eq!(field(zncc_stereo(&img, &img, &st().lr_tol(-2))), "lr_tol");
    assert_eq!(
        field(multiscopic_hdr(
            &[],
            &[],
            &[],
            &ms().pm(pm().c_min(2.0)),
            &NoProgress
        )),
        "c_min"
    );
    assert_eq!(
        field(calibrate_mitsunaga_nayar(&[], &[], 8, &mn().samples(0))),
        "samples"
    );
    assert_eq!(field(layered_scene(&sc().noise(f64::NAN), 0)), "noise");
}
