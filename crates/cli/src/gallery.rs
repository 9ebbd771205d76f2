//! The gallery: runs demos and writes `index.html`, one section per demo with its pictures,
//! its table of measured figures next to the paper's (or analytic) figures, and timings.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use wscg_math::progress::Progress;
use wscg_math::{Error, Result};

use crate::demo::{Demo, Report};

/// Outcome of one demo in the gallery.
pub struct Entry {
    /// The demo.
    pub demo: Demo,
    /// Its report, or the error it stopped with.
    pub result: Result<Report>,
    /// Wall-clock seconds the whole demo took.
    pub seconds: f64,
}

/// Runs every demo in `demos`, each writing into `out/NAME/`, and writes `out/index.html`.
/// A failing demo is shown in the page with its error; the others still run.
/// `progress(demo)` gives the progress receiver for each demo.
pub fn run<'a>(
    out: &Path,
    demos: &[Demo],
    progress: &dyn Fn(&Demo) -> Box<dyn Progress + 'a>,
) -> Result<Vec<Entry>> {
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let mut entries = Vec::new();
    for demo in demos {
        let dir = out.join(demo.name);
        let t = Instant::now();
        let result = std::fs::create_dir_all(&dir)
            .map_err(|e| Error::io(&dir, e))
            .and_then(|_| (demo.run)(&dir, progress(demo).as_ref()));
        entries.push(Entry {
            demo: *demo,
            result,
            seconds: t.elapsed().as_secs_f64(),
        });
    }
    let html = render(&entries);
    let index = out.join("index.html");
    wscg_math::io::atomic::write(&index, html)?;
    Ok(entries)
}

/// Escapes text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Renders the gallery page.
pub fn render(entries: &[Entry]) -> String {
    let mut h = String::new();
    h.push_str(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>wscg gallery</title><style>\
         body{font-family:sans-serif;max-width:1200px;margin:auto;padding:1em;color:#222}\
         table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;padding:4px 8px;text-align:left}\
         th{background:#eee}figure{display:inline-block;margin:0.5em;vertical-align:top}\
         figure img{max-width:280px;image-rendering:pixelated;border:1px solid #ccc}figcaption{font-size:0.85em;max-width:280px}\
         .err{color:#a00}nav a{margin-right:1em}</style></head><body>\n\
         <h1>wscg gallery</h1>\n<p>Demos of the papers of the Journal of WSCG vol. 23 on built-in \
         data. Each table lists our measured figure next to the paper's reported figure (or an \
         analytic value).</p>\n<nav>",
    );
    for e in entries {
        let _ = write!(h, "<a href=\"#{0}\">{0}</a>", escape(e.demo.name));
    }
    h.push_str("</nav>\n");
    for e in entries {
        let d = &e.demo;
        let paper = if d.paper == "-" {
            "shared crate".to_string()
        } else {
            format!("paper {}", d.paper)
        };
        let _ = writeln!(
            h,
            "<section id=\"{}\"><h2>{} <small>({}, demo <code>{}</code>, {:.2} s)</small></h2>",
            escape(d.name),
            escape(d.title),
            escape(&paper),
            escape(d.name),
            e.seconds
        );
        match &e.result {
            Err(err) => {
                let _ = writeln!(
                    h,
                    "<p class=\"err\">failed: {}</p>",
                    escape(&err.to_string())
                );
            }
            Ok(r) => {
                let _ = writeln!(h, "<p>{}</p>", escape(&r.summary));
                for f in &r.figures {
                    let _ = writeln!(
                        h,
                        "<figure><a href=\"{0}/{1}\"><img src=\"{0}/{1}\" alt=\"{2}\"></a><figcaption>{2}</figcaption></figure>",
                        escape(d.name),
                        escape(&f.file),
                        escape(&f.caption)
                    );
                }
                if !r.table.is_empty() {
                    h.push_str("<table><tr><th>quantity</th><th>ours</th><th>reference</th><th>source / note</th></tr>\n");
                    for row in &r.table {
                        let _ = writeln!(
                            h,
                            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                            escape(&row.quantity),
                            escape(&row.ours),
                            escape(&row.reference),
                            escape(&row.note)
                        );
                    }
                    h.push_str("</table>\n");
                }
                if !r.timings.is_empty() {
                    h.push_str("<table><tr><th>timing</th><th>seconds</th></tr>\n");
                    for (k, v) in &r.timings {
                        let _ = writeln!(h, "<tr><td>{}</td><td>{v:.4}</td></tr>", escape(k));
                    }
                    h.push_str("</table>\n");
                }
            }
        }
        h.push_str("</section>\n");
    }
    h.push_str("</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::demo::Row;

    fn ok_demo(_: &Path, _: &dyn Progress) -> Result<Report> {
        Ok(Report {
            summary: "a <b> & c".into(),
            table: vec![Row::new("q", "1", "2", "n")],
            ..Default::default()
        })
    }
    fn bad_demo(_: &Path, _: &dyn Progress) -> Result<Report> {
        Err(Error::invalid("x", "broken"))
    }

    #[test]
    fn failing_demos_are_reported_and_text_is_escaped() {
        let dir = tempfile::tempdir().unwrap();
        let demos = [
            Demo {
                name: "good",
                paper: "01",
                title: "Good",
                run: ok_demo,
            },
            Demo {
                name: "bad",
                paper: "02",
                title: "Bad",
                run: bad_demo,
            },
        ];
        let entries = run(dir.path(), &demos, &|_| {
            Box::new(wscg_math::progress::NoProgress)
        })
        .unwrap();
        assert!(entries[0].result.is_ok() && entries[1].result.is_err());
        let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
        assert!(html.contains("a &lt;b&gt; &amp; c"));
        assert!(html.contains("failed: invalid argument `x`: broken"));
        assert!(html.contains("<td>q</td><td>1</td><td>2</td>"));
        assert!(dir.path().join("good").is_dir());
    }
}
