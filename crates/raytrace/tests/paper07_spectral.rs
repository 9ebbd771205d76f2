//! Paper 07 acceptance checks 4, 5 (colour part) and 6: Fresnel equations against tmm,
//! colorimetry against colour-science, the optical constants of aluminium against measured
//! data, and the stereo rig's geometry.

mod fixtures {
    pub mod colour_reference;
    pub mod fresnel_tmm;
}

use fixtures::colour_reference as cref;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use wscg_raytrace::spectral::colour::bradford_adaptation;
use wscg_raytrace::spectral::*;
use wscg_raytrace::stereo::{Eye, StereoRig};

#[test]
fn check4_fresnel_equals_tmm() {
    let mut worst = 0.0f64;
    for &(c, n, k, ni, r) in fixtures::fresnel_tmm::FRESNEL_TMM.iter() {
        let ours = if k == 0.0 {
            fresnel_dielectric(c, n / ni)
        } else {
            fresnel_conductor(c, n / ni, k / ni)
        };
        worst = worst.max((ours - r).abs());
        // The conductor formula must also hold for k = 0 (dielectrics, total reflection).
        assert!((fresnel_conductor(c, n / ni, k / ni) - r).abs() < 1e-9);
    }
    assert!(worst < 1e-9, "max |dR| = {worst:e}");
}

fn visible(v: &[f64; 81]) -> Spectrum {
    Spectrum::new(SpectralGrid::VISIBLE, v.to_vec()).unwrap()
}

#[test]
fn check5_illuminant_chromaticities_equal_colour_science() {
    for (name, spd, xy) in cref::ILLUMINANTS.iter() {
        let ours = xyz_to_xy(to_xyz(&visible(spd)).unwrap());
        assert!(
            (ours[0] - xy[0]).abs() < 1e-6 && (ours[1] - xy[1]).abs() < 1e-6,
            "{name}: {ours:?} vs {xy:?}"
        );
    }
    // CIE daylight at 4700 K: spectrum and chromaticity.
    let d = daylight_d(4700.0).unwrap();
    for (a, b) in d.v.iter().zip(cref::D4700.iter()) {
        assert!((a - b).abs() < 1e-9 * b.abs().max(1.0), "{a} vs {b}");
    }
    let xy = xyz_to_xy(to_xyz(&d).unwrap());
    assert!((xy[0] - cref::D4700_XY[0]).abs() < 1e-9);
    // Planck.
    let bb = blackbody(4700.0).unwrap();
    for (a, b) in bb.v.iter().zip(cref::BLACKBODY_4700.iter()) {
        assert!((a / b - 1.0).abs() < 1e-6, "{a} vs {b}");
    }
}

#[test]
fn check5_white_under_d65_is_srgb_white() {
    let d65 = visible(&cref::ILLUMINANTS[0].1);
    let xyz = to_xyz(&d65).unwrap();
    let xyz = xyz.map(|v| v / xyz[1]);
    let rgb = xyz_to_rgb(xyz, &XYZ_TO_SRGB);
    for c in rgb {
        assert!((c - 1.0).abs() < 0.005, "{rgb:?}");
    }
    assert!((srgb_oetf(1.0) - 1.0).abs() < 1e-12);
    assert!((srgb_oetf(0.0031308) - 0.04045).abs() < 1e-5);
    // Bradford from illuminant A to D65 maps A's white onto D65's.
    let a = to_xyz(&visible(&cref::ILLUMINANTS[2].1)).unwrap();
    let m = bradford_adaptation(a, xyz);
    let mapped = xyz_to_rgb(a, &m);
    for k in 0..3 {
        assert!((mapped[k] - xyz[k]).abs() < 1e-9);
    }
}

#[test]
fn aluminium_constants_follow_measured_data() {
    // Hagemann, Gudat and Kunz (DESY SR-74/7, 1974), Table 3: an independent measurement.
    let measured = [
        (413.3, 0.548, 5.00),
        (495.9, 0.771, 5.91),
        (619.9, 1.292, 7.28),
        (688.8, 1.731, 7.96),
        (774.9, 2.588, 8.55),
    ];
    for (l, n, k) in measured {
        let c = aluminium_rakic_ld(l);
        assert!((c.re / n - 1.0).abs() < 0.25, "n at {l}: {} vs {n}", c.re);
        assert!((c.im / k - 1.0).abs() < 0.06, "k at {l}: {} vs {k}", c.im);
    }
    // Normal-incidence reflectance in air: about 0.92 in the green, the interband dip near
    // 800 nm.
    let r = |l: f64| {
        let c = aluminium_rakic_ld(l);
        fresnel_conductor(1.0, c.re, c.im)
    };
    assert!((0.90..0.93).contains(&r(550.0)), "{}", r(550.0));
    assert!(r(780.0) < r(550.0) - 0.02);
    // The paper's mode keeps k = 6.
    let m = MetalIor::AlRakicLdConstK { k: 6.0 };
    assert_eq!(m.nk(550.0).1, 6.0);
    assert!(MetalIor::Constant { n: 1.0, k: -1.0 }.validate().is_err());
}

#[test]
fn spectra_on_different_grids_are_rejected() {
    let a = Spectrum::constant(SpectralGrid::VISIBLE, 1.0);
    let g = SpectralGrid {
        l0_nm: 400.0,
        step_nm: 10.0,
        n: 31,
    };
    let b = Spectrum::constant(g, 1.0);
    assert!(a.mul(&b).is_err());
    assert!(to_xyz(&b).is_err());
    assert!(Spectrum::new(SpectralGrid::VISIBLE, vec![1.0; 80]).is_err());
    assert!(Spectrum::new(SpectralGrid::VISIBLE, vec![f64::NAN; 81]).is_err());
    assert!(daylight_d(3000.0).is_err());
    assert!(blackbody(-1.0).is_err());
}

#[test]
fn check6_stereo_geometry() {
    let rig = StereoRig::default();
    let a = rig.dist_m;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
    // Zero-parallax plane: same pixel in both eyes.
    for _ in 0..100 {
        let p = [rng.random_range(-0.2..0.2), rng.random_range(-0.1..0.1), a];
        let (l, r) = (
            rig.project(Eye::Left, p).unwrap(),
            rig.project(Eye::Right, p).unwrap(),
        );
        assert!((l.0 - r.0).abs() < 1e-6 && (l.1 - r.1).abs() < 1e-6);
    }
    // Parallax e (z - a) / z, no vertical parallax.
    let pitch = rig.screen_w_m / rig.res.0 as f64;
    for _ in 0..100 {
        let z = rng.random_range(0.3..3.0);
        let p = [rng.random_range(-0.3..0.3), rng.random_range(-0.2..0.2), z];
        let (l, r) = (
            rig.project(Eye::Left, p).unwrap(),
            rig.project(Eye::Right, p).unwrap(),
        );
        let expected = rig.eye_sep_m * (z - a) / z / pitch;
        assert!(
            (r.0 - l.0 - expected).abs() < 1e-6,
            "{} vs {expected}",
            r.0 - l.0
        );
        assert!((r.0 - l.0 - rig.parallax_px(z)).abs() < 1e-6);
        assert!((r.1 - l.1).abs() < 1e-6);
    }
    // Field of view 2 atan(b / 2a) (the paper's printed formula is inverted), and it is the
    // angle the cyclopean frustum actually spans.
    let (h, _) = rig.fov_deg();
    assert!((h - 2.0 * (rig.screen_w_m / (2.0 * a)).atan().to_degrees()).abs() < 1e-12);
    let l = Vector3::from(rig.ray(Eye::Cyclopean, 0.0, 540.0).dir);
    let r = Vector3::from(rig.ray(Eye::Cyclopean, 1920.0, 540.0).dir);
    assert!((l.angle(&r).to_degrees() - h).abs() < 1e-9);
    // The plate spans about 542 px at 1:1 (150 mm).
    assert!((0.150 / pitch - 542.0).abs() < 1.0);
    assert!(StereoRig { dist_m: 0.0, ..rig }.validate().is_err());
}
