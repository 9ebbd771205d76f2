//! faer's parallelism fixed for the process, so that its dense kernels give the same bits
//! with any thread count.
//!
//! faer's default global parallelism, `Par::rayon(0)`, splits a product or a factorisation
//! into as many tasks as the current rayon pool has threads, and the way the work is split
//! decides the rounding: an eigendecomposition computed inside a one-thread pool differs in
//! the last bits from the same one inside a two-thread pool, and a PCA axis that differs in
//! the last bits can change a kd-tree and every match built on it. A fixed task count gives
//! the same split, hence the same bits, in a pool of any size.

use std::sync::Once;

static FIXED: Once = Once::new();

/// Sets faer's global parallelism to `Par::rayon(n)`, `n` the machine's available
/// parallelism (which respects CPU quotas and does not change with the thread pool), once per
/// process. Every dense routine of this crate calls it before its first faer call; the Python
/// module and the command line call it at start-up, so the other crates' faer products are
/// fixed as well. A program that sets faer's parallelism itself should do so after this.
pub fn fix_faer_parallelism() {
    FIXED.call_once(|| {
        let n = std::thread::available_parallelism().map_or(1, |n| n.get());
        faer::set_global_parallelism(faer::Par::rayon(n));
    });
}
