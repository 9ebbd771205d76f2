//! Ray tracing papers of WSCG vol. 23.
//!
//! Paper 08 (Yoshida et al., "Adaptive importance caching for many-light rendering"):
//! [`manylight`], virtual point lights sampled from importance caches placed by clustering
//! and adaptive insertion.
//!
//! Paper 07 (da Graça, Paljic and Diaz, "Evaluating stereoscopic visualization for predictive
//! rendering"): the "virtual material workshop" for metallic-flake car paint.
//!
//! - [`spectral`]: spectra on the 380-780 nm grid, CIE observer and illuminants, colour
//!   conversion, aluminium's optical constants, Fresnel equations.
//! - [`paint`]: the flake microstructure of the binder layer (stack model, section 2.2).
//! - [`stereo`]: the off-axis stereo rig of section 3.
#![warn(missing_docs)]

/// The bounding volume hierarchy of the scenes and the flake layer, shared with the octree's
/// baseline and kept in `wscg-math`.
pub use wscg_math::bvh;
pub(crate) mod frame;
pub mod manylight;
pub mod paint;
pub mod spectral;
pub mod stereo;
