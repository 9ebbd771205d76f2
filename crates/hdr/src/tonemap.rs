//! Display of HDR radiance (pictures only; every measure works on radiance): the global
//! operator of Reinhard et al. (2002) with display gamma.

use wscg_math::{Error, Image, Result};

/// Global Reinhard tone mapping: luminance scaled so its log-average maps to `key`, then
/// `L / (1 + L)`, colours kept in ratio, gamma `1 / 2.2`. Output in `[0, 1]`.
///
/// Errors: `key` not in `(0, 1]`; non-finite or negative radiance.
pub fn reinhard(hdr: &Image<f32>, key: f32) -> Result<Image<f32>> {
    if !(key > 0.0 && key <= 1.0) {
        return Err(Error::invalid(
            "key",
            format!("must be in (0, 1], got {key}"),
        ));
    }
    hdr.ensure_finite("hdr")?;
    if hdr.data().iter().any(|&v| v < 0.0) {
        return Err(Error::invalid("hdr", "radiance must be >= 0"));
    }
    let c = hdr.channels();
    let lum = |p: &[f32]| {
        if c >= 3 {
            0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
        } else {
            p[0]
        }
    };
    let n = (hdr.height() * hdr.width()).max(1) as f64;
    let log_avg = (hdr
        .data()
        .chunks_exact(c)
        .map(|p| (lum(p) as f64 + 1e-6).ln())
        .sum::<f64>()
        / n)
        .exp() as f32;
    let scale = key / log_avg;
    let mut out = Vec::with_capacity(hdr.data().len());
    for p in hdr.data().chunks_exact(c) {
        let l = lum(p) * scale;
        let ratio = if l > 0.0 {
            (l / (1.0 + l)) / l * scale
        } else {
            0.0
        };
        out.extend(
            p.iter()
                .map(|&v| (v * ratio).clamp(0.0, 1.0).powf(1.0 / 2.2)),
        );
    }
    Image::new(hdr.height(), hdr.width(), c, out)
}
