//! A bounding volume hierarchy over axis-aligned boxes: binary, built with the binned surface
//! area heuristic (SAH), flattened depth-first, traversed front to back with a small stack.
//! The hierarchy knows only the primitives' boxes; the caller intersects the primitives of a
//! leaf (triangles of a scene, discs of the paint's flakes, the triangles of the octree's
//! baseline), so one structure serves every primitive type.

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
}

impl Aabb {
    /// The empty box (the identity of [`Aabb::union`]).
    pub fn empty() -> Self {
        Self {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        }
    }

    /// The smallest box holding `points` (the empty box for none).
    #[inline]
    pub fn around(points: &[[f64; 3]]) -> Aabb {
        points
            .iter()
            .fold(Aabb::empty(), |b, &p| b.union(&Aabb { min: p, max: p }))
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, o: &Aabb) -> Aabb {
        // `<=` and `>=` compile to one min/max instruction per component (`f64::min` and
        // `f64::max` also look for NaN).
        let lo = |a: f64, b: f64| if a <= b { a } else { b };
        let hi = |a: f64, b: f64| if a >= b { a } else { b };
        let (a, b) = (self, o);
        Aabb {
            min: [
                lo(a.min[0], b.min[0]),
                lo(a.min[1], b.min[1]),
                lo(a.min[2], b.min[2]),
            ],
            max: [
                hi(a.max[0], b.max[0]),
                hi(a.max[1], b.max[1]),
                hi(a.max[2], b.max[2]),
            ],
        }
    }

    /// Centre of the box.
    #[inline]
    pub fn centre(&self) -> [f64; 3] {
        let (a, b) = (self.min, self.max);
        [
            0.5 * (a[0] + b[0]),
            0.5 * (a[1] + b[1]),
            0.5 * (a[2] + b[2]),
        ]
    }

    /// Edge lengths, `max - min` (negative for the empty box).
    #[inline]
    pub fn extent(&self) -> [f64; 3] {
        let (a, b) = (self.min, self.max);
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
    }

    /// Length of the diagonal (0 for an empty box).
    pub fn diagonal(&self) -> f64 {
        let e = self.extent();
        if e.iter().any(|v| *v < 0.0) {
            return 0.0;
        }
        (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
    }

    /// Surface area (0 for an empty box).
    pub fn area(&self) -> f64 {
        let e = self.extent();
        if e.iter().any(|v| *v < 0.0) {
            return 0.0;
        }
        2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0])
    }

    /// Entry and exit parameters of the ray `o + t d` (`inv_d = 1 / d` per component) within
    /// `[0, t_max]`, or `None` when it misses.
    #[inline]
    pub fn slab(&self, o: [f64; 3], inv_d: [f64; 3], t_max: f64) -> Option<f64> {
        let mut t0 = 0.0f64;
        let mut t1 = t_max;
        for k in 0..3 {
            let a = (self.min[k] - o[k]) * inv_d[k];
            let b = (self.max[k] - o[k]) * inv_d[k];
            let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
            // NaN (0 * inf on a slab boundary) leaves the interval unchanged.
            if lo > t0 {
                t0 = lo;
            }
            if hi < t1 {
                t1 = hi;
            }
            if t0 > t1 {
                return None;
            }
        }
        Some(t0)
    }
}

#[derive(Clone, Copy, Debug)]
struct Node {
    min: [f64; 3],
    max: [f64; 3],
    /// Leaf: first index into `order`; inner: index of the second child (the first child
    /// follows its parent).
    offset: u32,
    /// Primitives in a leaf; 0 for an inner node.
    count: u32,
}

/// The hierarchy.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

const BINS: usize = 12;
/// Most levels of the tree (the traversal stack holds one entry per level).
const MAX_DEPTH: usize = 64;

impl Bvh {
    /// Builds the hierarchy over `boxes` (primitive `i` has box `boxes[i]`) with at most
    /// `leaf_size` primitives per leaf where the SAH allows it.
    pub fn build(boxes: &[Aabb], leaf_size: usize) -> Self {
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let mut b = Builder {
            boxes,
            centres: boxes.iter().map(Aabb::centre).collect(),
            leaf_size: leaf_size.max(1),
            nodes: Vec::with_capacity(2 * boxes.len().max(1)),
        };
        if !boxes.is_empty() {
            b.node(&mut order, 0, boxes.len(), 0);
        }
        let nodes = b.nodes;
        Self { nodes, order }
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether the hierarchy holds no primitive.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// The nearest primitive hit along `o + t d` with `0 < t <= t_max`. `hit(i, t_best)`
    /// intersects primitive `i` and returns its hit parameter when it is below `t_best`.
    pub fn nearest<F>(&self, o: [f64; 3], d: [f64; 3], t_max: f64, hit: F) -> Option<(u32, f64)>
    where
        F: FnMut(u32, f64) -> Option<f64>,
    {
        self.traverse(o, d, t_max, hit, false)
    }

    /// Any primitive hit along `o + t d` with `0 < t <= t_max` (a shadow ray): the traversal
    /// stops at the first hit found.
    pub fn any<F>(&self, o: [f64; 3], d: [f64; 3], t_max: f64, hit: F) -> bool
    where
        F: FnMut(u32, f64) -> Option<f64>,
    {
        self.traverse(o, d, t_max, hit, true).is_some()
    }

    fn traverse<F>(
        &self,
        o: [f64; 3],
        d: [f64; 3],
        t_max: f64,
        mut hit: F,
        first: bool,
    ) -> Option<(u32, f64)>
    where
        F: FnMut(u32, f64) -> Option<f64>,
    {
        let ray = SlabRay {
            o,
            inv: d.map(|c| 1.0 / c),
        };
        let mut best: Option<(u32, f64)> = None;
        let mut t_best = t_max;
        // Subtrees still to visit, with the parameter at which the ray enters them.
        let mut stack = [(0u32, 0.0f64); MAX_DEPTH];
        let mut sp = 0usize;
        let root = self.nodes.first()?;
        if ray.entry(root, t_best).is_infinite() {
            return None;
        }
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            if n.count > 0 {
                for &p in &self.order[n.offset as usize..(n.offset + n.count) as usize] {
                    if let Some(t) = hit(p, t_best) {
                        if t < t_best {
                            t_best = t;
                            best = Some((p, t));
                            if first {
                                return best;
                            }
                        }
                    }
                }
            } else {
                let (a, b) = (node + 1, n.offset);
                let ta = ray.entry(&self.nodes[a as usize], t_best);
                let tb = ray.entry(&self.nodes[b as usize], t_best);
                let (near, tn, far, tf) = if ta <= tb {
                    (a, ta, b, tb)
                } else {
                    (b, tb, a, ta)
                };
                if tn.is_finite() {
                    if tf.is_finite() {
                        stack[sp] = (far, tf);
                        sp += 1;
                    }
                    node = near;
                    continue;
                }
            }
            // Pop the next subtree that the ray enters before the best hit.
            loop {
                if sp == 0 {
                    return best;
                }
                sp -= 1;
                let (c, t) = stack[sp];
                if t <= t_best {
                    node = c;
                    break;
                }
            }
        }
    }
}

/// A ray prepared for box tests.
struct SlabRay {
    o: [f64; 3],
    inv: [f64; 3],
}

impl SlabRay {
    /// Parameter at which the ray enters the node's box within `[0, t_max]`, or infinity.
    #[inline(always)]
    fn entry(&self, n: &Node, t_max: f64) -> f64 {
        let mut t0 = 0.0f64;
        let mut t1 = t_max;
        for k in 0..3 {
            let a = (n.min[k] - self.o[k]) * self.inv[k];
            let b = (n.max[k] - self.o[k]) * self.inv[k];
            // `min`/`max` ignore a NaN (0 * inf on a slab's plane).
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        if t0 <= t1 {
            t0
        } else {
            f64::INFINITY
        }
    }
}

/// What the recursive build shares.
struct Builder<'a> {
    boxes: &'a [Aabb],
    centres: Vec<[f64; 3]>,
    leaf_size: usize,
    nodes: Vec<Node>,
}

impl Builder<'_> {
    /// Builds the subtree of `order[lo..hi]` at `depth`, returning its node index.
    fn node(&mut self, order: &mut [u32], lo: usize, hi: usize, depth: usize) -> u32 {
        let bounds = order[lo..hi]
            .iter()
            .fold(Aabb::empty(), |b, &i| b.union(&self.boxes[i as usize]));
        let me = self.nodes.len() as u32;
        self.nodes.push(Node {
            min: bounds.min,
            max: bounds.max,
            offset: lo as u32,
            count: (hi - lo) as u32,
        });
        let n = hi - lo;
        // The depth stays below the traversal stack's size: deeper ranges become leaves.
        if n <= self.leaf_size || depth + 1 >= MAX_DEPTH {
            return me;
        }
        let split = sah_split(self.boxes, &self.centres, &mut order[lo..hi]).unwrap_or(n / 2);
        if split == 0 || split == n {
            return me;
        }
        let mid = lo + split;
        self.node(order, lo, mid, depth + 1);
        let right = self.node(order, mid, hi, depth + 1);
        self.nodes[me as usize].offset = right;
        self.nodes[me as usize].count = 0;
        me
    }
}

/// Partitions `order` by the best binned SAH plane over the three axes and returns the size
/// of the left part, or `None` when the centres coincide.
fn sah_split(boxes: &[Aabb], centres: &[[f64; 3]], order: &mut [u32]) -> Option<usize> {
    let cb = order.iter().fold(Aabb::empty(), |b, &i| {
        let c = centres[i as usize];
        b.union(&Aabb { min: c, max: c })
    });
    let ext = cb.extent();
    let bin_of = |i: u32, axis: usize| -> usize {
        let f = (centres[i as usize][axis] - cb.min[axis]) / ext[axis];
        ((f * BINS as f64) as usize).min(BINS - 1)
    };
    // (cost, axis, last bin of the left part)
    let mut best = (f64::INFINITY, 0usize, 0usize);
    for (axis, &e) in ext.iter().enumerate() {
        if e <= 0.0 {
            continue;
        }
        let mut counts = [0usize; BINS];
        let mut bb = [Aabb::empty(); BINS];
        for &i in order.iter() {
            let b = bin_of(i, axis);
            counts[b] += 1;
            bb[b] = bb[b].union(&boxes[i as usize]);
        }
        // Sweep from the right to get the right-hand areas, then from the left.
        let mut right_area = [0.0; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc, mut cnt) = (Aabb::empty(), 0usize);
        for b in (1..BINS).rev() {
            acc = acc.union(&bb[b]);
            cnt += counts[b];
            right_area[b] = acc.area();
            right_count[b] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::empty(), 0usize);
        for b in 0..BINS - 1 {
            acc = acc.union(&bb[b]);
            cnt += counts[b];
            if cnt == 0 || right_count[b + 1] == 0 {
                continue;
            }
            let cost = acc.area() * cnt as f64 + right_area[b + 1] * right_count[b + 1] as f64;
            if cost < best.0 {
                best = (cost, axis, b);
            }
        }
    }
    if !best.0.is_finite() {
        return None;
    }
    let (_, axis, last) = best;
    let mut left = 0;
    for k in 0..order.len() {
        if bin_of(order[k], axis) <= last {
            order.swap(k, left);
            left += 1;
        }
    }
    Some(left)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vec3::{dot, normalized_or_zero, sub};
    use rand::{Rng, SeedableRng};

    /// Nearest hit among spheres by brute force equals the hierarchy's answer.
    #[test]
    fn nearest_matches_brute_force() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let spheres: Vec<([f64; 3], f64)> = (0..500)
            .map(|_| {
                (
                    [0; 3].map(|_| rng.random::<f64>() * 10.0),
                    rng.random_range(0.05..0.6),
                )
            })
            .collect();
        let boxes: Vec<Aabb> = spheres
            .iter()
            .map(|(c, r)| Aabb {
                min: c.map(|v| v - r),
                max: c.map(|v| v + r),
            })
            .collect();
        let bvh = Bvh::build(&boxes, 4);
        let sphere_hit = |o: [f64; 3], d: [f64; 3], i: usize| -> Option<f64> {
            let (c, r) = spheres[i];
            let oc = sub(o, c);
            let b = dot(oc, d);
            let disc = b * b - (dot(oc, oc) - r * r);
            if disc < 0.0 {
                return None;
            }
            let t = -b - disc.sqrt();
            (t > 0.0).then_some(t)
        };
        for _ in 0..2000 {
            let o = [0; 3].map(|_| rng.random::<f64>() * 12.0 - 1.0);
            let d = normalized_or_zero([0; 3].map(|_| rng.random_range(-1.0..1.0)));
            let brute = (0..spheres.len())
                .filter_map(|i| {
                    sphere_hit(o, d, i)
                        .filter(|t| *t <= 8.0)
                        .map(|t| (i as u32, t))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let fast = bvh.nearest(o, d, 8.0, |i, tb| {
                sphere_hit(o, d, i as usize).filter(|t| *t <= tb)
            });
            assert_eq!(brute.map(|b| b.0), fast.map(|f| f.0));
            let any = bvh.any(o, d, 8.0, |i, tb| {
                sphere_hit(o, d, i as usize).filter(|t| *t <= tb)
            });
            assert_eq!(any, brute.is_some());
        }
        assert_eq!(bvh.len(), 500);
        assert!(Bvh::build(&[], 4)
            .nearest([0.0; 3], [0.0, 0.0, 1.0], 1.0, |_, _| Some(0.5))
            .is_none());

        // The box helpers.
        let b = Aabb::around(&[[1.0, -2.0, 0.5], [-1.0, 2.0, 2.5]]);
        assert_eq!(b.min, [-1.0, -2.0, 0.5]);
        assert_eq!(b.max, [1.0, 2.0, 2.5]);
        assert_eq!(b.centre(), [0.0, 0.0, 1.5]);
        assert_eq!(b.extent(), [2.0, 4.0, 2.0]);
        assert!((b.diagonal() - 24f64.sqrt()).abs() < 1e-15);
        assert_eq!(b.area(), 2.0 * (8.0 + 8.0 + 4.0));
        assert_eq!(Aabb::empty().diagonal(), 0.0);
        assert_eq!(Aabb::around(&[]), Aabb::empty());
        // The ray along +x through the box enters at x = -1.
        assert_eq!(
            b.slab([-3.0, 0.0, 1.0], [1.0, f64::INFINITY, f64::INFINITY], 10.0),
            Some(2.0)
        );
        assert_eq!(
            b.slab([-3.0, 5.0, 1.0], [1.0, f64::INFINITY, f64::INFINITY], 10.0),
            None
        );
    }
}
