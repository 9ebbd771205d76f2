//! Paper 17: Ahmed, Paul and Gavrilova, "Kinect-Based Gait Recognition Using Sequences of the
//! Most Relevant Joint Relative Angles" (WSCG 2015).
//!
//! Person identification from Kinect skeleton streams (Kinect v2 and NTU RGB+D: 25 joints;
//! Kinect v1: 20 joints; [`JointSet`]), 30 fps:
//!
//! 1. **Gait cycle** ([`detect_gait_cycle`], section 3.1): three consecutive minima of the
//!    smoothed horizontal distance between the ankles.
//! 2. **Joint relative angles** ([`jra`], [`jra_matrix`], section 3.2, eq. 1): for every pair
//!    of joints the angle at the reference joint SpineBase, in every frame of the cycle;
//!    invariant to rotation, translation and scale of the skeleton. The pairs are those of
//!    the joints the stream holds (276 for 25 joints, 171 for 20).
//! 3. **Relevance** ([`relevance_matrix`], [`select_pairs`], section 3.3): the number of
//!    histogram bins a pair's angle occupies over the cycle; pairs occupying at least t = 20
//!    bins are kept.
//! 4. **DTW kernel** ([`crate::dtw::dtw_kernel`], section 3.4, eqs. 2-6): Δ = Σ over the kept
//!    pairs of the DTW distance between the two walks' sequences (no resampling).
//! 5. **Vote** ([`Vote`], [`GaitRecognizer`]): training walks ranked by Δ; 1-NN, majority,
//!    or the paper's top-#classes+1 rule.
//!
//! Baselines ([`baselines`]): Ball et al. 2012 and Preis et al. 2012 features, raw-coordinate
//! DTW, and a resampling ablation. [`synth`] is a synthetic Kinect walker with ground truth;
//! [`protocol`] runs the paper's cross-validation (Table 1, Fig. 9) on it. [`io`] reads skeleton
//! CSV and `.npy` files, [`ntu`] NTU RGB+D `.skeleton` files.

pub mod baselines;
pub mod cycle;
pub mod io;
pub mod jra;
pub mod ntu;
pub mod protocol;
pub mod recognizer;
pub mod relevance;
pub mod skeleton;
pub mod synth;

pub use baselines::{ball_features, preis_features, raw_coordinate_sample, GaussianNb, ZScoreNn};
pub use cycle::{detect_gait_cycle, CycleChoice, CycleParams, GaitCycle, StartLeg, UpAxis};
pub use io::{
    parse_skeleton_csv, read_skeleton, read_skeleton_csv, read_skeleton_npy, read_skeleton_with,
    write_skeleton_csv, write_skeleton_npy, GaitModelFile,
};
pub use jra::{all_pairs, all_pairs_in, jra, jra_matrix, jra_sequences, JraSet};
pub use ntu::{
    ntu_bodies, parse_ntu, parse_ntu_skeleton, read_ntu, BodyChoice, NtuBody, NtuParams,
};
pub use protocol::{cross_validate, prepare, CvReport, PreparedWalks, Protocol};
pub use recognizer::{gait_sample, vote, GaitParams, GaitRecognizer, GaitSample, Prediction, Vote};
pub use relevance::{occupied_bins, relevance_matrix, select_pairs, HistSpec, JointMap};
pub use skeleton::{
    interpolate_missing, Frame, Joint, JointSet, Pair, SkeletonSeq, JOINT_NAMES, KINECT_V1_JOINTS,
    KINECT_V1_NAMES, N_JOINTS,
};
