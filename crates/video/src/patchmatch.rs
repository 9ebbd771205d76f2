//! PatchMatch nearest-neighbour fields and patch voting on a space-time grid `(t, y, x)`
//! (an image is the grid with one frame).
//!
//! PatchMatch (Barnes et al. 2009; in space-time as in Newson et al. 2014): every target keeps
//! its best source so far; an iteration tries, for every target, the sources its grid
//! neighbours `+-t`, `+-y`, `+-x` found (shifted back by the same step: *propagation*) and
//! random sources around its own match in windows of halving radius (*random search*).
//! Here an iteration updates all targets at once from the previous iteration's field (Jacobi
//! order): the targets are processed in parallel, and with a per-target random stream the
//! result does not depend on the thread count.
//!
//! What a patch *is*, which sources are valid and how two patches compare is the caller's
//! [`PatchSpace`]: the completion stages compare RGB cubes of the video ([`crate::patch`]).
//!
//! Voting ([`vote`]): the value of a pixel is the weighted mean of what every target patch
//! covering it proposes there (Wexler et al. 2007).

use rand::Rng as _;
use rayon::prelude::*;

use wscg_math::rng;

/// A grid position `(t, y, x)`.
pub type P3 = [u32; 3];

/// The patches of a grid: which centres are valid sources and how far a target patch is
/// from a source patch.
pub trait PatchSpace: Sync {
    /// Grid extents `(frames, height, width)`.
    fn dims(&self) -> [usize; 3];
    /// Whether `s` may be used as a source centre.
    fn is_source(&self, s: P3) -> bool;
    /// The distance of the target patch at `t` to the source patch at `s` (a valid source).
    /// May stop early and return any value `>= bound` once the distance exceeds `bound`.
    fn distance(&self, t: P3, s: P3, bound: f32) -> f32;
}

/// A match: source centre and its distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Match {
    /// Source centre.
    pub source: P3,
    /// Patch distance to the target.
    pub dist: f32,
}

wscg_math::params! {
    /// Parameters of [`patchmatch`].
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub struct PatchMatchParams {
        /// Iterations (each: propagation and random search for every target).
        pub iterations: usize,
        /// Seed of the random search.
        pub seed: u64,
        /// Largest random-search radius per axis `(t, y, x)`; `None`: the grid extents.
        pub max_radius: Option<[u32; 3]>,
    }
}

impl Default for PatchMatchParams {
    fn default() -> Self {
        Self {
            iterations: 5,
            seed: 0,
            max_radius: None,
        }
    }
}

/// Row-major linear index of `p` in a grid of `dims`.
pub fn linear(dims: [usize; 3], p: P3) -> u64 {
    ((p[0] as u64 * dims[1] as u64) + p[1] as u64) * dims[2] as u64 + p[2] as u64
}

/// The position of row-major linear index `i`.
pub fn position(dims: [usize; 3], i: u64) -> P3 {
    let (w, h) = (dims[2] as u64, dims[1] as u64);
    [(i / (w * h)) as u32, ((i / w) % h) as u32, (i % w) as u32]
}

/// A sorted set of grid positions with `O(log n)` lookup of a position's rank: the targets of
/// a field, so that a target finds its grid neighbours' matches.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TargetSet {
    dims: [usize; 3],
    keys: Vec<u64>,
}

impl TargetSet {
    /// The set of `points` (any order, duplicates removed) in a grid of `dims`.
    pub fn new(dims: [usize; 3], points: impl IntoIterator<Item = P3>) -> Self {
        let mut keys: Vec<u64> = points.into_iter().map(|p| linear(dims, p)).collect();
        keys.par_sort_unstable();
        keys.dedup();
        Self { dims, keys }
    }

    /// Number of targets.
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// The `i`-th target (scan order).
    pub fn get(&self, i: usize) -> P3 {
        position(self.dims, self.keys[i])
    }

    /// Rank of `p` in the set, if present.
    pub fn rank(&self, p: P3) -> Option<usize> {
        self.keys.binary_search(&linear(self.dims, p)).ok()
    }

    /// Grid extents.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }
}

/// `p + sign * e_axis` when inside the grid.
pub fn step(dims: [usize; 3], p: P3, axis: usize, forward: bool) -> Option<P3> {
    let mut q = p;
    if forward {
        if p[axis] as usize + 1 >= dims[axis] {
            return None;
        }
        q[axis] += 1;
    } else {
        q[axis] = p[axis].checked_sub(1)?;
    }
    Some(q)
}

/// Replaces `best` by source `s` when `s` is valid and closer.
pub fn consider(space: &impl PatchSpace, target: P3, s: P3, best: &mut Match) {
    if s == best.source || !space.is_source(s) {
        return;
    }
    let d = space.distance(target, s, best.dist);
    if d < best.dist {
        *best = Match { source: s, dist: d };
    }
}

/// Random search (Barnes et al. 2009, ratio 1/2): one random source in windows around the
/// current match whose radius halves from `max_radius` to 1 (per axis, an axis of radius 0
/// stays fixed).
pub fn random_search(
    space: &impl PatchSpace,
    target: P3,
    best: &mut Match,
    max_radius: [u32; 3],
    r: &mut rng::Rng,
) {
    let dims = space.dims();
    let mut rad = max_radius;
    while rad.iter().any(|&v| v >= 1) {
        let c = best.source;
        let mut s = c;
        for a in 0..3 {
            if rad[a] == 0 {
                continue;
            }
            let lo = c[a].saturating_sub(rad[a]);
            let hi = (c[a] + rad[a]).min(dims[a] as u32 - 1);
            s[a] = r.random_range(lo..=hi);
        }
        consider(space, target, s, best);
        rad = rad.map(|v| v / 2);
    }
}

/// Propagation (Barnes et al. 2009): for each grid neighbour `t + e` of target `t` that is a
/// target itself, with match `s` in `field`, tries `s - e` for `t`.
pub fn propagate(
    space: &impl PatchSpace,
    targets: &TargetSet,
    field: &[Match],
    t: P3,
    best: &mut Match,
) {
    let dims = space.dims();
    for axis in 0..3 {
        for forward in [false, true] {
            let Some(n) = step(dims, t, axis, forward) else {
                continue;
            };
            let Some(j) = targets.rank(n) else {
                continue;
            };
            if let Some(s) = step(dims, field[j].source, axis, !forward) {
                consider(space, t, s, best);
            }
        }
    }
}

/// A per-target random stream: deterministic in `(seed, iteration, target)` whatever the
/// thread count.
pub fn target_rng(seed: u64, iteration: usize, target: usize) -> rng::Rng {
    rng::stream(
        seed ^ (iteration as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
        target as u64,
    )
}

/// Improves the field `nnf` (one [`Match`] per target of `targets`, distances current) by
/// `params.iterations` Jacobi PatchMatch iterations; returns how many matches changed in the
/// last iteration. A target's distance never increases.
///
/// # Panics
/// When `nnf.len() != targets.len()`.
pub fn patchmatch(
    space: &impl PatchSpace,
    targets: &TargetSet,
    nnf: &mut [Match],
    params: &PatchMatchParams,
) -> usize {
    assert_eq!(nnf.len(), targets.len(), "patchmatch: one match per target");
    let dims = space.dims();
    let max_radius = params
        .max_radius
        .unwrap_or([dims[0] as u32, dims[1] as u32, dims[2] as u32]);
    let mut changed = 0;
    for it in 0..params.iterations {
        // Stops early on a cancellation request; the caller reports it.
        if wscg_math::cancel::requested() {
            break;
        }
        let prev: &[Match] = nnf;
        let next: Vec<Match> = (0..targets.len())
            .into_par_iter()
            .map(|i| {
                let t = targets.get(i);
                let mut best = prev[i];
                propagate(space, targets, prev, t, &mut best);
                let mut r = target_rng(params.seed, it, i);
                random_search(space, t, &mut best, max_radius, &mut r);
                best
            })
            .collect();
        changed = next
            .iter()
            .zip(prev.iter())
            .filter(|(a, b)| a.source != b.source)
            .count();
        nnf.copy_from_slice(&next);
    }
    changed
}

/// Patch voting (Wexler et al. 2007): for every pixel `p` with `write(p)`, the weighted mean
/// over the targets `i` whose patch (half-sizes `radius`, `(t, y, x)`) covers `p` of the
/// value their match proposes there, `value(s_i + (p - t_i))`, with weight `weights[i]`.
/// Returns, per pixel in `pixels` order, the `channels` means, or `None` where no target
/// with positive weight covers the pixel. Pixels are processed in parallel; each sums its
/// targets in a fixed order, so the result does not depend on the thread count.
///
/// # Panics
/// When `nnf` or `weights` does not have one entry per target.
pub fn vote(
    targets: &TargetSet,
    nnf: &[Match],
    weights: &[f32],
    radius: [u32; 3],
    pixels: &[P3],
    channels: usize,
    value: impl Fn(P3, usize) -> f32 + Sync,
) -> Vec<Option<Vec<f32>>> {
    assert_eq!(nnf.len(), targets.len(), "vote: one match per target");
    assert_eq!(weights.len(), targets.len(), "vote: one weight per target");
    let dims = targets.dims();
    pixels
        .par_iter()
        .map(|&p| {
            let mut acc = vec![0.0f64; channels];
            let mut wsum = 0.0f64;
            let lo = |a: usize| p[a].saturating_sub(radius[a]);
            let hi = |a: usize| (p[a] + radius[a]).min(dims[a] as u32 - 1);
            for tt in lo(0)..=hi(0) {
                for ty in lo(1)..=hi(1) {
                    for tx in lo(2)..=hi(2) {
                        let Some(i) = targets.rank([tt, ty, tx]) else {
                            continue;
                        };
                        let w = weights[i];
                        if w <= 0.0 {
                            continue;
                        }
                        let s = nnf[i].source;
                        let q = [
                            s[0] as i64 + p[0] as i64 - tt as i64,
                            s[1] as i64 + p[1] as i64 - ty as i64,
                            s[2] as i64 + p[2] as i64 - tx as i64,
                        ];
                        if q.iter().zip(dims).any(|(&v, d)| v < 0 || v >= d as i64) {
                            continue;
                        }
                        let q = [q[0] as u32, q[1] as u32, q[2] as u32];
                        for (c, a) in acc.iter_mut().enumerate() {
                            *a += w as f64 * value(q, c) as f64;
                        }
                        wsum += w as f64;
                    }
                }
            }
            (wsum > 0.0).then(|| acc.iter().map(|a| (a / wsum) as f32).collect())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1-channel image with an integer texture; patches 3x3, SSD; sources: centres whose
    /// patch lies inside the image and outside the hole `[hy0, hy1) x [hx0, hx1)`.
    struct Img {
        h: usize,
        w: usize,
        v: Vec<f32>,
        hole: [u32; 4],
    }

    impl Img {
        fn in_hole(&self, y: u32, x: u32) -> bool {
            y >= self.hole[0] && y < self.hole[1] && x >= self.hole[2] && x < self.hole[3]
        }
    }

    impl PatchSpace for Img {
        fn dims(&self) -> [usize; 3] {
            [1, self.h, self.w]
        }
        fn is_source(&self, s: P3) -> bool {
            let (y, x) = (s[1], s[2]);
            if y < 1 || x < 1 || y as usize + 1 >= self.h || x as usize + 1 >= self.w {
                return false;
            }
            (y - 1..=y + 1).all(|yy| (x - 1..=x + 1).all(|xx| !self.in_hole(yy, xx)))
        }
        fn distance(&self, t: P3, s: P3, _bound: f32) -> f32 {
            let mut d = 0.0;
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (ty, tx) = (t[1] as i64 + dy, t[2] as i64 + dx);
                    if ty < 0 || tx < 0 || ty >= self.h as i64 || tx >= self.w as i64 {
                        continue;
                    }
                    let a = self.v[ty as usize * self.w + tx as usize];
                    let b =
                        self.v[(s[1] as i64 + dy) as usize * self.w + (s[2] as i64 + dx) as usize];
                    d += (a - b) * (a - b);
                }
            }
            d
        }
    }

    fn image() -> Img {
        let (h, w) = (40, 50);
        // A periodic texture (period 7 x 5): every target patch has exact copies elsewhere.
        let v = (0..h * w)
            .map(|i| (((i / w) % 7) * 5 + (i % w) % 5) as f32)
            .collect();
        Img {
            h,
            w,
            v,
            hole: [15, 22, 20, 27],
        }
    }

    #[test]
    fn finds_exact_copies_and_never_worsens() {
        let img = image();
        let targets = TargetSet::new(
            img.dims(),
            (15..22).flat_map(|y| (20..27).map(move |x| [0, y, x])),
        );
        assert_eq!(targets.len(), 49);
        let start = [0, 2, 2];
        let mut nnf: Vec<Match> = (0..targets.len())
            .map(|i| Match {
                source: start,
                dist: img.distance(targets.get(i), start, f32::INFINITY),
            })
            .collect();
        let before: Vec<f32> = nnf.iter().map(|m| m.dist).collect();
        let p = PatchMatchParams {
            iterations: 8,
            seed: 3,
            max_radius: None,
        };
        patchmatch(&img, &targets, &mut nnf, &p);
        for (i, m) in nnf.iter().enumerate() {
            assert!(img.is_source(m.source));
            assert!(m.dist <= before[i]);
            assert_eq!(
                m.dist,
                img.distance(targets.get(i), m.source, f32::INFINITY)
            );
        }
        // The texture repeats: (nearly) every target finds a zero-distance copy.
        let exact = nnf.iter().filter(|m| m.dist == 0.0).count();
        assert!(exact >= 45, "{exact} of 49 exact");
        // Determinism with another thread count.
        let mut again: Vec<Match> = before
            .iter()
            .map(|&d| Match {
                source: start,
                dist: d,
            })
            .collect();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        pool.install(|| patchmatch(&img, &targets, &mut again, &p));
        assert_eq!(again, nnf);
    }

    #[test]
    fn voting_averages_the_proposals() {
        let img = image();
        let dims = img.dims();
        // Two targets covering pixel (0, 10, 10) with matches that propose 2 and 6 there.
        let targets = TargetSet::new(dims, [[0, 10, 10], [0, 10, 11]]);
        let val = |q: P3, _c: usize| (q[1] * 100 + q[2]) as f32;
        let nnf = [
            Match {
                source: [0, 30, 30],
                dist: 0.0,
            },
            Match {
                source: [0, 20, 5],
                dist: 0.0,
            },
        ];
        let out = vote(
            &targets,
            &nnf,
            &[1.0, 3.0],
            [0, 1, 1],
            &[[0, 10, 10], [0, 0, 0]],
            1,
            val,
        );
        // Target 0 proposes value at (30, 30); target 1 (offset -1 in x) at (20, 4).
        let want = (3030.0 + 3.0 * 2004.0) / 4.0;
        assert!((out[0].as_ref().unwrap()[0] - want).abs() < 1e-3);
        assert!(out[1].is_none());
    }
}
