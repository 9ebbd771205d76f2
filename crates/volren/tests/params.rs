//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::{RefusedArgument, Volume};
use wscg_volren::illumination::{
    render, IlluminationParams, Light, Method, ScalarField, SliceCamera, TransferFunction,
};
use wscg_volren::phantoms::{head, head_tfs};
use wscg_volren::wavelet::HaarQuant;
use wscg_volren::{render_reference, Camera, HybridServer, RenderParams, ServerParams};

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    let il = IlluminationParams::default;
    assert!(il().validate().is_ok());
    assert_eq!(
        il().background([0.0, 2.0, 0.0])
            .validate()
            .refused_argument(),
        Some("background")
    );
    assert_eq!(
        il().early_stop(0.0).validate().refused_argument(),
        Some("early_stop")
    );
    assert_eq!(
        il().early_stop(f32::NAN).check().refused_argument(),
        Some("early_stop")
    );

    let rp = RenderParams::default;
    assert!(rp().validate().is_ok());
    assert_eq!(rp().step(0.0).validate().refused_argument(), Some("step"));
    assert_eq!(
        rp().context_step(65.0).validate().refused_argument(),
        Some("context_step")
    );
    assert_eq!(
        rp().early_stop(1.5).validate().refused_argument(),
        Some("early_stop")
    );
    assert_eq!(
        rp().background([-1.0; 3]).validate().refused_argument(),
        Some("background")
    );
    assert_eq!(rp().ka(f32::NAN).validate().refused_argument(), Some("ka"));
    assert_eq!(rp().kd(-1.0).validate().refused_argument(), Some("kd"));
    assert_eq!(
        rp().ks(f32::INFINITY).validate().refused_argument(),
        Some("ks")
    );

    let sp = ServerParams::default;
    assert!(sp().validate().is_ok());
    assert_eq!(
        sp().steps_sent(0).validate().refused_argument(),
        Some("steps_sent")
    );
    assert_eq!(
        sp().steps_sent(5).validate().refused_argument(),
        Some("steps_sent")
    );
    let mut q = HaarQuant::default();
    q.delta[2] = 0.0;
    assert_eq!(sp().quant(q).validate().refused_argument(), Some("quant"));

    // The methods check their parameters before their data.
    let f = ScalarField::from_f32(Volume::filled([4; 3], [1.0; 3], 0.0).unwrap()).unwrap();
    let tf = TransferFunction::from_points(&[(0.0, [1.0, 0.0, 0.0, 0.5])], 16).unwrap();
    let cam = SliceCamera::fit(&f, [0.0, 0.3, 1.0], [0.0, 1.0, 0.0], 8, 8).unwrap();
    let bad = il().early_stop(2.0);
    assert_eq!(
        render(&f, &tf, &cam, &Light::default(), &Method::ics(0.7), &bad).refused_argument(),
        Some("early_stop")
    );
    let v = head([16, 16, 16], 3).unwrap();
    assert_eq!(
        HybridServer::new(&v, head_tfs(), 0, sp().steps_sent(9)).refused_argument(),
        Some("steps_sent")
    );
    let cam = Camera::orbit(v.dims(), 30.0, 20.0, 8);
    assert_eq!(
        render_reference(&v, &head_tfs()[0], None, &cam, &rp().step(-1.0)).refused_argument(),
        Some("step")
    );
}
