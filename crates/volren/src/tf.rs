//! Piecewise-linear transfer functions and the materials they induce (paper 03, section 4:
//! "we virtually segment V in as many regions as linear segments of {TF_k}").
//!
//! The union of all control-point densities of all transfer functions, plus 0 and 256, cuts
//! the density range into intervals `[b_i, b_(i+1))`. An interval on which every transfer
//! function is transparent is *null* (material 0); the others get material ids 1, 2, ... in
//! order (at most 63, the 6 bits of the voxel code). A client colours material `m` under a
//! transfer function by its value at the interval's midpoint.

use std::path::Path;

use wscg_math::{Error, Result};

/// Reads a transfer-function file: JSON `{"tfs": [[[density, r, g, b, a], ...], ...],
/// "canonical": k}` (`canonical`, the index of the transfer function the server classifies
/// with, defaults to 0). Returns the transfer functions and `canonical`.
///
/// Errors: [`Error::Io`] when unreadable; [`Error::Format`] naming the path for text that is
/// not JSON or not of that shape; the errors of [`PiecewiseTransferFunction::new`].
pub fn read_tf_list(path: &Path) -> Result<(Vec<PiecewiseTransferFunction>, usize)> {
    parse_tf_list(&wscg_math::error::read_file(path)?, path)
}

/// [`read_tf_list`] of a file held in memory; `origin` names the file in errors.
pub fn parse_tf_list(
    bytes: &[u8],
    origin: &Path,
) -> Result<(Vec<PiecewiseTransferFunction>, usize)> {
    let bad = |m: String| Error::format(origin, m);
    let json: serde_json::Value =
        serde_json::from_slice(bytes).map_err(|e| bad(format!("not JSON: {e}")))?;
    let canonical = json
        .get("canonical")
        .map_or(Some(0), |c| c.as_u64())
        .and_then(|c| usize::try_from(c).ok())
        .ok_or_else(|| bad("\"canonical\" must be an index".into()))?;
    let tfs = json
        .get("tfs")
        .and_then(|t| t.as_array())
        .ok_or_else(|| bad("needs a \"tfs\" list".into()))?;
    let tfs = tfs
        .iter()
        .enumerate()
        .map(|(k, t)| {
            let rows = t
                .as_array()
                .ok_or_else(|| bad(format!("transfer function {k} is not a list")))?;
            let pts = rows
                .iter()
                .map(|r| {
                    let v: Vec<f32> = r
                        .as_array()
                        .map(|a| {
                            a.iter()
                                .filter_map(|x| x.as_f64())
                                .map(|x| x as f32)
                                .collect()
                        })
                        .unwrap_or_default();
                    match v.as_slice() {
                        [d, r, g, b, a] => Ok((*d, [*r, *g, *b, *a])),
                        _ => Err(bad(format!(
                            "transfer function {k}: each point is [density, r, g, b, a]"
                        ))),
                    }
                })
                .collect::<Result<Vec<_>>>()?;
            PiecewiseTransferFunction::new(pts)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok((tfs, canonical))
}

/// A piecewise-linear transfer function: density (0..=255) to RGBA, opacity per voxel length.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseTransferFunction {
    points: Vec<(f32, [f32; 4])>,
}

impl PiecewiseTransferFunction {
    /// A transfer function from control points `(density, [r, g, b, a])`, constant beyond the
    /// first and last point.
    ///
    /// Errors: fewer than 2 points, densities not strictly increasing or outside `[0, 255]`,
    /// colour or opacity outside `[0, 1]`, non-finite values.
    pub fn new(points: Vec<(f32, [f32; 4])>) -> Result<Self> {
        if points.len() < 2 {
            return Err(Error::invalid(
                "transfer function",
                format!("needs at least 2 control points, got {}", points.len()),
            ));
        }
        for (k, (d, c)) in points.iter().enumerate() {
            if !(d.is_finite() && (0.0..=255.0).contains(d)) {
                return Err(Error::invalid(
                    "transfer function",
                    format!("control point {k}: density {d} outside [0, 255]"),
                ));
            }
            if let Some(v) = c.iter().find(|v| !(0.0..=1.0).contains(*v)) {
                return Err(Error::invalid(
                    "transfer function",
                    format!("control point {k}: colour/opacity {v} outside [0, 1]"),
                ));
            }
        }
        if let Some(w) = points.windows(2).position(|w| w[1].0 <= w[0].0) {
            return Err(Error::invalid(
                "transfer function",
                format!(
                    "densities must increase: point {} ({}) after {}",
                    w + 1,
                    points[w + 1].0,
                    points[w].0
                ),
            ));
        }
        Ok(Self { points })
    }

    /// The control points.
    pub fn points(&self) -> &[(f32, [f32; 4])] {
        &self.points
    }

    /// RGBA at density `d` (linear between control points, constant outside).
    pub fn eval(&self, d: f32) -> [f32; 4] {
        let p = &self.points;
        if d <= p[0].0 {
            return p[0].1;
        }
        if d >= p[p.len() - 1].0 {
            return p[p.len() - 1].1;
        }
        let k = p.partition_point(|q| q.0 <= d) - 1;
        let (d0, c0) = p[k];
        let (d1, c1) = p[k + 1];
        let t = (d - d0) / (d1 - d0);
        std::array::from_fn(|c| c0[c] + t * (c1[c] - c0[c]))
    }

    /// The largest opacity on the closed interval `[lo, hi]` (exact: the function is linear
    /// between control points).
    pub fn max_opacity(&self, lo: f32, hi: f32) -> f32 {
        self.points
            .iter()
            .filter(|(d, _)| *d > lo && *d < hi)
            .map(|(_, c)| c[3])
            .fold(self.eval(lo)[3].max(self.eval(hi)[3]), f32::max)
    }

    /// Whether the opacity is zero on the closed interval `[lo, hi]` (the function is linear
    /// between control points, so checking the ends and the points inside suffices).
    pub fn transparent_on(&self, lo: f32, hi: f32) -> bool {
        self.eval(lo)[3] == 0.0
            && self.eval(hi)[3] == 0.0
            && self
                .points
                .iter()
                .filter(|(d, _)| *d > lo && *d < hi)
                .all(|(_, c)| c[3] == 0.0)
    }
}

/// Most materials the 6-bit field of the voxel code holds.
pub const MAX_MATERIALS: usize = 63;

/// The materials of a set of transfer functions.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialTable {
    /// Density interval `[lo, hi)` of material `m` at index `m - 1`.
    pub intervals: Vec<(f32, f32)>,
    /// Material of every density 0..=255 (0: null).
    pub lut: [u8; 256],
}

impl MaterialTable {
    /// The materials induced by `tfs`.
    ///
    /// Errors: no transfer function, more than 63 materials.
    pub fn from_tfs(tfs: &[PiecewiseTransferFunction]) -> Result<Self> {
        if tfs.is_empty() {
            return Err(Error::Empty("transfer functions"));
        }
        let mut cuts: Vec<f32> = tfs
            .iter()
            .flat_map(|t| t.points.iter().map(|p| p.0))
            .chain([0.0, 256.0])
            .collect();
        cuts.sort_by(f32::total_cmp);
        cuts.dedup();
        let mut intervals = Vec::new();
        let mut lut = [0u8; 256];
        for w in cuts.windows(2) {
            let (lo, hi) = (w[0], w[1]);
            if tfs.iter().all(|t| t.transparent_on(lo, hi)) {
                continue;
            }
            intervals.push((lo, hi));
            if intervals.len() > MAX_MATERIALS {
                return Err(Error::invalid(
                    "transfer functions",
                    format!("induce more than {MAX_MATERIALS} materials"),
                ));
            }
            let id = intervals.len() as u8;
            for (d, m) in lut.iter_mut().enumerate() {
                let d = d as f32;
                if d >= lo && d < hi {
                    *m = id;
                }
            }
        }
        Ok(Self { intervals, lut })
    }

    /// Material of density `d`.
    #[inline]
    pub fn material(&self, d: u8) -> u8 {
        self.lut[d as usize]
    }

    /// The density a client uses to colour material `m` (the interval's midpoint, clamped to
    /// 255); `None` for the null material or an unknown id.
    pub fn representative(&self, m: u8) -> Option<f32> {
        let (lo, hi) = *self.intervals.get((m as usize).checked_sub(1)?)?;
        Some((0.5 * (lo + hi)).min(255.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(lo: f32, hi: f32, top: f32) -> PiecewiseTransferFunction {
        PiecewiseTransferFunction::new(vec![(lo, [1.0, 1.0, 1.0, 0.0]), (hi, [1.0, 1.0, 1.0, top])])
            .unwrap()
    }

    #[test]
    fn evaluation_is_piecewise_linear_and_clamped() {
        let t = ramp(100.0, 200.0, 0.8);
        assert_eq!(t.eval(50.0)[3], 0.0);
        assert!((t.eval(150.0)[3] - 0.4).abs() < 1e-6);
        assert_eq!(t.eval(255.0)[3], 0.8);
        assert!(t.transparent_on(0.0, 100.0));
        assert!(!t.transparent_on(100.0, 200.0));
    }

    #[test]
    fn materials_follow_the_segments() {
        let bone = ramp(180.0, 255.0, 0.8);
        let soft = PiecewiseTransferFunction::new(vec![
            (30.0, [1.0, 0.5, 0.5, 0.0]),
            (60.0, [1.0, 0.5, 0.5, 0.05]),
            (110.0, [1.0, 0.5, 0.5, 0.05]),
            (120.0, [1.0, 0.5, 0.5, 0.0]),
        ])
        .unwrap();
        let m = MaterialTable::from_tfs(&[soft, bone]).unwrap();
        // Cuts 0, 30, 60, 110, 120, 180, 255, 256: null [0, 30), [120, 180).
        assert_eq!(
            m.intervals,
            vec![
                (30.0, 60.0),
                (60.0, 110.0),
                (110.0, 120.0),
                (180.0, 255.0),
                (255.0, 256.0)
            ]
        );
        assert_eq!(m.material(10), 0);
        assert_eq!(m.material(30), 1);
        assert_eq!(m.material(119), 3);
        assert_eq!(m.material(150), 0);
        assert_eq!(m.material(200), 4);
        assert_eq!(m.material(255), 5);
        assert_eq!(m.representative(4), Some(217.5));
        assert_eq!(m.representative(0), None);
    }

    #[test]
    fn bad_transfer_functions_are_rejected() {
        let p = |d: f32, a: f32| (d, [0.5, 0.5, 0.5, a]);
        assert!(PiecewiseTransferFunction::new(vec![p(0.0, 0.0)]).is_err());
        assert!(PiecewiseTransferFunction::new(vec![p(10.0, 0.0), p(5.0, 0.5)]).is_err());
        assert!(PiecewiseTransferFunction::new(vec![p(10.0, 0.0), p(10.0, 0.5)]).is_err());
        assert!(PiecewiseTransferFunction::new(vec![p(0.0, 0.0), p(300.0, 0.5)]).is_err());
        assert!(PiecewiseTransferFunction::new(vec![p(0.0, 0.0), p(10.0, 1.5)]).is_err());
        assert!(PiecewiseTransferFunction::new(vec![p(0.0, f32::NAN), p(10.0, 0.5)]).is_err());
        assert!(MaterialTable::from_tfs(&[]).is_err());
        // 64 opaque segments: one too many.
        let many: Vec<_> = (0..=64).map(|k| p(k as f32 * 3.0, 1.0)).collect();
        assert!(MaterialTable::from_tfs(&[PiecewiseTransferFunction::new(many).unwrap()]).is_err());
    }

    #[test]
    fn tf_list_files_read_their_functions_and_canonical_index() {
        let text = br#"{"tfs": [[[0, 0, 0, 0, 0], [255, 1, 1, 1, 1]], [[10, 0, 0, 0, 0], [20, 1, 0.5, 0, 0.25]]], "canonical": 1}"#;
        let (tfs, canonical) = parse_tf_list(text, Path::new("tf.json")).unwrap();
        assert_eq!(canonical, 1);
        assert_eq!(tfs.len(), 2);
        assert_eq!(
            tfs[1],
            PiecewiseTransferFunction::new(vec![(10.0, [0.0; 4]), (20.0, [1.0, 0.5, 0.0, 0.25])])
                .unwrap()
        );
        let one = br#"{"tfs": [[[0, 0, 0, 0, 0], [255, 1, 1, 1, 1]]]}"#;
        assert_eq!(parse_tf_list(one, Path::new("tf.json")).unwrap().1, 0);
        for bad in [
            &b"not json"[..],
            br#"{"canonical": 0}"#,
            br#"{"tfs": [[[0, 0, 0, 0]]]}"#,
            br#"{"tfs": [], "canonical": -1}"#,
        ] {
            let err = parse_tf_list(bad, Path::new("tf.json")).unwrap_err();
            assert!(err.to_string().contains("tf.json"), "{err}");
        }
    }
}
