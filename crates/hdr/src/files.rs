//! The calibration files of an exposure stack (paper section 3): the inverse camera response
//! `f^-1(Z)` as a CSV table (one row per code `Z = 0 ..= z_max`, one column per channel) and
//! the exposure times (text, one or more a line, or JSON: a list, or an object with
//! `exposure_times` or `times`). Every reader has a byte-level entry naming its origin in
//! errors; the writers are atomic.

use std::path::Path;

use wscg_math::io::csv;
use wscg_math::{Error, Result};

use crate::crf::Crf;

/// Largest calibration file read (16 MiB: a 16-bit response of 4 channels is about 4 MiB of
/// text).
pub const MAX_CALIBRATION_BYTES: u64 = 16 << 20;

fn read_bounded(path: &Path) -> Result<Vec<u8>> {
    wscg_math::error::read_file_at_most(path, MAX_CALIBRATION_BYTES, "calibration files")
}

impl Crf {
    /// Reads a response table written by [`Crf::write_csv`] (see [`Crf::from_csv_bytes`]).
    pub fn read_csv(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        Self::from_csv_bytes(&read_bounded(path)?, path)
    }

    /// A response from a CSV table held in memory: one row of `channels` numbers per code,
    /// `#` comments; `origin` names the file in errors.
    ///
    /// Errors ([`Error::Format`] naming `origin`, with the line where there is one): a cell
    /// that is not a number; rows of different lengths; no rows; a table that
    /// [`Crf::from_table`] refuses (fewer than 2 or more than 65536 rows, a decreasing or
    /// negative response).
    pub fn from_csv_bytes(bytes: &[u8], origin: &Path) -> Result<Self> {
        let mut values: Vec<f32> = Vec::new();
        let mut cols = 0;
        let rows = csv::records(bytes, origin, b',')?;
        for row in &rows {
            let r: Vec<f32> = row.deserialize(None, origin)?;
            if cols == 0 {
                cols = r.len();
            } else if r.len() != cols {
                return Err(Error::format(
                    origin,
                    format!("line {}: {} columns, expected {cols}", row.line, r.len()),
                ));
            }
            values.extend(r);
        }
        if cols == 0 {
            return Err(Error::format(origin, "no table rows"));
        }
        Self::from_table(&values, rows.len(), cols)
            .map_err(|e| Error::format(origin, e.to_string()))
    }

    /// Writes the response as CSV (a `#` comment line, then one row per code), atomically.
    pub fn write_csv(&self, path: impl AsRef<Path>) -> Result<()> {
        let mut text = format!(
            "# inverse camera response f^-1(Z), Z = 0..{}, one column per channel\n",
            self.z_max()
        );
        for row in self.table().chunks_exact(self.channels()) {
            let cells: Vec<String> = row.iter().map(|v| format!("{v:e}")).collect();
            text.push_str(&cells.join(","));
            text.push('\n');
        }
        wscg_math::io::atomic::write(path, text)
    }
}

/// Reads exposure times: JSON for a `.json` file ([`parse_exposure_times_json`]), text
/// otherwise ([`parse_exposure_times_text`]).
pub fn read_exposure_times(path: impl AsRef<Path>) -> Result<Vec<f64>> {
    let path = path.as_ref();
    let bytes = read_bounded(path)?;
    let json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if json {
        parse_exposure_times_json(&bytes, path)
    } else {
        parse_exposure_times_text(&bytes, path)
    }
}

/// Exposure times (seconds) from text held in memory: numbers separated by commas or line
/// ends, `#` comments; `origin` names the file in errors.
///
/// Errors ([`Error::Format`] naming `origin` and the line): a value that is not a finite
/// number `> 0`; no times.
pub fn parse_exposure_times_text(bytes: &[u8], origin: &Path) -> Result<Vec<f64>> {
    let mut times = Vec::new();
    for row in csv::records(bytes, origin, b',')? {
        for v in row.fields.iter().filter(|v| !v.is_empty()) {
            let t = v.parse::<f64>().ok().filter(|t| t.is_finite() && *t > 0.0);
            times.push(t.ok_or_else(|| {
                Error::format(
                    origin,
                    format!(
                        "line {}: {v:?} is not an exposure time (seconds > 0)",
                        row.line
                    ),
                )
            })?);
        }
    }
    if times.is_empty() {
        return Err(Error::format(origin, "no exposure times"));
    }
    Ok(times)
}

/// Exposure times (seconds) from JSON held in memory: a list of numbers, or an object whose
/// `exposure_times` (or `times`) is one; `origin` names the file in errors.
///
/// Errors ([`Error::Format`] naming `origin`): malformed JSON (with its line and column);
/// another shape; a time that is not a finite number `> 0`; no times.
pub fn parse_exposure_times_json(bytes: &[u8], origin: &Path) -> Result<Vec<f64>> {
    #[derive(serde::Deserialize)]
    #[serde(untagged)]
    enum Times {
        List(Vec<f64>),
        Object {
            #[serde(alias = "times")]
            exposure_times: Vec<f64>,
        },
    }
    let times = match serde_json::from_slice::<Times>(bytes) {
        Ok(Times::List(t) | Times::Object { exposure_times: t }) => t,
        Err(e) if e.is_syntax() || e.is_eof() => return Err(Error::format(origin, e.to_string())),
        Err(_) => {
            return Err(Error::format(
                origin,
                "expected a list of exposure times or {\"exposure_times\": [...]}",
            ))
        }
    };
    if let Some(i) = times.iter().position(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(Error::format(
            origin,
            format!(
                "exposure time {i} is {}; times must be > 0 seconds",
                times[i]
            ),
        ));
    }
    if times.is_empty() {
        return Err(Error::format(origin, "no exposure times"));
    }
    Ok(times)
}

/// Writes exposure times as text, one a line (atomically).
pub fn write_exposure_times(path: impl AsRef<Path>, times: &[f64]) -> Result<()> {
    let text: String = times.iter().map(|t| format!("{t}\n")).collect();
    wscg_math::io::atomic::write(path, text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_response_round_trips_through_its_table() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("crf.csv");
        let crf = Crf::gamma(2.2, 8, 3).unwrap();
        crf.write_csv(&p).unwrap();
        let back = Crf::read_csv(&p).unwrap();
        assert_eq!(back.table(), crf.table());
        assert_eq!((back.channels(), back.z_max()), (3, 255));
    }

    #[test]
    fn response_errors_name_the_file_and_the_line() {
        let o = Path::new("crf.csv");
        let err = |t: &[u8]| Crf::from_csv_bytes(t, o).unwrap_err().to_string();
        let e = err(b"# c\n0\n0.5,1\n");
        assert!(e.contains("crf.csv") && e.contains("line 3"), "{e}");
        let e = err(b"0\nx\n");
        assert!(e.contains("line 2"), "{e}");
        let e = err(b"1\n0.5\n");
        assert!(e.contains("crf.csv"), "{e}");
        assert!(err(b"# only\n").contains("no table rows"));
    }

    #[test]
    fn exposure_times_read_from_text_and_json() {
        let o = Path::new("times");
        assert_eq!(
            parse_exposure_times_text(b"# t\n0.01\n0.02, 0.04\n", o).unwrap(),
            [0.01, 0.02, 0.04]
        );
        let e = parse_exposure_times_text(b"0.01\n-1\n", o)
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2"), "{e}");
        assert!(parse_exposure_times_text(b"\n", o).is_err());
        for ok in [
            &b"[0.5, 1]"[..],
            br#"{"exposure_times": [0.5, 1]}"#,
            br#"{"times": [0.5, 1]}"#,
        ] {
            assert_eq!(parse_exposure_times_json(ok, o).unwrap(), [0.5, 1.0]);
        }
        for bad in [
            &b"[0.5, 1"[..],
            b"{}",
            br#"{"times": ["a"]}"#,
            b"[0]",
            b"[]",
            b"7",
        ] {
            let e = parse_exposure_times_json(bad, o).unwrap_err();
            assert!(matches!(e, Error::Format { .. }), "{e}");
        }
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("times.txt");
        write_exposure_times(&p, &[0.01, 1.0 / 3.0]).unwrap();
        assert_eq!(read_exposure_times(&p).unwrap(), [0.01, 1.0 / 3.0]);
    }
}
