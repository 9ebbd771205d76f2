//! # wscg-cs-mri
//!
//! Paper 11 of WSCG vol. 23: B. Yang, M. Yuan, Y. Ma & J. Zhang, "Magnetic Resonance Images
//! Reconstruction using Uniform Discrete Curvelet Transform Sparse Prior based Compressed
//! Sensing" (UDCSMRI). An MR image is reconstructed from
//! undersampled k-space by
//!
//! `min_x Phi(Psi x)  subject to  ||F_u x - y||_2 <= eps`
//!
//! where `Psi` is the uniform discrete curvelet transform (UDCT) of the image's real and
//! imaginary parts and `Phi` is the l1 norm or the TV of the synthesis, solved by C-SALSA.
//!
//! - [`udct`]: the 2-D UDCT (Nguyen & Chauris 2010): an exactly tight frame of redundancy 4
//!   with folded per-band FFTs; `tight = false` reproduces `ucurv` 0.1.1's windows.
//! - [`fdct`]: the wrapping fast discrete curvelet transform (Candes et al. 2006), the
//!   curvelet prior of the paper's Tables 2 and 3: a complex tight frame of redundancy
//!   about 2.9 (wavelets at the finest scale).
//! - [`sflct`]: the sharp-frequency-localized contourlet (Lu & Do 2006), the LRSFLCT and
//!   MRSFLCT priors of the paper's Tables 2 and 3: a tight frequency-domain pyramid and the
//!   PKVA ladder directional filter bank (a frame, nearly but not exactly tight).
//! - [`sparsifier`]: priors on complex images (UDCT split, FDCT, SFLCT split, orthonormal
//!   Daubechies, identity).
//! - [`csalsa()`]: the solver, l1 and TV regularisers, noise radius `eps`, per-iteration
//!   history (paper Fig. 6); frames that are not Parseval get a CG x-update.
//! - [`tv`]: isotropic total variation of complex images, gradient / divergence and
//!   Chambolle's TV prox (the TV regulariser and the TV baselines).
//! - [`baselines`]: zero-filled, FCSA, TVCMRI (Condat-Vu on its objective), WaTMRI and a
//!   direct TV-constrained solver (Chambolle-Pock).
//! - [`masks`]: variable-density Cartesian and pseudo-radial masks (paper Fig. 2).
//! - [`phantom`]: analytic Shepp-Logan k-space, complex-phase images, the rhombic lattice.
//! - [`metrics`]: PSNR and RLNE as the paper reports them.
//! - [`scale_choice`]: the number of UDCT scales chosen from the data by hold-out validation
//!   (beyond the paper, which fixes it per image class).
//!
//! k-space is un-shifted (DC at index 0) and scaled by the unitary FFT.
//!
//! ```
//! use wscg_cs_mri::{csalsa, masks, phantom, KSpace, CsalsaParams, Regularizer, UdctParams, UdctSparsifier};
//! use wscg_math::progress::NoProgress;
//! let n = 64;
//! let mask = masks::cartesian(n, n, 0.4, 0.08, 1).unwrap();
//! let data = KSpace::new(n, n, phantom::shepp_logan_kspace(n).unwrap(), mask).unwrap();
//! let psi = UdctSparsifier::new(n, n, &UdctParams::default()).unwrap();
//! let p = CsalsaParams::default().max_iter(20);
//! let rec = csalsa(&data, &psi, Regularizer::default(), &p, None, &NoProgress).unwrap();
//! assert_eq!(rec.image.len(), n * n);
//! ```
#![warn(missing_docs)]

pub mod baselines;
pub mod csalsa;
pub mod fdct;
mod fold;
pub mod fourier;
pub mod kspace;
pub mod masks;
pub mod metrics;
pub mod phantom;
pub mod prox;
pub mod scale_choice;
pub mod sflct;
pub mod sparsifier;
pub mod tv;
pub mod udct;

pub use baselines::CompositeParams;
pub use csalsa::{csalsa, reconstruct, CsalsaParams, IterStat, Reconstruction, Regularizer};
pub use fdct::{Fdct, FdctBand, FdctParams, Finest};
pub use fourier::Fourier;
pub use kspace::{noise_epsilon, KSpace};
pub use scale_choice::{
    choose_udct_scales, holdout_folds, ring_density, weighted_holdout_error, ScaleChoice,
    ScaleChoiceParams, ScaleScore,
};
pub use sflct::{Redundancy, Sflct, SflctBand, SflctParams};
pub use sparsifier::{
    CoeffVec, FdctSparsifier, IdentitySparsifier, SflctSparsifier, Sparsifier, UdctSparsifier,
    WaveletSparsifier,
};
pub use udct::{BandId, Udct, UdctCoeffs, UdctParams};
