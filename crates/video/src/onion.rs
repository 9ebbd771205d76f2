//! The "3D hole-filling" order of paper 06, section 3.2: hole pixels in shells of equal
//! distance to the known region `E`, outer shell first, so that every patch being updated
//! sees known pixels or pixels already updated in the current iteration.

use wscg_math::patchmatch::TargetSet;
use wscg_math::Result;

use crate::video::Mask3;

/// The hole pixels (ranks in `targets`, the hole's points in scan order) grouped in shells:
/// shell `k` holds the pixels whose exact 3-D Euclidean distance to `E` (voxel units, the
/// outside of the video not counting as `E`) lies in `(k, k + 1]`, each shell in scan order.
///
/// Errors: a hole without any known pixel in the video.
pub fn onion_order(hole: &Mask3, targets: &TargetSet) -> Result<Vec<Vec<u32>>> {
    let known: Vec<bool> = (0..hole.len_grid())
        .map(|i| !hole.contains_index(i))
        .collect();
    if !known.iter().any(|&k| k) {
        return Err(wscg_math::Error::invalid(
            "mask",
            "the mask covers the whole video: no known pixel to fill from",
        ));
    }
    let d2 = wscg_math::distance::squared_edt(&known, &hole.dims(), &[1.0; 3], false)?;
    let mut shells: Vec<Vec<u32>> = Vec::new();
    for i in 0..targets.len() {
        let d = d2[hole.index(targets.get(i))].sqrt();
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
