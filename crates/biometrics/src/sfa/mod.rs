//! Paper 05: Tewari, Taetz, Stricker and Grandidier, "Using Mutual Independence of Slow
//! Features for Increased Information and Improved Hand Pose Classification".
//!
//! - [`expansion`]: the quadratic expansion (section 3.1).
//! - [`scatter`]: streamed per-class moments and rank-robust whitening.
//! - [`temporal`]: temporal SFA (section 2.1, eqs. 1-7), the building block.
//! - [`class_sfa`]: the paper's class-wise SFA and its variance classifier (eqs. 8-17).
//! - [`global`]: SFA fitted once on all classes (Berkes 2005), the "Full dataset" row of
//!   Table 1, with the variance and Gaussian decision rules.
//! - [`knn`]: the k-NN baselines (Tables 4-6) and the confusion matrix.
//! - [`neighbours`]: exact brute-force k-nearest rows (k-NN and Isomap).
//! - [`isomap`]: Isomap (Tenenbaum 2000), exact and landmark, with out-of-sample
//!   projection: the 9-D Isomap + kNN baseline of the paper's Table 6.
//! - [`handpose`]: the synthetic hand-pose generator standing in for the private
//!   time-of-flight data, and the hand-crafted "physical" features of Table 4.

pub mod class_sfa;
pub mod expansion;
pub mod global;
pub mod handpose;
pub mod isomap;
pub mod knn;
pub mod model_file;
pub mod neighbours;
pub mod scatter;
pub mod temporal;

pub use class_sfa::{ClassObjective, ClassSfaParams, PerClassSfa};
pub use expansion::QuadraticExpansion;
pub use global::{GlobalRule, GlobalSfa};
pub use knn::{confusion_matrix, Knn, KnnTie};
pub use model_file::{FittedSfa, SfaModelFile, MAX_SFA_MODEL_BYTES};
pub use temporal::TemporalSfa;
