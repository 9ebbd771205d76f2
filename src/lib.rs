//! # wscg
//!
//! Software for the papers of the Journal of WSCG, vol. 23: each paper's method is a library
//! crate, re-exported here under one name. The `wscg` command line, its demos and the gallery
//! live in the `wscg-cli` crate, so depending on this crate compiles the libraries only.
//!
//! | module | crate | papers and contents |
//! |---|---|---|
//! | [`math`] | `wscg-math` | shared types and numerics (images, volumes, meshes, solvers, FFT, metrics, file formats) |
//! | [`biometrics`] | `wscg-biometrics` | paper 01: FDKECA; paper 05: slow feature analysis for hand poses; paper 14: ear recognition under occlusion; paper 17: Kinect gait recognition |
//! | [`cloth`] | `wscg-cloth` | paper 02: cloth with soft constraints |
//! | [`volren`] | `wscg-volren` | paper 03: hybrid ROI visualisation of medical volumes; paper 15: convolution-based volume illumination |
//! | [`meshfilter`] | `wscg-meshfilter` | paper 04: joint bilateral mesh denoising with colour |
//! | [`video`] | `wscg-video` | paper 06: localized-search HD video completion |
//! | [`raytrace`] | `wscg-raytrace` | paper 07: spectral metallic-flake paint, stereo rig, virtual observer; paper 08: many-light rendering with adaptive importance caching |
//! | [`doe`] | `wscg-doe` | paper 07: central composite designs, response surfaces, repeated-measures ANOVA |
//! | [`isosurface`] | `wscg-isosurface` | paper 09: sparse-grid marching cubes with tetrahedral-spline normals |
//! | [`octree`] | `wscg-octree` | paper 10: unified triangle/voxel octree, exact voxelization, LoD ray casting |
//! | [`csmri`] | `wscg-cs-mri` | paper 11: compressed-sensing MRI, exact tight UDCT, C-SALSA, FCSA/TVCMRI/WaTMRI |
//! | [`deblur`] | `wscg-deblur` | paper 12: gyroscope blur kernels, piecewise and multi-frame hyper-Laplacian deblurring |
//! | [`hdr`] | `wscg-hdr` | paper 13: multiscopic HDR, epipolar coherent PatchMatch, BDS voting, Khan merge |
//! | [`motion`] | `wscg-motion` | paper 16: anechoic demixing, Hopf primitives, LWLR, predictive planner, online synthesis, BVH |
//! | [`volseg`] | `wscg-volseg` | paper 18: bone separation in CT by random walks on the bone-only graph |
#![warn(missing_docs)]

pub use wscg_biometrics as biometrics;
pub use wscg_cloth as cloth;
pub use wscg_cs_mri as csmri;
pub use wscg_deblur as deblur;
pub use wscg_doe as doe;
pub use wscg_hdr as hdr;
pub use wscg_isosurface as isosurface;
pub use wscg_math as math;
pub use wscg_meshfilter as meshfilter;
pub use wscg_motion as motion;
pub use wscg_octree as octree;
pub use wscg_raytrace as raytrace;
pub use wscg_video as video;
pub use wscg_volren as volren;
pub use wscg_volseg as volseg;

/// The README's Rust examples, compiled and run as doc tests.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
