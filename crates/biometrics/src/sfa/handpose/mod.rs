//! Hand poses for paper 05 (§3.2): synthetic time-of-flight frames standing in for the
//! paper's private PMD-Nano recordings, the paper's pre-processing and split / augmentation
//! protocol, and the hand-crafted "physical" features of its KNN baseline (Table 4).
//!
//! - [`generate`](mod@generate): the synthetic generator (five poses FIST, FLAT, INDEX, OPEN,
//!   GRAB as in the paper's Fig. 3; 120 x 165 masks with depth, segmented from a simulated
//!   amplitude image as in the paper's §3.2.1), mask rotation and downscaling, and
//!   [`split_protocol`] (§3.2.1; split first, then augment the training frames only, an order
//!   the paper leaves open).
//! - [`features`]: fingertip, palm centre and radius, convex ratio, concave depth, polar and
//!   azimuth angle of the finger (§3.2.2, [RYZ11, PKK09, CLEL12]).
//! - [`protocol`]: the paper's comparison (Tables 3-6): class-wise SFA, KNN on physical
//!   features, on PCA-35 and on 9-D Isomap, and full-data-set SFA on one split; the
//!   rotation-robustness check.
//! - [`morphology`] (re-export of [`crate::imgops::mask`]): the mask geometry both use (connected components, exact Euclidean
//!   distance transform, contour tracing, convex hull, convexity defects).
//!
//! **The data are synthetic**: the paper's recordings are not public, and no accuracy
//! obtained on the generated frames is a measurement on real hands.

pub mod features;
pub mod generate;
pub use crate::imgops::mask as morphology;
pub mod protocol;

pub use features::{physical_features, physical_features_batch, FEATURE_NAMES, N_FEATURES};
pub use generate::{
    downscale, generate, generate_with, rotate_mask, rotated_rows, split_masks, split_protocol,
    HandposeSynthParams, Jitter, Split, SynthData, CLASS_NAMES, DOWNSCALE, N_CLASSES,
};
pub use protocol::{
    compare, compare_masks, compare_rows, rotation_robustness, CompareParams, Comparison,
    FeatureSets, Method, MethodResult, RotationCheck,
};
