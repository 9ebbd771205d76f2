//! Parameters of the random-walks segmentation (paper sections 2.1, 2.4 and 2.5).

use wscg_math::{Error, Result};

/// How CT values are mapped to `g ∈ [0, 1]` before the edge weights.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum IntensityNorm {
    /// `g = clamp((I − lo) / (hi − lo), 0, 1)`; default `lo = −1024`, `hi = 3071` HU (12-bit
    /// CT): β = 3000 only makes sense on a [0, 1] scale and the paper does not state one.
    Window {
        /// Value mapped to 0.
        lo: f64,
        /// Value mapped to 1.
        hi: f64,
    },
    /// The bone voxels' own minimum and maximum.
    MinMax,
    /// Values used as they are.
    None,
}

/// How the K systems are solved (the variants of the paper's Fig. 9).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Solver {
    /// All labels advance together, one sweep over the graph per iteration (ours: the graph is
    /// streamed once per iteration instead of K times).
    #[default]
    Block,
    /// One label after the other (the paper's CPU path).
    PerLabel,
}

/// Scalar type of the solver's vectors.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Precision {
    /// `f32` vectors, `f64` dot products (half the memory traffic).
    #[default]
    F32,
    /// `f64` throughout.
    F64,
}

wscg_math::params! {
    /// Parameters of [`crate::walker::RandomWalkSession`].
    ///
    /// The defaults of the edge weights (eq. 1) and the regulariser are `β = 1e4`, `ε = 2e-3`,
    /// `κ = 3e-5`, not the paper's `β = 3000`, `ε = 0.01`, `κ = 1e-3` (section 2.4;
    /// [`RandomWalkParams::paper`]). On the fractured-shell phantom (fragments joined by thin
    /// fracture gaps of lower but still bone density, 30 HU noise) the paper's `ε = 0.01`
    /// lets a fracture line of a few hundred edges conduct as much as a fragment's body, and
    /// `κ = 1e-3` drains every probability towards 0 over a few dozen voxels
    /// (`cosh μ = 1 + κ / 2w`), so the label of a voxel far from every stroke is decided by
    /// the leak rather than the image: DSC 0.75-0.92 at 96³-192³ with 6-10 fragments and
    /// ball strokes. The sweep of `ε × κ × β` (BENCHMARKS.md) chose the defaults: 0.956-0.979
    /// on the same phantoms (the geodesic nearest-seed baseline: 0.59-0.77). `κ = 0` scores
    /// as well with ball strokes, but strokes painted on the outer surface (partial-volume
    /// voxels, joined to the bone's body by weak edges only) then reach the whole bone
    /// through those weak edges and one label can take most of it (DSC 0.08-0.46);
    /// `κ = 3e-5` keeps each stroke's reach local (0.66-0.80; the paper's values 0.68-0.85).
    /// Costs and limits: about twice the CG iterations of `κ = 1e-3`; `β = 1e4` puts the
    /// weight of a 41 HU difference (on the default window) at `exp(-1)`, and from about
    /// `β = 1.5e4` thin or noisy bone is cut into pieces (DSC 0.69 at `β = 2e4` on a 64³
    /// phantom whose shell is 2.5 voxels thick), so a CT much noisier than 30 HU or a
    /// narrower intensity window calls for a smaller `β`.
    #[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    pub struct RandomWalkParams {
        /// Bone threshold `t_bone`, HU: voxels with `I >= t_bone` form the graph (300).
        pub t_bone: f64,
        /// Weight sharpness β of eq. 1 (1e4; the paper's 3000 in [`RandomWalkParams::paper`]).
        pub beta: f64,
        /// Constant ε added to every edge weight (2e-3; the paper's 0.01 in
        /// [`RandomWalkParams::paper`]).
        pub eps: f64,
        /// Regulariser κ added to every unseeded diagonal entry (3e-5; the paper's 1e-3 in
        /// [`RandomWalkParams::paper`]): the probabilities decay away from the seeds and the
        /// solve converges in fewer iterations. Unseeded components are left out of the
        /// systems, so `κ = 0` (Grady's plain Dirichlet problem) keeps them non-singular too.
        pub kappa: f64,
        /// Relative residual `‖r‖ / ‖b‖` at which CG stops (3e-3).
        pub tol: f64,
        /// Iteration cap per label (2000).
        pub max_iter: usize,
        /// Intensity normalisation.
        pub norm: IntensityNorm,
        /// Divide intensity differences by the voxel spacing along the edge (scikit-image's
        /// convention); `false` is the paper's eq. 1.
        pub spacing_in_weights: bool,
        /// Solver layout (block of all labels by default).
        pub solver: Solver,
        /// Vector precision (`f32` by default).
        pub precision: Precision,
        /// Jacobi preconditioner (`true`, the paper's choice; `false` gives plain CG).
        pub jacobi: bool,
        /// Worker threads (`None`: the rayon pool the solve is called from).
        pub threads: Option<usize>,
    }
}

impl Default for RandomWalkParams {
    fn default() -> Self {
        Self {
            t_bone: 300.0,
            beta: 1e4,
            eps: 2e-3,
            kappa: 3e-5,
            tol: 3e-3,
            max_iter: 2000,
            norm: IntensityNorm::Window {
                lo: -1024.0,
                hi: 3071.0,
            },
            spacing_in_weights: false,
            solver: Solver::Block,
            precision: Precision::F32,
            jacobi: true,
            threads: None,
        }
    }
}

impl RandomWalkParams {
    /// The paper's values (section 2.4): `β = 3000`, `ε = 0.01`, `κ = 1e-3`, the rest as
    /// [`Default`]. They converge in about half the iterations of the defaults but leak
    /// through thin fractures (see [`RandomWalkParams`]).
    pub fn paper() -> Self {
        Self {
            beta: 3000.0,
            eps: 0.01,
            kappa: 1e-3,
            ..Self::default()
        }
    }

    /// Errors: non-finite values, negative β, ε or κ, `tol <= 0`, `max_iter == 0`,
    /// `threads == Some(0)`, a window with `hi <= lo`.
    pub fn validate(&self) -> Result<()> {
        if !self.t_bone.is_finite() {
            return Err(Error::invalid(
                "t_bone",
                format!("must be finite, got {}", self.t_bone),
            ));
        }
        for (name, v) in [
            ("beta", self.beta),
            ("eps", self.eps),
            ("kappa", self.kappa),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and >= 0, got {v}"),
                ));
            }
        }
        if !(self.tol.is_finite() && self.tol > 0.0) {
            return Err(Error::invalid(
                "tol",
                format!("must be > 0, got {}", self.tol),
            ));
        }
        if self.threads == Some(0) {
            return Err(Error::invalid("threads", "must be at least 1"));
        }
        if self.max_iter == 0 {
            return Err(Error::invalid("max_iter", "must be at least 1"));
        }
        if let IntensityNorm::Window { lo, hi } = self.norm {
            if !(lo.is_finite() && hi.is_finite() && hi > lo) {
                return Err(Error::invalid("norm", "a window needs finite lo < hi"));
            }
        }
        Ok(())
    }
}
