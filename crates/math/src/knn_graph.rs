//! The k-nearest-neighbour graph of a point set: the k nearest other points of *every*
//! point at once, as the mesh filters need it every iteration.
//!
//! The points are binned on a uniform grid whose cell is about the k-th-neighbour distance
//! (the 90 % quantile over a sample, found on a first, coarser grid). The points of one cell
//! share one candidate list, the 3 x 3 x 3 block of cells around it; a point whose k-th
//! candidate is farther than the block's boundary (rare) continues with an exact search in
//! growing shells of cells. The result equals one exact query per point, ties broken by
//! point index ([`crate::knn::KdTree::knn`] gives the same rows).

use rayon::prelude::*;

use crate::error::{ensure_finite, Error, Result};
use crate::kbest::Best;
use crate::vec3::dist2;

/// Points whose k-th-neighbour distance sizes the grid cells.
const SAMPLES: usize = 256;
/// The quantile of the sampled k-th-neighbour distances used as the cell size.
const QUANTILE: f64 = 0.9;
/// Cells per point up to which the grid keeps a dense table of cell starts and sorts by
/// counting (otherwise cell runs are found by binary search in sorted keys).
const DENSE_CELLS: u64 = 4;
/// Shells searched around a point before it is compared with every point instead.
const MAX_SHELLS: u64 = 8;

/// The k-nearest-neighbour graph: row `i` of the returned `points.len() x k` array
/// (row-major) holds the indices of the `k` points nearest to point `i`, itself excluded,
/// nearest first, ties by index.
///
/// Errors: no points, non-finite coordinates, `k == 0` or `k >= points.len()`, more than
/// `u32::MAX - 1` points.
pub fn knn_graph(points: &[[f64; 3]], k: usize) -> Result<Vec<u32>> {
    let n = points.len();
    if n == 0 {
        return Err(Error::Empty("points"));
    }
    if n >= u32::MAX as usize {
        return Err(Error::invalid("points", "too many for a neighbour graph"));
    }
    ensure_finite("points", points.as_flattened())?;
    if k == 0 || k >= n {
        return Err(Error::invalid(
            "k",
            format!("{k} neighbours need 1 <= k < {n} points"),
        ));
    }
    let (lo, hi) = bounds(points);
    let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    // A first grid as if the points filled their bounding cube, to measure the k-th
    // neighbour distances of a sample; then the grid of the working cell size.
    let coarse = extent * (k as f64 / n as f64).cbrt();
    let mut grid = Grid::new(points, lo, hi, coarse);
    if let Some(g) = &grid {
        let mut best = Best::new(k);
        let mut rk: Vec<f64> = (0..n)
            .step_by(n.div_ceil(SAMPLES))
            .map(|i| {
                g.search(points, &points[i], i as u32, &mut best);
                best.bound().sqrt()
            })
            .collect();
        rk.sort_by(f64::total_cmp);
        let cell = rk[((rk.len() - 1) as f64 * QUANTILE) as usize];
        if cell > 0.0 && cell < 0.75 * coarse {
            if let Some(fine) = Grid::new(points, lo, hi, cell) {
                grid = Some(fine);
            }
        }
    }
    let mut out = vec![0u32; n * k];
    let Some(grid) = grid else {
        // All points coincide (or the grid cannot be indexed): compare with every point.
        out.par_chunks_mut(k).enumerate().for_each_init(
            || Best::new(k),
            |best, (i, row)| {
                brute(points, &points[i], i as u32, best);
                write_row(best, row);
            },
        );
        return Ok(out);
    };
    // Rows in cell order, then gathered into point order.
    let mut by_cell = vec![0u32; n * k];
    let mut parts = Vec::with_capacity(grid.runs.len());
    let mut rest = by_cell.as_mut_slice();
    for &(s, e) in &grid.runs {
        let (head, tail) = rest.split_at_mut((e - s) * k);
        parts.push((s, e, head));
        rest = tail;
    }
    parts.into_par_iter().for_each_init(
        || (Best::new(k), Vec::new(), Vec::new()),
        |(best, cand, keyed), (s, e, rows)| {
            let c = grid.coords(&points[grid.order[s] as usize]);
            cand.clear();
            grid.shell(c, 1, true, |a, b| cand.extend_from_slice(&grid.order[a..b]));
            for (t, row) in (s..e).zip(rows.chunks_mut(k)) {
                let id = grid.order[t];
                let q = points[id as usize];
                // The k smallest (squared distance, index) of the block by selection; the
                // bits of a non-negative f64 order like the number.
                keyed.clear();
                keyed.extend(
                    cand.iter()
                        .filter(|&&j| j != id)
                        .map(|&j| (dist2(points[j as usize], q).to_bits(), j)),
                );
                best.clear();
                if keyed.len() >= k {
                    keyed.select_nth_unstable(k - 1);
                    keyed[..k].sort_unstable();
                    best.items
                        .extend(keyed[..k].iter().map(|&(b, j)| (f64::from_bits(b), j)));
                }
                let reach = grid.reach(&q, c, 1);
                if !(best.items.len() == k && best.bound() < reach * reach) {
                    grid.search(points, &q, id, best);
                }
                write_row(best, row);
            }
        },
    );
    let mut rank = vec![0u32; n];
    for (t, &i) in grid.order.iter().enumerate() {
        rank[i as usize] = t as u32;
    }
    out.par_chunks_mut(k).enumerate().for_each(|(i, row)| {
        let t = rank[i] as usize;
        row.copy_from_slice(&by_cell[t * k..(t + 1) * k]);
    });
    Ok(out)
}

fn write_row(best: &Best, row: &mut [u32]) {
    for (r, c) in row.iter_mut().zip(&best.items) {
        *r = c.1;
    }
}

fn bounds(points: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

/// The nearest points to `q` other than `exclude`, by comparing with every point.
fn brute(points: &[[f64; 3]], q: &[f64; 3], exclude: u32, best: &mut Best) {
    best.clear();
    for (j, p) in points.iter().enumerate() {
        let d2 = dist2(*p, *q);
        if j as u32 != exclude && d2 <= best.bound() {
            best.offer(d2, j as u32);
        }
    }
}

/// A uniform grid over a point set: point indices sorted by cell key.
struct Grid {
    lo: [f64; 3],
    cell: f64,
    dims: [u64; 3],
    /// Point indices sorted by cell key.
    order: Vec<u32>,
    /// Cell key of every entry of `order` (only without the dense table).
    keys: Vec<u64>,
    /// `(start, end)` of every occupied cell in `order`.
    runs: Vec<(usize, usize)>,
    /// With at most [`DENSE_CELLS`] cells per point: `first[key]`, the first entry of
    /// `order` whose key is at least `key` (one entry per cell and one past the end).
    first: Vec<u32>,
}

impl Grid {
    /// The grid of cell size `cell` over the box `lo..hi`; `None` when the cell is not
    /// positive or there would be too many cells to index.
    fn new(points: &[[f64; 3]], lo: [f64; 3], hi: [f64; 3], cell: f64) -> Option<Self> {
        if !(cell > 0.0 && cell.is_finite()) {
            return None;
        }
        let dims = [0, 1, 2].map(|a| ((hi[a] - lo[a]) / cell).floor() + 1.0);
        if dims.iter().product::<f64>() >= 2f64.powi(60) {
            return None;
        }
        let n = points.len();
        let mut g = Self {
            lo,
            cell,
            dims: dims.map(|d| d as u64),
            order: Vec::new(),
            keys: Vec::new(),
            runs: Vec::new(),
            first: Vec::new(),
        };
        let key_of: Vec<u64> = points.par_iter().map(|p| g.key(g.coords(p))).collect();
        let cells = g.dims.iter().product::<u64>();
        if cells <= DENSE_CELLS * n as u64 {
            // Counting sort.
            let mut first = vec![0u32; cells as usize + 1];
            for &key in &key_of {
                first[key as usize + 1] += 1;
            }
            for c in 1..first.len() {
                first[c] += first[c - 1];
            }
            let mut next = first.clone();
            g.order = vec![0; n];
            for (i, &key) in key_of.iter().enumerate() {
                g.order[next[key as usize] as usize] = i as u32;
                next[key as usize] += 1;
            }
            g.runs = first
                .windows(2)
                .filter(|w| w[1] > w[0])
                .map(|w| (w[0] as usize, w[1] as usize))
                .collect();
            g.first = first;
        } else {
            let mut keyed: Vec<(u64, u32)> = key_of
                .iter()
                .enumerate()
                .map(|(i, &key)| (key, i as u32))
                .collect();
            keyed.par_sort_unstable();
            g.order = keyed.iter().map(|e| e.1).collect();
            g.keys = keyed.into_iter().map(|e| e.0).collect();
            let mut s = 0;
            for t in 1..=n {
                if t == n || g.keys[t] != g.keys[s] {
                    g.runs.push((s, t));
                    s = t;
                }
            }
        }
        Some(g)
    }

    fn coords(&self, p: &[f64; 3]) -> [u64; 3] {
        [0, 1, 2].map(|a| (((p[a] - self.lo[a]) / self.cell) as u64).min(self.dims[a] - 1))
    }

    fn key(&self, c: [u64; 3]) -> u64 {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    /// The entries of `order` with keys `k0..=k1`.
    fn key_range(&self, k0: u64, k1: u64) -> (usize, usize) {
        if self.first.is_empty() {
            let a = self.keys.partition_point(|&key| key < k0);
            (a, a + self.keys[a..].partition_point(|&key| key <= k1))
        } else {
            (
                self.first[k0 as usize] as usize,
                self.first[k1 as usize + 1] as usize,
            )
        }
    }

    /// Calls `visit(start, end)` for the runs of `order` in the cells at Chebyshev distance
    /// `r` from cell `c` (at most `r` when `filled`), clipped to the grid, row by row.
    fn shell(&self, c: [u64; 3], r: u64, filled: bool, mut visit: impl FnMut(usize, usize)) {
        let span = |a: usize| (c[a].saturating_sub(r), (c[a] + r).min(self.dims[a] - 1));
        let ((x0, x1), (y0, y1), (z0, z1)) = (span(0), span(1), span(2));
        for z in z0..=z1 {
            for y in y0..=y1 {
                let outer = filled || z.abs_diff(c[2]) == r || y.abs_diff(c[1]) == r;
                if outer {
                    let (a, b) = self.key_range(self.key([x0, y, z]), self.key([x1, y, z]));
                    visit(a, b);
                } else {
                    for x in [c[0].checked_sub(r), Some(c[0] + r)].into_iter().flatten() {
                        if x < self.dims[0] {
                            let key = self.key([x, y, z]);
                            let (a, b) = self.key_range(key, key);
                            visit(a, b);
                        }
                    }
                }
            }
        }
    }

    /// The distance from `q` (in cell `c`) to the boundary of the block of cells within
    /// Chebyshev distance `r`: every point nearer than this lies in the block. Faces on the
    /// grid's border count as infinitely far (no point lies beyond them).
    fn reach(&self, q: &[f64; 3], c: [u64; 3], r: u64) -> f64 {
        (0..3)
            .map(|a| {
                let below = if c[a] <= r {
                    f64::INFINITY
                } else {
                    q[a] - (self.lo[a] + (c[a] - r) as f64 * self.cell)
                };
                let above = if c[a] + r >= self.dims[a] - 1 {
                    f64::INFINITY
                } else {
                    self.lo[a] + (c[a] + r + 1) as f64 * self.cell - q[a]
                };
                below.min(above)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Exact nearest points to `q` other than `exclude`, in growing shells of cells.
    fn search(&self, points: &[[f64; 3]], q: &[f64; 3], exclude: u32, best: &mut Best) {
        best.clear();
        let c = self.coords(q);
        for r in 0..=MAX_SHELLS {
            self.shell(c, r, false, |a, b| {
                for &j in &self.order[a..b] {
                    let d2 = dist2(points[j as usize], *q);
                    if j != exclude && d2 <= best.bound() {
                        best.offer(d2, j);
                    }
                }
            });
            let reach = self.reach(q, c, r);
            if reach == f64::INFINITY
                || (best.items.len() == best.k && best.bound() < reach * reach)
            {
                return;
            }
        }
        brute(points, q, exclude, best);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::knn::KdTree;

    /// Every row equals the point's own exact query.
    fn check(points: &[[f64; 3]], k: usize) {
        let graph = knn_graph(points, k).unwrap();
        let tree = KdTree::new(points).unwrap();
        for (i, p) in points.iter().enumerate() {
            let want: Vec<u32> = tree.knn(p, k, Some(i)).iter().map(|x| x.0 as u32).collect();
            assert_eq!(&graph[k * i..k * (i + 1)], &want[..], "point {i}");
        }
    }

    #[test]
    fn degenerate_sets_match_exact_queries() {
        // All points equal: ties everywhere, by index.
        check(&[[1.0, 2.0, 3.0]; 30], 5);
        // A flat grid (no z extent) with a far outlier and a tight cluster.
        let mut pts: Vec<[f64; 3]> = (0..400)
            .map(|i| [(i % 20) as f64, (i / 20) as f64, 0.0])
            .collect();
        pts.push([1e4, -3e3, 50.0]);
        pts.extend((0..40).map(|i| [5.0 + 1e-6 * i as f64, 5.0, 0.0]));
        check(&pts, 7);
        // A curve: points along a helix.
        let helix: Vec<[f64; 3]> = (0..3000)
            .map(|i| {
                let t = i as f64 * 0.01;
                [t.cos(), t.sin(), 0.05 * t]
            })
            .collect();
        check(&helix, 16);
        // Two points.
        check(&[[0.0; 3], [1.0, 0.0, 0.0]], 1);
        // Random points squashed along y, with duplicates.
        let u = crate::rng::uniform_vec(3, 3 * 2000, -1.0, 1.0).unwrap();
        let mut pts: Vec<[f64; 3]> = u.chunks(3).map(|c| [c[0], c[1] * 0.1, c[2]]).collect();
        pts.extend_from_within(..50);
        check(&pts, 12);
        assert!(knn_graph(&pts, pts.len()).is_err());
    }

    #[test]
    fn grid_with_exact_ties_matches_brute_force() {
        // A lattice has many exact ties, broken by index.
        let mut pts = Vec::new();
        for i in 0..30 {
            for j in 0..30 {
                for l in 0..12 {
                    pts.push([i as f64, j as f64 * 0.5, l as f64 * 2.0]);
                }
            }
        }
        let graph = knn_graph(&pts, 10).unwrap();
        for i in (0..pts.len()).step_by(101) {
            let mut brute: Vec<(f64, u32)> = (0..pts.len())
                .filter(|&j| j != i)
                .map(|j| (dist2(pts[i], pts[j]), j as u32))
                .collect();
            brute.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let want: Vec<u32> = brute[..10].iter().map(|c| c.1).collect();
            assert_eq!(&graph[10 * i..10 * (i + 1)], &want[..]);
        }
    }

    #[test]
    fn bad_input_is_rejected() {
        assert!(knn_graph(&[], 1).is_err());
        assert!(knn_graph(&[[0.0; 3]; 4], 4).is_err());
        assert!(knn_graph(&[[0.0; 3]; 4], 0).is_err());
        assert!(knn_graph(&[[0.0, f64::INFINITY, 0.0], [0.0; 3]], 1).is_err());
    }
}
