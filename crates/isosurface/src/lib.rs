//! # wscg-isosurface
//!
//! Paper 09 of WSCG vol. 23: Wood and Newman, "Isosurface Orientation Estimation in Sparse
//! Grids Using Tetrahedral Splines". Marching cubes on rectilinear grids with missing samples
//! (NaN), where the classic central-difference vertex normals are undefined near dropouts; the
//! paper estimates each vertex normal from a tetrahedral spline fitted inside the cells sharing
//! the vertex's edge (four samples per cell, never zero).
//!
//! - [`grid`]: [`ScalarGrid`] (NaN = missing, anisotropic spacing, side hints), the paper's
//!   sparsification protocol and random dropouts.
//! - [`extract`]: marching cubes on sparse grids ([`marching_cubes`], [`IsoMesh`]).
//! - [`normals`]: the spline estimator (the paper's method) and the central-difference and
//!   LSN baselines.
//! - [`tables`]: the case table built in code, the paper's tetrahedron-selection extension,
//!   and the 23 rotation classes.
//! - [`metrics`]: angular errors and their RMS, per rotation class.
//! - [`fields`]: analytic fields with exact gradients and a sampler.
//! - [`study`]: the paper's evaluation protocol (Tables 1-5).
//!
//! ```
//! use wscg_isosurface::{fields, marching_cubes, sparsify_for_isosurface, NormalMethod, ScalarGrid};
//! let s = fields::sample_voxels(&fields::Sphere { centre: [7.3, 7.6, 7.1], radius: 5.0 }, [16; 3]).unwrap();
//! let (sparse, sides) = sparsify_for_isosurface(s.view(), 0.0).unwrap();
//! let g = ScalarGrid::from_volume(sparse.view()).unwrap().with_side_hint(&sides).unwrap();
//! let mesh = marching_cubes(&g, 0.0, NormalMethod::spline()).unwrap();
//! assert!(mesh.normals.iter().all(|n| n != &[0.0; 3]));
//! ```
#![warn(missing_docs)]

pub(crate) mod cell;
pub(crate) mod edge;
pub mod extract;
pub mod fields;
pub mod grid;
pub mod metrics;
pub mod normals;
pub mod study;
pub mod tables;

pub use extract::{extract, marching_cubes, vertex_on_edge, EdgeId, IsoMesh};
pub use grid::{random_dropouts, sparsify_for_isosurface, Sample, ScalarGrid};
pub use metrics::{angular_errors, rms, RmsSummary};
pub use normals::{
    estimate_normals, AmbiguousRule, LsnParams, NormalMethod, NormalStats, SplineParams,
    TetSelection,
};
pub use tables::mc_rotation_class;
