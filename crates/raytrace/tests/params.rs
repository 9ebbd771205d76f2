//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::progress::NoProgress;
use wscg_math::Result;
use wscg_raytrace::manylight::{
    cornell_box, generate_vpls, run, AdaptiveParams, ImportanceCachingParams, Interp,
    ManyLightParams, Method, VplParams,
};
use wscg_raytrace::paint::{
    render, score_runs, DiscLight, FlakeParams, NoFlakes, PaintRenderParams, PhotonParams, Plate,
    PlateStack, Rect, WorkshopParams,
};
use wscg_raytrace::stereo::{Eye, StereoRig};

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
    // Many-light rendering (paper 08).
    let vp = VplParams::default;
    assert!(vp().validate().is_ok());
    assert_eq!(field(vp().n_paths(0).validate()), "n_paths");

    let ic = ImportanceCachingParams::default;
    assert!(ic().validate().is_ok());
    assert_eq!(field(ic().n_cache(0).validate()), "n_cache");
    assert_eq!(field(ic().m_nearest(0).validate()), "m_nearest");
    assert_eq!(field(ic().spp(0).validate()), "spp");
    assert_eq!(field(ic().strategies([false; 4]).validate()), "strategies");
    assert_eq!(field(ic().alpha([1.0, 0.0, 1.0, 1.0]).validate()), "alpha");
    assert_eq!(
        field(ic().clamp_dist(Some(f64::NAN)).validate()),
        "clamp_dist"
    );
    assert!(ic().clamp_dist(Some(0.0)).validate().is_ok());

    let ad = AdaptiveParams::default;
    assert!(ad().validate().is_ok());
    assert_eq!(field(ad().init_fraction(0.0).validate()), "init_fraction");
    assert_eq!(field(ad().delta(-1.0).validate()), "delta");
    assert_eq!(
        field(ad().leaf_min_extent(f64::NAN).validate()),
        "leaf_min_extent"
    );
    assert_eq!(
        field(ad().min_inserted_fraction(-0.1).validate()),
        "min_inserted_fraction"
    );

    let ml = ManyLightParams::default;
    assert!(ml().validate().is_ok());
    assert_eq!(field(ml().vpl(vp().n_paths(0)).validate()), "n_paths");
    assert_eq!(field(ml().ic(ic().spp(0)).validate()), "spp");
    assert_eq!(field(ml().adaptive(ad().delta(-1.0)).validate()), "delta");
    let bad_weights = Interp::Clarberg {
        theta_max: 0.0,
        lambda: 5.0,
        dmax_factor: 2.0,
    };
    assert_eq!(field(ml().weights(bad_weights).validate()), "theta_max");

    // Car paint (paper 07).
    let ph = PhotonParams::default;
    assert!(ph().validate().is_ok());
    assert_eq!(field(ph().count(0).validate()), "count");
    assert_eq!(field(ph().k(0).validate()), "k");
    assert_eq!(field(ph().max_radius_um(0.0).validate()), "max_radius_um");
    assert_eq!(field(ph().margin_um(-1.0).validate()), "margin_um");

    let fl = FlakeParams::default;
    assert!(fl().validate().is_ok());
    assert_eq!(field(fl().radius_um(0.0).validate()), "radius_um");
    assert_eq!(field(fl().density(-1.0).validate()), "density");
    assert_eq!(field(fl().tile_um(f64::NAN).validate()), "tile_um");
    assert_eq!(field(fl().thickness_um(30.0).validate()), "thickness_um");
    assert_eq!(field(fl().radius_cv(3.0).validate()), "radius_cv");
    assert_eq!(field(fl().tiles_in_pool(0).validate()), "tiles_in_pool");
    assert_eq!(
        field(fl().max_clamped_fraction(2.0).validate()),
        "max_clamped_fraction"
    );

    let pr = PaintRenderParams::default;
    assert!(pr().validate().is_ok());
    assert_eq!(field(pr().spp(0).validate()), "spp");
    assert_eq!(field(pr().max_depth(0).validate()), "max_depth");
    assert_eq!(field(pr().magnification(0.0).validate()), "magnification");
    let empty = Rect::centred(0.0, 0.0, 0.0, 1.0);
    assert_eq!(field(pr().region_mm(Some(empty)).validate()), "region_mm");
    assert_eq!(field(pr().photons(Some(ph().k(0))).validate()), "k");
    assert!(pr().photons(None).validate().is_ok());

    let ws = WorkshopParams::default;
    assert!(ws().validate().is_ok());
    assert_eq!(
        field(ws().base(fl().tiles_in_pool(0)).validate()),
        "tiles_in_pool"
    );
    assert_eq!(field(ws().settings(pr().spp(0)).validate()), "spp");
    assert_eq!(
        field(ws().reference_renders(1).validate()),
        "reference_renders"
    );
    assert_eq!(field(ws().jnd_log(f64::NAN).validate()), "jnd_log");

    // The methods check their parameters before their data.
    let (scene, cam) = cornell_box(1, 8, 8).unwrap();
    assert_eq!(field(generate_vpls(&scene, &vp().n_paths(0))), "n_paths");
    assert_eq!(
        field(run(
            &scene,
            &cam,
            Method::Ic,
            &ml().ic(ic().m_nearest(0)),
            &NoProgress
        )),
        "m_nearest"
    );
    let plate = Plate::new(PlateStack::default(), Box::new(NoFlakes)).unwrap();
    let (light, rig) = (DiscLight::default(), StereoRig::default());
    assert_eq!(
        field(render(&plate, &light, &rig, Eye::Left, &pr().max_depth(0))),
        "max_depth"
    );
    assert_eq!(
        field(score_runs(
            (30.0, 6.5),
            &[(30.0, 6.5)],
            &ws().reference_renders(0),
            0,
            &NoProgress
        )),
        "reference_renders"
    );
}
