//! # wscg
//!
//! Software for the papers of the Journal of WSCG, vol. 23: each paper's method as a library
//! crate, re-exported here, plus the demos and the gallery that the `wscg` command line runs.
//!
//! | module | crate | contents |
//! |---|---|---|
//! | [`math`] | `wscg-math` | shared types and numerics (images, volumes, meshes, solvers, FFT, metrics) |
//! | [`biometrics`] | `wscg-biometrics` | paper 01: FDKECA with PCA, KPCA, KECA baselines and 1-NN recognition |
//! | [`cloth`] | `wscg-cloth` | paper 02: cloth with soft constraints (library in progress) |
//!
//! The paper crates are added to this table as they land (see the README).

pub use wscg_biometrics as biometrics;
pub use wscg_cloth as cloth;
pub use wscg_math as math;
pub use wscg_meshfilter as meshfilter;
pub use wscg_video as video;
pub use wscg_volren as volren;

pub mod demo;
pub mod gallery;
