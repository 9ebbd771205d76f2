//! Every parameter struct of the crate: its `Default` passes `validate()`, and a field set
//! out of range fails with an error naming that field (also at the start of the method that
//! takes the parameters).

use wscg_math::progress::NoProgress;
use wscg_math::RefusedArgument;
use wscg_raytrace::manylight::{
    cornell_box, generate_vpls, run, AdaptiveParams, ImportanceCachingParams, Interp,
    ManyLightParams, Method, VplParams,
};
use wscg_raytrace::paint::{
    render, score_runs, DiscLight, FlakeParams, NoFlakes, PaintRenderParams, PhotonParams, Plate,
    PlateStack, Rect, WorkshopParams,
};
use wscg_raytrace::stereo::{Eye, StereoRig};

#[test]
fn every_parameter_struct_validates_its_default_and_names_a_bad_field() {
    // Many-light rendering (paper 08).
    let vp = VplParams::default;
    assert!(vp().validate().is_ok());
    assert_eq!(
        vp().n_paths(0).validate().refused_argument(),
        Some("n_paths")
    );

    let ic = ImportanceCachingParams::default;
    assert!(ic().validate().is_ok());
    assert_eq!(
        ic().n_cache(0).validate().refused_argument(),
        Some("n_cache")
    );
    assert_eq!(
        ic().m_nearest(0).validate().refused_argument(),
        Some("m_nearest")
    );
    assert_eq!(ic().spp(0).validate().refused_argument(), Some("spp"));
    assert_eq!(
        ic().strategies([false; 4]).validate().refused_argument(),
        Some("strategies")
    );
    assert_eq!(
        ic().alpha([1.0, 0.0, 1.0, 1.0])
            .validate()
            .refused_argument(),
        Some("alpha")
    );
    assert_eq!(
        ic().clamp_dist(Some(f64::NAN))
            .validate()
            .refused_argument(),
        Some("clamp_dist")
    );
    assert!(ic().clamp_dist(Some(0.0)).validate().is_ok());
    for share in [-0.1, 1.0, f64::NAN] {
        assert_eq!(
            ic().near_share(share).validate().refused_argument(),
            Some("near_share")
        );
    }
    assert!(ic().near_share(0.0).validate().is_ok());
    assert_eq!(
        ic().near_vpls(0).validate().refused_argument(),
        Some("near_vpls")
    );

    let ad = AdaptiveParams::default;
    assert!(ad().validate().is_ok());
    assert_eq!(
        ad().init_fraction(0.0).validate().refused_argument(),
        Some("init_fraction")
    );
    assert_eq!(
        ad().delta(-1.0).validate().refused_argument(),
        Some("delta")
    );
    assert_eq!(
        ad().leaf_min_extent(f64::NAN).validate().refused_argument(),
        Some("leaf_min_extent")
    );
    assert_eq!(
        ad().min_inserted_fraction(-0.1)
            .validate()
            .refused_argument(),
        Some("min_inserted_fraction")
    );

    let ml = ManyLightParams::default;
    assert!(ml().validate().is_ok());
    assert_eq!(
        ml().vpl(vp().n_paths(0)).validate().refused_argument(),
        Some("n_paths")
    );
    assert_eq!(
        ml().ic(ic().spp(0)).validate().refused_argument(),
        Some("spp")
    );
    assert_eq!(
        ml().adaptive(ad().delta(-1.0))
            .validate()
            .refused_argument(),
        Some("delta")
    );
    let bad_weights = Interp::Clarberg {
        theta_max: 0.0,
        lambda: 5.0,
        dmax_factor: 2.0,
        defensive: 0.5,
    };
    assert_eq!(
        ml().weights(bad_weights).validate().refused_argument(),
        Some("theta_max")
    );

    // Car paint (paper 07).
    let ph = PhotonParams::default;
    assert!(ph().validate().is_ok());
    assert_eq!(ph().count(0).validate().refused_argument(), Some("count"));
    assert_eq!(ph().k(0).validate().refused_argument(), Some("k"));
    assert_eq!(
        ph().max_radius_um(0.0).validate().refused_argument(),
        Some("max_radius_um")
    );
    assert_eq!(
        ph().margin_um(-1.0).validate().refused_argument(),
        Some("margin_um")
    );

    let fl = FlakeParams::default;
    assert!(fl().validate().is_ok());
    assert_eq!(
        fl().radius_um(0.0).validate().refused_argument(),
        Some("radius_um")
    );
    assert_eq!(
        fl().density(-1.0).validate().refused_argument(),
        Some("density")
    );
    assert_eq!(
        fl().tile_um(f64::NAN).validate().refused_argument(),
        Some("tile_um")
    );
    assert_eq!(
        fl().thickness_um(30.0).validate().refused_argument(),
        Some("thickness_um")
    );
    assert_eq!(
        fl().radius_cv(3.0).validate().refused_argument(),
        Some("radius_cv")
    );
    assert_eq!(
        fl().tiles_in_pool(0).validate().refused_argument(),
        Some("tiles_in_pool")
    );
    assert_eq!(
        fl().max_clamped_fraction(2.0).validate().refused_argument(),
        Some("max_clamped_fraction")
    );

    let pr = PaintRenderParams::default;
    assert!(pr().validate().is_ok());
    assert_eq!(pr().spp(0).validate().refused_argument(), Some("spp"));
    assert_eq!(
        pr().max_depth(0).validate().refused_argument(),
        Some("max_depth")
    );
    assert_eq!(
        pr().magnification(0.0).validate().refused_argument(),
        Some("magnification")
    );
    let empty = Rect::centred(0.0, 0.0, 0.0, 1.0);
    assert_eq!(
        pr().region_mm(Some(empty)).validate().refused_argument(),
        Some("region_mm")
    );
    assert_eq!(
        pr().photons(Some(ph().k(0))).validate().refused_argument(),
        Some("k")
    );
    assert!(pr().photons(None).validate().is_ok());

    let ws = WorkshopParams::default;
    assert!(ws().validate().is_ok());
    assert_eq!(
        ws().base(fl().tiles_in_pool(0))
            .validate()
            .refused_argument(),
        Some("tiles_in_pool")
    );
    assert_eq!(
        ws().settings(pr().spp(0)).validate().refused_argument(),
        Some("spp")
    );
    assert_eq!(
        ws().reference_renders(1).validate().refused_argument(),
        Some("reference_renders")
    );
    assert_eq!(
        ws().jnd_log(f64::NAN).validate().refused_argument(),
        Some("jnd_log")
    );

    // The methods check their parameters before their data.
    let (scene, cam) = cornell_box(1, 8, 8).unwrap();
    assert_eq!(
        generate_vpls(&scene, &vp().n_paths(0)).refused_argument(),
        Some("n_paths")
    );
    assert_eq!(
        run(
            &scene,
            &cam,
            Method::Ic,
            &ml().ic(ic().m_nearest(0)),
            &NoProgress
        )
        .refused_argument(),
        Some("m_nearest")
    );
    let plate = Plate::new(PlateStack::default(), Box::new(NoFlakes)).unwrap();
    let (light, rig) = (DiscLight::default(), StereoRig::default());
    assert_eq!(
        render(&plate, &light, &rig, Eye::Left, &pr().max_depth(0)).refused_argument(),
        Some("max_depth")
    );
    assert_eq!(
        score_runs(
            (30.0, 6.5),
            &[(30.0, 6.5)],
            &ws().reference_renders(0),
            0,
            &NoProgress
        )
        .refused_argument(),
        Some("reference_renders")
    );
}
