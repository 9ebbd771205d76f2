//! Localized-search high-definition video completion (paper 06 of WSCG vol. 23: Benoit and
//! Paquette, "Localized search for high definition video completion").
//!
//! Remove an object from a video: the hole `H` (a mask per frame) is filled by copying, pixel
//! by pixel, the centre colour of the best-matching space-time patch of the known region `E`.
//!
//! - Stage 1 ([`lowres`]): at a working resolution of about 480 pixels wide, a pyramid
//!   completion started from an inpainting of the hole, sweeping the hole in onion-peel order
//!   ([`onion`]) with a single best match per pixel; the search also tries each pixel's
//!   temporal candidates, the same position in the nearest frames where it is known
//!   ([`field::temporal_sources`]: exact copies behind an object moving in front of a static
//!   camera).
//! - Stage 2 ([`refine`]): the worst matches try the sources their good neighbours imply.
//! - Stage 3 ([`local`]): at each finer resolution, every hole pixel searches exactly only a
//!   shrinking window around its up-scaled match ([`field`]), within the paper's thousand
//!   candidates per pixel, so HD videos need little more memory than the video itself.
//!
//! [`complete::complete_video`] runs the three stages. Baselines ([`wexler`]): Wexler et
//! al. 2007 (global search with weighted voting at every level) and per-frame image
//! PatchMatch inpainting. Measures ([`metrics`]): SSIM and PSNR in the hole, flicker.
//! Test clips with exact ground truth: [`synth`]. Frame folders: [`io`]. The space-time
//! PatchMatch search and patch voting that the stages and the baselines share: [`patchmatch`].
#![warn(missing_docs)]

pub mod complete;
pub mod field;
pub mod hypotheses;
pub mod init;
pub mod io;
pub mod local;
pub mod lowres;
pub mod metrics;
pub mod onion;
pub mod patch;
pub mod patchmatch;
pub mod pca_index;
pub mod pyramid;
pub mod refine;
pub mod search;
pub mod synth;
pub mod telea;
pub mod video;
pub mod wexler;

#[cfg(test)]
pub(crate) mod testing;

pub use complete::{
    complete_in_place, complete_video, complete_video_with, Completion, CompletionParams, Stats,
};
pub use field::MatchField;
pub use init::InitMethod;
pub use local::{LocalSearchParams, UpscaleStep};
pub use lowres::LowResParams;
pub use patch::PatchSize;
pub use pca_index::PcaKdParams;
pub use refine::RefineParams;
pub use search::SearchMethod;
pub use video::{Mask3, Video};
pub use wexler::{per_frame_patchmatch, wexler_complete, WexlerParams};
