//! A bounding volume hierarchy over axis-aligned boxes: binary, built with the binned surface
//! area heuristic (SAH), flattened depth-first, traversed front to back with a small stack.
//! The hierarchy knows only the primitives' boxes; the caller intersects the primitives of a
//! leaf (triangles of a scene, discs of the paint's flakes, the triangles of the octree's
//! baseline), so one structure serves every primitive type.

use nalgebra::Vector3;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vector3<f64>,
    /// Upper corner.
    pub max: Vector3<f64>,
}

impl Aabb {
    /// The empty box (the identity of [`Aabb::union`]).
    pub fn empty() -> Self {
        Self {
            min: Vector3::repeat(f64::INFINITY),
            max: Vector3::repeat(f64::NEG_INFINITY),
        }
    }

    /// The smallest box holding both.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            min: self.min.inf(&o.min),
            max: self.max.sup(&o.max),
        }
    }

    /// Centre of the box.
    pub fn centre(&self) -> Vector3<f64> {
        (self.min + self.max) * 0.5
    }

    /// Surface area (0 for an empty box).
    pub fn area(&self) -> f64 {
        let e = self.max - self.min;
        if e.iter().any(|v| *v < 0.0) {
            return 0.0;
        }
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Entry and exit parameters of the ray `o + t d` (`inv_d = 1 / d` per component) within
    /// `[0, t_max]`, or `None` when it misses.
    #[inline]
    pub fn slab(&self, o: &Vector3<f64>, inv_d: &Vector3<f64>, t_max: f64) -> Option<f64> {
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
    pub fn nearest<F>(
        &self,
        o: &Vector3<f64>,
        d: &Vector3<f64>,
        t_max: f64,
        hit: F,
    ) -> Option<(u32, f64)>
    where
        F: FnMut(u32, f64) -> Option<f64>,
    {
        self.traverse(o, d, t_max, hit, false)
    }

    /// Any primitive hit along `o + t d` with `0 < t <= t_max` (a shadow ray): the traversal
    /// stops at the first hit found.
    pub fn any<F>(&self, o: &Vector3<f64>, d: &Vector3<f64>, t_max: f64, hit: F) -> bool
    where
        F: FnMut(u32, f64) -> Option<f64>,
    {
        self.traverse(o, d, t_max, hit, true).is_some()
    }

    fn traverse<F>(
        &self,
        o: &Vector3<f64>,
        d: &Vector3<f64>,
        t_max: f64,
        mut hit: F,
        first: bool,
    ) -> Option<(u32, f64)>
    where
        F: FnMut(u32, f64) -> Option<f64>,
    {
        let ray = SlabRay {
            o: [o.x, o.y, o.z],
            inv: [1.0 / d.x, 1.0 / d.y, 1.0 / d.z],
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
    centres: Vec<Vector3<f64>>,
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
            min: [bounds.min.x, bounds.min.y, bounds.min.z],
            max: [bounds.max.x, bounds.max.y, bounds.max.z],
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
fn sah_split(boxes: &[Aabb], centres: &[Vector3<f64>], order: &mut [u32]) -> Option<usize> {
    let cb = order.iter().fold(Aabb::empty(), |b, &i| {
        let c = centres[i as usize];
        b.union(&Aabb { min: c, max: c })
    });
    let ext = cb.max - cb.min;
    let bin_of = |i: u32, axis: usize| -> usize {
        let f = (centres[i as usize][axis] - cb.min[axis]) / ext[axis];
        ((f * BINS as f64) as usize).min(BINS - 1)
    };
    // (cost, axis, last bin of the left part)
    let mut best = (f64::INFINITY, 0usize, 0usize);
    for axis in 0..3 {
        if ext[axis] <= 0.0 {
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
    use rand::{Rng, SeedableRng};

    /// Nearest hit among spheres by brute force equals the hierarchy's answer.
    #[test]
    fn nearest_matches_brute_force() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let spheres: Vec<(Vector3<f64>, f64)> = (0..500)
            .map(|_| {
                (
                    Vector3::new(rng.random(), rng.random(), rng.random()) * 10.0,
                    rng.random_range(0.05..0.6),
                )
            })
            .collect();
        let boxes: Vec<Aabb> = spheres
            .iter()
            .map(|(c, r)| Aabb {
                min: c - Vector3::repeat(*r),
                max: c + Vector3::repeat(*r),
            })
            .collect();
        let bvh = Bvh::build(&boxes, 4);
        let sphere_hit = |o: &Vector3<f64>, d: &Vector3<f64>, i: usize| -> Option<f64> {
            let (c, r) = spheres[i];
            let oc = o - c;
            let b = oc.dot(d);
            let disc = b * b - (oc.norm_squared() - r * r);
            if disc < 0.0 {
                return None;
            }
            let t = -b - disc.sqrt();
            (t > 0.0).then_some(t)
        };
        for _ in 0..2000 {
            let o = Vector3::new(rng.random(), rng.random(), rng.random()) * 12.0
                - Vector3::repeat(1.0);
            let d = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize();
            let brute = (0..spheres.len())
                .filter_map(|i| {
                    sphere_hit(&o, &d, i)
                        .filter(|t| *t <= 8.0)
                        .map(|t| (i as u32, t))
                })
                .min_by(|a, b| a.1.total_cmp(&b.1));
            let fast = bvh.nearest(&o, &d, 8.0, |i, tb| {
                sphere_hit(&o, &d, i as usize).filter(|t| *t <= tb)
            });
            assert_eq!(brute.map(|b| b.0), fast.map(|f| f.0));
            let any = bvh.any(&o, &d, 8.0, |i, tb| {
                sphere_hit(&o, &d, i as usize).filter(|t| *t <= tb)
            });
            assert_eq!(any, brute.is_some());
        }
        assert_eq!(bvh.len(), 500);
        assert!(Bvh::build(&[], 4)
            .nearest(&Vector3::zeros(), &Vector3::z(), 1.0, |_, _| Some(0.5))
            .is_none());
    }
}
