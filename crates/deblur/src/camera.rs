//! Camera model of the paper (section 3): pinhole intrinsics, rolling-shutter timing (eq. 6)
//! and the gamma camera response of section 3.3.

use nalgebra::Matrix3;
use wscg_math::{Error, Result};

/// Pinhole intrinsics `K = [[f, 0, cx], [0, f, cy], [0, 0, 1]]` in pixels (paper eq. 5).
/// Pixel `(x, y)` has its centre at integer coordinates; `x` grows to the right, `y` down,
/// and the optical axis is `+z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    /// Focal length in pixels (> 0).
    pub f: f64,
    /// Principal point, column.
    pub cx: f64,
    /// Principal point, row.
    pub cy: f64,
}

impl Intrinsics {
    /// Intrinsics with the principal point at the centre of a `width x height` frame.
    pub fn centred(f: f64, width: usize, height: usize) -> Self {
        Intrinsics {
            f,
            cx: (width as f64 - 1.0) / 2.0,
            cy: (height as f64 - 1.0) / 2.0,
        }
    }

    /// Errors: `f` not finite and positive, a non-finite principal point.
    pub fn validate(&self) -> Result<()> {
        if !(self.f.is_finite() && self.f > 0.0) {
            return Err(Error::invalid(
                "f",
                format!("focal length must be finite and > 0, got {}", self.f),
            ));
        }
        if !(self.cx.is_finite() && self.cy.is_finite()) {
            return Err(Error::invalid("cx, cy", "principal point must be finite"));
        }
        Ok(())
    }

    /// The matrix `K`.
    pub fn matrix(&self) -> Matrix3<f64> {
        Matrix3::new(self.f, 0.0, self.cx, 0.0, self.f, self.cy, 0.0, 0.0, 1.0)
    }

    /// The ray `K^-1 [x, y, 1]` of a pixel (not normalised).
    pub fn ray(&self, x: f64, y: f64) -> [f64; 3] {
        [(x - self.cx) / self.f, (y - self.cy) / self.f, 1.0]
    }

    /// The projection `pi(K X)` of a camera-frame point; `None` behind the camera.
    pub fn project(&self, p: [f64; 3]) -> Option<(f64, f64)> {
        let [x, y, z] = p;
        (z > 1e-9).then(|| (self.f * x / z + self.cx, self.f * y / z + self.cy))
    }
}

/// Exposure timing of one frame (paper eq. 6): row `y` of the frame opens its shutter at
/// `t_frame + t_delay + t_readout * y / height` and stays open for `t_exposure` seconds.
/// Times are in seconds on the frame clock; `t_delay` maps them onto the gyroscope clock.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    /// Frame timestamp `t_i` (s).
    pub t_frame: f64,
    /// Exposure time `t_e` (s, > 0).
    pub t_exposure: f64,
    /// Rolling-shutter readout time `t_r` of the whole frame (s, >= 0; 0 = global shutter).
    pub t_readout: f64,
    /// Gyroscope-camera delay `t_d` (s).
    pub t_delay: f64,
    /// Frame height `h` in rows.
    pub height: usize,
}

impl Timing {
    /// Errors: `t_exposure <= 0`, `t_readout < 0`, non-finite times, `height == 0`.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("t_frame", self.t_frame), ("t_delay", self.t_delay)] {
            if !v.is_finite() {
                return Err(Error::invalid(name, format!("must be finite, got {v}")));
            }
        }
        if !(self.t_exposure.is_finite() && self.t_exposure > 0.0) {
            return Err(Error::invalid(
                "t_exposure",
                format!("must be finite and > 0, got {}", self.t_exposure),
            ));
        }
        if !(self.t_readout.is_finite() && self.t_readout >= 0.0) {
            return Err(Error::invalid(
                "t_readout",
                format!("must be finite and >= 0, got {}", self.t_readout),
            ));
        }
        if self.height == 0 {
            return Err(Error::invalid("height", "frame height must be > 0"));
        }
        Ok(())
    }

    /// Shutter opening of row `y` (may be fractional), on the gyroscope clock (eq. 6).
    pub fn open(&self, y: f64) -> f64 {
        self.t_frame + self.t_delay + self.t_readout * y / self.height as f64
    }

    /// The same timing for another frame timestamp.
    pub fn at(&self, t_frame: f64) -> Self {
        Timing { t_frame, ..*self }
    }

    /// Reference time of the frame's virtual global shutter: the opening of its middle row
    /// (the target of the rolling-shutter rectification the paper takes from Karpenko et al.
    /// 2011, section 5; equals the frame's opening when `t_readout = 0`).
    pub fn reference(&self) -> f64 {
        self.open(self.height as f64 / 2.0)
    }
}

/// The camera response of section 3.3: a gamma curve (`gamma = 2.2` in the paper, after Li 2010).
/// Display values are in `[0, 1]`; linear irradiance `L = Z^gamma`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gamma(pub f32);

impl Default for Gamma {
    fn default() -> Self {
        Gamma(2.2)
    }
}

impl Gamma {
    /// Errors: a gamma that is not finite and positive.
    pub fn validate(&self) -> Result<()> {
        if !(self.0.is_finite() && self.0 > 0.0) {
            return Err(Error::invalid(
                "gamma",
                format!("must be finite and > 0, got {}", self.0),
            ));
        }
        Ok(())
    }

    /// Display value in `[0, 1]` (clamped) to linear irradiance.
    pub fn to_linear(&self, z: f32) -> f32 {
        z.clamp(0.0, 1.0).powf(self.0)
    }

    /// Linear irradiance (clamped to `[0, 1]`) to a display value.
    pub fn to_display(&self, l: f32) -> f32 {
        l.clamp(0.0, 1.0).powf(1.0 / self.0)
    }

    /// In-place conversion of a buffer to linear irradiance.
    pub fn linearise(&self, data: &mut [f32]) {
        data.iter_mut().for_each(|v| *v = self.to_linear(*v));
    }

    /// In-place conversion of a buffer to display values.
    pub fn encode(&self, data: &mut [f32]) {
        data.iter_mut().for_each(|v| *v = self.to_display(*v));
    }
}

/// Display values from linear ones in place: the camera response when given, else a clamp to
/// `[0, 1]`.
pub fn to_display(gamma: Option<Gamma>, data: &mut [f32]) {
    match gamma {
        Some(g) => g.encode(data),
        None => data.iter_mut().for_each(|v| *v = v.clamp(0.0, 1.0)),
    }
}
