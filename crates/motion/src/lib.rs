//! # wscg-motion
//!
//! Paper 16 of WSCG vol. 23: Mukovskiy, Land, Schack and Giese, *Modeling of predictive human
//! movement coordination patterns for applications in computer graphics* (2015).
//!
//! Joint-angle trajectories of a walk-then-reach task are decomposed into kinematic primitives
//! by anechoic demixing with delays shared across trials, in a step-wise regression over three
//! actions ([`stepwise`]); the sources become dynamic primitives, followers of a Hopf leader
//! oscillator in a star network mapped onto the sources ([`hopf`], [`map`], [`svr`]); mixing
//! weights are smooth functions of the step parameters ([`lwlr`]); a predictive planner splits
//! the goal distance into steps ([`planner`]) and the online [`synthesizer`] blends actions at
//! the leader's phase wrap ([`blend`]), re-planning when the goal moves.
//!
//! Baselines: PCA ([`pca`], paper Fig. 4), anechoic demixing with zero or per-trial delays
//! ([`anechoic::DelayMode`]), and the non-predictive planner variant that keeps normal steps
//! fixed and adapts only the last one ([`planner::Planner::human_like`]).
//!
//! Data: the synthetic walker ([`walker`]) with known ground truth stands in for the paper's
//! motion capture; [`bvh`] writes (and reads) BVH so any animation tool can play the result;
//! [`bvh_file`] parses BVH of any skeleton and [`retarget`] maps it onto the model's joints.
#![warn(missing_docs)]

pub mod anechoic;
pub mod blend;
pub mod bvh;
pub mod bvh_file;
pub mod data;
pub mod dataset;
pub mod dataset_io;
mod delay_search;
pub mod fourier;
pub mod hopf;
mod linalg;
pub mod lwlr;
pub mod map;
pub mod matching;
mod orbit;
pub mod pca;
pub mod planner;
pub mod retarget;
pub mod skeleton;
pub mod stats;
pub mod stepwise;
pub mod svr;
pub mod synthesizer;
pub mod walker;

pub use anechoic::{
    fit_anechoic, refine_anechoic, refit_weights, AnechoicModel, AnechoicParams, DelayMode, Init,
};
pub use blend::blend_alpha;
pub use data::{quality, TrialSet};
pub use dataset::{Dataset, TrialAction};
pub use dataset_io::{read_dataset, write_dataset};
pub use hopf::StarNetwork;
pub use lwlr::Lwlr;
pub use pca::{pca_qualities, pca_quality};
pub use planner::{Action, Plan, PlannedAction, Planner};
pub use stepwise::{fit_stepwise, ActionLibrary, StepwiseParams};
pub use svr::Svr;
pub use synthesizer::{MapKind, Synthesis, Synthesizer, SynthesizerParams};
pub use walker::{reach_walk, WalkerParams, WalkerTruth};
