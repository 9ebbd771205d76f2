//! Borrowed views: [`ImageView`], [`ImageStackView`] and [`VolumeView`].
//!
//! Functions that only read pixels or voxels take a view, so a caller's buffer (a numpy
//! array, one frame of a stack, an [`Image`] or a [`Volume`]) is read where it lies, never
//! copied. A view is checked once, when it is made (dimensions against the buffer length),
//! and the functions that take it rely on that check. [`Image::view`] and [`Volume::view`]
//! view owned data; the `new` constructors view any slice.
//!
//! The layouts are those of the owned types: an image is row-major with interleaved channels
//! (numpy `(H, W, C)`), a stack is `frames` images one after the other (numpy `(N, H, W)`),
//! and a volume is stored x fastest (numpy `(nz, ny, nx)`, see [`crate::volume`]).

use crate::error::{ensure_finite, Error, Result};
use crate::image::{check_len, Image};
use crate::volume::{check_parts, Volume};

/// A borrowed `H x W x C` image (row-major, interleaved channels).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageView<'a, T = f32> {
    height: usize,
    width: usize,
    channels: usize,
    data: &'a [T],
}

impl<'a, T: Copy> ImageView<'a, T> {
    /// A view of parts already checked by [`Image`]'s constructors.
    pub(crate) fn from_parts(height: usize, width: usize, channels: usize, data: &'a [T]) -> Self {
        Self {
            height,
            width,
            channels,
            data,
        }
    }

    /// Views `data` (length `height * width * channels`, interleaved, row-major).
    ///
    /// Errors: as [`Image::new`]: a zero dimension ([`Error::Empty`]) or a length that does
    /// not match ([`Error::ShapeMismatch`]).
    pub fn new(height: usize, width: usize, channels: usize, data: &'a [T]) -> Result<Self> {
        check_len(height, width, channels, data.len())?;
        Ok(Self {
            height,
            width,
            channels,
            data,
        })
    }

    /// Views `data` as a single-channel `height x width` image (a plane, a mask).
    ///
    /// Errors: as [`ImageView::new`].
    pub fn plane(height: usize, width: usize, data: &'a [T]) -> Result<Self> {
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
    /// Number of pixels, `height * width`.
    pub fn pixels(&self) -> usize {
        self.height * self.width
    }
    /// The interleaved values, with the lifetime of the viewed buffer.
    pub fn data(&self) -> &'a [T] {
        self.data
    }
    /// Value of channel `c` at `(y, x)`. Panics when out of bounds.
    pub fn at(&self, y: usize, x: usize, c: usize) -> T {
        self.data[(y * self.width + x) * self.channels + c]
    }
    /// Row `y` (all channels interleaved). Panics when out of bounds.
    pub fn row(&self, y: usize) -> &'a [T] {
        let n = self.width * self.channels;
        &self.data[y * n..(y + 1) * n]
    }
    /// Copies the view into an owned [`Image`].
    pub fn to_image(&self) -> Image<T> {
        Image {
            height: self.height,
            width: self.width,
            channels: self.channels,
            data: self.data.to_vec(),
        }
    }

    /// Refuses a view with more than one channel, naming the argument `name`.
    pub fn ensure_plane(&self, name: &'static str) -> Result<()> {
        if self.channels == 1 {
            Ok(())
        } else {
            Err(Error::invalid(
                name,
                format!(
                    "must be a single-channel image, got {} channels",
                    self.channels
                ),
            ))
        }
    }

    /// Refuses `other` unless it has the shape of `self`; the error names `other_name`.
    pub fn ensure_same_shape<U: Copy>(
        &self,
        other: &ImageView<'_, U>,
        other_name: &'static str,
    ) -> Result<()> {
        if self.shape() == other.shape() {
            Ok(())
        } else {
            Err(Error::ShapeMismatch(format!(
                "`{other_name}` has shape {:?}, expected {:?}",
                other.shape(),
                self.shape()
            )))
        }
    }

    /// Refuses a NaN or infinite value ([`Error::NonFinite`] naming `name`).
    pub fn ensure_finite(&self, name: &'static str) -> Result<()>
    where
        T: Into<f64>,
    {
        ensure_finite(name, self.data)
    }
}

impl<T: Copy> Image<T> {
    /// A borrowed view of the image (see [`ImageView`]), what functions that only read an
    /// image take.
    pub fn view(&self) -> ImageView<'_, T> {
        ImageView::from_parts(self.height, self.width, self.channels, &self.data)
    }
}

impl<'a, T: Copy> From<&'a Image<T>> for ImageView<'a, T> {
    fn from(image: &'a Image<T>) -> Self {
        image.view()
    }
}

/// A borrowed stack of `frames` single-channel `H x W` images stored one after the other
/// (numpy `(N, H, W)`): a set of masks, depth maps or video frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageStackView<'a, T = f32> {
    frames: usize,
    height: usize,
    width: usize,
    data: &'a [T],
}

impl<'a, T: Copy> ImageStackView<'a, T> {
    /// Views `data` (length `frames * height * width`) as `frames` images of
    /// `height x width`.
    ///
    /// Errors: a zero dimension ([`Error::Empty`]), an overflowing size
    /// ([`Error::LimitExceeded`]), a length that does not match ([`Error::ShapeMismatch`]).
    pub fn new(frames: usize, height: usize, width: usize, data: &'a [T]) -> Result<Self> {
        if frames == 0 {
            return Err(Error::Empty("image stack (no frames)"));
        }
        let frame = height
            .checked_mul(width)
            .ok_or_else(|| Error::LimitExceeded(format!("frame {height}x{width}")))?;
        let n = frame
            .checked_mul(frames)
            .ok_or_else(|| Error::LimitExceeded(format!("{frames} frames of {height}x{width}")))?;
        check_len(height, width, 1, frame)?;
        if data.len() != n {
            return Err(Error::ShapeMismatch(format!(
                "image stack has {} values, expected {frames}x{height}x{width} = {n}",
                data.len()
            )));
        }
        Ok(Self {
            frames,
            height,
            width,
            data,
        })
    }

    /// Number of images.
    pub fn frames(&self) -> usize {
        self.frames
    }
    /// Rows of every image.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Columns of every image.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Values per image, `height * width`.
    pub fn frame_len(&self) -> usize {
        self.height * self.width
    }
    /// All values, frame after frame.
    pub fn data(&self) -> &'a [T] {
        self.data
    }
    /// Image `i`, or `None` past the end.
    pub fn frame(&self, i: usize) -> Option<ImageView<'a, T>> {
        let p = self.frame_len();
        self.data.get(i * p..(i + 1) * p).map(|data| ImageView {
            height: self.height,
            width: self.width,
            channels: 1,
            data,
        })
    }
    /// The images in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = ImageView<'a, T>> + '_ {
        let (height, width) = (self.height, self.width);
        self.data
            .chunks_exact(self.frame_len())
            .map(move |data| ImageView {
                height,
                width,
                channels: 1,
                data,
            })
    }

    /// Refuses `other` unless it has the shape of `self`; the error names `other_name`.
    pub fn ensure_same_shape<U: Copy>(
        &self,
        other: &ImageStackView<'_, U>,
        other_name: &'static str,
    ) -> Result<()> {
        let (a, b) = (
            (self.frames, self.height, self.width),
            (other.frames, other.height, other.width),
        );
        if a == b {
            Ok(())
        } else {
            Err(Error::ShapeMismatch(format!(
                "`{other_name}` has shape {b:?}, expected {a:?}"
            )))
        }
    }

    /// Refuses a NaN or infinite value ([`Error::NonFinite`] naming `name`).
    pub fn ensure_finite(&self, name: &'static str) -> Result<()>
    where
        T: Into<f64>,
    {
        ensure_finite(name, self.data)
    }
}

/// A borrowed `nx x ny x nz` volume with its voxel spacing, stored x fastest (the layout of
/// [`Volume`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeView<'a, T = f32> {
    dims: [usize; 3],
    spacing: [f64; 3],
    data: &'a [T],
}

impl<'a, T: Copy> VolumeView<'a, T> {
    /// A view of parts already checked by [`Volume`]'s constructors.
    pub(crate) fn from_parts(dims: [usize; 3], spacing: [f64; 3], data: &'a [T]) -> Self {
        Self {
            dims,
            spacing,
            data,
        }
    }

    /// Views `data` (length `nx * ny * nz`, x fastest) as a volume of `dims = [nx, ny, nz]`
    /// voxels of size `spacing = [sx, sy, sz]`.
    ///
    /// Errors: as [`Volume::new`].
    pub fn new(dims: [usize; 3], spacing: [f64; 3], data: &'a [T]) -> Result<Self> {
        check_parts(dims, spacing, data.len())?;
        Ok(Self {
            dims,
            spacing,
            data,
        })
    }

    /// Number of voxels along x, y and z: `[nx, ny, nz]`.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }
    /// Voxel size along x, y and z: `[sx, sy, sz]`.
    pub fn spacing(&self) -> [f64; 3] {
        self.spacing
    }
    /// The values, x fastest, with the lifetime of the viewed buffer.
    pub fn data(&self) -> &'a [T] {
        self.data
    }
    /// Number of voxels.
    pub fn len(&self) -> usize {
        self.data.len()
    }
    /// Always false: a view has at least one voxel.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
    /// Linear index of voxel `(x, y, z)`.
    pub fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }
    /// Value of voxel `(x, y, z)`. Panics when out of bounds.
    pub fn at(&self, x: usize, y: usize, z: usize) -> T {
        self.data[self.index(x, y, z)]
    }
    /// Copies the view into an owned [`Volume`].
    pub fn to_volume(&self) -> Volume<T> {
        Volume {
            dims: self.dims,
            spacing: self.spacing,
            data: self.data.to_vec(),
            affine: None,
        }
    }

    /// Refuses `other` unless it has the dimensions of `self`; the error names `other_name`.
    pub fn ensure_same_dims<U: Copy>(
        &self,
        other: &VolumeView<'_, U>,
        other_name: &'static str,
    ) -> Result<()> {
        if self.dims == other.dims {
            Ok(())
        } else {
            Err(Error::ShapeMismatch(format!(
                "`{other_name}` has dims {:?}, expected {:?}",
                other.dims, self.dims
            )))
        }
    }

    /// Refuses a NaN or infinite value ([`Error::NonFinite`] naming `name`).
    pub fn ensure_finite(&self, name: &'static str) -> Result<()>
    where
        T: Into<f64>,
    {
        ensure_finite(name, self.data)
    }
}

impl<T: Copy> Volume<T> {
    /// A borrowed view of the volume (see [`VolumeView`]), what functions that only read a
    /// volume take.
    pub fn view(&self) -> VolumeView<'_, T> {
        VolumeView::from_parts(self.dims, self.spacing, &self.data)
    }
}

impl<'a, T: Copy> From<&'a Volume<T>> for VolumeView<'a, T> {
    fn from(volume: &'a Volume<T>) -> Self {
        volume.view()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_view_reads_the_buffer_in_place() {
        let data: Vec<f32> = (0..12).map(|v| v as f32).collect();
        let v = ImageView::new(2, 3, 2, &data).unwrap();
        assert_eq!(v.at(1, 2, 1), 11.0);
        assert_eq!(v.row(1), &data[6..12]);
        assert!(std::ptr::eq(v.data(), data.as_slice()));
        let img = v.to_image();
        assert_eq!(img.view(), v);
        assert!(v.ensure_plane("image").is_err());
        assert!(matches!(
            ImageView::new(2, 2, 1, &data[..3]),
            Err(Error::ShapeMismatch(_))
        ));
        assert!(matches!(
            ImageView::<f32>::plane(0, 2, &[]),
            Err(Error::Empty(_))
        ));
        let bad = [0.0, f32::NAN];
        let e = ImageView::plane(1, 2, &bad[..])
            .unwrap()
            .ensure_finite("img");
        assert!(matches!(e, Err(Error::NonFinite { name: "img", .. })));
    }

    #[test]
    fn stack_frames_are_consecutive_images() {
        let data: Vec<u8> = (0..24).collect();
        let s = ImageStackView::new(4, 2, 3, &data).unwrap();
        assert_eq!(s.frames(), 4);
        assert_eq!(s.frame(2).unwrap().data(), &data[12..18]);
        assert!(s.frame(4).is_none());
        assert_eq!(s.iter().len(), 4);
        assert_eq!(s.iter().nth(3).unwrap().at(1, 2, 0), 23);
        assert!(ImageStackView::new(5, 2, 3, &data).is_err());
        assert!(ImageStackView::new(0, 2, 3, &data[..0]).is_err());
        assert!(ImageStackView::new(usize::MAX, 2, 3, &data).is_err());
    }

    #[test]
    fn volume_view_matches_the_owned_volume() {
        let vol = Volume::from_fn([3, 2, 2], [1.0, 2.0, 0.5], |x, y, z| {
            (x + 10 * y + 100 * z) as f32
        })
        .unwrap();
        let v = vol.view();
        assert_eq!(v.at(2, 1, 1), 112.0);
        assert_eq!(v.to_volume(), vol);
        assert_eq!(VolumeView::new(v.dims(), v.spacing(), v.data()).unwrap(), v);
        assert!(VolumeView::new([3, 2, 2], [1.0, 0.0, 1.0], v.data()).is_err());
        assert!(VolumeView::new([3, 2, 3], [1.0; 3], v.data()).is_err());
    }
}
