//! Shading points: one primary ray through each pixel centre (paper 08, section 5), where
//! the records are placed; the box and tent pixel filters of [`super::render::PixelFilter`]
//! trace their sub-pixel rays at render time with [`shade_point`].

use nalgebra::Vector3;
use rayon::prelude::*;
use wscg_math::Result;

use super::camera::{Camera, CameraFrame};
use super::scene::{Rgb, Scene};

/// One pixel's shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingPoint {
    /// Hit position.
    pub pos: [f64; 3],
    /// Unit normal, turned towards the camera.
    pub normal: [f64; 3],
    /// Albedo.
    pub albedo: Rgb,
    /// Radiance emitted towards the camera.
    pub emitted: Rgb,
    /// Area of the surface the pixel covers (solid angle times distance squared over the
    /// cosine), used for the records' radii of influence.
    pub footprint: f64,
}

/// The shading points of an image, row-major from the top-left; `None` where the primary
/// ray leaves the scene.
#[derive(Clone, Debug)]
pub struct GBuffer {
    /// Width (pixels).
    pub width: usize,
    /// Height (pixels).
    pub height: usize,
    /// Per pixel.
    pub points: Vec<Option<ShadingPoint>>,
    /// The camera's frame (for records placed by extra primary rays).
    pub frame: CameraFrame,
}

impl ShadingPoint {
    /// As a receiver of VPL light.
    pub fn receiver(&self) -> super::shading::Receiver {
        super::shading::Receiver {
            pos: self.pos,
            normal: self.normal,
            albedo: self.albedo,
        }
    }
}

impl GBuffer {
    /// Number of pixels with a shading point.
    pub fn valid(&self) -> usize {
        self.points.iter().filter(|p| p.is_some()).count()
    }
}

/// The shading point seen along the camera ray through image position `(x, y)`, covering
/// `pixel_area` pixels.
pub fn shade_point(
    scene: &Scene,
    frame: &CameraFrame,
    x: f64,
    y: f64,
    pixel_area: f64,
) -> Option<ShadingPoint> {
    let d = frame.ray(x, y);
    let h = scene.intersect(frame.eye(), d, f64::INFINITY)?;
    let (d, hn) = (Vector3::from(d), Vector3::from(h.normal));
    let facing = hn.dot(&d) < 0.0;
    let normal = if facing { hn } else { -hn };
    let cos = normal.dot(&-d).max(1e-6);
    Some(ShadingPoint {
        pos: h.pos,
        normal: normal.into(),
        albedo: scene.albedo(h.tri),
        emitted: if facing {
            scene.emission(h.tri)
        } else {
            [0.0; 3]
        },
        footprint: frame.solid_angle(x, y, pixel_area) * h.t * h.t / cos,
    })
}

/// Traces the primary ray through every pixel centre.
///
/// Errors: an invalid camera.
pub fn trace_primary(scene: &Scene, cam: &Camera) -> Result<GBuffer> {
    let frame = cam.frame()?;
    let points = (0..cam.width * cam.height)
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % cam.width) as f64 + 0.5, (i / cam.width) as f64 + 0.5);
            shade_point(scene, &frame, x, y, 1.0)
        })
        .collect();
    Ok(GBuffer {
        width: cam.width,
        height: cam.height,
        points,
        frame,
    })
}
