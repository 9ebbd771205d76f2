//! Geodesic nearest-seed labelling: breadth-first search inside the bone mask from all seeds
//! at once (unweighted 6-neighbour steps); each bone voxel takes the label of the first seed
//! front to reach it. A cheap baseline (not in the paper) that random walks must beat.

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

/// Grady's original formulation on the whole image (the paper's comparison of section 2.4,
/// "by ~ 90% in our test cases"): every voxel is a
/// node, non-bone voxels included. Needs background seeds on the soft tissue; the bone-only
/// graph saves the memory and work of the ~90 % of voxels that are not bone.
pub fn full_image_graph(
    ct: &wscg_math::Volume<f32>,
    p: &crate::RandomWalkParams,
) -> wscg_math::Result<BoneGraph> {
    BoneGraph::from_mask(ct, &vec![true; ct.len()], p)
}
