//! # wscg-math
//!
//! Shared types and numerics of the wscg workspace: what two or more crates need, and only
//! that (a piece that a single paper crate uses lives in that crate).
//!
//! Types and numerics, always compiled:
//!
//! - [`image`]: [`Image`], an H x W x C row-major pixel buffer.
//! - [`volume`]: [`Volume`], an X x Y x Z grid with voxel spacing, trilinear sampling and
//!   gradients; [`volume::filter`]: Gaussian smoothing.
//! - [`view`]: [`ImageView`], [`ImageStackView`] and [`VolumeView`], the borrowed views that
//!   functions reading an image, a stack of images or a volume take (no copy of a caller's
//!   buffer); [`Image::view`] and [`Volume::view`] make them from owned data.
//! - [`mesh`]: [`TriMesh`] with adjacency, normals, areas and volumes; [`mesh::shapes`]: the
//!   icosphere, cube and grid generators.
//! - [`sparse`]: CSR matrices (faer storage) and a preconditioned conjugate gradient written
//!   against the [`sparse::LinOp`] operator trait.
//! - [`dense`]: symmetric eigen, SVD, least squares and the generalized symmetric eigenproblem
//!   through faer; [`eigh_partial`] and [`eigh_krylov`]: the few extreme eigenpairs of large
//!   matrices.
//! - [`fft`]: 1-D, 2-D and 3-D FFTs (rustfft) with numpy's normalisation conventions, and
//!   planned 2-D transforms ([`fft::Plan2`]) for repeated use.
//! - [`filter`], [`resize`]: separable Gaussian and box filters, area and bilinear resizing.
//! - [`distance`]: exact Euclidean distance transforms.
//! - [`dist`]: Student-t and F tail probabilities and the t quantile.
//! - [`metrics`]: MSE, RMSE, PSNR, SSIM (Wang et al. 2004), Dice.
//! - [`wavelet`]: orthonormal Daubechies wavelets (periodized, PyWavelets' conventions).
//! - [`knn`]: a kd-tree with exact k-nearest and nearest-point queries; [`knn_graph`]: the
//!   k-nearest-neighbour graph of a whole point set.
//! - [`bvh`]: a binned-SAH bounding volume hierarchy over axis-aligned boxes, traversed
//!   front to back (the ray tracers of papers 07 and 08 and the octree baseline of paper 10).
//! - [`vec3`]: small helpers on `[f64; 3]` points and vectors; [`reduce`]: sums in a fixed
//!   order, identical for any number of threads.
//! - [`params`]: the [`params!`] macro that declares every `XxxParams` struct of the workspace
//!   (`#[non_exhaustive]`, with chainable setters).
//! - [`rng`]: seeded, portable random generation.
//! - [`progress`]: a progress-reporting trait that the CLI renders as progress bars.
//! - [`error`]: the one [`Error`] type.
//! - [`alloc`]: buffers sized by a user's argument, checked against overflow and the memory
//!   limit ([`memory_limit`]) before allocating ([`try_vec!`]); [`cancel`]: the cancellation
//!   flag that long loops poll (Ctrl-C in Python).
//!
//! # File formats and cargo features
//!
//! [`io`] holds one module per file format, each behind a cargo feature, so that a crate
//! compiles only the codecs it reads and writes:
//!
//! | feature | modules | adds | dependency |
//! |---|---|---|---|
//! | `io-image` | `io::raster`, `io::exif` | PNG and TIFF (8/16-bit), JPEG, OpenEXR and Radiance HDR for [`Image`] (`Image::load`, `Image::save`, ...); EXIF exposure settings | `image`, `kamadak-exif` |
//! | `io-npy` | `io::npy`, also named `npy` | numpy `.npy` arrays | `ndarray-npy` |
//! | `io-volume` | `io::raw`, `io::nifti`, `io::npy` | raw, NIfTI-1 and `.npy` files for [`Volume`] (`Volume::read`, ...); enables `io-npy` | `nifti` |
//! | `io-mesh` | `io::obj`, `io::ply` | OBJ and PLY files for [`TriMesh`] (`TriMesh::read`, ...) | `ply-rs` |
//!
//! All four are default features: a plain dependency on `wscg-math` reads and writes every
//! format. The workspace declares the dependency with `default-features = false`, and each
//! crate names the features it uses (`wscg-math = { workspace = true, features = ["io-image"]
//! }`); a crate that names none, like `wscg-doe`, compiles no codec.
#![warn(missing_docs)]

pub mod error;

pub mod alloc;
pub mod cancel;
pub mod memory_limit;

pub mod bvh;
pub mod dense;
pub mod dist;
pub mod distance;
pub mod eigh_krylov;
pub mod eigh_partial;
pub mod faer_par;
pub mod fft;
pub mod filter;
pub mod image;
pub mod io;
mod kbest;
pub mod knn;
pub mod knn_graph;
pub mod mesh;
pub mod metrics;
pub mod params;
pub mod progress;
pub mod reduce;
pub mod resize;
pub mod rng;
pub mod sparse;
mod sym_eigen;
pub mod vec3;
pub mod view;
pub mod volume;
pub mod wavelet;

pub use error::{Error, RefusedArgument, Result};
pub use image::Image;
pub use mesh::{Adjacency, TriMesh};
pub use view::{ImageStackView, ImageView, VolumeView};
pub use volume::{Affine, Volume};

#[cfg(feature = "io-npy")]
pub use io::npy;
#[cfg(feature = "io-mesh")]
pub use io::PlyEncoding;
