//! Camera model of the paper (section 3): pinhole intrinsics, rolling-shutter timing (eq. 6)
//! and the gamma camera response of section 3.3.

use std::path::Path;

use nalgebra::Matrix3;
use wscg_math::{Error, Result};

/// Largest camera file read (64 KiB: six numbers need a hundred bytes).
pub const MAX_CAMERA_BYTES: u64 = 64 << 10;

/// A camera file (JSON): any of the focal length `f` and principal point `cx`, `cy` in pixels
/// (eq. 5), the exposure and rolling-shutter readout times and the gyroscope-camera delay in
/// seconds (eq. 6); the caller's values fill the keys it leaves out. Unknown keys are refused.
/// Example: `{"f": 720, "exposure": 0.03, "readout": 0.025, "delay": 0.01}`.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct CameraFile {
    /// Focal length (pixels).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub f: Option<f64>,
    /// Principal point, column (pixels).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cx: Option<f64>,
    /// Principal point, row (pixels).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cy: Option<f64>,
    /// Exposure time (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exposure: Option<f64>,
    /// Rolling-shutter readout time of the whole frame (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub readout: Option<f64>,
    /// Gyroscope-camera delay (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delay: Option<f64>,
}

impl CameraFile {
    /// Reads a camera file (see [`CameraFile::from_json_bytes`]).
    ///
    /// Errors: [`Error::Io`] when unreadable; [`Error::LimitExceeded`] above
    /// [`MAX_CAMERA_BYTES`]; the format errors of [`CameraFile::from_json_bytes`].
    pub fn read(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = wscg_math::error::read_file_at_most(path, MAX_CAMERA_BYTES, "camera files")?;
        Self::from_json_bytes(&bytes, path)
    }

    /// Parses a camera file held in memory; `origin` names the file in errors.
    ///
    /// Errors ([`Error::Format`] naming `origin`, with the line and column of the JSON
    /// error): not a JSON object of the keys above; an unknown key; a focal length that is
    /// not finite and positive; a principal point, exposure, readout or delay that is not
    /// finite; a negative exposure or readout.
    pub fn from_json_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        let c: Self =
            serde_json::from_slice(bytes).map_err(|e| Error::format(origin, e.to_string()))?;
        let bad = |key: &str, why: &str| Err(Error::format(origin, format!("`{key}` {why}")));
        if let Some(f) = c.f {
            if !(f.is_finite() && f > 0.0) {
                return bad("f", "must be finite and > 0");
            }
        }
        for (key, v, min) in [
            ("cx", c.cx, f64::NEG_INFINITY),
            ("cy", c.cy, f64::NEG_INFINITY),
            ("exposure", c.exposure, 0.0),
            ("readout", c.readout, 0.0),
            ("delay", c.delay, f64::NEG_INFINITY),
        ] {
            if let Some(v) = v {
                if !(v.is_finite() && v >= min) {
                    return bad(key, "must be finite (and >= 0 for times of the shutter)");
                }
            }
        }
        Ok(c)
    }

    /// Writes the camera file as JSON (atomically), only the keys it sets.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| Error::invalid("camera", e.to_string()))?;
        wscg_math::io::atomic::write(path, text)
    }
}

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

#[cfg(test)]
mod camera_file_tests {
    use super::*;

    #[test]
    fn a_camera_file_reads_its_keys_and_round_trips() {
        let o = Path::new("cam.json");
        let c = CameraFile::from_json_bytes(br#"{"f": 720, "delay": -0.01}"#, o).unwrap();
        assert_eq!((c.f, c.delay, c.cx), (Some(720.0), Some(-0.01), None));
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("cam.json");
        c.write(&p).unwrap();
        assert_eq!(CameraFile::read(&p).unwrap(), c);
    }

    #[test]
    fn bad_camera_files_are_format_errors_naming_the_file() {
        let o = Path::new("cam.json");
        for bad in [
            &br#"{"f": 720"#[..],
            br#"{"focal": 720}"#,
            br#"{"f": "720"}"#,
            br#"{"f": 0}"#,
            br#"{"f": -5}"#,
            br#"{"exposure": -0.1}"#,
            br#"{"cx": 1e999}"#,
            b"\xff",
        ] {
            let e = CameraFile::from_json_bytes(bad, o).unwrap_err();
            assert!(
                matches!(e, Error::Format { .. }) && e.to_string().contains("cam.json"),
                "{e}"
            );
        }
    }
}
