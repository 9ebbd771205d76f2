//! Dynamic time warping and the "DTW kernel" of paper 17 (Ahmed, Paul and Gavrilova, "Kinect-Based
//! Gait Recognition Using Sequences of the Most Relevant Joint Relative Angles", WSCG 2015,
//! section 3.4, eqs. 2-6).
//!
//! - [`dtw`] / [`dtw_path`]: the accumulated-cost recursion of eq. 5 (no slope constraint, no
//!   normalisation by path length), with an optional Sakoe-Chiba band and an absolute or squared
//!   local cost.
//! - [`dtw_kernel`]: the dissimilarity Δ of eq. 6 between two multichannel samples, the sum of
//!   the per-channel DTW distances (independent multivariate DTW, each channel warps on its own);
//!   with [`Multivariate::Dependent`], the dependent multivariate DTW (one warp path, the local
//!   cost between whole frames; [`dtw_dependent_bounded`] on [`Frames`]).
//! - [`dissimilarity_matrix`] / [`self_dissimilarity`]: Δ between every query and gallery sample,
//!   in parallel, and [`nearest`]: 1-NN search with exact early abandoning.
//! - [`ts_file`]: reader of the `.ts` time-series format of the UCR/UEA archive.
//!
//! Sequences may have different lengths (the paper compares gait cycles of different durations
//! without resampling).

mod core;
pub mod fused;
pub(crate) mod matrix;
pub mod ts_file;

pub use self::core::{
    dtw, dtw_bounded, dtw_dependent_bounded, dtw_path, DtwParams, Frames, LocalCost, Multivariate,
};
pub use matrix::{
    check_sample, dissimilarity_matrix, dtw_kernel, dtw_kernel_bounded, interleave_all, nearest,
    self_dissimilarity, DistMatrix,
};
