//! Geodesic nearest-seed labelling: breadth-first search inside the bone mask from all seeds
//! at once (unweighted 6-neighbour steps); each bone voxel takes the label of the first seed
//! front to reach it. The cheap baseline of spec section 2.3.

use std::collections::VecDeque;

use crate::graph::{BoneGraph, NONE};

/// Labels of every node by geodesic nearest seed (`seeds[i]`, 0 = none); nodes no seed
/// reaches stay 0. Ties go to the seed front queued first (lower node id).
pub fn nearest_seed_labels(g: &BoneGraph, seeds: &[u16]) -> Vec<u16> {
    let mut out = seeds.to_vec();
    let mut q: VecDeque<usize> = (0..g.len()).filter(|&i| seeds[i] != 0).collect();
    while let Some(i) = q.pop_front() {
        for &j in g.neighbours(i) {
            if j != NONE && out[j as usize] == 0 {
                out[j as usize] = out[i];
                q.push_back(j as usize);
            }
        }
    }
    out
}
