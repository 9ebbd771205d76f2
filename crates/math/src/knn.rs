//! Nearest neighbours of 3-D points: a static, balanced kd-tree (median splits on the axis of
//! largest spread, built in parallel) with exact k-nearest and nearest-point queries.
//!
//! Used by the mesh filters (the k-nearest-vertex graph of a mesh), the error metrics
//! (nearest ground-truth vertex) and anything else that needs exact Euclidean neighbours.
//! The points are stored in tree order so that a leaf is one contiguous run, nodes in
//! pre-order so that a left child follows its parent, and the search prunes with the
//! incremental distance to a cell (Arya and Mount) against the current k-th candidate. Ties
//! are broken by point index, so results do not depend on the traversal.
//!
//! The k nearest neighbours of *every* point of a set at once are
//! [`knn_graph`](crate::knn_graph::knn_graph), on a uniform grid.

use rayon::prelude::*;

use crate::error::{ensure_finite, Error, Result};
use crate::kbest::Best;
use crate::vec3::dist2;

/// Leaves hold at most this many points.
const LEAF: usize = 8;
/// Subtrees with more points than this are built in parallel.
const PAR_BUILD: usize = 1 << 12;
/// `axis` of a leaf node.
const LEAF_AXIS: u32 = 3;
/// "No point excluded".
const NONE: u32 = u32::MAX;

/// A node: a split (`axis` 0..3 at `value`, right child `right`; the left child is the next
/// node) or a leaf (points `start..end` in tree order).
#[derive(Clone, Copy, Debug)]
struct Node {
    value: f64,
    axis: u32,
    right: u32,
    start: u32,
    end: u32,
}

/// A kd-tree over a fixed set of points.
#[derive(Clone, Debug)]
pub struct KdTree {
    /// The points in tree order.
    points: Vec<[f64; 3]>,
    /// Original index of every point in tree order.
    ids: Vec<u32>,
    nodes: Vec<Node>,
}

/// Nodes of the tree over `m` points.
fn node_count(m: usize) -> usize {
    if m <= LEAF {
        1
    } else {
        1 + node_count(m / 2) + node_count(m - m / 2)
    }
}

/// Builds the subtree over `ids` (tree-order positions `start..`) into `nodes`, whose first
/// entry has global index `base`.
fn build(pts: &[[f64; 3]], ids: &mut [u32], nodes: &mut [Node], base: usize, start: usize) {
    let m = ids.len();
    if m <= LEAF {
        nodes[0] = Node {
            value: 0.0,
            axis: LEAF_AXIS,
            right: 0,
            start: start as u32,
            end: (start + m) as u32,
        };
        return;
    }
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for &i in ids.iter() {
        let p = pts[i as usize];
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let mid = m / 2;
    ids.select_nth_unstable_by(mid, |&a, &b| {
        pts[a as usize][axis].total_cmp(&pts[b as usize][axis])
    });
    let value = pts[ids[mid] as usize][axis];
    let nl = node_count(mid);
    let (head, rest) = nodes.split_at_mut(1);
    let (left_nodes, right_nodes) = rest.split_at_mut(nl);
    head[0] = Node {
        value,
        axis: axis as u32,
        right: (base + 1 + nl) as u32,
        start: 0,
        end: 0,
    };
    let (left_ids, right_ids) = ids.split_at_mut(mid);
    if m > PAR_BUILD {
        rayon::join(
            || build(pts, left_ids, left_nodes, base + 1, start),
            || build(pts, right_ids, right_nodes, base + 1 + nl, start + mid),
        );
    } else {
        build(pts, left_ids, left_nodes, base + 1, start);
        build(pts, right_ids, right_nodes, base + 1 + nl, start + mid);
    }
}

impl KdTree {
    /// Builds the tree. Errors: no points, non-finite coordinates, more than `u32::MAX - 1`
    /// points.
    pub fn new(points: &[[f64; 3]]) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::Empty("points"));
        }
        if points.len() >= NONE as usize {
            return Err(Error::invalid("points", "too many for a kd-tree"));
        }
        ensure_finite("points", points.as_flattened())?;
        let n = points.len();
        let mut ids: Vec<u32> = (0..n as u32).collect();
        let mut nodes = vec![
            Node {
                value: 0.0,
                axis: LEAF_AXIS,
                right: 0,
                start: 0,
                end: 0,
            };
            node_count(n)
        ];
        build(points, &mut ids, &mut nodes, 0, 0);
        let sorted = ids.par_iter().map(|&i| points[i as usize]).collect();
        Ok(Self {
            points: sorted,
            ids,
            nodes,
        })
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the tree is empty (never: construction needs a point).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Fills `best` with the nearest points to `q` other than `exclude` (an original index).
    fn search(&self, q: &[f64; 3], exclude: u32, best: &mut Best) {
        best.clear();
        if best.k > 0 {
            self.descend(0, q, 0.0, &mut [0.0; 3], exclude, best);
        }
    }

    fn descend(
        &self,
        node: usize,
        q: &[f64; 3],
        rd: f64,
        off: &mut [f64; 3],
        exclude: u32,
        best: &mut Best,
    ) {
        let n = self.nodes[node];
        if n.axis == LEAF_AXIS {
            let (s, e) = (n.start as usize, n.end as usize);
            for (p, &id) in self.points[s..e].iter().zip(&self.ids[s..e]) {
                let d2 = dist2(*p, *q);
                if d2 <= best.bound() && id != exclude {
                    best.offer(d2, id);
                }
            }
            return;
        }
        let a = n.axis as usize;
        let d = q[a] - n.value;
        let (near, far) = if d < 0.0 {
            (node + 1, n.right as usize)
        } else {
            (n.right as usize, node + 1)
        };
        self.descend(near, q, rd, off, exclude, best);
        let old = off[a];
        let rd_far = rd - old * old + d * d;
        if rd_far <= best.bound() {
            off[a] = d;
            self.descend(far, q, rd_far, off, exclude, best);
            off[a] = old;
        }
    }

    /// The `k` points nearest to `q` as `(index, distance)`, nearest first (ties by index),
    /// leaving out the point `exclude` if given. Fewer than `k` when the tree is smaller.
    pub fn knn(&self, q: &[f64; 3], k: usize, exclude: Option<usize>) -> Vec<(usize, f64)> {
        let mut best = Best::new(k);
        self.search(q, exclude.map_or(NONE, |e| e as u32), &mut best);
        best.items
            .iter()
            .map(|&(d2, i)| (i as usize, d2.sqrt()))
            .collect()
    }

    /// The point nearest to `q`: `(index, distance)`.
    pub fn nearest(&self, q: &[f64; 3]) -> (usize, f64) {
        let mut best = Best::new(1);
        self.search(q, NONE, &mut best);
        let (d2, i) = best.items[0];
        (i as usize, d2.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knn_matches_brute_force() {
        let u = crate::rng::uniform_vec(3, 3 * 2000, -1.0, 1.0).unwrap();
        // Clustered and duplicated points too.
        let mut pts: Vec<[f64; 3]> = u.chunks(3).map(|c| [c[0], c[1] * 0.1, c[2]]).collect();
        pts.extend_from_within(..50);
        let tree = KdTree::new(&pts).unwrap();
        let q = crate::rng::uniform_vec(4, 3 * 200, -1.2, 1.2).unwrap();
        for (j, c) in q.chunks(3).enumerate() {
            let p = [c[0], c[1] * 0.1, c[2]];
            let exclude = (j % 2 == 0).then_some(j);
            let mut brute: Vec<(usize, f64)> = pts
                .iter()
                .enumerate()
                .filter(|(i, _)| Some(*i) != exclude)
                .map(|(i, x)| (i, dist2(*x, p).sqrt()))
                .collect();
            brute.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            let got = tree.knn(&p, 12, exclude);
            assert_eq!(got.len(), 12);
            for (g, b) in got.iter().zip(&brute) {
                assert!((g.1 - b.1).abs() < 1e-15, "{g:?} vs {b:?}");
            }
            assert_eq!(tree.nearest(&p).1, brute_nearest(&pts, &p));
        }
        assert_eq!(tree.knn(&[0.0; 3], 5000, None).len(), pts.len());
        assert!(KdTree::new(&[]).is_err());
        assert!(KdTree::new(&[[0.0, f64::NAN, 0.0]]).is_err());
    }

    fn brute_nearest(pts: &[[f64; 3]], p: &[f64; 3]) -> f64 {
        pts.iter()
            .map(|x| dist2(*x, *p).sqrt())
            .fold(f64::INFINITY, f64::min)
    }
}
