//! Paper 04's comparisons (checks 3-5 and 7): the anti-shrinking and colour ablations and the
//! baselines at their best swept settings, on the noisy coloured cube S1 (n = 30, noise of
//! 0.5 MVD along the normals, k = 40, 15 iterations), the same edge comparisons on the CAD
//! part S2 with its fillet, and the colour-edge sanity check; all with the paper's update
//! (`normal_iterations = 0`; the two-stage update is checked in `edges.rs`).

use wscg_math::TriMesh;
use wscg_meshfilter::metrics::{corresponding_error, mean_error, mean_vertex_distance};
use wscg_meshfilter::sweep::{sweep, Setting};
use wscg_meshfilter::synth::{
    add_noise, cad_part, colored_cube, colored_plane, cube_edge_band, FILLET_CENTER, FILLET_PATCH,
    FILLET_RADIUS, NOISE_SEED,
};
use wscg_meshfilter::{jbmd_trace, JbmdParams};

const N: usize = 30;

struct Scene {
    gt: TriMesh,
    noisy: TriMesh,
    mvd: f64,
    /// Vertices within 1/n of a cube edge.
    band: Vec<bool>,
}

fn scene() -> Scene {
    let gt = colored_cube(N).unwrap();
    let mvd = mean_vertex_distance(&gt).unwrap();
    let noisy = add_noise(&gt, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let band = cube_edge_band(N, &gt.positions);
    Scene {
        gt,
        noisy,
        mvd,
        band,
    }
}

/// ME and edge-band error (both in MVD) after every iteration.
fn curves(s: &Scene, p: &JbmdParams) -> (Vec<f64>, Vec<f64>) {
    let (mut me, mut eb) = (Vec::new(), Vec::new());
    jbmd_trace(&s.noisy, p, |_, x, _| {
        me.push(mean_error(x, &s.gt.positions).unwrap() / s.mvd);
        eb.push(corresponding_error(x, &s.gt.positions, Some(&s.band)).unwrap() / s.mvd);
    })
    .unwrap();
    (me, eb)
}

/// The paper's update (no normal filter): these are checks of the paper's claims.
fn params(s: &Scene) -> JbmdParams {
    JbmdParams::from_mvd(s.mvd)
        .k(40)
        .iterations(15)
        .normal_iterations(0)
}

/// A baseline at its ME-optimal setting and iteration: (ME, edge-band error), in MVD.
fn best_swept(s: &Scene, grid: Vec<Setting>) -> (f64, f64) {
    let b = sweep(&s.noisy, &grid, 15, |x| {
        mean_error(x, &s.gt.positions).unwrap() / s.mvd
    })
    .unwrap()
    .unwrap();
    let band = corresponding_error(&b.positions, &s.gt.positions, Some(&s.band)).unwrap();
    (b.error, band / s.mvd)
}

#[test]
fn cad_part_creases_and_fillet() {
    // Checks 4 and 5 on S2, where creases (four convex, one concave) are colour edges and the
    // fillet's tangent joins are colour edges without a crease; and the fillet keeps its
    // radius (check 6's tolerance, relative).
    let part = cad_part(20).unwrap();
    let gt = part.mesh;
    let mvd = mean_vertex_distance(&gt).unwrap();
    let noisy = add_noise(&gt, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let s = Scene {
        gt,
        noisy,
        mvd,
        band: part.crease_band,
    };
    let p = params(&s);
    let (me, eb) = curves(&s, &p);
    let (_, eb_nc) = curves(&s, &p.use_color(false));
    let best_lap = best_swept(&s, Setting::laplacian_grid());
    let best_bmd = best_swept(&s, Setting::bmd_grid(s.mvd));
    let out = wscg_meshfilter::jbmd(&s.noisy, &p).unwrap();
    let radii: Vec<f64> = out
        .iter()
        .zip(&part.patch)
        .filter(|(_, &patch)| patch == FILLET_PATCH)
        .map(|(q, _)| (q[0] - FILLET_CENTER[0]).hypot(q[1] - FILLET_CENTER[1]))
        .collect();
    let radius = radii.iter().sum::<f64>() / radii.len() as f64;
    println!(
        "S2: JBMD ME {:.3} crease band {:.3}; no colour band {:.3}; best Laplacian {best_lap:.3?}, \
         best BMD {best_bmd:.3?}; fillet radius {radius:.4}",
        me[14], eb[14], eb_nc[14]
    );
    assert!(eb[14] <= 0.9 * eb_nc[14], "{} vs {}", eb[14], eb_nc[14]);
    assert!(eb[14] <= 0.75 * best_lap.1, "{} vs {}", eb[14], best_lap.1);
    assert!(eb[14] <= 0.75 * best_bmd.1, "{} vs {}", eb[14], best_bmd.1);
    assert!(me[14] <= best_bmd.0, "{} vs {}", me[14], best_bmd.0);
    assert!((radius / FILLET_RADIUS - 1.0).abs() <= 0.005, "{radius}");
}

#[test]
fn ablations_and_baselines() {
    let s = scene();
    let p = params(&s);
    let (me, eb) = curves(&s, &p);
    // Check 3: without anti-shrinking, as good early, clearly worse late.
    let (me_nas, _) = curves(&s, &p.anti_shrink(false));
    println!(
        "JBMD ME {:.3} edge band {:.3}; no anti-shrink ME {me_nas:.3?}",
        me[14], eb[14]
    );
    for it in 0..2 {
        assert!(
            me_nas[it] <= me[it] * 1.02,
            "iteration {}: {} vs {}",
            it + 1,
            me_nas[it],
            me[it]
        );
    }
    assert!(me_nas[14] >= 1.3 * me[14], "{} vs {}", me_nas[14], me[14]);
    // Check 2, no decay: the error turns back up.
    let (me_nd, _) = curves(&s, &p.lambda(1.0));
    let (arg, min) =
        me_nd.iter().enumerate().fold(
            (0, f64::INFINITY),
            |b, (i, &v)| if v < b.1 { (i, v) } else { b },
        );
    println!(
        "no decay: min {min:.3} at iteration {}, ME(15) {:.3}",
        arg + 1,
        me_nd[14]
    );
    // argmin at iteration <= 6 (index < 6).
    assert!(arg < 6 && me_nd[14] >= 1.15 * min);
    // Check 4: colour helps, most at the edges.
    let (me_nc, eb_nc) = curves(&s, &p.use_color(false));
    println!("no colour: ME {:.3} edge band {:.3}", me_nc[14], eb_nc[14]);
    assert!(me[14] <= 0.97 * me_nc[14]);
    assert!(eb[14] <= 0.9 * eb_nc[14]);
    // Check 5: the baselines at their ME-optimal settings (sweep over parameters and
    // iterations 1..15), compared on the edge band; BMD also globally.
    let best_lap = best_swept(&s, Setting::laplacian_grid());
    let best_bmd = best_swept(&s, Setting::bmd_grid(s.mvd));
    println!("best Laplacian (ME, edge band) {best_lap:.3?}; best BMD {best_bmd:.3?}");
    assert!(eb[14] <= 0.75 * best_lap.1, "{} vs {}", eb[14], best_lap.1);
    assert!(eb[14] <= 0.75 * best_bmd.1, "{} vs {}", eb[14], best_bmd.1);
    assert!(me[14] <= best_bmd.0, "{} vs {}", me[14], best_bmd.0);
}

#[test]
fn colour_edge_without_geometric_edge_is_smoothed() {
    // Check 7: a noisy plane with a colour step and no geometric edge.
    let plane = colored_plane(40).unwrap();
    let mvd = mean_vertex_distance(&plane).unwrap();
    let noisy = add_noise(&plane, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let out =
        wscg_meshfilter::jbmd(&noisy, &JbmdParams::from_mvd(mvd).k(40).iterations(15)).unwrap();
    let me0 = mean_error(&noisy.positions, &plane.positions).unwrap();
    let me1 = mean_error(&out, &plane.positions).unwrap();
    // Mean height on each side of the colour edge, away from the frozen boundary.
    let side = |left: bool| {
        let z: Vec<f64> = out
            .iter()
            .filter(|p| {
                (0.1..0.9).contains(&p[1]) && (p[0] < 0.5) == left && (p[0] - 0.5).abs() < 0.1
            })
            .map(|p| p[2])
            .collect();
        z.iter().sum::<f64>() / z.len() as f64
    };
    let step = (side(true) - side(false)).abs();
    println!(
        "plane: ME {:.3} -> {:.3} MVD, step across the colour edge {:.4} MVD",
        me0 / mvd,
        me1 / mvd,
        step / mvd
    );
    assert!(me1 <= 0.5 * me0);
    assert!(step < 0.1 * mvd);
}

#[test]
fn clean_cube_stays_sharp() {
    // Check 1 on the noise-free cube: flat regions do not move, the edges stay close.
    let s = scene();
    let p = params(&s);
    let clean = s.gt.clone();
    let one = wscg_meshfilter::jbmd(&clean, &p.iterations(1)).unwrap();
    let far = 8.0 / N as f64;
    for (a, b) in one.iter().zip(&clean.positions) {
        // Distance to the nearest cube edge: the second smallest distance to a face plane.
        let mut d: Vec<f64> = b.iter().map(|&c| c.min(1.0 - c)).collect();
        d.sort_by(f64::total_cmp);
        if d[1] > far {
            let m = (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max);
            assert!(m <= 1e-12, "{b:?} moved {m}");
        }
    }
    let band = |p: &JbmdParams| {
        let x = wscg_meshfilter::jbmd(&clean, p).unwrap();
        (
            mean_error(&x, &clean.positions).unwrap() / s.mvd,
            corresponding_error(&x, &clean.positions, Some(&s.band)).unwrap() / s.mvd,
        )
    };
    let (me, eb) = band(&p);
    let (_, eb_nas) = band(&p.anti_shrink(false));
    println!("clean cube after 15 iterations: ME {me:.3}, edge band {eb:.3}; without anti-shrinking {eb_nas:.3}");
    assert!(me <= 0.08 && eb <= 0.2 && eb_nas > 0.5);
}
