//! Paper 08 acceptance checks that need no procedural scene:
//! the analytic VPL term, the distributions' invariants, the weights' fallback, bad input.

use wscg_math::progress::NoProgress;
use wscg_math::vec3::{dist, norm, sub};
use wscg_raytrace::manylight::cache::{BOUNDED, FULL, UNOCCLUDED};
use wscg_raytrace::manylight::*;

/// A square plane of side `2 s` at height 0 facing +y, albedo `rho`, plus optional extra
/// triangles.
fn plane(s: f64, rho: f64, extra: &[([[f64; 3]; 3], [f64; 3])]) -> Scene {
    let mut v = vec![[-s, 0.0, -s], [s, 0.0, -s], [s, 0.0, s], [-s, 0.0, s]];
    let mut f = vec![[0u32, 2, 1], [0, 3, 2]];
    let mut a = vec![[rho; 3]; 2];
    for (tri, alb) in extra {
        let b = v.len() as u32;
        v.extend_from_slice(tri);
        f.push([b, b + 1, b + 2]);
        a.push(*alb);
    }
    let e = vec![[0.0; 3]; f.len()];
    Scene::from_triangles(&v, &f, &a, &e).unwrap()
}

fn top_camera(w: usize, h: usize) -> Camera {
    Camera {
        eye: [0.0, 6.0, 0.0],
        target: [0.0; 3],
        up: [0.0, 0.0, -1.0],
        fov_deg: 60.0,
        width: w,
        height: h,
    }
}

fn emitter_vpl(pos: [f64; 3], normal: [f64; 3], power: f64) -> Vpl {
    Vpl {
        pos,
        normal,
        power: [power; 3],
        kind: VplKind::Emitter,
    }
}

#[test]
fn check1_single_vpl_over_a_plane_is_analytic() {
    let scene = plane(10.0, 0.5, &[]);
    let g = trace_primary(&scene, &top_camera(48, 36)).unwrap();
    let h = 1.0;
    let vpls = [emitter_vpl(
        [0.3, h, -0.2],
        [0.0, -1.0, 0.0],
        std::f64::consts::PI,
    )];
    for dc in [0.0, 2.0] {
        let img = render_reference(&scene, &g, &vpls, Some(dc), &NoProgress).unwrap();
        let mut checked = 0;
        for (i, p) in g.points.iter().enumerate() {
            let Some(p) = p else { continue };
            let d = dist(vpls[0].pos, p.pos);
            // (rho / pi) (Phi / pi) cos_x cos_y / max(d, d_c)^2 with both cosines h / d.
            let want = 0.5 / std::f64::consts::PI * (h / d) * (h / d) / (d * d).max(dc * dc);
            for c in 0..3 {
                let got = img.data()[3 * i + c] as f64;
                assert!(
                    (got - want).abs() <= 1e-5 * want,
                    "d_c {dc}, pixel {i}: {got} vs {want}"
                );
            }
            checked += 1;
        }
        assert!(checked > 1000);
    }
}

#[test]
fn check6_distributions_invariants() {
    // A plane with a wall occluding part of the VPLs, VPLs above and below the plane.
    let wall = (
        [[0.0, 0.0, -3.0], [0.0, 0.0, 3.0], [0.0, 2.0, 0.0]],
        [0.5; 3],
    );
    let wall_back = (
        [[0.0, 0.0, 3.0], [0.0, 0.0, -3.0], [0.0, 2.0, 0.0]],
        [0.5; 3],
    );
    let scene = plane(10.0, 0.5, &[wall, wall_back]);
    let mut vpls = Vec::new();
    for k in 0..60 {
        let t = k as f64 / 60.0 * std::f64::consts::TAU;
        let y = if k % 7 == 0 {
            -0.5
        } else {
            0.5 + (k % 5) as f64 * 0.4
        };
        vpls.push(emitter_vpl(
            [3.0 * t.cos(), y, 3.0 * t.sin()],
            [0.0, -1.0, 0.0],
            1.0 + (k % 3) as f64,
        ));
    }
    let sh = Shading::new(&scene, &vpls, None).unwrap();
    let rec = Record {
        at: Receiver {
            pos: [1.0, 0.0, 0.2],
            normal: [0.0, 1.0, 0.0],
            albedo: [0.5; 3],
        },
        radius: 0.3,
        pixel: None,
        cluster: None,
        inserted: false,
    };
    let d = Distributions::compute(&sh, &rec);
    let (f, u, b) = (
        d.pmf[FULL].as_ref().unwrap(),
        d.pmf[UNOCCLUDED].as_ref().unwrap(),
        d.pmf[BOUNDED].as_ref().unwrap(),
    );
    for p in [f, u, b] {
        let s: f64 = p.pdfs().iter().map(|v| *v as f64).sum();
        assert!((s - 1.0).abs() < 1e-5, "sum {s}");
        assert!(p.cdf().windows(2).all(|w| w[0] <= w[1]));
        assert_eq!(*p.cdf().last().unwrap(), 1.0);
    }
    // Unnormalised: F <= U <= B element-wise; F = 0 behind the record or the wall.
    let mut occluded = 0;
    for (j, vpl) in vpls.iter().enumerate() {
        let un = luminance(&sh.unoccluded(&rec.at, j));
        let full = luminance(&sh.contribution(&rec.at, j));
        let bound = sh.bound(&rec.at, j, rec.radius);
        assert!(
            full <= un && un <= bound * (1.0 + 1e-12),
            "VPL {j}: {full} {un} {bound}"
        );
        if vpl.pos[1] < 0.0 {
            assert_eq!(f.pdf(j), 0.0);
            assert_eq!(u.pdf(j), 0.0);
        }
        if un > 0.0 && full == 0.0 {
            occluded += 1;
            assert_eq!(f.pdf(j), 0.0);
        }
    }
    assert!(occluded > 5, "the wall hides some VPLs: {occluded}");
}

#[test]
fn check5_fallback_for_an_isolated_record() {
    // Two records: one on the plane, one far away with a perpendicular normal. A shading
    // point next to the second gets no positive similarity weight (normals 90 degrees apart)
    // and falls back to the uniform choice, which keeps records facing its side.
    let scene = plane(10.0, 0.5, &[]);
    let vpls = [emitter_vpl([0.0, 1.0, 0.0], [0.0, -1.0, 0.0], 1.0)];
    let sh = Shading::new(&scene, &vpls, None).unwrap();
    let mk = |pos: [f64; 3], normal: [f64; 3]| Record {
        at: Receiver {
            pos,
            normal,
            albedo: [0.5; 3],
        },
        radius: 0.1,
        pixel: None,
        cluster: None,
        inserted: false,
    };
    // Six records 0.2 apart on the plane (so d_max is about 0.8), one far away standing
    // perpendicular to it.
    let mut recs: Vec<Record> = (0..6)
        .map(|k| mk([0.2 * k as f64, 0.0, 0.0], [0.0, 1.0, 0.0]))
        .collect();
    recs.push(mk([5.0, 0.5, 0.0], [1.0, 0.0, 0.0]));
    let cache = ImportanceCache::build(&sh, recs, Interp::default(), 3).unwrap();
    assert!(cache.d_max < 1.0, "d_max {}", cache.d_max);
    let found = cache.lookup([5.0, 0.0, 0.0], [0.0, 1.0, 0.0], None);
    let total: f64 = found.iter().map(|e| e.1).sum();
    assert!((total - 1.0).abs() < 1e-12);
    // The fallback: the three nearest records facing +y, uniformly.
    let mut ks: Vec<usize> = found.iter().map(|e| e.0).collect();
    ks.sort_unstable();
    assert_eq!(ks, vec![3, 4, 5]);
    assert!(found.iter().all(|&(_, w)| (w - 1.0 / 3.0).abs() < 1e-12));
    // Among the plane's records the similarity weights apply: the nearest weighs most.
    let near = cache.lookup([0.45, 0.0, 0.0], [0.0, 1.0, 0.0], None);
    let total: f64 = near.iter().map(|e| e.1).sum();
    assert!((total - 1.0).abs() < 1e-12 && near.len() == 3);
    let w_of = |k: usize| near.iter().find(|e| e.0 == k).map_or(0.0, |e| e.1);
    assert!(w_of(2) > w_of(1) && w_of(2) > w_of(3) && w_of(3) > 0.0);
}

#[test]
fn bad_input_is_an_error() {
    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let f = [[0u32, 1, 2]];
    let a = [[0.5; 3]];
    let e = [[0.0; 3]];
    assert!(Scene::from_triangles(&v, &[], &[], &[]).is_err());
    assert!(Scene::from_triangles(&v, &[[0, 1, 5]], &a, &e).is_err());
    let nan = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert!(Scene::from_triangles(&nan, &f, &a, &e).is_err());
    assert!(Scene::from_triangles(&v, &f, &[[-0.1, 0.5, 0.5]], &e).is_err());
    assert!(Scene::from_triangles(&v, &f, &a, &[[-1.0, 0.0, 0.0]]).is_err());
    assert!(Scene::from_triangles(&v, &f, &a, &[]).is_err());
    // Degenerate triangles are skipped and counted.
    let vd = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [2.0, 0.0, 0.0],
    ];
    let s = Scene::from_triangles(&vd, &[[0, 1, 2], [0, 1, 3]], &[[0.5; 3]; 2], &[[0.0; 3]; 2])
        .unwrap();
    assert_eq!((s.len(), s.skipped_degenerate), (1, 1));
    // No emitter.
    let scene = plane(10.0, 0.5, &[]);
    assert!(generate_vpls(&scene, &VplParams::default()).is_err());
    // Camera and parameters.
    let mut cam = top_camera(0, 10);
    assert!(trace_primary(&scene, &cam).is_err());
    cam.width = 10;
    cam.fov_deg = 180.0;
    assert!(trace_primary(&scene, &cam).is_err());
    let g = trace_primary(&scene, &top_camera(16, 12)).unwrap();
    let vpls = [emitter_vpl([0.0, 1.0, 0.0], [0.0, -1.0, 0.0], 1.0)];
    let ok = ImportanceCachingParams::default();
    for bad in [
        ok.n_cache(0),
        ok.m_nearest(0),
        ok.spp(0),
        ok.strategies([false; 4]),
        ok.n_cache(10_000),
    ] {
        let r = build_cache(
            &scene,
            &g,
            &vpls,
            &Placement::Adaptive(AdaptiveParams::default()),
            Interp::default(),
            &bad,
        );
        assert!(r.is_err(), "{bad:?}");
    }
    assert!(build_cache(
        &scene,
        &g,
        &[],
        &Placement::RandomScreen,
        Interp::Uniform,
        &ok.n_cache(10)
    )
    .is_err());
    for bad in [
        AdaptiveParams::default().delta(-1.0),
        AdaptiveParams::default().init_fraction(0.0),
    ] {
        let p = ok.n_cache(10);
        assert!(build_cache(
            &scene,
            &g,
            &vpls,
            &Placement::Adaptive(bad),
            Interp::Uniform,
            &p
        )
        .is_err());
    }
    let bad_interp = Interp::Clarberg {
        theta_max: 4.0,
        lambda: 5.0,
        dmax_factor: 2.0,
        defensive: 0.5,
    };
    let p = ok.n_cache(10);
    assert!(build_cache(&scene, &g, &vpls, &Placement::RandomScreen, bad_interp, &p).is_err());
    // A camera that sees nothing: a black image for the reference, an error for a cache.
    let away = Camera {
        eye: [0.0, 6.0, 0.0],
        target: [0.0, 12.0, 0.0],
        up: [0.0, 0.0, 1.0],
        ..top_camera(8, 6)
    };
    let g0 = trace_primary(&scene, &away).unwrap();
    let img = render_reference(&scene, &g0, &vpls, None, &NoProgress).unwrap();
    assert!(img.data().iter().all(|v| *v == 0.0));
    assert!(build_cache(
        &scene,
        &g0,
        &vpls,
        &Placement::RandomScreen,
        Interp::Uniform,
        &p
    )
    .is_err());
}

#[test]
fn shadow_ray_batches_match_brute_force() {
    let (scene, _) = wscg_raytrace::manylight::scenes::cornell_box(2, 8, 8).unwrap();
    let b = scene.bounds();
    let pt = |k: usize| {
        let f = |a: f64| (0.5 + k as f64 * a).fract();
        let u = [f(0.7548776662), f(0.5698402910), f(0.3623612264)];
        [0, 1, 2].map(|c| b.min[c] + (b.max[c] - b.min[c]) * u[c])
    };
    let (a, t): (Vec<_>, Vec<_>) = (0..4000).map(|k| (pt(2 * k), pt(2 * k + 1))).unzip();
    let fast = scene.occluded_batch(&a, &t).unwrap();
    let mut blocked = 0;
    for ((p, q), f) in a.iter().zip(&t).zip(&fast) {
        let d = sub(*q, *p);
        let len = norm(d);
        let dir = d.map(|c| c / len);
        let brute = scene
            .triangles()
            .iter()
            .any(|tri| tri.intersect(*p, dir, len).is_some());
        assert_eq!(*f, brute, "segment {p:?} -> {q:?}");
        blocked += brute as usize;
    }
    // Both outcomes occur.
    assert!(blocked > 400 && blocked < 3600, "{blocked} of 4000 blocked");
    assert!(scene.occluded_batch(&a, &t[1..]).is_err());
}

/// `Shading::visible_share` on two equal VPLs seen from a point halfway between them: all of
/// the light reaches it, half once a triangle blocks one of them, none of it is defined for a
/// receiver facing away from both.
#[test]
fn visible_share_counts_the_blocked_light() {
    let vpls = [
        emitter_vpl([-1.0, 1.0, 0.0], [0.0, -1.0, 0.0], 1.0),
        emitter_vpl([1.0, 1.0, 0.0], [0.0, -1.0, 0.0], 1.0),
    ];
    let at = |normal: [f64; 3]| Receiver {
        pos: [0.0; 3],
        normal,
        albedo: [0.5; 3],
    };
    let open = plane(5.0, 0.5, &[]);
    let sh = Shading::new(&open, &vpls, Some(0.0)).unwrap();
    assert_eq!(sh.visible_share(&at([0.0, 1.0, 0.0])), Some(1.0));
    assert_eq!(sh.visible_share(&at([0.0, -1.0, 0.0])), None);
    // A horizontal triangle at height 0.5 across the segment to the second VPL only.
    let blocker = [[0.2, 0.5, -0.5], [0.9, 0.5, -0.5], [0.2, 0.5, 0.9]];
    let blocked = plane(5.0, 0.5, &[(blocker, [0.5; 3])]);
    let sh = Shading::new(&blocked, &vpls, Some(0.0)).unwrap();
    let v = sh.visible_share(&at([0.0, 1.0, 0.0])).unwrap();
    assert!((v - 0.5).abs() < 1e-12, "{v}");
}

/// The pixel's own distribution (beyond the paper, `near_share`): the `k` VPLs of positive
/// power nearest the point, by brute force, those that light it, in proportion to their
/// contributions without visibility there (a wall between them does not matter).
#[test]
fn near_distribution_is_the_nearest_vpls_by_contribution() {
    let wall = (
        [[0.3, 0.0, -3.0], [0.3, 0.0, 3.0], [0.3, 2.0, 0.0]],
        [0.5; 3],
    );
    let scene = plane(10.0, 0.5, &[wall]);
    let mut vpls = Vec::new();
    for k in 0..80 {
        let t = k as f64 * 2.399_963;
        let rad = 0.2 + 0.05 * k as f64;
        // Every fifth one faces away from the plane, every seventh has no power.
        let normal = if k % 5 == 0 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, -1.0, 0.0]
        };
        let power = if k % 7 == 0 {
            0.0
        } else {
            1.0 + (k % 3) as f64
        };
        vpls.push(emitter_vpl(
            [rad * t.cos(), 0.4, rad * t.sin()],
            normal,
            power,
        ));
    }
    let sh = Shading::new(&scene, &vpls, None).unwrap();
    let near = near::NearVpls::new(&sh).unwrap();
    let r = Receiver {
        pos: [0.1, 0.0, 0.2],
        normal: [0.0, 1.0, 0.0],
        albedo: [0.5; 3],
    };
    let k = 12;
    let got = near.distribution(&sh, &r, k);
    let mut by_distance: Vec<usize> = (0..vpls.len())
        .filter(|&j| luminance(&sh.intensity[j]) > 0.0)
        .collect();
    by_distance.sort_by(|&a, &b| dist(vpls[a].pos, r.pos).total_cmp(&dist(vpls[b].pos, r.pos)));
    let lit: Vec<(usize, f64)> = by_distance[..k]
        .iter()
        .map(|&j| (j, luminance(&sh.unoccluded(&r, j))))
        .filter(|e| e.1 > 0.0)
        .collect();
    assert!(lit.len() < k, "some of the nearest face away");
    let total: f64 = lit.iter().map(|e| e.1).sum();
    let mut want: Vec<(usize, f64)> = lit.iter().map(|&(j, u)| (j, u / total)).collect();
    want.sort_by_key(|e| e.0);
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(g.0, w.0);
        assert!((g.1 - w.1).abs() < 1e-12, "{g:?} vs {w:?}");
    }
    // A point no VPL lights (under the plane, facing down): empty.
    let below = Receiver {
        pos: [0.1, -0.01, 0.2],
        normal: [0.0, -1.0, 0.0],
        albedo: [0.5; 3],
    };
    assert!(near.distribution(&sh, &below, k).is_empty());
}
