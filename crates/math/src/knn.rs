//! Nearest neighbours of 3-D points: a static, balanced kd-tree (median splits on the axis of
//! largest spread) with exact k-nearest and nearest-point queries.
//!
//! Used by the mesh filters (k-nearest vertices), the error metrics (nearest ground-truth
//! vertex) and anything else that needs exact Euclidean neighbours. Queries are independent
//! and can run in parallel over one tree.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::error::{Error, Result};
use crate::vec3::dist2;

/// Leaves hold at most this many points.
const LEAF: usize = 8;

#[derive(Clone, Debug)]
enum Node {
    Leaf {
        start: usize,
        end: usize,
    },
    Split {
        axis: usize,
        value: f64,
        left: usize,
        right: usize,
    },
}

/// A kd-tree over a fixed set of points.
#[derive(Clone, Debug)]
pub struct KdTree {
    points: Vec<[f64; 3]>,
    /// Point indices, grouped by leaf.
    order: Vec<usize>,
    nodes: Vec<Node>,
}

/// A candidate of a k-nearest query (squared distance, index): the scratch heap of
/// [`KdTree::knn_indices`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cand(f64, usize);

impl Eq for Cand {}
impl PartialOrd for Cand {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Cand {
    fn cmp(&self, o: &Self) -> Ordering {
        self.0.total_cmp(&o.0).then(self.1.cmp(&o.1))
    }
}

impl KdTree {
    /// Builds the tree. Errors: no points, non-finite coordinates.
    pub fn new(points: &[[f64; 3]]) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::Empty("points"));
        }
        if let Some(i) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(Error::NonFinite {
                name: "points",
                index: 3 * i,
            });
        }
        let mut t = Self {
            points: points.to_vec(),
            order: (0..points.len()).collect(),
            nodes: Vec::new(),
        };
        t.build(0, points.len());
        Ok(t)
    }

    fn build(&mut self, start: usize, end: usize) -> usize {
        let id = self.nodes.len();
        if end - start <= LEAF {
            self.nodes.push(Node::Leaf { start, end });
            return id;
        }
        let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
        for &i in &self.order[start..end] {
            for a in 0..3 {
                lo[a] = lo[a].min(self.points[i][a]);
                hi[a] = hi[a].max(self.points[i][a]);
            }
        }
        let axis = (0..3)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap_or(0);
        let mid = (start + end) / 2;
        let pts = &self.points;
        self.order[start..end]
            .select_nth_unstable_by(mid - start, |&a, &b| pts[a][axis].total_cmp(&pts[b][axis]));
        let value = self.points[self.order[mid]][axis];
        self.nodes.push(Node::Leaf { start, end });
        let left = self.build(start, mid);
        let right = self.build(mid, end);
        self.nodes[id] = Node::Split {
            axis,
            value,
            left,
            right,
        };
        id
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the tree is empty (never: construction needs a point).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The `k` points nearest to `q` as `(index, distance)`, nearest first (ties by index),
    /// leaving out the point `exclude` if given. Fewer than `k` when the tree is smaller.
    pub fn knn(&self, q: &[f64; 3], k: usize, exclude: Option<usize>) -> Vec<(usize, f64)> {
        if k == 0 {
            return Vec::new();
        }
        let mut heap = BinaryHeap::with_capacity(k + 1);
        self.search(0, q, k, exclude, &mut heap);
        let mut out: Vec<(usize, f64)> = heap.into_iter().map(|c| (c.1, c.0.sqrt())).collect();
        out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        out
    }

    fn search(
        &self,
        node: usize,
        q: &[f64; 3],
        k: usize,
        exclude: Option<usize>,
        heap: &mut BinaryHeap<Cand>,
    ) {
        match self.nodes[node] {
            Node::Leaf { start, end } => {
                for &i in &self.order[start..end] {
                    if Some(i) == exclude {
                        continue;
                    }
                    let c = Cand(dist2(self.points[i], *q), i);
                    if heap.len() < k {
                        heap.push(c);
                    } else if c < *heap.peek().expect("k > 0") {
                        heap.pop();
                        heap.push(c);
                    }
                }
            }
            Node::Split {
                axis,
                value,
                left,
                right,
            } => {
                let d = q[axis] - value;
                let (near, far) = if d < 0.0 {
                    (left, right)
                } else {
                    (right, left)
                };
                self.search(near, q, k, exclude, heap);
                if heap.len() < k || d * d <= heap.peek().expect("non-empty").0 {
                    self.search(far, q, k, exclude, heap);
                }
            }
        }
    }

    /// The indices of the `k` points nearest to `q` (leaving out `exclude`), in no particular
    /// order, written to `out` (cleared first); `heap` is scratch space reused across calls.
    pub fn knn_indices(
        &self,
        q: &[f64; 3],
        k: usize,
        exclude: Option<usize>,
        heap: &mut BinaryHeap<Cand>,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        heap.clear();
        if k == 0 {
            return;
        }
        self.search(0, q, k, exclude, heap);
        out.extend(heap.drain().map(|c| c.1 as u32));
    }

    /// The point nearest to `q`: `(index, distance)`.
    pub fn nearest(&self, q: &[f64; 3]) -> (usize, f64) {
        self.knn(q, 1, None)[0]
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
        // The unsorted variant returns the same set.
        let (mut heap, mut out) = (BinaryHeap::new(), Vec::new());
        let p = [0.1, 0.0, -0.3];
        tree.knn_indices(&p, 12, Some(7), &mut heap, &mut out);
        let mut a: Vec<u32> = tree
            .knn(&p, 12, Some(7))
            .iter()
            .map(|x| x.0 as u32)
            .collect();
        a.sort_unstable();
        out.sort_unstable();
        assert_eq!(a, out);
        assert!(KdTree::new(&[]).is_err());
        assert!(KdTree::new(&[[0.0, f64::NAN, 0.0]]).is_err());
    }

    fn brute_nearest(pts: &[[f64; 3]], p: &[f64; 3]) -> f64 {
        pts.iter()
            .map(|x| dist2(*x, *p).sqrt())
            .fold(f64::INFINITY, f64::min)
    }
}
