//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_hdr::synth::{layered_scene, Layer, SceneParams};
use wscg_hdr::{
    calibrate_mitsunaga_nayar, multiscopic_hdr, patchmatch, zncc_stereo, Align,
    MitsunagaNayarParams, MultiscopicParams, PatchMatchParams, StereoParams,
};
use wscg_math::progress::NoProgress;
use wscg_math::{Image, RefusedArgument};

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    let pm = PatchMatchParams::default;
    assert!(pm().validate().is_ok());
    assert!(PatchMatchParams::barnes(7, 2, 0).validate().is_ok());
    assert_eq!(pm().patch(6).validate().refused_argument(), Some("patch"));
    assert_eq!(pm().patch(1).validate().refused_argument(), Some("patch"));
    assert_eq!(
        pm().d_min(5).d_max(3).validate().refused_argument(),
        Some("d_min")
    );
    assert_eq!(pm().v_tol(-1).validate().refused_argument(), Some("v_tol"));
    assert_eq!(pm().alpha(1.0).validate().refused_argument(), Some("alpha"));
    assert_eq!(pm().c_min(0.0).validate().refused_argument(), Some("c_min"));
    // The bounds the image size sets.
    assert!(pm().validate_for(100, 200).is_ok());
    assert_eq!(
        pm().validate_for(100, 64).refused_argument(),
        Some("max_disparity")
    );
    assert_eq!(
        pm().v_tol(8).validate_for(8, 200).refused_argument(),
        Some("v_tol")
    );
    assert_eq!(pm().validate_for(5, 200).refused_argument(), Some("patch"));

    let st = StereoParams::default;
    assert!(st().validate().is_ok());
    assert_eq!(st().window(8).validate().refused_argument(), Some("window"));
    assert_eq!(
        st().lr_tol(-1).validate().refused_argument(),
        Some("lr_tol")
    );
    assert_eq!(
        st().d_min(5).d_max(3).validate().refused_argument(),
        Some("d_min")
    );
    assert_eq!(
        st().validate_for(100, 64).refused_argument(),
        Some("max_disparity")
    );
    assert_eq!(st().validate_for(5, 200).refused_argument(), Some("window"));

    let ms = MultiscopicParams::default;
    assert!(ms().validate().is_ok());
    assert_eq!(
        ms().pm(pm().alpha(0.0)).validate().refused_argument(),
        Some("alpha")
    );
    assert!(ms()
        .align(Align::None)
        .pm(pm().alpha(0.0))
        .validate()
        .is_ok());
    assert_eq!(
        ms().align(Align::Zncc)
            .zncc_window(4)
            .validate()
            .refused_argument(),
        Some("zncc_window")
    );

    let mn = MitsunagaNayarParams::default;
    assert!(mn().validate().is_ok());
    assert_eq!(
        mn().degree(Some(0)).validate().refused_argument(),
        Some("degree")
    );
    assert_eq!(
        mn().max_degree(11).validate().refused_argument(),
        Some("max_degree")
    );
    assert_eq!(
        mn().samples(0).validate().refused_argument(),
        Some("samples")
    );
    assert_eq!(
        mn().tol(f64::NAN).validate().refused_argument(),
        Some("tol")
    );
    assert_eq!(
        mn().max_iter(0).validate().refused_argument(),
        Some("max_iter")
    );

    let sc = SceneParams::default;
    assert!(sc().validate().is_ok());
    assert_eq!(
        sc().times(vec![0.01]).validate().refused_argument(),
        Some("times")
    );
    assert_eq!(
        sc().times(vec![0.01, -1.0]).validate().refused_argument(),
        Some("times")
    );
    assert_eq!(
        sc().layers(Vec::new()).validate().refused_argument(),
        Some("layers")
    );
    let back = Layer::new(5.0, [0.0, 1.0, 0.0, 1.0], 1);
    for bad in [
        Layer::new(f64::NAN, [0.0, 1.0, 0.0, 1.0], 2),
        Layer::new(9.0, [0.6, 0.2, 0.0, 1.0], 2),
        Layer::new(9.0, [0.0, 1.0, 0.5, 1.5], 2),
        Layer::new(9.0, [0.0, 1.0, 0.0, 1.0], 2).gain(0.0),
        Layer::new(9.0, [0.0, 1.0, 0.0, 1.0], 2).gain(f64::INFINITY),
    ] {
        let e = sc().layers(vec![back, bad]).validate();
        assert_eq!(e.refused_argument(), Some("layers"), "{bad:?}");
        assert!(e.unwrap_err().to_string().contains("layer 1"));
    }
    assert_eq!(sc().height(4).validate().refused_argument(), Some("height"));
    assert_eq!(sc().width(7).validate().refused_argument(), Some("width"));
    assert_eq!(
        sc().noise(-0.1).validate().refused_argument(),
        Some("noise")
    );
    assert_eq!(
        sc().emitter_peak(0.5).validate().refused_argument(),
        Some("emitter_peak")
    );
    assert_eq!(sc().bits(0).validate().refused_argument(), Some("bits"));

    // The methods check their parameters before their data.
    let img = Image::<f32>::filled(1, 1, 1, 0.5).unwrap();
    assert_eq!(
        patchmatch(&img, &img, &pm().patch(4)).refused_argument(),
        Some("patch")
    );
    assert_eq!(
        zncc_stereo(&img, &img, &st().lr_tol(-2)).refused_argument(),
        Some("lr_tol")
    );
    assert_eq!(
        multiscopic_hdr(&[], &[], &[], &ms().pm(pm().c_min(2.0)), &NoProgress).refused_argument(),
        Some("c_min")
    );
    assert_eq!(
        calibrate_mitsunaga_nayar(&[], &[], 8, &mn().samples(0)).refused_argument(),
        Some("samples")
    );
    assert_eq!(
        layered_scene(&sc().noise(f64::NAN), 0).refused_argument(),
        Some("noise")
    );
}
