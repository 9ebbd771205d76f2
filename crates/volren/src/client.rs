//! The client's renderings (paper 03, section 5): the hybrid image of the low-resolution
//! context and the ROI's Gradient Octree, and the baselines' viewers, all cast by
//! [`crate::render`]'s two-level ray caster from the data the client received.

use wscg_math::{Error, Image, Result, Volume};

use crate::gradient_octree::Roi;
use crate::package::HybridClient;
use crate::render::{cast, Camera, EmptyCells, RenderParams, Source};
use crate::tf::PiecewiseTransferFunction;

/// Transfer function `k` of `tfs`, or an error naming the ROI's transfer function.
fn tf_index(tfs: &[PiecewiseTransferFunction], k: usize) -> Result<&PiecewiseTransferFunction> {
    tfs.get(k)
        .ok_or_else(|| Error::invalid("roi_tf", format!("transfer function {k} of {}", tfs.len())))
}

impl HybridClient {
    fn context(&self) -> Source<'_> {
        Source::Context {
            lowres: &self.lowres,
            factor: self.lowres_factor as f64,
            tf: &self.tfs[self.canonical],
            empty: &self.context_empty,
        }
    }

    fn roi_source<'a>(
        &'a self,
        tf: &'a PiecewiseTransferFunction,
        exact: Option<&'a Volume<u8>>,
    ) -> Option<(&'a Roi, Source<'a>)> {
        self.roi.as_ref().map(|(r, s, leaves)| {
            (
                r,
                Source::Octree {
                    structure: s,
                    leaves,
                    mats: &self.materials,
                    tf,
                    exact,
                },
            )
        })
    }

    /// The hybrid image: `V_W` under the canonical transfer function outside the ROI, the
    /// octree under transfer function `roi_tf` inside (the context only without a ROI).
    /// RGBA, `height x width x 4`.
    ///
    /// Errors: bad camera or options, `roi_tf` out of range.
    pub fn render(&self, cam: &Camera, roi_tf: usize, opts: &RenderParams) -> Result<Image<f32>> {
        opts.validate()?;
        self.render_with(cam, roi_tf, opts, None)
    }

    /// [`HybridClient::render`] with the ROI shaded by unquantised normals computed from
    /// `volume` (the server's volume): the reference that measures the normal code's loss.
    ///
    /// Errors: as `render`, and a volume of other dims than the client's.
    pub fn render_exact_normals(
        &self,
        volume: &Volume<u8>,
        cam: &Camera,
        roi_tf: usize,
        opts: &RenderParams,
    ) -> Result<Image<f32>> {
        opts.validate()?;
        if volume.dims() != self.dims {
            return Err(Error::ShapeMismatch(format!(
                "volume {:?} for a client of {:?}",
                volume.dims(),
                self.dims
            )));
        }
        self.render_with(cam, roi_tf, opts, Some(volume))
    }

    fn render_with(
        &self,
        cam: &Camera,
        roi_tf: usize,
        opts: &RenderParams,
        exact: Option<&Volume<u8>>,
    ) -> Result<Image<f32>> {
        let tf = tf_index(&self.tfs, roi_tf)?;
        let roi = self.roi_source(tf, exact).map(|(r, s)| (r, s, opts.step));
        cast(
            self.dims,
            cam,
            opts,
            roi,
            (self.context(), opts.context_step),
        )
    }

    /// The Gradient-Octree baseline: the ROI's octree alone under `roi_tf`, nothing outside
    /// (with the ROI set to the whole volume, the paper's full Gradient Octree viewer).
    ///
    /// Errors: no ROI set, bad camera or options, `roi_tf` out of range.
    pub fn render_octree(
        &self,
        cam: &Camera,
        roi_tf: usize,
        opts: &RenderParams,
    ) -> Result<Image<f32>> {
        opts.validate()?;
        let tf = tf_index(&self.tfs, roi_tf)?;
        let (_, src) = self
            .roi_source(tf, None)
            .ok_or_else(|| Error::invalid("roi", "no ROI package received"))?;
        cast(self.dims, cam, opts, None, (src, opts.step))
    }

    /// The wavelet scheme's client (baseline [1] of the paper): with every wavelet step
    /// received (`full`, the `w_l = 4` decode of a package sent with 4 steps), the decoded
    /// full-resolution volume under `roi_tf` inside the ROI box and `V_W` under the canonical
    /// transfer function outside, both unlit.
    ///
    /// Errors: no ROI set, `full` of another size than the client's padded volume, bad camera,
    /// options or `roi_tf`.
    pub fn render_wavelet_scheme(
        &self,
        full: &Volume<f32>,
        cam: &Camera,
        roi_tf: usize,
        opts: &RenderParams,
    ) -> Result<Image<f32>> {
        opts.validate()?;
        let tf = tf_index(&self.tfs, roi_tf)?;
        let (roi, _, _) = self
            .roi
            .as_ref()
            .ok_or_else(|| Error::invalid("roi", "no ROI package received"))?;
        let padded = self.lowres.dims().map(|d| d * self.lowres_factor);
        if full.dims() != padded {
            return Err(Error::ShapeMismatch(format!(
                "full-resolution decode {:?} for a padded volume {padded:?}",
                full.dims()
            )));
        }
        let empty = EmptyCells::new(full, tf);
        let inside = Source::Context {
            lowres: full,
            factor: 1.0,
            tf,
            empty: &empty,
        };
        cast(
            self.dims,
            cam,
            opts,
            Some((roi, inside, opts.step)),
            (self.context(), opts.context_step),
        )
    }

    /// The wavelet-context baseline: `V_W` everywhere, no ROI.
    pub fn render_context(&self, cam: &Camera, opts: &RenderParams) -> Result<Image<f32>> {
        opts.validate()?;
        cast(
            self.dims,
            cam,
            opts,
            None,
            (self.context(), opts.context_step),
        )
    }
}
