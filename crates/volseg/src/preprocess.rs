//! Optional smoothing before the threshold (paper section 2.1): the paper smooths with
//! a small Gaussian "taking voxel anisotropy into account" without giving a formula; here the
//! standard deviation along axis `a` is `0.6 · min(spacing) / spacing_a` voxels, 3 taps
//! (kernel radius 1; an axis whose sigma is below 0.3 voxel is left alone), replicated border.

use wscg_math::filter::Border;
use wscg_math::{Error, Result, Volume};

/// Sigma (voxels) of the finest axis.
const SIGMA: f64 = 0.6;

/// `passes` rounds of the anisotropy-aware 3-tap Gaussian above (0 returns a copy).
/// Errors: non-finite CT values.
pub fn gaussian_smooth3(ct: &Volume<f32>, passes: u32) -> Result<Volume<f32>> {
    if let Some(index) = ct.data().iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite { name: "ct", index });
    }
    let h = ct.spacing();
    let hmin = h.iter().copied().fold(f64::INFINITY, f64::min);
    let sigma = h.map(|a| SIGMA * hmin / a);
    let mut out = ct.clone();
    for _ in 0..passes {
        // Radius int(truncate · sigma + 0.5) = 1 for sigma in [0.3, 0.6].
        out = out.gaussian_filter(sigma, 1.0 / SIGMA, Border::Nearest)?;
    }
    Ok(out)
}

/// The bone mask `I >= t_bone` (paper section 2.1; `>=` so that it matches the isosurface of
/// section 2.2).
pub fn threshold(ct: &Volume<f32>, t_bone: f64) -> Vec<bool> {
    ct.data().iter().map(|&v| f64::from(v) >= t_bone).collect()
}
