//! CSV tables through the `csv` crate: the records of a file with their line numbers, and
//! rows deserialized with serde, every error naming the file and the line.
//!
//! Every CSV reader of the workspace (gyroscope logs, skeleton streams, design-of-experiments
//! runs and scores, motion step tables) goes through [`records`] and [`deserialize`]: fields
//! are trimmed, lines whose first non-blank character is `#` are comments and blank lines
//! are skipped; a row may
//! have any number of fields (the readers check the count, so that they can say which line
//! is short).

use std::path::Path;

pub use ::csv::StringRecord;

use crate::{Error, Result};

/// One record of a table and the line it starts on (1-based).
#[derive(Clone, Debug)]
pub struct Row {
    /// Line number of the record's first byte (1-based).
    pub line: u64,
    /// The fields, trimmed.
    pub fields: StringRecord,
}

impl Row {
    /// Field `k`, or a format error naming the file and the line when the row is shorter.
    pub fn get(&self, k: usize, origin: &Path) -> Result<&str> {
        self.fields.get(k).ok_or_else(|| {
            Error::format(
                origin,
                format!(
                    "line {}: {} fields, expected at least {}",
                    self.line,
                    self.fields.len(),
                    k + 1
                ),
            )
        })
    }

    /// The fields split further at any of `separators` (for the formats that also accept
    /// semicolons, tabs or spaces between values), each piece trimmed.
    pub fn split_fields<'a>(&'a self, separators: &'a [char]) -> impl Iterator<Item = &'a str> {
        self.fields
            .iter()
            .flat_map(move |f| f.split(separators).map(str::trim))
    }

    /// The row deserialized as `T` (a struct with named fields reads its columns by name from
    /// `header`, or in order without one; a `Vec` or tuple reads them in order); errors name
    /// the file, the line and the field.
    pub fn deserialize<T: serde::de::DeserializeOwned>(
        &self,
        header: Option<&StringRecord>,
        origin: &Path,
    ) -> Result<T> {
        self.fields
            .deserialize(header)
            .map_err(|e| Error::format(origin, format!("line {}: {e}", self.line)))
    }
}

/// The records of `bytes`, split at `delimiter`; `origin` names the file in errors.
///
/// Errors: [`Error::Format`] naming the file and the line for text that is not UTF-8 or a
/// quoted field that is never closed.
pub fn records(bytes: &[u8], origin: &Path, delimiter: u8) -> Result<Vec<Row>> {
    // Comment lines are blanked here rather than by the reader's `comment` option, so that
    // they keep their place in the line numbers.
    let text = without_comments(bytes);
    let mut reader = ::csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .has_headers(false)
        .flexible(true)
        .trim(::csv::Trim::All)
        .from_reader(&*text);
    let mut rows = Vec::new();
    let mut record = StringRecord::new();
    // The line of a record is counted here from its byte offset: the reader's own line
    // count misses the empty lines before the first record. The offset may point at empty
    // lines the reader skipped, so those are stepped over first.
    let (mut counted, mut line) = (0usize, 1u64);
    let mut line_at = |byte: usize| {
        let start = byte
            + text[byte.min(text.len())..]
                .iter()
                .take_while(|&&b| b == b'\n' || b == b'\r')
                .count();
        let start = start.min(text.len());
        if start >= counted {
            line += text[counted..start].iter().filter(|&&b| b == b'\n').count() as u64;
            counted = start;
        }
        line
    };
    loop {
        match reader.read_record(&mut record) {
            Ok(false) => break,
            Ok(true) => {
                let line = line_at(record.position().map_or(0, |p| p.byte() as usize));
                if record.iter().all(str::is_empty) {
                    continue;
                }
                rows.push(Row {
                    line,
                    fields: record.clone(),
                });
            }
            Err(e) => {
                let line = e.position().map_or(0, |p| line_at(p.byte() as usize));
                let reason = match e.kind() {
                    ::csv::ErrorKind::Utf8 { err, .. } => {
                        format!("not UTF-8 text (field {})", err.field() + 1)
                    }
                    _ => e.to_string(),
                };
                return Err(Error::format(origin, format!("line {line}: {reason}")));
            }
        }
    }
    Ok(rows)
}

/// `bytes` with every line whose first non-blank byte is `#` emptied (its end of line kept).
fn without_comments(bytes: &[u8]) -> std::borrow::Cow<'_, [u8]> {
    let is_comment = |l: &[u8]| l.trim_ascii_start().first() == Some(&b'#');
    if !bytes.split(|&b| b == b'\n').any(is_comment) {
        return bytes.into();
    }
    let mut out = Vec::with_capacity(bytes.len());
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if i > 0 {
            out.push(b'\n');
        }
        if !is_comment(line) {
            out.extend_from_slice(line);
        }
    }
    out.into()
}

/// [`records`] with the first row taken as the header: `(header, rows)`, the header's names
/// lowercased so that columns match their names in any case.
///
/// Errors: those of [`records`]; an empty table.
pub fn table(bytes: &[u8], origin: &Path, delimiter: u8) -> Result<(StringRecord, Vec<Row>)> {
    let mut rows = records(bytes, origin, delimiter)?.into_iter();
    let header = rows
        .next()
        .ok_or_else(|| Error::format(origin, "empty file: no header line"))?;
    let header: StringRecord = header.fields.iter().map(str::to_ascii_lowercase).collect();
    Ok((header, rows.collect()))
}

/// Writes a table (a header, then the rows) atomically through [`super::atomic`], quoting
/// the fields that need it, so that [`table`] reads it back.
///
/// Errors: I/O failures, naming the file.
pub fn write<I, R, F>(path: &Path, header: &[&str], rows: I) -> Result<()>
where
    I: IntoIterator<Item = R>,
    R: IntoIterator<Item = F>,
    F: AsRef<[u8]>,
{
    let fail = |e: ::csv::Error| Error::format(path, format!("cannot write CSV: {e}"));
    let mut w = ::csv::WriterBuilder::new()
        .flexible(true)
        .from_writer(Vec::new());
    w.write_record(header).map_err(fail)?;
    for row in rows {
        w.write_record(row).map_err(fail)?;
    }
    let bytes = w.into_inner().map_err(|e| fail(e.into_error().into()))?;
    super::atomic::write(path, bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_are_trimmed_numbered_and_skip_comments_and_blank_lines() {
        let text = b"# comment\na, b ,c\n\n   \n1,2\n\"x,y\",3\n";
        let rows = records(text, Path::new("t.csv"), b',').unwrap();
        let lines: Vec<u64> = rows.iter().map(|r| r.line).collect();
        assert_eq!(lines, [2, 5, 6]);
        assert_eq!(rows[0].fields, vec!["a", "b", "c"]);
        assert_eq!(rows[1].fields.len(), 2);
        assert_eq!(&rows[2].fields[0], "x,y");
        let split: Vec<&str> = rows[2].split_fields(&[',', ';']).collect();
        assert_eq!(split, ["x", "y", "3"]);
        let e = rows[1].get(2, Path::new("t.csv")).unwrap_err().to_string();
        assert!(e.contains("t.csv") && e.contains("line 5"), "{e}");
    }

    #[test]
    fn invalid_utf8_names_the_line() {
        let e = records(b"a,b\n1,\xff\n", Path::new("bad.csv"), b',')
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.csv") && e.contains("line 2"), "{e}");
    }

    #[test]
    fn rows_deserialize_by_name_with_a_lowercased_header() {
        #[derive(Debug, serde::Deserialize)]
        struct R {
            a: u32,
            b: f64,
        }
        let (h, rows) = table(b"B,A\n2.5,7\n2.5,x\n", Path::new("t.csv"), b',').unwrap();
        let r: R = rows[0].deserialize(Some(&h), Path::new("t.csv")).unwrap();
        assert_eq!((r.a, r.b), (7, 2.5));
        let e = rows[1]
            .deserialize::<R>(Some(&h), Path::new("t.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 3"), "{e}");
        assert!(table(b"\n# only a comment\n", Path::new("e.csv"), b',').is_err());
    }
}
