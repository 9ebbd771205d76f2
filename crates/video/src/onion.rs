//! The "3D hole-filling" order of paper 06, section 3.2: hole pixels in shells of equal
//! distance to the known region `E`, outer shell first, so that every patch being updated
//! sees known pixels or pixels already updated in the current iteration.

use wscg_math::Result;

use crate::patchmatch::{TargetSet, P3};
use crate::video::Mask3;

/// The exact 3-D Euclidean distance (voxel units) to the known region `E`, held on the hole's
/// bounding box grown by one voxel: every point outside the box is known, so the nearest
/// known point of a hole pixel lies in the grown box. Memory is proportional to the box, not
/// to the video.
struct DistanceBox {
    lo: P3,
    hi: P3,
    ext: [usize; 3],
    d2: Vec<f64>,
}

impl DistanceBox {
    /// Errors: a hole covering the whole video.
    fn new(hole: &Mask3) -> Result<Self> {
        let dims = hole.dims();
        let n = hole.count();
        if n == hole.len_grid() {
            return Err(wscg_math::Error::invalid(
                "mask",
                "the mask covers the whole video: no known pixel to fill from",
            ));
        }
        if n == 0 {
            return Ok(Self {
                lo: [1, 1, 1],
                hi: [0, 0, 0],
                ext: [0; 3],
                d2: Vec::new(),
            });
        }
        let mut lo = [u32::MAX; 3];
        let mut hi = [0u32; 3];
        for p in hole.iter_points() {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        for a in 0..3 {
            lo[a] = lo[a].saturating_sub(1);
            hi[a] = (hi[a] + 1).min(dims[a] as u32 - 1);
        }
        let ext = [0, 1, 2].map(|a| (hi[a] - lo[a] + 1) as usize);
        let mut b = Self {
            lo,
            hi,
            ext,
            d2: Vec::new(),
        };
        let mut known = vec![true; ext.iter().product()];
        for p in hole.iter_points() {
            known[b.index(p)] = false;
        }
        b.d2 = wscg_math::distance::squared_edt(&known, &ext, &[1.0; 3], false)?;
        Ok(b)
    }

    fn index(&self, p: P3) -> usize {
        let [lo, ext] = [self.lo, self.ext.map(|e| e as u32)];
        (((p[0] - lo[0]) * ext[1] + (p[1] - lo[1])) as usize) * ext[2] as usize
            + (p[2] - lo[2]) as usize
    }

    /// The distance of `p` to `E` (0 outside the box).
    fn at(&self, p: P3) -> f64 {
        if (0..3).all(|a| p[a] >= self.lo[a] && p[a] <= self.hi[a]) {
            self.d2[self.index(p)].sqrt()
        } else {
            0.0
        }
    }
}

/// The exact 3-D Euclidean distance (voxel units) of every point of `points` to the known
/// region `E` (0 for known points; the outside of the video does not count as `E`).
///
/// Errors: a hole covering the whole video.
pub fn distance_to_known(hole: &Mask3, points: impl Iterator<Item = P3>) -> Result<Vec<f64>> {
    let b = DistanceBox::new(hole)?;
    Ok(points.map(|p| b.at(p)).collect())
}

/// The hole pixels (ranks in `targets`, the hole's points in scan order) grouped in shells:
/// shell `k` holds the pixels whose exact 3-D Euclidean distance to `E` (voxel units, the
/// outside of the video not counting as `E`) lies in `(k, k + 1]`, each shell in scan order.
///
/// Errors: a hole without any known pixel in the video.
pub fn onion_order(hole: &Mask3, targets: &TargetSet) -> Result<Vec<Vec<u32>>> {
    let b = DistanceBox::new(hole)?;
    let mut shells: Vec<Vec<u32>> = Vec::new();
    for i in 0..targets.len() {
        let d = b.at(targets.get(i));
        let k = (d.ceil() as usize).max(1) - 1;
        if shells.len() <= k {
            shells.resize(k + 1, Vec::new());
        }
        shells[k].push(i as u32);
    }
    shells.retain(|s| !s.is_empty());
    Ok(shells)
}

/// The scan-line order (the ablation of section 3.2): every hole pixel in its own step, in
/// scan order.
pub fn scanline_order(targets: &TargetSet) -> Vec<Vec<u32>> {
    (0..targets.len() as u32).map(|i| vec![i]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shells_peel_a_box_from_the_outside() {
        // A 5 x 5 x 5 hole in the middle of 11^3: shells at distance 1, 2 and 3.
        let hole = Mask3::from_fn(11, 11, 11, |t, y, x| {
            [t, y, x].iter().all(|&v| (3..8).contains(&v))
        });
        let targets = TargetSet::new(hole.dims(), hole.points());
        let shells = onion_order(&hole, &targets).unwrap();
        assert_eq!(shells.len(), 3);
        assert_eq!(shells.iter().map(Vec::len).sum::<usize>(), 125);
        assert_eq!(shells[2].len(), 1);
        assert_eq!(targets.get(shells[2][0] as usize), [5, 5, 5]);
        assert_eq!(shells[0].len(), 125 - 27);
        let all = Mask3::from_fn(2, 2, 2, |_, _, _| true);
        let t = TargetSet::new(all.dims(), all.points());
        assert!(onion_order(&all, &t).is_err());
    }
}
