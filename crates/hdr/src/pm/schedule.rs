//! The schedule of a sweep: its rows run on the pool's threads as a pipeline in which a row
//! visits a column only once the row before it (in scan order) has left that column, so
//! every pixel sees exactly the neighbours the sequential scan would show it. The per-pixel
//! state is shared by the row workers as raw pointers ([`Cells`]); the release/acquire
//! counts of the rows order every access of one pixel.

use std::sync::atomic::{AtomicUsize, Ordering};

use rayon::prelude::*;

/// Waits until the row ahead has visited column `j` (its count `ahead` exceeds `j`), spinning
/// briefly, then yielding; `seen` caches the last count read, so a row reads the shared count
/// only when its cached value is not enough.
#[inline(always)]
pub(super) fn wait_past(ahead: &AtomicUsize, j: usize, seen: &mut usize) {
    let mut spins = 0u32;
    while *seen <= j {
        *seen = ahead.load(Ordering::Acquire);
        if *seen <= j {
            spins += 1;
            if spins < 1 << 12 {
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
    }
}

/// How many columns a row visits between two publications of its progress (fewer
/// cross-core messages; the row behind trails by at most this many columns more).
pub(super) const PUBLISH: usize = 16;

/// One row's turn in a sweep: the row, the scan direction, the visited-column count of the
/// row ahead of it in scan order (`None` for the first) and its own.
#[derive(Clone, Copy)]
pub(super) struct RowTurn<'a> {
    pub(super) y: i32,
    pub(super) forward: bool,
    pub(super) ahead: Option<&'a AtomicUsize>,
    pub(super) done: &'a AtomicUsize,
}

/// Marks a row as finished if its visit unwinds, so the rows behind it stop waiting and the
/// panic reaches the caller instead of hanging the sweep.
struct UnblockOnPanic<'a>(&'a AtomicUsize);

impl Drop for UnblockOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.store(usize::MAX, Ordering::Release);
        }
    }
}

/// The per-pixel state of a run (offsets, costs, kept SSDs) as raw pointers, shared by the
/// row workers of one sweep, each of which writes only its own row.
#[derive(Clone, Copy)]
pub(super) struct Cells {
    pub(super) off: *mut [i32; 2],
    pub(super) cost: *mut f32,
    pub(super) ssd: *mut f32,
}

// SAFETY: the row schedule of `pipeline` keeps every access of one pixel on one thread at a
// time, ordered by the release/acquire counts of the rows.
unsafe impl Send for Cells {}
unsafe impl Sync for Cells {}

/// Runs `visit` on each of `ha` rows, in scan order (`forward`: top to bottom), as a pipeline
/// on the pool's threads: workers take the rows in scan order, and [`RowTurn`] hands each row
/// the visited-column count of the row ahead of it (which the visit waits on, see
/// [`wait_past`]) and its own (which the visit publishes). Rows are taken in scan order, so
/// the row a worker waits for is being visited by a running worker (a worker makes no rayon
/// calls while it holds a row).
pub(super) fn pipeline(ha: usize, forward: bool, visit: impl Fn(RowTurn) + Sync) {
    // Columns of each row (in scan order) already visited, and the next row to take.
    let done: Vec<AtomicUsize> = (0..ha).map(|_| AtomicUsize::new(0)).collect();
    let next = AtomicUsize::new(0);
    let workers = rayon::current_num_threads().clamp(1, ha);
    (0..workers).into_par_iter().for_each(|_| loop {
        let k = next.fetch_add(1, Ordering::Relaxed);
        if k >= ha {
            break;
        }
        let y = if forward { k } else { ha - 1 - k } as i32;
        let ahead = k.checked_sub(1).map(|j| &done[j]);
        let row = RowTurn {
            y,
            forward,
            ahead,
            done: &done[k],
        };
        let _unblock = UnblockOnPanic(&done[k]);
        visit(row);
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row waits for column `j` of the row ahead until that row has visited `j + 1`
    /// columns: a count of exactly `j` (column `j` not yet written) keeps it waiting, `j + 1`
    /// releases it. A wait that returned at `j` (an off-by-one the thread-count test cannot
    /// see reliably) fails here.
    #[test]
    fn a_row_waits_until_the_row_ahead_has_left_the_column() {
        use std::sync::atomic::AtomicBool;
        use std::time::Duration;
        let ahead = AtomicUsize::new(7);
        let released = AtomicBool::new(false);
        let early = std::thread::scope(|s| {
            s.spawn(|| {
                let mut seen = 0;
                wait_past(&ahead, 7, &mut seen);
                released.store(true, Ordering::SeqCst);
                assert!(seen >= 8, "{seen}");
            });
            std::thread::sleep(Duration::from_millis(100));
            let early = released.load(Ordering::SeqCst);
            // Released in any case, so a failing check cannot leave the waiter spinning.
            ahead.store(8, Ordering::Release);
            early
        });
        assert!(!early, "released at count 7 for column 7");
        assert!(released.load(Ordering::SeqCst));
        // A cached count that is already past the column does not read the shared one.
        let mut seen = 12;
        wait_past(&AtomicUsize::new(0), 11, &mut seen);
        assert_eq!(seen, 12);
    }

    /// A row whose visit unwinds marks itself finished (so the rows behind it stop waiting);
    /// a row that returns normally leaves its count to its own stores.
    #[test]
    fn an_unwinding_row_releases_the_rows_behind_it() {
        let done = AtomicUsize::new(3);
        let caught = std::panic::catch_unwind(|| {
            let _unblock = UnblockOnPanic(&done);
            panic!("visit failed");
        });
        assert!(caught.is_err());
        assert_eq!(done.load(Ordering::Acquire), usize::MAX);
        let done = AtomicUsize::new(3);
        {
            let _unblock = UnblockOnPanic(&done);
        }
        assert_eq!(done.load(Ordering::Acquire), 3);
    }
}
