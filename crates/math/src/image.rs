//! [`Image`]: a row-major H x W x C pixel buffer.
//!
//! Pixels are stored interleaved, row after row: the value of channel `c` at row `y`, column
//! `x` is `data[(y * width + x) * channels + c]`, the layout of a C-ordered numpy array of
//! shape `(H, W, C)`. Files (8- and 16-bit PNG and TIFF, JPEG, OpenEXR and Radiance HDR) are
//! read and written by [`crate::io`] (feature `io-image`), which adds `Image::load`,
//! `Image::save` and their variants.

use ndarray::{Array3, ArrayView3};

use crate::error::{ensure_finite, Error, Result};

/// Checks an image shape against a buffer length: no zero dimension ([`Error::Empty`]), no
/// overflow ([`Error::LimitExceeded`]), `len = height * width * channels`
/// ([`Error::ShapeMismatch`]).
pub(crate) fn check_len(height: usize, width: usize, channels: usize, len: usize) -> Result<()> {
    if height == 0 || width == 0 || channels == 0 {
        return Err(Error::Empty(
            "image (height, width and channels must be > 0)",
        ));
    }
    let n = height
        .checked_mul(width)
        .and_then(|v| v.checked_mul(channels))
        .ok_or_else(|| Error::LimitExceeded(format!("image {height}x{width}x{channels}")))?;
    if len != n {
        return Err(Error::ShapeMismatch(format!(
            "image data has {len} values, expected {height}x{width}x{channels} = {n}"
        )));
    }
    Ok(())
}

/// A row-major H x W x C image (f32 by default).
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T = f32> {
    pub(crate) height: usize,
    pub(crate) width: usize,
    pub(crate) channels: usize,
    pub(crate) data: Vec<T>,
}

impl<T: Copy> Image<T> {
    /// Wraps `data` (length `height * width * channels`, interleaved, row-major).
    ///
    /// Errors: a zero dimension ([`Error::Empty`]) or a length that does not match
    /// ([`Error::ShapeMismatch`]).
    pub fn new(height: usize, width: usize, channels: usize, data: Vec<T>) -> Result<Self> {
        check_len(height, width, channels, data.len())?;
        Ok(Self {
            height,
            width,
            channels,
            data,
        })
    }

    /// An image with every value equal to `value`.
    ///
    /// Errors: as [`Image::new`]; [`Error::OutOfMemory`] naming `height, width` when the image
    /// does not fit in memory ([`crate::alloc`]).
    pub fn filled(height: usize, width: usize, channels: usize, value: T) -> Result<Self> {
        let n = crate::alloc::elements("height, width", &[height, width, channels])?;
        Self::new(
            height,
            width,
            channels,
            crate::alloc::try_vec("height, width", value, n)?,
        )
    }

    /// Builds a single-channel image from `f(y, x)`.
    pub fn from_fn(height: usize, width: usize, f: impl Fn(usize, usize) -> T) -> Result<Self> {
        let n = crate::alloc::elements("height, width", &[height, width])?;
        let mut data = crate::alloc::try_with_capacity("height, width", n)?;
        for y in 0..height {
            for x in 0..width {
                data.push(f(y, x));
            }
        }
        Self::new(height, width, 1, data)
    }

    /// Number of rows.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Number of columns.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.channels
    }
    /// `(height, width, channels)`.
    pub fn shape(&self) -> (usize, usize, usize) {
        (self.height, self.width, self.channels)
    }
    /// The interleaved values.
    pub fn data(&self) -> &[T] {
        &self.data
    }
    /// The interleaved values, mutable.
    pub fn data_mut(&mut self) -> &mut [T] {
        &mut self.data
    }
    /// Consumes the image, returning its values.
    pub fn into_data(self) -> Vec<T> {
        self.data
    }
    /// Value of channel `c` at `(y, x)`. Panics when out of bounds.
    pub fn at(&self, y: usize, x: usize, c: usize) -> T {
        self.data[(y * self.width + x) * self.channels + c]
    }
    /// Sets channel `c` at `(y, x)`. Panics when out of bounds.
    pub fn set(&mut self, y: usize, x: usize, c: usize, v: T) {
        self.data[(y * self.width + x) * self.channels + c] = v;
    }
    /// All channels of the pixel at `(y, x)`.
    pub fn pixel(&self, y: usize, x: usize) -> &[T] {
        let i = (y * self.width + x) * self.channels;
        &self.data[i..i + self.channels]
    }
    /// Channel `c` as a single-channel image.
    pub fn channel(&self, c: usize) -> Result<Image<T>> {
        if c >= self.channels {
            return Err(Error::invalid(
                "channel",
                format!(
                    "{c} is out of range for an image with {} channels",
                    self.channels
                ),
            ));
        }
        let data = self
            .data
            .iter()
            .skip(c)
            .step_by(self.channels)
            .copied()
            .collect();
        Image::new(self.height, self.width, 1, data)
    }
    /// Applies `f` to every value.
    pub fn map<U: Copy>(&self, f: impl Fn(T) -> U) -> Image<U> {
        Image {
            height: self.height,
            width: self.width,
            channels: self.channels,
            data: self.data.iter().map(|&v| f(v)).collect(),
        }
    }
    /// Copies into an ndarray of shape `(H, W, C)`.
    pub fn to_ndarray(&self) -> Array3<T> {
        Array3::from_shape_vec((self.height, self.width, self.channels), self.data.clone())
            .expect("image shape is consistent by construction")
    }
    /// Copies from an ndarray view of shape `(H, W, C)` in any memory order.
    pub fn from_ndarray(a: ArrayView3<T>) -> Result<Self> {
        let (h, w, c) = a.dim();
        Self::new(h, w, c, a.iter().copied().collect())
    }
    /// Returns `Ok` if both images have the same shape, [`Error::ShapeMismatch`] otherwise.
    pub fn ensure_same_shape<U: Copy>(&self, other: &Image<U>) -> Result<()> {
        if self.shape() == other.shape() {
            Ok(())
        } else {
            Err(Error::ShapeMismatch(format!(
                "images have shapes {:?} and {:?}",
                self.shape(),
                other.shape()
            )))
        }
    }
}

impl Image<f32> {
    /// Errors with [`Error::NonFinite`] naming `name` if any value is NaN or infinite.
    pub fn ensure_finite(&self, name: &'static str) -> Result<()> {
        ensure_finite(name, &self.data)
    }

    /// Channel `c` as an f64 plane of `height * width` values (row-major). Panics if
    /// `c >= channels` (a programming error).
    pub fn plane_f64(&self, c: usize) -> Vec<f64> {
        assert!(c < self.channels, "channel {c} of {}", self.channels);
        self.data
            .iter()
            .skip(c)
            .step_by(self.channels)
            .map(|&v| v as f64)
            .collect()
    }

    /// Luminance (Rec. 709 weights) of an RGB(A) image; a one- or two-channel image returns
    /// its first channel. Alpha is dropped.
    pub fn to_gray(&self) -> Image<f32> {
        if self.channels < 3 {
            return self.channel(0).expect("channel 0 exists");
        }
        let data = self
            .data
            .chunks_exact(self.channels)
            .map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2])
            .collect();
        Image {
            height: self.height,
            width: self.width,
            channels: 1,
            data,
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn ramp(h: usize, w: usize, c: usize) -> Image {
        let n = h * w * c;
        Image::new(h, w, c, (0..n).map(|i| i as f32 / (n - 1) as f32).collect()).unwrap()
    }

    #[test]
    fn layout_is_row_major_interleaved() {
        let img = ramp(2, 3, 2);
        assert_eq!(img.at(1, 2, 1), img.data()[(3 + 2) * 2 + 1]);
        assert_eq!(img.pixel(1, 0), &img.data()[6..8]);
        let a = img.to_ndarray();
        assert_eq!(a[[1, 2, 1]], img.at(1, 2, 1));
        assert_eq!(Image::from_ndarray(a.view()).unwrap(), img);
        // A transposed (non-contiguous) view is copied in logical order.
        let t = a.view().permuted_axes([1, 0, 2]);
        let it = Image::from_ndarray(t).unwrap();
        assert_eq!(it.at(2, 1, 1), img.at(1, 2, 1));
    }

    #[test]
    fn bad_shapes_are_rejected() {
        assert!(matches!(
            Image::new(2, 2, 1, vec![0.0f32; 3]),
            Err(Error::ShapeMismatch(_))
        ));
        assert!(matches!(
            Image::<f32>::new(0, 2, 1, vec![]),
            Err(Error::Empty(_))
        ));
        assert!(ramp(2, 2, 1).channel(1).is_err());
        assert!(ramp(2, 2, 1).ensure_same_shape(&ramp(2, 3, 1)).is_err());
    }

    #[test]
    fn gray_uses_rec709() {
        let img = Image::new(1, 1, 3, vec![1.0, 0.0, 0.0]).unwrap();
        assert!((img.to_gray().at(0, 0, 0) - 0.2126).abs() < 1e-7);
    }
}
