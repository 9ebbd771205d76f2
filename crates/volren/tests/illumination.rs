//! Paper 15 acceptance checks that need no external data: the exact
//! Beer-Lambert slab, the semigroup penumbra, delta kernel = shadow rays, pre-integration
//! against analytic integrals, the Table-1 shape on Marschner-Lobb, invariants, determinism
//! and bad input.

use wscg_math::{Volume, VolumeView};
use wscg_volren::illumination::kernel::discrete_gaussian;
use wscg_volren::illumination::preintegration::integrate_segment;
use wscg_volren::illumination::scenes::{
    self, constant, half_plane, marschner_lobb, marschner_lobb_tf,
};
use wscg_volren::illumination::study::mean_abs_diff;
use wscg_volren::illumination::*;

fn headlight(kernel: Kernel) -> Light {
    Light {
        dir_view: [0.0, 0.0, 1.0],
        ambient: 0.0,
        kernel,
    }
}

/// Camera looking along +z with image x = volume x and image y = volume y, 1 voxel pixels.
fn along_z(field: &ScalarField, w: usize, h: usize) -> SliceCamera {
    SliceCamera {
        dir: [0.0, 0.0, 1.0],
        up: [0.0, -1.0, 0.0],
        center: field.world_center(),
        width: w,
        height: h,
        pixel_size: 1.0,
    }
}

fn constant_tf(rgb: [f32; 3], a: f32) -> TransferFunction {
    TransferFunction::from_points(&[(0.0, [rgb[0], rgb[1], rgb[2], a])], 2).unwrap()
}

/// Check 1: centre pixel = (1 - (1 - alpha)^(2N)) / (2 - alpha).
#[test]
fn discrete_beer_lambert_slab() {
    let field = constant([64, 64, 40], 1.0).unwrap();
    let tf = constant_tf([1.0; 3], 0.05);
    let cam = along_z(&field, 64, 64);
    let light = headlight(Kernel::Delta);
    let mut errs = Vec::new();
    for (ds, want) in [(0.25f32, 0.494895), (0.5, 0.498048), (1.0, 0.504351)] {
        let alpha = 1.0 - 0.95f64.powf(ds as f64);
        let n = 40.0 / ds as f64;
        let formula = (1.0 - (1.0 - alpha).powf(2.0 * n)) / (2.0 - alpha);
        assert!(
            (formula - want).abs() < 1e-6,
            "tabulated value {want} vs formula {formula}"
        );
        let r = render(
            &field,
            &tf,
            &cam,
            &light,
            &Method::ics(ds),
            &IlluminationParams::default(),
        )
        .unwrap();
        assert_eq!(r.slices, n as usize);
        let got = r.image.at(32, 32, 0) as f64;
        assert!(
            (got - want).abs() <= 1e-4,
            "ds {ds}: centre {got} vs {want}"
        );
        errs.push(got - 0.5 * (1.0 - (-2.0 * -(0.95f64.ln()) * 40.0).exp()));
    }
    // The error against the continuum limit 0.491742 shrinks in proportion to ds.
    assert!((errs[1] / errs[0] - 2.0).abs() < 0.02 && (errs[2] / errs[1] - 2.0).abs() < 0.02);
}

fn phi(x: f64) -> f64 {
    0.5 * (1.0 + erf(x / std::f64::consts::SQRT_2))
}

/// erf by its Maclaurin series for |x| < 2.5 and the continued fraction of erfc beyond.
fn erf(x: f64) -> f64 {
    if x.abs() < 2.5 {
        // Maclaurin series.
        let mut sum = x;
        let mut term = x;
        let x2 = x * x;
        for n in 1..80 {
            term *= -x2 / n as f64;
            sum += term / (2 * n + 1) as f64;
        }
        2.0 / std::f64::consts::PI.sqrt() * sum
    } else {
        // Continued fraction for erfc.
        let t = x.abs();
        let mut f = 0.0;
        for n in (1..60).rev() {
            f = n as f64 / 2.0 / (t + f);
        }
        let erfc = (-t * t).exp() / std::f64::consts::PI.sqrt() / (t + f);
        x.signum() * (1.0 - erfc)
    }
}

/// Fits `L(x) = Phi((x - x_e) / sigma)` on the central row; returns (x_e, sigma, max error
/// of the fit with sigma fixed to `sigma0`).
fn fit_edge(row: &[f32], sigma0: f64) -> (f64, f64, f64) {
    let xs: Vec<usize> = (0..row.len())
        .filter(|&x| (x as f64 - 63.5).abs() <= 24.0)
        .collect();
    let sse = |xe: f64, s: f64| -> f64 {
        xs.iter()
            .map(|&x| (row[x] as f64 - phi((x as f64 - xe) / s)).powi(2))
            .sum()
    };
    let golden = |f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64| -> f64 {
        for _ in 0..200 {
            let (c, d) = (b - 0.618 * (b - a), a + 0.618 * (b - a));
            if f(c) < f(d) {
                b = d;
            } else {
                a = c;
            }
        }
        0.5 * (a + b)
    };
    let xe_fixed = golden(&|xe| sse(xe, sigma0), 50.0, 80.0);
    let max_err = xs
        .iter()
        .map(|&x| (row[x] as f64 - phi((x as f64 - xe_fixed) / sigma0)).abs())
        .fold(0.0, f64::max);
    // Free fit: alternate.
    let (mut xe, mut s) = (xe_fixed, sigma0);
    for _ in 0..20 {
        s = golden(&|s| sse(xe, s), 0.5 * sigma0, 2.0 * sigma0);
        xe = golden(&|xe| sse(xe, s), 50.0, 80.0);
    }
    (xe, s, max_err)
}

fn penumbra_row(ds: f32, light: &Light) -> Vec<f32> {
    penumbra_row_in(ds, light, 10..12)
}

/// The central row of the light buffer 32 voxels behind a half-plane occluder at the `z`
/// indices `zr` (x < 64).
fn penumbra_row_in(ds: f32, light: &Light, zr: std::ops::Range<usize>) -> Vec<f32> {
    occluder_row(ds, light, zr, 64, LightBorder::Open)
}

/// The central row of the light buffer 32 voxels behind an occluder at the `z` indices `zr`
/// covering `x < x_edge` of a 128 x 64 x 80 box, with the light border `border`.
fn occluder_row(
    ds: f32,
    light: &Light,
    zr: std::ops::Range<usize>,
    x_edge: usize,
    border: LightBorder,
) -> Vec<f32> {
    let (z0, z1) = (zr.start as f64, zr.end as f64);
    let field = half_plane([128, 64, 80], x_edge, zr).unwrap();
    // Step transfer function: opaque for s >= 1/2.
    let tf = TransferFunction::from_points(
        &[
            (0.0, [1.0, 1.0, 1.0, 0.0]),
            (0.499, [1.0, 1.0, 1.0, 0.0]),
            (0.5, [1.0; 4]),
            (1.0, [1.0; 4]),
        ],
        1024,
    )
    .unwrap();
    let cam = along_z(&field, 128, 64);
    let settings = IlluminationParams::default()
        .interp(Interp::Nearest)
        .border(border);
    // The last slice sampling the occluder (voxel k spans depths [k, k + 1) from the front).
    let k_o = (0..1000usize)
        .filter(|&k| {
            let d = (k as f64 + 0.5) * ds as f64;
            (z0..z1).contains(&d)
        })
        .max()
        .unwrap();
    let z_o = (k_o as f64 + 0.5) * ds as f64;
    let (buf, depth) = light_buffer_at(
        &field,
        &tf,
        &cam,
        light,
        &Method::ics(ds),
        &settings,
        z_o + 32.0,
    )
    .unwrap();
    assert!((depth - (z_o + 32.0)).abs() < 1e-9);
    (0..128).map(|x| buf.at(32, x, 0)).collect()
}

/// Check 2: one penumbra for every slice distance (variances add: sigma^2 = 2 D z).
#[test]
fn semigroup_penumbra() {
    let sigma = (2.0f64 * 0.5 * 32.0).sqrt();
    assert!((phi(-4.0 / sigma) - 0.2398).abs() < 1e-4);
    let light = headlight(Kernel::Gaussian { spread: 0.5 });
    let mut edges = Vec::new();
    for ds in [0.25f32, 0.5, 1.0, 2.0] {
        let row = penumbra_row(ds, &light);
        let (xe, s, max_err) = fit_edge(&row, sigma);
        assert!(max_err <= 0.01, "ds {ds}: max error {max_err}");
        assert!(
            (s / sigma - 1.0).abs() <= 0.03,
            "ds {ds}: sigma {s} vs {sigma}"
        );
        // The edge sits at the occluder's boundary (63.5) up to the light that diffuses into
        // the 2-voxel-thick occluder between its slices and is absorbed there (a blur of
        // sigma = sqrt(2 D 2) = 1.4 px inside it): it moves towards the lit side by less than
        // a pixel, and not at all when one slice samples the occluder (ds = 2).
        assert!((xe - 63.5).abs() < 1.0, "ds {ds}: edge {xe}");
        edges.push(xe);
    }
    // The cone kernel of directional occlusion shading is not variance-additive: its blur
    // depends on the slice distance.
    let disk = headlight(Kernel::Disk { tan_half: 1.0 });
    let (_, s_fine, _) = fit_edge(&penumbra_row(0.5, &disk), sigma);
    let (_, s_coarse, _) = fit_edge(&penumbra_row(2.0, &disk), sigma);
    assert!(
        s_coarse > 1.3 * s_fine,
        "disk blur {s_fine} at 0.5, {s_coarse} at 2"
    );
}

/// The light border: a 2-voxel opaque slab covering `x < 124` (it reaches the box's `-x`
/// side and stops 4 voxels short of its `+x` side), a headlight with a Gaussian kernel
/// (sigma = sqrt(2 D z) = 5.66 px 32 voxels behind). Open (as before): light from outside
/// the box leaks in under both edges, `Phi((x - 124) / sigma)` behind the slab and
/// `Phi(-x / sigma)` at the `-x` side. Closed: the outside beyond the sides is opaque, so at
/// the `-x` side nothing arrives and near the gap at most the gap's own light spreads,
/// `Phi((x - 124) / sigma) - Phi((x - 128) / sigma)` (absorbing walls only take light away).
/// The open edges sit up to 0.6 px towards the lit side of the analytic ones (light that
/// diffuses into the occluder between its slices is absorbed there, see `semigroup_penumbra`),
/// hence the tolerance 0.05 on the open light.
#[test]
fn closed_border_stops_light_leaking_round_the_occluder() {
    let sigma = (2.0f64 * 0.5 * 32.0).sqrt();
    let light = headlight(Kernel::Gaussian { spread: 0.5 });
    let open = occluder_row(0.5, &light, 10..12, 124, LightBorder::Open);
    let closed = occluder_row(0.5, &light, 10..12, 124, LightBorder::Closed);
    let c = |x: usize| x as f64 + 0.5;
    // The -x side: the slab reaches it.
    for x in 0..8 {
        let leak = phi(-c(x) / sigma);
        assert!(
            (open[x] as f64 - leak).abs() < 0.05,
            "open, x {x}: {} vs {leak}",
            open[x]
        );
        assert!(closed[x] < 1e-6, "closed, x {x}: {}", closed[x]);
    }
    // Behind the slab near the gap.
    for x in 108..124 {
        let through_gap = phi((c(x) - 124.0) / sigma) - phi((c(x) - 128.0) / sigma);
        let with_outside = phi((c(x) - 124.0) / sigma);
        assert!(
            (open[x] as f64 - with_outside).abs() < 0.05,
            "open, x {x}: {} vs {with_outside}",
            open[x]
        );
        assert!(
            (closed[x] as f64) <= through_gap + 0.01,
            "closed, x {x}: {} above the gap's own light {through_gap}",
            closed[x]
        );
    }
    // The light from outside is a real share of the open light there.
    let (x, xc) = (118, c(118));
    assert!(open[x] as f64 - closed[x] as f64 > 0.5 * phi((xc - 128.0) / sigma));
    // Far behind the slab both are dark; in the middle of the box neither border matters.
    assert!(open[64] < 1e-6 && closed[64] < 1e-6);
}

/// An oblique light moves the shadow edge by depth * l_x / l_z.
#[test]
fn oblique_light_shifts_the_shadow() {
    let lx = 0.3f64;
    let lz = (1.0 - lx * lx).sqrt();
    // One slice samples the occluder (a 1-voxel occluder at ds = 1, a 2-voxel one at ds = 2):
    // the headlight's edge is then exactly at the occluder's boundary, 63.5.
    for kernel in [Kernel::Gaussian { spread: 0.5 }, Kernel::Delta] {
        for (ds, zr) in [(1.0f32, 10..11), (2.0, 10..12)] {
            let light = Light {
                dir_view: [lx, 0.0, lz],
                ambient: 0.0,
                kernel,
            };
            let edge = |row: &[f32]| {
                let mid = (0..127)
                    .find(|&x| row[x] < 0.5 && row[x + 1] >= 0.5)
                    .unwrap();
                mid as f64 + (0.5 - row[mid] as f64) / (row[mid + 1] - row[mid]) as f64
            };
            let xe = edge(&penumbra_row_in(ds, &light, zr.clone()));
            let x_head = edge(&penumbra_row_in(ds, &headlight(kernel), zr));
            assert!(
                (x_head - 63.5).abs() < 0.02,
                "{kernel:?} ds {ds}: headlight edge {x_head}"
            );
            // Light comes from +x: the shadow edge moves towards -x by 32 l_x / l_z.
            let want = x_head - 32.0 * lx / lz;
            assert!(
                (xe - want).abs() < 0.1,
                "{kernel:?} ds {ds}: edge {xe} vs {want}"
            );
        }
    }
}

/// Check 3: ICS with the delta kernel and a headlight equals shadow rays.
#[test]
fn delta_kernel_equals_shadow_rays() {
    let field = marschner_lobb(41).unwrap();
    let tf = marschner_lobb_tf();
    let cam = SliceCamera::fit(&field, [0.3, -0.5, 1.0], [0.0, 1.0, 0.0], 64, 64).unwrap();
    let light = headlight(Kernel::Delta);
    let s = IlluminationParams::default();
    for ds in [0.5f32, 1.0] {
        let a = render(&field, &tf, &cam, &light, &Method::ics(ds), &s).unwrap();
        // Without blur the closed border changes nothing: light never turns back into the
        // box through a face that is not turned towards it.
        let closed = s.border(LightBorder::Closed);
        let a_closed = render(&field, &tf, &cam, &light, &Method::ics(ds), &closed).unwrap();
        assert_eq!(a.image.data(), a_closed.image.data(), "ds {ds}");
        let b = render(
            &field,
            &tf,
            &cam,
            &light,
            &Method::ShadowRays { step: ds },
            &s,
        )
        .unwrap();
        let mad = mean_abs_diff(&a.image, &b.image).unwrap();
        assert!(mad <= 1e-4, "ds {ds}: MAD {mad}");
        // Shadows matter here: emission-absorption alone differs.
        let c = render(
            &field,
            &tf,
            &cam,
            &light,
            &Method::RaycastEa { step: ds },
            &s,
        )
        .unwrap();
        assert!(mean_abs_diff(&a.image, &c.image).unwrap() > 1e-2);
    }
}

/// Check 4: the pre-integration table against analytic integrals.
#[test]
fn preintegration_table_is_exact() {
    let tf = marschner_lobb_tf();
    for l in [0.5f32, 1.0, 2.0] {
        let t = PreIntegrationTable::build(&tf, l).unwrap();
        let n = t.n;
        for i in 0..n {
            let s = i as f32 / (n - 1) as f32;
            let (_, tau) = tf.eval(s);
            let a = 1.0 - (-(tau as f64) * l as f64).exp();
            assert!((t.rgba[i * n + i][3] as f64 - a).abs() <= 1e-6, "diag {i}");
            for j in 0..n {
                let (x, y) = (t.rgba[i * n + j], t.rgba[j * n + i]);
                assert!((x[3] - y[3]).abs() <= 1e-6, "symmetry {i} {j}");
            }
        }
    }
    // tau(s) = k s: alpha = 1 - exp(-k l (s_f + s_b) / 2).
    let k = 3.0f32;
    let n = 256;
    let tau: Vec<f32> = (0..n).map(|i| k * i as f32 / (n - 1) as f32).collect();
    let rgb = vec![[0.8f32, 0.5, 0.2]; n];
    let lin = TransferFunction::from_extinction(&rgb, &tau).unwrap();
    let t = PreIntegrationTable::build(&lin, 1.5).unwrap();
    for (i, j) in [(0, 255), (10, 200), (255, 0), (128, 128), (37, 38)] {
        let (sf, sb) = (i as f64 / 255.0, j as f64 / 255.0);
        let want = 1.0 - (-(k as f64) * 1.5 * (sf + sb) / 2.0).exp();
        let e = t.rgba[i * n + j];
        assert!(
            (e[3] as f64 - want).abs() <= 1e-4,
            "({i},{j}): {} vs {want}",
            e[3]
        );
        // Constant colour: C = c alpha.
        assert!((e[0] as f64 - 0.8 * want).abs() <= 1e-4);
    }
    // A step transfer function against brute force with 4096 sub-steps.
    let step = TransferFunction::from_points(
        &[
            (0.0, [0.2, 0.4, 1.0, 0.0]),
            (0.5, [0.2, 0.4, 1.0, 0.0]),
            (0.5, [1.0, 0.5, 0.2, 0.9]),
            (1.0, [1.0, 0.5, 0.2, 0.9]),
        ],
        256,
    )
    .unwrap();
    let t = PreIntegrationTable::build(&step, 1.0).unwrap();
    let mut worst = 0f32;
    for i in (0..256).step_by(5) {
        for j in (0..256).step_by(7) {
            let bf = integrate_segment(&step, i as f32 / 255.0, j as f32 / 255.0, 1.0, 4096);
            let e = t.rgba[i * 256 + j];
            for c in 0..4 {
                worst = worst.max((bf[c] - e[c]).abs());
            }
        }
    }
    assert!(worst <= 1e-3, "step TF: worst {worst}");
    // The table's shared fine grid gives what direct midpoint integration with the same
    // K = max(24, 6 |b - f|) sub-steps gives, in both directions.
    for tf in [&step, &marschner_lobb_tf()] {
        let t = PreIntegrationTable::build(tf, 0.7).unwrap();
        for i in (0..256usize).step_by(3) {
            for j in (0..256usize).step_by(5) {
                let k = (6 * i.abs_diff(j)).max(24);
                let direct = integrate_segment(tf, i as f32 / 255.0, j as f32 / 255.0, 0.7, k);
                let e = t.rgba[i * 256 + j];
                for c in 0..4 {
                    assert!(
                        (direct[c] - e[c]).abs() <= 2e-5,
                        "({i},{j}) channel {c}: {} vs {}",
                        e[c],
                        direct[c]
                    );
                }
            }
        }
    }
}

/// Pre-integration integrates the segment between two samples: with the light switched off
/// (ambient 1) PI-ICS at a coarse slice distance is far closer to a finely stepped
/// emission-absorption ray caster than post-classified ICS at the same distance; with a
/// transfer function constant in `s` both equal the fine reference.
#[test]
fn preintegration_tracks_the_fine_integral() {
    // Concentric shells, transparent near the box faces so that only the interior matters.
    let n = 41;
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = |t: usize| -1.0 + 2.0 * t as f64 / (n - 1) as f64;
                let r = (c(i).powi(2) + c(j).powi(2) + c(k).powi(2)).sqrt();
                let v = 0.5
                    * (1.0 + (6.0 * std::f64::consts::PI * r).cos())
                    * (-(r / 0.6).powi(2)).exp();
                data.push(v as f32);
            }
        }
    }
    let field = ScalarField::from_f32(Volume::new([n; 3], [1.0; 3], data).unwrap()).unwrap();
    let tf = marschner_lobb_tf();
    let cam = SliceCamera::fit(&field, [0.4, -0.7, 1.0], [0.0, 1.0, 0.0], 96, 96).unwrap();
    let unlit = Light {
        ambient: 1.0,
        ..Light::default()
    };
    let s = IlluminationParams::default();
    let img = |m: Method| render(&field, &tf, &cam, &unlit, &m, &s).unwrap().image;
    let fine = img(Method::RaycastEa { step: 0.05 });
    for ds in [0.5f32, 1.0] {
        let e_pi = mean_abs_diff(&img(Method::pi_scs(ds, 0)), &fine).unwrap();
        let e_ics = mean_abs_diff(&img(Method::ics(ds)), &fine).unwrap();
        eprintln!("ds {ds}: PI {e_pi} vs ICS {e_ics}");
        assert!(e_pi < e_ics / 3.0, "ds {ds}: PI {e_pi} vs ICS {e_ics}");
    }
    let flat = constant_tf([0.9, 0.5, 0.3], 0.08);
    for (ds, m) in [(0.5f32, 0u32), (1.0, 2)] {
        let a = render(&field, &flat, &cam, &unlit, &Method::scs(ds, m), &s).unwrap();
        let b = render(&field, &flat, &cam, &unlit, &Method::pi_scs(ds, m), &s).unwrap();
        let mad = mean_abs_diff(&a.image, &b.image).unwrap();
        assert!(mad < 2e-5, "ds {ds} m {m}: {mad}");
    }
}

/// SCS on a homogeneous slab with a delta kernel: every sub-sample composited with
/// opacity alpha_delta and light interpolated linearly between the two slices (E5, E6).
#[test]
fn scs_interpolates_light_between_slices() {
    let field = constant([32, 32, 24], 1.0).unwrap();
    let a = 0.08f32;
    let tf = constant_tf([1.0; 3], a);
    let cam = along_z(&field, 32, 32);
    let light = Light {
        dir_view: [0.0, 0.0, 1.0],
        ambient: 0.2,
        kernel: Kernel::Delta,
    };
    for (ds, m) in [(1.0f64, 1usize), (2.0, 3), (1.5, 2)] {
        let r = render(
            &field,
            &tf,
            &cam,
            &light,
            &Method::scs(ds as f32, m as u32),
            &IlluminationParams::default(),
        )
        .unwrap();
        // Scalar model of the same sums (the transfer function is constant, so samples
        // outside the box count too).
        let n = (24.0 / ds).ceil() as usize;
        let tau = -(1.0 - a as f64).ln();
        let ad = 1.0 - (-tau * ds / (m as f64 + 1.0)).exp();
        let model = |interpolate: bool| {
            let (mut c, mut acc, mut l) = (0f64, 0f64, 1f64);
            for _ in 0..n {
                let l_next = l * (1.0 - ad).powi(m as i32 + 1);
                for j in 0..=m {
                    let w = if interpolate {
                        j as f64 / (m as f64 + 1.0)
                    } else {
                        0.0
                    };
                    let lj = (1.0 - w) * l + w * l_next;
                    c += (1.0 - acc) * ad * (0.2 + 0.8 * lj);
                    acc += (1.0 - acc) * ad;
                }
                l = l_next;
            }
            c
        };
        let (want, fake) = (model(true), model(false));
        let got = r.image.at(16, 16, 0) as f64;
        assert!((got - want).abs() < 2e-5, "ds {ds} m {m}: {got} vs {want}");
        // Lighting every sub-sample with L_n (the easy fake) gives a resolvably different value.
        assert!(
            (fake - want).abs() > 1e-3,
            "ds {ds} m {m}: fake {fake} vs {want}"
        );
    }
}

fn ml_scene() -> (ScalarField, TransferFunction, SliceCamera, Light) {
    let field = marschner_lobb(41).unwrap();
    let tf = marschner_lobb_tf();
    let cam = SliceCamera::fit(&field, [0.4, -0.7, 1.0], [0.0, 1.0, 0.0], 96, 96).unwrap();
    (field, tf, cam, headlight(Kernel::Gaussian { spread: 0.5 }))
}

/// Check 5 on Marschner-Lobb: the shape of Table 1.
#[test]
fn table1_shape_on_marschner_lobb() {
    let (field, tf, cam, light) = ml_scene();
    let s = IlluminationParams::default();
    let reference = render(&field, &tf, &cam, &light, &Method::ics(0.2), &s)
        .unwrap()
        .image;
    let mad = |m: Method| {
        mean_abs_diff(
            &render(&field, &tf, &cam, &light, &m, &s).unwrap().image,
            &reference,
        )
        .unwrap()
    };
    let m0: Vec<f64> = [0.4f32, 0.6, 0.8]
        .iter()
        .map(|&d| mad(Method::ics(d)))
        .collect();
    assert!(
        m0[0] < m0[1] && m0[1] < m0[2],
        "MAD(m=0) over 0.4, 0.6, 0.8: {m0:?}"
    );
    let m3 = mad(Method::scs(0.8, 3));
    assert!(
        m3 <= 0.6 * m0[2],
        "MAD(0.8, m=3) {m3} vs MAD(0.8, m=0) {}",
        m0[2]
    );
    for (d, m) in [(0.4f32, 1u32), (0.6, 2), (0.8, 3)] {
        let v = mad(Method::scs(d, m));
        assert!(v <= 0.01, "diagonal ({d}, {m}): {v}");
    }
    eprintln!("ML Table 1: m=0 {m0:?}, (0.8, 3) {m3}");
}

/// Check 8: invariants.
#[test]
fn invariants() {
    let field = marschner_lobb(41).unwrap();
    let clear = TransferFunction::from_points(&[(0.0, [1.0, 0.0, 0.0, 0.0])], 16).unwrap();
    let cam = SliceCamera::fit(&field, [0.0, 0.3, 1.0], [0.0, 1.0, 0.0], 48, 40).unwrap();
    let light = headlight(Kernel::default());
    let s = IlluminationParams::default().background([0.1, 0.2, 0.3]);
    for m in [
        Method::ics(0.7),
        Method::scs(1.0, 2),
        Method::pi_scs(1.0, 1),
        Method::RaycastEa { step: 0.5 },
    ] {
        let r = render(&field, &clear, &cam, &light, &m, &s).unwrap();
        for px in r.image.data().chunks(4) {
            assert_eq!(px, &[0.1, 0.2, 0.3, 0.0]);
        }
    }
    let (buf, _) =
        light_buffer_at(&field, &clear, &cam, &light, &Method::ics(0.5), &s, 30.0).unwrap();
    assert!(buf.data().iter().all(|&v| (v - 1.0).abs() < 1e-6));
    let tf = marschner_lobb_tf();
    for depth in [20.0, 40.0, 60.0] {
        let (buf, _) =
            light_buffer_at(&field, &tf, &cam, &light, &Method::scs(0.8, 2), &s, depth).unwrap();
        assert!(buf
            .data()
            .iter()
            .all(|&v| (-1e-6..=1.0 + 1e-6).contains(&v)));
        assert!(
            buf.data().iter().any(|&v| v < 0.9),
            "depth {depth}: no shadow"
        );
    }
    for k in [
        Kernel::Delta,
        Kernel::Gaussian { spread: 0.5 },
        Kernel::Gaussian { spread: 3.0 },
        Kernel::Disk { tan_half: 1.5 },
    ] {
        for ds in [0.1, 0.5, 2.0] {
            for shift in [[0.0, 0.0], [0.3, -0.7], [1.6, 2.4]] {
                let sk = StepKernel::new(&k, ds, 1.0, shift);
                assert!((sk.weight_sum() - 1.0).abs() < 1e-5, "{k:?}");
            }
        }
    }
    // Only 2-D buffers: at most 64 floats per pixel of the image.
    let r = render(&field, &tf, &cam, &light, &Method::pi_scs(0.5, 3), &s).unwrap();
    assert!(
        r.buffer_floats > 0 && r.buffer_floats <= 64 * 48 * 40,
        "{}",
        r.buffer_floats
    );
}

/// The discrete Gaussian has the exact variance and mean asked for.
#[test]
fn kernel_variance_is_exact() {
    for var in [0.0, 0.05, 0.2, 0.5, 0.51, 1.0, 2.0, 7.3] {
        for mean in [0.0, 0.25, -0.4, 1.3] {
            let t = discrete_gaussian(var, mean);
            let sum: f64 = t.w.iter().map(|&w| w as f64).sum();
            assert!((sum - 1.0).abs() < 1e-6);
            assert!(t.w.iter().all(|&w| w >= 0.0));
            let (m, v) = t.moments();
            let f = mean - mean.round();
            let want = var.max(f.abs() * (1.0 - f.abs()));
            assert!(
                (m - mean).abs() < 1e-4,
                "var {var} mean {mean}: got mean {m}"
            );
            assert!(
                (v - want).abs() < 1e-4 * want.max(1.0),
                "var {var} mean {mean}: got {v}"
            );
        }
    }
}

/// Baseline 2: on a linear ramp every sample has the same gradient, so behind an iso-surface
/// inside the volume a pixel is `alpha (c (k_a + k_d |n.l|) + k_s |n.h|^n)` exactly, with `n`
/// the ramp's direction; checked for a headlight (`l = h`) and an oblique light, with
/// trilinear and nearest sampling and an anisotropic spacing (the gradient is per world unit).
#[test]
fn phong_shades_a_ramp_by_its_analytic_normal() {
    let dims = [24usize, 26, 20];
    let spacing = [1.0, 1.0, 1.25];
    let axis = [-0.8f64, 0.35, -0.45];
    let norm = axis.iter().map(|v| v * v).sum::<f64>().sqrt();
    let a = axis.map(|v| v / norm);
    let ctr: [f64; 3] = std::array::from_fn(|k| 0.5 * (dims[k] as f64 - 1.0) * spacing[k]);
    let data: Vec<f32> = (0..dims.iter().product::<usize>())
        .map(|i| {
            let p = [
                i % dims[0],
                (i / dims[0]) % dims[1],
                i / (dims[0] * dims[1]),
            ];
            let d: f64 = (0..3)
                .map(|k| a[k] * (p[k] as f64 * spacing[k] - ctr[k]))
                .sum();
            (0.5 + 0.02 * d) as f32
        })
        .collect();
    let field = ScalarField::from_f32(Volume::new(dims, spacing, data).unwrap()).unwrap();
    // Transparent below the iso-value 0.5 (and outside the box), white and opaque above it:
    // the view rays enter through the transparent side (the ramp rises along the view).
    let lut: Vec<[f32; 4]> = (0..256)
        .map(|i| [1.0, 1.0, 1.0, if i >= 128 { 0.95 } else { 0.0 }])
        .collect();
    let tf = TransferFunction::from_lut(&lut).unwrap();
    let cam = SliceCamera::orbit(&field, 35.0, 20.0, 64).unwrap();
    let frame = cam.frame().unwrap();
    assert!((0..3).map(|k| a[k] * frame.d[k]).sum::<f64>() > 0.3);
    let ph = Phong::default();
    for light_dir in [[0.0, 0.0, 1.0], [0.4, 0.3, 1.0]] {
        let light = Light {
            dir_view: light_dir,
            ..headlight(Kernel::Delta)
        };
        let l = frame.light_world(light.unit_dir().unwrap());
        let h: [f64; 3] = std::array::from_fn(|k| l[k] - frame.d[k]);
        let hn = h.iter().map(|v| v * v).sum::<f64>().sqrt();
        let dot = |v: [f64; 3], s: f64| ((0..3).map(|k| a[k] * v[k]).sum::<f64>() / s).abs();
        let (nl, nh) = (dot(l, 1.0), dot(h, hn));
        let shade = ph.ka as f64 + ph.kd as f64 * nl + ph.ks as f64 * nh.powf(ph.shininess as f64);
        for interp in [Interp::Trilinear, Interp::Nearest] {
            let s = IlluminationParams::default().interp(interp);
            let m = Method::RaycastPhong {
                step: 0.5,
                phong: ph,
            };
            let img = render(&field, &tf, &cam, &light, &m, &s).unwrap().image;
            for y in 29..35 {
                for x in 29..35 {
                    let px = &img.data()[4 * (y * 64 + x)..4 * (y * 64 + x) + 4];
                    assert!(px[3] > 0.99, "alpha {} at ({x}, {y})", px[3]);
                    for c in 0..3 {
                        let want = px[3] as f64 * shade;
                        assert!(
                            (px[c] as f64 - want).abs() < 2e-4,
                            "{interp:?} light {light_dir:?} ({x}, {y}): {} vs {want}",
                            px[c]
                        );
                    }
                }
            }
        }
    }
}

/// Check 9: the same image with 1 and 2 threads.
#[test]
fn deterministic_across_thread_counts() {
    let (field, tf, cam, light) = ml_scene();
    let run = |threads: usize, m: Method| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                render(
                    &field,
                    &tf,
                    &cam,
                    &light,
                    &m,
                    &IlluminationParams::default(),
                )
                .unwrap()
            })
    };
    for m in [
        Method::scs(0.8, 2),
        Method::pi_scs(1.0, 1),
        Method::RaycastPhong {
            step: 0.5,
            phong: Phong::default(),
        },
    ] {
        assert_eq!(
            run(1, m).image.data(),
            run(2, m).image.data(),
            "{}",
            m.name()
        );
    }
}

/// Bad input is an error naming the problem, never a panic.
#[test]
fn bad_input_is_rejected() {
    let dims = [4, 4, 4];
    assert!(VolumeView::new(dims, [1.0; 3], &[0u8; 63]).is_err());
    assert!(VolumeView::<u8>::new([0, 4, 4], [1.0; 3], &[]).is_err());
    assert!(VolumeView::new(dims, [1.0, 0.0, 1.0], &[0u8; 64]).is_err());
    assert!(VolumeView::new(dims, [1.0, f64::NAN, 1.0], &[0u8; 64]).is_err());
    let mut nan = vec![0.5f32; 64];
    nan[7] = f32::NAN;
    assert!(ScalarField::from_f32(Volume::new(dims, [1.0; 3], nan.clone()).unwrap()).is_err());
    let nan_view = VolumeView::new(dims, [1.0; 3], &nan).unwrap();
    assert!(ScalarField::from_f32_range(nan_view, 0.0, 1.0).is_err());
    let zeros = VolumeView::new(dims, [1.0; 3], &[0.0f32; 64]).unwrap();
    assert!(ScalarField::from_f32_range(zeros, 1.0, 1.0).is_err());
    assert!(TransferFunction::from_lut(&[[0.0, 0.0, 0.0, 0.5]]).is_err());
    assert!(TransferFunction::from_lut(&[[0.0; 4], [0.0, 0.0, 0.0, 1.5]]).is_err());
    assert!(TransferFunction::from_lut(&[[0.0; 4], [0.0, 0.0, f32::NAN, 1.0]]).is_err());
    let field =
        ScalarField::from_u8(VolumeView::new(dims, [1.0; 3], &[100u8; 64]).unwrap()).unwrap();
    let tf = marschner_lobb_tf();
    let cam = SliceCamera::fit(&field, [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], 8, 8).unwrap();
    let light = Light::default();
    let s = IlluminationParams::default();
    let bad = |c: &SliceCamera, l: &Light, m: Method| {
        render(&field, &tf, c, l, &m, &s).unwrap_err().to_string()
    };
    assert!(bad(&cam, &light, Method::ics(0.0)).contains("slice_distance"));
    assert!(bad(&cam, &light, Method::ics(f32::NAN)).contains("slice_distance"));
    assert!(bad(&cam, &light, Method::scs(1.0, 65)).contains("subsamples"));
    assert!(bad(&cam, &light, Method::RaycastEa { step: -1.0 }).contains("step"));
    assert!(bad(&SliceCamera { width: 0, ..cam }, &light, Method::ics(1.0)).contains("size"));
    assert!(bad(
        &SliceCamera {
            pixel_size: 0.0,
            ..cam
        },
        &light,
        Method::ics(1.0)
    )
    .contains("pixel_size"));
    assert!(bad(
        &SliceCamera {
            up: [0.0, 0.0, 2.0],
            ..cam
        },
        &light,
        Method::ics(1.0)
    )
    .contains("up"));
    let neg = Light {
        kernel: Kernel::Gaussian { spread: -1.0 },
        ..light
    };
    assert!(bad(&cam, &neg, Method::ics(1.0)).contains("kernel"));
    let behind = Light {
        dir_view: [0.0, 0.5, -1.0],
        ..light
    };
    assert!(bad(&cam, &behind, Method::ics(1.0)).contains("light_dir"));
    assert!(light_buffer_at(
        &field,
        &tf,
        &cam,
        &light,
        &Method::RaycastEa { step: 1.0 },
        &s,
        1.0
    )
    .is_err());
    assert!(light_buffer_at(&field, &tf, &cam, &light, &Method::ics(1.0), &s, f64::NAN).is_err());
    assert!(PreIntegrationTable::build(&tf, 0.0).is_err());
}

/// Renders that could not finish are refused up front.
#[test]
fn unbounded_work_is_refused() {
    let field = marschner_lobb(9).unwrap();
    let tf = marschner_lobb_tf();
    let cam = SliceCamera::fit(&field, [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], 8, 8).unwrap();
    let s = IlluminationParams::default();
    let light = Light::default();
    let err = |l: &Light, m: Method| {
        render(&field, &tf, &cam, l, &m, &s)
            .unwrap_err()
            .to_string()
    };
    assert!(err(&light, Method::ics(1e-6)).contains("slice_distance"));
    assert!(err(&light, Method::RaycastEa { step: 1e-6 }).contains("step"));
    let wide = Light {
        kernel: Kernel::Gaussian { spread: 1e30 },
        ..light
    };
    assert!(err(&wide, Method::ics(1.0)).contains("kernel"));
    let cone = Light {
        kernel: Kernel::Disk { tan_half: 1e6 },
        ..light
    };
    assert!(err(&cone, Method::ics(1.0)).contains("kernel"));
}

/// Without light (ambient 1) ICS composites exactly the samples of an emission-absorption ray
/// caster with the same step: on a sparse volume (two blobs in empty space, so both skip
/// empty cells and the ray caster clips its rays to the box) the images agree.
#[test]
fn unlit_ics_equals_ray_casting_with_empty_space_skipping() {
    let blobs = [([20.0, 30.0, 25.0], 9.0), ([50.0, 44.0, 48.0], 12.0)];
    let field = scenes::blobs([72; 3], [1.0; 3], &blobs).unwrap();
    let tf = scenes::blobs_tf();
    let unlit = Light {
        ambient: 1.0,
        ..Light::default()
    };
    let s = IlluminationParams::default();
    for dir in [[0.3, -0.5, 1.0], [-1.0, 0.2, -0.4]] {
        let cam = SliceCamera::fit(&field, dir, [0.0, 0.0, 1.0], 64, 64).unwrap();
        for step in [0.5f32, 1.3] {
            let a = render(&field, &tf, &cam, &unlit, &Method::ics(step), &s).unwrap();
            let b = render(&field, &tf, &cam, &unlit, &Method::RaycastEa { step }, &s).unwrap();
            let mad = mean_abs_diff(&a.image, &b.image).unwrap();
            assert!(mad < 1e-6, "{dir:?} step {step}: {mad}");
            assert!(a.image.data().iter().any(|&v| v > 0.1));
            // With the light: one blob shadows the other; the delta kernel equals shadow rays
            // (the light buffer is only updated where the slices meet the volume).
            let hard = Light {
                kernel: Kernel::Delta,
                ..Light::default()
            };
            let a = render(&field, &tf, &cam, &hard, &Method::ics(step), &s).unwrap();
            let b = render(&field, &tf, &cam, &hard, &Method::ShadowRays { step }, &s).unwrap();
            let mad = mean_abs_diff(&a.image, &b.image).unwrap();
            assert!(mad < 1e-5, "{dir:?} step {step}: shadows {mad}");
        }
    }
}
