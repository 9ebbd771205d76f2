//! Acceptance checks of paper 02 (cloth with soft constraints): the closed-form linear and
//! damped oscillators, iteration independence of
//! the accumulated multipliers, the relaxation identity, energy ordering and bad input.

use nalgebra::Vector3;
use wscg_cloth::{ClothModel, LambdaMode, Method, Simulation, SolverParams};
use wscg_math::vec3::{dist, sub};

const H: f64 = 1.0 / 60.0;

/// Largest absolute component of `p - q`.
fn amax(p: [f64; 3], q: [f64; 3]) -> f64 {
    sub(p, q).iter().fold(0.0, |m: f64, c| m.max(c.abs()))
}

/// One 1 kg particle on a link (k = 100 N/m, rest 1 m) to a pinned anchor, stretched 5 cm
/// along x, no gravity.
fn oscillator(cfg: SolverParams) -> Simulation {
    let mut m = ClothModel::new(vec![[0.0; 3], [1.05, 0.0, 0.0]], &[1.0, 1.0], &[0]).unwrap();
    m.gravity = [0.0; 3];
    m.add_link(0, 1, 100.0, Some(1.0)).unwrap();
    Simulation::new(m, cfg).unwrap()
}

fn state(sim: &Simulation) -> (f64, f64) {
    let m = sim.model();
    (m.x[1][0] - 1.0, m.v[1][0])
}

/// Check 1: the (alpha, beta) scheme reproduces its closed-form amplification.
#[test]
fn linear_oscillator_matches_closed_form() {
    let w2 = 100.0;
    for (alpha, beta) in [(1.0, 1.0), (0.6, 0.6), (0.55, 0.55), (0.5, 0.5)] {
        let mut runs = Vec::new();
        for iterations in [1, 25] {
            let mut sim = oscillator(
                SolverParams::default()
                    .alpha(alpha)
                    .beta(beta)
                    .iterations(iterations),
            );
            let (mut x, mut v) = (0.05, 0.0);
            for step in 0..1000 {
                let xn = ((1.0 - H * H * beta * (1.0 - alpha) * w2) * x + H * v)
                    / (1.0 + H * H * alpha * beta * w2);
                let vn = v - H * w2 * ((1.0 - alpha) * x + alpha * xn);
                (x, v) = (xn, vn);
                sim.step(H).unwrap();
                let (sx, sv) = state(&sim);
                let scale = 0.05f64.max(x.abs());
                assert!(
                    (sx - x).abs() <= 1e-12 * scale && (sv - v).abs() <= 1e-12 * scale / H,
                    "alpha {alpha} iterations {iterations} step {step}: ({sx}, {sv}) vs ({x}, {v})"
                );
            }
            runs.push(state(&sim));
        }
        // Linear problem: 1 and 25 accumulated iterations give the same state.
        assert!((runs[0].0 - runs[1].0).abs() <= 1e-14 && (runs[0].1 - runs[1].1).abs() <= 1e-13);
    }
    // alpha = beta = 1/2 conserves the oscillator's energy: drift < 1e-10 over 1e4 steps.
    let mut sim = oscillator(SolverParams::default().alpha(0.5).beta(0.5));
    let e0 = sim.energy().total;
    sim.run(H, 10_000).unwrap();
    let drift = (sim.energy().total - e0).abs() / e0;
    assert!(drift < 1e-10, "energy drift {drift}");
    // alpha = beta = 1: the state is the 2 x 2 step matrix to the power n, whose spectral
    // radius is (1 + w^2 h^2)^(-1/2).
    let mut sim = oscillator(SolverParams::default());
    let d = 1.0 + H * H * w2;
    let step = [[1.0 / d, H / d], [-H * w2 / d, 1.0 / d]];
    let (mut x, mut v) = (0.05, 0.0);
    for _ in 0..500 {
        (x, v) = (
            step[0][0] * x + step[0][1] * v,
            step[1][0] * x + step[1][1] * v,
        );
    }
    sim.run(H, 500).unwrap();
    let (sx, sv) = state(&sim);
    assert!((sx - x).abs() <= 1e-12 * 0.05 && (sv - v).abs() <= 1e-12 * 0.05 / H);
    // Eigenvalues of the step matrix have modulus det^(1/2) = (1 + w^2 h^2)^(-1/2).
    let det = step[0][0] * step[1][1] - step[0][1] * step[1][0];
    assert!((det.sqrt() - d.powf(-0.5)).abs() < 1e-15);
}

/// Check 2: constraint damping gamma = 10 h against its closed form.
#[test]
fn damped_oscillator_matches_closed_form() {
    let (w2, gamma) = (100.0, 10.0 * H);
    let mut sim = oscillator(SolverParams::default().gamma(gamma));
    let (mut x, mut v) = (0.05f64, 0.0f64);
    for step in 0..1000 {
        v = (v - H * w2 * x) / (1.0 + w2 * H * (H + gamma));
        x += H * v;
        sim.step(H).unwrap();
        let (sx, sv) = state(&sim);
        assert!(
            (sx - x).abs() <= 1e-12 * 0.05 && (sv - v).abs() <= 1e-12 * 0.05 / H,
            "step {step}: ({sx}, {sv}) vs ({x}, {v})"
        );
    }
}

/// Elongation of each link of a settled chain.
fn chain_elongations(iterations: usize, mode: LambdaMode) -> Vec<f64> {
    let model = ClothModel::chain(10, 0.1, 0.1, 100.0).unwrap();
    let mut sim = Simulation::new(
        model,
        SolverParams::default()
            .iterations(iterations)
            .gamma(0.1)
            .lambda_mode(mode),
    )
    .unwrap();
    sim.run(H, 30 * 60).unwrap();
    let m = sim.model();
    m.links
        .iter()
        .map(|l| dist(m.x[l.i], m.x[l.j]) - l.rest)
        .collect()
}

/// Check 3: with accumulated multipliers the static elongation is the spring's, whatever the
/// iteration count; the paper's printed update stiffens the chain as iterations grow.
#[test]
fn chain_elongation_is_iteration_independent_only_with_accumulation() {
    let (m, g, k) = (0.1, 9.81, 100.0);
    for iterations in [50, 500] {
        let e = chain_elongations(iterations, LambdaMode::Accumulate);
        for (j, ej) in e.iter().enumerate() {
            let below = (9 - j) as f64;
            let want = below * m * g / k;
            assert!(
                (ej - want).abs() <= 1e-6,
                "iterations {iterations}, link {j}: {ej} vs {want}"
            );
        }
    }
    let total = |it| -> f64 { chain_elongations(it, LambdaMode::PaperReset).iter().sum() };
    let (e1, e5, e25) = (total(1), total(5), total(25));
    println!("PaperReset total elongation: 1 it {e1:.6}, 5 it {e5:.6}, 25 it {e25:.6} m");
    assert!(e1 > e5 && e5 > e25, "{e1} {e5} {e25}");
    // The spring value is 0.1 * 9.81 * (9 + 8 + ... + 1) / 100 = 0.44145 m.
    assert!(e25 < 0.5 * 0.44145);
}

/// Check 5: one PaperReset iteration on a single link equals one plain-PBD projection with
/// relaxation w = (1 + (h^2 k A)^-1)^-1.
#[test]
fn paper_reset_iteration_is_relaxed_pbd() {
    let k = 250.0;
    let build = || {
        let mut m =
            ClothModel::new(vec![[0.0, 0.0, 0.0], [0.3, 0.9, 0.2]], &[0.5, 2.0], &[]).unwrap();
        m.gravity = [0.0; 3];
        m.add_link(0, 1, k, Some(0.7)).unwrap();
        m
    };
    let a = 1.0 / 0.5 + 1.0 / 2.0;
    let omega = 1.0 / (1.0 + 1.0 / (H * H * k * a));
    let mut soft = Simulation::new(
        build(),
        SolverParams::default()
            .iterations(1)
            .lambda_mode(LambdaMode::PaperReset),
    )
    .unwrap();
    let mut pbd = Simulation::new(
        build(),
        SolverParams::default()
            .iterations(1)
            .method(Method::PlainPbd { stiffness: omega }),
    )
    .unwrap();
    soft.step(H).unwrap();
    pbd.step(H).unwrap();
    for p in 0..2 {
        let d = dist(soft.model().x[p], pbd.model().x[p]);
        assert!(d <= 1e-14, "particle {p}: {d}");
    }
}

/// Check 8 (energy ordering, Fig. 4): the energy-preserving alpha = beta = 0.6 loses less
/// energy than regularized PBD (alpha = beta = 1) on a hanging 10 x 10 cloth with k = 2 N/m.
#[test]
fn alpha_beta_scheme_loses_less_energy_than_implicit_euler() {
    let loss = |ab: f64| {
        let model = ClothModel::grid(10, 10, (1.0, 1.0), 0.1, 2.0, Some(2.0), Some(2.0)).unwrap();
        let mut sim = Simulation::new(model, SolverParams::default().alpha(ab).beta(ab)).unwrap();
        let e0 = sim.energy().total;
        sim.run(H, 600).unwrap();
        e0 - sim.energy().total
    };
    let (l06, l1) = (loss(0.6), loss(1.0));
    println!("energy lost over 10 s: alpha = beta = 0.6: {l06:.5} J, 1.0: {l1:.5} J");
    assert!(l06 < l1 && l1 > 0.0);
}

#[test]
fn bad_input_is_rejected() {
    let ok = || oscillator(SolverParams::default());
    let mut sim = ok();
    assert!(sim.step(0.0).is_err() && sim.step(-H).is_err() && sim.step(f64::NAN).is_err());
    for cfg in [
        SolverParams::default().alpha(0.0),
        SolverParams::default().beta(1.5),
        SolverParams::default().gamma(-1.0),
        SolverParams::default().iterations(0),
        SolverParams::default().method(Method::PlainPbd { stiffness: 0.0 }),
    ] {
        assert!(
            Simulation::new(ok().model().clone(), cfg).is_err(),
            "{cfg:?}"
        );
    }
    let p = vec![[0.0; 3], [1.0, 0.0, 0.0]];
    assert!(ClothModel::new(p.clone(), &[1.0], &[]).is_err());
    assert!(ClothModel::new(p.clone(), &[1.0, -1.0], &[]).is_err());
    assert!(ClothModel::new(p.clone(), &[1.0, f64::NAN], &[]).is_err());
    assert!(ClothModel::new(p.clone(), &[1.0, 1.0], &[5]).is_err());
    assert!(ClothModel::new(vec![[f64::NAN, 0.0, 0.0]], &[1.0], &[]).is_err());
    assert!(ClothModel::new(Vec::new(), &[], &[]).is_err());
    let mut m = ClothModel::new(p, &[1.0, 1.0], &[]).unwrap();
    assert!(m.add_link(0, 0, 1.0, None).is_err());
    assert!(m.add_link(0, 2, 1.0, None).is_err());
    assert!(m.add_link(0, 1, 0.0, None).is_err());
    assert!(m.add_link(0, 1, 1.0, Some(0.0)).is_err());
    // A diverging step leaves the state unchanged.
    let mut m = ok().model().clone();
    m.links[0].compliance = 1e-300;
    m.x[1] = [1e300, 0.0, 0.0];
    let mut sim = Simulation::new(m.clone(), SolverParams::default()).unwrap();
    assert!(sim.step(H).is_err());
    assert_eq!(sim.model(), &m);
    assert_eq!(sim.steps(), 0);
}

/// The linearised implicit Euler baselines (CG and sparse Cholesky) are exact on the linear
/// oscillator: they equal the alpha = beta = 1 closed form.
#[test]
fn linearised_implicit_euler_matches_closed_form_on_linear_oscillator() {
    for method in [
        Method::ImplicitEulerCg {
            tol: 1e-14,
            max_iter: 50,
        },
        Method::ImplicitEulerDirect,
    ] {
        let mut sim = oscillator(SolverParams::default().method(method));
        let (mut x, mut v) = (0.05f64, 0.0f64);
        let d = 1.0 + H * H * 100.0;
        for _ in 0..300 {
            (x, v) = ((x + H * v) / d, (v - H * 100.0 * x) / d);
            sim.step(H).unwrap();
        }
        let (sx, sv) = state(&sim);
        assert!(
            (sx - x).abs() <= 1e-10 && (sv - v).abs() <= 1e-9,
            "{method:?}: ({sx}, {sv}) vs ({x}, {v})"
        );
    }
}

/// The Cholesky and CG solves of the linearised step agree on a membrane with links,
/// pinned particles and rollers.
#[test]
fn direct_and_cg_linearised_steps_agree() {
    let mut model = ClothModel::fem_grid(9, 9, (1.0, 1.0), 0.1, 800.0, 0.3).unwrap();
    model.add_link(0, 80, 300.0, None).unwrap();
    model
        .add_roller(40, [0.0, 0.0, 1.0], model.x[40][2])
        .unwrap();
    let run = |method| {
        let mut sim =
            Simulation::new(model.clone(), SolverParams::default().method(method)).unwrap();
        sim.run(H, 20).unwrap();
        sim.model().x.clone()
    };
    let cg = run(Method::ImplicitEulerCg {
        tol: 1e-14,
        max_iter: 5000,
    });
    let direct = run(Method::ImplicitEulerDirect);
    let d = cg
        .iter()
        .zip(&direct)
        .map(|(p, q)| amax(*p, *q))
        .fold(0.0, f64::max);
    assert!(d < 1e-10, "{d}");
    assert!(
        (direct[40][2] - model.x[40][2]).abs() < 1e-12,
        "roller violated"
    );
    assert!(direct[80][1] < -0.1, "the cloth did not fall");
}

/// Check 8, reference part: symplectic Euler with h/64 substeps keeps the hanging cloth's
/// energy within 1 % over 10 s.
#[test]
fn symplectic_euler_reference_conserves_energy() {
    let model = ClothModel::grid(10, 10, (1.0, 1.0), 0.1, 2.0, Some(2.0), Some(2.0)).unwrap();
    let mut sim = Simulation::new(
        model,
        SolverParams::default().method(Method::SymplecticEuler { substeps: 64 }),
    )
    .unwrap();
    let e0 = sim.energy();
    let mut swing = 0.0f64;
    for _ in 0..600 {
        sim.step(H).unwrap();
        swing = swing.max((sim.energy().gravity - e0.gravity).abs());
    }
    let drift = (sim.energy().total - e0.total).abs();
    println!("symplectic Euler: |E(10 s) - E(0)| = {drift:.3e} J, gravity swing {swing:.3} J");
    assert!(drift < 0.01 * swing, "drift {drift} vs swing {swing}");
}

/// The velocity-projection baseline scales a link's relative velocity along the link by
/// `1 - k_d` and leaves the rest of the motion alone.
#[test]
fn velocity_projection_scales_relative_normal_velocity() {
    let run = |kd: f64| {
        let mut m = ClothModel::new(vec![[0.0; 3], [1.0, 0.0, 0.0]], &[1.0, 3.0], &[]).unwrap();
        m.gravity = [0.0; 3];
        m.v = vec![[-0.5, 0.2, 0.0], [0.7, -0.1, 0.3]];
        m.add_link(0, 1, 50.0, Some(1.0)).unwrap();
        let mut sim = Simulation::new(m, SolverParams::default().velocity_damping(kd)).unwrap();
        sim.step(H).unwrap();
        sim.model().clone()
    };
    let (a, b) = (run(0.0), run(0.4));
    let v = |m: &ClothModel, q: usize| Vector3::from(m.v[q]);
    let n = (Vector3::from(a.x[1]) - Vector3::from(a.x[0])).normalize();
    let rel = |m: &ClothModel| n.dot(&(v(m, 1) - v(m, 0)));
    assert!((rel(&b) - 0.6 * rel(&a)).abs() < 1e-13);
    // Momentum and tangential motion are unchanged.
    let p = |m: &ClothModel| v(m, 0) * 1.0 + v(m, 1) * 3.0;
    assert!((p(&a) - p(&b)).norm() < 1e-13);
    let t = |m: &ClothModel| (v(m, 1) - v(m, 0)) - n * rel(m);
    assert!((t(&a) - t(&b)).norm() < 1e-13);
    assert!(Simulation::new(
        ClothModel::chain(3, 0.1, 0.1, 10.0).unwrap(),
        SolverParams::default().velocity_damping(1.5)
    )
    .is_err());
}

/// Check 10: Conjugate Residuals on the constraint-space system of a 20 x 20 cloth (links
/// and membrane triangles): monotone residual, 1e-10 within m iterations, and the dense
/// solution to 1e-9.
#[test]
fn conjugate_residual_on_constraint_space_system() {
    use faer::linalg::solvers::Solve;
    use wscg_cloth::constraint_space::ConstraintSystem;
    use wscg_math::sparse::{conjugate_residual, InitialGuess, PcgParams};
    for fem in [false, true] {
        let mut model = if fem {
            ClothModel::fem_grid(20, 20, (1.0, 1.0), 0.1, 1000.0, 0.3).unwrap()
        } else {
            ClothModel::grid(20, 20, (1.0, 1.0), 0.1, 2000.0, Some(500.0), Some(50.0)).unwrap()
        };
        // A deformed state: let the cloth fall for a few steps.
        let cfg = SolverParams::default();
        let mut sim = Simulation::new(model.clone(), cfg).unwrap();
        sim.run(H, 20).unwrap();
        model = sim.model().clone();
        let sys = ConstraintSystem::new(&model, &model.x, H * H);
        let m = sys.len();
        let b: Vec<f64> = (0..m)
            .map(|i| ((i * 37) % 11) as f64 * 1e-3 - 5e-3)
            .collect();
        let cr = conjugate_residual(
            &sys,
            &b,
            InitialGuess::Zero,
            &PcgParams::default().tol(1e-10).max_iter(Some(m)),
        )
        .unwrap();
        assert!(cr.converged, "fem {fem}: {} iterations", cr.iterations);
        assert!(cr
            .residuals
            .windows(2)
            .all(|w| w[1] <= w[0] * (1.0 + 1e-10)));
        let dense = sys.dense();
        let a = faer::Mat::from_fn(m, m, |i, j| dense[i * m + j]);
        let rhs = faer::Mat::from_fn(m, 1, |i, _| b[i]);
        let x = a.partial_piv_lu().solve(&rhs);
        let err = (0..m)
            .map(|i| (x[(i, 0)] - cr.x[i]).abs())
            .fold(0.0, f64::max);
        let scale = (0..m).map(|i| x[(i, 0)].abs()).fold(0.0, f64::max);
        println!(
            "fem {fem}: m = {m}, CR iterations {}, max error {err:.2e} (|x| {scale:.2e})",
            cr.iterations
        );
        assert!(err <= 1e-9 * scale.max(1.0), "fem {fem}: {err}");
    }
}

/// Check 4: the paper's central claim, projection of soft constraints = implicit Euler.
/// One step of a perturbed 10 x 10 link cloth (k = 2000 N/m) against the Newton minimiser
/// of the incremental potential.
#[test]
fn soft_projection_equivalence_with_implicit_euler() {
    use wscg_cloth::newton::{incremental_potential, inertial_target};
    let mut model =
        ClothModel::grid(10, 10, (1.0, 1.0), 0.1, 2000.0, Some(2000.0), Some(2000.0)).unwrap();
    let r = wscg_math::rng::uniform_vec(5, 3 * 100, -1.0, 1.0).unwrap();
    for q in 0..100 {
        if model.inv_mass[q] > 0.0 {
            model.v[q] =
                (Vector3::new(r[3 * q], r[3 * q + 1], r[3 * q + 2]).normalize() * 0.5).into();
        }
    }
    let one_step = |method: Method, iterations: usize| {
        let mut sim = Simulation::new(
            model.clone(),
            SolverParams::default()
                .method(method)
                .iterations(iterations),
        )
        .unwrap();
        sim.step(H).unwrap();
        sim.model().x.clone()
    };
    let dist = |a: &[[f64; 3]], b: &[[f64; 3]]| {
        a.iter()
            .zip(b)
            .map(|(p, q)| amax(*p, *q))
            .fold(0.0, f64::max)
    };
    let reference = one_step(Method::ImplicitEulerNewton { tol: 1e-10 }, 1);
    let xt = inertial_target(&model, H);
    let disp = dist(&reference, &model.x);
    let phi = |x: &[[f64; 3]]| incremental_potential(&model, x, &xt, H);

    let global = one_step(
        Method::GlobalCr {
            primal_residual: true,
            tol: 1e-13,
        },
        60,
    );
    let d_global = dist(&global, &reference);
    let xpbd = one_step(Method::SoftProjection, 2000);
    let d_xpbd = dist(&xpbd, &reference);
    let linear = one_step(
        Method::ImplicitEulerCg {
            tol: 1e-12,
            max_iter: 5000,
        },
        1,
    );
    let d_linear = dist(&linear, &reference);
    let direct = one_step(Method::ImplicitEulerDirect, 1);
    let d_direct = dist(&direct, &reference);
    assert!(dist(&direct, &linear) < 1e-10);
    let ncg = one_step(
        Method::Ncg {
            variant: wscg_cloth::NcgVariant::Consistent,
        },
        3000,
    );
    let d_ncg = dist(&ncg, &reference);
    println!(
        "step displacement {disp:.3e} m; distance to the IE minimiser: global CR (primal) \
         {d_global:.2e} m, XPBD GS converged {d_xpbd:.2e} m ({:.1} % of the step, Phi higher by \
         {:.3e}), linearised IE {d_linear:.2e} m (CG), {d_direct:.2e} m (Cholesky), NCG \
         consistent {d_ncg:.2e} m",
        100.0 * d_xpbd / disp,
        phi(&xpbd) - phi(&reference)
    );
    assert!(d_global <= 1e-8, "global CR {d_global}");
    assert!(d_ncg <= 1e-7, "NCG {d_ncg}");
    assert!(phi(&xpbd) >= phi(&reference) - 1e-12);
    assert!(phi(&linear) >= phi(&reference) - 1e-12);
}

/// Kinetic + gravitational energy ("total - elastic", the paper's Fig. 5) over 3 s of a
/// 40 x 40 cloth with k = 2000 N/m and 25 iterations.
fn swing_curve(cfg: SolverParams) -> Vec<f64> {
    let model =
        ClothModel::grid(40, 40, (1.0, 1.0), 0.1, 2000.0, Some(2000.0), Some(2000.0)).unwrap();
    let mut sim = Simulation::new(model, cfg).unwrap();
    let mut out = Vec::with_capacity(181);
    let e = sim.energy();
    out.push(e.kinetic + e.gravity);
    for _ in 0..180 {
        sim.step(H).unwrap();
        let e = sim.energy();
        out.push(e.kinetic + e.gravity);
    }
    out
}

/// Steps until `|E(t) - E(end)|` stays below 10 % of its largest value.
fn settle_steps(curve: &[f64]) -> usize {
    let end = *curve.last().unwrap();
    let dev: Vec<f64> = curve.iter().map(|e| (e - end).abs()).collect();
    let peak = dev.iter().cloned().fold(0.0, f64::max);
    dev.iter()
        .rposition(|&d| d > 0.1 * peak)
        .map_or(0, |i| i + 1)
}

/// Check 9 (Fig. 5): constraint damping gamma = 10 h settles the swing at least twice as
/// fast as no damping; the velocity-projection baseline tuned to the same constraint
/// violation is slower.
///
/// Not met on this machine's implementation: with the settling measure below (steps until
/// the deviation of kinetic + gravitational energy from its 3 s value stays under 10 % of its
/// peak) gamma = 0 takes 137 steps, gamma = 10 h 111 (1.23x), velocity projection 0.5 136.
/// The cloth's swing is a rigid pendulum-like motion that damping along the constraints does
/// not touch, and 25 Gauss-Seidel sweeps of implicit Euler already damp the strain modes.
#[test]
#[ignore = "check 9 not met: 1.23x faster settling with gamma = 10h, 2x required"]
fn constraint_damping_settles_faster() {
    let plain = settle_steps(&swing_curve(SolverParams::default()));
    let damped = settle_steps(&swing_curve(SolverParams::default().gamma(10.0 * H)));
    let projected = settle_steps(&swing_curve(SolverParams::default().velocity_damping(0.5)));
    println!("steps to settle: gamma = 0: {plain}, gamma = 10h: {damped}, velocity projection 0.5: {projected}");
    assert!(2 * damped <= plain, "{damped} vs {plain}");
}

/// Meshes: area-lumped masses, edge and bending links, membrane triangles, bad faces.
#[test]
fn cloth_from_triangle_mesh() {
    let v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
    ];
    let f = [[0, 1, 2], [0, 2, 3]];
    let m = ClothModel::from_trimesh(&v, &f, 0.6, None, 100.0, Some(1.0)).unwrap();
    let mass: Vec<f64> = m.inv_mass.iter().map(|w| 1.0 / w).collect();
    for (got, want) in mass.iter().zip([0.2, 0.1, 0.2, 0.1]) {
        assert!((got - want).abs() < 1e-12, "{mass:?}");
    }
    // Five edges and one bending link across the shared diagonal (vertices 1 and 3).
    assert_eq!(m.links.len(), 6);
    assert!(m
        .links
        .iter()
        .any(|l| (l.i, l.j) == (1, 3) && (l.compliance - 1.0).abs() < 1e-15));
    let fem = ClothModel::from_trimesh(&v, &f, 0.6, Some((500.0, 0.3)), 0.0, None).unwrap();
    assert_eq!((fem.links.len(), fem.tris.len()), (0, 2));
    assert!(fem.tris.iter().all(|t| (t.area - 0.5).abs() < 1e-12));
    assert!(ClothModel::from_trimesh(&v, &[], 0.6, None, 1.0, None).is_err());
    assert!(ClothModel::from_trimesh(&v, &[[0, 1, 7]], 0.6, None, 1.0, None).is_err());
    assert!(ClothModel::from_trimesh(&v, &[[0, 1, 1]], 0.6, None, 1.0, None).is_err());
    assert!(ClothModel::from_trimesh(&v, &[[0, 1, 2]], 0.6, None, 1.0, None).is_err()); // vertex 3 unused
    assert!(ClothModel::from_trimesh(&v, &f, -1.0, None, 1.0, None).is_err());
}
