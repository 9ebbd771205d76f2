//! # wscg-volseg
//!
//! Paper 18 of the Journal of WSCG vol. 23: Nysjö, Malmberg, Sintorn and Nyström, "BoneSplit
//! – A 3D Texture Painting Tool for Interactive Bone Separation in CT Images".
//!
//! Touching bones are segmented together by a threshold; BoneSplit separates them with
//! Grady's random walks on a graph of the **bone voxels only**:
//!
//! 1. [`graph`]: threshold at `t_bone`, number the bone voxels, 6-connected edges between
//!    bone voxels with weights `w_ij = exp(−β (g_i − g_j)²) + ε` (paper eq. 1).
//! 2. [`walker`]: for every label `k` the combinatorial Dirichlet problem
//!    `(L_U + κ I) x_k = −Bᵀ m_k` solved by Jacobi-preconditioned CG to a relative residual
//!    of 3e-3, warm-started from the previous solution when seeds are added; each bone voxel
//!    takes the label of largest probability (unreached components stay 0).
//! 3. [`baseline`]: geodesic nearest-seed labelling (breadth-first inside the bone mask), the
//!    cheap baseline a random-walk result must beat.
//! 4. [`edit`]: the local grow brush of section 2.6 and the removal of small label islands;
//!    [`preprocess`]: the optional anisotropy-aware smoothing and the threshold.
//! 5. [`phantom`]: a fractured-shell CT phantom with exact fragment labels and seed strokes
//!    (no clinical CT is redistributable), and [`metrics::dice_multilabel`] (paper eq. 2).
//!
//! Volumes are [`wscg_math::Volume`]s, x fastest (`idx = x + nx (y + ny z)`).
#![warn(missing_docs)]

pub mod baseline;
mod block;
pub mod edit;
pub mod graph;
pub mod metrics;
pub mod params;
pub mod phantom;
pub mod preprocess;
pub mod walker;

pub use baseline::{full_image_graph, nearest_seed_labels};
pub use edit::{
    local_grow_edit, paint_strokes, read_strokes, remove_small_components, GrowWeights,
};
pub use graph::BoneGraph;
pub use metrics::dice_multilabel;
pub use params::{IntensityNorm, Precision, RandomWalkParams, Solver};
pub use phantom::{fractured_shell_phantom, Phantom, PhantomParams};
pub use preprocess::{gaussian_smooth3, threshold};
pub use walker::{RandomWalkSession, SolveReport};
