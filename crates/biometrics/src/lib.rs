//! # wscg-biometrics
//!
//! Image-based biometrics from the Journal of WSCG vol. 23.
//!
//! - [`subspace`]: paper 01, Damavandinejadmonfared and Varadharajan, "A New Extension to
//!   Kernel Entropy Component Analysis for Image-based Authentication Systems": FDKECA
//!   (feature-dependent kernel entropy component analysis) with the baselines it is compared
//!   against (PCA, KPCA, KECA), the 1-NN recognition pipeline of its section 5, and the
//!   accuracy-versus-dimension protocol of its section 6.
//! - [`gait`] and [`dtw`]: paper 17, Ahmed, Paul and Gavrilova, "Kinect-Based Gait Recognition
//!   Using Sequences of the Most Relevant Joint Relative Angles": gait cycles, joint relative
//!   angles, pair relevance, the DTW kernel and voting, with the Ball and Preis baselines and a
//!   synthetic Kinect walker.
//! - [`data`]: generated data sets with known labels (synthetic finger veins).
//!
//! Data matrices hold **one sample per row** (`n x d`, as scikit-learn); the paper writes
//! samples as columns.
#![warn(missing_docs)]

pub mod data;
pub mod dtw;
pub mod ear;
pub mod gait;
pub mod imgops;
mod model_json;
pub mod sfa;
pub mod subspace;
