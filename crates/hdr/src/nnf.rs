//! Dense nearest-neighbour fields between two images: per pixel of the first image, the
//! offset `(dx, dy)` of its match in the second and the cost of that match.

use wscg_math::{Error, Image, Result};

/// A dense nearest-neighbour field from an image `A` (`height x width`) to an image `B`:
/// pixel `p` of `A` matches pixel `p + off(p)` of `B`.
#[derive(Clone, Debug, PartialEq)]
pub struct Nnf {
    width: usize,
    height: usize,
    /// Offsets `(dx, dy)`, row-major.
    pub off: Vec<[i32; 2]>,
    /// Cost of each match, row-major.
    pub cost: Vec<f32>,
}

impl Nnf {
    /// A field from its offsets and costs (`height * width` each).
    pub fn new(height: usize, width: usize, off: Vec<[i32; 2]>, cost: Vec<f32>) -> Result<Self> {
        if off.len() != height * width || cost.len() != height * width {
            return Err(Error::ShapeMismatch(format!(
                "a {height} x {width} field needs {} offsets and costs, got {} and {}",
                height * width,
                off.len(),
                cost.len()
            )));
        }
        Ok(Self {
            width,
            height,
            off,
            cost,
        })
    }

    /// Width of the field (of image `A`).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height of the field.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Offset of pixel `(y, x)`.
    #[inline]
    pub fn at(&self, y: usize, x: usize) -> [i32; 2] {
        self.off[y * self.width + x]
    }

    /// The horizontal offsets as an image (the disparity map of an epipolar field).
    pub fn dx_image(&self) -> Image<f32> {
        let v = self.off.iter().map(|o| o[0] as f32).collect();
        Image::new(self.height, self.width, 1, v).expect("field shape")
    }
}

/// Reads `img` at `(y, x)` clamped into the image, channel slice.
#[inline]
pub fn clamped(img: &Image<f32>, y: i64, x: i64) -> &[f32] {
    let (h, w, _) = img.shape();
    img.pixel(
        y.clamp(0, h as i64 - 1) as usize,
        x.clamp(0, w as i64 - 1) as usize,
    )
}
