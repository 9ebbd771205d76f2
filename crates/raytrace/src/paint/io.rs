//! Writing rendered views: tristimulus and spectral OpenEXR files, and the stereo pair as a
//! side-by-side or a red-cyan anaglyph picture.

use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image as ExrImage, Layer, LayerAttributes,
    SmallVec, WritableImage,
};
use wscg_math::image::Image;
use wscg_math::{Error, Result};

use super::render::XyzImage;

fn write_channels(
    path: &Path,
    size: (usize, usize),
    channels: Vec<(String, Vec<f32>)>,
) -> Result<()> {
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .into_iter()
        .map(|(name, v)| AnyChannel::new(name.as_str(), FlatSamples::F32(v)))
        .collect();
    let layer = Layer::new(
        size,
        LayerAttributes::named("paint"),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(list),
    );
    ExrImage::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| Error::format(path, e.to_string()))
}

/// Writes the view's CIE XYZ as a 32-bit float OpenEXR file with channels `X`, `Y`, `Z`.
///
/// Errors: the file cannot be written.
pub fn write_xyz_exr(img: &XyzImage, path: impl AsRef<Path>) -> Result<()> {
    let plane = |c: usize| img.xyz.iter().skip(c).step_by(3).copied().collect();
    write_channels(
        path.as_ref(),
        (img.width, img.height),
        vec![
            ("X".into(), plane(0)),
            ("Y".into(), plane(1)),
            ("Z".into(), plane(2)),
        ],
    )
}

/// Writes the view's radiance per band as a 32-bit float OpenEXR file, one channel per band
/// named by its wavelength (`380nm`, `385nm`, ...).
///
/// Errors: a view rendered without [`super::render::PaintRenderParams::keep_spectrum`], or a
/// file that cannot be written.
pub fn write_spectral_exr(img: &XyzImage, path: impl AsRef<Path>) -> Result<()> {
    let n = img.bands_nm.len();
    if n == 0 || img.spectrum.len() != n * img.width * img.height {
        return Err(Error::invalid(
            "img",
            "the view holds no spectrum: render it with keep_spectrum",
        ));
    }
    let channels = img
        .bands_nm
        .iter()
        .enumerate()
        .map(|(k, l)| {
            (
                format!("{l:.0}nm"),
                img.spectrum.iter().skip(k).step_by(n).copied().collect(),
            )
        })
        .collect();
    write_channels(path.as_ref(), (img.width, img.height), channels)
}

/// The two display images side by side (left on the left), for cross-free parallel viewing
/// or a side-by-side stereo display.
///
/// Errors: images of different shapes.
pub fn side_by_side(left: &Image<f32>, right: &Image<f32>) -> Result<Image<f32>> {
    left.ensure_same_shape(right)?;
    let (h, w, c) = left.shape();
    let mut out = Vec::with_capacity(2 * h * w * c);
    for y in 0..h {
        out.extend_from_slice(&left.data()[y * w * c..(y + 1) * w * c]);
        out.extend_from_slice(&right.data()[y * w * c..(y + 1) * w * c]);
    }
    Image::new(h, 2 * w, c, out)
}

/// A red-cyan anaglyph of two display images: red from the left image, green and blue from
/// the right (each eye's filter passes its own view).
///
/// Errors: images of different shapes or without three channels.
pub fn anaglyph(left: &Image<f32>, right: &Image<f32>) -> Result<Image<f32>> {
    left.ensure_same_shape(right)?;
    let (h, w, c) = left.shape();
    if c != 3 {
        return Err(Error::invalid(
            "left",
            format!("an RGB image is needed, got {c} channels"),
        ));
    }
    let data = left
        .data()
        .chunks_exact(3)
        .zip(right.data().chunks_exact(3))
        .flat_map(|(l, r)| [l[0], r[1], r[2]])
        .collect();
    Image::new(h, w, 3, data)
}
