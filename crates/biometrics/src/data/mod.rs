//! Data for the recognition pipeline: generated data sets with known labels (nothing is
//! downloaded) and loaders for users' own images and `.npy` files.

pub mod files;
pub mod fingervein;

pub use files::{load_identity_folder, read_npy_dataset, IdentityImages};
pub use fingervein::{finger_veins, split_per_subject, FingerVeinParams, LabelledImages};
