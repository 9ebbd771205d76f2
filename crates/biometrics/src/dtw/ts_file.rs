//! Reader of the `.ts` time-series format of the UCR/UEA archive (as shipped, for example,
//! inside the sktime wheel): `#` comments, `@` header tags, then after `@data` one case per
//! line, dimensions separated by `:`, values by `,`, the class label last.

use std::path::Path;

use wscg_math::{Error, Result};

/// Largest file [`read_ts`] accepts (512 MiB).
pub const MAX_TS_BYTES: u64 = 512 << 20;

/// A labelled time-series set read from a `.ts` file.
#[derive(Clone, Debug, PartialEq)]
pub struct TsData {
    /// `@problemName`, or empty.
    pub problem: String,
    /// `series[case][dimension]`: the values of one dimension of one case (lengths may differ
    /// between cases when `@equalLength false`). A missing value `?` reads as NaN.
    pub series: Vec<Vec<Vec<f64>>>,
    /// Class label of each case, as written in the file.
    pub labels: Vec<String>,
    /// The labels listed by `@classLabel true ...`, in file order (empty if absent).
    pub class_labels: Vec<String>,
}

impl TsData {
    /// Each case's label as its index in [`Self::class_labels`] (or, when the header lists
    /// none, in order of first appearance).
    pub fn label_indices(&self) -> Vec<u32> {
        let mut classes = self.class_labels.clone();
        for l in &self.labels {
            if !classes.contains(l) {
                classes.push(l.clone());
            }
        }
        self.labels
            .iter()
            .map(|l| classes.iter().position(|c| c == l).unwrap_or(0) as u32)
            .collect()
    }
}

/// Reads a `.ts` file.
///
/// Errors: [`Error::Io`] when unreadable, [`Error::Format`] for a malformed file (no `@data`,
/// a bad number, cases with different dimension counts), [`Error::UnsupportedFormat`] for
/// `@timeStamps true`, [`Error::LimitExceeded`] above [`MAX_TS_BYTES`].
pub fn read_ts(path: impl AsRef<Path>) -> Result<TsData> {
    let path = path.as_ref();
    let text = wscg_math::error::read_text_at_most(path, MAX_TS_BYTES, ".ts files")?;
    parse_ts(&text).map_err(|reason| match reason {
        Error::InvalidArgument { reason, .. } => Error::Format {
            path: path.to_path_buf(),
            reason,
        },
        other => other,
    })
}

fn bad(reason: String) -> Error {
    Error::invalid("text", reason)
}

/// Parses the text of a `.ts` file (see [`read_ts`]); format problems are reported as
/// [`Error::InvalidArgument`] naming `text`.
pub fn parse_ts(text: &str) -> Result<TsData> {
    let mut out = TsData {
        problem: String::new(),
        series: Vec::new(),
        labels: Vec::new(),
        class_labels: Vec::new(),
    };
    let mut in_data = false;
    let mut has_labels = true;
    for (ln, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if !in_data {
            if !line.starts_with('@') {
                return Err(bad(format!(
                    "line {}: expected a header tag or @data",
                    ln + 1
                )));
            }
            let mut words = line.split_whitespace();
            let tag = words.next().unwrap_or("").to_ascii_lowercase();
            match tag.as_str() {
                "@data" => in_data = true,
                "@problemname" => out.problem = words.collect::<Vec<_>>().join(" "),
                "@timestamps" if words.next().is_some_and(|w| w.eq_ignore_ascii_case("true")) => {
                    return Err(Error::UnsupportedFormat(
                        ".ts files with @timeStamps true".into(),
                    ));
                }
                "@classlabel" => {
                    has_labels = words.next().is_some_and(|w| w.eq_ignore_ascii_case("true"));
                    out.class_labels = words.map(str::to_string).collect();
                }
                "@targetlabel" => has_labels = true,
                _ => {}
            }
            continue;
        }
        let mut fields: Vec<&str> = line.split(':').collect();
        if has_labels {
            if fields.len() < 2 {
                return Err(bad(format!(
                    "line {}: a case needs values and a label",
                    ln + 1
                )));
            }
            out.labels
                .push(fields.pop().unwrap_or("").trim().to_string());
        }
        let mut case = Vec::with_capacity(fields.len());
        for f in fields {
            let mut dim = Vec::new();
            for v in f.split(',').map(str::trim).filter(|v| !v.is_empty()) {
                let x = if v == "?" {
                    f64::NAN
                } else {
                    v.parse::<f64>()
                        .map_err(|_| bad(format!("line {}: `{v}` is not a number", ln + 1)))?
                };
                dim.push(x);
            }
            if dim.is_empty() {
                return Err(bad(format!("line {}: an empty dimension", ln + 1)));
            }
            case.push(dim);
        }
        if let Some(first) = out.series.first() {
            if first.len() != case.len() {
                return Err(bad(format!(
                    "line {}: {} dimensions, the first case has {}",
                    ln + 1,
                    case.len(),
                    first.len()
                )));
            }
        }
        out.series.push(case);
    }
    if !in_data {
        return Err(bad("no @data section".into()));
    }
    if out.series.is_empty() {
        return Err(bad("no cases after @data".into()));
    }
    Ok(out)
}
