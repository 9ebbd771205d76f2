//! Gyroscope integration (paper section 3.2): body-frame angular rates are rotated into the
//! camera axes, integrated into orientations at the sample times and super-resolved in between
//! by spherical linear interpolation (SLERP).

use std::path::Path;

use nalgebra::{Rotation3, UnitQuaternion, Vector3};
use wscg_math::io::csv;
use wscg_math::{Error, Result};

/// One gyroscope reading: time `t` (s, gyroscope clock) and angular rate `w` (rad/s, IMU axes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GyroSample {
    /// Time stamp in seconds.
    pub t: f64,
    /// Angular rate in rad/s about the IMU's x, y, z axes.
    pub w: [f64; 3],
}

impl GyroSample {
    /// A sample from a time and three rates.
    pub fn new(t: f64, wx: f64, wy: f64, wz: f64) -> Self {
        GyroSample { t, w: [wx, wy, wz] }
    }
}

/// Reads a gyroscope log: one `t,wx,wy,wz` row per sample (commas, semicolons, spaces or
/// tabs between the numbers; an optional header row; `#` comments).
///
/// Errors: [`Error::Io`] when unreadable; [`Error::Format`] naming the path for text that is
/// not UTF-8, a row without four numbers, or no samples.
pub fn read_gyro_csv(path: &Path) -> Result<Vec<GyroSample>> {
    parse_gyro_csv(&wscg_math::error::read_file(path)?, path)
}

/// [`read_gyro_csv`] of a file held in memory; `origin` names the file in errors.
pub fn parse_gyro_csv(bytes: &[u8], origin: &Path) -> Result<Vec<GyroSample>> {
    let mut out = Vec::new();
    for (i, row) in csv::records(bytes, origin, b',')?.iter().enumerate() {
        // Runs of spaces separate like one.
        let nums: std::result::Result<Vec<f64>, _> = row
            .split_fields(&[';', ' ', '\t'])
            .filter(|s| !s.is_empty())
            .map(str::parse::<f64>)
            .collect();
        match nums {
            Ok(n) if n.len() == 4 => out.push(GyroSample::new(n[0], n[1], n[2], n[3])),
            Err(_) if i == 0 => continue, // a header row
            _ => {
                return Err(Error::format(
                    origin,
                    format!("line {}: expected 4 numbers t,wx,wy,wz", row.line),
                ))
            }
        }
    }
    if out.is_empty() {
        return Err(Error::format(origin, "no gyroscope samples"));
    }
    Ok(out)
}

/// Reads the start times of video frames (seconds, on the gyroscope log's clock, as
/// `wscg deblur frames` takes them in `times.txt`): numbers separated by commas or line
/// ends, `#` comments.
pub fn read_frame_times(path: &Path) -> Result<Vec<f64>> {
    parse_frame_times(&wscg_math::error::read_file(path)?, path)
}

/// [`read_frame_times`] of a file held in memory; `origin` names the file in errors.
///
/// Errors ([`Error::Format`] naming `origin` and the line): a value that is not a finite
/// number; no times.
pub fn parse_frame_times(bytes: &[u8], origin: &Path) -> Result<Vec<f64>> {
    let mut times = Vec::new();
    for row in csv::records(bytes, origin, b',')? {
        for v in row.fields.iter().filter(|v| !v.is_empty()) {
            let t = v.parse::<f64>().ok().filter(|t| t.is_finite());
            times.push(t.ok_or_else(|| {
                Error::format(
                    origin,
                    format!("line {}: {v:?} is not a time in seconds", row.line),
                )
            })?);
        }
    }
    if times.is_empty() {
        return Err(Error::format(origin, "no frame times"));
    }
    Ok(times)
}

/// Writes a gyroscope log that [`read_gyro_csv`] reads back (atomically): a comment
/// `# t,wx,wy,wz` naming the columns (s, rad/s), then one `t,wx,wy,wz` row per sample (6 decimals: microseconds and
/// micro-radians per second).
pub fn write_gyro_csv(path: impl AsRef<Path>, samples: &[GyroSample]) -> Result<()> {
    let rows = samples.iter().map(|s| {
        [s.t, s.w[0], s.w[1], s.w[2]]
            .iter()
            .map(|v| format!("{v:.6}"))
            .collect::<Vec<_>>()
    });
    csv::write(path.as_ref(), &["# t", "wx", "wy", "wz"], rows)
}

/// An integrated gyroscope trace: the camera orientation `q(t)` (camera axes to the frame of
/// the first sample) at every sample time, SLERP in between.
///
/// Integration (body-frame rates, right multiplication): `q_{k+1} = q_k * exp(1/2 R_ci (w_mid -
/// bias) dt)` with the mid-interval rate `w_mid = (w_k + w_{k+1}) / 2`, so between two samples
/// the camera turns at a constant rate and SLERP is exact for that motion.
#[derive(Clone, Debug)]
pub struct GyroTrack {
    times: Vec<f64>,
    orientations: Vec<UnitQuaternion<f64>>,
}

impl GyroTrack {
    /// Integrates `samples` (strictly increasing times) with the camera-from-IMU rotation
    /// `r_cam_imu` (rates are expressed in camera axes as `r_cam_imu * w`) and a constant
    /// `bias` (rad/s, IMU axes) subtracted from every reading.
    ///
    /// Errors: fewer than two samples, non-finite values, unsorted or duplicate time stamps.
    pub fn new(samples: &[GyroSample], r_cam_imu: Rotation3<f64>, bias: [f64; 3]) -> Result<Self> {
        if samples.len() < 2 {
            return Err(Error::invalid(
                "gyro",
                format!("need at least 2 gyroscope samples, got {}", samples.len()),
            ));
        }
        if !bias.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid("bias", "gyroscope bias must be finite"));
        }
        for (i, s) in samples.iter().enumerate() {
            if !(s.t.is_finite() && s.w.iter().all(|v| v.is_finite())) {
                return Err(Error::NonFinite {
                    name: "gyro",
                    index: i,
                });
            }
            if i > 0 && s.t <= samples[i - 1].t {
                return Err(Error::invalid(
                    "gyro",
                    format!(
                        "time stamps must be strictly increasing: sample {i} at t = {} follows t = {}",
                        s.t,
                        samples[i - 1].t
                    ),
                ));
            }
        }
        let mut orientations = Vec::with_capacity(samples.len());
        let mut q = UnitQuaternion::identity();
        orientations.push(q);
        for pair in samples.windows(2) {
            let dt = pair[1].t - pair[0].t;
            let w_mid =
                (Vector3::from(pair[0].w) + Vector3::from(pair[1].w)) * 0.5 - Vector3::from(bias);
            q *= UnitQuaternion::from_scaled_axis(r_cam_imu * w_mid * dt);
            orientations.push(q);
        }
        Ok(GyroTrack {
            times: samples.iter().map(|s| s.t).collect(),
            orientations,
        })
    }

    /// Integrates samples given in camera axes with no bias.
    pub fn from_camera_rates(samples: &[GyroSample]) -> Result<Self> {
        Self::new(samples, Rotation3::identity(), [0.0; 3])
    }

    /// First and last sample time.
    pub fn span(&self) -> (f64, f64) {
        (self.times[0], self.times[self.times.len() - 1])
    }

    /// Errors naming the uncovered part when `[t0, t1]` is not inside the sampled span.
    pub fn ensure_covers(&self, t0: f64, t1: f64) -> Result<()> {
        let (a, b) = self.span();
        if t0 < a || t1 > b || !(t0.is_finite() && t1.is_finite()) {
            return Err(Error::invalid(
                "gyro",
                format!(
                    "gyroscope samples cover [{a:.6}, {b:.6}] s but the exposure needs [{t0:.6}, {t1:.6}] s \
                     (gap of {:.6} s); check t_delay, t_exposure and the frame times",
                    (a - t0).max(t1 - b).max(0.0)
                ),
            ));
        }
        Ok(())
    }

    /// Camera orientation at `t` (camera axes to the reference frame): SLERP between the two
    /// enclosing samples, clamped to the first or last sample outside the span.
    pub fn orientation(&self, t: f64) -> UnitQuaternion<f64> {
        let n = self.times.len();
        if t <= self.times[0] {
            return self.orientations[0];
        }
        if t >= self.times[n - 1] {
            return self.orientations[n - 1];
        }
        let k = self.times.partition_point(|&s| s <= t) - 1;
        let f = (t - self.times[k]) / (self.times[k + 1] - self.times[k]);
        self.orientations[k].slerp(&self.orientations[k + 1], f)
    }

    /// Rotation taking camera-at-`t1` coordinates to camera-at-`t0` coordinates,
    /// `R(t0)^T R(t1)`.
    pub fn relative(&self, t0: f64, t1: f64) -> Rotation3<f64> {
        (self.orientation(t0).inverse() * self.orientation(t1)).to_rotation_matrix()
    }
}

#[cfg(test)]
mod csv_tests {
    use super::*;

    #[test]
    fn frame_times_read_lines_and_commas_and_name_bad_values() {
        let text = b"# t (s)\n0.0, 0.0334\n-0.5\n\n1e-1\n";
        let got = parse_frame_times(text, Path::new("times.txt")).unwrap();
        assert_eq!(got, vec![0.0, 0.0334, -0.5, 0.1]);
        for (bad, expect) in [
            (&b"0.0\n0.1\nabc\n"[..], "line 3"),
            (b"0.0\nNaN\n", "line 2"),
            (b"# none\n", "no frame times"),
            (b"", "no frame times"),
        ] {
            let err = parse_frame_times(bad, Path::new("times.txt")).unwrap_err();
            assert!(matches!(err, Error::Format { .. }), "{err}");
            let text = err.to_string();
            assert!(
                text.contains("times.txt") && text.contains(expect),
                "{text}"
            );
        }
    }

    #[test]
    fn gyro_csv_reads_rows_after_a_header_and_names_bad_lines() {
        let text = b"t,wx,wy,wz\n# comment\n0.0,0.1,-0.2,0.3\n0.01 0.5\t1e-3;2\n";
        let got = parse_gyro_csv(text, Path::new("g.csv")).unwrap();
        assert_eq!(
            got,
            vec![
                GyroSample::new(0.0, 0.1, -0.2, 0.3),
                GyroSample::new(0.01, 0.5, 1e-3, 2.0)
            ]
        );
        let err = parse_gyro_csv(b"0,1,2,3\n0.1,1,2\n", Path::new("g.csv")).unwrap_err();
        assert!(matches!(err, Error::Format { .. }));
        assert!(err.to_string().contains("line 2") && err.to_string().contains("g.csv"));
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("g.csv");
        write_gyro_csv(&p, &got).unwrap();
        assert_eq!(read_gyro_csv(&p).unwrap(), got);
        for bad in [&b""[..], b"t,wx,wy,wz\n", b"\xff\xfe"] {
            assert!(matches!(
                parse_gyro_csv(bad, Path::new("g.csv")),
                Err(Error::Format { .. })
            ));
        }
    }
}
