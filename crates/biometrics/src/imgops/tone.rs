//! 8-bit tone operations with OpenCV's exact arithmetic, so `cv2` is a bit-exact oracle.
//!
//! - [`rgb_to_gray`]: `Y = (9798 R + 19235 G + 3735 B + 16384) >> 15`, the fixed-point BT.601
//!   of `cv2.cvtColor(img, cv2.COLOR_RGB2GRAY)` in OpenCV 4 and 5 (15-bit weights; the 14-bit
//!   `4899 / 9617 / 1868` of OpenCV 3.4 differ by one level on 0.26 % of all colours).
//! - [`equalize_hist`]: `cv2.equalizeHist`: `lut(v) = round((cdf(v) - c_min) * 255 / (P -
//!   c_min))` with the scale in f32 and rounding half to even.
//! - [`resize_u8`]: area averaging when neither axis grows (`cv2.INTER_AREA`), bilinear
//!   with half-pixel centres otherwise (`cv2.INTER_LINEAR`), rounded half to even.

use wscg_math::image::Image;
use wscg_math::resize::{resize, Interpolation};
use wscg_math::{Error, Result};

/// Grey levels of an 8-bit RGB image (`h x w x 3`, channels R, G, B): OpenCV's fixed-point
/// BT.601, `Y = (9798 R + 19235 G + 3735 B + 16384) >> 15` (weights 0.299, 0.587, 0.114
/// rounded to 15 bits, as `cv2.COLOR_RGB2GRAY` since OpenCV 4.0).
///
/// Errors: an image that does not have 3 channels.
pub fn rgb_to_gray(rgb: &Image<u8>) -> Result<Vec<u8>> {
    if rgb.channels() != 3 {
        return Err(Error::invalid(
            "image",
            format!("needs 3 colour channels (RGB), got {}", rgb.channels()),
        ));
    }
    Ok(rgb
        .data()
        .chunks_exact(3)
        .map(|p| {
            let y = 9798 * p[0] as u32 + 19235 * p[1] as u32 + 3735 * p[2] as u32 + 16384;
            (y >> 15) as u8
        })
        .collect())
}

/// Histogram equalisation with the arithmetic of `cv2.equalizeHist`.
///
/// With `h` the 256-bin histogram, `cdf(v) = sum_{u <= v} h(u)`, `c_min` the count of the
/// lowest present level and `P` the pixel count: `lut(v) = round_half_even(f32(cdf(v) -
/// c_min) * (255f32 / (P - c_min)))`. An image with a single grey level is returned
/// unchanged; an empty slice gives an empty result.
pub fn equalize_hist(gray: &[u8]) -> Vec<u8> {
    equalize_hist_within(gray, None)
}

/// [`equalize_hist`] whose histogram counts only the pixels where `within` is non-zero
/// (all pixels with `None`); the mapping is applied to every pixel, and levels below the
/// lowest counted one map to 0. An empty selection returns the image unchanged.
///
/// Panics if `within` is given with another length than `gray` (an internal invariant).
pub fn equalize_hist_within(gray: &[u8], within: Option<&[u8]>) -> Vec<u8> {
    let mut hist = [0u32; 256];
    match within {
        Some(m) => {
            assert_eq!(m.len(), gray.len(), "selection and image differ in length");
            for (&v, &k) in gray.iter().zip(m) {
                hist[v as usize] += u32::from(k != 0);
            }
        }
        None => gray.iter().for_each(|&v| hist[v as usize] += 1),
    }
    let total: u32 = hist.iter().sum();
    let Some(first) = hist.iter().position(|&c| c != 0) else {
        return gray.to_vec();
    };
    if hist[first] == total {
        return gray.to_vec();
    }
    let scale = 255.0f32 / (total - hist[first]) as f32;
    let mut lut = [0u8; 256];
    let mut sum = 0u32;
    for v in first + 1..256 {
        sum += hist[v];
        lut[v] = ((sum as f32) * scale).round_ties_even().clamp(0.0, 255.0) as u8;
    }
    gray.iter().map(|&v| lut[v as usize]).collect()
}

/// Resizes an 8-bit image (any channel count) to `height x width`: exact area averaging when
/// neither axis grows (OpenCV's `INTER_AREA`; equal to it within one grey level for
/// non-integer factors, where OpenCV accumulates in f32), bilinear with half-pixel centres
/// when an axis grows (as OpenCV's `INTER_AREA` falls back to interpolation when
/// upsampling). Values are rounded half to even, as OpenCV's `saturate_cast`, except for an
/// exact halving, where OpenCV's fast path `(a + b + c + d + 2) >> 2` (ties up) is used so
/// the result is bit-identical. The same size returns a copy.
///
/// Errors: a zero target size.
pub fn resize_u8(img: &Image<u8>, height: usize, width: usize) -> Result<Image<u8>> {
    let (h, w, c) = img.shape();
    if height == 0 || width == 0 {
        return Err(Error::invalid(
            "height, width",
            format!("target size must be > 0, got {height}x{width}"),
        ));
    }
    if (h, w) == (height, width) {
        return Ok(img.clone());
    }
    if (h, w) == (2 * height, 2 * width) {
        return Ok(halve(img));
    }
    let method = if height <= h && width <= w {
        Interpolation::Area
    } else {
        Interpolation::Bilinear
    };
    let f = Image::new(h, w, c, img.data().iter().map(|&v| v as f32).collect())?;
    let r = resize(&f, height, width, method)?;
    Ok(r.map(|v| v.round_ties_even().clamp(0.0, 255.0) as u8))
}

/// Exact 2 x 2 block means with OpenCV's integer rounding `(a + b + c + d + 2) >> 2`.
fn halve(img: &Image<u8>) -> Image<u8> {
    let (h, w, c) = img.shape();
    let (oh, ow) = (h / 2, w / 2);
    let d = img.data();
    let mut out = Vec::with_capacity(oh * ow * c);
    for y in 0..oh {
        let (r0, r1) = (2 * y * w * c, (2 * y + 1) * w * c);
        for x in 0..ow {
            for ch in 0..c {
                let i = 2 * x * c + ch;
                let s = d[r0 + i] as u32
                    + d[r0 + i + c] as u32
                    + d[r1 + i] as u32
                    + d[r1 + i + c] as u32;
                out.push(((s + 2) >> 2) as u8);
            }
        }
    }
    Image::new(oh, ow, c, out).expect("halved image has a consistent shape")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gray_uses_the_fixed_point_weights() {
        let img = Image::new(1, 4, 3, vec![255, 0, 0, 0, 255, 0, 10, 20, 30, 1, 123, 0]).unwrap();
        let g = rgb_to_gray(&img).unwrap();
        assert_eq!(
            g,
            // (9798 * 10 + 19235 * 20 + 3735 * 30 + 16384) >> 15 = 611114 >> 15 = 18; the
            // last colour is 73 with 15-bit weights (OpenCV 4 and 5) and 72 with 14-bit ones.
            vec![76, 150, 18, 73]
        );
        let grey = Image::new(1, 1, 1, vec![7u8]).unwrap();
        assert!(rgb_to_gray(&grey).is_err());
    }

    #[test]
    fn equalisation_of_two_levels_and_of_a_constant() {
        // Two levels: the lower maps to 0, the upper to 255.
        assert_eq!(equalize_hist(&[3, 3, 9, 9, 9]), vec![0, 0, 255, 255, 255]);
        assert_eq!(equalize_hist(&[42; 7]), vec![42; 7]);
        assert!(equalize_hist(&[]).is_empty());
        // Four equally frequent levels: cdf - c_min = 0, 1, 2, 3 pixels of 3 -> 0, 85, 170, 255.
        assert_eq!(equalize_hist(&[10, 20, 30, 40]), vec![0, 85, 170, 255]);
    }

    #[test]
    fn resize_down_is_the_block_mean_and_up_is_bilinear() {
        let img = Image::new(2, 2, 1, vec![0u8, 10, 20, 31]).unwrap();
        let r = resize_u8(&img, 1, 1).unwrap();
        // (0 + 10 + 20 + 31) / 4 = 15.25 -> 15.
        assert_eq!(r.data(), &[15]);
        // A tie of the halving rounds up, as OpenCV's fast path: 10 / 4 = 2.5 -> 3.
        let tie = Image::new(2, 2, 1, vec![0u8, 0, 0, 10]).unwrap();
        assert_eq!(resize_u8(&tie, 1, 1).unwrap().data(), &[3]);
        // Other factors round half to even: 3 x 3 -> 1 x 1 has no ties; 2 x 4 -> 1 x 1 is a
        // general area mean, 20 / 8 = 2.5 -> 2.
        let gen = Image::new(2, 4, 1, vec![0u8, 0, 0, 0, 0, 0, 10, 10]).unwrap();
        assert_eq!(resize_u8(&gen, 1, 1).unwrap().data(), &[2]);
        let up = resize_u8(&img, 4, 4).unwrap();
        assert_eq!(up.at(0, 0, 0), 0);
        assert_eq!(up.at(3, 3, 0), 31);
        assert!(resize_u8(&img, 0, 4).is_err());
    }
}
