//! Paper 05: Tewari, Taetz, Stricker and Grandidier, "Using Mutual Independence of Slow
//! Features for Increased Information and Improved Hand Pose Classification".
//!
//! - [`isomap`]: Isomap (Tenenbaum 2000), exact and landmark, with out-of-sample
//!   projection: the 9-D Isomap + kNN baseline of the paper's Table 6.
//! - [`handpose`]: the synthetic hand-pose generator standing in for the private
//!   time-of-flight data, and the hand-crafted "physical" features of Table 4.

pub mod handpose;
pub mod isomap;
