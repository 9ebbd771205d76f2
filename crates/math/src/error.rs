//! The one error type of `wscg-math`, shared by the paper crates through `wscg_math::Error`.
//!
//! Every variant names what went wrong and, where it applies, the argument or file that caused
//! it, so that a message can be shown to a user as it is (the Python bindings map I/O and format
//! errors to `OSError` and everything else to `ValueError`).

use std::path::{Path, PathBuf};

/// Errors returned by `wscg-math` and by the paper crates built on it.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An argument is out of its allowed range or otherwise unusable.
    #[error("invalid argument `{name}`: {reason}")]
    InvalidArgument {
        /// Name of the argument as the caller knows it.
        name: &'static str,
        /// What is wrong and what is allowed.
        reason: String,
    },
    /// Two inputs (or an input and a declared size) disagree in shape.
    #[error("shape mismatch: {0}")]
    ShapeMismatch(String),
    /// An input holds NaN or an infinity where finite numbers are required.
    #[error("`{name}` contains a non-finite value (NaN or infinity) at flat index {index}")]
    NonFinite {
        /// Name of the argument.
        name: &'static str,
        /// Flat index of the first offending element.
        index: usize,
    },
    /// An input has no elements where at least one is required.
    #[error("`{0}` is empty")]
    Empty(&'static str),
    /// The operating system refused a read or write.
    #[error("cannot access {path}: {source}")]
    Io {
        /// The file concerned.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A file was read but its content is malformed, truncated or not what its format requires.
    #[error("cannot decode {path}: {reason}")]
    Format {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// A file format or element type that is not supported.
    #[error("unsupported format: {0}")]
    UnsupportedFormat(String),
    /// A size limit (guarding against hostile files or absurd requests) would be exceeded.
    #[error("limit exceeded: {0}")]
    LimitExceeded(String),
    /// A numerical method failed (matrix not positive definite, no convergence, ...).
    #[error("numerical failure: {0}")]
    Numerical(String),
    /// A buffer sized by an argument does not fit in memory: its size overflows, exceeds the
    /// memory limit of [`crate::alloc`], or the allocator refused it. The Python bindings raise
    /// `MemoryError`.
    #[error(
        "cannot allocate {} for `{what}`: {}",
        crate::memory_limit::describe_bytes(*bytes),
        match limit {
            Some(l) => format!(
                "more than the memory limit of {} (the machine's physical memory unless set \
                 through {} or set_memory_limit)",
                crate::memory_limit::describe_bytes(Some(*l as u128)),
                crate::memory_limit::ENV_VAR
            ),
            None => "the system refused the allocation".to_string(),
        }
    )]
    OutOfMemory {
        /// The argument whose value sets the size.
        what: &'static str,
        /// The bytes requested; `None` when the count overflowed.
        bytes: Option<u128>,
        /// The limit in force, or `None` when the allocator itself refused.
        limit: Option<u64>,
    },
    /// The work was stopped by a cancellation request ([`crate::cancel`]), as Ctrl-C makes in
    /// Python. The Python bindings raise `KeyboardInterrupt`.
    #[error("interrupted")]
    Interrupted,
}

/// `Result` with [`Error`] as the error type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Which argument a call refused, read from its [`Result`] without matching the error:
/// `params.validate().refused_argument() == Some("k")`.
pub trait RefusedArgument {
    /// The argument an [`Error::InvalidArgument`] names; `None` for `Ok` and other errors.
    fn refused_argument(&self) -> Option<&'static str>;
}

impl<T> RefusedArgument for Result<T> {
    fn refused_argument(&self) -> Option<&'static str> {
        self.as_ref().err().and_then(Error::argument)
    }
}

impl Error {
    /// Shorthand for [`Error::InvalidArgument`].
    pub fn invalid(name: &'static str, reason: impl Into<String>) -> Self {
        Error::InvalidArgument {
            name,
            reason: reason.into(),
        }
    }

    /// The argument an [`Error::InvalidArgument`] or [`Error::OutOfMemory`] names, `None` for
    /// every other error: lets a caller tell which of its inputs was refused without parsing
    /// the message.
    pub fn argument(&self) -> Option<&'static str> {
        match self {
            Error::InvalidArgument { name, .. } => Some(name),
            Error::OutOfMemory { what, .. } => Some(what),
            _ => None,
        }
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl AsRef<Path>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.as_ref().to_path_buf(),
            source,
        }
    }

    /// Shorthand for [`Error::Format`].
    pub fn format(path: impl AsRef<Path>, reason: impl Into<String>) -> Self {
        Error::Format {
            path: path.as_ref().to_path_buf(),
            reason: reason.into(),
        }
    }

    /// True for errors about files (I/O, decoding, unsupported formats): the Python bindings
    /// raise `OSError` for these and `ValueError` for the rest.
    pub fn is_io(&self) -> bool {
        matches!(
            self,
            Error::Io { .. } | Error::Format { .. } | Error::UnsupportedFormat(_)
        )
    }
}

/// Returns [`Error::NonFinite`] naming `name` if any element of `data` is NaN or infinite.
pub fn ensure_finite<T: Copy + Into<f64>>(name: &'static str, data: &[T]) -> Result<()> {
    match data.iter().position(|&v| !v.into().is_finite()) {
        Some(index) => Err(Error::NonFinite { name, index }),
        None => Ok(()),
    }
}

/// Returns [`Error::Empty`] naming `name` if `len` is zero.
pub fn ensure_nonempty(name: &'static str, len: usize) -> Result<()> {
    if len == 0 {
        Err(Error::Empty(name))
    } else {
        Ok(())
    }
}

/// Returns [`Error::InvalidArgument`] unless `value` is finite and strictly positive.
pub fn ensure_positive(name: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            name,
            format!("must be a finite number > 0, got {value}"),
        ))
    }
}

/// Reads a whole file, mapping the failure to [`Error::Io`] naming the path.
///
/// Only regular files are read: a device (`/dev/zero`, `/dev/urandom`) or a pipe has no end
/// and would be read until memory runs out, so it is refused ([`Error::Io`]), as is a
/// file larger than the memory limit of [`crate::memory_limit`] ([`Error::LimitExceeded`]). Every
/// reader of the workspace reads its files through this function or [`read_text`].
pub fn read_file(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read;
    let not_regular = || {
        Error::io(
            path,
            std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file (a folder, device or pipe)",
            ),
        )
    };
    // Checked before opening too: opening a FIFO for reading blocks until a writer comes.
    if !std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .is_file()
    {
        return Err(not_regular());
    }
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let meta = file.metadata().map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        return Err(not_regular());
    }
    let limit = crate::memory_limit::limit();
    if meta.len() > limit {
        return Err(Error::LimitExceeded(format!(
            "{}: {} bytes, more than the memory limit of {limit} bytes",
            path.display(),
            meta.len()
        )));
    }
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(meta.len() as usize)
        .map_err(|_| Error::LimitExceeded(format!("{}: cannot hold the file", path.display())))?;
    // A file that grows while it is read stops at the limit.
    file.take(limit)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    Ok(bytes)
}

/// Reads a whole file as [`read_file`] does, after refusing one larger than `max` bytes
/// ([`Error::LimitExceeded`] naming the file and `what` it should be: "paint descriptions
/// above 1048576 bytes are refused"), for formats whose files are small by nature.
pub fn read_file_at_most(path: &Path, max: u64, what: &str) -> Result<Vec<u8>> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.len() > max {
        return Err(Error::LimitExceeded(format!(
            "{} is {} bytes; {what} above {max} bytes are refused",
            path.display(),
            meta.len()
        )));
    }
    read_file(path)
}

/// Reads a whole text file as [`read_file`] does; content that is not UTF-8 is
/// [`Error::Format`] naming the file.
pub fn read_text(path: &Path) -> Result<String> {
    utf8(path, read_file(path)?)
}

/// [`read_text`] with the size limit of [`read_file_at_most`].
pub fn read_text_at_most(path: &Path, max: u64, what: &str) -> Result<String> {
    utf8(path, read_file_at_most(path, max, what)?)
}

fn utf8(path: &Path, bytes: Vec<u8>) -> Result<String> {
    String::from_utf8(bytes).map_err(|e| Error::format(path, format!("not UTF-8 text: {e}")))
}

/// Maps errors of a decoding reader: corrupt or truncated data is a format error, the rest
/// I/O.
pub fn read_error(path: &Path, e: std::io::Error) -> Error {
    use std::io::ErrorKind;
    match e.kind() {
        ErrorKind::InvalidData | ErrorKind::InvalidInput | ErrorKind::UnexpectedEof => {
            Error::format(path, format!("corrupt or truncated data: {e}"))
        }
        _ => Error::io(path, e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finite_check_reports_first_bad_index() {
        let e = ensure_finite("x", &[1.0f32, 2.0, f32::NAN, f32::INFINITY]).unwrap_err();
        assert!(matches!(
            e,
            Error::NonFinite {
                name: "x",
                index: 2
            }
        ));
        assert!(e.to_string().contains("`x`"));
        assert!(ensure_finite("x", &[0.0f64, -1.0]).is_ok());
    }

    #[test]
    fn positive_check_rejects_zero_nan_and_negative() {
        for v in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(ensure_positive("sigma", v).is_err(), "{v}");
        }
        assert!(ensure_positive("sigma", 1e-9).is_ok());
    }

    #[test]
    fn only_regular_files_are_read() {
        let dir = tempfile::tempdir().unwrap();
        // A folder, and on Unix a device without end: refused by name instead of read.
        let e = read_file(dir.path()).unwrap_err();
        assert!(e.is_io() && e.to_string().contains("regular file"), "{e}");
        #[cfg(unix)]
        assert!(read_file(Path::new("/dev/zero")).is_err());
        let f = dir.path().join("a.txt");
        std::fs::write(&f, "héllo").unwrap();
        assert_eq!(read_text(&f).unwrap(), "héllo");
        std::fs::write(&f, [0xff, 0xfe]).unwrap();
        assert!(read_text(&f).unwrap_err().is_io());
    }

    #[test]
    fn io_errors_are_classified() {
        assert!(Error::format("a.png", "truncated").is_io());
        assert!(!Error::invalid("k", "too large").is_io());
        assert!(Error::Empty("x").to_string().contains("empty"));
    }
}
