//! Raster image files through the `image` crate: 8- and 16-bit PNG, 8- and 16-bit TIFF
//! (grey, grey + alpha, RGB, RGBA; uncompressed, LZW, Deflate or PackBits, as cameras and
//! raw converters write them), JPEG, OpenEXR and Radiance HDR, loaded into and saved from
//! [`Image`]. Integer formats are scaled to `[0, 1]` on load (`v / 255`, `v / 65535`);
//! floating-point formats (OpenEXR, Radiance HDR, 32-bit float TIFF) keep their values. A
//! 16-bit file saved with [`PixelDepth::U16`] and loaded again gives back the same codes
//! (`round(v * 65535)`). A multi-page TIFF is read from its first page.
//!
//! Decoding is bounded before any pixel is decoded: a file whose header declares more than
//! [`max_image_pixels`] pixels (default [`DEFAULT_MAX_IMAGE_PIXELS`], 16384 x 16384), a side
//! above [`MAX_DECODE_SIDE`], or a decoder allocation above [`MAX_DECODE_BYTES`] (or 16 bytes
//! per allowed pixel, when larger) is refused with [`Error::LimitExceeded`] naming the file.
//! A small compressed file can declare a huge image (a PNG of a few hundred kilobytes
//! inflates to gigabytes), so the header, not the file size, is what is checked. The pixel
//! cap can be raised for the whole process with [`set_max_image_pixels`] (Python
//! `wscg.set_max_image_pixels`) or the environment variable `WSCG_MAX_IMAGE_PIXELS` (read on
//! first use; the way to raise it for the command line).

use std::io::Cursor;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;

use image::{DynamicImage, ImageBuffer, ImageDecoder, ImageFormat, ImageReader, Limits};

use crate::error::{read_file, Error, Result};
use crate::image::Image;

/// Largest width or height accepted when decoding a file (a guard against hostile headers).
pub const MAX_DECODE_SIDE: u32 = 1 << 16;
/// Largest number of bytes a decoder may allocate for one file (raised to 16 bytes per pixel
/// of [`max_image_pixels`] when that is larger).
pub const MAX_DECODE_BYTES: u64 = 4 << 30;
/// The default of [`max_image_pixels`]: 16384 x 16384 = 268 million pixels (1 GiB as 8-bit
/// RGBA, 4 GiB as one f32 channel), far above any camera and below what a typical machine
/// can hold once decoded to floats.
pub const DEFAULT_MAX_IMAGE_PIXELS: u64 = 1 << 28;
/// The environment variable that sets [`max_image_pixels`] for the process (read on first
/// use; a positive integer).
pub const MAX_IMAGE_PIXELS_ENV: &str = "WSCG_MAX_IMAGE_PIXELS";

/// The pixel cap set by [`set_max_image_pixels`]; 0 when none was set.
static MAX_PIXELS: AtomicU64 = AtomicU64::new(0);

/// The largest `width x height` an image file may declare to be decoded: the value set by
/// [`set_max_image_pixels`], else `WSCG_MAX_IMAGE_PIXELS`, else
/// [`DEFAULT_MAX_IMAGE_PIXELS`].
pub fn max_image_pixels() -> u64 {
    static FROM_ENV: OnceLock<u64> = OnceLock::new();
    match MAX_PIXELS.load(Ordering::Relaxed) {
        0 => *FROM_ENV.get_or_init(|| {
            std::env::var(MAX_IMAGE_PIXELS_ENV)
                .ok()
                .and_then(|v| v.trim().parse::<u64>().ok())
                .filter(|&v| v > 0)
                .unwrap_or(DEFAULT_MAX_IMAGE_PIXELS)
        }),
        n => n,
    }
}

/// Sets [`max_image_pixels`] for the whole process (`None` or `Some(0)` restores the default).
pub fn set_max_image_pixels(pixels: Option<u64>) {
    MAX_PIXELS.store(pixels.unwrap_or(0), Ordering::Relaxed);
}

/// Maps a decoding error of the `image` crate for the file `origin`.
fn image_error(origin: &Path, e: image::ImageError) -> Error {
    match e {
        image::ImageError::Limits(l) => Error::LimitExceeded(format!("{}: {l}", origin.display())),
        image::ImageError::Unsupported(u) => {
            Error::UnsupportedFormat(format!("{}: {u}", origin.display()))
        }
        image::ImageError::IoError(io) => crate::error::read_error(origin, io),
        other => Error::format(origin, other.to_string()),
    }
}

/// Decodes an image file held in memory (format guessed from the content) under the limits
/// of this module: the header is read first, and a declared size above [`max_image_pixels`]
/// or [`MAX_DECODE_SIDE`] is refused before any pixel is decoded. `origin` names the source
/// in error messages. Every raster reader of the workspace decodes through this function.
pub fn decode_dynamic(bytes: &[u8], origin: &Path) -> Result<DynamicImage> {
    let mut reader = ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| Error::io(origin, e))?;
    if reader.format().is_none() {
        return Err(Error::format(
            origin,
            "not a recognised image (PNG, TIFF, JPEG, OpenEXR or Radiance HDR)",
        ));
    }
    if reader.format() == Some(ImageFormat::Jpeg) {
        check_jpeg_complete(bytes, origin)?;
        check_jpeg_sides(bytes, origin)?;
    }
    let max_pixels = max_image_pixels();
    let mut limits = Limits::default();
    limits.max_image_width = Some(MAX_DECODE_SIDE);
    limits.max_image_height = Some(MAX_DECODE_SIDE);
    limits.max_alloc = Some(MAX_DECODE_BYTES.max(max_pixels.saturating_mul(16)));
    reader.limits(limits);
    let decoder = guarded(origin, || {
        reader.into_decoder().map_err(|e| image_error(origin, e))
    })?;
    let (w, h) = decoder.dimensions();
    let pixels = u64::from(w) * u64::from(h);
    if pixels > max_pixels {
        return Err(Error::LimitExceeded(format!(
            "{}: declares {w} x {h} = {pixels} pixels, more than the limit of {max_pixels} \
             (raise it with set_max_image_pixels or {MAX_IMAGE_PIXELS_ENV})",
            origin.display()
        )));
    }
    guarded(origin, || {
        DynamicImage::from_decoder(decoder).map_err(|e| image_error(origin, e))
    })
}

/// Runs a step of the `image` crate's decoders under [`super::guarded`].
fn guarded<T>(origin: &Path, step: impl FnOnce() -> Result<T>) -> Result<T> {
    super::guarded(origin, "the image decoder", step)
}

/// Refuses a JPEG stream that ends before its end-of-image marker. The JPEG decoder fills
/// the missing part of a truncated file (an interrupted download or copy) with grey and
/// reports no error; this check makes it an error naming the file, as libjpeg and PIL do.
///
/// The marker `FF D9` is looked for after the first start-of-scan (`FF DA`): inside
/// entropy-coded data every `FF` byte is followed by `00` or a restart marker (ITU-T T.81,
/// B.1.1.5), so `FF D9` there can only be the end of the image; an EXIF thumbnail's own end
/// marker comes before the main scan.
fn check_jpeg_complete(bytes: &[u8], origin: &Path) -> Result<()> {
    let scan = bytes.windows(2).position(|w| w == [0xFF, 0xDA]);
    let complete =
        scan.is_some_and(|start| bytes[start + 2..].windows(2).any(|w| w == [0xFF, 0xD9]));
    if complete {
        Ok(())
    } else {
        Err(Error::format(
            origin,
            "truncated JPEG: the file ends before its end-of-image marker (an incomplete \
             download or copy?)",
        ))
    }
}

/// Largest JPEG width or height decoded: the JPEG decoder rounds each side up to a multiple
/// of 8 in 16-bit arithmetic, which overflows above `u16::MAX - 7`.
const MAX_JPEG_SIDE: u16 = u16::MAX - 7;

/// Refuses a JPEG whose frame header (any SOF marker before the first scan) declares a side
/// above [`MAX_JPEG_SIDE`], before the decoder reads it.
fn check_jpeg_sides(bytes: &[u8], origin: &Path) -> Result<()> {
    let header = bytes
        .windows(2)
        .position(|w| w == [0xFF, 0xDA])
        .map_or(bytes, |scan| &bytes[..scan]);
    for (i, w) in header.windows(2).enumerate() {
        let sof =
            w[0] == 0xFF && matches!(w[1], 0xC0..=0xCF) && !matches!(w[1], 0xC4 | 0xC8 | 0xCC);
        // SOFn: marker, length (2 bytes), precision (1), height (2), width (2).
        if let (true, Some(f)) = (sof, header.get(i + 5..i + 9)) {
            let (h, w) = (
                u16::from_be_bytes([f[0], f[1]]),
                u16::from_be_bytes([f[2], f[3]]),
            );
            if h > MAX_JPEG_SIDE || w > MAX_JPEG_SIDE {
                return Err(Error::LimitExceeded(format!(
                    "{}: a JPEG of {w} x {h} pixels; sides above {MAX_JPEG_SIDE} are not decoded",
                    origin.display()
                )));
            }
        }
    }
    Ok(())
}

impl Image<f32> {
    /// Converts a decoded [`DynamicImage`]: integer formats scaled to `[0, 1]`, float formats
    /// kept. Channels: L = 1, LA = 2, RGB = 3, RGBA = 4.
    pub fn from_dynamic(img: &DynamicImage) -> Self {
        let (w, h) = (img.width() as usize, img.height() as usize);
        let (channels, data): (usize, Vec<f32>) = match img {
            DynamicImage::ImageLuma8(b) => (1, b.iter().map(|&v| v as f32 / 255.0).collect()),
            DynamicImage::ImageLumaA8(b) => (2, b.iter().map(|&v| v as f32 / 255.0).collect()),
            DynamicImage::ImageRgb8(b) => (3, b.iter().map(|&v| v as f32 / 255.0).collect()),
            DynamicImage::ImageRgba8(b) => (4, b.iter().map(|&v| v as f32 / 255.0).collect()),
            DynamicImage::ImageLuma16(b) => (1, b.iter().map(|&v| v as f32 / 65535.0).collect()),
            DynamicImage::ImageLumaA16(b) => (2, b.iter().map(|&v| v as f32 / 65535.0).collect()),
            DynamicImage::ImageRgb16(b) => (3, b.iter().map(|&v| v as f32 / 65535.0).collect()),
            DynamicImage::ImageRgba16(b) => (4, b.iter().map(|&v| v as f32 / 65535.0).collect()),
            DynamicImage::ImageRgb32F(b) => (3, b.as_raw().clone()),
            DynamicImage::ImageRgba32F(b) => (4, b.as_raw().clone()),
            other => (4, other.to_rgba32f().into_raw()),
        };
        Image {
            height: h,
            width: w,
            channels,
            data,
        }
    }

    /// Converts to a [`DynamicImage`] of the given [`PixelDepth`]. Integer depths clamp to
    /// `[0, 1]` and round; two-channel images become luma + alpha.
    pub fn to_dynamic(&self, depth: PixelDepth) -> Result<DynamicImage> {
        let (w, h) = (self.width as u32, self.height as u32);
        let q8 = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        let q16 = |v: f32| (v.clamp(0.0, 1.0) * 65535.0).round() as u16;
        let bad = || Error::ShapeMismatch(format!("image of shape {:?}", self.shape()));
        let img = match (depth, self.channels) {
            (PixelDepth::U8, 1) => DynamicImage::ImageLuma8(
                ImageBuffer::from_raw(w, h, self.data.iter().map(|&v| q8(v)).collect())
                    .ok_or_else(bad)?,
            ),
            (PixelDepth::U8, 2) => DynamicImage::ImageLumaA8(
                ImageBuffer::from_raw(w, h, self.data.iter().map(|&v| q8(v)).collect())
                    .ok_or_else(bad)?,
            ),
            (PixelDepth::U8, 3) => DynamicImage::ImageRgb8(
                ImageBuffer::from_raw(w, h, self.data.iter().map(|&v| q8(v)).collect())
                    .ok_or_else(bad)?,
            ),
            (PixelDepth::U8, 4) => DynamicImage::ImageRgba8(
                ImageBuffer::from_raw(w, h, self.data.iter().map(|&v| q8(v)).collect())
                    .ok_or_else(bad)?,
            ),
            (PixelDepth::U16, 1) => DynamicImage::ImageLuma16(
                ImageBuffer::from_raw(w, h, self.data.iter().map(|&v| q16(v)).collect())
                    .ok_or_else(bad)?,
            ),
            (PixelDepth::U16, 2) => DynamicImage::ImageLumaA16(
                ImageBuffer::from_raw(w, h, self.data.iter().map(|&v| q16(v)).collect())
                    .ok_or_else(bad)?,
            ),
            (PixelDepth::U16, 3) => DynamicImage::ImageRgb16(
                ImageBuffer::from_raw(w, h, self.data.iter().map(|&v| q16(v)).collect())
                    .ok_or_else(bad)?,
            ),
            (PixelDepth::U16, 4) => DynamicImage::ImageRgba16(
                ImageBuffer::from_raw(w, h, self.data.iter().map(|&v| q16(v)).collect())
                    .ok_or_else(bad)?,
            ),
            (PixelDepth::F32, 3) => DynamicImage::ImageRgb32F(
                ImageBuffer::from_raw(w, h, self.data.clone()).ok_or_else(bad)?,
            ),
            (PixelDepth::F32, 4) => DynamicImage::ImageRgba32F(
                ImageBuffer::from_raw(w, h, self.data.clone()).ok_or_else(bad)?,
            ),
            (PixelDepth::F32, 1 | 2) => {
                let rgb: Vec<f32> = self
                    .data
                    .chunks_exact(self.channels)
                    .flat_map(|p| [p[0], p[0], p[0]])
                    .collect();
                DynamicImage::ImageRgb32F(ImageBuffer::from_raw(w, h, rgb).ok_or_else(bad)?)
            }
            (_, c) => {
                return Err(Error::invalid(
                    "image",
                    format!("{c} channels cannot be encoded; use 1 to 4"),
                ))
            }
        };
        Ok(img)
    }

    /// Decodes an image from bytes in memory (format guessed from the content).
    /// `origin` names the source in error messages.
    pub fn decode(bytes: &[u8], origin: &Path) -> Result<Self> {
        Ok(Self::from_dynamic(&decode_dynamic(bytes, origin)?))
    }

    /// Loads PNG or TIFF (8/16-bit), JPEG, OpenEXR or Radiance HDR. Integer formats are
    /// scaled to `[0, 1]`. The file is only read.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = read_file(path)?;
        Self::decode(&bytes, path)
    }

    /// Saves by extension: `.png` and `.tif`/`.tiff` (8-bit), `.jpg`/`.jpeg` (8-bit, 1 or 3
    /// channels), `.exr` (32-bit float) and `.hdr` (RGB float). Use
    /// [`Image::save_with_depth`] for 16-bit PNG or TIFF.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let depth = match format_of(path)? {
            ImageFormat::OpenExr | ImageFormat::Hdr => PixelDepth::F32,
            _ => PixelDepth::U8,
        };
        self.save_with_depth(path, depth)
    }

    /// Saves with an explicit pixel depth: `U8` or `U16` for PNG and TIFF (TIFF: 1, 3 or 4
    /// channels, uncompressed; also `F32` for 3 or 4), `U8` for JPEG, `F32` for OpenEXR and Radiance HDR.
    pub fn save_with_depth(&self, path: impl AsRef<Path>, depth: PixelDepth) -> Result<()> {
        let path = path.as_ref();
        let format = format_of(path)?;
        self.ensure_finite("image")?;
        let allowed = match format {
            ImageFormat::Png => matches!(depth, PixelDepth::U8 | PixelDepth::U16),
            // The TIFF encoder writes grey, RGB and RGBA, not grey + alpha.
            ImageFormat::Tiff => matches!(
                (depth, self.channels),
                (PixelDepth::U8 | PixelDepth::U16, 1 | 3 | 4) | (PixelDepth::F32, 3 | 4)
            ),
            ImageFormat::Jpeg => depth == PixelDepth::U8 && matches!(self.channels, 1 | 3),
            ImageFormat::OpenExr => depth == PixelDepth::F32,
            ImageFormat::Hdr => depth == PixelDepth::F32 && self.channels == 3,
            _ => false,
        };
        if !allowed {
            return Err(Error::UnsupportedFormat(format!(
                "{} cannot hold a {}-channel image at depth {depth:?}",
                path.display(),
                self.channels
            )));
        }
        let img = self.to_dynamic(depth)?;
        super::atomic::write_with(path, |out| {
            img.write_to(out, format).map_err(|e| match e {
                image::ImageError::IoError(io) => Error::io(path, io),
                other => Error::format(path, other.to_string()),
            })
        })
    }
}

impl Image<u16> {
    /// Loads an 8- or 16-bit PNG or TIFF (or 8-bit JPEG) as raw integer codes with their bit
    /// depth (8 or 16): what a camera response maps to radiance. Alpha channels are dropped.
    /// Float formats (OpenEXR, Radiance HDR, float TIFF) are errors: they hold no codes. The
    /// file is only read.
    pub fn load_codes(path: impl AsRef<Path>) -> Result<(Self, u8)> {
        let path = path.as_ref();
        let bytes = read_file(path)?;
        let img = decode_dynamic(&bytes, path)?;
        let (w, h) = (img.width() as usize, img.height() as usize);
        let (channels, bits, data): (usize, u8, Vec<u16>) =
            match &img {
                DynamicImage::ImageLuma8(b) => (1, 8, b.iter().map(|&v| v as u16).collect()),
                DynamicImage::ImageLumaA8(b) => {
                    (1, 8, b.iter().step_by(2).map(|&v| v as u16).collect())
                }
                DynamicImage::ImageRgb8(b) => (3, 8, b.iter().map(|&v| v as u16).collect()),
                DynamicImage::ImageRgba8(b) => (
                    3,
                    8,
                    b.chunks_exact(4)
                        .flat_map(|p| [p[0], p[1], p[2]])
                        .map(u16::from)
                        .collect(),
                ),
                DynamicImage::ImageLuma16(b) => (1, 16, b.to_vec()),
                DynamicImage::ImageLumaA16(b) => (1, 16, b.iter().step_by(2).copied().collect()),
                DynamicImage::ImageRgb16(b) => (3, 16, b.to_vec()),
                DynamicImage::ImageRgba16(b) => (
                    3,
                    16,
                    b.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect(),
                ),
                _ => return Err(Error::format(
                    path,
                    "holds float pixels, not integer codes; give 8- or 16-bit PNG/TIFF or JPEG \
                     views",
                )),
            };
        Ok((Image::new(h, w, channels, data)?, bits))
    }
}

impl Image<u8> {
    /// Loads an 8-bit image (PNG, TIFF, JPEG; 16-bit files are rounded to 8 bits,
    /// `(v + 128) / 257`)
    /// as 1 (grey) or 3 (RGB) channels of raw codes; alpha is dropped. The file is only read.
    /// Errors as [`Image::load_codes`].
    pub fn load_u8(path: impl AsRef<Path>) -> Result<Self> {
        let (img, bits) = Image::<u16>::load_codes(path)?;
        let (h, w, c) = img.shape();
        let data = img
            .into_data()
            .into_iter()
            .map(|v| {
                if bits == 16 {
                    ((v as u32 + 128) / 257) as u8
                } else {
                    v as u8
                }
            })
            .collect();
        Image::new(h, w, c, data)
    }

    /// Saves 8-bit codes by extension (`.png`, `.jpg`), exactly for PNG.
    pub fn save_u8(&self, path: impl AsRef<Path>) -> Result<()> {
        self.map(|v| v as f32 / 255.0).save(path)
    }
}

impl Image<f32> {
    /// JPEG bytes of a 1- or 3-channel image at `quality` (1..=100), values clamped to
    /// `[0, 1]` (baseline JPEG, as a thin client would receive).
    ///
    /// Errors: another channel count, quality outside 1..=100, non-finite pixels.
    pub fn encode_jpeg(&self, quality: u8) -> Result<Vec<u8>> {
        if !matches!(self.channels, 1 | 3) || !(1..=100).contains(&quality) {
            return Err(Error::invalid(
                "jpeg",
                format!(
                    "needs 1 or 3 channels and quality 1..=100, got {} and {quality}",
                    self.channels
                ),
            ));
        }
        self.ensure_finite("image")?;
        let img = self.to_dynamic(PixelDepth::U8)?;
        let mut out = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality)
            .encode_image(&img)
            .map_err(|e| Error::invalid("jpeg", e.to_string()))?;
        Ok(out)
    }
}

/// Sample depth used when encoding an [`Image`] to a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelDepth {
    /// 8 bits per sample, `[0, 1]` mapped to `0..=255`.
    U8,
    /// 16 bits per sample, `[0, 1]` mapped to `0..=65535`.
    U16,
    /// 32-bit float samples (OpenEXR, HDR).
    F32,
}

fn format_of(path: &Path) -> Result<ImageFormat> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "png" => Ok(ImageFormat::Png),
        "jpg" | "jpeg" => Ok(ImageFormat::Jpeg),
        "exr" => Ok(ImageFormat::OpenExr),
        "hdr" => Ok(ImageFormat::Hdr),
        "tif" | "tiff" => Ok(ImageFormat::Tiff),
        _ => Err(Error::UnsupportedFormat(format!(
            "extension {ext:?} of {}; supported: png, tif, tiff, jpg, jpeg, exr, hdr",
            path.display()
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::tests::ramp;

    #[test]
    fn jpeg_bytes_decode_to_the_image() {
        let img = ramp(16, 24, 3);
        let bytes = img.encode_jpeg(95).unwrap();
        let back = Image::decode(&bytes, Path::new("mem.jpg")).unwrap();
        assert_eq!(back.shape(), (16, 24, 3));
        let err = back
            .data()
            .iter()
            .zip(img.data())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(err < 0.05, "{err}");
        assert!(ramp(4, 4, 2).encode_jpeg(80).is_err());
        assert!(img.encode_jpeg(0).is_err());
    }

    /// Found by fuzzing (FUZZING.md): a JPEG declaring a side of 65530 pixels overflowed the
    /// decoder's 16-bit rounding to whole 8 x 8 blocks (a panic in debug builds).
    #[test]
    fn jpeg_sides_the_decoder_cannot_round_are_refused() {
        let img = ramp(6, 8, 1);
        let bytes = img.encode_jpeg(90).unwrap();
        let sof = bytes.windows(2).position(|w| w == [0xFF, 0xC0]).unwrap();
        for (at, side) in [(sof + 7, 0xFFFAu16), (sof + 5, 0xFFFF)] {
            let mut bad = bytes.clone();
            bad[at..at + 2].copy_from_slice(&side.to_be_bytes());
            let err = Image::decode(&bad, Path::new("wide.jpg")).unwrap_err();
            assert!(matches!(err, Error::LimitExceeded(_)), "{err}");
            assert!(err.to_string().contains("wide.jpg"), "{err}");
        }
        // The largest side still goes to the decoder (whatever it makes of the short data).
        let mut edge = bytes.clone();
        edge[sof + 7..sof + 9].copy_from_slice(&MAX_JPEG_SIDE.to_be_bytes());
        let edge = Image::decode(&edge, Path::new("edge.jpg"));
        assert!(edge.map_or_else(|e| !e.to_string().contains("not decoded"), |_| true));
    }

    #[test]
    fn truncated_jpeg_and_png_files_are_refused() {
        // A photograph-like image (smooth ramp plus texture), so that half of the file is
        // well inside the entropy-coded scan.
        let img = ramp(64, 96, 3);
        for (name, bytes) in [
            ("half.jpg", img.encode_jpeg(90).unwrap()),
            ("half.png", {
                let mut out = Vec::new();
                img.to_dynamic(PixelDepth::U8)
                    .unwrap()
                    .write_to(&mut Cursor::new(&mut out), ImageFormat::Png)
                    .unwrap();
                out
            }),
        ] {
            assert!(Image::decode(&bytes, Path::new(name)).is_ok());
            // A JPEG cut anywhere loses its end-of-image marker; a PNG cut after its last
            // pixel row but inside the IEND chunk is complete, as for libpng.
            let cuts = if name.ends_with(".jpg") {
                vec![bytes.len() / 2, bytes.len() - 2]
            } else {
                vec![bytes.len() / 2]
            };
            for cut in cuts {
                let Err(err) = Image::decode(&bytes[..cut], Path::new(name)) else {
                    panic!("{name} cut at {cut} of {} bytes decoded", bytes.len());
                };
                assert!(
                    matches!(err, Error::Format { .. }) || matches!(err, Error::Io { .. }),
                    "{name} cut at {cut}: {err}"
                );
                assert!(err.to_string().contains(name), "{err}");
            }
        }
        // Bytes after the end-of-image marker (some cameras append data) are accepted.
        let mut padded = img.encode_jpeg(90).unwrap();
        padded.extend_from_slice(&[0u8; 64]);
        assert!(Image::decode(&padded, Path::new("padded.jpg")).is_ok());
    }

    #[test]
    fn png8_png16_exr_hdr_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        for c in [1, 2, 3, 4] {
            let img = ramp(5, 7, c);
            let p = dir.path().join(format!("a{c}.png"));
            img.save(&p).unwrap();
            let back = Image::load(&p).unwrap();
            assert_eq!(back.shape(), img.shape());
            for (a, b) in img.data().iter().zip(back.data()) {
                assert!((a - b).abs() <= 0.5 / 255.0 + 1e-6);
            }
            let p16 = dir.path().join(format!("b{c}.png"));
            img.save_with_depth(&p16, PixelDepth::U16).unwrap();
            let back = Image::load(&p16).unwrap();
            for (a, b) in img.data().iter().zip(back.data()) {
                assert!((a - b).abs() <= 0.5 / 65535.0 + 1e-7);
            }
        }
        // Float formats keep values outside [0, 1].
        let hdrimg = ramp(4, 6, 3).map(|v| v * 40.0 + 0.01);
        let p = dir.path().join("c.exr");
        hdrimg.save(&p).unwrap();
        let back = Image::load(&p).unwrap();
        assert_eq!(back.channels(), 3);
        for (a, b) in hdrimg.data().iter().zip(back.data()) {
            assert!((a - b).abs() <= 1e-6 * a.abs().max(1.0));
        }
        let p = dir.path().join("d.hdr");
        hdrimg.save(&p).unwrap();
        let back = Image::load(&p).unwrap();
        // RGBE keeps about 8 bits of mantissa relative to the largest channel.
        for (pa, pb) in hdrimg.data().chunks(3).zip(back.data().chunks(3)) {
            let m = pa.iter().cloned().fold(0.0f32, f32::max);
            for (a, b) in pa.iter().zip(pb) {
                assert!((a - b).abs() <= m / 128.0, "{a} {b}");
            }
        }
    }

    #[test]
    fn jpeg_round_trip_is_close() {
        let dir = tempfile::tempdir().unwrap();
        let img = Image::from_fn(32, 32, |y, x| (x as f32 + y as f32) / 62.0).unwrap();
        let p = dir.path().join("g.jpg");
        img.save(&p).unwrap();
        let back = Image::load(&p).unwrap();
        let err: f32 = img
            .data()
            .iter()
            .zip(back.data())
            .map(|(a, b)| (a - b).abs())
            .sum::<f32>()
            / 1024.0;
        assert!(err < 0.02, "mean abs error {err}");
        assert!(ramp(4, 4, 2).save(dir.path().join("x.jpg")).is_err());
    }

    /// A PNG declaring `w x h` 8-bit grey pixels whose pixel data stops after the zlib header.
    fn png_header(w: u32, h: u32) -> Vec<u8> {
        let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut ihdr = w.to_be_bytes().to_vec();
        ihdr.extend(h.to_be_bytes());
        ihdr.extend([8, 0, 0, 0, 0]);
        for (kind, data) in [
            (&b"IHDR"[..], &ihdr[..]),
            (b"IDAT", &[0x78, 0x9c]),
            (b"IEND", &[]),
        ] {
            out.extend((data.len() as u32).to_be_bytes());
            let chunk = [kind, data].concat();
            out.extend(&chunk);
            out.extend(crc32(&chunk).to_be_bytes());
        }
        out
    }

    fn crc32(data: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in data {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    #[test]
    fn declared_sizes_above_the_pixel_cap_are_refused_before_decoding() {
        // 20000 x 20000 = 4e8 pixels > the default cap: refused from the header alone (a
        // decoder that went on would report the missing pixel data instead).
        let e = Image::decode(&png_header(20000, 20000), Path::new("bomb.png")).unwrap_err();
        assert!(matches!(e, Error::LimitExceeded(_)), "{e}");
        let msg = e.to_string();
        assert!(
            msg.contains("bomb.png") && msg.contains("20000 x 20000"),
            "{msg}"
        );
        assert!(Image::<u16>::load_codes(Path::new("/nonexistent.png")).is_err());
        // Under the cap, the same truncated header is a format error, not a limit.
        let small = Image::decode(&png_header(100, 100), Path::new("cut.png")).unwrap_err();
        assert!(small.is_io(), "{small}");
        assert_eq!(max_image_pixels(), DEFAULT_MAX_IMAGE_PIXELS);
    }

    /// A little-endian baseline TIFF declaring `w x h` 8-bit grey pixels in one strip of
    /// `strip` bytes at offset `at` (the file itself holds `data` after the IFD).
    fn tiff_header(w: u32, h: u32, at: u32, strip: u32, data: &[u8]) -> Vec<u8> {
        let entries: [(u16, u16, u32); 9] = [
            (256, 4, w),     // ImageWidth
            (257, 4, h),     // ImageLength
            (258, 3, 8),     // BitsPerSample
            (259, 3, 1),     // Compression: none
            (262, 3, 1),     // PhotometricInterpretation: black is zero
            (273, 4, at),    // StripOffsets
            (277, 3, 1),     // SamplesPerPixel
            (278, 4, h),     // RowsPerStrip
            (279, 4, strip), // StripByteCounts
        ];
        let mut out = b"II*\0".to_vec();
        out.extend(8u32.to_le_bytes());
        out.extend((entries.len() as u16).to_le_bytes());
        for (tag, kind, value) in entries {
            out.extend(tag.to_le_bytes());
            out.extend(kind.to_le_bytes());
            out.extend(1u32.to_le_bytes());
            match kind {
                3 => out.extend([(value as u16).to_le_bytes(), [0, 0]].concat()),
                _ => out.extend(value.to_le_bytes()),
            }
        }
        out.extend(0u32.to_le_bytes());
        out.extend(data);
        out
    }

    /// Offset of the pixel data of [`tiff_header`]: header, count, 9 entries, next IFD.
    const TIFF_DATA_AT: u32 = 8 + 2 + 9 * 12 + 4;

    #[test]
    fn tiff_8_and_16_bit_round_trips_are_exact() {
        let dir = tempfile::tempdir().unwrap();
        for c in [1, 3, 4] {
            let img = ramp(5, 7, c);
            for (depth, scale) in [(PixelDepth::U8, 255.0f32), (PixelDepth::U16, 65535.0)] {
                let p = dir.path().join(format!("a{c}_{depth:?}.tif"));
                img.save_with_depth(&p, depth).unwrap();
                let back = Image::load(&p).unwrap();
                assert_eq!(back.shape(), img.shape());
                for (a, b) in img.data().iter().zip(back.data()) {
                    // Exactly the quantised value, read back as the same code.
                    assert_eq!((a * scale).round(), (b * scale).round(), "{depth:?}");
                    assert!((a - b).abs() <= 0.5 / scale + 1e-6);
                }
                let (codes, bits) = Image::<u16>::load_codes(&p).unwrap();
                assert_eq!(bits, if depth == PixelDepth::U8 { 8 } else { 16 });
                let colour = if c >= 3 { 3 } else { 1 };
                assert_eq!(codes.shape(), (5, 7, colour));
                for y in 0..5 {
                    for x in 0..7 {
                        for k in 0..colour {
                            let want = (img.at(y, x, k) * scale).round() as u16;
                            assert_eq!(codes.at(y, x, k), want);
                        }
                    }
                }
            }
        }
        // `save` writes 8 bits; float TIFF keeps values outside [0, 1].
        let p = dir.path().join("plain.tiff");
        ramp(3, 4, 3).save(&p).unwrap();
        assert_eq!(Image::<u16>::load_codes(&p).unwrap().1, 8);
        let hdrimg = ramp(4, 6, 3).map(|v| v * 40.0 + 0.01);
        let p = dir.path().join("f.tif");
        hdrimg.save_with_depth(&p, PixelDepth::F32).unwrap();
        let back = Image::load(&p).unwrap();
        assert_eq!(back.data(), hdrimg.data());
        assert!(Image::<u16>::load_codes(&p).is_err());
        for bad in [ramp(2, 2, 1), ramp(2, 2, 2)] {
            assert!(bad
                .save_with_depth(dir.path().join("g.tif"), PixelDepth::F32)
                .is_err());
        }
        assert!(ramp(2, 2, 2).save(dir.path().join("la.tif")).is_err());
    }

    #[test]
    fn hand_made_tiff_decodes_and_bad_tiffs_are_refused() {
        let pixels: Vec<u8> = (0..12).map(|v| v * 20).collect();
        let good = tiff_header(4, 3, TIFF_DATA_AT, 12, &pixels);
        let img = Image::decode(&good, Path::new("hand.tif")).unwrap();
        assert_eq!(img.shape(), (3, 4, 1));
        assert_eq!(img.at(2, 3, 0), 220.0 / 255.0);
        let refused = |bytes: &[u8], name: &str| {
            let Err(e) = Image::decode(bytes, Path::new(name)) else {
                panic!("{name} decoded");
            };
            assert!(e.to_string().contains(name), "{e}");
            e
        };
        // Truncated: the strip is cut, then the IFD itself.
        for cut in [good.len() - 5, 20, 6] {
            let e = refused(&good[..cut], "cut.tif");
            assert!(e.is_io() || matches!(e, Error::LimitExceeded(_)), "{e}");
        }
        // Wrong magic: 43 (BigTIFF's number) with a classic header, and a byte-order mark
        // that is neither II nor MM.
        let mut magic = good.clone();
        magic[2] = 43;
        refused(&magic, "magic43.tif");
        let mut order = good.clone();
        order[..2].copy_from_slice(b"IM");
        refused(&order, "order.tif");
        // Inconsistent headers: the strip outside the file, a strip shorter than the image,
        // the first IFD past the end.
        refused(&tiff_header(4, 3, 5000, 12, &pixels), "strip_outside.tif");
        // Bits per sample (entry 2) of 7; three samples per pixel (entry 6) with grey
        // photometry and a strip one third that size.
        for (entry, value, name) in [(2, 7u16, "bits7.tif"), (6, 3, "samples3.tif")] {
            let mut bad = good.clone();
            let at = 10 + 12 * entry + 8;
            bad[at..at + 2].copy_from_slice(&value.to_le_bytes());
            refused(&bad, name);
        }
        // A StripByteCounts smaller than the strip, with the pixels present: read as libtiff
        // does (it recomputes the count of an uncompressed strip from the image size).
        let short = tiff_header(4, 3, TIFF_DATA_AT, 5, &pixels);
        assert_eq!(Image::decode(&short, Path::new("short.tif")).unwrap(), img);
        let mut ifd = good.clone();
        ifd[4..8].copy_from_slice(&9000u32.to_le_bytes());
        refused(&ifd, "ifd.tif");
    }

    #[test]
    fn tiff_sizes_above_the_pixel_cap_are_refused_before_decoding() {
        // 20000 x 20000 declared with a strip of 12 bytes: a decoder that allocated the
        // image first would ask for 400 MB.
        let bomb = tiff_header(20000, 20000, TIFF_DATA_AT, 12, &[0; 12]);
        let e = Image::decode(&bomb, Path::new("bomb.tif")).unwrap_err();
        assert!(matches!(e, Error::LimitExceeded(_)), "{e}");
        assert!(e.to_string().contains("bomb.tif"), "{e}");
        // The widest side the decoder would take.
        let wide = tiff_header(u32::MAX, 1, TIFF_DATA_AT, 12, &[0; 12]);
        let e = Image::decode(&wide, Path::new("wide.tif")).unwrap_err();
        assert!(matches!(e, Error::LimitExceeded(_)), "{e}");
    }

    #[test]
    fn bad_files_give_errors() {
        let dir = tempfile::tempdir().unwrap();
        assert!(matches!(
            Image::load(dir.path().join("missing.png")),
            Err(Error::Io { .. })
        ));
        let garbage = dir.path().join("garbage.png");
        std::fs::write(&garbage, b"this is not an image at all").unwrap();
        assert!(Image::load(&garbage).unwrap_err().is_io());
        // Truncated PNG: a valid file cut in half.
        let good = dir.path().join("good.png");
        ramp(64, 64, 3).save(&good).unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let cut = dir.path().join("cut.png");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        assert!(Image::load(&cut).unwrap_err().is_io());
        assert!(ramp(2, 2, 1).save(dir.path().join("a.bmp")).is_err());
        let nan = Image::new(1, 1, 1, vec![f32::NAN]).unwrap();
        assert!(nan.save(dir.path().join("nan.png")).is_err());
    }
}
