//! # wscg-meshfilter
//!
//! Paper 04 of WSCG vol. 23: Wasenmüller, Bleser and Stricker, "Joint Bilateral Mesh
//! Denoising using Color Information and Local Anti-Shrinking". A coloured triangle mesh
//! (an RGB-D or photogrammetry reconstruction) is denoised by moving every vertex along its
//! normal by a bilateral mean of its k nearest neighbours' offsets to its tangent plane,
//! weighted by distance, offset and **colour difference**; a second pass removes the local
//! shrinkage, and the offset range decays every iteration so that the iteration converges.
//!
//! - [`params`]: the parameters, the paper's Table 1 presets and MVD-relative defaults.
//! - [`jbmd`]: the method, with the paper's ablations as switches.
//! - [`bmd`]: bilateral mesh denoising of Fleishman et al. (2003), with and without volume
//!   preservation, the baseline the paper extends.
//! - [`smoothing`]: the Laplacian, Taubin and HC-Laplacian baselines.
//! - [`metrics`]: the paper's mean error (eq. 3), corresponding-vertex error, mean vertex
//!   distance.
//! - [`sweep`]: the grid search of the paper's comparisons (best setting and iteration).
//! - [`synth`]: synthetic coloured meshes with exact ground truth, and noise.
//!
//! Meshes are [`wscg_math::TriMesh`] (colours in `[0, 1]`; the colour range `sigma_c` is on
//! the paper's 0-255 scale).
#![warn(missing_docs)]

pub mod bmd;
pub mod jbmd;
pub mod metrics;
pub mod params;
pub mod smoothing;
pub mod sweep;
pub mod synth;

pub use jbmd::{jbmd, jbmd_trace};
pub use params::JbmdParams;
