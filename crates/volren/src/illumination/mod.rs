//! Paper 15, Angelelli and Bruckner, "Performance and Quality Analysis of Convolution-Based
//! Volume Illumination": slice-based direct volume rendering with instant convolution shadows
//! (ICS: a light buffer attenuated by each slice and convolved before the next) and the
//! paper's two ways of sampling the tissue more finely than the light: supersampling (SCS,
//! `m` tissue sub-samples per slice lit by interpolated light) and pre-integration (PI-ICS, a
//! 2-D lookup table per segment), and both (PI-SCS). Baselines: emission-absorption and
//! Blinn-Phong ray casting, and ray casting with shadow rays (the delta-kernel limit).
//!
//! - [`field`]: the normalised scalar volume and its sampling.
//! - [`classify`]: the transfer function and opacity correction.
//! - [`preintegration`]: the pre-integration table (§3.1).
//! - [`kernel`]: the light kernels with exact per-slice variance.
//! - [`camera`]: the orthographic camera and the view-aligned slices.
//! - [`method`]: methods, light and settings.
//! - [`scenes`]: analytic test volumes (Marschner-Lobb, slab, half-plane occluder).
//! - [`study`]: the paper's quality/speed study (MAD, alias test, slice-distance sweeps).
//!
//! Only `O(W H)` buffers are allocated besides the volume: there is no 3-D illumination
//! volume (the paper's premise).
//!
//! The volume's box bounds the light's propagation: the light buffer starts unattenuated at
//! the box's front face. With [`LightBorder::Open`] (the default) the outside of the box is
//! empty, so light passes round an occluder that does not reach the box's sides and, with a
//! blurring kernel, leaks in under its edges; with [`LightBorder::Closed`] the outside is
//! opaque beyond the faces not turned towards the light, so light enters only through the
//! faces turned towards it.

mod bricks;
pub mod camera;
mod cells;
pub mod classify;
pub mod field;
pub mod kernel;
pub mod method;
pub mod preintegration;
mod raycast;
mod sampler;
pub mod scenes;
mod slicer;
pub mod study;
mod voxels;

pub use camera::{SliceCamera, Slicing};
pub use classify::{SampleLut, TransferFunction};
pub use field::{Interp, ScalarField};
pub use kernel::{Kernel, StepKernel};
pub use method::{
    IlluminationParams, Light, LightAtten, LightBorder, Method, Phong, MAX_SUBSAMPLES,
};
pub use preintegration::PreIntegrationTable;

use wscg_math::{Error, Image, Result};

use raycast::{raycast, RayShading};
use sampler::Sampler;
use slicer::{Prepared, SliceRun};

/// A rendered image and what it cost.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// RGBA, `H x W x 4`, colour composited over the background, alpha = accumulated opacity.
    pub image: Image<f32>,
    /// Slices (slice methods) or samples per ray (ray casters).
    pub slices: usize,
    /// Floats held in 2-D working buffers (slice methods; 0 for ray casters).
    pub buffer_floats: usize,
}

/// Renders `field` classified by `tf` from `cam` with `method` (paper §3 and the baselines of
/// §5.1).
///
/// Errors: an invalid camera, light (`z <= 0`, bad kernel or ambient), method parameter
/// (distance not finite and positive, more than 64 sub-samples, more than 2^20 slices or
/// samples per ray, a kernel reaching more than 65,536 pixels per slice) or setting.
pub fn render(
    field: &ScalarField,
    tf: &TransferFunction,
    cam: &SliceCamera,
    light: &Light,
    method: &Method,
    settings: &IlluminationParams,
) -> Result<Rendered> {
    let mut out = render_many(
        field,
        tf,
        std::slice::from_ref(cam),
        light,
        method,
        settings,
    )?;
    Ok(out.remove(0))
}

/// Renders several views with the same transfer function and method; the classification
/// tables (the pre-integration table in particular) and the empty-space cells are built once.
/// Errors: as [`render`], no camera.
pub fn render_many(
    field: &ScalarField,
    tf: &TransferFunction,
    cams: &[SliceCamera],
    light: &Light,
    method: &Method,
    settings: &IlluminationParams,
) -> Result<Vec<Rendered>> {
    settings.validate()?;
    if cams.is_empty() {
        return Err(Error::Empty("cameras"));
    }
    let frames = cams.iter().map(|c| c.frame()).collect::<Result<Vec<_>>>()?;
    method.check()?;
    light.unit_dir()?;
    let image = |cam: &SliceCamera, rgba: Vec<f32>| Image::new(cam.height, cam.width, 4, rgba);
    match *method {
        Method::Ics { .. } => {
            let prep = Prepared::new(field, tf, settings, method)?;
            cams.iter()
                .zip(&frames)
                .map(|(cam, frame)| {
                    let out = SliceRun::new(field, &prep, frame, light, settings)?.render();
                    wscg_math::cancel::check()?;
                    Ok(Rendered {
                        image: image(cam, out.rgba)?,
                        slices: out.slices,
                        buffer_floats: out.buffer_floats,
                    })
                })
                .collect()
        }
        Method::RaycastEa { step }
        | Method::RaycastPhong { step, .. }
        | Method::ShadowRays { step } => {
            let shading = match *method {
                Method::RaycastPhong { phong, .. } => RayShading::Phong(phong),
                Method::ShadowRays { .. } => RayShading::Shadow,
                _ => RayShading::None,
            };
            let sampler = Sampler::new(field, tf, settings.interp, false);
            let lut = tf.sampled(step);
            cams.iter()
                .zip(&frames)
                .map(|(cam, frame)| {
                    let (rgba, n) =
                        raycast(field, &sampler, &lut, frame, light, settings, step, shading)?;
                    wscg_math::cancel::check()?;
                    Ok(Rendered {
                        image: image(cam, rgba)?,
                        slices: n,
                        buffer_floats: 0,
                    })
                })
                .collect()
        }
    }
}

/// The light buffer arriving at the slice nearest to `depth` (world units behind the front
/// of the volume's depth range), `H x W`, 1 where no volume is in the way; returns the buffer
/// and the exact depth of that slice. A test and debugging hook.
///
/// Errors: as [`render`], a method that is not slice-based, a non-finite or negative depth.
pub fn light_buffer_at(
    field: &ScalarField,
    tf: &TransferFunction,
    cam: &SliceCamera,
    light: &Light,
    method: &Method,
    settings: &IlluminationParams,
    depth: f64,
) -> Result<(Image<f32>, f64)> {
    settings.validate()?;
    let frame = cam.frame()?;
    method.check()?;
    if !(depth.is_finite() && depth >= 0.0) {
        return Err(Error::invalid(
            "depth",
            format!("must be finite and >= 0, got {depth}"),
        ));
    }
    let prep = Prepared::new(field, tf, settings, method)?;
    let run = SliceRun::new(field, &prep, &frame, light, settings)?;
    let sl = run.slicing();
    let k = ((depth / sl.ds - 0.5).round().max(0.0) as usize).min(sl.n);
    let buf = run.light_at(k);
    Ok((
        Image::new(cam.height, cam.width, 1, buf)?,
        (k as f64 + 0.5) * sl.ds,
    ))
}
