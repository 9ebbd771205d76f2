//! Process-wide cancellation of long-running work (Ctrl-C in Python).
//!
//! Long loops (the sample loops of the renderers, iterative solvers, per-frame loops) call
//! [`check`] once per outer iteration: one relaxed atomic load, free next to the iteration's
//! work. While a cancellation is requested it returns [`Error::Interrupted`], which the loop
//! passes up with `?`. The Python bindings request a cancellation when the interpreter
//! receives SIGINT during a call ([`Request`]), wait for the work to stop, and raise
//! `KeyboardInterrupt`.
//!
//! The request is process-wide: every loop that polls stops while one is active, including
//! work started from other Python threads (their calls raise `KeyboardInterrupt` too, as
//! Python delivers the signal to the process). Requests are counted, so overlapping ones end
//! only when the last is dropped.

use std::sync::atomic::{AtomicUsize, Ordering};

use crate::error::{Error, Result};

/// A count of live cancellation requests.
#[derive(Debug, Default)]
struct Flag(AtomicUsize);

impl Flag {
    fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed) != 0
    }
}

/// The process's requests.
static GLOBAL: Flag = Flag(AtomicUsize::new(0));

/// Whether a cancellation is requested now.
#[inline]
pub fn requested() -> bool {
    GLOBAL.requested()
}

/// `Err(Error::Interrupted)` while a cancellation is requested: the poll that long loops make
/// once per outer iteration.
#[inline]
pub fn check() -> Result<()> {
    if requested() {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}

/// A cancellation request, active from [`Request::new`] until dropped.
#[derive(Debug)]
pub struct Request(&'static Flag);

impl Request {
    /// Requests that every polling loop stop, until the returned value is dropped.
    pub fn new() -> Self {
        Self::on(&GLOBAL)
    }

    fn on(flag: &'static Flag) -> Self {
        flag.0.fetch_add(1, Ordering::SeqCst);
        Request(flag)
    }
}

impl Default for Request {
    fn default() -> Self {
        Self::new()
    }
}

impl Drop for Request {
    fn drop(&mut self) {
        self.0 .0.fetch_sub(1, Ordering::SeqCst);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_are_counted_until_dropped() {
        // A flag of its own: a request on the process's flag would stop other tests' loops.
        let flag: &'static Flag = Box::leak(Box::default());
        assert!(!flag.requested());
        let a = Request::on(flag);
        let b = Request::on(flag);
        assert!(flag.requested());
        drop(a);
        assert!(flag.requested());
        drop(b);
        assert!(!flag.requested());
        assert!(check().is_ok());
    }
}
