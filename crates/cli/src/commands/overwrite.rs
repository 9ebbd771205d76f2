//! The one check that no command writes over its own input unless `--overwrite` is given.
//!
//! Paths are compared as the files they name, not as strings: both sides are resolved
//! (symbolic links, `.` and `..`), and two existing files are the same when they share a
//! device and inode, so `./a.obj`, `a.obj` and a hard link to it are all caught. An output
//! file is refused when it is an input or lies inside an input folder; an output folder is
//! refused when it is an input folder or contains an input.

use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use wscg_math::{Error, Result};

/// Whether `--overwrite` was given (set once, before the command runs).
static ALLOWED: AtomicBool = AtomicBool::new(false);

/// Records the `--overwrite` flag for every later check.
pub fn allow(yes: bool) {
    ALLOWED.store(yes, Ordering::Relaxed);
}

/// Refuses to write the file `output` (given as the argument `arg`) when it is one of
/// `inputs` or lies inside an input folder, unless `--overwrite` was given. Inputs that do
/// not exist are skipped (reading them fails on its own).
pub fn check_file<P: AsRef<Path>>(
    arg: &'static str,
    output: &Path,
    inputs: impl IntoIterator<Item = P>,
) -> Result<()> {
    check(arg, output, false, inputs)
}

/// Refuses to write into the folder `output` (given as the argument `arg`) when it is an input
/// folder, contains an input, or lies inside an input folder, unless `--overwrite` was given.
pub fn check_folder<P: AsRef<Path>>(
    arg: &'static str,
    output: &Path,
    inputs: impl IntoIterator<Item = P>,
) -> Result<()> {
    check(arg, output, true, inputs)
}

fn check<P: AsRef<Path>>(
    arg: &'static str,
    output: &Path,
    folder: bool,
    inputs: impl IntoIterator<Item = P>,
) -> Result<()> {
    if ALLOWED.load(Ordering::Relaxed) {
        return Ok(());
    }
    let out = resolve(output);
    for input in inputs {
        let input = input.as_ref();
        let Ok(meta) = std::fs::metadata(input) else {
            continue;
        };
        let inp = resolve(input);
        let how = if same_file(input, output) || inp == out {
            "is the input"
        } else if meta.is_dir() && out.starts_with(&inp) {
            "lies inside the input folder"
        } else if folder && inp.starts_with(&out) {
            "contains the input"
        } else {
            continue;
        };
        return Err(Error::invalid(
            arg,
            format!(
                "{} {how} {}: writing it would modify the input; give --overwrite to allow it",
                output.display(),
                input.display()
            ),
        ));
    }
    Ok(())
}

/// True when both paths exist and name the same file (same device and inode on Unix).
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        #[cfg(unix)]
        (Ok(x), Ok(y)) => {
            use std::os::unix::fs::MetadataExt;
            x.dev() == y.dev() && x.ino() == y.ino()
        }
        #[cfg(not(unix))]
        (Ok(_), Ok(_)) => a.canonicalize().ok() == b.canonicalize().ok(),
        _ => false,
    }
}

/// `p` made absolute with symbolic links resolved, as far as it exists; the part that does
/// not exist yet is appended with `.` and `..` applied.
fn resolve(p: &Path) -> PathBuf {
    let absolute = if p.is_absolute() {
        p.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(p)
    };
    let mut existing = absolute.as_path();
    let mut rest = Vec::new();
    loop {
        if let Ok(c) = existing.canonicalize() {
            let mut out = c;
            for part in rest.iter().rev() {
                match part {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::CurDir => {}
                    other => out.push(other.as_os_str()),
                }
            }
            return out;
        }
        match (existing.parent(), existing.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last);
                existing = parent;
            }
            _ => return absolute,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolve_appends_the_missing_part() {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path().canonicalize().unwrap();
        assert_eq!(
            resolve(&dir.path().join("a/./b/../c.png")),
            base.join("a/c.png")
        );
        assert_eq!(resolve(&dir.path().join("x/..")), base);
    }
}
