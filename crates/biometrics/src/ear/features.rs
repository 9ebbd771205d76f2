//! Pre-processing and enrolment features (section 3.2).
//!
//! The colour ear crop is resized to `height x width` (100 x 80; area averaging down,
//! bilinear up), converted to grey with OpenCV's fixed-point BT.601 and histogram-equalised
//! with `cv2.equalizeHist` arithmetic (resize first, so the equalisation sees the final
//! pixels; never per channel, which would destroy the chromaticity of Algorithm 1). The
//! feature image `F = Y_eq / 255` is cut into `block x block` tiles (10 x 10, index
//! `b = cols * i + j`, row-major); each tile's level-1 Haar LL band (5 x 5 values in
//! `[0, 2]`) is its feature vector. Because the tiles are even-aligned, the tile LLs together
//! are the LL band of the whole image.

use wscg_math::image::Image;
use wscg_math::wavelet::haar_ll;
use wscg_math::{Error, ImageView, Result};

use super::params::EarParams;
use crate::imgops::tone::{equalize_hist_within, resize_u8, rgb_to_gray};

/// An enrolled ear: `blocks x block_len` Haar LL features (80 x 25 by default), row-major
/// by block index.
#[derive(Clone, Debug, PartialEq)]
pub struct EarTemplate {
    feats: Vec<f32>,
    blocks: usize,
    block_len: usize,
}

impl EarTemplate {
    /// Wraps `blocks * block_len` features. Errors: a length mismatch, non-finite values.
    pub fn new(feats: Vec<f32>, blocks: usize, block_len: usize) -> Result<Self> {
        if blocks == 0 || block_len == 0 || feats.len() != blocks * block_len {
            return Err(Error::ShapeMismatch(format!(
                "template has {} values, expected {blocks} blocks x {block_len} features",
                feats.len()
            )));
        }
        if let Some(i) = feats.iter().position(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                name: "template",
                index: i,
            });
        }
        Ok(EarTemplate {
            feats,
            blocks,
            block_len,
        })
    }

    /// All features, block after block.
    pub fn features(&self) -> &[f32] {
        &self.feats
    }

    /// Features of block `b`.
    pub fn block(&self, b: usize) -> &[f32] {
        &self.feats[b * self.block_len..(b + 1) * self.block_len]
    }

    /// Number of blocks.
    pub fn blocks(&self) -> usize {
        self.blocks
    }

    /// Features per block.
    pub fn block_len(&self) -> usize {
        self.block_len
    }

    /// Checks the template fits `p` (block count and length).
    pub fn check(&self, p: &EarParams) -> Result<()> {
        p.check_layout("template", self.blocks, self.block_len)
    }
}

/// Checks an input ear image: at least 2 x 2 pixels, and 3 channels (`allow_gray`: 1 or 3).
pub fn check_input(img: &Image<u8>, allow_gray: bool) -> Result<()> {
    let (h, w, c) = img.shape();
    if h < 2 || w < 2 {
        return Err(Error::invalid(
            "image",
            format!("must be at least 2 x 2 pixels, got {h} x {w}"),
        ));
    }
    match (c, allow_gray) {
        (3, _) | (1, true) => Ok(()),
        (1, false) => Err(Error::invalid(
            "image",
            "is grey (1 channel); occlusion detection needs RGB, and grey enrolment must be \
             asked for explicitly (gray_enrolment)",
        )),
        _ => Err(Error::invalid(
            "image",
            format!("needs 3 colour channels (RGB), got {c}"),
        )),
    }
}

/// Resizes the crop to the normalised `p.height x p.width` (100 x 80 in the paper, §3.2 and
/// Algorithm 1 step 1).
pub fn normalise(img: &Image<u8>, p: &EarParams) -> Result<Image<u8>> {
    resize_u8(img, p.height, p.width)
}

/// The feature image `F = equalize(grey) / 255` of an image already at the normalised size
/// (the histogram equalisation of §3.2 and Algorithm 1 step 1, applied to the grey image only
/// so that the chromaticity of the skin test is untouched); grey (1-channel) input skips the
/// colour conversion. With `within`, the equalisation histogram counts only those pixels (see
/// [`EarParams::equalize_on_skin`]).
pub fn feature_plane(small: &Image<u8>, within: Option<&[u8]>) -> Result<Image<f64>> {
    let gray = if small.channels() == 1 {
        small.data().to_vec()
    } else {
        rgb_to_gray(small)?
    };
    let plane = equalize_hist_within(&gray, within)
        .into_iter()
        .map(|v| v as f64 / 255.0)
        .collect();
    Image::new(small.height(), small.width(), 1, plane)
}

/// Haar LL features of every block of a single-channel `p.height x p.width` plane (paper
/// §3.2: the low-frequency subband of a one-level 2-D Haar DWT per block; orthonormal Haar,
/// `LL = (sum of a 2 x 2 cell) / 2`), `blocks x block_len`, row-major by block index.
///
/// Errors: a plane of another size or with more than one channel.
pub fn block_features(plane: ImageView<'_, f64>, p: &EarParams) -> Result<Vec<f32>> {
    if (plane.height(), plane.width()) != (p.height, p.width) {
        return Err(Error::ShapeMismatch(format!(
            "`plane` is {} x {}, the parameters need {} x {}",
            plane.height(),
            plane.width(),
            p.height,
            p.width
        )));
    }
    let ll = haar_ll(plane)?;
    let ll = ll.data();
    let (gr, gc) = p.grid();
    let (hb, lw) = (p.block / 2, p.width / 2);
    let mut out = Vec::with_capacity(p.blocks() * p.block_len());
    for bi in 0..gr {
        for bj in 0..gc {
            for u in 0..hb {
                let row = (bi * hb + u) * lw + bj * hb;
                out.extend(ll[row..row + hb].iter().map(|&v| v as f32));
            }
        }
    }
    Ok(out)
}

/// Enrols a clean ear crop (section 3.2): normalise, equalise, per-block Haar LL. No skin
/// masking (enrolment is supervised and assumed un-occluded).
///
/// Errors: an image under 2 x 2, a non-RGB image (grey only with `p.gray_enrolment`), bad
/// parameters.
pub fn enroll(img: &Image<u8>, p: &EarParams) -> Result<EarTemplate> {
    p.validate()?;
    check_input(img, p.gray_enrolment)?;
    let small = normalise(img, p)?;
    let plane = feature_plane(&small, None)?;
    EarTemplate::new(block_features(plane.view(), p)?, p.blocks(), p.block_len())
}
