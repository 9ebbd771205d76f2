//! Paper 14: Sultana, Paul and Gavrilova, "Occlusion Detection and Index-based Ear
//! Recognition" (WSCG 2015).
//!
//! Closed-set ear identification that survives hair, earrings, headphones and scarves:
//!
//! 1. **Enrolment** ([`enroll`], section 3.2): the clean crop is resized to 100 x 80,
//!    histogram-equalised, cut into 80 blocks of 10 x 10, and each block's level-1 Haar LL
//!    (5 x 5) is stored under its block index.
//! 2. **Occlusion detection** ([`detect_occlusion`], section 3.3, Algorithm 1): a Gaussian
//!    skin model in normalised `(r, g)` (eqs. 2-5), closing with a radius-10 disk and hole
//!    filling mark the skin; blocks mostly skin are un-occluded; a probe with more than 60 %
//!    occluded blocks is rejected for reacquisition.
//! 3. **Index-based matching** ([`score`], [`identify`], section 3.4, eqs. 7-18): only the
//!    un-occluded blocks are compared with the same-index blocks of each template, also
//!    under the eight one-block shifts, and the block-wise best similarities are averaged.
//!
//! The paper's baseline (whole-ear Haar features, no occlusion handling; Fig. 12) is
//! [`make_baseline_probe`] / [`baseline_score`] / [`identify_baseline`]; all four score rules
//! of Fig. 11 are [`ScoreRule`]s. [`synth`] generates ears with exact occluder masks (the
//! WPUT database is not redistributable) and [`protocol`] runs the paper's experiments on
//! them.
//!
//! Conventions: images are `Image<u8>` with 3 channels R, G, B (row-major); block `b` sits at
//! grid row `b / 8`, column `b % 8` (0-based; the paper numbers 1..80).

pub mod features;
pub mod gallery_file;
pub mod matching;
pub mod occlusion;
pub mod params;
pub mod protocol;
pub mod skin;
pub mod synth;

pub use features::{block_features, enroll, feature_plane, normalise, EarTemplate};
pub use gallery_file::{EarGalleryFile, GALLERY_JSON, GALLERY_TEMPLATES};
pub use matching::{
    baseline_params, baseline_score, cmc, identify, identify_baseline, identify_image,
    make_baseline_probe, make_probe, rank, score, scores, scores_by_rule, Gallery, Identification,
    Probe, ScoreBreakdown,
};
pub use occlusion::{detect_occlusion, skin_pixels, OcclusionReport};
pub use params::{EarParams, ScoreRule, SHIFTS_NINE};
pub use skin::{chromaticity, SkinModel, SkinRule};
