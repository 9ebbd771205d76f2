//! Roller reaction forces (paper 02, section 5: hard constraints and their multipliers):
//! every solver that supports rollers (the soft projection, the linearised, Newton and
//! constraint-space implicit Euler) reports the constraint force, which balances gravity
//! for a cloth at rest on them.

use wscg_cloth::{ClothModel, Method, Simulation, SolverParams};

const H: f64 = 1.0 / 100.0;

/// A 7 x 5 cloth of 0.35 kg with every particle on a roller plane through the x axis tilted
/// by `tilt` radians (normal `(0, cos t, -sin t)`), its links stretched by the tilt: free
/// to slide on the plane, never to leave it.
fn cloth_on_rollers(tilt: f64) -> ClothModel {
    let mut m = ClothModel::grid(7, 5, (0.6, 0.4), 0.35, 500.0, Some(200.0), None).unwrap();
    let mass = 0.35 / 35.0;
    for w in m.inv_mass.iter_mut() {
        *w = 1.0 / mass;
    }
    let normal = [0.0, tilt.cos(), -tilt.sin()];
    // Pre-stretched start: each particle lifted onto the tilted plane.
    let x: Vec<[f64; 3]> =
        m.x.iter()
            .map(|p| [p[0], p[2] * tilt.tan(), p[2]])
            .collect();
    m.x = x;
    for p in 0..m.len() {
        m.add_roller(p, normal, 0.0).unwrap();
    }
    m
}

fn methods() -> Vec<Method> {
    vec![
        Method::SoftProjection,
        Method::ImplicitEulerCg {
            tol: 1e-12,
            max_iter: 500,
        },
        Method::ImplicitEulerDirect,
        Method::ImplicitEulerNewton { tol: 1e-10 },
        Method::GlobalCr {
            primal_residual: true,
            tol: 1e-12,
        },
    ]
}

#[test]
fn roller_reactions_balance_gravity_for_every_solver() {
    for tilt in [0.0f64, 0.5] {
        for method in methods() {
            let mut sim = Simulation::new(
                cloth_on_rollers(tilt),
                SolverParams::default().method(method),
            )
            .unwrap();
            sim.run(H, 40).unwrap();
            let m = sim.model();
            let mass = 1.0 / m.inv_mass[0];
            // Analytic: each particle's normal reaction is m g cos(tilt), the in-plane
            // forces (links, the slide down the slope) have no normal component.
            let want = mass * 9.81 * tilt.cos();
            let r = sim.roller_forces();
            assert_eq!(r.len(), m.len());
            let total: f64 = r.iter().sum();
            assert!(
                (total / (want * r.len() as f64) - 1.0).abs() < 1e-6,
                "{method:?}, tilt {tilt}: total {total} vs {}",
                want * r.len() as f64
            );
            for (p, &f) in r.iter().enumerate() {
                assert!(
                    (f / want - 1.0).abs() < 1e-4,
                    "{method:?}, tilt {tilt}: particle {p} reaction {f} vs m g cos = {want}"
                );
            }
            // The particles stay on their planes.
            for p in &m.x {
                assert!((p[1] * tilt.cos() - p[2] * tilt.sin()).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn hanging_cloth_at_rest_on_rollers_carries_its_weight() {
    // A cloth hanging in the x-y plane from its top row, which rides on rollers (horizontal
    // planes y = 0): at rest the top row's reactions carry the whole weight.
    let (nx, ny) = (6, 5);
    let mut m = ClothModel::grid(nx, ny, (0.5, 0.4), 0.3, 800.0, Some(300.0), None).unwrap();
    for w in m.inv_mass.iter_mut() {
        *w = nx as f64 * ny as f64 / 0.3;
    }
    // Hang it: z becomes -y (the grid's rows hang down from row 0).
    let x: Vec<[f64; 3]> = m.x.iter().map(|p| [p[0], -p[2], 0.0]).collect();
    m.x = x;
    for i in 0..nx {
        m.add_roller(i, [0.0, 1.0, 0.0], 0.0).unwrap();
        m.add_roller(i, [1.0, 0.0, 0.0], m.x[i][0]).unwrap();
    }
    for method in methods() {
        let cfg = SolverParams::default().method(method).velocity_damping(0.5);
        let mut sim = Simulation::new(m.clone(), cfg).unwrap();
        sim.run(H, 1500).unwrap();
        let speed = sim
            .model()
            .v
            .iter()
            .map(|v| v.iter().map(|c| c * c).sum::<f64>().sqrt())
            .fold(0.0, f64::max);
        let r = sim.roller_forces();
        let vertical: f64 = r.iter().step_by(2).sum();
        let sideways: f64 = r.iter().skip(1).step_by(2).sum();
        let weight = 0.3 * 9.81;
        assert!(
            (vertical / weight - 1.0).abs() < 1e-3,
            "{method:?}: vertical reactions {vertical} vs weight {weight} (speed {speed})"
        );
        assert!(sideways.abs() < 1e-3 * weight, "{method:?}: {sideways}");
    }
}

#[test]
fn particles_off_their_roller_planes_are_refused_by_name() {
    let mut m = cloth_on_rollers(0.0);
    m.x[12][1] = 1e-3;
    for method in [
        Method::ImplicitEulerCg {
            tol: 1e-10,
            max_iter: 100,
        },
        Method::ImplicitEulerDirect,
    ] {
        let mut sim = Simulation::new(m.clone(), SolverParams::default().method(method)).unwrap();
        let e = sim.step(H).unwrap_err().to_string();
        assert!(e.contains("particle 12") && e.contains("roller"), "{e}");
    }
    // The soft projection, Newton and the global solve move it onto its plane.
    for method in [
        Method::SoftProjection,
        Method::ImplicitEulerNewton { tol: 1e-10 },
        Method::GlobalCr {
            primal_residual: true,
            tol: 1e-12,
        },
    ] {
        let mut sim = Simulation::new(m.clone(), SolverParams::default().method(method)).unwrap();
        sim.step(H).unwrap();
        assert!(sim.model().x[12][1].abs() < 1e-9, "{method:?}");
    }
}
