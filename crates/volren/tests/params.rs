//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::Result;
use wscg_volren::illumination::{
    render, IlluminationParams, Light, Method, ScalarField, SliceCamera, TransferFunction,
};
use wscg_volren::phantoms::{head, head_tfs};
use wscg_volren::wavelet::HaarQuant;
use wscg_volren::{render_reference, Camera, HybridServer, RenderParams, ServerParams};

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
    let il = IlluminationParams::default;
    assert!(il().validate().is_ok());
    assert_eq!(
        field(il().background([0.0, 2.0, 0.0]).validate()),
        "background"
    );
    assert_eq!(field(il().early_stop(0.0).validate()), "early_stop");
    assert_eq!(field(il().early_stop(f32::NAN).check()), "early_stop");

    let rp = RenderParams::default;
    assert!(rp().validate().is_ok());
    assert_eq!(field(rp().step(0.0).validate()), "step");
    assert_eq!(field(rp().context_step(65.0).validate()), "context_step");
    assert_eq!(field(rp().early_stop(1.5).validate()), "early_stop");
    assert_eq!(field(rp().background([-1.0; 3]).validate()), "background");
    assert_eq!(field(rp().ka(f32::NAN).validate()), "ka");
    assert_eq!(field(rp().kd(-1.0).validate()), "kd");
    assert_eq!(field(rp().ks(f32::INFINITY).validate()), "ks");

    let sp = ServerParams::default;
    assert!(sp().validate().is_ok());
    assert_eq!(field(sp().steps_sent(0).validate()), "steps_sent");
    assert_eq!(field(sp().steps_sent(5).validate()), "steps_sent");
    let mut q = HaarQuant::default();
    q.delta[2] = 0.0;
    assert_eq!(field(sp().quant(q).validate()), "quant");

    // The methods check their parameters before their data.
    let f = ScalarField::from_f32([4; 3], [1.0; 3], vec![0.0; 64]).unwrap();
    let tf = TransferFunction::from_points(&[(0.0, [1.0, 0.0, 0.0, 0.5])], 16).unwrap();
    let cam = SliceCamera::fit(&f, [0.0, 0.3, 1.0], [0.0, 1.0, 0.0], 8, 8).unwrap();
    let bad = il().early_stop(2.0);
    assert_eq!(
        field(render(
            &f,
            &tf,
            &cam,
            &Light::default(),
            &Method::ics(0.7),
            &bad
        )),
        "early_stop"
    );
    let v = head([16, 16, 16], 3).unwrap();
    assert_eq!(
        field(HybridServer::new(&v, head_tfs(), 0, sp().steps_sent(9))),
        "steps_sent"
    );
    let cam = Camera::orbit(v.dims(), 30.0, 20.0, 8);
    assert_eq!(
        field(render_reference(
            &v,
            &head_tfs()[0],
            None,
            &cam,
            &rp().step(-1.0)
        )),
        "step"
    );
}
