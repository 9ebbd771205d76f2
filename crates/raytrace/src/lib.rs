//! Ray tracing papers of WSCG vol. 23.
//!
//! Paper 07 (da Graça, Paljic and Diaz, "Evaluating stereoscopic visualization for predictive
//! rendering"): the "virtual material workshop" for metallic-flake car paint.
//!
//! - [`paint`]: the flake microstructure of the binder layer (stack model, section 2.2).

pub mod paint;
