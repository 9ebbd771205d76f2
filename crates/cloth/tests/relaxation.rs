//! The sweep variants of the soft projection (paper section 7): Gauss-Seidel, SOR, Jacobi
//! and graph-coloured Gauss-Seidel solve the same per-step constraints; the coloured sweep is
//! race-free, so its result does not depend on the number of threads.

use nalgebra::Vector3;
use wscg_cloth::{grid_triangles, ClothModel, Relaxation, Simulation, SolverParams, StepStats};

const H: f64 = 1.0 / 60.0;

/// An `n x n` membrane (FEM triangles, bending links), two corners pinned, expanding in its
/// plane with a random perturbation: under tension the step's minimiser is unique (StVK and
/// bending links under compression have several, which different sweep orders may pick).
fn membrane(n: usize) -> ClothModel {
    let mut m = ClothModel::fem_grid(n, n, (1.0, 1.0), 0.1, 500.0, 0.3).unwrap();
    m.add_bending_links(&grid_triangles(n, n), 20.0).unwrap();
    let r = wscg_math::rng::uniform_vec(3, 3 * n * n, -1.0, 1.0).unwrap();
    for q in 0..n * n {
        if m.inv_mass[q] > 0.0 {
            let out = (Vector3::from(m.x[q]) - Vector3::new(0.5, 0.0, 0.5)) * 1.0;
            m.v[q] = (out + Vector3::new(r[3 * q], r[3 * q + 1], r[3 * q + 2]) * 0.05).into();
        }
    }
    m
}

fn run(model: &ClothModel, relaxation: Relaxation, iterations: usize, steps: usize) -> Simulation {
    run_stats(model, relaxation, iterations, steps).0
}

/// The simulation after `steps` steps and the statistics of the last one.
fn run_stats(
    model: &ClothModel,
    relaxation: Relaxation,
    iterations: usize,
    steps: usize,
) -> (Simulation, StepStats) {
    let mut sim = Simulation::new(
        model.clone(),
        SolverParams::default()
            .iterations(iterations)
            .relaxation(relaxation),
    )
    .unwrap();
    let mut stats = StepStats::default();
    for _ in 0..steps {
        stats = sim.step(H).unwrap();
    }
    (sim, stats)
}

fn dist(a: &Simulation, b: &Simulation) -> f64 {
    a.model()
        .x
        .iter()
        .zip(&b.model().x)
        .map(|(p, q)| (Vector3::from(*p) - Vector3::from(*q)).amax())
        .fold(0.0, f64::max)
}

fn sweeps() -> [(Relaxation, usize); 4] {
    [
        (Relaxation::GaussSeidel, 8000),
        (Relaxation::ColoredGaussSeidel, 8000),
        (Relaxation::Sor { omega: 1.3 }, 8000),
        (Relaxation::Jacobi { omega: 0.15 }, 40000),
    ]
}

/// A vertical chain moving along its axis keeps its constraint gradients fixed, so the
/// projection's fixed point is unique (the implicit Euler step): every sweep must reach it.
#[test]
fn all_sweeps_reach_the_implicit_euler_step_of_a_chain() {
    let mut model = ClothModel::chain(12, 0.01, 0.05, 50.0).unwrap();
    for (q, v) in model.v.iter_mut().enumerate().skip(1) {
        v[1] = 0.4 * ((q as f64) * 1.3).sin();
    }
    let mut newton = Simulation::new(
        model.clone(),
        SolverParams::default().method(wscg_cloth::Method::ImplicitEulerNewton { tol: 1e-13 }),
    )
    .unwrap();
    newton.step(H).unwrap();
    for (relaxation, iterations) in sweeps() {
        let sim = run(&model, relaxation, iterations, 1);
        let d = dist(&sim, &newton);
        println!("{relaxation:?}: {d:.2e} m from Newton's implicit Euler");
        assert!(d < 1e-10, "{relaxation:?}: {d}");
    }
    // A few sweeps are not converged: the variants then differ, so the test is not vacuous.
    let d = dist(
        &run(&model, Relaxation::GaussSeidel, 3, 1),
        &run(&model, Relaxation::Jacobi { omega: 0.5 }, 3, 1),
    );
    assert!(d > 1e-6, "{d}");
}

/// On a membrane the Jacobians turn during the step and the converged projection depends
/// on the visiting order (the gap between XPBD and implicit Euler, check 4); every sweep
/// must still converge (residual below 1e-12) to a state close to Gauss-Seidel's.
#[test]
fn all_sweeps_converge_on_a_membrane() {
    let model = membrane(8);
    let gs = run(&model, Relaxation::GaussSeidel, 8000, 1);
    let moved = dist(&gs, &run(&model, Relaxation::GaussSeidel, 1, 0));
    for (relaxation, iterations) in sweeps() {
        let (sim, stats) = run_stats(&model, relaxation, iterations, 1);
        let d = dist(&sim, &gs);
        println!(
            "{relaxation:?}: residual {:.1e}, {d:.2e} m from Gauss-Seidel (step {moved:.2e} m)",
            stats.max_residual
        );
        assert!(
            stats.max_residual < 1e-9,
            "{relaxation:?}: {}",
            stats.max_residual
        );
        assert!(d < 0.02 * moved, "{relaxation:?}: {d}");
    }
}

#[test]
fn colored_sweep_is_independent_of_the_thread_count() {
    let model = membrane(48);
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| run(&model, Relaxation::ColoredGaussSeidel, 10, 20));
    let four = pool(4).install(|| run(&model, Relaxation::ColoredGaussSeidel, 10, 20));
    let (lc, tc) = one.color_classes();
    assert!(lc >= 2 && tc >= 2, "{lc} link and {tc} triangle colours");
    assert_eq!(one.model().x, four.model().x);
    assert_eq!(one.model().v, four.model().v);
    assert_eq!(one.multipliers(), four.multipliers());
}

#[test]
fn relaxation_factors_out_of_range_are_rejected() {
    let model = membrane(3);
    for relaxation in [
        Relaxation::Jacobi { omega: 0.0 },
        Relaxation::Jacobi { omega: 1.5 },
        Relaxation::Sor { omega: 2.0 },
        Relaxation::Sor { omega: f64::NAN },
    ] {
        let cfg = SolverParams::default().relaxation(relaxation);
        let err = Simulation::new(model.clone(), cfg).unwrap_err().to_string();
        assert!(err.contains("omega"), "{err}");
    }
}
