//! Front-to-back ray traversal of the hybrid octree with a short stack, exact triangle hits in
//! the leaves, and level-of-detail stops at pre-filtered voxels (paper §4, "Traversal" and
//! "Inter-level blending").

use std::mem::MaybeUninit;

use crate::node::{LeafTris, Node};
use crate::octree::{HybridOctree, Tri};

/// A ray `origin + t dir` with `t` in `[t_min, t_max]` (single precision, like the traversal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: [f32; 3],
    /// Direction (need not be unit length; `t` is measured in its units).
    pub dir: [f32; 3],
    /// Smallest accepted `t`.
    pub t_min: f32,
    /// Largest accepted `t`.
    pub t_max: f32,
}

impl Ray {
    /// A ray over `[0, inf)`.
    pub fn new(origin: [f32; 3], dir: [f32; 3]) -> Self {
        Self {
            origin,
            dir,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }
}

/// What the traversal returns at a node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TraceMode {
    /// Exact triangles only: descend to the leaves, never stop at voxels (baseline).
    Triangles,
    /// Voxels only: stop at the first non-empty node at `level` or at a leaf (`None`: leaves).
    Voxels {
        /// Level to stop at.
        level: Option<u8>,
    },
    /// The paper's hybrid: stop at the first level whose voxel is no larger than
    /// `lod_scale` times the pixel footprint, else intersect triangles.
    Hybrid {
        /// Multiplier of the footprint (1 = the paper's criterion).
        lod_scale: f32,
        /// Blend the voxel colour with its parent's (the paper's inter-level blending).
        blend: bool,
        /// Treat leaves with one or two triangles as voxels too (the alternative reading of
        /// the paper; default `false`: such leaves are intersected exactly).
        small_leaves_as_voxels: bool,
    },
}

impl TraceMode {
    /// The paper's hybrid mode: footprint criterion as is, blending on.
    pub const HYBRID: TraceMode = TraceMode::Hybrid {
        lod_scale: 1.0,
        blend: true,
        small_leaves_as_voxels: false,
    };
    /// Finest voxels (leaves).
    pub const VOXELS: TraceMode = TraceMode::Voxels { level: None };
}

/// Width of a pixel's footprint along a ray: `f(t) = width0 + spread * t * |dir|` (Igehy 1999
/// for a pinhole camera: `spread = 2 tan(fov_y / 2) / H`, `width0 = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// Width at the origin.
    pub width0: f32,
    /// Growth per unit distance.
    pub spread: f32,
}

/// What was hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HitKind {
    /// A triangle, with barycentric `u, v` (weights of vertices 1 and 2).
    Triangle {
        /// Triangle index.
        prim: u32,
        /// Weight of vertex 1.
        u: f32,
        /// Weight of vertex 2.
        v: f32,
    },
    /// A voxel of node `node` at `level`; `blend` is the weight of its colour against its
    /// parent's (eq. of §4, `i = (2 v_w - f) / v_w` clamped to `[0, 1]`).
    Voxel {
        /// Level of the node.
        level: u8,
        /// Node index.
        node: u32,
        /// Weight of this level's colour.
        blend: f32,
    },
}

/// A ray hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter (cell entry for voxels).
    pub t: f32,
    /// Triangle or voxel.
    pub kind: HitKind,
    /// Unit normal (geometric for triangles, pre-filtered for voxels), not flipped.
    pub normal: [f32; 3],
    /// RGB colour in `[0, 1]`.
    pub color: [f32; 3],
}

/// `a . b` in single precision.
#[inline(always)]
pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b` in single precision.
#[inline(always)]
pub(crate) fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Möller-Trumbore ray / triangle intersection: `(t, u, v)` for any `t` (the caller checks
/// the range), or `None` when the ray misses or is parallel.
#[inline(always)]
pub fn intersect_tri(tri: &Tri, o: [f32; 3], d: [f32; 3]) -> Option<(f32, f32, f32)> {
    let p = cross(d, tri.e2);
    let det = dot(tri.e1, p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = [o[0] - tri.v0[0], o[1] - tri.v0[1], o[2] - tri.v0[2]];
    let u = dot(s, p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = cross(s, tri.e1);
    let v = dot(d, q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    Some((dot(tri.e2, q) * inv, u, v))
}

/// Unit geometric normal of a prepared triangle.
#[inline]
pub fn tri_normal(tri: &Tri) -> [f32; 3] {
    let n = cross(tri.e1, tri.e2);
    let l = dot(n, n).sqrt();
    if l > 0.0 {
        n.map(|x| x / l)
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// A triangle hit during the traversal: triangle, ray parameter, barycentrics.
#[derive(Clone, Copy)]
struct TriHit {
    prim: u32,
    t: f32,
    u: f32,
    v: f32,
}

/// Where a walk ended: a triangle, or a voxel stop (its stack entry, its cell size and the
/// ray's footprint as `(width0, spread * |dir|)`).
#[derive(Clone, Copy)]
enum Found {
    Tri(TriHit),
    Voxel(Entry, f32, Option<(f32, f32)>),
}

/// One entry of the traversal stack.
#[derive(Clone, Copy)]
struct Entry {
    node: u32,
    level: u8,
    cell: [u32; 3],
    t0: f32,
    t1: f32,
    parent: u32,
}

/// Hints the cache to load the line at `p` (no effect off x86-64).
#[inline(always)]
fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch never faults, whatever the address.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// Recent triangle tests of a ray, so that a triangle overlapping several leaves along the
/// ray is intersected once (mailboxing; direct-mapped on the triangle index).
struct Mailbox {
    prim: [u32; MAILBOX],
    hit: [Option<(f32, f32, f32)>; MAILBOX],
}

const MAILBOX: usize = 8;

impl Default for Mailbox {
    fn default() -> Self {
        Self {
            prim: [u32::MAX; MAILBOX],
            hit: [None; MAILBOX],
        }
    }
}

impl Mailbox {
    #[inline(always)]
    fn get(&self, p: u32) -> Option<Option<(f32, f32, f32)>> {
        let k = p as usize % MAILBOX;
        (self.prim[k] == p).then_some(self.hit[k])
    }

    #[inline(always)]
    fn put(&mut self, p: u32, r: Option<(f32, f32, f32)>) {
        let k = p as usize % MAILBOX;
        self.prim[k] = p;
        self.hit[k] = r;
    }
}

/// Weight of a voxel stop's colour against its parent's in the hybrid mode with blending
/// (§4: `i = (2 v_w - f) / v_w` clamped to `[0, 1]`, `f` the footprint at the cell entry); 1
/// in the other modes and at the root, which has no parent.
fn voxel_blend(e: &Entry, vw: f32, mode: &TraceMode, fp: Option<(f32, f32)>) -> f32 {
    match (mode, fp) {
        (TraceMode::Hybrid { blend: true, .. }, Some((w0, s))) if e.parent != u32::MAX => {
            ((2.0 * vw - (w0 + s * e.t0)) / vw).clamp(0.0, 1.0)
        }
        _ => 1.0,
    }
}

/// Deepest stack: at most three siblings wait per level plus the four children of the last.
const STACK: usize = 3 * 21 + 8;

impl HybridOctree {
    /// Colour of triangle `prim` at barycentric `(u, v)`.
    pub fn tri_color(&self, prim: u32, u: f32, v: f32) -> [f32; 3] {
        match &self.mesh.colors {
            Some(c) => {
                let f = self.mesh.faces[prim as usize];
                let w = [1.0 - u - v, u, v];
                std::array::from_fn(|k| (0..3).map(|j| w[j] * c[f[j] as usize][k]).sum())
            }
            None => [crate::voxelize::DEFAULT_RGBA[0] as f32 / 255.0; 3],
        }
    }

    /// The nearest hit along `ray` in `mode`; `footprint` drives the LoD stop of
    /// [`TraceMode::Hybrid`] (without one the hybrid mode intersects triangles only). A zero,
    /// NaN or infinite direction returns `None`.
    pub fn intersect(
        &self,
        ray: &Ray,
        mode: &TraceMode,
        footprint: Option<Footprint>,
    ) -> Option<Hit> {
        self.trace::<false>(ray, mode, footprint).map(|f| match f {
            Found::Tri(b) => self.tri_hit(b),
            Found::Voxel(e, vw, fp) => self.voxel_hit(e, vw, mode, fp),
        })
    }

    /// The nearest hit along `ray` as [`Self::intersect`] finds it, without the shading
    /// lookups: its ray parameter and what was hit (triangle and barycentrics, or voxel and
    /// blend weight), but no normal or colour. This is the query of depth maps, picking and
    /// distance probes; it skips the reads of the triangle's vertex indices, vertex colours and
    /// voxel attributes that [`Self::intersect`] makes for every hit.
    pub fn cast(
        &self,
        ray: &Ray,
        mode: &TraceMode,
        footprint: Option<Footprint>,
    ) -> Option<(f32, HitKind)> {
        self.trace::<false>(ray, mode, footprint).map(|f| match f {
            Found::Tri(b) => (
                b.t,
                HitKind::Triangle {
                    prim: b.prim,
                    u: b.u,
                    v: b.v,
                },
            ),
            Found::Voxel(e, vw, fp) => (
                e.t0,
                HitKind::Voxel {
                    level: e.level,
                    node: e.node,
                    blend: voxel_blend(&e, vw, mode, fp),
                },
            ),
        })
    }

    /// Whether anything blocks `ray` within its range (shadow and ambient-occlusion rays):
    /// `intersect(..).is_some()`, but the walk ends at the first hit in the range rather than
    /// the closest.
    pub fn occluded(&self, ray: &Ray, mode: &TraceMode, footprint: Option<Footprint>) -> bool {
        self.trace::<true>(ray, mode, footprint).is_some()
    }

    /// The walk behind [`Self::intersect`] and [`Self::cast`] (`ANY = false`: the closest
    /// hit) and [`Self::occluded`] (`ANY = true`: any hit in the ray's range).
    fn trace<const ANY: bool>(
        &self,
        ray: &Ray,
        mode: &TraceMode,
        footprint: Option<Footprint>,
    ) -> Option<Found> {
        let o = ray.origin;
        let d = ray.dir;
        let dd = dot(d, d);
        if !(dd > 0.0 && dd.is_finite()) || o.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let inv = d.map(|x| {
            let x = if x.abs() < 1e-30 {
                1e-30f32.copysign(x)
            } else {
                x
            };
            1.0 / x
        });
        let cmin = self.cube.min.map(|v| v as f32);
        let size = self.cube.size as f32;
        let mut t0 = ray.t_min.max(0.0);
        let mut t1 = ray.t_max;
        for k in 0..3 {
            let a = (cmin[k] - o[k]) * inv[k];
            let b = (cmin[k] + size - o[k]) * inv[k];
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        if t0 > t1 {
            return None;
        }
        // Past the root test only: most rays of a far view miss the root cell.
        let dn = dd.sqrt();
        let fp = footprint.map(|f| (f.width0, f.spread * dn));
        // Every triangle lies in the mesh's bounding box, and a non-empty cell of side `vw`
        // overlaps it, so lies within `vw` of it. A hybrid stop needs `vw <= lod_scale (w0 +
        // s t)` with `t` at most the root's exit `t1`: a ray that misses the box widened by
        // that much misses everything. (The voxel mode stops at leaves of any size.)
        let margin = match *mode {
            TraceMode::Triangles => Some(0.0),
            TraceMode::Hybrid { lod_scale, .. } => {
                // (Widened by 1e-4 of itself against rounding.)
                Some(fp.map_or(0.0, |(w0, s)| {
                    (lod_scale * (w0 + s * t1)).max(0.0) * (1.0 + 1e-4)
                }))
            }
            TraceMode::Voxels { .. } => None,
        };
        if let Some(m) = margin.filter(|m| *m < size) {
            let [lo, hi] = self.bounds;
            let (mut a0, mut a1) = (t0, t1);
            for k in 0..3 {
                let a = (lo[k] - m - o[k]) * inv[k];
                let b = (hi[k] + m - o[k]) * inv[k];
                a0 = a0.max(a.min(b));
                a1 = a1.min(a.max(b));
            }
            if a0 > a1 {
                return None;
            }
        }
        // Tolerance for accepting a triangle hit in a leaf (rounding of the cell bounds).
        let eps = 4e-6 * size / dn;
        let (t_lo, t_hi) = (ray.t_min.max(0.0), ray.t_max);
        // Triangles already intersected along this ray (a triangle spans several leaves).
        let mut mailbox = Mailbox::default();
        // The node slice, taken once rather than through `NodeArray`'s deref at every read.
        let nodes: &[Node] = &self.nodes;
        // The closest triangle hit in `[t_lo, t_hi]` among the triangles tested so far.
        let mut best: Option<TriHit> = None;
        // Entries `0..sp` are initialized; leaving the rest uninitialized spares a 2 KB memset
        // per ray.
        let mut stack = [const { MaybeUninit::<Entry>::uninit() }; STACK];
        let root = Entry {
            node: 0,
            level: 0,
            cell: [0; 3],
            t0,
            t1,
            parent: u32::MAX,
        };
        let mut sp = 0usize;
        // The nearest child of the last inner node, visited next without a trip through the
        // stack (a load right after its store would wait for store forwarding).
        let mut nearest = Some(root);
        loop {
            let e = match nearest.take() {
                Some(e) => e,
                None if sp > 0 => {
                    sp -= 1;
                    // SAFETY: `sp < ` the number of entries written, all of which were
                    // initialized.
                    unsafe { stack[sp].assume_init() }
                }
                None => break,
            };
            if best.is_some_and(|b| e.t0 > b.t) {
                // Every cell still ahead starts behind the closest triangle hit found so far.
                break;
            }
            let node = nodes[e.node as usize];
            if node.is_empty() {
                continue;
            }
            let leaf = node.is_leaf();
            let vw = self.cell_sizes[e.level as usize];
            let stop = match *mode {
                TraceMode::Triangles => false,
                TraceMode::Voxels { level } => leaf || level == Some(e.level),
                TraceMode::Hybrid {
                    lod_scale,
                    small_leaves_as_voxels,
                    ..
                } => match fp {
                    Some((w0, s)) => {
                        let small = leaf && node.index() < self.n_tris + self.n_pair_words;
                        (!small || small_leaves_as_voxels) && vw <= lod_scale * (w0 + s * e.t0)
                    }
                    None => false,
                },
            };
            if stop {
                return Some(Found::Voxel(e, vw, fp));
            }
            if leaf {
                self.leaf_test(
                    self.decode_code(node.index()),
                    o,
                    d,
                    (t_lo, t_hi),
                    &mut mailbox,
                    &mut best,
                );
                if best.is_some_and(|b| ANY || b.t <= e.t1 + eps) {
                    // The hit lies in this cell (or, by rounding, just past it), or any hit
                    // will do.
                    break;
                }
                continue;
            }
            // Children crossed by the ray, front to back (parametric traversal).
            let half = 0.5 * vw;
            let mut tm = [0f32; 3];
            let mut oct = 0usize;
            for k in 0..3 {
                let mid = cmin[k] + (2 * e.cell[k] + 1) as f32 * half;
                tm[k] = (mid - o[k]) * inv[k];
                let upper = if inv[k] > 0.0 {
                    tm[k] <= e.t0
                } else {
                    tm[k] > e.t0
                };
                oct |= usize::from(upper) << k;
            }
            let mut cross = [(0f32, 0usize); 3];
            let mut nc = 0;
            for (k, &t) in tm.iter().enumerate() {
                if t > e.t0 && t < e.t1 {
                    cross[nc] = (t, k);
                    nc += 1;
                }
            }
            // Three-element sorting network.
            if nc > 1 && cross[1].0 < cross[0].0 {
                cross.swap(0, 1);
            }
            if nc > 2 {
                if cross[2].0 < cross[1].0 {
                    cross.swap(1, 2);
                }
                if cross[1].0 < cross[0].0 {
                    cross.swap(0, 1);
                }
            }
            let mut seq = [(0usize, 0f32, 0f32); 4];
            let mut ta = e.t0;
            for (i, &(t, k)) in cross[..nc].iter().enumerate() {
                seq[i] = (oct, ta, t);
                oct ^= 1 << k;
                ta = t;
            }
            seq[nc] = (oct, ta, e.t1);
            let first = node.index();
            for &(c, a, b) in seq[..=nc].iter().rev() {
                let child = first + c as u32;
                let cn = nodes[child as usize];
                if cn.is_empty() {
                    continue;
                }
                let code = cn.index();
                if !cn.is_leaf() {
                    // The grandchildren are read when the child is popped: fetch them now.
                    prefetch(nodes.as_ptr().wrapping_add(code as usize));
                } else if code < self.n_tris {
                    // So is a single-triangle leaf's triangle, or the words of a pair or list.
                    prefetch(self.tris().as_ptr().wrapping_add(code as usize));
                } else {
                    prefetch(
                        self.tri_index
                            .as_ptr()
                            .wrapping_add((code - self.n_tris) as usize),
                    );
                }
                let entry = Entry {
                    node: child,
                    level: e.level + 1,
                    cell: [
                        2 * e.cell[0] + (c as u32 & 1),
                        2 * e.cell[1] + ((c as u32 >> 1) & 1),
                        2 * e.cell[2] + ((c as u32 >> 2) & 1),
                    ],
                    t0: a,
                    t1: b,
                    parent: node.payload,
                };
                if let Some(farther) = nearest.replace(entry) {
                    stack[sp].write(farther);
                    sp += 1;
                }
            }
        }
        best.map(Found::Tri)
    }

    /// Tests a leaf's triangles (through the mailbox) and keeps in `best` the closest hit with
    /// `t` in `range`, wherever along the ray it lies: the traversal stops once it passes it.
    #[inline]
    fn leaf_test(
        &self,
        tris: LeafTris<'_>,
        o: [f32; 3],
        d: [f32; 3],
        range: (f32, f32),
        mailbox: &mut Mailbox,
        best: &mut Option<TriHit>,
    ) {
        tris.for_each(|p| {
            let r = match mailbox.get(p) {
                Some(r) => r,
                None => {
                    let r = intersect_tri(&self.tris()[p as usize], o, d);
                    mailbox.put(p, r);
                    r
                }
            };
            if let Some((t, u, v)) = r {
                if t >= range.0 && t <= range.1 && best.is_none_or(|b| t < b.t) {
                    *best = Some(TriHit { prim: p, t, u, v });
                }
            }
        });
    }

    fn tri_hit(&self, b: TriHit) -> Hit {
        Hit {
            t: b.t,
            kind: HitKind::Triangle {
                prim: b.prim,
                u: b.u,
                v: b.v,
            },
            normal: tri_normal(&self.tris()[b.prim as usize]),
            color: self.tri_color(b.prim, b.u, b.v),
        }
    }

    fn voxel_hit(&self, e: Entry, vw: f32, mode: &TraceMode, fp: Option<(f32, f32)>) -> Hit {
        let node = self.nodes[e.node as usize];
        let vox = self.voxels[node.payload as usize];
        let mut color = vox.color();
        let blend = voxel_blend(&e, vw, mode, fp);
        if blend < 1.0 {
            let pc = self.voxels[e.parent as usize].color();
            color = std::array::from_fn(|k| blend * color[k] + (1.0 - blend) * pc[k]);
        }
        Hit {
            t: e.t0,
            kind: HitKind::Voxel {
                level: e.level,
                node: e.node,
                blend,
            },
            normal: vox.normal(),
            color,
        }
    }
}
