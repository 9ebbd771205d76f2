//! Time stepping.
//!
//! **Soft projection** (paper sections 4-6; eqs. 17 and 20 as one update, with the factor
//! `beta` that eq. 20 leaves out of `S` and the accumulated multiplier below). The unified
//! scheme `M (v' - v)/h = f_ext + (1 - alpha) f(x) + alpha f(x')`,
//! `(x' - x)/h = (1 - beta) v + beta v'` with `alpha, beta` in `(0, 1]` (`alpha = beta = 1`:
//! implicit Euler, i.e. regularized PBD; `1/2`: implicit midpoint) starts from the candidate
//! `x~ = x + h v + h^2 g + h^2 beta (1 - alpha) W f(x)`, `v~ = v + h g + h (1 - alpha) W f(x)`
//! (paper section 5, with `f(x) = sum J' lambda`, `lambda = -c / eps` for soft links) and then
//! projects every constraint in turn (Gauss-Seidel):
//!
//! `S dl = -(alpha (c(x) + gamma J v) + Lambda)`, `S = alpha h (beta h + gamma) J W J' + eps`,
//! `x += beta h^2 W J' dl`, `v += h W J' dl`,
//!
//! with `Lambda = eps lambda_acc` in [`LambdaMode::Accumulate`] (the multiplier accumulated
//! over the step's iterations, the XPBD-consistent form whose fixed point satisfies the soft
//! constraint `c + eps lambda = 0`, so the material stiffness does not depend on the number of
//! iterations) or `Lambda = 0` in [`LambdaMode::PaperReset`] (the paper's eqs. 13 and 17 as
//! printed: iterating to convergence drives `c` to 0, so the cloth stiffens with the
//! iteration count). With `gamma = 0` this is the paper's eq. 17, with `beta = 1` its eq. 20;
//! `gamma` adds the paper's damping along the constraint directions (section 6).
//!
//! **Plain PBD** (Mueller et al. 2007, the baseline): hard projection scaled by a stiffness
//! factor `k' = 1 - (1 - k)^(1/N)` per iteration, velocities `(x' - x)/h`.

use nalgebra::Vector3;
use wscg_math::{Error, Result};

use crate::baselines::{self, LinearSolve};
use crate::collision::{CollisionState, Collisions};
use crate::energy::Energy;
use crate::model::ClothModel;
use crate::projection::{self, Prepared, Relaxation, StepConsts, VelocityFrame};
pub use crate::system::StepStats;
use crate::system::Stepped;
use crate::vecs::{into_arrays, V3};

/// How the constraint multipliers enter each iteration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum LambdaMode {
    /// `Lambda = eps lambda_acc` (default): iteration-count independent stiffness.
    #[default]
    Accumulate,
    /// `Lambda = 0`, the paper's printed equations (stiffness grows with iterations).
    PaperReset,
}

/// The integrator.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Method {
    /// Projection of soft constraints with the `alpha`/`beta` scheme (the paper's method).
    SoftProjection,
    /// Position-based dynamics with a stiffness factor in `(0, 1]` (baseline).
    PlainPbd {
        /// PBD stiffness `k` in `(0, 1]`.
        stiffness: f64,
    },
    /// Symplectic Euler with `substeps` explicit substeps per step (energy reference).
    SymplecticEuler {
        /// Substeps per step (>= 1).
        substeps: usize,
    },
    /// Global solves of the constraint-space system by Conjugate Residuals (paper section
    /// 7), `iterations` outer iterations, `alpha = beta = 1`, `gamma = 0`; with `primal_residual` the
    /// momentum residual is kept and the result is exact implicit Euler.
    GlobalCr {
        /// Keep the momentum residual (exact implicit Euler).
        primal_residual: bool,
        /// Relative tolerance of each CR solve.
        tol: f64,
    },
    /// The paper's nonlinear conjugate gradient implicit solver (Algorithm 1), `iterations`
    /// iterations.
    Ncg {
        /// Residual variant.
        variant: crate::ncg::NcgVariant,
    },
    /// Exact implicit Euler: Newton's method on the incremental potential to a relative
    /// gradient tolerance `tol` (the reference of the paper's section 2).
    ImplicitEulerNewton {
        /// Relative gradient tolerance (e.g. 1e-10).
        tol: f64,
    },
    /// One linearised implicit Euler step solved by a sparse Cholesky factorisation (the
    /// paper's "exact" baseline).
    ImplicitEulerDirect,
    /// One linearised implicit Euler step solved by conjugate gradients (baseline).
    ImplicitEulerCg {
        /// Relative residual tolerance.
        tol: f64,
        /// Iteration cap.
        max_iter: usize,
    },
}

wscg_math::params! {
    /// Parameters of a [`Simulation`].
    #[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    pub struct SolverParams {
        /// Integrator (default soft projection).
        pub method: Method,
        /// Gauss-Seidel sweeps per step (25 in the paper's experiments).
        pub iterations: usize,
        /// Force blending `alpha` in `(0, 1]` (1: implicit Euler).
        pub alpha: f64,
        /// Position blending `beta` in `(0, 1]` (1: implicit Euler).
        pub beta: f64,
        /// Constraint damping `gamma = d/k` in seconds (>= 0).
        pub gamma: f64,
        /// Multiplier mode (default accumulate).
        pub lambda_mode: LambdaMode,
        /// Velocity-projection damping factor `k_d` in `[0, 1]` applied after each step (the
        /// baseline of the paper's Fig. 5; default 0).
        pub velocity_damping: f64,
        /// How each sweep of the soft projection visits the constraints (default sequential
        /// Gauss-Seidel).
        pub relaxation: Relaxation,
    }
}

impl Default for SolverParams {
    fn default() -> Self {
        Self {
            method: Method::SoftProjection,
            iterations: 25,
            alpha: 1.0,
            beta: 1.0,
            gamma: 0.0,
            lambda_mode: LambdaMode::Accumulate,
            velocity_damping: 0.0,
            relaxation: Relaxation::GaussSeidel,
        }
    }
}

impl SolverParams {
    /// Checks the parameter ranges: `alpha` and `beta` in `(0, 1]`, `gamma` finite and
    /// `>= 0`, `iterations >= 1`, `velocity_damping` in `[0, 1]`, and the settings inside
    /// `method` and `relaxation` (each error names the setting, such as `stiffness`, `tol`,
    /// `substeps` or `omega`).
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("alpha", self.alpha), ("beta", self.beta)] {
            if !(v > 0.0 && v <= 1.0) {
                return Err(Error::invalid(name, format!("must be in (0, 1], got {v}")));
            }
        }
        if !(self.gamma >= 0.0 && self.gamma.is_finite()) {
            return Err(Error::invalid(
                "gamma",
                format!("must be finite and >= 0, got {}", self.gamma),
            ));
        }
        if self.iterations == 0 {
            return Err(Error::invalid("iterations", "must be >= 1"));
        }
        match self.method {
            Method::PlainPbd { stiffness } if !(stiffness > 0.0 && stiffness <= 1.0) => {
                return Err(Error::invalid(
                    "stiffness",
                    format!("PBD stiffness must be in (0, 1], got {stiffness}"),
                ))
            }
            Method::GlobalCr { tol, .. } if !(tol.is_finite() && tol > 0.0) => {
                return Err(Error::invalid(
                    "tol",
                    format!("the global CR solve needs a finite tol > 0, got {tol}"),
                ))
            }
            Method::GlobalCr { .. }
                if self.alpha != 1.0 || self.beta != 1.0 || self.gamma != 0.0 =>
            {
                return Err(Error::invalid(
                    "method",
                    "the global CR solve needs tol > 0, alpha = beta = 1 and gamma = 0",
                ))
            }
            Method::ImplicitEulerNewton { tol } if !(tol.is_finite() && tol > 0.0) => {
                return Err(Error::invalid(
                    "tol",
                    format!("Newton tolerance must be finite and > 0, got {tol}"),
                ))
            }
            Method::SymplecticEuler { substeps: 0 } => {
                return Err(Error::invalid("substeps", "must be >= 1"))
            }
            Method::ImplicitEulerCg { tol, .. } if !(tol.is_finite() && tol > 0.0) => {
                return Err(Error::invalid(
                    "tol",
                    format!("CG needs a finite tol > 0, got {tol}"),
                ))
            }
            Method::ImplicitEulerCg { max_iter: 0, .. } => {
                return Err(Error::invalid("max_iter", "CG needs max_iter >= 1, got 0"))
            }
            _ => {}
        }
        match self.relaxation {
            Relaxation::Jacobi { omega } if !(omega > 0.0 && omega <= 1.0) => {
                return Err(Error::invalid(
                    "omega",
                    format!("Jacobi relaxation factor must be in (0, 1], got {omega}"),
                ))
            }
            Relaxation::Sor { omega } if !(omega > 0.0 && omega < 2.0) => {
                return Err(Error::invalid(
                    "omega",
                    format!("SOR relaxation factor must be in (0, 2), got {omega}"),
                ))
            }
            _ => {}
        }
        if !(0.0..=1.0).contains(&self.velocity_damping) {
            return Err(Error::invalid(
                "velocity_damping",
                format!("must be in [0, 1], got {}", self.velocity_damping),
            ));
        }
        Ok(())
    }
}

/// A running simulation.
///
/// It serialises with `serde` as its state (model, parameters, multipliers of the last step,
/// step count, collision settings); deserialising rebuilds the derived data, so that the
/// deserialised simulation steps exactly as the original would.
#[derive(Clone, Debug)]
pub struct Simulation {
    model: ClothModel,
    cfg: SolverParams,
    /// Multipliers of the last step: one per link (N), then three per triangle.
    lambda: Vec<f64>,
    steps: u64,
    /// The constraints in the layout of the projection sweeps.
    prep: Prepared,
    /// Obstacles and self-collision settings.
    collisions: CollisionState,
}

/// The serialised state of a [`Simulation`] (borrowed to serialise).
#[derive(serde::Serialize)]
struct StateRef<'a> {
    model: &'a ClothModel,
    cfg: &'a SolverParams,
    lambda: &'a [f64],
    steps: u64,
    collisions: &'a Collisions,
}

/// The serialised state of a [`Simulation`], as [`StateRef`] writes it.
#[derive(serde::Deserialize)]
struct State {
    model: ClothModel,
    cfg: SolverParams,
    lambda: Vec<f64>,
    steps: u64,
    collisions: Collisions,
}

impl serde::Serialize for Simulation {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        StateRef {
            model: &self.model,
            cfg: &self.cfg,
            lambda: &self.lambda,
            steps: self.steps,
            collisions: &self.collisions.settings,
        }
        .serialize(s)
    }
}

impl<'de> serde::Deserialize<'de> for Simulation {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let State {
            model,
            cfg,
            lambda,
            steps,
            collisions,
        } = State::deserialize(d)?;
        let restore = || -> Result<Self> {
            let mut sim = Self::new(model, cfg)?;
            if lambda.len() != sim.lambda.len() {
                return Err(Error::invalid(
                    "lambda",
                    format!(
                        "{} multipliers for {} constraint rows",
                        lambda.len(),
                        sim.lambda.len()
                    ),
                ));
            }
            sim.lambda = lambda;
            sim.steps = steps;
            sim.set_collisions(collisions)?;
            Ok(sim)
        };
        restore().map_err(serde::de::Error::custom)
    }
}

impl Simulation {
    /// A simulation of `model` with `cfg`. Errors: invalid model or parameters.
    pub fn new(model: ClothModel, cfg: SolverParams) -> Result<Self> {
        model.validate()?;
        cfg.validate()?;
        let lambda = vec![0.0; model.constraint_rows()];
        let prep = Prepared::new(&model, cfg.relaxation == Relaxation::ColoredGaussSeidel);
        Ok(Self {
            model,
            cfg,
            lambda,
            steps: 0,
            prep,
            collisions: CollisionState::default(),
        })
    }

    /// The current state.
    pub fn model(&self) -> &ClothModel {
        &self.model
    }

    /// The configuration.
    pub fn config(&self) -> &SolverParams {
        &self.cfg
    }

    /// Multipliers of the last step: one per link (N), then `(uu, vv, uv)` per triangle.
    pub fn multipliers(&self) -> &[f64] {
        &self.lambda
    }

    /// The rollers' reaction forces of the last step (N, along each roller's unit normal, in
    /// the order the rollers were added): the rollers' rows of [`Simulation::multipliers`].
    /// The soft projection's multiplier of a roller is its force (the position correction
    /// is `h^2 w n lambda`, paper section 5); the implicit Euler steps (linearised, Newton
    /// and the global constraint solve), which keep particles on rollers in their planes by
    /// velocity filters, report the constraint force of the step,
    /// `n . (m (v1 - v0) / h - m g - f(x1))`, split over the particle's rollers (for Newton
    /// and the global solve: the normal part of the momentum residual at convergence). At
    /// rest the reactions balance gravity and the elastic forces.
    pub fn roller_forces(&self) -> &[f64] {
        &self.lambda[self.lambda.len() - self.model.rollers.len()..]
    }

    /// Sets the obstacles and self-collision handling (the projection integrators, soft and
    /// plain PBD, solve contacts in their iteration loop).
    ///
    /// Errors: invalid settings, or an integrator without contact handling.
    pub fn set_collisions(&mut self, collisions: Collisions) -> Result<()> {
        collisions.validate()?;
        let projection = matches!(
            self.cfg.method,
            Method::SoftProjection | Method::PlainPbd { .. }
        );
        if collisions.is_active() && !projection {
            return Err(Error::invalid(
                "collisions",
                "contacts are solved by the projection integrators (soft, pbd) only",
            ));
        }
        self.collisions = CollisionState::new(collisions, &self.model);
        Ok(())
    }

    /// The collision settings.
    pub fn collisions(&self) -> &Collisions {
        &self.collisions.settings
    }

    /// Number of colour classes of the links and of the triangles used by
    /// [`Relaxation::ColoredGaussSeidel`].
    pub fn color_classes(&self) -> (usize, usize) {
        self.prep.colors()
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Energy of the current state.
    pub fn energy(&self) -> Energy {
        Energy::of(&self.model)
    }

    /// Advances by `h` seconds. Errors: `h` not positive and finite; a non-finite result or a
    /// cancellation ([`wscg_math::cancel`]; the state is then left unchanged).
    pub fn step(&mut self, h: f64) -> Result<StepStats> {
        if !(h > 0.0 && h.is_finite()) {
            return Err(Error::invalid("h", format!("must be positive, got {h}")));
        }
        let Stepped {
            x,
            mut v,
            lambda,
            stats,
        } = match self.cfg.method {
            Method::SoftProjection => Self::soft_projection(
                &self.model,
                &self.cfg,
                &self.lambda,
                &mut self.prep,
                &self.collisions,
                h,
            ),
            Method::PlainPbd { stiffness } => self.plain_pbd(h, stiffness),
            Method::SymplecticEuler { substeps } => {
                baselines::symplectic_euler(&self.model, h, substeps)?
            }
            Method::ImplicitEulerCg { tol, max_iter } => baselines::implicit_euler_linearised(
                &self.model,
                h,
                LinearSolve::Cg { tol, max_iter },
            )?,
            Method::ImplicitEulerDirect => {
                baselines::implicit_euler_linearised(&self.model, h, LinearSolve::Cholesky)?
            }
            Method::ImplicitEulerNewton { tol } => crate::newton::step(&self.model, h, tol)?,
            Method::Ncg { variant } => {
                crate::ncg::step(&self.model, h, self.cfg.iterations, variant)?
            }
            Method::GlobalCr {
                primal_residual,
                tol,
            } => crate::constraint_space::global_step(
                &self.model,
                h,
                self.cfg.iterations,
                tol,
                primal_residual,
            )?,
        };
        // A step whose iterations a cancellation request cut short is dropped: the state is
        // left as it was.
        wscg_math::cancel::check()?;
        if self.cfg.velocity_damping > 0.0 {
            baselines::project_velocities(&self.model, &x, &mut v, self.cfg.velocity_damping);
        }
        let finite = |p: &[Vector3<f64>]| p.iter().all(|q| q.iter().all(|c| c.is_finite()));
        if !(finite(&x) && finite(&v)) {
            return Err(Error::Numerical(format!(
                "the simulation diverged at step {} (non-finite state); state left unchanged",
                self.steps
            )));
        }
        let mut lambda = lambda;
        if matches!(
            self.cfg.method,
            Method::ImplicitEulerCg { .. }
                | Method::ImplicitEulerDirect
                | Method::ImplicitEulerNewton { .. }
                | Method::GlobalCr { .. }
        ) {
            // The velocity filters enforce the rollers without multipliers: their rows get
            // the constraint force of the step.
            let r0 = lambda.len() - self.model.rollers.len();
            crate::system::roller_reactions(&self.model, &x, &v, h, &mut lambda[r0..]);
        }
        self.model.x = into_arrays(x);
        self.model.v = into_arrays(v);
        self.lambda = lambda;
        self.steps += 1;
        Ok(stats)
    }

    /// Runs `n` steps of `h`.
    pub fn run(&mut self, h: f64, n: usize) -> Result<()> {
        for _ in 0..n {
            self.step(h)?;
        }
        Ok(())
    }

    fn soft_projection(
        m: &ClothModel,
        cfg: &SolverParams,
        stored_lambda: &[f64],
        prep: &mut Prepared,
        collisions: &CollisionState,
        h: f64,
    ) -> Stepped {
        let SolverParams {
            alpha,
            beta,
            gamma,
            lambda_mode,
            iterations,
            ..
        } = *cfg;
        // Elastic force at x^n: soft links from -c/eps, hard links from the stored multiplier.
        let (xn, vn, g) = (m.xs(), m.vs(), m.g());
        let mut f = vec![Vector3::zeros(); m.len()];
        if alpha < 1.0 {
            for (l, &stored) in m.links.iter().zip(stored_lambda) {
                let d = xn[l.i] - xn[l.j];
                let len = d.norm();
                if len < 1e-12 {
                    continue;
                }
                let lam = if l.compliance > 0.0 {
                    -(len - l.rest) / l.compliance
                } else {
                    stored
                };
                let g = d * (lam / len);
                f[l.i] += g;
                f[l.j] -= g;
            }
            for t in &m.tris {
                crate::fem::add_forces(t, xn, &mut f);
            }
            let r0 = m.links.len() + 3 * m.tris.len();
            for (r, &stored) in m.rollers.iter().zip(&stored_lambda[r0..]) {
                f[r.p] += V3::from(r.normal) * stored;
            }
        }
        let (mut x, mut v): (Vec<Vector3<f64>>, Vec<Vector3<f64>>) = xn
            .iter()
            .zip(vn)
            .zip(&m.inv_mass)
            .zip(&f)
            .map(|(((xp, vp), &w), fp)| {
                if w > 0.0 {
                    let dx = g + fp * (beta * (1.0 - alpha) * w);
                    let dv = g + fp * ((1.0 - alpha) * w);
                    (xp + vp * h + dx * (h * h), vp + dv * h)
                } else {
                    (xp + vp * h, *vp)
                }
            })
            .unzip();
        let x0 = x.clone();
        let contacts = collisions.detect(m, &x);
        let mut max_penetration = 0.0;
        let mut lambda = vec![0.0; m.constraint_rows()];
        let omega = match cfg.relaxation {
            Relaxation::Jacobi { omega } | Relaxation::Sor { omega } => omega,
            _ => 1.0,
        };
        let k = StepConsts {
            alpha,
            s_coef: alpha * h * (beta * h + gamma),
            sx: beta * h * h,
            gamma,
            inv_bh: 1.0 / (beta * h),
            accumulate: lambda_mode == LambdaMode::Accumulate,
            omega,
        };
        prep.prepare_step(&k, &m.inv_mass);
        let vf = VelocityFrame { x0: &x0, v0: &v };
        let r0 = m.links.len() + 3 * m.tris.len();
        let mut scratch = Vec::new();
        let mut max_residual = 0.0;
        let prep = &*prep;
        let mut sweeps = || {
            for _ in 0..iterations {
                if wscg_math::cancel::requested() {
                    break;
                }
                let (lam_el, lam_roll) = lambda.split_at_mut(r0);
                max_residual =
                    projection::sweep(prep, cfg.relaxation, &mut x, &mut scratch, lam_el, &k, vf);
                let r = projection::project_rollers(m, &mut x, lam_roll, &k, vf);
                max_residual = max_residual.max(r);
                max_penetration = collisions.project(&contacts, m, &mut x);
            }
        };
        if cfg.relaxation == Relaxation::ColoredGaussSeidel {
            // Run the sweeps on a worker of the thread pool, so that each colour class is a
            // cheap fork-join rather than a hand-off from an outside thread.
            rayon::scope(|_| sweeps());
        } else {
            sweeps();
        }
        // v = v~ + (x - x~) / (beta h): the velocity updates of all corrections at once.
        for ((vp, xp), x0p) in v.iter_mut().zip(&x).zip(&x0) {
            *vp += (xp - x0p) * k.inv_bh;
        }
        Stepped::projected(x, v, lambda, max_residual, &contacts, max_penetration)
    }

    fn plain_pbd(&self, h: f64, stiffness: f64) -> Stepped {
        let m = &self.model;
        let n_it = self.cfg.iterations;
        let k_it = 1.0 - (1.0 - stiffness).powf(1.0 / n_it as f64);
        let (xn, vn) = (m.xs(), m.vs());
        let mut x: Vec<Vector3<f64>> = (0..m.len())
            .map(|p| {
                let g = if m.inv_mass[p] > 0.0 {
                    m.g()
                } else {
                    Vector3::zeros()
                };
                xn[p] + (vn[p] + g * h) * h
            })
            .collect();
        let contacts = self.collisions.detect(m, &x);
        let mut max_residual = 0.0f64;
        let mut max_penetration = 0.0;
        for it in 0..n_it {
            for l in &m.links {
                let (wi, wj) = (m.inv_mass[l.i], m.inv_mass[l.j]);
                let a = wi + wj;
                let d = x[l.i] - x[l.j];
                let len = d.norm();
                if len < 1e-12 || a <= 0.0 {
                    continue;
                }
                let c = len - l.rest;
                if it + 1 == n_it {
                    max_residual = max_residual.max(c.abs());
                }
                let dp = d * (k_it * c / (a * len));
                x[l.i] -= dp * wi;
                x[l.j] += dp * wj;
            }
            max_penetration = self.collisions.project(&contacts, m, &mut x);
        }
        let v = x.iter().zip(xn).map(|(a, b)| (a - b) / h).collect();
        let lambda = vec![0.0; m.constraint_rows()];
        Stepped::projected(x, v, lambda, max_residual, &contacts, max_penetration)
    }
}
