//! Exact k-nearest-neighbour queries among high-dimensional rows (images, features), by
//! brute force in blocks of matrix products: shared by the k-NN classifier of the paper 05
//! baselines and by Isomap's neighbourhood graph.

use faer::MatRef;
use rayon::prelude::*;

/// The `k` nearest training rows of each query row, row-major `q x k`, nearest first.
pub struct Neighbours {
    /// Neighbours per query.
    pub k: usize,
    /// Training row indices.
    pub idx: Vec<usize>,
    /// Euclidean distances.
    pub dist: Vec<f64>,
}

/// Squared Euclidean norms of the rows of `x`.
fn row_sq_norms(x: MatRef<'_, f64>) -> Vec<f64> {
    let mut s = vec![0.0; x.nrows()];
    for j in 0..x.ncols() {
        for (i, si) in s.iter_mut().enumerate() {
            *si += x[(i, j)] * x[(i, j)];
        }
    }
    s
}

/// Brute-force `k` nearest neighbours of the rows of `query` among the rows of `train`
/// (`k <= train.nrows()`, minus one with `exclude_self`, which skips `train` row `i` for
/// query row `i`). Candidates come from `|q|^2 + |x|^2 - 2 q.x` (one matrix product per
/// block of queries, queries in parallel, a bounded sorted buffer per query); the `k`
/// selected distances are then recomputed directly and sorted (ties by index).
pub fn k_nearest(
    query: MatRef<'_, f64>,
    train: MatRef<'_, f64>,
    k: usize,
    exclude_self: bool,
) -> Neighbours {
    let (q, n, d) = (query.nrows(), train.nrows(), train.ncols());
    let tsq = row_sq_norms(train);
    let qsq = row_sq_norms(query);
    let mut idx = vec![0usize; q * k];
    let mut dist = vec![0.0; q * k];
    // Blocks of at most ~4M Gram entries (32 MB).
    let block = ((1usize << 22) / n.max(1)).clamp(16, 1024);
    let order = |a: &(f64, usize), b: &(f64, usize)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
    let mut start = 0;
    while start < q {
        let len = block.min(q - start);
        let g = train * query.subrows(start, len).transpose(); // n x len
        let range = start * k..(start + len) * k;
        idx[range.clone()]
            .par_chunks_mut(k)
            .zip(dist[range].par_chunks_mut(k))
            .enumerate()
            .for_each(|(b, (ib, db))| {
                let i = start + b;
                let gb = g.col_as_slice(b);
                // The k smallest (d^2, j), sorted; j increases, so ties keep the lower index.
                let mut cand: Vec<(f64, usize)> = Vec::with_capacity(k + 1);
                for (j, &gij) in gb.iter().enumerate() {
                    if exclude_self && j == i {
                        continue;
                    }
                    let d2 = (tsq[j] + qsq[i] - 2.0 * gij).max(0.0);
                    if cand.len() == k && d2 >= cand[k - 1].0 {
                        continue;
                    }
                    let at = cand.partition_point(|c| c.0 <= d2);
                    cand.insert(at, (d2, j));
                    cand.truncate(k);
                }
                for c in cand.iter_mut() {
                    let s: f64 = (0..d)
                        .map(|t| {
                            let u = query[(i, t)] - train[(c.1, t)];
                            u * u
                        })
                        .sum();
                    c.0 = s.sqrt();
                }
                cand.sort_by(order);
                for ((it, dt), &(dd, j)) in ib.iter_mut().zip(db.iter_mut()).zip(&cand) {
                    *it = j;
                    *dt = dd;
                }
            });
        start += len;
    }
    Neighbours { k, idx, dist }
}
