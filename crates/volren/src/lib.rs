//! # wscg-volren
//!
//! Volume rendering papers of WSCG vol. 23.
//!
//! Paper 03, Campoalegre, Navazo and Brunet, "Hybrid ROI-Based Visualization of Medical
//! Models": a server turns an 8-bit volume and its transfer functions into a low-resolution
//! volume (transfer-function-aware block Haar wavelets) and a Gradient Octree of the
//! material-boundary voxels (3 bytes a voxel, structure at one bit per node); a client
//! renders the low-resolution volume everywhere and the octree inside a region of interest.
//!
//! - [`tf`]: piecewise-linear transfer functions and the materials they induce.
//! - [`normal_code`]: the 3-byte voxel code (6-bit material, 9 + 9-bit octahedral normal).
//! - [`gradient_octree`]: edge voxels, the pointer-less octree, its 1-bit-per-node structure,
//!   the client's lossless rebuild, the paper's eq. 1 addressing and ROI restriction.
//! - [`wavelet`]: the block Haar transform and its byte coding.
//! - [`package`]: the static and ROI packages (versioned, CRC-checked wire format), the
//!   server and the client's data.
//! - [`net`]: the server and client over TCP.
//! - [`render`]: the client's two-level ray caster, the baselines' renderers and the
//!   full-resolution reference.
//! - [`phantoms`]: analytic head and thorax volumes with their transfer functions.
//!
//! Paper 15, Angelelli and Bruckner, "Performance and Quality Analysis of Convolution-Based
//! Volume Illumination": [`illumination`] renders slice by slice with instant convolution
//! shadows, supersampled (SCS) and pre-integrated (PI-ICS, PI-SCS) variants, and the ray
//! casting baselines; [`vti`] reads VTK XML image data.
#![warn(missing_docs)]

mod bytes;
mod client;
pub mod gradient_octree;
pub mod illumination;
pub mod net;
pub mod normal_code;
pub mod package;
pub mod phantoms;
pub mod render;
pub mod tf;
pub mod vti;
pub mod wavelet;

pub use gradient_octree::{GoStructure, GradientOctree, Roi};
pub use package::{HybridClient, HybridServer, ServerParams, SizeReport};
pub use render::{render_reference, Camera, RenderParams};
pub use tf::{MaterialTable, PiecewiseTransferFunction};
