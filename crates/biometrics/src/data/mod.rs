//! Generated data sets with known labels (nothing is downloaded).

pub mod fingervein;

pub use fingervein::{finger_veins, split_per_subject, FingerVeinParams, LabelledImages};
