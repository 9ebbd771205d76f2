//! Log records of the Rust crates, delivered to Python's `logging` under the `wscg` logger.
//!
//! Every wscg crate logs through the `log` facade with its module path as the target
//! (`wscg_volseg::walker`); Python sees the record on the logger `wscg.volseg.walker`, a
//! child of `wscg`, at the same level (Rust's `trace` is level 5, below `DEBUG`). Records of
//! other crates are dropped.
//!
//! Most records are written on the pool's worker threads while the calling Python thread
//! waits without the GIL ([`crate::pool::detach`]). Such a thread must not wait for the GIL
//! itself (the caller could be holding it while it waits for that very thread), so a record
//! written without the GIL is queued and handed to `logging` by the calling thread: while it
//! waits, every few tens of milliseconds, and when the call returns ([`flush`]). A record
//! written with the GIL held goes to `logging` at once. Python's levels and handlers decide
//! what is shown, as for any Python library: `logging.getLogger("wscg").setLevel("INFO")`.

use std::sync::{Mutex, OnceLock};

use log::{Level, Log, Metadata, Record};
use pyo3::prelude::*;

/// The installed bridge (leaked once: `log` keeps a `&'static` logger).
static BRIDGE: OnceLock<&'static Bridge> = OnceLock::new();

/// A record written off the GIL, kept until a thread holding the GIL forwards it.
struct Queued {
    level: Level,
    target: String,
    message: String,
    module_path: Option<String>,
    file: Option<String>,
    line: Option<u32>,
}

/// Forwards wscg records to pyo3-log's logger, queueing those written without the GIL.
struct Bridge {
    python: pyo3_log::Logger,
    queue: Mutex<Vec<Queued>>,
}

/// The Rust target of a wscg record as a Python logger name under `wscg`
/// (`wscg_volseg::walker` -> `wscg::volseg::walker`; pyo3-log turns `::` into `.`), or None
/// for another crate's record.
fn python_target(target: &str) -> Option<String> {
    if !is_wscg(target) {
        return None;
    }
    Some(match target.strip_prefix("wscg_") {
        Some(crate_path) => format!("wscg::{crate_path}"),
        None => target.to_string(),
    })
}

/// Whether the calling thread holds the GIL.
///
/// `PyGILState_Check` (CPython 3.4 and later, unchanged since) is outside the limited API
/// that the abi3 wheel is built against, so pyo3 does not declare it there; on Unix the
/// extension resolves it from the running interpreter like every other C-API symbol. Where
/// it cannot be resolved (Windows' `python3.dll` does not export it) every record is queued
/// and reaches `logging` at the next flush of the calling thread (`flush`).
#[cfg(unix)]
fn holds_gil() -> bool {
    extern "C" {
        fn PyGILState_Check() -> std::os::raw::c_int;
    }
    // SAFETY: PyGILState_Check only reads the calling thread's state; the interpreter is
    // initialised (this module was imported).
    unsafe { PyGILState_Check() == 1 }
}

/// Whether the calling thread holds the GIL: not known without `PyGILState_Check` (see the
/// Unix version), so records are queued for the next flush.
#[cfg(not(unix))]
fn holds_gil() -> bool {
    false
}

impl Bridge {
    fn forward(&self, q: &Queued) {
        self.python.log(
            &Record::builder()
                .level(q.level)
                .target(&q.target)
                .args(format_args!("{}", q.message))
                .module_path(q.module_path.as_deref())
                .file(q.file.as_deref())
                .line(q.line)
                .build(),
        );
    }

    fn take(&self) -> Vec<Queued> {
        match self.queue.lock() {
            Ok(mut q) => std::mem::take(&mut *q),
            Err(poisoned) => std::mem::take(&mut *poisoned.into_inner()),
        }
    }
}

/// Whether `target` is a wscg crate's (the test of [`python_target`], without allocating).
fn is_wscg(target: &str) -> bool {
    target
        .strip_prefix("wscg")
        .is_some_and(|rest| rest.is_empty() || rest.starts_with("::") || rest.starts_with('_'))
}

impl Log for Bridge {
    fn enabled(&self, metadata: &Metadata<'_>) -> bool {
        is_wscg(metadata.target())
    }

    fn log(&self, record: &Record<'_>) {
        let Some(target) = python_target(record.target()) else {
            return;
        };
        let queued = Queued {
            level: record.level(),
            target,
            message: record.args().to_string(),
            module_path: record.module_path().map(str::to_string),
            file: record.file().map(str::to_string),
            line: record.line(),
        };
        if holds_gil() {
            // Earlier records of other threads first, so that the order is kept.
            for q in self.take() {
                self.forward(&q);
            }
            self.forward(&queued);
        } else {
            match self.queue.lock() {
                Ok(mut q) => q.push(queued),
                Err(poisoned) => poisoned.into_inner().push(queued),
            }
        }
    }

    fn flush(&self) {}
}

/// Installs the bridge as the process's `log` logger (once; later calls do nothing).
pub fn install(py: Python<'_>) -> PyResult<()> {
    if BRIDGE.get().is_some() {
        return Ok(());
    }
    // Caching::Loggers: Python logger objects are looked up once, their levels on every
    // record, so a level set after import takes effect at once.
    let python =
        pyo3_log::Logger::new(py, pyo3_log::Caching::Loggers)?.filter(log::LevelFilter::Trace);
    let bridge: &'static Bridge = Box::leak(Box::new(Bridge {
        python,
        queue: Mutex::new(Vec::new()),
    }));
    if log::set_logger(bridge).is_ok() {
        log::set_max_level(log::LevelFilter::Trace);
        let _ = BRIDGE.set(bridge);
    }
    Ok(())
}

/// Hands the records queued by threads without the GIL to Python's `logging`; called by the
/// thread that holds the GIL (the `py` token proves it).
pub fn flush(_py: Python<'_>) {
    if let Some(bridge) = BRIDGE.get() {
        for q in bridge.take() {
            bridge.forward(&q);
        }
    }
}
