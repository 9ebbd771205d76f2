//! Paper 02, section 9: StVK membrane triangles as soft constraints (checks 6 and 7).

use nalgebra::{Matrix2, Vector2};
use wscg_cloth::FemTri;
use wscg_math::rng;

fn random_triangle(seed: u64) -> (FemTri, Vec<[f64; 3]>) {
    let r = rng::uniform_vec(seed, 20, -1.0, 1.0).unwrap();
    let uv = [
        [0.0, 0.0],
        [1.0 + 0.3 * r[0], 0.2 * r[1]],
        [0.3 * r[2], 0.9 + 0.3 * r[3]],
    ];
    let t = FemTri::new([0, 1, 2], uv, 800.0 + 400.0 * r[4], 0.2 + 0.2 * r[5].abs()).unwrap();
    // Deform the rest shape: rotate into 3-D, stretch each axis by up to 30 %, shear a bit.
    let (sx, sy, sh) = (1.0 + 0.3 * r[6], 1.0 + 0.3 * r[7], 0.2 * r[8]);
    let x = uv
        .iter()
        .map(|p| {
            let (u, v) = (sx * p[0] + sh * p[1], sy * p[1]);
            [u, 0.3 * u * r[9] + 0.4 * v * r[10], v]
        })
        .collect();
    (t, x)
}

/// Check 6: the soft-constraint potential with the solver's compliance blocks equals the
/// StVK membrane energy, and the strain gradients match central differences.
#[test]
fn soft_constraint_energy_is_stvk_and_gradients_match() {
    for seed in 0..50 {
        let (t, x) = random_triangle(seed);
        let st = t.strain(&x);
        let (c2, cs) = t.compliance();
        let e2 = Vector2::new(st.e[0], st.e[1]);
        let inv: Matrix2<f64> = c2.try_inverse().unwrap();
        let soft = 0.5 * e2.dot(&(inv * e2)) + 0.5 * st.e[2] * st.e[2] / cs;
        let stvk = t.energy(&x);
        assert!(
            (soft - stvk).abs() <= 1e-12 * stvk.abs().max(1e-300),
            "seed {seed}: {soft} vs {stvk}"
        );
        // The energy is the StVK formula with the plane-stress matrix, written out.
        let (y, nu) = (t.young, t.poisson);
        let [a, b, g] = st.e;
        let written = 0.5 * t.area * y / (1.0 - nu * nu)
            * (a * a + b * b + 2.0 * nu * a * b + 0.5 * (1.0 - nu) * g * g);
        assert!((written - stvk).abs() <= 1e-12 * stvk);
        // Gradients against central differences.
        let step = 1e-6;
        for p in 0..3 {
            for c in 0..3 {
                let mut xp = x.clone();
                let mut xm = x.clone();
                xp[p][c] += step;
                xm[p][c] -= step;
                let (sp, sm) = (t.strain(&xp), t.strain(&xm));
                for k in 0..3 {
                    let fd = (sp.e[k] - sm.e[k]) / (2.0 * step);
                    let an = st.grad[k][p][c];
                    assert!(
                        (fd - an).abs() <= 1e-6 * an.abs().max(1.0),
                        "seed {seed} strain {k} vertex {p} axis {c}: {an} vs {fd}"
                    );
                }
            }
        }
    }
}

#[test]
fn rest_shape_has_zero_strain_and_degenerate_triangles_fail() {
    let (t, _) = random_triangle(3);
    let x = [[0.0, 0.0], [1.0, 0.1], [0.2, 0.8]];
    let t2 = FemTri::new([0, 1, 2], x, 1000.0, 0.3).unwrap();
    let pos: Vec<[f64; 3]> = x.iter().map(|p| [p[0], p[1], 0.0]).collect();
    assert!(t2.strain(&pos).e.iter().all(|e| e.abs() < 1e-15));
    assert!(t.area > 0.0);
    // Local rest coordinates of a 3-D triangle preserve its edge lengths.
    let p3 = [[0.1, 0.2, 0.3], [1.0, -0.5, 0.7], [-0.2, 0.9, 1.1]];
    let uv = FemTri::local_uv(p3);
    let t3 = FemTri::new([0, 1, 2], uv, 1000.0, 0.3).unwrap();
    assert!(t3.strain(&p3).e.iter().all(|e| e.abs() < 1e-13));
    assert!(FemTri::new([0, 1, 2], [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]], 1.0, 0.3).is_err());
    assert!(FemTri::new([0, 1, 2], x, 0.0, 0.3).is_err());
    assert!(FemTri::new([0, 1, 2], x, 1.0, 0.5).is_err());
    assert!(FemTri::new(
        [0, 1, 2],
        [[f64::NAN, 0.0], [1.0, 0.0], [0.0, 1.0]],
        1.0,
        0.3
    )
    .is_err());
}

/// A jittered `n x n` triangulation of the unit square in the x-z plane (jitter 0.3 of the
/// spacing on interior vertices), with StVK triangles (`young`, `poisson`) or edge links of
/// stiffness `young` when `links` is set; rest coordinates are the jittered `(x, z)`.
fn jittered_sheet(n: usize, young: f64, poisson: f64, links: bool) -> wscg_cloth::ClothModel {
    use wscg_cloth::ClothModel;
    let mut m = ClothModel::grid(n, n, (1.0, 1.0), 1.0, 1.0, None, None).unwrap();
    m.links.clear();
    m.inv_mass = vec![(n * n) as f64; n * n];
    m.gravity = [0.0; 3];
    let jit = rng::uniform_vec(11, 2 * n * n, -0.3, 0.3).unwrap();
    let sp = 1.0 / (n - 1) as f64;
    for j in 1..n - 1 {
        for i in 1..n - 1 {
            let p = j * n + i;
            m.x[p][0] += jit[2 * p] * sp;
            m.x[p][2] += jit[2 * p + 1] * sp;
        }
    }
    let id = |i: usize, j: usize| j * n + i;
    for t in wscg_cloth::model::grid_triangles(n, n) {
        if links {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                if !m
                    .links
                    .iter()
                    .any(|l| (l.i, l.j) == (a, b) || (l.i, l.j) == (b, a))
                {
                    m.add_link(a, b, young, None).unwrap();
                }
            }
        } else {
            let uv = t.map(|p| [m.x[p][0], m.x[p][2]]);
            m.add_fem_triangle(t, Some(uv), young, poisson).unwrap();
        }
    }
    // Rollers: left edge on x = 0, right edge on x = 1.01; one left vertex fully pinned;
    // every vertex stays in the y = 0 plane.
    for j in 0..n {
        m.add_roller(id(0, j), [1.0, 0.0, 0.0], 0.0).unwrap();
        m.add_roller(id(n - 1, j), [1.0, 0.0, 0.0], 1.01).unwrap();
        m.x[id(n - 1, j)][0] = 1.01;
    }
    for p in 0..n * n {
        m.add_roller(p, [0.0, 1.0, 0.0], 0.0).unwrap();
    }
    m.inv_mass[id(0, 0)] = 0.0;
    m
}

/// Green strains `(e_xx, e_zz)` of the triangle `t` at positions `x`, with rest coordinates
/// `rest` (the strain in the world axes, whatever the triangle's rest map).
fn world_strain(t: &FemTri, rest: &[[f64; 3]], x: &[[f64; 3]]) -> (f64, f64) {
    let axis = FemTri::new(t.idx, t.idx.map(|p| [rest[p][0], rest[p][2]]), 1.0, 0.0).unwrap();
    let e = axis.strain(x).e;
    (e[0], e[1])
}

/// Run to rest under linearised implicit Euler (its fixed point is the exact equilibrium
/// `f(x) = 0`).
fn settle(model: wscg_cloth::ClothModel) -> wscg_cloth::Simulation {
    use wscg_cloth::{Method, Simulation, SolverParams};
    let mut sim = Simulation::new(
        model,
        SolverParams::default().method(Method::ImplicitEulerCg {
            tol: 1e-12,
            max_iter: 2000,
        }),
    )
    .unwrap();
    for _ in 0..4000 {
        sim.step(0.05).unwrap();
        let vmax = sim
            .model()
            .v
            .iter()
            .flatten()
            .fold(0.0, |m: f64, c| m.max(c.abs()));
        if vmax < 1e-10 {
            break;
        }
    }
    sim
}

/// Check 7: the FEM patch test. Uniaxial stretch of 1 % between rollers gives every
/// triangle the exact StVK uniaxial-stress strains `e_xx = (1.01^2 - 1)/2` and
/// `e_zz = -nu e_xx`; a spring network on the same mesh does not.
#[test]
fn fem_patch_test_and_poisson_effect() {
    let nu = 0.3;
    let rest = jittered_sheet(30, 1000.0, nu, false);
    // Rest positions: the right edge was moved onto its roller at x = 1.01.
    let mut rest_x = rest.x.clone();
    for j in 0..30 {
        rest_x[j * 30 + 29][0] = 1.0;
    }
    let sim = settle(rest.clone());
    let m = sim.model();
    let exx = 0.5 * (1.01f64 * 1.01 - 1.0);
    let mut worst = (0.0f64, 0.0f64);
    for t in &m.tris {
        let (a, b) = world_strain(t, &rest_x, &m.x);
        worst.0 = worst.0.max((a - exx).abs() / exx);
        worst.1 = worst.1.max((b + nu * exx).abs() / (nu * exx));
    }
    println!(
        "FEM patch test after {} steps: max rel. error e_xx {:.2e}, e_zz {:.2e}",
        sim.steps(),
        worst.0,
        worst.1
    );
    assert!(worst.0 <= 1e-6 && worst.1 <= 1e-6, "{worst:?}");

    // The same sheet as a spring network: report the spread of e_xx.
    let springs = jittered_sheet(30, 1000.0, nu, true);
    let sim = settle(springs);
    let m = sim.model();
    let strains: Vec<f64> = rest
        .tris
        .iter()
        .map(|t| world_strain(t, &rest_x, &m.x).0)
        .collect();
    let mean = strains.iter().sum::<f64>() / strains.len() as f64;
    let sd =
        (strains.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / strains.len() as f64).sqrt();
    println!("edge links: e_xx mean {mean:.5}, std/mean {:.3}", sd / mean);
    assert!(sd / mean > 10.0 * worst.0);
}
