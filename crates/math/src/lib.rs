//! # wscg-math
//!
//! Shared types and numerics of the wscg workspace: what two or more paper crates need, and
//! only that.
//!
//! - [`image`]: [`Image`], an H x W x C row-major buffer with PNG/JPEG/16-bit PNG/EXR/HDR IO.
//! - [`volume`]: [`Volume`], an X x Y x Z grid with voxel spacing, trilinear sampling, gradients,
//!   raw, NIfTI and `.npy` IO.
//! - [`mesh`]: [`TriMesh`] with adjacency, normals, areas, OBJ and PLY (ascii and binary) IO.
//! - [`sparse`]: CSR matrices (faer storage) and a preconditioned conjugate gradient written
//!   against the [`sparse::LinOp`] operator trait.
//! - [`dense`]: symmetric eigen, SVD, least squares and the generalized symmetric eigenproblem
//!   through faer.
//! - [`fft`]: 1-D, 2-D and 3-D FFTs (rustfft) with numpy's normalisation conventions, and
//!   planned 2-D transforms ([`fft::Plan2`]) for repeated use.
//! - [`filter`], [`resize`]: separable Gaussian and box filters, area and bilinear resizing.
//! - [`dist`]: Student-t and F tail probabilities and the t quantile.
//! - [`metrics`]: MSE, RMSE, PSNR, SSIM (Wang et al. 2004), Dice.
//! - [`wavelet`]: orthonormal Daubechies wavelets (periodized, PyWavelets' conventions).
//! - [`tv`]: isotropic total variation, gradient / divergence and Chambolle's TV prox.
//! - [`knn`]: a kd-tree with exact k-nearest and nearest-point queries.
//! - [`bvh`]: a binned-SAH bounding volume hierarchy over axis-aligned boxes, traversed
//!   front to back (the ray tracers of papers 07 and 08 and the octree baseline of paper 10).
//! - [`vec3`]: small helpers on `[f64; 3]` points and vectors.
//! - [`params`]: the [`params!`] macro that declares every `XxxParams` struct of the workspace
//!   (`#[non_exhaustive]`, with chainable setters).
//! - [`rng`]: seeded, portable random generation.
//! - [`progress`]: a progress-reporting trait that the CLI renders as progress bars.
//! - [`error`]: the one [`Error`] type.
#![warn(missing_docs)]

pub mod error;

pub mod bvh;
pub mod dense;
pub mod dist;
pub mod distance;
pub mod eigh_krylov;
pub mod eigh_partial;
pub mod fft;
pub mod filter;
pub mod image;
mod kbest;
pub mod knn;
pub mod knn_graph;
pub mod mesh;
pub mod metrics;
pub mod npy;
pub mod params;
pub mod patchmatch;
pub mod progress;
pub mod reduce;
pub mod resize;
pub mod rng;
pub mod sparse;
mod sym_eigen;
pub mod tv;
pub mod vec3;
pub mod volume;
pub mod wavelet;

pub use error::{Error, Result};
pub use image::Image;
pub use mesh::{Adjacency, PlyEncoding, TriMesh};
pub use volume::Volume;
