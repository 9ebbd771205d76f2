//! Separable filters on images and 2-D planes: Gaussian, box, and any separable kernel.
//!
//! The border handling and the Gaussian kernel follow `scipy.ndimage` exactly (same
//! [`Border`] modes, kernel radius `int(truncate * sigma + 0.5)`, normalised samples of
//! `exp(-x^2 / (2 sigma^2))`), so results agree with `scipy.ndimage.gaussian_filter` and
//! `uniform_filter` to rounding. Filtering is a correlation; every kernel here is symmetric,
//! so it is also a convolution. Rows are processed in parallel with rayon; sums are in f64.

use rayon::prelude::*;

use crate::error::{ensure_finite, ensure_positive, Error, Result};
use crate::image::Image;
use crate::view::ImageView;

/// How samples outside the array are defined (names and meanings as in `scipy.ndimage`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Border {
    /// `d c b a | a b c d | d c b a`: half-sample symmetric (scipy's default `reflect`).
    #[default]
    Reflect,
    /// `d c b | a b c d | c b a`: whole-sample symmetric (`mirror`).
    Mirror,
    /// `a a a | a b c d | d d d`: edge value repeated (`nearest`).
    Nearest,
    /// `b c d | a b c d | a b c`: periodic (`wrap`).
    Wrap,
    /// A constant value outside (`constant` with `cval`).
    Constant(f64),
}

impl Border {
    /// Maps a possibly out-of-range index `i` onto `0..n`; `None` means the constant value.
    #[inline]
    pub fn map(self, i: isize, n: usize) -> Option<usize> {
        let ni = n as isize;
        if (0..ni).contains(&i) {
            return Some(i as usize);
        }
        Some(match self {
            Border::Constant(_) => return None,
            Border::Nearest => i.clamp(0, ni - 1) as usize,
            Border::Wrap => i.rem_euclid(ni) as usize,
            Border::Reflect => {
                let m = i.rem_euclid(2 * ni);
                (if m < ni { m } else { 2 * ni - 1 - m }) as usize
            }
            Border::Mirror => {
                if n == 1 {
                    0
                } else {
                    let p = 2 * ni - 2;
                    let m = i.rem_euclid(p);
                    (if m < ni { m } else { p - m }) as usize
                }
            }
        })
    }

    pub(crate) fn cval(self) -> f64 {
        match self {
            Border::Constant(v) => v,
            _ => 0.0,
        }
    }
}

/// The sampled, normalised Gaussian of standard deviation `sigma` (pixels), of radius
/// `int(truncate * sigma + 0.5)` (scipy's `_gaussian_kernel1d`). Length `2 * radius + 1`.
///
/// Errors: `sigma` or `truncate` not finite and > 0; [`Error::OutOfMemory`] naming
/// `truncate * sigma` when the kernel does not fit in memory ([`crate::alloc`]).
pub fn gaussian_kernel(sigma: f64, truncate: f64) -> Result<Vec<f64>> {
    ensure_positive("sigma", sigma)?;
    ensure_positive("truncate", truncate)?;
    let what = "truncate * sigma";
    let radius = (truncate * sigma + 0.5).floor();
    // 2^62 taps are far beyond any memory limit; the check keeps the conversions exact.
    if radius >= (1u64 << 62) as f64 {
        return Err(crate::alloc::overflow(what));
    }
    let radius = radius as isize;
    let mut k = crate::alloc::try_with_capacity(what, 2 * radius as usize + 1)?;
    k.extend((-radius..=radius).map(|x| (-0.5 * (x as f64) * (x as f64) / (sigma * sigma)).exp()));
    let s: f64 = k.iter().sum();
    k.iter_mut().for_each(|v| *v /= s);
    Ok(k)
}

fn check_kernel(name: &'static str, k: &[f64]) -> Result<()> {
    if k.is_empty() || k.len().is_multiple_of(2) {
        return Err(Error::invalid(
            name,
            format!("kernel length must be odd (centred), got {}", k.len()),
        ));
    }
    ensure_finite(name, k)
}

/// Correlates the single-channel image `src` with `ky` along rows (vertical) and `kx` along
/// columns (horizontal). Kernels have odd length and are centred.
///
/// Errors: `src` with more than one channel, even or non-finite kernels.
pub fn separable_plane(
    src: ImageView<'_, f64>,
    ky: &[f64],
    kx: &[f64],
    border: Border,
) -> Result<Image<f64>> {
    src.ensure_plane("src")?;
    check_kernel("ky", ky)?;
    check_kernel("kx", kx)?;
    let (h, w) = (src.height(), src.width());
    let tmp = vertical(src.data(), h, w, ky, border);
    Image::new(h, w, 1, horizontal(&tmp, h, w, kx, border))
}

fn vertical(src: &[f64], h: usize, w: usize, k: &[f64], border: Border) -> Vec<f64> {
    let r = (k.len() / 2) as isize;
    let cval = border.cval();
    let mut out = vec![0.0; h * w];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (j, &kj) in k.iter().enumerate() {
            match border.map(y as isize + j as isize - r, h) {
                Some(sy) => {
                    let s = &src[sy * w..sy * w + w];
                    row.iter_mut().zip(s).for_each(|(o, &v)| *o += kj * v);
                }
                None => row.iter_mut().for_each(|o| *o += kj * cval),
            }
        }
    });
    out
}

fn horizontal(src: &[f64], h: usize, w: usize, k: &[f64], border: Border) -> Vec<f64> {
    let r = k.len() / 2;
    let cval = border.cval();
    let mut out = vec![0.0; h * w];
    out.par_chunks_mut(w).enumerate().for_each_init(
        || vec![0.0; w + 2 * r],
        |pad, (y, row)| {
            let s = &src[y * w..y * w + w];
            for (i, p) in pad.iter_mut().enumerate() {
                *p = border
                    .map(i as isize - r as isize, w)
                    .map_or(cval, |sx| s[sx]);
            }
            // Accumulate tap by tap so the inner loop runs along the row (vectorises).
            for (j, &kj) in k.iter().enumerate() {
                row.iter_mut()
                    .zip(&pad[j..j + w])
                    .for_each(|(o, &v)| *o += kj * v);
            }
        },
    );
    out
}

/// Applies `f` (a plane filter) to every channel of `img` and reassembles the image.
pub fn per_channel(
    img: &Image<f32>,
    f: impl Fn(ImageView<'_, f64>) -> Result<Image<f64>>,
) -> Result<Image<f32>> {
    let (h, w, c) = img.shape();
    let mut out = vec![0.0f32; h * w * c];
    for ch in 0..c {
        let plane = img.plane_f64(ch);
        let res = f(ImageView::plane(h, w, &plane)?)?;
        for (o, &v) in out.iter_mut().skip(ch).step_by(c).zip(res.data()) {
            *o = v as f32;
        }
    }
    Image::new(h, w, c, out)
}

/// Gaussian blur of every channel with standard deviation `sigma` pixels, as
/// `scipy.ndimage.gaussian_filter(img, sigma=(sigma, sigma, 0), truncate=truncate, mode=...)`.
///
/// Errors: `sigma`/`truncate` not > 0, non-finite pixels.
pub fn gaussian_filter(
    img: &Image<f32>,
    sigma: f64,
    truncate: f64,
    border: Border,
) -> Result<Image<f32>> {
    img.ensure_finite("img")?;
    let k = gaussian_kernel(sigma, truncate)?;
    per_channel(img, |p| separable_plane(p, &k, &k, border))
}

/// The normalised box kernel of radius `radius` (length `2 radius + 1`, every tap equal).
///
/// Errors: [`Error::OutOfMemory`] naming `radius` when the kernel does not fit in memory.
pub fn box_kernel(radius: usize) -> Result<Vec<f64>> {
    let n = radius
        .checked_mul(2)
        .and_then(|d| d.checked_add(1))
        .ok_or_else(|| crate::alloc::overflow("radius"))?;
    crate::alloc::try_vec("radius", 1.0 / n as f64, n)
}

/// Mean over a `(2 radius + 1)^2` window of every channel, as
/// `scipy.ndimage.uniform_filter(img, size=2*radius+1)` per channel.
///
/// Errors: non-finite pixels; [`Error::OutOfMemory`] naming `radius` (see [`box_kernel`]).
pub fn box_filter(img: &Image<f32>, radius: usize, border: Border) -> Result<Image<f32>> {
    img.ensure_finite("img")?;
    let k = box_kernel(radius)?;
    per_channel(img, |p| separable_plane(p, &k, &k, border))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn border_modes_match_scipy_definitions() {
        // n = 4, indices -3..7 for each mode (scipy.ndimage docs).
        let idx: Vec<isize> = (-3..7).collect();
        let m = |b: Border| -> Vec<Option<usize>> { idx.iter().map(|&i| b.map(i, 4)).collect() };
        let s = |v: &[usize]| v.iter().map(|&x| Some(x)).collect::<Vec<_>>();
        assert_eq!(m(Border::Reflect), s(&[2, 1, 0, 0, 1, 2, 3, 3, 2, 1]));
        assert_eq!(m(Border::Mirror), s(&[3, 2, 1, 0, 1, 2, 3, 2, 1, 0]));
        assert_eq!(m(Border::Nearest), s(&[0, 0, 0, 0, 1, 2, 3, 3, 3, 3]));
        assert_eq!(m(Border::Wrap), s(&[1, 2, 3, 0, 1, 2, 3, 0, 1, 2]));
        assert_eq!(Border::Constant(0.0).map(-1, 4), None);
        assert_eq!(Border::Mirror.map(-2, 1), Some(0));
    }

    #[test]
    fn gaussian_kernel_matches_scipy_values() {
        // scipy.ndimage._filters._gaussian_kernel1d(1.5, 0, 5) (skimage SSIM window).
        let k = gaussian_kernel(1.5, 3.5).unwrap();
        assert_eq!(k.len(), 11);
        let z: f64 = (-5..=5).map(|x: i32| (-(x * x) as f64 / 4.5).exp()).sum();
        assert!((k[5] - 1.0 / z).abs() < 1e-15);
        assert!((k.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        assert!(gaussian_kernel(0.0, 4.0).is_err());
        assert!(gaussian_kernel(1.0, f64::NAN).is_err());
        for (sigma, truncate) in [(1e12, 4.0), (1.0, 1e15), (1e300, 1e300)] {
            let e = gaussian_kernel(sigma, truncate).unwrap_err();
            assert!(matches!(e, Error::OutOfMemory { .. }), "{e}");
            assert_eq!(e.argument(), Some("truncate * sigma"));
        }
        assert_eq!(
            box_kernel(usize::MAX).unwrap_err().argument(),
            Some("radius")
        );
        assert_eq!(box_kernel(1 << 40).unwrap_err().argument(), Some("radius"));
        assert_eq!(box_kernel(2).unwrap(), vec![0.2; 5]);
    }

    #[test]
    fn filters_preserve_constants_and_linear_ramps() {
        // A normalised symmetric kernel reproduces affine functions away from the border,
        // and Reflect keeps constants everywhere.
        let img = Image::from_fn(20, 30, |y, x| 0.5 + 0.01 * y as f32 - 0.02 * x as f32).unwrap();
        let g = gaussian_filter(&img, 1.2, 4.0, Border::Reflect).unwrap();
        for y in 6..14 {
            for x in 6..24 {
                assert!((g.at(y, x, 0) - img.at(y, x, 0)).abs() < 1e-5);
            }
        }
        let c = Image::filled(5, 7, 3, 0.25f32).unwrap();
        for b in [
            Border::Reflect,
            Border::Mirror,
            Border::Nearest,
            Border::Wrap,
        ] {
            let f = box_filter(&c, 2, b).unwrap();
            assert!(f.data().iter().all(|v| (v - 0.25).abs() < 1e-6));
        }
    }

    #[test]
    fn impulse_response_is_the_outer_product_kernel() {
        let mut img = Image::filled(15, 15, 1, 0.0f32).unwrap();
        img.set(7, 7, 0, 1.0);
        let k = gaussian_kernel(1.0, 4.0).unwrap();
        let g = gaussian_filter(&img, 1.0, 4.0, Border::Constant(0.0)).unwrap();
        for dy in 0..9 {
            for dx in 0..9 {
                let v = g.at(3 + dy, 3 + dx, 0) as f64;
                assert!((v - k[dy] * k[dx]).abs() < 1e-7);
            }
        }
        // Mass is conserved away from the border.
        let s: f32 = g.data().iter().sum();
        assert!((s - 1.0).abs() < 1e-5);
    }

    #[test]
    fn constant_border_uses_cval() {
        let img = Image::filled(3, 3, 1, 0.0f32).unwrap();
        let f = box_filter(&img, 1, Border::Constant(9.0)).unwrap();
        // Corner window has 5 of 9 outside samples.
        assert!((f.at(0, 0, 0) - 5.0).abs() < 1e-5);
        assert!(f.at(1, 1, 0).abs() < 1e-6);
    }

    #[test]
    fn bad_input_is_rejected() {
        let two = ImageView::new(1, 3, 2, &[0.0; 6]).unwrap();
        assert!(separable_plane(two, &[1.0], &[1.0], Border::Reflect).is_err());
        let plane = ImageView::plane(2, 3, &[0.0; 6]).unwrap();
        assert!(separable_plane(plane, &[0.5, 0.5], &[1.0], Border::Reflect).is_err());
        let nan = Image::new(1, 2, 1, vec![0.0, f32::NAN]).unwrap();
        assert!(gaussian_filter(&nan, 1.0, 4.0, Border::Reflect).is_err());
    }
}
