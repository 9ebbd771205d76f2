//! Progress reporting for long work.
//!
//! Library functions that run for more than a moment take a `&dyn Progress`; the CLI passes an
//! implementation that draws indicatif progress bars, tests and the Python bindings pass
//! [`NoProgress`]. Implementations must be thread-safe: `advance` may be called from rayon
//! workers.

use std::sync::atomic::{AtomicU64, Ordering};

/// Receives progress of a long computation.
pub trait Progress: Sync {
    /// A new stage named `stage` with `total` steps begins.
    fn begin(&self, stage: &str, total: u64);
    /// `steps` more steps of the current stage are done.
    fn advance(&self, steps: u64);
    /// The current stage is finished.
    fn finish(&self);
}

/// Ignores all progress.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn begin(&self, _stage: &str, _total: u64) {}
    fn advance(&self, _steps: u64) {}
    fn finish(&self) {}
}

/// Counts steps; useful in tests and for polling from another thread.
#[derive(Debug, Default)]
pub struct CountingProgress {
    total: AtomicU64,
    done: AtomicU64,
    stages: AtomicU64,
}

impl CountingProgress {
    /// Steps advanced in the current stage.
    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }
    /// Total announced for the current stage.
    pub fn total(&self) -> u64 {
        self.total.load(Ordering::Relaxed)
    }
    /// Number of stages begun.
    pub fn stages(&self) -> u64 {
        self.stages.load(Ordering::Relaxed)
    }
}

impl Progress for CountingProgress {
    fn begin(&self, _stage: &str, total: u64) {
        self.total.store(total, Ordering::Relaxed);
        self.done.store(0, Ordering::Relaxed);
        self.stages.fetch_add(1, Ordering::Relaxed);
    }
    fn advance(&self, steps: u64) {
        self.done.fetch_add(steps, Ordering::Relaxed);
    }
    fn finish(&self) {}
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    #[test]
    fn counting_progress_is_thread_safe() {
        let p = CountingProgress::default();
        p.begin("work", 1000);
        (0..1000).into_par_iter().for_each(|_| p.advance(1));
        p.finish();
        assert_eq!((p.done(), p.total(), p.stages()), (1000, 1000, 1));
    }
}
