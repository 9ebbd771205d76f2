//! Image quality as Table 1 of the paper reports it (section 6.2): PSNR (range 255) and
//! SSIM (Wang 2004, Gaussian window sigma 1.5, K1 = 0.01, K2 = 0.03, as scikit-image's
//! `structural_similarity(gaussian_weights=True, use_sample_covariance=False)`) on 8-bit
//! display values, excluding a border.

use wscg_math::metrics::{psnr, ssim_plane, SsimParams};
use wscg_math::{Error, Image, ImageView, Result};

/// `(PSNR, SSIM)` of `restored` against `truth` (display values in `[0, 1]`, quantised to 8
/// bits here) over the frame minus `border` pixels on each side.
///
/// Errors: different shapes, a border that leaves fewer than 16 x 16 pixels.
pub fn quality(restored: &Image<f32>, truth: &Image<f32>, border: usize) -> Result<(f64, f64)> {
    restored.ensure_same_shape(truth)?;
    let (h, w) = (truth.height(), truth.width());
    if h < 2 * border + 16 || w < 2 * border + 16 {
        return Err(Error::invalid(
            "border",
            format!("{border} px leaves too little of a {w}x{h} image"),
        ));
    }
    let crop = |img: &Image<f32>| -> Vec<f64> {
        (border..h - border)
            .flat_map(|y| (border..w - border).map(move |x| (y, x)))
            .map(|(y, x)| (img.at(y, x, 0).clamp(0.0, 1.0) * 255.0).round() as f64)
            .collect()
    };
    let (a, b) = (crop(restored), crop(truth));
    let p = psnr(&a, &b, 255.0)?;
    let (ch, cw) = (h - 2 * border, w - 2 * border);
    let s = ssim_plane(
        ImageView::plane(ch, cw, &a)?,
        ImageView::plane(ch, cw, &b)?,
        &SsimParams::default().data_range(255.0),
    )?;
    Ok((p, s))
}
