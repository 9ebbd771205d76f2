//! The two-stage update (joint bilateral normal filter, then the vertex update that fits the
//! filtered normals; the default of `JbmdParams::from_mvd`) at sharp edges: against the
//! paper's update and the Laplacian, Taubin and bilateral (Fleishman et al. 2003) baselines,
//! each at its best setting and iteration for the error being compared (the corresponding-
//! vertex error of the vertices within one grid step of an edge). Developed on the coloured
//! cube with the default noise seed; checked on a coloured octahedron (dihedral angle 109.5
//! degrees) and the CAD part S2 with other seeds.

use wscg_math::TriMesh;
use wscg_meshfilter::metrics::{corresponding_error, mean_error, mean_vertex_distance};
use wscg_meshfilter::sweep::{sweep, Setting};
use wscg_meshfilter::synth::{
    add_noise, cad_part, colored_cube, colored_octahedron, cube_edge_band, icosphere,
    octahedron_edge_band, NOISE_SEED,
};
use wscg_meshfilter::{jbmd, JbmdParams};

/// Iterations of the baselines' sweeps (their best edge errors come in the first few).
const SWEEP_ITERS: usize = 20;

/// Edge-band errors in MVD: (the default two-stage JBMD, the paper's update, the best
/// Laplacian, Taubin and bilateral smoothing).
fn edge_errors(gt: &TriMesh, band: &[bool], seed: u64) -> (f64, f64, [f64; 3]) {
    let mvd = mean_vertex_distance(gt).unwrap();
    let noisy = add_noise(gt, 0.5 * mvd, false, seed).unwrap();
    let err = |x: &[[f64; 3]]| corresponding_error(x, &gt.positions, Some(band)).unwrap() / mvd;
    let p = JbmdParams::from_mvd(mvd);
    let ours = err(&jbmd(&noisy, &p).unwrap());
    let paper = err(&jbmd(&noisy, &p.normal_iterations(0)).unwrap());
    let best = [
        Setting::laplacian_grid(),
        Setting::taubin_grid(),
        Setting::bmd_grid(mvd),
    ]
    .map(|grid| {
        sweep(&noisy, &grid, SWEEP_ITERS, err)
            .unwrap()
            .unwrap()
            .error
    });
    (ours, paper, best)
}

fn check(name: &str, gt: &TriMesh, band: &[bool], seed: u64) {
    let (ours, paper, best) = edge_errors(gt, band, seed);
    let min = best.iter().copied().fold(f64::INFINITY, f64::min);
    println!(
        "{name}, seed {seed}: edge band (MVD) two-stage {ours:.3}, paper's update {paper:.3}; \
         best Laplacian / Taubin / bilateral {best:.3?}; ratio {:.2}",
        ours / min
    );
    assert!(ours <= 0.8 * min, "{name}: {ours} vs {min}");
}

#[test]
fn cube_edges_beat_the_best_smoothers() {
    let gt = colored_cube(30).unwrap();
    let band = cube_edge_band(30, &gt.positions);
    check("cube", &gt, &band, NOISE_SEED);
}

#[test]
fn octahedron_edges_beat_the_best_smoothers() {
    let gt = colored_octahedron(24).unwrap();
    let band = octahedron_edge_band(24, &gt.positions);
    assert_eq!(gt.euler_characteristic(), 2);
    assert_eq!(gt.num_vertices(), 4 * 24 * 24 + 2);
    assert!(gt.is_closed());
    for seed in [1, 2] {
        check("octahedron", &gt, &band, seed);
    }
}

#[test]
fn cad_part_creases_beat_the_best_smoothers() {
    let part = cad_part(20).unwrap();
    check("CAD part", &part.mesh, &part.crease_band, 7);
}

#[test]
fn colour_separates_the_faces() {
    // Without the colour term the normal filter alone mixes the faces at the edges.
    let gt = colored_cube(30).unwrap();
    let band = cube_edge_band(30, &gt.positions);
    let mvd = mean_vertex_distance(&gt).unwrap();
    let noisy = add_noise(&gt, 0.5 * mvd, false, NOISE_SEED).unwrap();
    let err = |p: &JbmdParams| {
        let x = jbmd(&noisy, p).unwrap();
        corresponding_error(&x, &gt.positions, Some(&band)).unwrap() / mvd
    };
    let p = JbmdParams::from_mvd(mvd);
    let (with, without) = (err(&p), err(&p.use_color(false)));
    println!("cube edge band: with colour {with:.3}, without {without:.3}");
    assert!(with <= 0.6 * without, "{with} vs {without}");
}

#[test]
fn clean_cube_and_sphere() {
    // A noise-free cube keeps its edges; a noisy sphere keeps its radius (no shrinkage).
    let gt = colored_cube(30).unwrap();
    let band = cube_edge_band(30, &gt.positions);
    let mvd = mean_vertex_distance(&gt).unwrap();
    let x = jbmd(&gt, &JbmdParams::from_mvd(mvd)).unwrap();
    let eb = corresponding_error(&x, &gt.positions, Some(&band)).unwrap() / mvd;
    let me = mean_error(&x, &gt.positions).unwrap() / mvd;
    let s = icosphere(4).unwrap();
    let smvd = mean_vertex_distance(&s).unwrap();
    let noisy = add_noise(&s, 0.5 * smvd, false, NOISE_SEED).unwrap();
    let y = jbmd(&noisy, &JbmdParams::from_mvd(smvd)).unwrap();
    let r: Vec<f64> = y
        .iter()
        .map(|q| (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt())
        .collect();
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    let sme = mean_error(&y, &s.positions).unwrap() / smvd;
    let sme0 = mean_error(&noisy.positions, &s.positions).unwrap() / smvd;
    println!("clean cube: ME {me:.4}, edge band {eb:.4}; sphere radius {mean:.4}, ME {sme0:.3} -> {sme:.3}");
    assert!(me <= 0.02 && eb <= 0.05, "{me} {eb}");
    assert!((0.995..=1.005).contains(&mean), "{mean}");
    assert!(sme <= 0.5 * sme0, "{sme} vs {sme0}");
}
