//! Collisions (paper section 10): contacts with static obstacles and between the cloth's own
//! particles, solved as inequality constraints (`eps = 0`, projected only while violated)
//! in the same iteration loop as the cloth's constraints, with Coulomb friction applied per
//! contact iteration.
//!
//! At the start of a step every free particle's candidate position `x~` is tested against
//! each obstacle; a particle closer than `thickness + margin` (the margin covers the motion
//! of the step) gets a contact: the obstacle's closest point `q` and outward normal `n`, and
//! the linearised constraint `n . (x - q) >= thickness`. Each iteration projects the violated
//! contacts (`x += -c n`) and then removes tangential motion of the step up to `mu` times the
//! normal correction (static friction when it covers it all, kinetic otherwise).
//!
//! Obstacles are planes, spheres and capsules (closed form) and arbitrary closed triangle
//! meshes (a body or a chair), queried through parry's bounding volume hierarchy. Self
//! contacts keep particles that share no constraint at least `thickness` apart; candidate
//! pairs come from a uniform hash grid built on `x~`.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use nalgebra::Vector3;
use parry3d::math::Vector as PVec;
use parry3d::query::PointQuery;
use parry3d::shape::{TriMesh as ParryMesh, TriMeshFlags};
use wscg_math::{Error, Result};

use crate::model::ClothModel;
use crate::vecs::V3;

/// A static obstacle.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum Collider {
    /// The half-space `normal . x >= offset` (a floor, a wall).
    Plane {
        /// Unit normal pointing out of the obstacle.
        normal: [f64; 3],
        /// Offset (m).
        offset: f64,
    },
    /// A solid ball.
    Sphere {
        /// Centre (m).
        center: [f64; 3],
        /// Radius (m, > 0).
        radius: f64,
    },
    /// A solid capsule: the points within `radius` of the segment `a`-`b`.
    Capsule {
        /// First end of the axis.
        a: [f64; 3],
        /// Second end of the axis.
        b: [f64; 3],
        /// Radius (m, > 0).
        radius: f64,
    },
    /// A closed, consistently oriented triangle mesh (outward normals), e.g. a body.
    Mesh(MeshCollider),
}

/// A triangle-mesh obstacle with its bounding volume hierarchy.
///
/// It serialises as its vertices (single precision, as the hierarchy stores them) and
/// triangles; deserialising rebuilds the hierarchy.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
#[serde(into = "MeshParts", try_from = "MeshParts")]
pub struct MeshCollider {
    mesh: Arc<ParryMesh>,
}

impl std::fmt::Debug for MeshCollider {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MeshCollider({} triangles)", self.mesh.indices().len())
    }
}

/// The serialised form of a [`MeshCollider`].
#[derive(serde::Serialize, serde::Deserialize)]
struct MeshParts {
    vertices: Vec<[f32; 3]>,
    faces: Vec<[u32; 3]>,
}

impl From<MeshCollider> for MeshParts {
    fn from(m: MeshCollider) -> Self {
        Self {
            vertices: m.mesh.vertices().iter().map(|v| [v.x, v.y, v.z]).collect(),
            faces: m.mesh.indices().to_vec(),
        }
    }
}

impl TryFrom<MeshParts> for MeshCollider {
    type Error = Error;

    fn try_from(p: MeshParts) -> Result<Self> {
        // Single-precision vertices round-trip through f64 unchanged.
        let v: Vec<[f64; 3]> = p.vertices.iter().map(|c| c.map(f64::from)).collect();
        let f: Vec<[usize; 3]> = p.faces.iter().map(|f| f.map(|i| i as usize)).collect();
        Self::new(&v, &f)
    }
}

impl MeshCollider {
    /// A mesh obstacle from vertices and triangles (outward-facing, counter-clockwise).
    ///
    /// Errors: no triangles, non-finite vertices, indices out of range, a mesh parry cannot
    /// orient (open or inconsistently wound).
    pub fn new(vertices: &[[f64; 3]], faces: &[[usize; 3]]) -> Result<Self> {
        if faces.is_empty() {
            return Err(Error::Empty("collider faces"));
        }
        if vertices.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
            return Err(Error::invalid("collider", "vertices must be finite"));
        }
        let n = vertices.len();
        if let Some(f) = faces.iter().find(|f| f.iter().any(|&p| p >= n)) {
            return Err(Error::invalid(
                "collider",
                format!("face {f:?} out of range for {n} vertices"),
            ));
        }
        let v = vertices
            .iter()
            .map(|p| PVec::new(p[0] as f32, p[1] as f32, p[2] as f32))
            .collect();
        let idx = faces.iter().map(|f| f.map(|p| p as u32)).collect();
        let mesh = ParryMesh::with_flags(v, idx, TriMeshFlags::ORIENTED)
            .map_err(|e| Error::invalid("collider", format!("invalid mesh: {e:?}")))?;
        Ok(Self {
            mesh: Arc::new(mesh),
        })
    }

    /// Closest surface point and whether `p` is inside.
    fn project(&self, p: &V3) -> (V3, bool) {
        let q = self
            .mesh
            .project_local_point(PVec::new(p.x as f32, p.y as f32, p.z as f32), false);
        (
            V3::new(q.point.x as f64, q.point.y as f64, q.point.z as f64),
            q.is_inside,
        )
    }
}

impl Collider {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        let finite = |v: &[f64; 3]| v.iter().all(|c| c.is_finite());
        let ok = match self {
            Collider::Plane { normal, offset } => {
                finite(normal)
                    && offset.is_finite()
                    && (V3::from(*normal).norm() - 1.0).abs() < 1e-9
            }
            Collider::Sphere { center, radius } => {
                finite(center) && radius.is_finite() && *radius > 0.0
            }
            Collider::Capsule { a, b, radius } => {
                finite(a) && finite(b) && radius.is_finite() && *radius > 0.0
            }
            Collider::Mesh(_) => true,
        };
        if ok {
            Ok(())
        } else {
            Err(Error::invalid(
                "collider",
                format!("{self:?}: needs finite values, a unit plane normal and a radius > 0"),
            ))
        }
    }

    /// A plane through `point` with outward `normal` (normalised here).
    pub fn plane(normal: [f64; 3], point: [f64; 3]) -> Result<Self> {
        let normal = V3::from(normal);
        let len = normal.norm();
        if !(len.is_finite() && len > 0.0) {
            return Err(Error::invalid("normal", "must be finite and non-zero"));
        }
        let normal = normal / len;
        let c = Collider::Plane {
            normal: normal.into(),
            offset: normal.dot(&V3::from(point)),
        };
        c.validate()?;
        Ok(c)
    }

    /// Signed distance of `p` to the surface and the outward normal there (the closest
    /// surface point is `p - d n`).
    pub fn signed_distance(&self, p: [f64; 3]) -> (f64, [f64; 3]) {
        let (d, n) = self.signed_distance_v(&V3::from(p));
        (d, n.into())
    }

    /// [`Collider::signed_distance`] on the solvers' vectors.
    fn signed_distance_v(&self, p: &V3) -> (f64, V3) {
        let ball = |c: V3, r: f64| {
            let d = p - c;
            let len = d.norm();
            let n = if len > 1e-12 { d / len } else { V3::y() };
            (len - r, n)
        };
        match self {
            Collider::Plane { normal, offset } => {
                let normal = V3::from(*normal);
                (normal.dot(p) - offset, normal)
            }
            Collider::Sphere { center, radius } => ball(V3::from(*center), *radius),
            Collider::Capsule { a, b, radius } => {
                let (a, b) = (V3::from(*a), V3::from(*b));
                let ab = b - a;
                let l2 = ab.norm_squared();
                let t = if l2 > 0.0 {
                    ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                ball(a + ab * t, *radius)
            }
            Collider::Mesh(m) => {
                let (q, inside) = m.project(p);
                let d = p - q;
                let len = d.norm();
                if len < 1e-9 {
                    return (0.0, V3::y());
                }
                if inside {
                    (-len, -d / len)
                } else {
                    (len, d / len)
                }
            }
        }
    }
}

/// Collision settings of a simulation.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Collisions {
    /// Static obstacles.
    pub colliders: Vec<Collider>,
    /// Cloth thickness (m): the distance kept from obstacles and between particles.
    pub thickness: f64,
    /// Coulomb friction coefficient (>= 0) against obstacles.
    pub friction: f64,
    /// Whether particles that share no constraint repel each other.
    pub self_collision: bool,
}

impl Default for Collisions {
    fn default() -> Self {
        Self {
            colliders: Vec::new(),
            thickness: 0.005,
            friction: 0.3,
            self_collision: false,
        }
    }
}

impl Collisions {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        if !(self.thickness.is_finite() && self.thickness > 0.0) {
            return Err(Error::invalid(
                "thickness",
                format!("must be > 0, got {}", self.thickness),
            ));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(Error::invalid(
                "friction",
                format!("must be finite and >= 0, got {}", self.friction),
            ));
        }
        self.colliders.iter().try_for_each(Collider::validate)
    }

    /// Whether there is anything to collide with.
    pub fn is_active(&self) -> bool {
        !self.colliders.is_empty() || self.self_collision
    }
}

/// A contact of particle `p` with an obstacle: `n . (x - q) >= thickness`.
#[derive(Clone, Copy, Debug)]
struct Contact {
    p: usize,
    n: V3,
    q: V3,
}

/// The contacts of one step.
#[derive(Clone, Debug, Default)]
pub(crate) struct StepContacts {
    obstacles: Vec<Contact>,
    pairs: Vec<(usize, usize)>,
}

impl StepContacts {
    /// Number of contacts (obstacle contacts plus particle pairs).
    pub(crate) fn len(&self) -> usize {
        self.obstacles.len() + self.pairs.len()
    }
}

/// The collision settings of a simulation with what they need at every step.
#[derive(Clone, Debug, Default)]
pub(crate) struct CollisionState {
    pub(crate) settings: Collisions,
    /// Particle pairs joined by a constraint (no self contacts between them).
    neighbours: HashSet<(usize, usize)>,
}

impl CollisionState {
    pub(crate) fn new(settings: Collisions, m: &ClothModel) -> Self {
        let neighbours = if settings.self_collision {
            neighbours(m)
        } else {
            HashSet::new()
        };
        Self {
            settings,
            neighbours,
        }
    }

    /// The contacts of the candidate positions `x` (moved from `m.x` this step), if any
    /// collision handling is on.
    pub(crate) fn detect(&self, m: &ClothModel, x: &[V3]) -> Option<StepContacts> {
        self.settings
            .is_active()
            .then(|| detect(&self.settings, m, x, m.xs(), &self.neighbours))
    }

    /// Projects the contacts once (see [`project`]).
    pub(crate) fn project(
        &self,
        contacts: &Option<StepContacts>,
        m: &ClothModel,
        x: &mut [V3],
    ) -> f64 {
        match contacts {
            Some(c) => project(&self.settings, c, &m.inv_mass, x, m.xs()),
            None => 0.0,
        }
    }
}

/// Particles joined by a constraint (self contacts between them are skipped).
fn neighbours(m: &ClothModel) -> HashSet<(usize, usize)> {
    let mut s = HashSet::new();
    let mut add = |a: usize, b: usize| {
        s.insert((a.min(b), a.max(b)));
    };
    for l in &m.links {
        add(l.i, l.j);
    }
    for t in &m.tris {
        let [a, b, c] = t.idx;
        add(a, b);
        add(b, c);
        add(a, c);
    }
    s
}

/// Finds the contacts of the candidate positions `x` (moved from `x_start` this step).
fn detect(
    col: &Collisions,
    m: &ClothModel,
    x: &[V3],
    x_start: &[V3],
    excluded: &HashSet<(usize, usize)>,
) -> StepContacts {
    let mut out = StepContacts::default();
    let th = col.thickness;
    for (p, xp) in x.iter().enumerate() {
        if m.inv_mass[p] == 0.0 {
            continue;
        }
        let margin = th + (xp - x_start[p]).norm();
        for c in &col.colliders {
            let (d, n) = c.signed_distance_v(xp);
            if d < th + margin {
                out.obstacles.push(Contact {
                    p,
                    n,
                    q: xp - n * d,
                });
            }
        }
    }
    if col.self_collision {
        // Hash grid of cell `2 thickness + motion`: pairs closer than that meet in
        // neighbouring cells.
        let motion = x
            .iter()
            .zip(x_start)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        let cell = 2.0 * th + 2.0 * motion;
        let key = |p: &V3| (p / cell).map(|c| c.floor() as i64);
        let mut grid: HashMap<Vector3<i64>, Vec<usize>> = HashMap::new();
        for (p, xp) in x.iter().enumerate() {
            grid.entry(key(xp)).or_default().push(p);
        }
        for (p, xp) in x.iter().enumerate() {
            let k = key(xp);
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let Some(cellp) = grid.get(&(k + Vector3::new(dx, dy, dz))) else {
                            continue;
                        };
                        for &q in cellp {
                            if q <= p
                                || (m.inv_mass[p] == 0.0 && m.inv_mass[q] == 0.0)
                                || excluded.contains(&(p, q))
                            {
                                continue;
                            }
                            if (x[q] - xp).norm() < cell {
                                out.pairs.push((p, q));
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

/// Projects the violated contacts once, with friction against obstacles; returns the
/// largest violation met.
fn project(
    col: &Collisions,
    contacts: &StepContacts,
    inv_mass: &[f64],
    x: &mut [V3],
    x_start: &[V3],
) -> f64 {
    let th = col.thickness;
    let mut worst = 0.0f64;
    for c in &contacts.obstacles {
        let pen = th - c.n.dot(&(x[c.p] - c.q));
        if pen <= 0.0 {
            continue;
        }
        worst = worst.max(pen);
        x[c.p] += c.n * pen;
        // Coulomb friction on the tangential motion of the step.
        let dx = x[c.p] - x_start[c.p];
        let dt = dx - c.n * c.n.dot(&dx);
        let lt = dt.norm();
        if lt > 0.0 {
            let limit = col.friction * pen;
            x[c.p] -= if lt <= limit { dt } else { dt * (limit / lt) };
        }
    }
    for &(p, q) in &contacts.pairs {
        let (wp, wq) = (inv_mass[p], inv_mass[q]);
        let d = x[p] - x[q];
        let len = d.norm();
        let pen = th - len;
        if pen <= 0.0 || len < 1e-12 {
            continue;
        }
        worst = worst.max(pen);
        let corr = d * (pen / (len * (wp + wq)));
        x[p] += corr * wp;
        x[q] -= corr * wq;
    }
    worst
}
