//! Training folders of the walk-and-reach task (paper 16, section 3: per trial, a normal
//! step, a shortened step and the reach): `angles.npy` `[R, 3, I, N]` (joint angles, one
//! time-normalised block per trial and action), `root.npy` `[R, 3, N]` (pelvis travel,
//! optional) and `steps.csv` (`trial,action,step_length,duration`, one row per trial and
//! action, actions numbered 1 to 3).

use std::path::Path;

use serde::Deserialize;
use wscg_math::io::csv::{self, table};
use wscg_math::{npy, Error, Result};

use crate::dataset::{Dataset, TrialAction};

/// The header of `steps.csv`.
pub const STEPS_HEADER: [&str; 4] = ["trial", "action", "step_length", "duration"];

/// One row of `steps.csv`, read by position.
#[derive(Deserialize)]
struct StepRow {
    trial: usize,
    action: usize,
    step_length: f64,
    duration: f64,
}

/// The step parameters of `trials` trials, `(step_length, duration)` per trial and action,
/// from a `steps.csv` held in memory: a header line, then rows
/// `trial,action,step_length,duration` (trial from 0, action 1 to 3) in any order; `origin`
/// names the file in errors.
///
/// Errors ([`Error::Format`] naming `origin` and the line): a row without four fields or
/// with a field that is not a number; a trial or action out of range; a trial and action
/// listed twice or never.
pub fn parse_steps(bytes: &[u8], origin: &Path, trials: usize) -> Result<Vec<[(f64, f64); 3]>> {
    let (_, rows) = table(bytes, origin, b',')?;
    if rows.len() > 3 * trials {
        return Err(Error::format(
            origin,
            format!(
                "line {}: more rows than the {trials} trials x 3 actions",
                rows[3 * trials].line
            ),
        ));
    }
    let mut params = vec![[(f64::NAN, f64::NAN); 3]; trials];
    for row in &rows {
        if row.fields.len() != STEPS_HEADER.len() {
            return Err(Error::format(
                origin,
                format!(
                    "line {}: {} fields, expected trial,action,step_length,duration",
                    row.line,
                    row.fields.len()
                ),
            ));
        }
        let r: StepRow = row.deserialize(None, origin)?;
        if r.trial >= trials || !(1..=3).contains(&r.action) {
            return Err(Error::format(
                origin,
                format!(
                    "line {}: trial {} / action {} out of range ({trials} trials, actions 1 to 3)",
                    row.line, r.trial, r.action
                ),
            ));
        }
        let slot = &mut params[r.trial][r.action - 1];
        if !slot.0.is_nan() {
            return Err(Error::format(
                origin,
                format!(
                    "line {}: trial {} action {} is listed twice",
                    row.line, r.trial, r.action
                ),
            ));
        }
        *slot = (r.step_length, r.duration);
    }
    for (t, p) in params.iter().enumerate() {
        if let Some(k) = p.iter().position(|v| v.0.is_nan()) {
            return Err(Error::format(
                origin,
                format!("no row for trial {t} action {}", k + 1),
            ));
        }
    }
    Ok(params)
}

/// Reads a training folder written by [`write_dataset`] (or by hand, see the module
/// documentation); `root.npy` may be missing (the actions then have no root curves).
///
/// Errors: a missing or malformed file (named, with the line for `steps.csv`); arrays of
/// the wrong shape; everything [`Dataset::validate`] checks.
pub fn read_dataset(dir: impl AsRef<Path>) -> Result<Dataset> {
    let dir = dir.as_ref();
    let angles_path = dir.join("angles.npy");
    let a = npy::read::<f64>(&angles_path)?;
    if a.shape.len() != 4 || a.shape[1] != 3 {
        return Err(Error::format(
            &angles_path,
            format!("expected shape [R, 3, I, N], got {:?}", a.shape),
        ));
    }
    let (r, i, n) = (a.shape[0], a.shape[2], a.shape[3]);
    let root_path = dir.join("root.npy");
    let root = match npy::read::<f64>(&root_path) {
        Ok(v) if v.shape == [r, 3, n] => Some(v.data),
        Ok(v) => {
            return Err(Error::format(
                &root_path,
                format!("expected shape [{r}, 3, {n}], got {:?}", v.shape),
            ))
        }
        Err(e) if e.is_io() && !root_path.exists() => None,
        Err(e) => return Err(e),
    };
    let steps_path = dir.join("steps.csv");
    let params = parse_steps(&wscg_math::error::read_file(&steps_path)?, &steps_path, r)?;
    let trials = params
        .iter()
        .enumerate()
        .map(|(t, p)| {
            std::array::from_fn(|k| {
                let o = (t * 3 + k) * i * n;
                TrialAction {
                    angles: a.data[o..o + i * n].to_vec(),
                    step_length: p[k].0,
                    duration: p[k].1,
                    root: root.as_ref().map_or(Vec::new(), |v| {
                        v[(t * 3 + k) * n..(t * 3 + k + 1) * n].to_vec()
                    }),
                }
            })
        })
        .collect();
    let ds = Dataset {
        n_channels: i,
        n_samples: n,
        trials,
        distances: Vec::new(),
    };
    ds.validate()?;
    Ok(ds)
}

/// Writes a training folder (created if needed) that [`read_dataset`] reads back; each file
/// is written atomically, `root.npy` only when every action has its root curve. The trials'
/// `distances` are not stored.
///
/// Errors: a dataset that [`Dataset::validate`] refuses; I/O failures.
pub fn write_dataset(dir: impl AsRef<Path>, data: &Dataset) -> Result<()> {
    data.validate()?;
    let dir = dir.as_ref();
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let (r, i, n) = (data.trials.len(), data.n_channels, data.n_samples);
    let actions = || data.trials.iter().flat_map(|t| t.iter());
    let angles: Vec<f64> = actions().flat_map(|a| a.angles.iter().copied()).collect();
    npy::write_f64(dir.join("angles.npy"), &[r, 3, i, n], &angles)?;
    if actions().all(|a| a.root.len() == n) {
        let root: Vec<f64> = actions().flat_map(|a| a.root.iter().copied()).collect();
        npy::write_f64(dir.join("root.npy"), &[r, 3, n], &root)?;
    }
    let rows = data.trials.iter().enumerate().flat_map(|(k, t)| {
        t.iter().enumerate().map(move |(a, act)| {
            [
                k.to_string(),
                (a + 1).to_string(),
                act.step_length.to_string(),
                act.duration.to_string(),
            ]
        })
    });
    csv::write(&dir.join("steps.csv"), &STEPS_HEADER, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn action(v: f64, root: bool) -> TrialAction {
        TrialAction {
            angles: vec![v, v + 0.5, -v, 0.25, 1.0, 2.0],
            step_length: 0.6 + v,
            duration: 1.0 + v,
            root: if root {
                vec![0.0, 0.1, 0.3]
            } else {
                Vec::new()
            },
        }
    }

    fn dataset(root: bool) -> Dataset {
        Dataset {
            n_channels: 2,
            n_samples: 3,
            trials: (0..2)
                .map(|t| std::array::from_fn(|a| action((t * 3 + a) as f64 * 0.1, root)))
                .collect(),
            distances: Vec::new(),
        }
    }

    #[test]
    fn a_dataset_round_trips_with_and_without_root_curves() {
        for root in [true, false] {
            let dir = tempfile::tempdir().unwrap();
            let ds = dataset(root);
            write_dataset(dir.path(), &ds).unwrap();
            assert_eq!(dir.path().join("root.npy").exists(), root);
            assert_eq!(read_dataset(dir.path()).unwrap(), ds);
        }
    }

    #[test]
    fn steps_errors_name_the_file_and_the_line() {
        let o = Path::new("steps.csv");
        let err = |t: &[u8]| parse_steps(t, o, 1).unwrap_err().to_string();
        let good = b"trial,action,step_length,duration\n0,1,0.6,1\n0,2,0.5,1\n0,3,0.4,1\n";
        assert_eq!(parse_steps(good, o, 1).unwrap()[0][2], (0.4, 1.0));
        let e = err(b"h\n0,1,0.6,1\n0,2,0.5\n0,3,0.4,1\n");
        assert!(e.contains("steps.csv") && e.contains("line 3"), "{e}");
        let e = err(b"h\n0,1,0.6,1\n0,2,x,1\n0,3,0.4,1\n");
        assert!(e.contains("line 3"), "{e}");
        let e = err(b"h\n0,1,0.6,1\n0,4,0.5,1\n0,3,0.4,1\n");
        assert!(e.contains("line 3") && e.contains("out of range"), "{e}");
        let e = err(b"h\n0,1,0.6,1\n0,1,0.5,1\n0,3,0.4,1\n");
        assert!(e.contains("line 3") && e.contains("twice"), "{e}");
        let e = err(b"h\n0,1,0.6,1\n0,3,0.4,1\n");
        assert!(e.contains("no row for trial 0 action 2"), "{e}");
        let e = err(b"h\n0,1,0.6,1\n0,2,0.5,1\n0,3,0.4,1\n1,1,1,1\n");
        assert!(e.contains("line 5"), "{e}");
    }

    #[test]
    fn folder_errors_name_the_file() {
        let dir = tempfile::tempdir().unwrap();
        write_dataset(dir.path(), &dataset(true)).unwrap();
        std::fs::write(dir.path().join("steps.csv"), "trial\n0,1,a,b\n").unwrap();
        let e = read_dataset(dir.path()).unwrap_err().to_string();
        assert!(e.contains("steps.csv") && e.contains("line 2"), "{e}");
        std::fs::remove_file(dir.path().join("angles.npy")).unwrap();
        let e = read_dataset(dir.path()).unwrap_err();
        assert!(e.is_io() && e.to_string().contains("angles.npy"), "{e}");
    }
}
