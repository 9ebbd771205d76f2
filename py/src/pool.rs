//! The one rayon thread pool that runs the Rust work of every binding in this process.
//!
//! Every binding releases the GIL and runs its Rust work inside this pool ([`detach`]); no
//! binding touches rayon's global pool. The pool belongs to the process that built it: a
//! child created by `fork` inherits the parent's memory but none of its threads, so a pool
//! built before the fork would wait forever for workers that do not exist. [`pool`] therefore
//! builds a fresh pool in a forked child (detected by an at-fork handler and by the process
//! id) and leaks the parent's, whose locks may have been held by threads that are gone.
//!
//! The number of threads is one process-wide setting: `wscg.set_num_threads(n)`, with the
//! default taken from the environment variable `WSCG_NUM_THREADS` when the module is
//! imported, else rayon's default (`RAYON_NUM_THREADS`, else the available parallelism).
//!
//! [`pool`] is only called with the GIL held, and `os.fork` holds the GIL too, so no thread
//! of the parent is inside the pool's mutex when the process forks.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, Once};
use std::time::Duration;

use pyo3::exceptions::{PyRuntimeError, PyRuntimeWarning};
use pyo3::prelude::*;
use pyo3::types::PyModule;

use crate::errors::value_error;

/// Largest accepted thread count (the bound `volseg` uses for its per-solve pools).
const MAX_THREADS: usize = 1024;

/// The environment variable that sets the default thread count at import.
const ENV_VAR: &str = "WSCG_NUM_THREADS";

/// The pool setting and the pool built from it.
struct Setting {
    /// Requested thread count; 0 is rayon's default.
    requested: usize,
    /// The pool, when one has been built.
    built: Option<Built>,
}

/// A pool together with the process (and fork generation) it was built in.
struct Built {
    /// Process id when the pool was built.
    pid: u32,
    /// Value of [`FORKS`] when the pool was built.
    generation: u64,
    /// The requested count the pool was built for (0: rayon's default).
    requested: usize,
    /// The pool; a running binding holds a clone, so a replaced pool lives until it returns.
    pool: Arc<rayon::ThreadPool>,
}

static SETTING: Mutex<Setting> = Mutex::new(Setting {
    requested: 0,
    built: None,
});

/// Number of forks this process descends from since the module was loaded (bumped in the
/// child by the at-fork handler).
static FORKS: AtomicU64 = AtomicU64::new(0);

#[cfg(unix)]
extern "C" fn bump_fork_generation() {
    // Async-signal-safe: one atomic add, nothing else runs in the forked child here.
    FORKS.fetch_add(1, Ordering::SeqCst);
}

/// Registers the at-fork handler once per process (the handler is inherited by children).
fn register_at_fork() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        #[cfg(unix)]
        {
            extern "C" {
                fn pthread_atfork(
                    prepare: Option<extern "C" fn()>,
                    parent: Option<extern "C" fn()>,
                    child: Option<extern "C" fn()>,
                ) -> std::os::raw::c_int;
            }
            // SAFETY: registers a handler that only performs an atomic add; the function
            // pointer stays valid for the life of the process (the module is never unloaded).
            unsafe {
                pthread_atfork(None, None, Some(bump_fork_generation));
            }
        }
    });
}

fn setting() -> MutexGuard<'static, Setting> {
    // A panic while holding the lock leaves a consistent state (every update is a single
    // assignment), so a poisoned lock is used as is.
    SETTING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Builds a pool of `requested` threads (0: rayon's default).
fn build(requested: usize) -> Result<rayon::ThreadPool, rayon::ThreadPoolBuildError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(requested)
        .thread_name(|i| format!("wscg-{i}"))
        .build()
}

/// The pool of `s`, (re)built when there is none, when it was built in another process (a
/// `fork`ed child sees its parent's pool, whose threads it does not have) or for another
/// thread count.
fn current(s: &mut Setting) -> Result<Arc<rayon::ThreadPool>, rayon::ThreadPoolBuildError> {
    let (pid, generation) = (std::process::id(), FORKS.load(Ordering::SeqCst));
    match &s.built {
        Some(b) if b.pid == pid && b.generation == generation && b.requested == s.requested => {
            return Ok(Arc::clone(&b.pool));
        }
        _ => {}
    }
    let pool = Arc::new(build(s.requested)?);
    let old = s.built.replace(Built {
        pid,
        generation,
        requested: s.requested,
        pool: Arc::clone(&pool),
    });
    if let Some(old) = old {
        if old.pid != pid || old.generation != generation {
            // Built before a fork: its workers do not exist in this process and its locks
            // may be held by them, so it must never be dropped (dropping wakes the workers).
            std::mem::forget(old);
        }
    }
    Ok(pool)
}

/// The process's pool, built on first use and rebuilt after a `fork` or a change of the
/// thread count. Call with the GIL held.
///
/// # Panics
/// When the operating system refuses to start the pool's threads.
pub fn pool() -> Arc<rayon::ThreadPool> {
    current(&mut setting()).unwrap_or_else(|e| panic!("cannot start the wscg thread pool: {e}"))
}

/// Whether a job has finished, with a condition variable to wait for it.
#[derive(Default)]
struct Done {
    finished: Mutex<bool>,
    changed: Condvar,
}

impl Done {
    /// Waits up to `timeout`; true once the job has finished.
    fn wait(&self, timeout: Duration) -> bool {
        let g = self.finished.lock().unwrap_or_else(|e| e.into_inner());
        let (g, _) = self
            .changed
            .wait_timeout_while(g, timeout, |finished| !*finished)
            .unwrap_or_else(|e| e.into_inner());
        *g
    }

    /// A guard that marks the job finished when dropped.
    fn finisher(&self) -> Finisher<'_> {
        Finisher(self)
    }
}

/// Marks its [`Done`] finished when dropped (also while unwinding from a panic).
struct Finisher<'a>(&'a Done);

impl Drop for Finisher<'_> {
    fn drop(&mut self) {
        *self.0.finished.lock().unwrap_or_else(|e| e.into_inner()) = true;
        self.0.changed.notify_all();
    }
}

/// How long the calling thread waits, with the GIL released, between two looks for Ctrl-C.
const SLICE: Duration = Duration::from_millis(50);

/// Runs `f` in the process's pool with the GIL released: the way every binding runs its
/// Rust work (rayon calls inside `f` use this pool, never rayon's global one).
///
/// A panic in `f` (a bug: bad input is an error, never a panic) is caught here and returned
/// as a `RuntimeError` carrying the panic message, which `except Exception` catches, rather
/// than reaching Python as pyo3's `PanicException`, a `BaseException`. A pool that cannot be
/// started is a `RuntimeError` too.
///
/// Ctrl-C: while `f` runs, the calling thread waits in slices of [`SLICE`], taking the GIL
/// back after each to look for a SIGINT that Python has received (only the main thread sees
/// one). On one it requests a cancellation ([`wscg_math::cancel`]), which the long loops of
/// the Rust work poll and turn into [`wscg_math::Error::Interrupted`], waits for `f` to
/// return, and sets the signal pending again: the binding's error then becomes the handler's
/// exception (`KeyboardInterrupt`) through `errors::interrupted`, and work that finished without
/// polling returns normally and Python raises the exception right after.
pub fn detach<T, F>(py: Python<'_>, f: F) -> PyResult<T>
where
    F: FnOnce() -> T + Send,
    T: Send,
{
    let pool = current(&mut setting())
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the wscg thread pool: {e}")))?;
    let f = move || std::panic::catch_unwind(AssertUnwindSafe(f));
    if pool.current_thread_index().is_some() {
        // Called back from inside the pool's own work: waiting here could hold the only
        // worker, so run in place.
        let out = py.detach(f);
        crate::logs::flush(py);
        return out.map_err(|payload| panic_error(payload.as_ref()));
    }
    let done = Done::default();
    let mut out = None;
    let mut request = None;
    let slot = &mut out;
    let signal = &done;
    pool.in_place_scope(|scope| {
        scope.spawn(move |_| {
            // Dropped when `f` returns: ends the wait.
            let _finish = signal.finisher();
            *slot = Some(f());
        });
        while !py.detach(|| done.wait(SLICE)) {
            crate::logs::flush(py);
            // SAFETY: the GIL is held (outside `py.detach`); the call reads and clears the
            // interpreter's SIGINT flag and is a no-op off the main thread.
            if request.is_none() && unsafe { pyo3::ffi::PyOS_InterruptOccurred() } != 0 {
                request = Some(wscg_math::cancel::Request::new());
            }
        }
    });
    crate::logs::flush(py);
    if request.take().is_some() {
        // SAFETY: GIL held; marks SIGINT pending again so that Python runs its handler.
        unsafe { pyo3::ffi::PyErr_SetInterrupt() };
    }
    out.expect("the scope ran the job to completion")
        .map_err(|payload| panic_error(payload.as_ref()))
}

/// Work (in elementary steps, e.g. DTW cells) below which [`detach_serial`] runs in place:
/// about a millisecond.
pub const SERIAL_WORK: usize = 1 << 20;

/// Runs `f`, work that makes no rayon call (one DTW of two sequences), with the GIL
/// released: in the calling thread when its size `work` is at most [`SERIAL_WORK`], where
/// handing the job to the pool and waking the caller again would cost more than the work
/// (about 15 us a call; Ctrl-C is then seen when the call returns), else as [`detach`].
/// Panics are caught in both cases.
pub fn detach_serial<T, F>(py: Python<'_>, work: usize, f: F) -> PyResult<T>
where
    F: FnOnce() -> T + Send,
    T: Send,
{
    if work > SERIAL_WORK {
        return detach(py, f);
    }
    let out = py.detach(move || std::panic::catch_unwind(AssertUnwindSafe(f)));
    crate::logs::flush(py);
    out.map_err(|payload| panic_error(payload.as_ref()))
}

/// The `RuntimeError` for a caught panic, with the panic's message.
fn panic_error(payload: &(dyn std::any::Any + Send)) -> PyErr {
    let message = payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied())
        .unwrap_or("no message");
    PyRuntimeError::new_err(format!(
        "internal error in wscg (please report it): {message}"
    ))
}

/// Sets the requested thread count (0: default) and starts the pool for it, so that a count
/// the system cannot provide is an error here rather than in a later call.
fn set(requested: usize) -> PyResult<()> {
    let mut s = setting();
    let previous = s.requested;
    s.requested = requested;
    if let Err(e) = current(&mut s) {
        s.requested = previous;
        return Err(PyRuntimeError::new_err(format!(
            "cannot start a thread pool of {requested} threads: {e}"
        )));
    }
    Ok(())
}

/// `n` as a requested thread count: `None` or 0 is the default, 1..=1024 a count.
fn requested_count(n: Option<i64>) -> PyResult<usize> {
    match n {
        None | Some(0) => Ok(0),
        Some(n) if n >= 1 && n as u64 <= MAX_THREADS as u64 => Ok(n as usize),
        Some(n) => Err(value_error(format!(
            "`n` must be a thread count in 1..={MAX_THREADS} (or 0 or None for the default), \
             got {n}"
        ))),
    }
}

/// Sets the number of threads of the pool that runs every wscg function in this process;
/// `None` or 0 restores the default.
#[pyfunction]
#[pyo3(signature = (n))]
fn set_num_threads(n: Option<i64>) -> PyResult<()> {
    set(requested_count(n)?)
}

/// The number of threads of the pool that runs every wscg function in this process.
#[pyfunction]
fn get_num_threads() -> usize {
    pool().current_num_threads()
}

/// Whether rayon's global pool was ever started in this process. A check for the tests:
/// it starts a one-thread global pool when there was none, so call it only in a process about
/// to exit (a forked child).
#[pyfunction]
fn _global_pool_started() -> bool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global()
        .is_err()
}

/// The default thread count from `WSCG_NUM_THREADS`: unset or empty is rayon's default, an
/// integer in 0..=1024 a count (0: default). Any other value keeps the default and warns. The
/// pool itself starts on first use.
fn from_env(py: Python<'_>) -> PyResult<()> {
    let Some(raw) = std::env::var_os(ENV_VAR) else {
        return Ok(());
    };
    let raw = raw.to_string_lossy();
    let text = raw.trim();
    if text.is_empty() {
        return Ok(());
    }
    match text.parse::<usize>() {
        Ok(n) if n <= MAX_THREADS => {
            setting().requested = n;
            Ok(())
        }
        _ => {
            let msg = format!(
                "{ENV_VAR}={text:?} is not a thread count in 0..={MAX_THREADS}; \
                 using the default number of threads"
            );
            let msg = std::ffi::CString::new(msg).unwrap_or_default();
            PyErr::warn(py, &py.get_type::<PyRuntimeWarning>(), &msg, 1)
        }
    }
}

/// Panics inside [`detach`] with `message`: a hook for the tests that check that a panic
/// reaches Python as a `RuntimeError`. Not part of the API.
#[pyfunction]
fn _panic_in_detach_for_tests(py: Python<'_>, message: String) -> PyResult<()> {
    detach(py, move || -> () { panic!("{message}") })
}

/// Adds `set_num_threads`, `get_num_threads` and the test check to the module, registers the
/// at-fork handler and applies `WSCG_NUM_THREADS`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    register_at_fork();
    m.add_function(wrap_pyfunction!(set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(get_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(_global_pool_started, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_in_detach_for_tests, m)?)?;
    from_env(m.py())
}
