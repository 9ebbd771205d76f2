//! Paper 07 acceptance checks 5 (rendered colour), 7 (microstructure statistics), 8 (glint
//! physics) and 9 (Monte-Carlo sanity), and bad input for the paint model.

mod fixtures {
    #[allow(dead_code)]
    pub mod colour_reference;
}

use fixtures::colour_reference as cref;
use nalgebra::Vector3;
use wscg_raytrace::paint::*;
use wscg_raytrace::spectral::*;
use wscg_raytrace::stereo::{Eye, StereoRig};

/// Kolmogorov-Smirnov p-value of the sample against a continuous CDF.
fn ks_p(sample: &mut [f64], cdf: impl Fn(f64) -> f64) -> f64 {
    sample.sort_by(f64::total_cmp);
    let n = sample.len() as f64;
    let mut d = 0.0f64;
    for (i, &x) in sample.iter().enumerate() {
        let f = cdf(x);
        d = d
            .max((f - i as f64 / n).abs())
            .max(((i + 1) as f64 / n - f).abs());
    }
    let l = (n.sqrt() + 0.12 + 0.11 / n.sqrt()) * d;
    let mut p = 0.0;
    for k in 1..100 {
        let t = 2.0 * (-1f64).powi(k - 1) * (-2.0 * (k as f64 * l).powi(2)).exp();
        p += t;
        if t.abs() < 1e-12 {
            break;
        }
    }
    p.clamp(0.0, 1.0)
}

/// Check 7 on 200 tiles of one model: Poisson counts, lognormal radii, the layer's bounds,
/// the tilt law.
fn check_statistics(p: &FlakeParams) -> Vec<FlakeTile> {
    let tiles: Vec<FlakeTile> = (0..200)
        .map(|s| generate_tile(p, 1000 + s).unwrap())
        .collect();
    let counts: Vec<f64> = tiles.iter().map(|t| t.flakes.len() as f64).collect();
    let n = counts.len() as f64;
    let mean = counts.iter().sum::<f64>() / n;
    let var = counts.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let lambda = p.expected_count();
    // Mean within 3 standard errors of a Poisson mean; dispersion 1 within 3 sd of the
    // sample variance ratio (sqrt(2 / (n - 1))).
    assert!(
        (mean - lambda).abs() < 3.0 * (lambda / n).sqrt(),
        "mean count {mean} vs {lambda}"
    );
    assert!(
        (var / mean - 1.0).abs() < 3.0 * (2.0 / (n - 1.0)).sqrt(),
        "dispersion {}",
        var / mean
    );
    let radii: Vec<f64> = tiles
        .iter()
        .flat_map(|t| t.flakes.iter().map(|f| f.r))
        .collect();
    let m = radii.iter().sum::<f64>() / radii.len() as f64;
    let sd =
        (radii.iter().map(|r| (r - m).powi(2)).sum::<f64>() / (radii.len() as f64 - 1.0)).sqrt();
    assert!((m / p.radius_um - 1.0).abs() < 0.02, "mean radius {m}");
    assert!(
        (sd / m / p.radius_cv - 1.0).abs() < 0.02,
        "radius cv {}",
        sd / m
    );
    for t in &tiles {
        for f in &t.flakes {
            let e = f.half_height(p.thickness_um);
            assert!(
                f.c[2] - e >= -1e-9 && f.c[2] + e <= p.layer_um + 1e-9,
                "flake outside the layer"
            );
            assert!((Vector3::from(f.n).norm() - 1.0).abs() < 1e-12 && f.n[2] > 0.0);
        }
    }
    let mut tilts: Vec<f64> = tiles
        .iter()
        .flat_map(|t| t.flakes.iter().map(|f| f.tilt()))
        .collect();
    let pks = ks_p(&mut tilts, |x| p.tilt.cdf(x));
    assert!(pks > 0.01, "tilt KS p = {pks}");
    // A wrong law is rejected by the same test.
    if let TiltDist::HalfNormal { sigma_deg } = p.tilt {
        let wrong = TiltDist::HalfNormal {
            sigma_deg: 1.1 * sigma_deg,
        };
        assert!(ks_p(&mut tilts, |x| wrong.cdf(x)) < 0.01);
    }
    tiles
}

/// Whether flakes `a` and `b` (shifted by `shift`, a periodic image) interpenetrate as slabs
/// of thickness `h`: over points of `b`'s mid-plane disc above or below `a`'s disc, the
/// vertical gap between the mid-planes must keep one sign and exceed the sum of the two half
/// vertical thicknesses.
fn interpenetrate(a: &Flake, b: &Flake, h: f64, shift: Vector3<f64>) -> bool {
    let (ac, an, bn) = (Vector3::from(a.c), Vector3::from(a.n), Vector3::from(b.n));
    let bc = Vector3::from(b.c) + shift;
    let (u, v) = {
        let helper = if bn.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = bn.cross(&helper).normalize();
        (u, bn.cross(&u))
    };
    let za = |x: f64, y: f64| ac.z - (an.x * (x - ac.x) + an.y * (y - ac.y)) / an.z;
    let need = 0.5 * h / an.z + 0.5 * h / bn.z - 1e-6;
    let (mut above, mut below) = (false, false);
    for ri in 0..=16 {
        let rr = b.r * ri as f64 / 16.0;
        for k in 0..64 {
            let ph = k as f64 * std::f64::consts::TAU / 64.0;
            let p = bc + (u * ph.cos() + v * ph.sin()) * rr;
            let q = Vector3::new(p.x, p.y, za(p.x, p.y));
            if (q - ac).norm() > a.r {
                continue;
            }
            let gap = p.z - q.z;
            if gap.abs() < need {
                return true;
            }
            above |= gap > 0.0;
            below |= gap < 0.0;
        }
    }
    above && below
}

#[test]
fn check7_deposit_statistics_and_no_interpenetration() {
    // Parameters at which the deposit fits the layer (the study's densities do not: see
    // `FlakeParams::model`).
    let p = FlakeParams::default()
        .model(StackModel::Deposit)
        .radius_um(15.0)
        .density(3.5)
        .tilt(TiltDist::HalfNormal { sigma_deg: 3.0 });
    let tiles = check_statistics(&p);
    let l = p.tile_um;
    let (mut pairs, mut under) = (0, 0);
    for t in tiles.iter().take(3) {
        assert!(t.clamped * 200 <= t.flakes.len(), "{} clamped", t.clamped);
        let f = &t.flakes;
        let free = |i: usize| !t.clamped_flakes.contains(&(i as u32));
        for j in (0..f.len()).filter(|&j| free(j)) {
            for i in (0..j).filter(|&i| free(i)) {
                // Nearest periodic image of j relative to i.
                let mut d = Vector3::from(f[j].c) - Vector3::from(f[i].c);
                let sx = -(d.x / l).round() * l;
                let sy = -(d.y / l).round() * l;
                d.x += sx;
                d.y += sy;
                if d.x.hypot(d.y) >= f[i].r + f[j].r {
                    continue;
                }
                pairs += 1;
                assert!(
                    !interpenetrate(&f[i], &f[j], p.thickness_um, Vector3::new(sx, sy, 0.0)),
                    "flakes {i} and {j} interpenetrate"
                );
                under += (f[j].c[2] < f[i].c[2]) as usize;
            }
        }
    }
    assert!(pairs > 10_000, "only {pairs} overlapping pairs checked");
    // Later flakes settle under raised edges too, not only on top.
    assert!(under > 0);
    // The layer is filled from the base up: the mean centre height stays well below the top.
    let zc: Vec<f64> = tiles[0].flakes.iter().map(|f| f.c[2]).collect();
    eprintln!(
        "deposit: {pairs} overlapping pairs, {under} later flakes below earlier ones, mean height {:.2} µm",
        zc.iter().sum::<f64>() / zc.len() as f64
    );
    // The same check finds the interpenetration of the Boolean model.
    let b = p.model(StackModel::Boolean).radius_um(10.0).density(6.5);
    let t = generate_tile(&b, 5).unwrap();
    let f = &t.flakes;
    let crossing = (0..f.len())
        .flat_map(|j| (0..j).map(move |i| (i, j)))
        .filter(|&(i, j)| {
            (f[j].c[0] - f[i].c[0]).hypot(f[j].c[1] - f[i].c[1]) < 0.5 * (f[i].r + f[j].r)
        })
        .any(|(i, j)| interpenetrate(&f[i], &f[j], b.thickness_um, Vector3::zeros()));
    assert!(
        crossing,
        "a Boolean layer this dense has interpenetrating flakes"
    );
}

#[test]
fn check7_boolean_statistics() {
    let p = FlakeParams::default()
        .model(StackModel::Boolean)
        .radius_um(10.0)
        .tilt(TiltDist::UniformCap { max_deg: 20.0 });
    let tiles = check_statistics(&p);
    // Heights uniform over the allowed range: mean at the layer's middle.
    let z: Vec<f64> = tiles
        .iter()
        .flat_map(|t| t.flakes.iter().map(|f| f.c[2]))
        .collect();
    let m = z.iter().sum::<f64>() / z.len() as f64;
    assert!((m - 0.5 * p.layer_um).abs() < 0.05, "{m}");
    // Coverage of untilted discs is 1 - exp(-density) (Matheron).
    let flat = p.tilt(TiltDist::Flat).radius_cv(0.0).density(1.2);
    let t = generate_tile(&flat, 9).unwrap();
    let mut covered = 0usize;
    let k = 300;
    for j in 0..k {
        for i in 0..k {
            let o = [(i as f64 + 0.5) * 1.5, (j as f64 + 0.5) * 1.5, 30.0];
            if t.hit(o, [0.0, 0.0, -1.0], 100.0).is_some() {
                covered += 1;
            }
        }
    }
    let frac = covered as f64 / (k * k) as f64;
    assert!(
        (frac - (1.0 - (-1.2f64).exp())).abs() < 0.06,
        "coverage {frac}"
    );
}

/// The paint of checks 8: sparse, small flakes with normals uniform over a cap, in the
/// Boolean model (no stacking), under the default coat.
fn sparse_plate(max_tilt_deg: f64, density: f64, seed: u64) -> (FlakePlate, Plate) {
    let p = FlakeParams::default()
        .model(StackModel::Boolean)
        .radius_um(10.0)
        .radius_cv(0.0)
        .density(density)
        .tilt(TiltDist::UniformCap {
            max_deg: max_tilt_deg,
        });
    let micro = FlakePlate::new(&p, (150.0, 100.0), seed).unwrap();
    let plate = Plate::new(PlateStack::default(), Box::new(micro.clone())).unwrap();
    (micro, plate)
}

/// Refraction of a unit direction through a horizontal interface from index n1 to n2.
fn refract(d: Vector3<f64>, n1: f64, n2: f64) -> Option<Vector3<f64>> {
    let (x, y) = (d.x * n1 / n2, d.y * n1 / n2);
    let s = x * x + y * y;
    (s < 1.0).then(|| Vector3::new(x, y, (1.0 - s).sqrt().copysign(d.z)))
}

/// The analytic mirror chain of one flake seen from `eye`: the ray through the coat that
/// reaches the flake's centre, its reflection, its exit; whether the exit direction lies in the
/// lamp's disc and the paths in and out are free of other flakes.
fn predicted_glint(
    f: &PlacedFlake,
    micro: &FlakePlate,
    stack: &PlateStack,
    rig: &StereoRig,
    eye: Eye,
    light: &DiscLight,
) -> bool {
    let n_c = stack.top_ior();
    let z_top = stack.top_um();
    let e = rig.eye(eye);
    // Eye in plate coordinates (µm): the plate's top surface is at distance a from the eyes.
    let eye_p = Vector3::new(e[0] * 1e6, e[1] * 1e6, z_top + rig.dist_m * 1e6);
    let c = Vector3::from(f.disc.c);
    // Entry point: fixed-point iteration on the refracted direction.
    let mut entry = Vector3::new(c.x, c.y, z_top);
    let mut d_in = Vector3::zeros();
    for _ in 0..20 {
        let d_air = (entry - eye_p).normalize();
        d_in = refract(d_air, 1.0, n_c).unwrap();
        let t = (z_top - c.z) / -d_in.z;
        entry = Vector3::new(c.x - d_in.x * t, c.y - d_in.y * t, z_top);
    }
    let n = Vector3::from(f.disc.n);
    let d_r = d_in - n * (2.0 * d_in.dot(&n));
    if d_r.z <= 0.0 {
        return false;
    }
    let Some(out) = refract(d_r, n_c, 1.0) else {
        return false;
    };
    if !light.contains(out.into()) {
        return false;
    }
    // Visibility: some point of the disc (a polar grid) is free of other flakes on the way in
    // and on the way out.
    let tb = stack.binder_um;
    let clear = |p: Vector3<f64>| {
        let t_in = (tb - p.z) / -d_in.z;
        let t_out = (tb - p.z) / d_r.z;
        let hit_in = micro.hit((p - d_in * t_in).into(), d_in.into(), t_in * (1.0 + 1e-9));
        let seen = matches!(hit_in, Some(h) if h.id == f.id && (h.t - t_in).abs() < 1e-6);
        seen && micro.hit(p.into(), d_r.into(), t_out).is_none()
    };
    let (u, v) = {
        let helper = if n.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = n.cross(&helper).normalize();
        (u, n.cross(&u))
    };
    (0..=4).any(|ri| {
        let rr = 0.95 * f.disc.r * ri as f64 / 4.0;
        let k = if ri == 0 { 1 } else { 12 * ri };
        (0..k).any(|j| {
            let ph = j as f64 * std::f64::consts::TAU / k as f64;
            let p = c + (u * ph.cos() + v * ph.sin()) * rr;
            let (x0, y0, x1, y1) = f.cell;
            p.x > x0 && p.x < x1 && p.y > y0 && p.y < y1 && clear(p)
        })
    })
}

#[test]
fn check8_glints_follow_the_mirror_chain() {
    let (micro, plate) = sparse_plate(30.0, 0.3, 8);
    let stack = PlateStack::default();
    let rig = StereoRig::default();
    let light = DiscLight::from_elevation(45.0, 6.0);
    let half = 4.0;
    let s = PaintRenderParams::default()
        .spp(4)
        .region_mm(Some(Rect::centred(0.0, 0.0, 2.0 * half, 2.0 * half)))
        .magnification(27.75);
    let img = render(&plate, &light, &rig, Eye::Left, &s).unwrap();
    let flakes = micro.flakes_in(
        -half * 1e3 + 20.0,
        -half * 1e3 + 20.0,
        half * 1e3 - 20.0,
        half * 1e3 - 20.0,
    );
    let rendered: std::collections::HashSet<u64> = img.glint_ids.iter().copied().collect();
    let (mut agree, mut predicted, mut found) = (0usize, 0usize, 0usize);
    for f in &flakes {
        let p = predicted_glint(f, &micro, &stack, &rig, Eye::Left, &light);
        let r = rendered.contains(&f.id);
        predicted += p as usize;
        found += (p && r) as usize;
        agree += (p == r) as usize;
    }
    let glinting = flakes.iter().filter(|f| rendered.contains(&f.id)).count();
    eprintln!(
        "{} flakes, {predicted} predicted, {glinting} rendered, {found} both",
        flakes.len()
    );
    assert!(predicted > 100, "{predicted}");
    assert!(agree as f64 >= 0.99 * flakes.len() as f64);
    // Among the flakes that glint either way, the two agree too (measured: 195 of 196).
    let union = predicted + glinting - found;
    assert!(found as f64 >= 0.98 * union as f64, "{found} of {union}");
}

/// Area of the intersection of two discs of radius `r` whose centres are `d` apart, over the
/// area of one.
fn lens_ratio(r: f64, d: f64) -> f64 {
    if d >= 2.0 * r {
        return 0.0;
    }
    let a = 2.0 * r * r * (d / (2.0 * r)).acos() - 0.5 * d * (4.0 * r * r - d * d).sqrt();
    a / (std::f64::consts::PI * r * r)
}

#[test]
fn check8_binocular_overlap_is_the_lens_of_two_lamp_cones() {
    let (_, plate) = sparse_plate(10.0, 0.3, 18);
    let rig = StereoRig::default();
    let sep = (rig.eye_sep_m / rig.dist_m).atan().to_degrees();
    let s = PaintRenderParams::default()
        .spp(4)
        .region_mm(Some(Rect::centred(0.0, 0.0, 5.0, 5.0)))
        .magnification(27.75);
    for radius in [1.0, 3.0, 4.0, 6.0] {
        let light = DiscLight::from_elevation(70.0, radius);
        let l = render(&plate, &light, &rig, Eye::Left, &s).unwrap();
        let r = render(&plate, &light, &rig, Eye::Right, &s).unwrap();
        let ov = binocular_overlap(&l.glint_ids, &r.glint_ids);
        let expected = lens_ratio(radius, sep);
        eprintln!(
            "lamp {radius} deg: {} / {} glints, overlap {ov:.3}, lens {expected:.3}",
            l.glint_ids.len(),
            r.glint_ids.len()
        );
        assert!(l.glint_ids.len() > 30);
        assert!(
            (ov - expected).abs() < 0.05,
            "lamp {radius}: {ov} vs {expected}"
        );
    }
}

#[test]
fn check9_energy_and_coat_only() {
    let rig = StereoRig::default();
    let s = PaintRenderParams::default()
        .spp(4)
        .region_mm(Some(Rect::centred(0.0, 0.0, 10.0, 10.0)))
        .magnification(2.0);
    // Without flakes, a lamp straight above: every pixel sees the lamp in the coat, Y = F(cos) Y_lamp.
    let bare = Plate::new(PlateStack::default(), Box::new(NoFlakes)).unwrap();
    let above = DiscLight::from_elevation(90.0, 1.0);
    let img = render(&bare, &above, &rig, Eye::Cyclopean, &s).unwrap();
    let y = img.luminance();
    let f0 = fresnel_dielectric(1.0, 1.5);
    for &v in y.data() {
        assert!(
            (v as f64 / img.lamp_y / f0 - 1.0).abs() < 2e-3,
            "{} vs {}",
            v,
            f0 * img.lamp_y
        );
    }
    // Lamp at 45 degrees: the coat's mirror image misses it, the image is black.
    let side = DiscLight::default();
    let img = render(&bare, &side, &rig, Eye::Cyclopean, &s).unwrap();
    assert!(img.xyz.iter().all(|&v| v == 0.0));
    // With flakes: no pixel brighter than the lamp.
    let micro = FlakePlate::new(&FlakeParams::default(), (150.0, 100.0), 3).unwrap();
    let plate = Plate::new(PlateStack::default(), Box::new(micro)).unwrap();
    for light in [above, side] {
        let img = render(&plate, &light, &rig, Eye::Left, &s).unwrap();
        let max = img.luminance().data().iter().fold(0.0f32, |m, &v| m.max(v));
        assert!(
            max as f64 <= img.lamp_y * (1.0 + 1e-9) && max > 0.0,
            "{max} vs {}",
            img.lamp_y
        );
    }
}

#[test]
fn check9_error_falls_as_one_over_root_spp() {
    let micro = FlakePlate::new(&FlakeParams::default(), (150.0, 100.0), 4).unwrap();
    let plate = Plate::new(PlateStack::default(), Box::new(micro)).unwrap();
    let rig = StereoRig::default();
    // A lamp of 4 degrees: with 1 degree the glints are so rare and bright that one
    // realisation's error is dominated by a handful of events.
    let light = DiscLight::from_elevation(75.0, 4.0);
    let base = PaintRenderParams::default()
        .region_mm(Some(Rect::centred(0.0, 0.0, 3.0, 3.0)))
        .magnification(4.0);
    let run = |spp: u32, seed: u64, independent: bool| {
        let s = base
            .clone()
            .spp(spp)
            .seed(seed)
            .independent_samples(independent);
        render(&plate, &light, &rig, Eye::Cyclopean, &s)
            .unwrap()
            .luminance()
            .into_data()
    };
    let reference = run(4096, 99, true);
    let rmse = |a: &[f32]| {
        (a.iter()
            .zip(&reference)
            .map(|(x, y)| ((x - y) as f64).powi(2))
            .sum::<f64>()
            / a.len() as f64)
            .sqrt()
    };
    // Independent samples: the error halves when the samples quadruple (2 +- 0.3, the
    // reference's own noise included).
    let ratio = rmse(&run(64, 1, true)) / rmse(&run(256, 2, true));
    let strat = rmse(&run(64, 1, false)) / rmse(&run(256, 2, false));
    eprintln!("RMSE ratio 64 -> 256 spp: independent {ratio:.3}, stratified {strat:.3}");
    assert!((ratio - 2.0).abs() < 0.3, "independent: {ratio}");
    // Stratified (jittered) samples do at least as well.
    assert!(strat > 1.9, "stratified: {strat}");
}

#[test]
fn check5_white_lambertian_plate_renders_to_the_illuminant() {
    let stack = PlateStack {
        coat: None,
        binder_ior: 1.0,
        base_albedo: 1.0,
        ..PlateStack::default()
    };
    let plate = Plate::new(stack, Box::new(NoFlakes)).unwrap();
    let rig = StereoRig::default();
    let s = PaintRenderParams::default()
        .spp(16)
        .region_mm(Some(Rect::centred(0.0, 0.0, 5.0, 5.0)))
        .magnification(1.0);
    for (name, spd, xy) in cref::ILLUMINANTS.iter() {
        let light = DiscLight {
            spectrum: Spectrum::new(SpectralGrid::VISIBLE, spd.to_vec()).unwrap(),
            ..DiscLight::from_elevation(60.0, 2.0)
        };
        let img = render(&plate, &light, &rig, Eye::Cyclopean, &s).unwrap();
        let n = (img.width * img.height) as f64;
        let mut m = [0.0f64; 3];
        for p in img.xyz.chunks_exact(3) {
            for k in 0..3 {
                m[k] += p[k] as f64 / n;
            }
        }
        assert!((m[1] - 1.0).abs() < 0.005, "{name}: Y = {}", m[1]);
        let ours = xyz_to_xy(m);
        assert!(
            (ours[0] - xy[0]).abs() < 1e-3 && (ours[1] - xy[1]).abs() < 1e-3,
            "{name}: {ours:?} vs {xy:?}"
        );
        if *name == "D65" {
            for c in xyz_to_rgb(m, &XYZ_TO_SRGB) {
                assert!((c - 1.0).abs() < 0.005, "{name}: sRGB {c}");
            }
        }
    }
}

#[test]
fn left_and_right_share_the_microstructure() {
    let micro = FlakePlate::new(&FlakeParams::default(), (150.0, 100.0), 11).unwrap();
    let plate = Plate::new(PlateStack::default(), Box::new(micro)).unwrap();
    let light = DiscLight::from_elevation(75.0, 3.0);
    let rig = StereoRig::default();
    let s = PaintRenderParams::default()
        .spp(4)
        .region_mm(Some(Rect::centred(0.0, 0.0, 5.0, 5.0)))
        .magnification(4.0);
    let l = render(&plate, &light, &rig, Eye::Left, &s).unwrap();
    let r = render(&plate, &light, &rig, Eye::Right, &s).unwrap();
    let ov = binocular_overlap(&l.glint_ids, &r.glint_ids);
    // Same flakes glint for both eyes in part (a re-seeded right view would share none).
    assert!(ov > 0.05 && ov < 0.95, "overlap {ov}");
    // Deterministic: the same settings give the same image, whatever the thread count.
    let again = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| render(&plate, &light, &rig, Eye::Left, &s).unwrap());
    assert_eq!(again, l);
}

#[test]
fn bad_input_is_an_error() {
    let p = FlakeParams::default();
    for bad in [
        p.radius_um(0.0),
        p.radius_um(300.0),
        p.density(-1.0),
        p.density(f64::NAN),
        p.thickness_um(21.0),
        p.tiles_in_pool(0),
        p.tilt(TiltDist::UniformCap { max_deg: 95.0 }),
    ] {
        assert!(generate_tile(&bad, 0).is_err(), "{bad:?}");
    }
    // A deposit that overflows the layer is an error, not a silent clamp.
    let over = p
        .model(StackModel::Deposit)
        .density(40.0)
        .max_clamped_fraction(0.01);
    let e = generate_tile(&over, 0).unwrap_err().to_string();
    assert!(e.contains("overflow"), "{e}");
    // Tilts at which a flake would leave the layer are lowered to the largest that fits.
    let tall = p
        .model(StackModel::Boolean)
        .radius_cv(0.0)
        .tilt(TiltDist::UniformCap { max_deg: 60.0 });
    let t = generate_tile(&tall, 0).unwrap();
    let limit = max_tilt(30.0, 0.5, 20.24);
    assert!(
        (limit.to_degrees() - 19.23).abs() < 0.01,
        "{}",
        limit.to_degrees()
    );
    let at_limit = t
        .flakes
        .iter()
        .filter(|f| (f.tilt() - limit).abs() < 1e-12)
        .count();
    assert!(at_limit > t.flakes.len() / 2);
    for f in &t.flakes {
        assert!(f.tilt() <= limit + 1e-12);
        let e = f.half_height(0.5);
        assert!(f.c[2] - e >= -1e-9 && f.c[2] + e <= 20.24 + 1e-9);
    }
    let bad_stack = PlateStack {
        coat: Some(Coat {
            ior: 0.9,
            thickness_um: 40.0,
        }),
        ..PlateStack::default()
    };
    assert!(Plate::new(bad_stack, Box::new(NoFlakes)).is_err());
    let metal = PlateStack {
        metal: MetalIor::Constant { n: 1.0, k: -6.0 },
        ..PlateStack::default()
    };
    assert!(Plate::new(metal, Box::new(NoFlakes)).is_err());
    let plate = Plate::new(PlateStack::default(), Box::new(NoFlakes)).unwrap();
    let rig = StereoRig::default();
    let light = DiscLight::default();
    let ok = PaintRenderParams::default();
    for bad in [
        ok.clone().spp(0),
        ok.clone().max_depth(0),
        ok.clone().magnification(0.0),
        ok.clone()
            .region_mm(Some(Rect::centred(0.0, 0.0, 0.0, 1.0))),
        ok.clone()
            .region_mm(Some(Rect::centred(100.0, 0.0, 10.0, 10.0))),
    ] {
        assert!(
            render(&plate, &light, &rig, Eye::Left, &bad).is_err(),
            "{bad:?}"
        );
    }
    let low = DiscLight::from_elevation(0.5, 1.0);
    assert!(render(&plate, &low, &rig, Eye::Left, &ok).is_err());
    assert!(FlakePlate::new(&p, (0.0, 10.0), 0).is_err());
}

#[test]
fn rgb_baseline_equals_spectral_for_grey_flakes_only() {
    let rig = StereoRig::default();
    let light = DiscLight::from_elevation(75.0, 3.0);
    let micro = FlakePlate::new(&FlakeParams::default(), (150.0, 100.0), 12).unwrap();
    let s = PaintRenderParams::default()
        .spp(16)
        .region_mm(Some(Rect::centred(0.0, 0.0, 3.0, 3.0)))
        .magnification(4.0);
    let rgb = s.clone().colour(ColourMode::Rgb);
    let render_both = |metal: MetalIor| {
        let stack = PlateStack {
            metal,
            ..PlateStack::default()
        };
        let plate = Plate::new(stack, Box::new(micro.clone())).unwrap();
        (
            render(&plate, &light, &rig, Eye::Cyclopean, &s).unwrap(),
            render(&plate, &light, &rig, Eye::Cyclopean, &rgb).unwrap(),
        )
    };
    // A metal of constant index: the three bands carry the lamp's colour exactly.
    let (a, b) = render_both(MetalIor::Constant { n: 1.2, k: 7.0 });
    let (ma, mb) = (a.mean_xyz(), b.mean_xyz());
    assert!(ma[1] > 0.0);
    for k in 0..3 {
        assert!((ma[k] / mb[k] - 1.0).abs() < 1e-9, "{ma:?} vs {mb:?}");
    }
    // Aluminium's reflectance varies over the spectrum: the RGB render's colour is off.
    let (a, b) = render_both(MetalIor::AlRakicLd);
    let (xa, xb) = (xyz_to_xy(a.mean_xyz()), xyz_to_xy(b.mean_xyz()));
    let shift = (xa[0] - xb[0]).hypot(xa[1] - xb[1]);
    eprintln!("aluminium glints: spectral xy {xa:?}, RGB xy {xb:?}, shift {shift:.5}");
    assert!(shift > 1e-4 && shift < 0.02, "{shift}");
}

#[test]
fn spectral_output_integrates_to_xyz_and_round_trips_through_exr() {
    use wscg_raytrace::spectral::tables::{CMF_X, CMF_Y, CMF_Z};
    let micro = FlakePlate::new(&FlakeParams::default(), (150.0, 100.0), 5).unwrap();
    let plate = Plate::new(PlateStack::default(), Box::new(micro)).unwrap();
    let s = PaintRenderParams::default()
        .spp(4)
        .region_mm(Some(Rect::centred(0.0, 0.0, 2.0, 2.0)))
        .magnification(4.0)
        .keep_spectrum(true);
    let img = render(
        &plate,
        &DiscLight::from_elevation(75.0, 3.0),
        &StereoRig::default(),
        Eye::Left,
        &s,
    )
    .unwrap();
    assert_eq!(img.bands_nm.len(), 81);
    let mut lit = 0;
    for (p, sp) in img.xyz.chunks_exact(3).zip(img.spectrum.chunks_exact(81)) {
        let integ = |cmf: &[f64]| {
            sp.iter()
                .zip(cmf)
                .map(|(v, c)| *v as f64 * c * 5.0)
                .sum::<f64>()
        };
        let xyz = [integ(&CMF_X), integ(&CMF_Y), integ(&CMF_Z)];
        for k in 0..3 {
            assert!(
                (xyz[k] - p[k] as f64).abs() <= 1e-4 * (p[k] as f64).max(1e-3),
                "{xyz:?} vs {p:?}"
            );
        }
        lit += (p[1] > 0.0) as usize;
    }
    assert!(lit > 0);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("spectral.exr");
    write_spectral_exr(&img, &path).unwrap();
    write_xyz_exr(&img, dir.path().join("xyz.exr")).unwrap();
    let back = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let layer = &back.layer_data[0];
    assert_eq!(layer.channel_data.list.len(), 81);
    let c550 = layer
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == "550nm")
        .unwrap();
    let exr::prelude::FlatSamples::F32(v) = &c550.sample_data else {
        panic!("f32 samples expected")
    };
    let k550 = 34;
    for (i, val) in v.iter().enumerate() {
        assert_eq!(*val, img.spectrum[i * 81 + k550]);
    }
    // A view without its spectrum cannot be written as one.
    let plain = render(
        &plate,
        &DiscLight::default(),
        &StereoRig::default(),
        Eye::Left,
        &s.clone().keep_spectrum(false),
    )
    .unwrap();
    assert!(write_spectral_exr(&plain, dir.path().join("x.exr")).is_err());
}

/// A mirror plane tilted by 45 degrees about the x axis, facing -y, between heights `z1` and
/// `z2` of the binder: `z - y = zm`. Light from a lamp towards +y reaches it from its front
/// and is reflected straight down onto the base, a caustic of known irradiance.
struct TiltedMirror {
    zm: f64,
    z1: f64,
    z2: f64,
}

impl Microstructure for TiltedMirror {
    fn hit(&self, o: [f64; 3], d: [f64; 3], t_max: f64) -> Option<FlakeHit> {
        let n = Vector3::new(0.0, -1.0, 1.0) / 2f64.sqrt();
        let denom = d[2] - d[1];
        if denom.abs() < 1e-12 {
            return None;
        }
        let t = (self.zm - (o[2] - o[1])) / denom;
        let z = o[2] + t * d[2];
        (t > 1e-9 && t <= t_max && z >= self.z1 && z <= self.z2).then_some(FlakeHit {
            t,
            normal: n.into(),
            id: 1,
        })
    }
}

#[test]
fn photon_map_direct_irradiance_matches_the_refracted_lamp() {
    // No flakes, all photons kept: the base irradiance is the lamp's solid angle times the
    // cosine, the top surface's transmission and the binder's absorption along the path.
    let stack = PlateStack {
        binder_sigma_a_per_mm: 2.0,
        ..PlateStack::default()
    };
    let plate = Plate::new(stack.clone(), Box::new(NoFlakes)).unwrap();
    let light = DiscLight::from_elevation(40.0, 1.0);
    let ps = PhotonParams::default().count(1_000_000).k(400);
    let map = trace_photons(
        &plate,
        &light,
        [-1500.0, -1500.0, 1500.0, 1500.0],
        &ps,
        false,
    )
    .unwrap();
    let ct = light.dir_to_light[2];
    let n = stack.top_ior();
    let st_b = (1.0 - ct * ct).sqrt() / n;
    let ct_b = (1.0 - st_b * st_b).sqrt();
    // The binder absorbs; the clear coat does not.
    let path_mm = stack.binder_um * 1e-3 / ct_b;
    let expect = light.solid_angle()
        * ct
        * (1.0 - fresnel_dielectric(ct, n))
        * (-stack.binder_sigma_a_per_mm * path_mm).exp();
    let mut mean = 0.0;
    for i in 0..5 {
        for j in 0..5 {
            mean += map.irradiance(-800.0 + 400.0 * i as f64, -800.0 + 400.0 * j as f64) / 25.0;
        }
    }
    assert!(
        (mean / expect - 1.0).abs() < 0.02,
        "photon irradiance {mean} vs analytic {expect}"
    );
    // Every stored photon came straight through the flake-free binder.
    assert!(map.photons.iter().all(|p| p.n == 0));
}

/// Mean `Y` of the cyclopean view rendered with `s` (its photon map) and without photons.
fn mean_y_with_and_without_photons(
    plate: &Plate,
    light: &DiscLight,
    s: &PaintRenderParams,
) -> (f64, f64) {
    let rig = StereoRig::default();
    let y = |s: &PaintRenderParams| {
        render(plate, light, &rig, Eye::Cyclopean, s)
            .unwrap()
            .mean_xyz()[1]
    };
    let without = s.clone().photons(None);
    (y(s), y(&without))
}

#[test]
fn photon_map_caustic_of_a_tilted_mirror() {
    // Light refracted into the binder at theta_b reaches a 45-degree mirror and leaves it
    // straight down at 90 - theta_b from the vertical: the reflected beam's irradiance on the
    // base is the direct irradiance times R(cos_i) tan(theta_b) (the beam's cross-section
    // projected onto the base), over the strip between y = z - zm - z cot(theta_b) for
    // z = z1 and z = z2.
    let stack = PlateStack {
        coat: None,
        binder_um: 100.0,
        base_albedo: 1.0,
        ..PlateStack::default()
    };
    let mirror = TiltedMirror {
        zm: 50.0,
        z1: 20.0,
        z2: 80.0,
    };
    let plate = Plate::new(stack.clone(), Box::new(mirror)).unwrap();
    let light = DiscLight::from_elevation(45.0, 0.5);
    let ps = PhotonParams::default()
        .count(2_000_000)
        .k(200)
        .max_radius_um(20.0)
        .margin_um(300.0);
    let mut map = trace_photons(&plate, &light, [-200.0, -300.0, 200.0, 200.0], &ps, true).unwrap();
    let ct = light.dir_to_light[2];
    let nb = stack.binder_ior;
    let st_b = (1.0 - ct * ct).sqrt() / nb;
    let ct_b = (1.0 - st_b * st_b).sqrt();
    let direct = light.solid_angle() * ct * (1.0 - fresnel_dielectric(ct, nb));
    let caustic = direct * st_b / ct_b;
    let ends = [
        20.0 - 50.0 - 20.0 * ct_b / st_b,
        80.0 - 50.0 - 80.0 * ct_b / st_b,
    ];
    let (y_lo, y_hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
    let y_mid = 0.5 * (y_lo + y_hi);
    assert!(y_hi - y_lo > 40.0);
    // Independent estimates (disjoint discs of about 4 µm) over the strip's middle.
    let mut mean = 0.0;
    for i in 0..37 {
        for dy in [-10.0, 0.0, 10.0] {
            mean += map.irradiance(-180.0 + 10.0 * i as f64, y_mid + dy) / 111.0;
        }
    }
    assert!(
        (mean / caustic - 1.0).abs() < 0.03,
        "caustic irradiance {mean} vs analytic {caustic}"
    );
    // Outside the strip no caustic photon lands.
    assert_eq!(map.irradiance(0.0, y_hi + 40.0), 0.0);
    assert_eq!(map.irradiance(0.0, y_lo - 40.0), 0.0);
    // Per band, the flux carries the aluminium's reflectance at the mirror's incidence.
    let cos_i = (ct_b - st_b) / 2f64.sqrt();
    let rel: Vec<_> = [450.0, 550.0, 650.0]
        .iter()
        .map(|&l| plate.relative_index(l))
        .collect();
    map.set_bands(&rel);
    let mut e = [0.0; 3];
    assert!(map.band_irradiance(0.0, y_mid, &mut e));
    let e0 = map.irradiance(0.0, y_mid);
    for (k, r) in rel.iter().enumerate() {
        let want = e0 * fresnel_conductor(cos_i, r.re, r.im);
        assert!(
            (e[k] / want - 1.0).abs() < 2e-3,
            "band {k}: {} vs {want}",
            e[k]
        );
    }

    // The renderer adds the caustic to the light-sampled direct light: over the strip, a
    // base of albedo 1 seen from above is brighter by 1 + R tan(theta_b) with the photons.
    let s = PaintRenderParams::default()
        .spp(16)
        .region_mm(Some(Rect::centred(0.0, y_mid * 1e-3, 0.06, 0.02)))
        .magnification(30.0)
        .photons(Some(ps));
    let (with, without) = mean_y_with_and_without_photons(&plate, &light, &s);
    let ratio = with / without;
    let r560 = plate.relative_index(560.0);
    let want = 1.0 + fresnel_conductor(cos_i, r560.re, r560.im) * st_b / ct_b;
    assert!(
        (ratio / want - 1.0).abs() < 0.03,
        "with / without photons {ratio} vs {want}"
    );
}

#[test]
fn caustics_brighten_a_diffuse_base_and_bad_photon_settings_are_errors() {
    // A sparse paint (half the base visible), so that the base shows.
    let p = FlakeParams::default().density(0.7);
    let micro = FlakePlate::new(&p, (150.0, 100.0), 5).unwrap();
    let stack = PlateStack {
        base_albedo: 0.5,
        ..PlateStack::default()
    };
    let plate = Plate::new(stack, Box::new(micro)).unwrap();
    let light = DiscLight::default();
    let rig = StereoRig::default();
    let s = PaintRenderParams::default()
        .spp(4)
        .region_mm(Some(Rect::centred(0.0, 0.0, 2.0, 2.0)))
        .magnification(4.0)
        .photons(Some(
            PhotonParams::default().count(300_000).margin_um(500.0),
        ));
    let (a, b) = mean_y_with_and_without_photons(&plate, &light, &s);
    eprintln!("diffuse base 0.5: Y with caustics {a:.4}, without {b:.4}");
    // Light reflected up by the flakes comes back down at the top surface (Fresnel, and
    // total internal reflection beyond 42 degrees): a few percent more on the base.
    assert!(a > 1.005 * b, "caustics add light: {a} vs {b}");
    for bad in [
        PhotonParams::default().count(0),
        PhotonParams::default().k(0),
        PhotonParams::default().max_radius_um(f64::NAN),
        PhotonParams::default().margin_um(-1.0),
    ] {
        let s = s.clone().photons(Some(bad));
        assert!(render(&plate, &light, &rig, Eye::Cyclopean, &s).is_err());
    }
}

#[test]
fn lamp_directions_are_uniform_in_the_disc() {
    // Uniform in solid angle over a cap of angular radius r: every direction inside, the
    // mean cosine to the axis (1 + cos r) / 2, no bias across the axis.
    let light = DiscLight::from_elevation(40.0, 5.0);
    let a = Vector3::from(light.dir_to_light);
    let n = 100_000;
    let (mut cos_sum, mut side) = (0.0, Vector3::zeros());
    for k in 0..n {
        let u1 = (k as f64 + 0.5) / n as f64;
        let u2 = (k as f64 * 0.618_033_988_75).fract();
        let d = light.sample_direction(u1, u2);
        assert!(light.contains(d));
        let d = Vector3::from(d);
        assert!((d.norm() - 1.0).abs() < 1e-12);
        cos_sum += d.dot(&a);
        side += d - a * d.dot(&a);
    }
    let want = 0.5 * (1.0 + light.cos_radius());
    assert!(
        (cos_sum / n as f64 - want).abs() < 1e-6,
        "{} vs {want}",
        cos_sum / n as f64
    );
    assert!(side.norm() / (n as f64) < 1e-4);
}

/// Unpolarised Fresnel reflectance of a smooth interface from index `n1` into `n2` at the
/// incidence cosine `c` (1 beyond the critical angle), written out here independently of
/// the renderer.
fn fresnel_exact(c: f64, n1: f64, n2: f64) -> f64 {
    let sin_t = n1 / n2 * (1.0 - c * c).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n1 * c - n2 * ct) / (n1 * c + n2 * ct);
    let rp = (n2 * c - n1 * ct) / (n2 * c + n1 * ct);
    0.5 * (rs * rs + rp * rp)
}

/// Hemispherical (diffuse) reflectance `int_0^1 F(mu) 2 mu dmu` of the interface from `n1`
/// into `n2`: composite Simpson's rule on each side of the critical angle.
fn diffuse_fresnel(n1: f64, n2: f64) -> f64 {
    let mu_c = if n1 > n2 {
        (1.0 - (n2 / n1).powi(2)).sqrt()
    } else {
        0.0
    };
    let m = 20_000;
    let h = (1.0 - mu_c) / m as f64;
    let f = |mu: f64| fresnel_exact(mu, n1, n2) * 2.0 * mu;
    let simpson: f64 = (0..=m)
        .map(|i| {
            let w = if i == 0 || i == m {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f(mu_c + i as f64 * h)
        })
        .sum::<f64>()
        * h
        / 3.0;
    mu_c * mu_c + simpson
}

#[test]
fn diffuse_base_under_a_smooth_coat_keeps_its_energy() {
    // A Lambertian base of albedo a under a smooth dielectric of index n, seen at the
    // cosine mu_o and lit at mu_i, has the reflectance factor (Saunderson's correction)
    //   (1 - F(mu_i)) (1 - F(mu_o)) a / (n^2 (1 - a F_dr,in)),
    // with F_dr,in the inside hemispherical reflectance, 1 - (1 - F_dr,out) / n^2 by
    // reciprocity; integrated over the outgoing directions it gives back
    // (1 - F(mu_i)) a (1 - F_dr,in) / (1 - a F_dr,in): 1 - F(mu_i) for a white base.
    for n in [1.3, 1.5, 1.8] {
        let inside = diffuse_fresnel(n, 1.0);
        let outside = diffuse_fresnel(1.0, n);
        assert!((inside - (1.0 - (1.0 - outside) / (n * n))).abs() < 1e-6);
    }
    let rig = StereoRig::default();
    let light = DiscLight::from_elevation(35.0, 0.5);
    let mu_i = light.dir_to_light[2];
    let (cx, cy) = (30.0, -20.0);
    let mu_o =
        rig.dist_m / (rig.dist_m.powi(2) + (cx * 1e-3f64).powi(2) + (cy * 1e-3f64).powi(2)).sqrt();
    let s = PaintRenderParams::default()
        .spp(4)
        .seed(3)
        .photons(None)
        .region_mm(Some(Rect::centred(cx, cy, 1.0, 1.0)));
    // (albedo, index, with a coat of the binder's index)
    for (a, n, coated) in [
        (1.0, 1.5, true),
        (0.3, 1.3, false),
        (0.8, 1.8, false),
        (0.6, 1.6, true),
        (1.0, 1.4, false),
        (0.7, 1.0, false),
    ] {
        let stack = PlateStack {
            coat: coated.then_some(Coat {
                ior: n,
                thickness_um: 25.0,
            }),
            binder_ior: n,
            base_albedo: a,
            ..PlateStack::default()
        };
        let plate = Plate::new(stack, Box::new(NoFlakes)).unwrap();
        let y = render(&plate, &light, &rig, Eye::Cyclopean, &s)
            .unwrap()
            .mean_xyz()[1];
        let f_in = diffuse_fresnel(n, 1.0);
        let want = (1.0 - fresnel_exact(mu_i, 1.0, n)) * (1.0 - fresnel_exact(mu_o, 1.0, n)) * a
            / (n * n * (1.0 - a * f_in));
        eprintln!("albedo {a}, n {n}, coat {coated}: Y {y:.4}, analytic {want:.4}");
        assert!(
            (y / want - 1.0).abs() < 0.01,
            "albedo {a}, n {n}: Y {y} vs analytic {want}"
        );
    }
    // The fraction sent back down to the base, traced, is F_dr,in without flakes.
    let plate = Plate::new(PlateStack::default(), Box::new(NoFlakes)).unwrap();
    let rel = [plate.relative_index(550.0)];
    let rho = base_return(&plate, &rel, [0.0, 0.0, 500.0, 500.0], 10_000, 1).unwrap();
    let want = diffuse_fresnel(1.5, 1.0);
    assert!((rho[0] - want).abs() < 2e-3, "{} vs {want}", rho[0]);
    assert!(base_return(&plate, &rel, [0.0, 0.0, 0.0, 1.0], 100, 1).is_err());
    assert!(base_return(&plate, &rel, [0.0, 0.0, 1.0, 1.0], 0, 1).is_err());
}
