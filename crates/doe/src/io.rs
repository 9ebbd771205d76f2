//! The study's files (paper 07, section 4): the long-format score table of a perceptual study
//! (`subject,condition,stimulus,score`, one row per observation) and the numeric tables of
//! runs (factor columns in coded units, then the response) and of designs (factor columns
//! only), all CSV with a header line, read through [`wscg_math::io::csv`].
//!
//! Every reader has a byte-level entry (`parse_*`, `origin` naming the file in errors) and a
//! path function (`read_*`); errors name the file and the line. The writers are atomic.

use std::path::Path;

use nalgebra::DMatrix;
use serde::Deserialize;
use wscg_math::io::csv::{self, table};
use wscg_math::{Error, Result};

/// The scores of a perceptual study: every subject scored every stimulus in every condition
/// once (paper 07: 26 observers, 2 conditions, 13 stimuli).
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    /// Subject names, sorted.
    pub subjects: Vec<String>,
    /// Condition names, sorted.
    pub conditions: Vec<String>,
    /// Number of stimuli (numbered from 0).
    pub stimuli: usize,
    /// `scores[(s * conditions + c) * stimuli + k]`: the `(subjects, conditions, stimuli)`
    /// array of [`crate::rm_anova`], row-major.
    pub scores: Vec<f64>,
}

impl Study {
    /// The score of subject `s`, condition `c` and stimulus `k` (indices).
    pub fn score(&self, s: usize, c: usize, k: usize) -> f64 {
        self.scores[(s * self.conditions.len() + c) * self.stimuli + k]
    }
}

/// One row of a score table; the columns are found by name (in any case and order; other
/// columns are ignored).
#[derive(Deserialize)]
struct ScoreRow {
    subject: String,
    condition: String,
    stimulus: usize,
    score: f64,
}

/// Reads a study's score table (see [`parse_study`]).
pub fn read_study(path: impl AsRef<Path>) -> Result<Study> {
    let path = path.as_ref();
    parse_study(&wscg_math::error::read_file(path)?, path)
}

/// Parses a score table held in memory: a header naming the columns `subject`,
/// `condition`, `stimulus` (an index from 0) and `score` (finite), then one row per
/// observation in any order; `origin` names the file in errors.
///
/// Errors ([`Error::Format`] naming `origin`, and the line where there is one): a missing
/// column; a row whose stimulus is not an index or whose score is not a finite number; a
/// cell scored twice; a missing cell (named); no rows.
pub fn parse_study(bytes: &[u8], origin: &Path) -> Result<Study> {
    let (header, rows) = table(bytes, origin, b',')?;
    for name in ["subject", "condition", "stimulus", "score"] {
        if !header.iter().any(|c| c == name) {
            return Err(Error::format(
                origin,
                format!("line 1: the header has no `{name}` column"),
            ));
        }
    }
    let mut obs = Vec::with_capacity(rows.len());
    for row in &rows {
        let r: ScoreRow = row.deserialize(Some(&header), origin)?;
        if !r.score.is_finite() {
            return Err(Error::format(
                origin,
                format!("line {}: score is not finite", row.line),
            ));
        }
        obs.push((row.line, r));
    }
    let names = |f: fn(&ScoreRow) -> &String| {
        let mut v: Vec<String> = obs.iter().map(|(_, r)| f(r).clone()).collect();
        v.sort();
        v.dedup();
        v
    };
    let subjects = names(|r| &r.subject);
    let conditions = names(|r| &r.condition);
    let stimuli = obs
        .iter()
        .map(|(_, r)| r.stimulus.saturating_add(1))
        .max()
        .ok_or_else(|| Error::format(origin, "no scores after the header line"))?;
    let (ns, nc) = (subjects.len(), conditions.len());
    // The cell of every observation, sorted: a complete table is 0, 1, ... n - 1 with no
    // repeats, checked before the score array is allocated (a huge stimulus index over a
    // few rows is a missing cell, not an allocation).
    let mut cells: Vec<(u128, usize)> = obs
        .iter()
        .enumerate()
        .map(|(i, (_, r))| {
            let s = subjects.binary_search(&r.subject).unwrap_or_default() as u128;
            let c = conditions.binary_search(&r.condition).unwrap_or_default() as u128;
            (
                (s * nc as u128 + c) * stimuli as u128 + r.stimulus as u128,
                i,
            )
        })
        .collect();
    cells.sort_unstable();
    let name = |cell: u128| {
        let k = cell % stimuli as u128;
        let rest = cell / stimuli as u128;
        format!(
            "subject {}, condition {}, stimulus {k}",
            subjects[(rest / nc as u128) as usize],
            conditions[(rest % nc as u128) as usize]
        )
    };
    for w in cells.windows(2) {
        if w[0].0 == w[1].0 {
            let (line_a, line_b) = (
                obs[w[0].1].0.min(obs[w[1].1].0),
                obs[w[0].1].0.max(obs[w[1].1].0),
            );
            return Err(Error::format(
                origin,
                format!(
                    "line {line_b}: {} is scored twice (also on line {line_a})",
                    name(w[0].0)
                ),
            ));
        }
    }
    let total = ns as u128 * nc as u128 * stimuli as u128;
    if (cells.len() as u128) < total {
        let missing = cells
            .iter()
            .enumerate()
            .find(|(i, (cell, _))| *cell != *i as u128)
            .map_or(cells.len() as u128, |(i, _)| i as u128);
        return Err(Error::format(
            origin,
            format!("missing cell: {}", name(missing)),
        ));
    }
    let mut scores = vec![0.0; cells.len()];
    for (cell, i) in &cells {
        scores[*cell as usize] = obs[*i].1.score;
    }
    Ok(Study {
        subjects,
        conditions,
        stimuli,
        scores,
    })
}

/// Writes a study as a score table that [`read_study`] reads back (atomically).
///
/// Errors: scores that do not fill `subjects x conditions x stimuli`; I/O failures.
pub fn write_study(path: impl AsRef<Path>, study: &Study) -> Result<()> {
    let (ns, nc, nk) = (study.subjects.len(), study.conditions.len(), study.stimuli);
    if study.scores.len() != ns * nc * nk || study.scores.is_empty() {
        return Err(Error::ShapeMismatch(format!(
            "{} scores for {ns} subjects x {nc} conditions x {nk} stimuli",
            study.scores.len()
        )));
    }
    let rows = (0..ns * nc * nk).map(|i| {
        let (s, c, k) = (i / (nc * nk), i / nk % nc, i % nk);
        [
            study.subjects[s].clone(),
            study.conditions[c].clone(),
            k.to_string(),
            study.scores[i].to_string(),
        ]
    });
    csv::write(
        path.as_ref(),
        &["subject", "condition", "stimulus", "score"],
        rows,
    )
}

/// Reads a design: a header line, then one row of factor levels per stimulus (see
/// [`parse_design`]).
pub fn read_design(path: impl AsRef<Path>) -> Result<DMatrix<f64>> {
    let path = path.as_ref();
    parse_design(&wscg_math::error::read_file(path)?, path)
}

/// Parses a numeric table with a header line held in memory as a matrix (one row a line).
///
/// Errors ([`Error::Format`] naming `origin` and the line): a cell that is not a number; rows
/// of different lengths; no rows after the header.
pub fn parse_design(bytes: &[u8], origin: &Path) -> Result<DMatrix<f64>> {
    let (_, rows) = table(bytes, origin, b',')?;
    let mut values: Vec<f64> = Vec::new();
    let mut ncols = 0;
    for row in &rows {
        let r: Vec<f64> = row.deserialize(None, origin)?;
        if ncols == 0 {
            ncols = r.len();
        } else if r.len() != ncols {
            return Err(Error::format(
                origin,
                format!("line {}: {} columns, expected {ncols}", row.line, r.len()),
            ));
        }
        values.extend(r);
    }
    if rows.is_empty() || ncols == 0 {
        return Err(Error::format(origin, "no rows after the header line"));
    }
    Ok(DMatrix::from_row_slice(rows.len(), ncols, &values))
}

/// Reads runs: factor columns then the response (see [`parse_runs`]).
pub fn read_runs(path: impl AsRef<Path>) -> Result<(DMatrix<f64>, Vec<f64>)> {
    let path = path.as_ref();
    parse_runs(&wscg_math::error::read_file(path)?, path)
}

/// Parses a table of runs held in memory: a header line, then per run its factor levels
/// (coded units) and, in the last column, the response; returns `(x, y)` for
/// [`crate::fit_quadratic`].
///
/// Errors: those of [`parse_design`]; fewer than two columns.
pub fn parse_runs(bytes: &[u8], origin: &Path) -> Result<(DMatrix<f64>, Vec<f64>)> {
    let m = parse_design(bytes, origin)?;
    if m.ncols() < 2 {
        return Err(Error::format(
            origin,
            "need factor columns and a response (at least two columns)",
        ));
    }
    let k = m.ncols() - 1;
    Ok((
        m.columns(0, k).into_owned(),
        m.column(k).iter().copied().collect(),
    ))
}

/// Writes runs `(x, y)` with the header `x1,...,xk,y` (atomically); [`read_runs`] reads them
/// back.
///
/// Errors: `y` not one value per row of `x`, no runs or no factors; I/O failures.
pub fn write_runs(path: impl AsRef<Path>, x: &DMatrix<f64>, y: &[f64]) -> Result<()> {
    if x.nrows() != y.len() || y.is_empty() || x.ncols() == 0 {
        return Err(Error::ShapeMismatch(format!(
            "{} x {} factor levels for {} responses",
            x.nrows(),
            x.ncols(),
            y.len()
        )));
    }
    let mut header: Vec<String> = (1..=x.ncols()).map(|i| format!("x{i}")).collect();
    header.push("y".into());
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let rows = x
        .row_iter()
        .zip(y)
        .map(|(r, v)| r.iter().chain([v]).map(f64::to_string).collect::<Vec<_>>());
    csv::write(path.as_ref(), &header, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(bytes: &[u8]) -> String {
        parse_study(bytes, Path::new("scores.csv"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn a_study_reads_in_any_row_and_column_order() {
        let text = b"Score,stimulus,subject,condition\n\
            4,1,bob,stereo\n1,0,ann,mono\n2,1,ann,mono\n3,0,bob,stereo\n\
            5,0,ann,stereo\n6,1,ann,stereo\n7,0,bob,mono\n8,1,bob,mono\n";
        let st = parse_study(text, Path::new("s.csv")).unwrap();
        assert_eq!(st.subjects, ["ann", "bob"]);
        assert_eq!(st.conditions, ["mono", "stereo"]);
        assert_eq!(st.stimuli, 2);
        assert_eq!(st.scores, [1.0, 2.0, 5.0, 6.0, 7.0, 8.0, 3.0, 4.0]);
        assert_eq!(st.score(1, 1, 1), 4.0);
    }

    #[test]
    fn study_errors_name_the_file_the_line_and_the_cell() {
        let e = err(b"subject,condition,score\n");
        assert!(e.contains("scores.csv") && e.contains("`stimulus`"), "{e}");
        let e = err(b"subject,condition,stimulus,score\na,c,x,1\n");
        assert!(e.contains("line 2"), "{e}");
        let e = err(b"subject,condition,stimulus,score\na,c,0,1\na,c,0,inf\n");
        assert!(e.contains("line 3") && e.contains("not finite"), "{e}");
        let e = err(b"subject,condition,stimulus,score\na,c,0,1\n\na,c,0,2\n");
        assert!(e.contains("line 4") && e.contains("scored twice"), "{e}");
        let e = err(b"subject,condition,stimulus,score\na,c,0,1\na,c,2,2\n");
        assert!(
            e.contains("missing cell: subject a, condition c, stimulus 1"),
            "{e}"
        );
        let e = err(b"subject,condition,stimulus,score\na,c,0,1\na,d,1,2\nb,c,1,1\n");
        assert!(
            e.contains("missing cell: subject a, condition c, stimulus 1"),
            "{e}"
        );
        let e = err(b"subject,condition,stimulus,score\n");
        assert!(e.contains("no scores"), "{e}");
        assert!(err(b"").contains("empty file"));
    }

    #[test]
    fn a_huge_stimulus_index_is_a_missing_cell_not_an_allocation() {
        let e = err(b"subject,condition,stimulus,score\na,c,18446744073709551614,1\n");
        assert!(e.contains("missing cell"), "{e}");
        let e = err(b"subject,condition,stimulus,score\na,c,18446744073709551615,1\n");
        assert!(e.contains("missing cell"), "{e}");
    }

    #[test]
    fn runs_and_studies_round_trip_through_the_writers() {
        let dir = tempfile::tempdir().unwrap();
        let x = DMatrix::from_row_slice(3, 2, &[-1.0, 0.5, 1.0, -0.25, 0.0, 1.0 / 3.0]);
        let y = [1.5, -2.0, 0.1];
        let p = dir.path().join("runs.csv");
        write_runs(&p, &x, &y).unwrap();
        assert_eq!(read_runs(&p).unwrap(), (x.clone(), y.to_vec()));
        assert!(write_runs(&p, &x, &y[..2]).is_err());
        let st = Study {
            subjects: vec!["a".into(), "b, c".into()],
            conditions: vec!["mono".into()],
            stimuli: 2,
            scores: vec![1.0, 2.5, 3.0, 0.1],
        };
        let p = dir.path().join("scores.csv");
        write_study(&p, &st).unwrap();
        assert_eq!(read_study(&p).unwrap(), st);
    }

    #[test]
    fn design_errors_name_the_line() {
        let o = Path::new("design.csv");
        let e = parse_design(b"a,b\n1,2\n3\n", o).unwrap_err().to_string();
        assert!(e.contains("design.csv") && e.contains("line 3"), "{e}");
        let e = parse_design(b"a,b\n1,2\n3,x\n", o).unwrap_err().to_string();
        assert!(e.contains("line 3"), "{e}");
        assert!(parse_design(b"a,b\n", o).is_err());
        let e = parse_runs(b"y\n1\n2\n", o).unwrap_err().to_string();
        assert!(e.contains("two columns"), "{e}");
        let m = parse_design(b"a, b\n 1 ,2\n\n3,4\n", o).unwrap();
        assert_eq!(m, DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 3.0, 4.0]));
    }
}
