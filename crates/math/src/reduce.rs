//! Parallel sums that give the same result for any thread count: fixed-size chunks are
//! summed in parallel, then the chunk sums in order (rayon's own `sum` splits work
//! depending on scheduling, so its rounding can change from run to run).

use rayon::prelude::*;

/// Items per chunk of the deterministic sums.
pub const SUM_CHUNK: usize = 4096;

/// Sum of `f(item)` over `items`, deterministic for any thread count.
pub fn chunked_sum<T: Sync>(items: &[T], f: impl Fn(&T) -> f64 + Sync) -> f64 {
    let partial: Vec<f64> = items
        .par_chunks(SUM_CHUNK)
        .map(|c| c.iter().map(&f).sum::<f64>())
        .collect();
    partial.iter().sum()
}

/// Sum of `f(a_i, b_i)` over two slices of the same length (an inner product, say),
/// deterministic for any thread count.
pub fn chunked_sum_pairs<A: Sync, B: Sync>(
    a: &[A],
    b: &[B],
    f: impl Fn(&A, &B) -> f64 + Sync,
) -> f64 {
    let partial: Vec<f64> = a
        .par_chunks(SUM_CHUNK)
        .zip(b.par_chunks(SUM_CHUNK))
        .map(|(x, y)| x.iter().zip(y).map(|(p, q)| f(p, q)).sum::<f64>())
        .collect();
    partial.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_are_those_of_fixed_chunks_in_order() {
        let a: Vec<f64> = (0..10_000)
            .map(|i| ((i * 7919) % 1000) as f64 * 1e-3 + 1e-9)
            .collect();
        let b: Vec<f64> = a.iter().rev().copied().collect();
        let mut want = 0.0;
        for c in a.chunks(SUM_CHUNK) {
            want += c.iter().sum::<f64>();
        }
        assert_eq!(chunked_sum(&a, |v| *v), want);
        let mut want2 = 0.0;
        for (x, y) in a.chunks(SUM_CHUNK).zip(b.chunks(SUM_CHUNK)) {
            want2 += x.iter().zip(y).map(|(p, q)| p * q).sum::<f64>();
        }
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let got = pool.install(|| chunked_sum_pairs(&a, &b, |p, q| p * q));
            assert_eq!(got, want2);
        }
    }
}
