//! # wscg-deblur
//!
//! Paper 12 of WSCG vol. 23: G. Sörös, S. Münger, C. Beltrame & L. Humair, "Multiframe
//! Visual-Inertial Blur Estimation and Removal for Unmodified Smartphones".
//!
//! Camera shake blur of a smartphone preview frame is removed with the help of the gyroscope
//! and of the neighbouring frames:
//!
//! - [`gyro`]: rate integration and SLERP super-resolution of the camera orientation.
//! - [`kernel`]: per-pixel blur kernels rendered from the gyroscope under the rotation-only
//!   homography `K R K^-1` with rolling-shutter timing (eqs. 5-6), region grids, blurriness.
//! - [`wstep`] and [`deconv`]: the Krishnan-Fergus hyper-Laplacian solver (eqs. 7-8), its
//!   multi-frame prior (eq. 9), Wiener and Richardson-Lucy.
//! - [`noise`]: the input's noise level (Donoho's wavelet MAD) and the noise-aware `lambda`.
//! - [`tiling`]: piecewise-uniform deblurring of `30 x 30` regions on edge-tapered windows,
//!   blended without seams; the global-kernel baseline.
//! - [`warp`] and [`align`]: rolling-shutter rectification (Karpenko 2011), homography
//!   warps, ECC alignment.
//! - [`multiframe`]: the full pipeline of section 5 with per-region frame weights.
//! - [`calibrate`]: gyro-camera delay from phase correlation (section 3.1).
//! - [`synth`]: Ornstein-Uhlenbeck shake and densely rendered blurred frames with ground truth.
//!
//! Images are single-channel [`wscg_math::Image`]s; the solvers work on linear intensities in
//! `[0, 1]` (the multi-frame pipeline converts with the gamma camera response of section 3.3).
//!
//! ```
//! use wscg_deblur::{deconv_hl, synth, HyperLaplacianParams, Kernel};
//! let sharp = synth::scene(64, 64, 1).unwrap();
//! let k = Kernel::line(7.0, 0.3).unwrap();
//! let blurred = wscg_deblur::tiling::convolve(&sharp, &k).unwrap();
//! let restored = deconv_hl(&blurred, &k, &HyperLaplacianParams::default()).unwrap();
//! assert_eq!(restored.shape(), (64, 64, 1));
//! ```
#![warn(missing_docs)]

pub mod align;
pub mod calibrate;
pub mod camera;
pub mod deconv;
pub mod gyro;
pub mod kernel;
pub mod metrics;
pub mod multiframe;
pub mod noise;
pub(crate) mod spectral;
pub mod synth;
pub mod tiling;
pub mod warp;
pub mod wstep;

pub use align::{align_homography, AlignParams, Alignment};
pub use calibrate::{estimate_time_delay, phase_correlation};
pub use camera::{CameraFile, Gamma, Intrinsics, Timing};
pub use deconv::HyperLaplacianParams;
pub use gyro::{GyroSample, GyroTrack};
pub use kernel::{blurriness, kernel_grid, render_kernel, Kernel, KernelGrid, KernelParams};
pub use multiframe::{
    deblur_frame, deblur_multiframe, frame_weights, AlignMode, DeblurResult, FrameInput,
    MultiframeParams,
};
pub use noise::{estimate_noise, lambda_for_noise};
pub use spectral::smooth_size;
pub use tiling::{
    convolve, convolve_piecewise, deblur_piecewise, deconv_hl, deconv_hl_multi, richardson_lucy,
    wiener, Method, Tiling,
};
pub use warp::rectify_rolling_shutter;
