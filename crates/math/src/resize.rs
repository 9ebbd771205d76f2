//! Image resizing: area averaging and bilinear interpolation.
//!
//! Both methods are separable: a weight table is built per axis and applied to rows, then
//! to columns (in parallel). Pixel centres sit at half-integer positions (`x + 0.5`), as in
//! OpenCV and scikit-image, so resizing does not shift the image.
//!
//! - [`Interpolation::Area`]: every output pixel is the exact area-weighted mean of the
//!   input pixels its footprint covers (fractional coverage at the edges). For integer
//!   downscaling factors this is the block mean, equal to OpenCV's `INTER_AREA`. Use it to
//!   downscale without aliasing.
//! - [`Interpolation::Bilinear`]: the output pixel centre `(i + 0.5) * scale - 0.5` is
//!   interpolated between its two neighbours per axis, clamped at the border (OpenCV's
//!   `INTER_LINEAR`).

use rayon::prelude::*;

use crate::alloc;
use crate::error::{Error, Result};
use crate::image::Image;

/// Resampling method of [`resize`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interpolation {
    /// Exact area averaging (box filter over the output pixel's footprint).
    #[default]
    Area,
    /// Bilinear interpolation with half-pixel centres.
    Bilinear,
}

/// Per-output-sample list of `(input index, weight)`.
type Taps = Vec<Vec<(usize, f64)>>;

fn taps(n_in: usize, n_out: usize, method: Interpolation) -> Taps {
    let scale = n_in as f64 / n_out as f64;
    (0..n_out)
        .map(|o| match method {
            Interpolation::Area => {
                let (lo, hi) = (o as f64 * scale, (o + 1) as f64 * scale);
                let mut t = Vec::new();
                let mut i = lo.floor() as usize;
                while (i as f64) < hi && i < n_in {
                    let cover = (hi.min(i as f64 + 1.0) - lo.max(i as f64)).max(0.0);
                    if cover > 0.0 {
                        t.push((i, cover / scale));
                    }
                    i += 1;
                }
                t
            }
            Interpolation::Bilinear => {
                let s = ((o as f64 + 0.5) * scale - 0.5).clamp(0.0, (n_in - 1) as f64);
                let i0 = s.floor() as usize;
                let f = s - i0 as f64;
                if f == 0.0 || i0 + 1 >= n_in {
                    vec![(i0, 1.0)]
                } else {
                    vec![(i0, 1.0 - f), (i0 + 1, f)]
                }
            }
        })
        .collect()
}

/// Resizes `img` to `height x width` (channels kept) with the given method.
///
/// Errors: a zero target size, non-finite pixels; [`Error::OutOfMemory`] naming
/// `height, width` when the output does not fit in memory ([`crate::alloc`]).
pub fn resize(
    img: &Image<f32>,
    height: usize,
    width: usize,
    method: Interpolation,
) -> Result<Image<f32>> {
    if height == 0 || width == 0 {
        return Err(Error::invalid(
            "height, width",
            format!("target size must be > 0, got {height}x{width}"),
        ));
    }
    img.ensure_finite("img")?;
    let (h, w, c) = img.shape();
    let what = "height, width";
    let n_out = alloc::ensure_shape::<f32>(what, &[height, width, c])?;
    let n_tmp = alloc::ensure_shape::<f64>(what, &[h, width, c])?;
    alloc::ensure::<(usize, f64)>(what, height.saturating_add(width).saturating_mul(2))?;
    let tx = taps(w, width, method);
    let ty = taps(h, height, method);
    // Horizontal pass: h x width x c.
    let mut tmp = alloc::try_vec(what, 0.0f64, n_tmp)?;
    tmp.par_chunks_mut(width * c)
        .enumerate()
        .for_each(|(y, row)| {
            let src = &img.data()[y * w * c..(y + 1) * w * c];
            for (x, t) in tx.iter().enumerate() {
                for &(i, wt) in t {
                    for ch in 0..c {
                        row[x * c + ch] += wt * src[i * c + ch] as f64;
                    }
                }
            }
        });
    // Vertical pass.
    let mut out = alloc::try_vec(what, 0.0f32, n_out)?;
    out.par_chunks_mut(width * c)
        .enumerate()
        .for_each(|(y, row)| {
            let mut acc = vec![0.0f64; width * c];
            for &(i, wt) in &ty[y] {
                let src = &tmp[i * width * c..(i + 1) * width * c];
                acc.iter_mut().zip(src).for_each(|(a, &s)| *a += wt * s);
            }
            row.iter_mut().zip(acc).for_each(|(o, a)| *o = a as f32);
        });
    Image::new(height, width, c, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_downscale_by_integer_factor_is_block_mean() {
        let img = Image::from_fn(6, 9, |y, x| (y * 9 + x) as f32).unwrap();
        let r = resize(&img, 2, 3, Interpolation::Area).unwrap();
        for oy in 0..2 {
            for ox in 0..3 {
                let mut s = 0.0;
                for y in 0..3 {
                    for x in 0..3 {
                        s += img.at(oy * 3 + y, ox * 3 + x, 0);
                    }
                }
                assert!((r.at(oy, ox, 0) - s / 9.0).abs() < 1e-4);
            }
        }
    }

    #[test]
    fn area_resize_preserves_the_mean_for_any_factor() {
        let img = Image::from_fn(37, 23, |y, x| ((y * 7 + x * 3) % 11) as f32 / 10.0).unwrap();
        let mean =
            |i: &Image| i.data().iter().map(|&v| v as f64).sum::<f64>() / i.data().len() as f64;
        for (h, w) in [(10, 7), (37, 23), (74, 50), (5, 19)] {
            let r = resize(&img, h, w, Interpolation::Area).unwrap();
            assert!((mean(&r) - mean(&img)).abs() < 1e-5, "{h}x{w}");
        }
    }

    #[test]
    fn bilinear_reproduces_affine_images_in_the_interior() {
        let f = |y: f64, x: f64| 0.1 + 0.02 * y - 0.03 * x;
        let img = Image::from_fn(16, 20, |y, x| f(y as f64, x as f64) as f32).unwrap();
        let (h2, w2) = (40, 30);
        let r = resize(&img, h2, w2, Interpolation::Bilinear).unwrap();
        for oy in 2..h2 - 2 {
            for ox in 2..w2 - 2 {
                let sy = (oy as f64 + 0.5) * 16.0 / h2 as f64 - 0.5;
                let sx = (ox as f64 + 0.5) * 20.0 / w2 as f64 - 0.5;
                assert!((r.at(oy, ox, 0) as f64 - f(sy, sx)).abs() < 1e-5);
            }
        }
        // Same size is the identity.
        let same = resize(&img, 16, 20, Interpolation::Bilinear).unwrap();
        assert_eq!(same, img);
    }

    #[test]
    fn multichannel_and_bad_sizes() {
        let img = Image::new(2, 2, 3, (0..12).map(|v| v as f32).collect()).unwrap();
        let r = resize(&img, 1, 1, Interpolation::Area).unwrap();
        assert_eq!(r.shape(), (1, 1, 3));
        assert!((r.at(0, 0, 1) - (1.0 + 4.0 + 7.0 + 10.0) / 4.0).abs() < 1e-6);
        assert!(resize(&img, 0, 3, Interpolation::Area).is_err());
    }
}
