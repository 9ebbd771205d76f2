//! Segmentation accuracy (paper eq. 2).

use wscg_math::{Error, Result};

/// Multi-label Dice similarity `2 |A ∩ B| / (|A| + |B|)`: `|A ∩ B|` counts voxels with the
/// same non-zero label in both, `|A|` the non-zero voxels of `A` (paper eq. 2). 1 when both
/// are empty. Errors: different lengths.
pub fn dice_multilabel(a: &[u16], b: &[u16]) -> Result<f64> {
    if a.len() != b.len() {
        return Err(Error::ShapeMismatch(format!(
            "{} and {} voxels",
            a.len(),
            b.len()
        )));
    }
    let (mut inter, mut na, mut nb) = (0usize, 0usize, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        na += usize::from(x != 0);
        nb += usize::from(y != 0);
        inter += usize::from(x != 0 && x == y);
    }
    Ok(if na + nb == 0 {
        1.0
    } else {
        2.0 * inter as f64 / (na + nb) as f64
    })
}
