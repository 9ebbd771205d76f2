//! Paper 02, section 9: StVK membrane triangles as soft constraints (specification checks 6
//! and 7).

use nalgebra::{Matrix2, Vector2, Vector3};
use wscg_cloth::FemTri;
use wscg_math::rng;

fn random_triangle(seed: u64) -> (FemTri, Vec<Vector3<f64>>) {
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
            Vector3::new(u, 0.3 * u * r[9] + 0.4 * v * r[10], v)
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
    let pos: Vec<Vector3<f64>> = x.iter().map(|p| Vector3::new(p[0], p[1], 0.0)).collect();
    assert!(t2.strain(&pos).e.iter().all(|e| e.abs() < 1e-15));
    assert!(t.area > 0.0);
    // Local rest coordinates of a 3-D triangle preserve its edge lengths.
    let p3 = [
        Vector3::new(0.1, 0.2, 0.3),
        Vector3::new(1.0, -0.5, 0.7),
        Vector3::new(-0.2, 0.9, 1.1),
    ];
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
