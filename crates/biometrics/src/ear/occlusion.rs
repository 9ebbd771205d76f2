//! Occlusion detection and estimation (section 3.3, Algorithm 1).
//!
//! On the normalised colour image (not equalised): per-pixel skin decision in `(r, g)`
//! (steps 2-6), closing with an exact Euclidean disk of radius 10 and hole filling (step 7),
//! per-block skin fraction (steps 9-10), occlusion percentage `E = 100 (blocks - m) / blocks`
//! (step 11: the printed eq. 6 is garbled and its prose says "un-occluded over total", but
//! the rejection rule only makes sense for occluded over total) and rejection when
//! `E > 60` (step 12; exactly 60 % is accepted).

use wscg_math::image::Image;
use wscg_math::{ImageView, Result};

use super::features::{check_input, normalise};
use super::params::EarParams;
use crate::imgops::mask::{close_disk, fill_holes};

/// What Algorithm 1 found in a probe.
#[derive(Clone, Debug, PartialEq)]
pub struct OcclusionReport {
    /// Skin (un-occluded) mask `Z` after closing and hole filling, `height x width`, 0/1.
    pub skin_mask: Image<u8>,
    /// Fraction of skin pixels of `Z` in every block, by block index.
    pub block_skin_fraction: Vec<f64>,
    /// Whether each block is un-occluded (fraction `>= block_skin_fraction`).
    pub block_unoccluded: Vec<bool>,
    /// Occlusion percentage `E` (step 11).
    pub occluded_pct: f64,
    /// `E > reject_above_pct`: the probe should be reacquired (step 12).
    pub rejected: bool,
}

impl OcclusionReport {
    /// Indices of the un-occluded blocks, ascending (the index vector `I` of step 10).
    pub fn index(&self) -> Vec<usize> {
        (0..self.block_unoccluded.len())
            .filter(|&b| self.block_unoccluded[b])
            .collect()
    }
}

/// Per-pixel skin decision of a normalised RGB image (steps 2-6), 0/1, before closing.
pub fn skin_pixels(small: &Image<u8>, p: &EarParams) -> Vec<u8> {
    small
        .data()
        .chunks_exact(3)
        .map(|px| {
            u8::from(
                p.skin_rule
                    .is_skin(&p.skin_model, [px[0], px[1], px[2]], p.min_intensity),
            )
        })
        .collect()
}

/// Occlusion report of an RGB ear crop of any size (it is normalised first).
///
/// Errors: an image under 2 x 2, a non-RGB image, bad parameters.
pub fn detect_occlusion(img: &Image<u8>, p: &EarParams) -> Result<OcclusionReport> {
    p.validate()?;
    check_input(img, false)?;
    detect_on_normalised(&normalise(img, p)?, p)
}

/// [`detect_occlusion`] on an image already at the normalised size.
pub(crate) fn detect_on_normalised(small: &Image<u8>, p: &EarParams) -> Result<OcclusionReport> {
    let (h, w) = (p.height, p.width);
    let skin = skin_pixels(small, p);
    let mut z = close_disk(ImageView::plane(h, w, &skin)?, p.close_radius)?;
    if p.fill_holes {
        z = fill_holes(z.view())?;
    }
    let zd = z.data();
    let (gr, gc) = p.grid();
    let area = (p.block * p.block) as f64;
    let mut frac = Vec::with_capacity(gr * gc);
    for bi in 0..gr {
        for bj in 0..gc {
            let mut n = 0usize;
            for y in bi * p.block..(bi + 1) * p.block {
                let row = &zd[y * w + bj * p.block..y * w + (bj + 1) * p.block];
                n += row.iter().filter(|&&v| v != 0).count();
            }
            frac.push(n as f64 / area);
        }
    }
    let keep: Vec<bool> = frac.iter().map(|&f| f >= p.block_skin_fraction).collect();
    let m = keep.iter().filter(|&&k| k).count();
    let occluded_pct = 100.0 * (keep.len() - m) as f64 / keep.len() as f64;
    Ok(OcclusionReport {
        skin_mask: z,
        block_skin_fraction: frac,
        block_unoccluded: keep,
        occluded_pct,
        rejected: occluded_pct > p.reject_above_pct,
    })
}
