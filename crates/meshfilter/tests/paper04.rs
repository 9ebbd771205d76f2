//! Acceptance checks of paper 04 (joint bilateral mesh denoising) on synthetic meshes with
//! exact ground truth, with the paper's update (`normal_iterations = 0`) where they check
//! the paper's claims.

use wscg_math::TriMesh;
use wscg_meshfilter::metrics::{
    corresponding_error, mean_error, mean_vertex_distance, surface_error,
};
use wscg_meshfilter::synth::{add_noise, colored_cube, colored_plane, icosphere, NOISE_SEED};
use wscg_meshfilter::{jbmd, jbmd_trace, JbmdParams};

fn radii(p: &[[f64; 3]]) -> (f64, f64) {
    let r: Vec<f64> = p
        .iter()
        .map(|q| (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt())
        .collect();
    let m = r.iter().sum::<f64>() / r.len() as f64;
    let s = (r.iter().map(|x| (x - m).powi(2)).sum::<f64>() / r.len() as f64).sqrt();
    (m, s)
}

#[test]
fn clean_plane_is_unchanged() {
    // Check 1: a noise-free open plane with a frozen boundary stays put.
    let m = colored_plane(20).unwrap();
    let mvd = mean_vertex_distance(&m).unwrap();
    let out = jbmd(&m, &JbmdParams::from_mvd(mvd)).unwrap();
    let d = corresponding_error(&out, &m.positions, None).unwrap();
    assert!(d < 1e-12, "{d}");
}

#[test]
fn sphere_keeps_its_radius_with_anti_shrinking() {
    // Checks 3 (second part) and 6 on S3.
    let s = icosphere(4).unwrap();
    let mvd = mean_vertex_distance(&s).unwrap();
    let noisy = add_noise(&s, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let (_, noisy_std) = radii(&noisy.positions);
    let p = JbmdParams::from_mvd(mvd)
        .k(40)
        .iterations(15)
        .normal_iterations(0);
    let (mean, std) = radii(&jbmd(&noisy, &p).unwrap());
    let no_as = p.anti_shrink(false);
    let (mean_shrunk, _) = radii(&jbmd(&noisy, &no_as).unwrap());
    println!(
        "sphere: radius {mean:.4} +- {std:.4} (noisy +- {noisy_std:.4}); without anti-shrinking \
         {mean_shrunk:.4}"
    );
    assert!((0.995..=1.005).contains(&mean), "{mean}");
    assert!(std <= 0.3 * noisy_std, "{std} vs {noisy_std}");
    assert!(mean_shrunk < 0.97, "{mean_shrunk}");
}

#[test]
fn cube_converges_below_the_noise() {
    // Check 2 on S1 (n = 30, noise 0.5 MVD along the normals, k = 40, 15 iterations).
    let cube = colored_cube(30).unwrap();
    assert_eq!((cube.num_vertices(), cube.num_faces()), (5402, 10800));
    let mvd = mean_vertex_distance(&cube).unwrap();
    let noisy = add_noise(&cube, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let p = JbmdParams::from_mvd(mvd)
        .k(40)
        .iterations(15)
        .normal_iterations(0);
    let mut me = Vec::new();
    jbmd_trace(&noisy, &p, |_, x, _| {
        me.push(mean_error(x, &cube.positions).unwrap() / mvd)
    })
    .unwrap();
    let noisy_me = mean_error(&noisy.positions, &cube.positions).unwrap() / mvd;
    println!("noisy ME {noisy_me:.3} MVD; JBMD ME by iteration {me:.3?}");
    assert!(me[14] <= 0.17, "{}", me[14]);
    for w in me[2..].windows(2) {
        assert!(w[1] <= w[0] * 1.01, "ME rose: {w:?}");
    }
}

#[test]
fn mean_error_matches_brute_force_and_scale_invariance() {
    // Check 8.
    let a = wscg_math::rng::uniform_vec(1, 3 * 2000, -1.0, 1.0).unwrap();
    let b = wscg_math::rng::uniform_vec(2, 3 * 2000, -1.0, 1.0).unwrap();
    let x: Vec<[f64; 3]> = a.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    let g: Vec<[f64; 3]> = b.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    let brute = x
        .iter()
        .map(|p| {
            g.iter()
                .map(|q| {
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
                })
                .fold(f64::INFINITY, f64::min)
        })
        .sum::<f64>()
        / x.len() as f64;
    assert!((mean_error(&x, &g).unwrap() - brute).abs() < 1e-12);
    // Check 9: scaling the mesh and the ranges by 1000 scales the output.
    let s = icosphere(3).unwrap();
    let mvd = mean_vertex_distance(&s).unwrap();
    let noisy = add_noise(&s, 0.5 * mvd, false, 5).unwrap();
    let mut big = noisy.clone();
    big.positions
        .iter_mut()
        .for_each(|p| *p = p.map(|c| 1000.0 * c));
    let p = JbmdParams::from_mvd(mvd);
    let pb = p.sigma_d(1000.0 * p.sigma_d).sigma_o(1000.0 * p.sigma_o);
    let small = jbmd(&noisy, &p).unwrap();
    let large = jbmd(&big, &pb).unwrap();
    for (a, b) in small.iter().zip(&large) {
        for k in 0..3 {
            assert!(
                (1000.0 * a[k] - b[k]).abs() <= 1e-9 * 1000.0,
                "{a:?} vs {b:?}"
            );
        }
    }
}

#[test]
fn surface_error_is_the_distance_to_the_cube() {
    // Point-to-surface metric: the exact distance to the boundary of [0, 1]^3, for points
    // outside (distance to the box) and inside (distance to the nearest face), far from the
    // cube's vertices so that the nearest-vertex metric differs.
    let cube = colored_cube(7).unwrap();
    let a = wscg_math::rng::uniform_vec(3, 3 * 3000, -0.5, 1.5).unwrap();
    let x: Vec<[f64; 3]> = a.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    let exact = x
        .iter()
        .map(|p| {
            let out = p.map(|c| (-c).max(c - 1.0).max(0.0));
            let d = (out[0] * out[0] + out[1] * out[1] + out[2] * out[2]).sqrt();
            if d > 0.0 {
                d
            } else {
                p.iter()
                    .map(|&c| c.min(1.0 - c))
                    .fold(f64::INFINITY, f64::min)
            }
        })
        .sum::<f64>()
        / x.len() as f64;
    let got = surface_error(&x, &cube).unwrap();
    assert!((got - exact).abs() < 1e-6, "{got} vs {exact}");
    // The surface contains the vertices: the nearest-vertex error can only be larger.
    let nearest_vertex = mean_error(&x, &cube.positions).unwrap();
    assert!(nearest_vertex > got, "{nearest_vertex} vs {got}");
    // Tangential drift on a face is free for the surface metric.
    let slid: Vec<[f64; 3]> = cube
        .positions
        .iter()
        .map(|p| {
            if p[2] >= 1.0 && p[0] > 0.1 && p[0] < 0.9 {
                [p[0] + 0.05, p[1], p[2]]
            } else {
                *p
            }
        })
        .collect();
    assert!(surface_error(&slid, &cube).unwrap() < 1e-7);
    assert!(surface_error(&[], &cube).is_err());
    assert!(surface_error(&[[f64::NAN, 0.0, 0.0]], &cube).is_err());
}

#[test]
fn bad_input_is_rejected() {
    let m = icosphere(1).unwrap();
    let p = JbmdParams::from_mvd(0.1);
    assert!(jbmd(&TriMesh::new(vec![], vec![]).unwrap(), &p).is_err());
    let mut nan = m.clone();
    nan.positions[3][1] = f64::NAN;
    assert!(jbmd(&nan, &p).is_err());
    for bad in [
        p.sigma_d(0.0),
        p.sigma_o(-1.0),
        p.sigma_c(f64::NAN),
        p.lambda(0.0),
        p.lambda(1.5),
        p.k(0),
        p.k(m.num_vertices()),
    ] {
        assert!(jbmd(&m, &bad).is_err(), "{bad:?}");
    }
    assert!(colored_cube(0).is_err());
    assert!(add_noise(&m, -1.0, false, 1).is_err());
}

#[test]
fn sphere_beats_the_best_laplacian() {
    // Check 5 on S3: JBMD ME(15) <= the best Laplacian ME over lambda and iterations.
    let s = icosphere(4).unwrap();
    let mvd = mean_vertex_distance(&s).unwrap();
    let noisy = add_noise(&s, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let p = JbmdParams::from_mvd(mvd)
        .k(40)
        .iterations(15)
        .normal_iterations(0);
    let ours = mean_error(&jbmd(&noisy, &p).unwrap(), &s.positions).unwrap() / mvd;
    let best = wscg_meshfilter::sweep::sweep(
        &noisy,
        &wscg_meshfilter::sweep::Setting::laplacian_grid(),
        15,
        |x| mean_error(x, &s.positions).unwrap() / mvd,
    )
    .unwrap()
    .unwrap()
    .error;
    println!("sphere: JBMD ME {ours:.3} MVD, best Laplacian {best:.3}");
    assert!(ours <= best, "{ours} vs {best}");
}

#[test]
fn sweep_returns_the_lowest_error_over_settings_and_iterations() {
    use wscg_meshfilter::smoothing::laplacian;
    use wscg_meshfilter::sweep::{sweep, Setting};
    let s = icosphere(2).unwrap();
    let noisy = add_noise(&s, 0.02, false, 9).unwrap();
    let err = |x: &[[f64; 3]]| mean_error(x, &s.positions).unwrap();
    let grid = Setting::laplacian_grid();
    let best = sweep(&noisy, &grid, 6, err).unwrap().unwrap();
    // Brute force over the same grid and iterations, by independent calls.
    let mut brute = (f64::INFINITY, 0.0, 0);
    for g in &grid {
        let Setting::Laplacian { lambda } = *g else {
            unreachable!()
        };
        for it in 1..=6 {
            let e = err(&laplacian(&noisy, lambda, it).unwrap());
            if e < brute.0 {
                brute = (e, lambda, it);
            }
        }
    }
    assert_eq!(best.setting, Setting::Laplacian { lambda: brute.1 });
    assert_eq!(best.iteration, brute.2);
    assert!((best.error - brute.0).abs() < 1e-15);
    assert_eq!(best.curve.len(), 6);
    assert_eq!(best.positions, laplacian(&noisy, brute.1, brute.2).unwrap());
}

#[test]
fn table1_presets() {
    // The paper's Table 1: sigma_d, sigma_o, sigma_c, lambda per mesh.
    for (name, want) in [
        ("fandisk", [0.1, 0.05, 30.0, 0.8]),
        ("lion", [1.0, 0.5, 30.0, 0.6]),
        ("allegorie", [0.0008, 0.0004, 35.0, 0.7]),
        ("person1", [0.01, 0.005, 20.0, 0.7]),
        ("person2", [0.01, 0.005, 20.0, 0.7]),
    ] {
        let p = JbmdParams::preset(name).unwrap();
        assert_eq!([p.sigma_d, p.sigma_o, p.sigma_c, p.lambda], want, "{name}");
        assert!(p.anti_shrink && p.use_color);
    }
    assert!(JbmdParams::preset("bunny").is_none());
}

#[test]
fn cad_part_lies_on_its_analytic_surface() {
    use wscg_meshfilter::synth::{cad_part, FILLET_CENTER, FILLET_PATCH, FILLET_RADIUS};
    let s2 = cad_part(20).unwrap();
    let m = &s2.mesh;
    assert_eq!(m.num_vertices(), 4116);
    // Every vertex on its patch: the fillet on its circle, the others on their lines.
    // (axis, value) of the straight patches, in profile order.
    let lines = [(1, 0.0), (0, 3.0), (1, 1.0), (0, 1.5), (1, 2.0), (0, 0.0)];
    for (p, &patch) in m.positions.iter().zip(&s2.patch) {
        if patch == FILLET_PATCH {
            let r = (p[0] - FILLET_CENTER[0]).hypot(p[1] - FILLET_CENTER[1]);
            assert!((r - FILLET_RADIUS).abs() < 1e-12);
            assert!(p[0] <= FILLET_CENTER[0] + 1e-12 && p[1] >= FILLET_CENTER[1] - 1e-12);
        } else {
            let (axis, value) = lines[patch as usize - usize::from(patch > FILLET_PATCH)];
            assert!((p[axis] - value).abs() < 1e-12, "{p:?} patch {patch}");
        }
    }
    // Outward orientation: the bottom's normals point down, the fillet's away from its axis.
    let normals = m.vertex_normals();
    for ((p, n), &patch) in m.positions.iter().zip(&normals).zip(&s2.patch) {
        if patch == 0 && p[0] > 0.2 && p[0] < 2.8 {
            assert!(n[1] < -0.999, "{n:?}");
        }
        if patch == FILLET_PATCH {
            let out = [p[0] - FILLET_CENTER[0], p[1] - FILLET_CENTER[1]];
            assert!(out[0] * n[0] + out[1] * n[1] > 0.0);
        }
    }
    // Five creases (two sample rows each side, one on the corner) times 21 layers.
    assert_eq!(s2.crease_band.iter().filter(|&&b| b).count(), 5 * 3 * 21);
    assert!(cad_part(0).is_err());
}
