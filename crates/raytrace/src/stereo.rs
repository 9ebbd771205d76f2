//! The off-axis stereo rig of paper 07, section 3: eyes 6.5 cm apart, 77 cm from the plate,
//! parallel optical axes with asymmetric frusta (never toe-in, which adds vertical parallax),
//! the plate in the zero-parallax plane, and the screen of the study (ASUS VG248QE, 1920 x 1080,
//! 531.36 x 298.89 mm) so that the plate is shown at 1:1 scale.
//!
//! Coordinates (metres): eyes at `(-e/2, 0, 0)` (left), `(0, 0, 0)` (cyclopean) and `(e/2, 0,
//! 0)` (right), x to the right, y up, z from the viewer towards the screen; the screen (and the
//! plate's top surface) is the plane `z = a`.

use nalgebra::Vector3;
use wscg_math::{Error, Result};

/// Which eye a view is rendered for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Eye {
    /// Left eye, at `-e/2`.
    Left,
    /// Right eye, at `+e/2`.
    Right,
    /// Between the eyes: the monoscopic condition (the same image shown to both eyes).
    Cyclopean,
}

/// A ray: origin and unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: [f64; 3],
    /// Unit direction.
    pub dir: [f64; 3],
}

/// The viewing geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StereoRig {
    /// Interocular distance `e` (m); 0.065 in the paper.
    pub eye_sep_m: f64,
    /// Viewing distance `a` to the screen and plate (m); 0.77 in the paper.
    pub dist_m: f64,
    /// Screen width `b` (m).
    pub screen_w_m: f64,
    /// Screen height (m).
    pub screen_h_m: f64,
    /// Screen resolution (pixels).
    pub res: (u32, u32),
}

impl Default for StereoRig {
    fn default() -> Self {
        Self {
            eye_sep_m: 0.065,
            dist_m: 0.77,
            screen_w_m: 0.53136,
            screen_h_m: 0.29889,
            res: (1920, 1080),
        }
    }
}

impl StereoRig {
    /// Errors unless every length is finite and positive (the eye separation may be 0) and
    /// the resolution non-zero.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("dist_m", self.dist_m),
            ("screen_w_m", self.screen_w_m),
            ("screen_h_m", self.screen_h_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    name,
                    format!("must be finite and positive, got {v}"),
                ));
            }
        }
        if !(self.eye_sep_m.is_finite() && self.eye_sep_m >= 0.0) {
            return Err(Error::invalid(
                "eye_sep_m",
                format!("must be finite and >= 0, got {}", self.eye_sep_m),
            ));
        }
        if self.res.0 == 0 || self.res.1 == 0 {
            return Err(Error::invalid("res", "the resolution must be non-zero"));
        }
        Ok(())
    }

    /// The position of `eye`.
    pub fn eye(&self, eye: Eye) -> [f64; 3] {
        let x = match eye {
            Eye::Left => -0.5 * self.eye_sep_m,
            Eye::Right => 0.5 * self.eye_sep_m,
            Eye::Cyclopean => 0.0,
        };
        [x, 0.0, 0.0]
    }

    /// Horizontal and vertical fields of view (degrees) of the cyclopean frustum:
    /// `fov = 2 atan(b / (2 a))`. The paper prints `2 atan(2a / b)`, which is inverted.
    pub fn fov_deg(&self) -> (f64, f64) {
        let f = |b: f64| 2.0 * (b / (2.0 * self.dist_m)).atan().to_degrees();
        (f(self.screen_w_m), f(self.screen_h_m))
    }

    /// Size of one screen pixel (m), horizontally and vertically.
    pub fn pixel_pitch_m(&self) -> (f64, f64) {
        (
            self.screen_w_m / self.res.0 as f64,
            self.screen_h_m / self.res.1 as f64,
        )
    }

    /// The screen point at continuous pixel coordinates `(px, py)` (pixel `(i, j)` covers
    /// `[i, i+1) x [j, j+1)`, its centre at `i + 1/2`; `j` grows downwards).
    pub fn screen_point(&self, px: f64, py: f64) -> [f64; 3] {
        let (sx, sy) = self.pixel_pitch_m();
        [
            -0.5 * self.screen_w_m + px * sx,
            0.5 * self.screen_h_m - py * sy,
            self.dist_m,
        ]
    }

    /// The ray from `eye` through the screen point at `(px, py)`: each eye has its own
    /// asymmetric frustum onto the same screen rectangle (off-axis projection).
    pub fn ray(&self, eye: Eye, px: f64, py: f64) -> Ray {
        let o = self.eye(eye);
        Ray {
            origin: o,
            dir: (Vector3::from(self.screen_point(px, py)) - Vector3::from(o))
                .normalize()
                .into(),
        }
    }

    /// Continuous pixel coordinates where `p` (in front of the eyes, `p.z > 0`) appears for
    /// `eye`; `None` for points at or behind the eye plane.
    pub fn project(&self, eye: Eye, p: [f64; 3]) -> Option<(f64, f64)> {
        let p = Vector3::from(p);
        if p.z.is_nan() || p.z <= 0.0 {
            return None;
        }
        let o = Vector3::from(self.eye(eye));
        let s = o + (p - o) * (self.dist_m / p.z);
        let (sx, sy) = self.pixel_pitch_m();
        Some((
            (s.x + 0.5 * self.screen_w_m) / sx,
            (0.5 * self.screen_h_m - s.y) / sy,
        ))
    }

    /// Screen parallax (right minus left image position, pixels) of a point at depth `z`:
    /// `P = e (z - a) / z`, positive behind the screen.
    pub fn parallax_px(&self, z: f64) -> f64 {
        self.eye_sep_m * (z - self.dist_m) / z / self.pixel_pitch_m().0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wscg_math::vec3::add_scaled;

    #[test]
    fn ray_and_projection_are_inverse() {
        let rig = StereoRig::default();
        for eye in [Eye::Left, Eye::Right, Eye::Cyclopean] {
            let r = rig.ray(eye, 100.25, 700.5);
            let p = add_scaled(r.origin, 1.3, r.dir);
            let (x, y) = rig.project(eye, p).unwrap();
            assert!((x - 100.25).abs() < 1e-9 && (y - 700.5).abs() < 1e-9);
        }
        assert!(rig.project(Eye::Left, [0.0, 0.0, -1.0]).is_none());
    }
}
