//! # wscg-cloth
//!
//! Paper 02 of WSCG vol. 23: Francu and Moldoveanu, "Cloth Simulation Using Soft Constraints".
//! Implicit Euler on stiff springs and the projection of *regularized* constraints
//! `c(x) + eps lambda = 0` (`eps = 1/k`) solve the same problem (section 2); on that result the
//! paper builds a one-parameter family of projection integrators (`alpha`, `beta`, sections
//! 5-6) that loses less energy than implicit Euler, and a damping along the constraint
//! directions.
//!
//! - [`model`]: particles, pinned vertices and link constraints, with builders for grids and
//!   chains.
//! - [`fem`]: StVK membrane triangles as soft constraints (section 9).
//! - [`ncg`]: the paper's nonlinear conjugate gradient implicit solver (Algorithm 1).
//! - [`newton`]: exact implicit Euler, the Newton minimiser of the incremental potential
//!   (the reference of the paper's section 2 equivalence).
//! - [`solver`]: the soft-projection step (the paper's eqs. 17 and 20 in one update, with the
//!   accumulated-multiplier term), in the XPBD-consistent `Accumulate` mode or
//!   the paper's printed `PaperReset` mode.
//! - [`projection`]: the constraint sweeps of the soft projection: Gauss-Seidel, SOR,
//!   Jacobi and graph-coloured parallel Gauss-Seidel (section 7).
//! - [`baselines`]: symplectic Euler, linearised implicit Euler by conjugate gradients and
//!   velocity-projection damping, the comparisons of the paper's Figs. 1 and 5.
//! - [`constraint_space`]: the global constraint-space system `(h^2 J W J' + C)` solved by
//!   Conjugate Residuals (section 7).
//! - [`collision`]: planes, spheres, capsules, triangle meshes (parry) and self contacts as
//!   inequality constraints with Coulomb friction (section 10).
//! - [`energy`]: kinetic, gravitational and elastic energy.
//!
//! Units: metres, kilograms, seconds; a link's stiffness `k` in N/m, its compliance `1/k` in
//! m/N, the damping parameter `gamma = d/k` in seconds.
#![warn(missing_docs)]

pub mod baselines;
pub mod collision;
pub mod constraint_space;
pub mod energy;
pub mod fem;
pub mod model;
pub mod ncg;
pub mod newton;
pub mod projection;
pub mod solver;
mod system;
mod vecs;

pub use collision::{Collider, Collisions, MeshCollider};
pub use energy::Energy;
pub use fem::FemTri;
pub use model::{grid_triangles, ClothModel, Link, Roller};
pub use ncg::NcgVariant;
pub use projection::Relaxation;
pub use solver::{LambdaMode, Method, Simulation, SolverParams, StepStats};
