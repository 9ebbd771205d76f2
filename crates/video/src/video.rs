//! The data of video completion: a video as one contiguous `(t, y, x, c)` byte buffer and a
//! hole mask as a bit set of the same `(t, y, x)` grid.

use wscg_math::{Error, Result};

use crate::patchmatch::P3;

/// A video of `frames` frames of `height x width` pixels with `channels` (1 or 3) bytes each,
/// stored frame by frame, row by row (`(t, y, x, c)` order).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Video {
    /// Number of frames.
    pub frames: usize,
    /// Frame height in pixels.
    pub height: usize,
    /// Frame width in pixels.
    pub width: usize,
    /// Channels per pixel (1: grey, 3: RGB).
    pub channels: usize,
    /// `frames * height * width * channels` bytes.
    pub data: Vec<u8>,
}

impl Video {
    /// A video from its bytes.
    ///
    /// Errors: a zero extent, channels other than 1 or 3, a data length that does not match,
    /// more than `u32::MAX` rows, columns or frames.
    pub fn new(
        frames: usize,
        height: usize,
        width: usize,
        channels: usize,
        data: Vec<u8>,
    ) -> Result<Self> {
        if frames == 0 || height == 0 || width == 0 {
            return Err(Error::invalid(
                "video",
                format!("empty video: {frames} frames of {height} x {width}"),
            ));
        }
        if channels != 1 && channels != 3 {
            return Err(Error::invalid(
                "channels",
                format!("1 (grey) or 3 (RGB) channels expected, got {channels}"),
            ));
        }
        if [frames, height, width]
            .iter()
            .any(|&v| v > u32::MAX as usize)
        {
            return Err(Error::invalid("video", "extents above u32::MAX"));
        }
        let n = frames * height * width * channels;
        if data.len() != n {
            return Err(Error::invalid(
                "video",
                format!(
                    "{} bytes for {frames} x {height} x {width} x {channels} = {n}",
                    data.len()
                ),
            ));
        }
        Ok(Self {
            frames,
            height,
            width,
            channels,
            data,
        })
    }

    /// A video filled with `value`.
    ///
    /// Errors: as [`Video::new`]; [`wscg_math::Error::OutOfMemory`] when it does not fit.
    pub fn filled(
        frames: usize,
        height: usize,
        width: usize,
        channels: usize,
        value: u8,
    ) -> Result<Self> {
        let what = "frames, height, width";
        let n = wscg_math::alloc::elements(what, &[frames, height, width, channels])?;
        Self::new(
            frames,
            height,
            width,
            channels,
            wscg_math::alloc::try_vec(what, value, n)?,
        )
    }

    /// Grid extents `(frames, height, width)`.
    pub fn dims(&self) -> [usize; 3] {
        [self.frames, self.height, self.width]
    }

    /// Pixels per frame.
    pub fn frame_len(&self) -> usize {
        self.height * self.width
    }

    /// Byte offset of pixel `p`.
    #[inline]
    pub fn offset(&self, p: P3) -> usize {
        ((p[0] as usize * self.height + p[1] as usize) * self.width + p[2] as usize) * self.channels
    }

    /// The channel values of pixel `p`.
    #[inline]
    pub fn pixel(&self, p: P3) -> &[u8] {
        let o = self.offset(p);
        &self.data[o..o + self.channels]
    }

    /// Copies the colour of pixel `src` onto pixel `dst`.
    #[inline]
    pub fn copy_pixel(&mut self, dst: P3, src: P3) {
        let (d, s, c) = (self.offset(dst), self.offset(src), self.channels);
        self.data.copy_within(s..s + c, d);
    }

    /// Frame `t` as bytes (`height * width * channels`).
    pub fn frame(&self, t: usize) -> &[u8] {
        let n = self.frame_len() * self.channels;
        &self.data[t * n..(t + 1) * n]
    }

    /// Errors unless `mask` has this video's grid.
    pub fn check_mask(&self, mask: &Mask3) -> Result<()> {
        if mask.dims() != self.dims() {
            return Err(Error::invalid(
                "mask",
                format!(
                    "mask of {:?} (frames, height, width) for a video of {:?}",
                    mask.dims(),
                    self.dims()
                ),
            ));
        }
        Ok(())
    }

    /// Errors unless `other` has the same extents and channels.
    pub fn check_same(&self, other: &Video) -> Result<()> {
        if other.dims() != self.dims() || other.channels != self.channels {
            return Err(Error::invalid(
                "video",
                format!(
                    "videos of {:?} x {} and {:?} x {} channels differ in shape",
                    self.dims(),
                    self.channels,
                    other.dims(),
                    other.channels
                ),
            ));
        }
        Ok(())
    }
}

/// A set of grid points stored one bit each (`(t, y, x)` row-major): the hole `H` of a video,
/// the valid source centres, ...
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mask3 {
    /// Number of frames.
    pub frames: usize,
    /// Frame height.
    pub height: usize,
    /// Frame width.
    pub width: usize,
    bits: Vec<u64>,
}

impl Mask3 {
    /// The empty set on a grid.
    pub fn empty(frames: usize, height: usize, width: usize) -> Self {
        let n = frames * height * width;
        Self {
            frames,
            height,
            width,
            bits: vec![0; n.div_ceil(64)],
        }
    }

    /// The set of points where `f(t, y, x)` holds.
    pub fn from_fn(
        frames: usize,
        height: usize,
        width: usize,
        f: impl Fn(usize, usize, usize) -> bool,
    ) -> Self {
        let mut m = Self::empty(frames, height, width);
        for t in 0..frames {
            for y in 0..height {
                for x in 0..width {
                    if f(t, y, x) {
                        m.insert_index((t * height + y) * width + x);
                    }
                }
            }
        }
        m
    }

    /// The set of `values` that are non-zero (`frames * height * width` values, row-major).
    ///
    /// Errors: a length that does not match.
    pub fn from_bytes(frames: usize, height: usize, width: usize, values: &[u8]) -> Result<Self> {
        if values.len() != frames * height * width {
            return Err(Error::invalid(
                "mask",
                format!(
                    "{} values for a mask of {frames} x {height} x {width}",
                    values.len()
                ),
            ));
        }
        let mut m = Self::empty(frames, height, width);
        for (i, &v) in values.iter().enumerate() {
            if v != 0 {
                m.insert_index(i);
            }
        }
        Ok(m)
    }

    /// Grid extents `(frames, height, width)`.
    pub fn dims(&self) -> [usize; 3] {
        [self.frames, self.height, self.width]
    }

    /// Number of grid points.
    pub fn len_grid(&self) -> usize {
        self.frames * self.height * self.width
    }

    /// Linear index of `p`.
    #[inline]
    pub fn index(&self, p: P3) -> usize {
        (p[0] as usize * self.height + p[1] as usize) * self.width + p[2] as usize
    }

    /// Whether the point of linear index `i` is in the set.
    #[inline]
    pub fn contains_index(&self, i: usize) -> bool {
        self.bits[i >> 6] >> (i & 63) & 1 == 1
    }

    /// Whether `p` is in the set.
    #[inline]
    pub fn contains(&self, p: P3) -> bool {
        self.contains_index(self.index(p))
    }

    /// Adds the point of linear index `i`.
    #[inline]
    pub fn insert_index(&mut self, i: usize) {
        self.bits[i >> 6] |= 1 << (i & 63);
    }

    /// Adds `p`.
    #[inline]
    pub fn insert(&mut self, p: P3) {
        let i = self.index(p);
        self.insert_index(i);
    }

    /// Removes `p`.
    #[inline]
    pub fn remove(&mut self, p: P3) {
        let i = self.index(p);
        self.bits[i >> 6] &= !(1 << (i & 63));
    }

    /// Number of points in the set.
    pub fn count(&self) -> usize {
        self.bits.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// The points of the set in scan order, without collecting them.
    pub fn iter_points(&self) -> impl Iterator<Item = P3> + '_ {
        let (h, w) = (self.height, self.width);
        self.bits.iter().enumerate().flat_map(move |(k, &word)| {
            let mut bits = word;
            std::iter::from_fn(move || {
                if bits == 0 {
                    return None;
                }
                let i = k * 64 + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                Some([(i / (h * w)) as u32, ((i / w) % h) as u32, (i % w) as u32])
            })
        })
    }

    /// The points of the set in scan order.
    pub fn points(&self) -> Vec<P3> {
        let mut out = Vec::with_capacity(self.count());
        out.extend(self.iter_points());
        out
    }

    /// One byte per grid point: 1 in the set, 0 outside.
    pub fn to_bytes(&self) -> Vec<u8> {
        (0..self.len_grid())
            .map(|i| u8::from(self.contains_index(i)))
            .collect()
    }

    /// Whether frame `t` has any point of the set.
    pub fn frame_any(&self, t: usize) -> bool {
        let n = self.height * self.width;
        (t * n..(t + 1) * n).any(|i| self.contains_index(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mask_bits_round_trip() {
        let m = Mask3::from_fn(3, 5, 7, |t, y, x| (t + 2 * y + 3 * x) % 4 == 0);
        let b = m.to_bytes();
        assert_eq!(Mask3::from_bytes(3, 5, 7, &b).unwrap(), m);
        let pts = m.points();
        assert_eq!(pts.len(), m.count());
        assert!(pts.iter().all(|&p| m.contains(p)));
        assert!(pts.windows(2).all(|w| m.index(w[0]) < m.index(w[1])));
        assert!(Mask3::from_bytes(3, 5, 7, &b[1..]).is_err());
    }

    #[test]
    fn video_checks_its_shape() {
        assert!(Video::new(2, 3, 4, 3, vec![0; 72]).is_ok());
        assert!(Video::new(2, 3, 4, 3, vec![0; 71]).is_err());
        assert!(Video::new(0, 3, 4, 3, vec![]).is_err());
        assert!(Video::new(2, 3, 4, 2, vec![0; 48]).is_err());
        let v = Video::filled(2, 3, 4, 3, 7).unwrap();
        assert!(v.check_mask(&Mask3::empty(2, 3, 4)).is_ok());
        assert!(v.check_mask(&Mask3::empty(2, 4, 3)).is_err());
    }
}
