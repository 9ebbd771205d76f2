//! # wscg-hdr
//!
//! Paper 13 of WSCG vol. 23: R. Ramirez Orozco, C. Loscos, I. Martin & A. Artusi,
//! "Multiscopic HDR Image Sequence Generation".
//!
//! A horizontal camera array shoots a static scene with a different exposure per camera;
//! every view becomes an HDR image:
//!
//! - [`crf`]: inverse camera responses, Debevec-Malik calibration from an exposure stack.
//! - [`mitsunaga_nayar`]: the polynomial self-calibration of RASCAL, which the paper used,
//!   with the exposure ratios re-estimated from approximate times.
//! - [`radiance`]: views to radiance space with Khan weights (eq. 7).
//! - [`pm`]: the paper's epipolar PatchMatch with the coherence-penalised cost (eqs. 1-4),
//!   and the original 2-D PatchMatch of Barnes et al. 2009.
//! - [`stereo`]: the ZNCC stereo baseline with left-right check.
//! - [`vote`]: bidirectional-similarity patch voting (eq. 5) and the direct warp.
//! - [`merge`]: the weighted merge (eq. 6) with a defined fallback for clipped pixels.
//! - [`multiscopic`]: the driver over all ordered pairs of views, with the unaligned merge
//!   baseline.
//! - [`tonemap`]: Reinhard's global operator for pictures.
//! - [`synth`] and [`metrics`]: a layered multi-view scene with ground truth, log-radiance
//!   error, bad-pixel rates and field coherence.
//!
//! ```
//! use wscg_hdr::{multiscopic_hdr, synth, MultiscopicParams, PatchMatchParams};
//! let cfg = synth::SceneParams::default()
//!     .height(48)
//!     .width(64)
//!     .times(vec![0.005, 0.04, 0.3]);
//! let scene = synth::layered_scene(&cfg, 1).unwrap();
//! let p = MultiscopicParams::default().pm(PatchMatchParams::default().d_min(-40).d_max(40));
//! let out = multiscopic_hdr(&scene.views, &scene.times, &[scene.crf.clone()], &p,
//!                           &wscg_math::progress::NoProgress).unwrap();
//! assert_eq!(out.hdr.len(), 3);
//! ```
#![warn(missing_docs)]

pub mod crf;
pub mod files;
pub mod merge;
pub mod metrics;
pub mod mitsunaga_nayar;
pub mod multiscopic;
pub mod nnf;
pub mod pm;
pub mod radiance;
pub mod stereo;
pub mod synth;
pub mod tonemap;
pub mod vote;

pub use crf::{calibrate_debevec, Crf};
pub use files::{read_exposure_times, write_exposure_times};
pub use merge::{merge, merge_stack, MergeInput, Merged};
pub use mitsunaga_nayar::{
    calibrate_mitsunaga_nayar, MitsunagaNayarChannel, MitsunagaNayarFit, MitsunagaNayarParams,
};
pub use multiscopic::{multiscopic_hdr, Align, MultiscopicParams, MultiscopicResult, Synthesis};
pub use nnf::Nnf;
pub use pm::{patchmatch, patchmatch_2d, patchmatch_weighted, PatchMatchParams};
pub use radiance::{khan_weight, to_radiance, to_samples, ViewSamples};
pub use stereo::{zncc_stereo, StereoParams};
pub use vote::{vote_bds, warp_direct};
