//! The constraint projections of the soft-projection step (the update of [`crate::solver`]:
//! the paper's eqs. 17 and 20 with the damping of section 6), written for speed.
//!
//! Two identities keep the sweeps light:
//!
//! - Every correction moves positions by `beta h^2 W J' dl` and velocities by `h W J' dl`, so
//!   throughout the iterations `v = v~ + (x - x~) / (beta h)`: the sweeps update positions only
//!   and the velocities are recovered once at the end (and, when `gamma > 0`, read on the fly).
//! - For a membrane triangle (paper section 9) the gradients are `a_p w_u`, `b_p w_v` and
//!   `a_p w_v + b_p w_u`, so `J W J'` needs only the per-triangle sums `sum w_p a_p^2`,
//!   `sum w_p b_p^2`, `sum w_p a_p b_p` (fixed for the whole simulation) and the current
//!   `w_u, w_v`; the shear projection that follows the stretch pair updates `w_u, w_v`
//!   analytically, and each vertex is written once per triangle.
//!
//! The sweeps come in the paper's variants (section 7): sequential Gauss-Seidel in creation
//! order, successive over-relaxation, Jacobi (corrections accumulated and applied after the
//! sweep) and graph-coloured Gauss-Seidel, whose colour classes share no particle and run in
//! parallel.

use rayon::prelude::*;

use crate::model::ClothModel;
use crate::vecs::V3;

/// How the constraints of one sweep are visited.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Relaxation {
    /// Sequential Gauss-Seidel in creation order (links, triangles, rollers, contacts).
    #[default]
    GaussSeidel,
    /// Gauss-Seidel over colour classes of constraints that share no particle, each class
    /// projected in parallel (rayon). The order differs from [`Relaxation::GaussSeidel`], so
    /// trajectories differ while the converged state is the same.
    ColoredGaussSeidel,
    /// Jacobi: every correction of a sweep computed from the same positions, scaled by
    /// `omega` in `(0, 1]`, and applied after the sweep. The sweep is stable only for `omega`
    /// below about the inverse of the number of constraints meeting at a particle: 0.5
    /// suffices for a chain, a membrane with bending links needs about 0.15.
    Jacobi {
        /// Relaxation factor in `(0, 1]`.
        omega: f64,
    },
    /// Successive over-relaxation: Gauss-Seidel corrections scaled by `omega` in `(0, 2)`.
    Sor {
        /// Relaxation factor in `(0, 2)`.
        omega: f64,
    },
}

/// A link in sweep order: its multiplier index `k` and, for the current step constants, `1/S`
/// (times the relaxation factor) and `beta h^2 w` of each end.
#[derive(Clone, Copy, Debug)]
struct PLink {
    i: u32,
    j: u32,
    k: u32,
    rest: f64,
    compliance: f64,
    inv_s: f64,
    kwi: f64,
    kwj: f64,
}

/// A membrane triangle in sweep order with the sums of its `J W J'`.
#[derive(Clone, Copy, Debug)]
struct PTri {
    idx: [u32; 3],
    /// Inverse masses of the vertices.
    w: [f64; 3],
    /// Index of the triangle (its multipliers are `3k..3k+3` after the links').
    k: u32,
    a: [f64; 3],
    b: [f64; 3],
    /// `sum w_p a_p^2`, `sum w_p b_p^2`, `sum w_p a_p b_p`.
    saa: f64,
    sbb: f64,
    sab: f64,
    /// Stretch compliance `(1/(Y area)) [[1, -nu], [-nu, 1]]` as `(1/(Y area), nu)`.
    cy: f64,
    nu: f64,
    /// Shear compliance `1/(G area)`.
    cs: f64,
}

/// The constraints of a model in the order and layout the sweeps read: creation order, or
/// colour classes stored contiguously for [`Relaxation::ColoredGaussSeidel`].
#[derive(Clone, Debug)]
pub(crate) struct Prepared {
    links: Vec<PLink>,
    tris: Vec<PTri>,
    /// Ranges of `links` and `tris` forming the colour classes (one range each when not
    /// coloured).
    link_classes: Vec<std::ops::Range<usize>>,
    tri_classes: Vec<std::ops::Range<usize>>,
    /// Step constants (`s_coef`, `sx`, `omega`) the link factors were computed for.
    key: Option<[f64; 3]>,
}

/// Greedy colouring: each constraint (touching the particles `parts`) gets the smallest
/// colour no earlier constraint on the same particles has. Returns the constraint indices
/// grouped by colour.
fn color_classes<const N: usize>(
    n_particles: usize,
    items: impl Iterator<Item = [u32; N]>,
) -> Vec<Vec<u32>> {
    let mut used: Vec<Vec<bool>> = vec![Vec::new(); n_particles];
    let mut classes: Vec<Vec<u32>> = Vec::new();
    for (k, parts) in items.enumerate() {
        let free = |c: usize| {
            parts
                .iter()
                .all(|&p| !used[p as usize].get(c).copied().unwrap_or(false))
        };
        let c = (0..=classes.len())
            .find(|&c| free(c))
            .unwrap_or(classes.len());
        for &p in &parts {
            let u = &mut used[p as usize];
            if u.len() <= c {
                u.resize(c + 1, false);
            }
            u[c] = true;
        }
        if classes.len() <= c {
            classes.resize(c + 1, Vec::new());
        }
        classes[c].push(k as u32);
    }
    classes
}

/// `items` in the order of `classes` (or unchanged when `None`), with the class ranges.
fn ordered<T: Copy>(
    items: &[T],
    classes: Option<Vec<Vec<u32>>>,
) -> (Vec<T>, Vec<std::ops::Range<usize>>) {
    match classes {
        None => (items.to_vec(), std::iter::once(0..items.len()).collect()),
        Some(classes) => {
            let mut out = Vec::with_capacity(items.len());
            let mut ranges = Vec::with_capacity(classes.len());
            for class in classes {
                let start = out.len();
                out.extend(class.iter().map(|&k| items[k as usize]));
                ranges.push(start..out.len());
            }
            (out, ranges)
        }
    }
}

impl Prepared {
    /// The constraints of `m`, in colour-class order when `colored`.
    pub(crate) fn new(m: &ClothModel, colored: bool) -> Self {
        let w = &m.inv_mass;
        let links: Vec<PLink> = m
            .links
            .iter()
            .enumerate()
            .map(|(k, l)| PLink {
                i: l.i as u32,
                j: l.j as u32,
                k: k as u32,
                rest: l.rest,
                compliance: l.compliance,
                inv_s: 0.0,
                kwi: 0.0,
                kwj: 0.0,
            })
            .collect();
        let tris: Vec<PTri> = m
            .tris
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let wp = t.idx.map(|p| w[p]);
                let sum = |f: &dyn Fn(usize) -> f64| (0..3).map(|p| wp[p] * f(p)).sum::<f64>();
                let (c2, cs) = t.compliance();
                PTri {
                    idx: t.idx.map(|p| p as u32),
                    w: wp,
                    k: k as u32,
                    a: t.a,
                    b: t.b,
                    saa: sum(&|p| t.a[p] * t.a[p]),
                    sbb: sum(&|p| t.b[p] * t.b[p]),
                    sab: sum(&|p| t.a[p] * t.b[p]),
                    cy: c2[(0, 0)],
                    nu: t.poisson,
                    cs,
                }
            })
            .collect();
        let (link_cl, tri_cl) = if colored {
            (
                Some(color_classes(m.len(), links.iter().map(|l| [l.i, l.j]))),
                Some(color_classes(m.len(), tris.iter().map(|t| t.idx))),
            )
        } else {
            (None, None)
        };
        let (links, link_classes) = ordered(&links, link_cl);
        let (tris, tri_classes) = ordered(&tris, tri_cl);
        Self {
            links,
            tris,
            link_classes,
            tri_classes,
            key: None,
        }
    }

    /// Computes the link factors for the step constants `k` (kept while they repeat).
    pub(crate) fn prepare_step(&mut self, k: &StepConsts, inv_mass: &[f64]) {
        let key = [k.s_coef, k.sx, k.omega];
        if self.key == Some(key) {
            return;
        }
        for l in &mut self.links {
            let (wi, wj) = (inv_mass[l.i as usize], inv_mass[l.j as usize]);
            let s = k.s_coef * (wi + wj) + l.compliance;
            (l.inv_s, l.kwi, l.kwj) = if s > 0.0 {
                (k.omega / s, k.sx * wi, k.sx * wj)
            } else {
                (0.0, 0.0, 0.0)
            };
        }
        self.key = Some(key);
    }

    /// Number of colour classes (links, triangles).
    pub(crate) fn colors(&self) -> (usize, usize) {
        (self.link_classes.len(), self.tri_classes.len())
    }
}

/// Per-step constants of the projections.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepConsts {
    pub alpha: f64,
    /// `alpha h (beta h + gamma)`, the factor of `J W J'` in `S`.
    pub s_coef: f64,
    /// `beta h^2`, the factor of the position update.
    pub sx: f64,
    /// `gamma`, and `1/(beta h)` to read velocities.
    pub gamma: f64,
    pub inv_bh: f64,
    /// Keep the accumulated-multiplier term (`LambdaMode::Accumulate`).
    pub accumulate: bool,
    /// Relaxation factor of the corrections.
    pub omega: f64,
}

/// Read/write access to the positions during a sweep.
trait Positions {
    fn get(&self, p: u32) -> V3;
    fn add(&mut self, p: u32, d: V3);
}

/// Gauss-Seidel: corrections land at once.
struct Direct<'a>(&'a mut [V3]);

impl Positions for Direct<'_> {
    #[inline(always)]
    fn get(&self, p: u32) -> V3 {
        self.0[p as usize]
    }
    #[inline(always)]
    fn add(&mut self, p: u32, d: V3) {
        self.0[p as usize] += d;
    }
}

/// Jacobi: positions read from the start of the sweep, corrections accumulated apart.
struct Deferred<'a> {
    x: &'a [V3],
    dx: &'a mut [V3],
}

impl Positions for Deferred<'_> {
    #[inline(always)]
    fn get(&self, p: u32) -> V3 {
        self.x[p as usize]
    }
    #[inline(always)]
    fn add(&mut self, p: u32, d: V3) {
        self.dx[p as usize] += d;
    }
}

/// Shared access for the constraints of one colour class, which touch disjoint particles.
#[derive(Clone, Copy)]
struct Shared<T> {
    ptr: *mut T,
    len: usize,
}

// SAFETY: a `Shared` is only handed to the constraints of one colour class, which read and
// write disjoint particles (and their own multipliers), so no element is accessed by two
// threads at once.
unsafe impl<T: Send> Send for Shared<T> {}
unsafe impl<T: Send> Sync for Shared<T> {}

impl<T: Copy + std::ops::AddAssign> Shared<T> {
    fn new(s: &mut [T]) -> Self {
        Self {
            ptr: s.as_mut_ptr(),
            len: s.len(),
        }
    }
    #[inline(always)]
    fn read(&self, k: usize) -> T {
        assert!(k < self.len);
        // SAFETY: in bounds (checked), and no other thread writes element `k` (colouring).
        unsafe { *self.ptr.add(k) }
    }
    #[inline(always)]
    fn add_to(&self, k: usize, d: T) {
        assert!(k < self.len);
        // SAFETY: as in `read`.
        unsafe { *self.ptr.add(k) += d }
    }
}

impl Positions for Shared<V3> {
    #[inline(always)]
    fn get(&self, p: u32) -> V3 {
        self.read(p as usize)
    }
    #[inline(always)]
    fn add(&mut self, p: u32, d: V3) {
        self.add_to(p as usize, d)
    }
}

/// Velocities `v = v~ + (x - x~) / (beta h)` for the damping term.
#[derive(Clone, Copy)]
pub(crate) struct VelocityFrame<'a> {
    pub(crate) x0: &'a [V3],
    pub(crate) v0: &'a [V3],
}

impl VelocityFrame<'_> {
    #[inline(always)]
    fn v(&self, p: u32, x: V3, inv_bh: f64) -> V3 {
        let p = p as usize;
        self.v0[p] + (x - self.x0[p]) * inv_bh
    }
}

/// Projects one link: `dl = -rhs / (h alpha (beta h + gamma) sum_p w_p |grad_p c|^2 + eps)`,
/// the scalar form of the update (the paper's eq. 22 with the soft and damping terms);
/// returns the multiplier change and the residual `|rhs|`.
#[inline(always)]
fn project_link<P: Positions>(
    l: &PLink,
    lam: f64,
    x: &mut P,
    k: &StepConsts,
    vf: VelocityFrame,
) -> (f64, f64) {
    let (xi, xj) = (x.get(l.i), x.get(l.j));
    let d = xi - xj;
    let len2 = d.norm_squared();
    if len2 < 1e-24 || l.inv_s == 0.0 {
        return (0.0, 0.0);
    }
    let inv_len = 1.0 / len2.sqrt();
    let mut rhs = k.alpha * (len2 * inv_len - l.rest);
    if k.gamma > 0.0 {
        let jv = d.dot(&(vf.v(l.i, xi, k.inv_bh) - vf.v(l.j, xj, k.inv_bh))) * inv_len;
        rhs += k.alpha * k.gamma * jv;
    }
    if k.accumulate {
        rhs += l.compliance * lam;
    }
    let dl = -rhs * l.inv_s;
    let dp = d * (dl * inv_len);
    x.add(l.i, dp * l.kwi);
    x.add(l.j, -dp * l.kwj);
    (dl, rhs.abs())
}

/// Projects one membrane triangle: the stretch pair `(e_uu, e_vv)` as a 2 x 2 block, then
/// the shear `g_uv` at the updated positions (paper section 9). Returns the three multiplier
/// changes and the largest residual.
#[inline(always)]
fn project_tri<P: Positions>(
    t: &PTri,
    lam: [f64; 3],
    x: &mut P,
    k: &StepConsts,
    vf: VelocityFrame,
) -> ([f64; 3], f64) {
    let xs = t.idx.map(|p| x.get(p));
    let wu = xs[0] * t.a[0] + xs[1] * t.a[1] + xs[2] * t.a[2];
    let wv = xs[0] * t.b[0] + xs[1] * t.b[1] + xs[2] * t.b[2];
    // J v for the damping term: (w_u . sum a_p v_p, w_v . sum b_p v_p, ...).
    let (mut vu, mut vv) = (V3::zeros(), V3::zeros());
    if k.gamma > 0.0 {
        for (p, (&q, &xq)) in t.idx.iter().zip(&xs).enumerate() {
            let vp = vf.v(q, xq, k.inv_bh);
            vu += vp * t.a[p];
            vv += vp * t.b[p];
        }
    }
    let (uu, vvn, uv) = (wu.norm_squared(), wv.norm_squared(), wu.dot(&wv));
    // S = alpha h (beta h + gamma) J W J' + C for the stretch pair, solved in closed form.
    let c01 = -t.nu * t.cy;
    let (s00, s01, s11) = (
        k.s_coef * t.saa * uu + t.cy,
        k.s_coef * t.sab * uv + c01,
        k.s_coef * t.sbb * vvn + t.cy,
    );
    let (mut r0, mut r1) = (k.alpha * 0.5 * (uu - 1.0), k.alpha * 0.5 * (vvn - 1.0));
    if k.gamma > 0.0 {
        r0 += k.alpha * k.gamma * wu.dot(&vu);
        r1 += k.alpha * k.gamma * wv.dot(&vv);
    }
    if k.accumulate {
        r0 += t.cy * lam[0] + c01 * lam[1];
        r1 += c01 * lam[0] + t.cy * lam[1];
    }
    let mut res = r0.abs().max(r1.abs());
    let det = s00 * s11 - s01 * s01;
    let dl2 = if det != 0.0 && det.is_finite() {
        let f = -k.omega / det;
        [f * (s11 * r0 - s01 * r1), f * (s00 * r1 - s01 * r0)]
    } else {
        [0.0, 0.0]
    };
    // Positions move by sx w_p (a_p w_u dl0 + b_p w_v dl1); w_u, w_v follow linearly.
    let (gu, gv) = (wu * dl2[0], wv * dl2[1]);
    let (wu1, wv1) = (
        wu + (gu * t.saa + gv * t.sab) * k.sx,
        wv + (gu * t.sab + gv * t.sbb) * k.sx,
    );
    // Shear at the updated positions; its gradient is a_p w_v + b_p w_u.
    let a1 = t.saa * wv1.norm_squared() + 2.0 * t.sab * wu1.dot(&wv1) + t.sbb * wu1.norm_squared();
    let s1 = k.s_coef * a1 + t.cs;
    let mut rhs1 = k.alpha * wu1.dot(&wv1);
    if k.gamma > 0.0 {
        // sum a_p v_p and sum b_p v_p after the stretch correction, v += dx / (beta h).
        let vu1 = vu + (gu * t.saa + gv * t.sab) * (k.sx * k.inv_bh);
        let vv1 = vv + (gu * t.sab + gv * t.sbb) * (k.sx * k.inv_bh);
        rhs1 += k.alpha * k.gamma * (wv1.dot(&vu1) + wu1.dot(&vv1));
    }
    if k.accumulate {
        rhs1 += t.cs * lam[2];
    }
    res = res.max(rhs1.abs());
    let dl1 = if s1 > 0.0 { -k.omega * rhs1 / s1 } else { 0.0 };
    let (su, sv) = (wu1 * dl1, wv1 * dl1);
    for p in 0..3 {
        if t.w[p] > 0.0 {
            let g = (gu + sv) * t.a[p] + (gv + su) * t.b[p];
            x.add(t.idx[p], g * (k.sx * t.w[p]));
        }
    }
    ([dl2[0], dl2[1], dl1], res)
}

/// One sweep over the links and triangles. `lambda` holds one multiplier per link, then three
/// per triangle. Returns the largest residual met.
pub(crate) fn sweep(
    prep: &Prepared,
    relax: Relaxation,
    x: &mut [V3],
    scratch: &mut Vec<V3>,
    lambda: &mut [f64],
    k: &StepConsts,
    vf: VelocityFrame,
) -> f64 {
    let nl = prep.links.len();
    let (lam_links, lam_tris) = lambda.split_at_mut(nl);
    match relax {
        Relaxation::GaussSeidel | Relaxation::Sor { .. } => {
            let mut pos = Direct(x);
            sequential(prep, &mut pos, lam_links, lam_tris, k, vf)
        }
        Relaxation::Jacobi { .. } => {
            scratch.clear();
            scratch.resize(x.len(), V3::zeros());
            let res = {
                let mut pos = Deferred { x, dx: scratch };
                sequential(prep, &mut pos, lam_links, lam_tris, k, vf)
            };
            for (p, d) in x.iter_mut().zip(scratch.iter()) {
                *p += d;
            }
            res
        }
        Relaxation::ColoredGaussSeidel => colored(prep, x, lam_links, lam_tris, k, vf),
    }
}

fn sequential<P: Positions>(
    prep: &Prepared,
    pos: &mut P,
    lam_links: &mut [f64],
    lam_tris: &mut [f64],
    k: &StepConsts,
    vf: VelocityFrame,
) -> f64 {
    let mut res = 0.0f64;
    for l in &prep.links {
        let lam = &mut lam_links[l.k as usize];
        let (dl, r) = project_link(l, *lam, pos, k, vf);
        *lam += dl;
        res = res.max(r);
    }
    for t in &prep.tris {
        let lam = &mut lam_tris[3 * t.k as usize..3 * t.k as usize + 3];
        let (dl, r) = project_tri(t, [lam[0], lam[1], lam[2]], pos, k, vf);
        for c in 0..3 {
            lam[c] += dl[c];
        }
        res = res.max(r);
    }
    res
}

/// Smallest number of constraints worth a parallel task.
const MIN_CHUNK: usize = 256;

/// Chunk length splitting `n` constraints into one task per thread.
fn chunk_len(n: usize) -> usize {
    n.div_ceil(rayon::current_num_threads()).max(MIN_CHUNK)
}

fn colored(
    prep: &Prepared,
    x: &mut [V3],
    lam_links: &mut [f64],
    lam_tris: &mut [f64],
    k: &StepConsts,
    vf: VelocityFrame,
) -> f64 {
    let xs = Shared::new(x);
    let ll = Shared::new(lam_links);
    let lt = Shared::new(lam_tris);
    let links = par_classes(&prep.links, &prep.link_classes, xs, |l, pos| {
        let c = l.k as usize;
        let (dl, r) = project_link(l, ll.read(c), pos, k, vf);
        ll.add_to(c, dl);
        r
    });
    let tris = par_classes(&prep.tris, &prep.tri_classes, xs, |t, pos| {
        let c = 3 * t.k as usize;
        let lam = [lt.read(c), lt.read(c + 1), lt.read(c + 2)];
        let (dl, r) = project_tri(t, lam, pos, k, vf);
        for (q, d) in dl.iter().enumerate() {
            lt.add_to(c + q, *d);
        }
        r
    });
    links.max(tris)
}

/// Projects the colour classes (ranges of `items`) one after the other, the constraints of a
/// class in parallel; `project` returns a constraint's residual. Returns the largest.
fn par_classes<T: Sync>(
    items: &[T],
    classes: &[std::ops::Range<usize>],
    xs: Shared<V3>,
    project: impl Fn(&T, &mut Shared<V3>) -> f64 + Sync,
) -> f64 {
    let mut res = 0.0f64;
    for class in classes {
        let class = &items[class.clone()];
        let r = class
            .par_chunks(chunk_len(class.len()))
            .map(|chunk| {
                let mut pos = xs;
                chunk
                    .iter()
                    .map(|c| project(c, &mut pos))
                    .fold(0.0, f64::max)
            })
            .reduce(|| 0.0, f64::max);
        res = res.max(r);
    }
    res
}

/// Projects the rollers (hard plane constraints on single particles) sequentially; returns
/// the largest residual.
pub(crate) fn project_rollers(
    m: &ClothModel,
    x: &mut [V3],
    lambda: &mut [f64],
    k: &StepConsts,
    vf: VelocityFrame,
) -> f64 {
    let mut res = 0.0f64;
    for (r, lam) in m.rollers.iter().zip(lambda.iter_mut()) {
        let w = m.inv_mass[r.p];
        let s1 = k.s_coef * w;
        if s1 <= 0.0 {
            continue;
        }
        let normal = V3::from(r.normal);
        let mut rhs = k.alpha * (normal.dot(&x[r.p]) - r.offset);
        if k.gamma > 0.0 {
            let v = vf.v(r.p as u32, x[r.p], k.inv_bh);
            rhs += k.alpha * k.gamma * normal.dot(&v);
        }
        res = res.max(rhs.abs());
        let dl = -k.omega * rhs / s1;
        *lam += dl;
        x[r.p] += normal * (dl * k.sx * w);
    }
    res
}
