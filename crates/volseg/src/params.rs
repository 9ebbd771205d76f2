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
    /// Parameters of [`crate::walker::RandomWalkSession`], the paper's values by default.
    #[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
    pub struct RandomWalkParams {
        /// Bone threshold `t_bone`, HU: voxels with `I >= t_bone` form the graph (300).
        pub t_bone: f64,
        /// Weight sharpness β of eq. 1 (3000; 2000-4000 give similar results).
        pub beta: f64,
        /// Constant ε added to every edge weight (0.01).
        pub eps: f64,
        /// Regulariser κ added to every unseeded diagonal entry (1e-3): keeps systems of
        /// components without seeds non-singular.
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
            beta: 3000.0,
            eps: 0.01,
            kappa: 1e-3,
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
