//! Atomic, checked file writes: the one way every writer of the workspace puts a file on disk.
//!
//! A file is written to a fresh temporary file in the destination's folder, flushed, synced to
//! the disk, and only then renamed over the destination. Every error on the way (create,
//! write, flush, sync, rename) is returned as [`Error::Io`] naming the destination, and the
//! temporary file is removed. So a failed write (full disk, file-size limit, permission)
//! leaves the previous file untouched (or no file), and a writer killed half-way leaves no
//! truncated file at the destination: at worst a `wscg_tmp_*` file next to it.
//!
//! The temporary file is named `wscg_tmp_<tag>_<pid>_<n>.<ext>`, where `<tag>` is the
//! destination's file name with every character other than an ASCII letter, digit, `_` or
//! `-` replaced by `-`, cut to [`TEMP_TAG_LEN`] characters ([`temp_tag`]). So a program that
//! re-runs a killed writer can remove the leftovers of the files it is about to write, and
//! only those, while other writers work in the same folder.
//!
//! A destination that already exists keeps its permissions, and a read-only one is refused
//! (as opening it for writing would be) rather than replaced. The rename replaces a symbolic
//! link at the destination by the new file rather than writing through it.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::{Error, Result};

/// Writes `bytes` to `path` atomically (the checked, atomic `std::fs::write`).
///
/// Errors: [`Error::Io`] naming `path` when any step fails; `path` is then unchanged.
pub fn write(path: impl AsRef<Path>, bytes: impl AsRef<[u8]>) -> Result<()> {
    let path = path.as_ref();
    write_with(path, |out| {
        out.write_all(bytes.as_ref())
            .map_err(|e| Error::io(path, e))
    })
}

/// Writes `path` atomically through a buffered writer: `fill` writes the content (its errors
/// are returned as they are, so map I/O errors with [`Error::io`] naming `path`), then the
/// buffer is flushed, the file synced and renamed over `path`.
///
/// Errors: `fill`'s error, or [`Error::Io`] naming `path` when creating, flushing, syncing or
/// renaming fails; `path` is then unchanged and the temporary file removed.
pub fn write_with<F>(path: impl AsRef<Path>, fill: F) -> Result<()>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<()>,
{
    let path = path.as_ref();
    refuse_read_only(path)?;
    let tmp = temp_sibling(path, "tmp");
    let result = create_new(&tmp)
        .map_err(|e| Error::io(path, e))
        .and_then(|file| {
            let mut out = BufWriter::new(file);
            fill(&mut out)?;
            let file = out
                .into_inner()
                .map_err(|e| Error::io(path, e.into_error()))?;
            finish(file, &tmp, path)
        });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `path` atomically through a writer that only takes a file name (a codec library
/// that opens the file itself): `fill` writes a temporary file in `path`'s folder whose name
/// ends in `.ext` and has no other dot (codecs pick the format from it), which is then synced
/// and renamed over `path`.
///
/// Errors: `fill`'s error, or [`Error::Io`] naming `path` when syncing or renaming fails;
/// `path` is then unchanged and the temporary file removed.
pub fn write_via_temp_path<F>(path: impl AsRef<Path>, ext: &str, fill: F) -> Result<()>
where
    F: FnOnce(&Path) -> Result<()>,
{
    let path = path.as_ref();
    refuse_read_only(path)?;
    let tmp = temp_sibling(path, ext);
    let result = fill(&tmp).and_then(|()| {
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(&tmp)
            .map_err(|e| Error::io(path, e))?;
        finish(file, &tmp, path)
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Syncs `file` (written at `tmp`) to the disk, gives it the permissions of an existing
/// `path`, closes it and renames it over `path`.
fn finish(file: File, tmp: &Path, path: &Path) -> Result<()> {
    let io = |e| Error::io(path, e);
    file.sync_all().map_err(io)?;
    if let Ok(old) = std::fs::metadata(path) {
        if old.is_file() {
            file.set_permissions(old.permissions()).map_err(io)?;
        }
    }
    drop(file);
    std::fs::rename(tmp, path).map_err(io)
}

/// [`Error::Io`] (permission denied) when `path` is an existing read-only file.
fn refuse_read_only(path: &Path) -> Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() && m.permissions().readonly() => Err(Error::io(
            path,
            std::io::Error::new(
                std::io::ErrorKind::PermissionDenied,
                "the file is read-only",
            ),
        )),
        _ => Ok(()),
    }
}

/// Creates `path`, failing if it exists (a temporary name is never shared).
fn create_new(path: &Path) -> std::io::Result<File> {
    OpenOptions::new().write(true).create_new(true).open(path)
}

/// The longest destination tag in a temporary file's name, in characters.
pub const TEMP_TAG_LEN: usize = 96;

/// The tag of destination `file_name` in the names of its temporary files: the name with
/// every character other than an ASCII letter, digit, `_` or `-` replaced by `-`, cut to
/// [`TEMP_TAG_LEN`] characters (`labels.nii.gz` gives `labels-nii-gz`).
pub fn temp_tag(file_name: &str) -> String {
    file_name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '-'
            }
        })
        .take(TEMP_TAG_LEN)
        .collect()
}

/// A fresh temporary file name in the folder of `path`, `wscg_tmp_<tag>_<pid>_<n>.<ext>`
/// ([`temp_tag`]), ending in `.ext` with no other dot.
fn temp_sibling(path: &Path, ext: &str) -> PathBuf {
    static COUNTER: AtomicUsize = AtomicUsize::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tag = temp_tag(&path.file_name().unwrap_or_default().to_string_lossy());
    let name = format!("wscg_tmp_{tag}_{}_{n}.{ext}", std::process::id());
    match path.parent() {
        Some(dir) => dir.join(name),
        None => PathBuf::from(name),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn temporary_names_carry_the_destination() {
        assert_eq!(temp_tag("labels.nii.gz"), "labels-nii-gz");
        assert_eq!(temp_tag("0001_udct.npy"), "0001_udct-npy");
        assert_eq!(temp_tag("é x"), "--x");
        assert_eq!(temp_tag(&"a".repeat(300)).len(), TEMP_TAG_LEN);
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("scan.nii.gz");
        let mut seen = String::new();
        write_via_temp_path(&p, "gz", |tmp| {
            seen = tmp.file_name().unwrap().to_string_lossy().into_owned();
            std::fs::write(tmp, b"x").map_err(|e| Error::io(tmp, e))
        })
        .unwrap();
        let prefix = format!("wscg_tmp_scan-nii-gz_{}_", std::process::id());
        assert!(seen.starts_with(&prefix), "{seen}");
        assert!(
            seen.ends_with(".gz") && seen.matches('.').count() == 1,
            "{seen}"
        );
    }

    #[test]
    fn writes_replaces_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        write(&p, b"first").unwrap();
        write(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert_eq!(names(dir.path()), ["a.txt"]);
    }

    #[test]
    fn a_failed_fill_keeps_the_old_file_and_removes_the_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        write(&p, b"old").unwrap();
        let err = write_with(&p, |out| {
            out.write_all(b"partial").unwrap();
            Err(Error::io(&p, std::io::Error::other("disk full")))
        })
        .unwrap_err();
        assert!(err.to_string().contains("a.txt"), "{err}");
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["a.txt"]);
        let err = write_via_temp_path(&p, "txt", |tmp| {
            std::fs::write(tmp, b"partial").unwrap();
            Err(Error::io(&p, std::io::Error::other("codec failed")))
        })
        .unwrap_err();
        assert!(err.to_string().contains("a.txt"), "{err}");
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["a.txt"]);
    }

    #[test]
    fn a_missing_folder_is_an_error_naming_the_destination() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("no/such/folder/a.txt");
        let err = write(&p, b"x").unwrap_err();
        assert!(matches!(err, Error::Io { .. }));
        assert!(err.to_string().contains("no/such/folder/a.txt"), "{err}");
    }

    /// Run by [`a_full_disk_keeps_the_old_file`] in a child process whose file-size limit
    /// makes every write past 8 KiB fail with `EFBIG` (SIGXFSZ ignored).
    #[test]
    #[ignore = "run by a_full_disk_keeps_the_old_file under a file-size limit"]
    fn child_writes_past_the_file_size_limit() {
        let Some(p) = std::env::var_os("WSCG_ATOMIC_CHILD_PATH") else {
            return;
        };
        let p = PathBuf::from(p);
        // Small enough to fit the write buffer: the error comes from the final flush.
        let small = write(&p, vec![7u8; 8192 + 100]);
        let large = write(&p, vec![7u8; 1 << 20]);
        for err in [small.unwrap_err(), large.unwrap_err()] {
            assert!(matches!(err, Error::Io { .. }), "{err}");
            assert!(err.to_string().contains("a.bin"), "{err}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_full_disk_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.bin");
        write(&p, b"old").unwrap();
        let exe = std::env::current_exe().unwrap();
        let child = std::process::Command::new("sh")
            .arg("-c")
            .arg("trap '' XFSZ; ulimit -f 16 && exec \"$0\" \"$@\"")
            .arg(exe)
            .args([
                "--exact",
                "io::atomic::tests::child_writes_past_the_file_size_limit",
                "--ignored",
                "--test-threads=1",
            ])
            .env("WSCG_ATOMIC_CHILD_PATH", &p)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&child.stdout);
        assert!(
            child.status.success() && stdout.contains("1 passed"),
            "{stdout}"
        );
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["a.bin"]);
    }

    #[cfg(unix)]
    #[test]
    fn an_existing_file_keeps_its_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        write(&p, b"old").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o640)).unwrap();
        write(&p, b"new").unwrap();
        let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o444)).unwrap();
        let err = write(&p, b"newer").unwrap_err();
        assert!(err.to_string().contains("read-only"), "{err}");
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
    }
}
