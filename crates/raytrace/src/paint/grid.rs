//! A uniform 2-D grid over a tile for the nearest flake along a ray. The flake layer is thin
//! (20 µm) and wide (450 µm) and its discs overlap heavily in plan view, so a grid over the
//! plane, each cell listing the discs whose footprint reaches it, beats a bounding volume
//! hierarchy: a ray crossing the layer visits one to three cells of a dozen discs each, in
//! order along the ray, and stops at the first cell holding a hit. Each cell keeps its discs
//! twice, by decreasing top and by increasing bottom, so that a ray going down (up) stops
//! testing once the discs left lie wholly below (above) the best hit so far.

use nalgebra::Vector3;

use super::disc::Flake;

/// Inclusive ranges of cell columns and rows a disc reaches.
type CellSpan = ((usize, usize), (usize, usize));

/// The grid: `n x n` square cells of side `cell` over `[0, size)^2`, each listing discs.
#[derive(Clone, Debug)]
pub struct FlakeGrid {
    n: usize,
    cell: f64,
    size: f64,
    /// Cell `k` lists `down[start[k]..start[k + 1]]` (by decreasing top) and the same discs
    /// in `up[start[k]..start[k + 1]]` (by increasing bottom).
    start: Vec<u32>,
    down: Vec<u32>,
    up: Vec<u32>,
    /// Lowest and highest z of each disc.
    z_range: Vec<(f64, f64)>,
}

impl FlakeGrid {
    /// Builds the grid over the square `[0, size)^2` for `discs`, with cells of about half the
    /// mean radius (at most 256 per side).
    pub fn build(discs: &[Flake], size: f64) -> Self {
        let mean_r = if discs.is_empty() {
            size
        } else {
            discs.iter().map(|f| f.r).sum::<f64>() / discs.len() as f64
        };
        let n = ((size / (0.5 * mean_r)).ceil() as usize).clamp(1, 256);
        let cell = size / n as f64;
        let range = |lo: f64, hi: f64| {
            let a = (lo / cell).floor().max(0.0) as usize;
            let b = ((hi / cell).floor().max(0.0) as usize).min(n - 1);
            (a, b)
        };
        let mut counts = vec![0u32; n * n + 1];
        let spans: Vec<Option<CellSpan>> = discs
            .iter()
            .map(|f| {
                let b = f.aabb();
                if b.max[0] < 0.0 || b.min[0] >= size || b.max[1] < 0.0 || b.min[1] >= size {
                    return None;
                }
                Some((range(b.min[0], b.max[0]), range(b.min[1], b.max[1])))
            })
            .collect();
        for ((i0, i1), (j0, j1)) in spans.iter().flatten() {
            for j in *j0..=*j1 {
                for i in *i0..=*i1 {
                    counts[j * n + i + 1] += 1;
                }
            }
        }
        for k in 1..counts.len() {
            counts[k] += counts[k - 1];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[n * n] as usize];
        for (d, span) in spans.iter().enumerate() {
            if let Some(((i0, i1), (j0, j1))) = span {
                for j in *j0..=*j1 {
                    for i in *i0..=*i1 {
                        let k = j * n + i;
                        items[fill[k] as usize] = d as u32;
                        fill[k] += 1;
                    }
                }
            }
        }
        let z_range: Vec<(f64, f64)> = discs
            .iter()
            .map(|f| {
                let b = f.aabb();
                (b.min[2], b.max[2])
            })
            .collect();
        let mut down = items;
        let mut up = down.clone();
        for k in 0..n * n {
            let (a, b) = (counts[k] as usize, counts[k + 1] as usize);
            down[a..b]
                .sort_unstable_by(|&p, &q| z_range[q as usize].1.total_cmp(&z_range[p as usize].1));
            up[a..b]
                .sort_unstable_by(|&p, &q| z_range[p as usize].0.total_cmp(&z_range[q as usize].0));
        }
        Self {
            n,
            cell,
            size,
            start: counts,
            down,
            up,
            z_range,
        }
    }

    /// The nearest hit `(t, disc index)` of `o + t d` with `0 < t <= t_max` whose hit point
    /// lies inside the square.
    pub fn nearest(
        &self,
        discs: &[Flake],
        o: [f64; 3],
        d: [f64; 3],
        t_max: f64,
    ) -> Option<(f64, u32)> {
        // Clip the segment to the square.
        let (mut ta, mut tb) = (0.0f64, t_max);
        for (oc, dc) in [(o[0], d[0]), (o[1], d[1])] {
            if dc == 0.0 {
                if oc < 0.0 || oc >= self.size {
                    return None;
                }
            } else {
                let (a, b) = ((0.0 - oc) / dc, (self.size - oc) / dc);
                ta = ta.max(a.min(b));
                tb = tb.min(a.max(b));
            }
        }
        if ta > tb {
            return None;
        }
        // The ray as the discs' intersection takes it, converted once.
        let (ov, dv) = (Vector3::from(o), Vector3::from(d));
        let n = self.n as isize;
        let c = self.cell;
        let px = o[0] + d[0] * ta;
        let py = o[1] + d[1] * ta;
        let mut i = ((px / c).floor() as isize).clamp(0, n - 1);
        let mut j = ((py / c).floor() as isize).clamp(0, n - 1);
        let axis = |p: f64, dc: f64, k: isize| -> (isize, f64, f64) {
            if dc > 0.0 {
                (1, ta + ((k + 1) as f64 * c - p) / dc, c / dc)
            } else if dc < 0.0 {
                (-1, ta + (k as f64 * c - p) / dc, -c / dc)
            } else {
                (0, f64::INFINITY, f64::INFINITY)
            }
        };
        let (si, mut next_x, dx) = axis(px, d[0], i);
        let (sj, mut next_y, dy) = axis(py, d[1], j);
        let mut t_in = ta;
        loop {
            let t_out = next_x.min(next_y).min(tb);
            let k = (j * n + i) as usize;
            let mut best: Option<(f64, u32)> = None;
            let (a, b) = (self.start[k] as usize, self.start[k + 1] as usize);
            let list = if d[2] < 0.0 {
                &self.down[a..b]
            } else {
                &self.up[a..b]
            };
            for &idx in list {
                if let Some((tb, _)) = best {
                    // Discs further in the list lie wholly beyond the best hit's height.
                    let zb = o[2] + d[2] * tb;
                    let (lo, hi) = self.z_range[idx as usize];
                    if (d[2] < 0.0 && hi < zb) || (d[2] > 0.0 && lo > zb) {
                        break;
                    }
                }
                if let Some((t, _)) = discs[idx as usize].intersect_v(&ov, &dv) {
                    // Slack of 1e-9 µm at the cell's faces: a hit on a face is found in
                    // either cell.
                    if t >= t_in - 1e-9 && t <= t_out + 1e-9 && best.is_none_or(|b| t < b.0) {
                        best = Some((t, idx));
                    }
                }
            }
            if best.is_some() || t_out >= tb {
                return best;
            }
            if next_x <= next_y {
                i += si;
                next_x += dx;
            } else {
                j += sj;
                next_y += dy;
            }
            if i < 0 || j < 0 || i >= n || j >= n {
                return None;
            }
            t_in = t_out;
        }
    }
}
