//! Pinhole camera of the many-light renderer.

use nalgebra::Vector3;
use wscg_math::{Error, Result};

/// A pinhole camera: eye, view direction, up vector, vertical field of view, image size.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: [f64; 3],
    /// Point looked at (the image centre).
    pub target: [f64; 3],
    /// Up direction (need not be orthogonal to the view direction).
    pub up: [f64; 3],
    /// Vertical field of view (degrees).
    pub fov_deg: f64,
    /// Image width (pixels).
    pub width: usize,
    /// Image height (pixels).
    pub height: usize,
}

/// The camera's orthonormal frame and image-plane scale.
#[derive(Clone, Copy, Debug)]
pub struct CameraFrame {
    eye: Vector3<f64>,
    right: Vector3<f64>,
    up: Vector3<f64>,
    forward: Vector3<f64>,
    /// Half-height of the image plane at distance 1.
    tan_half: f64,
    width: usize,
    height: usize,
}

impl Camera {
    /// Errors: a zero-size image, a field of view outside (0, 180) degrees, a non-finite
    /// vector, an eye on its target, an up vector along the view direction.
    pub fn frame(&self) -> Result<CameraFrame> {
        if self.width == 0 || self.height == 0 {
            return Err(Error::invalid(
                "camera",
                format!("image size {} x {} is empty", self.width, self.height),
            ));
        }
        // Per pixel: the G-buffer point (about 120 bytes), the image and the per-pixel
        // statistics; 256 bytes bound them.
        wscg_math::alloc::ensure_shape::<[u8; 256]>("width, height", &[self.width, self.height])?;
        if !(self.fov_deg > 0.0 && self.fov_deg < 180.0) {
            return Err(Error::invalid(
                "fov_deg",
                format!("must lie in (0, 180), got {}", self.fov_deg),
            ));
        }
        let all = [self.eye, self.target, self.up];
        if all.iter().any(|v| v.iter().any(|c| !c.is_finite())) {
            return Err(Error::invalid(
                "camera",
                "eye, target and up must be finite",
            ));
        }
        let (eye, up) = (Vector3::from(self.eye), Vector3::from(self.up));
        let f = Vector3::from(self.target) - eye;
        if f.norm() == 0.0 {
            return Err(Error::invalid("camera", "the eye lies on its target"));
        }
        let forward = f.normalize();
        let r = forward.cross(&up);
        if r.norm() <= 1e-9 * up.norm() {
            return Err(Error::invalid(
                "camera",
                "up is parallel to the view direction",
            ));
        }
        let right = r.normalize();
        Ok(CameraFrame {
            eye,
            right,
            up: right.cross(&forward),
            forward,
            tan_half: (0.5 * self.fov_deg.to_radians()).tan(),
            width: self.width,
            height: self.height,
        })
    }
}

impl CameraFrame {
    /// Eye position.
    pub fn eye(&self) -> [f64; 3] {
        self.eye.into()
    }

    /// View direction (unit).
    pub fn forward(&self) -> [f64; 3] {
        self.forward.into()
    }

    /// Unit direction through image position `(x, y)` in pixels (`(0, 0)` the top-left
    /// corner, `(w, h)` the bottom-right).
    pub fn ray(&self, x: f64, y: f64) -> [f64; 3] {
        self.ray_v(x, y).into()
    }

    fn ray_v(&self, x: f64, y: f64) -> Vector3<f64> {
        let aspect = self.width as f64 / self.height as f64;
        let sx = (2.0 * x / self.width as f64 - 1.0) * self.tan_half * aspect;
        let sy = (1.0 - 2.0 * y / self.height as f64) * self.tan_half;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// Solid angle of `area` square pixels around image position `(x, y)`.
    pub fn solid_angle(&self, x: f64, y: f64, area: f64) -> f64 {
        let d = self.ray_v(x, y);
        // The image plane at distance 1: a pixel is (2 tan_half / height)^2 in area there.
        let px = 2.0 * self.tan_half / self.height as f64;
        let cos = d.dot(&self.forward);
        area * px * px * cos * cos * cos
    }
}
