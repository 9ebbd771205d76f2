//! Beyond paper 08: a pixel's own distribution over its nearest VPLs, mixed into the
//! unoccluded strategy ([`super::render::ImportanceCachingParams::near_share`]).
//!
//! A VPL close to a shading point but far from every record gets a tiny probability from the
//! records' distributions, all computed farther away, while the geometry term of eq. (1)
//! makes its contribution there large. Drawing some samples from the VPLs nearest the pixel,
//! in proportion to their contributions without visibility, bounds those samples' weights.

use wscg_math::knn::KdTree;
use wscg_math::Result;

use super::scene::luminance;
use super::shading::{Receiver, Shading};

/// A search structure over the VPLs of positive power, built once per render.
pub struct NearVpls {
    tree: Option<KdTree>,
    ids: Vec<usize>,
}

impl NearVpls {
    /// The VPLs of positive power of `sh` (none: every distribution is empty).
    ///
    /// Errors: a VPL position that is not finite.
    pub fn new(sh: &Shading) -> Result<Self> {
        let ids: Vec<usize> = (0..sh.len())
            .filter(|&j| luminance(&sh.intensity[j]) > 0.0)
            .collect();
        let pts: Vec<[f64; 3]> = ids.iter().map(|&j| sh.vpls[j].pos).collect();
        let tree = if pts.is_empty() {
            None
        } else {
            Some(KdTree::new(&pts)?)
        };
        Ok(Self { tree, ids })
    }

    /// The distribution at `r` over its `k` nearest VPLs of positive power, proportional to
    /// their contributions without visibility there: `(VPL, probability)` sorted by VPL,
    /// empty when none of them lights the point.
    pub fn distribution(&self, sh: &Shading, r: &Receiver, k: usize) -> Vec<(usize, f64)> {
        let Some(tree) = &self.tree else {
            return Vec::new();
        };
        let mut out: Vec<(usize, f64)> = tree
            .knn(&r.pos, k, None)
            .into_iter()
            .map(|(i, _)| {
                let j = self.ids[i];
                (j, luminance(&sh.unoccluded(r, j)))
            })
            .filter(|e| e.1 > 0.0)
            .collect();
        let total: f64 = out.iter().map(|e| e.1).sum();
        if total.is_finite() && total > 0.0 {
            out.iter_mut().for_each(|e| e.1 /= total);
            out.sort_unstable_by_key(|e| e.0);
        } else {
            out.clear();
        }
        out
    }
}
