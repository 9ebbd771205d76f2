//! The simulated system: particles (positions, velocities, inverse masses, zero for pinned
//! particles), gravity, and soft link constraints `c = |x_i - x_j| - rest` with compliance
//! `1/k` (paper section 8).

use wscg_math::{Error, Result};

use crate::fem::FemTri;
use crate::vecs::{v3s, V3};

/// A distance constraint between two particles.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Link {
    /// First particle.
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Rest length (m, > 0).
    pub rest: f64,
    /// Compliance `eps = 1/k` (m/N, >= 0; 0 is a hard constraint).
    pub compliance: f64,
}

/// A hard equality constraint `n . x_p = offset` on one particle: a roller that lets the
/// particle slide in the plane (boundary conditions of the FEM patch test).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Roller {
    /// Particle.
    pub p: usize,
    /// Unit plane normal.
    pub normal: [f64; 3],
    /// Plane offset (m).
    pub offset: f64,
}

/// Particles and constraints.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClothModel {
    /// Positions (m).
    pub x: Vec<[f64; 3]>,
    /// Velocities (m/s).
    pub v: Vec<[f64; 3]>,
    /// Inverse masses (1/kg); 0 pins a particle.
    pub inv_mass: Vec<f64>,
    /// Link constraints, solved in this order by Gauss-Seidel.
    pub links: Vec<Link>,
    /// StVK membrane triangles (solved after the links).
    pub tris: Vec<FemTri>,
    /// Rollers (hard plane constraints on single particles, solved last).
    pub rollers: Vec<Roller>,
    /// Gravity (m/s^2).
    pub gravity: [f64; 3],
}

fn finite3(name: &'static str, v: &[[f64; 3]]) -> Result<()> {
    match v.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        Some(i) => Err(Error::NonFinite { name, index: 3 * i }),
        None => Ok(()),
    }
}

impl ClothModel {
    /// A model from particle positions and masses (kg; `f64::INFINITY` or a `pinned` index
    /// makes a particle immovable); velocities start at zero, gravity is 9.81 m/s^2 along -y.
    ///
    /// Errors: empty input, length mismatch, non-finite positions, negative or NaN masses,
    /// zero mass of a free particle, pinned index out of range.
    pub fn new(x: Vec<[f64; 3]>, mass: &[f64], pinned: &[usize]) -> Result<Self> {
        if x.is_empty() {
            return Err(Error::Empty("positions"));
        }
        if mass.len() != x.len() {
            return Err(Error::ShapeMismatch(format!(
                "{} masses for {} particles",
                mass.len(),
                x.len()
            )));
        }
        let mut inv_mass = Vec::with_capacity(mass.len());
        for (i, &m) in mass.iter().enumerate() {
            if m.is_nan() || m <= 0.0 {
                return Err(Error::invalid(
                    "mass",
                    format!("particle {i} has mass {m}; masses must be positive"),
                ));
            }
            inv_mass.push(1.0 / m);
        }
        for &p in pinned {
            *inv_mass.get_mut(p).ok_or_else(|| {
                Error::invalid(
                    "pinned",
                    format!("index {p} is out of range for {} particles", x.len()),
                )
            })? = 0.0;
        }
        let n = x.len();
        let m = Self {
            x,
            v: vec![[0.0; 3]; n],
            inv_mass,
            links: Vec::new(),
            tris: Vec::new(),
            rollers: Vec::new(),
            gravity: [0.0, -9.81, 0.0],
        };
        m.validate()?;
        Ok(m)
    }

    /// Adds a link with stiffness `k` (N/m; `f64::INFINITY` for a hard constraint) and rest
    /// length `rest` (the current distance when `None`).
    ///
    /// Errors: index out of range, `i == j`, a rest length that is not positive, `k <= 0`.
    pub fn add_link(&mut self, i: usize, j: usize, k: f64, rest: Option<f64>) -> Result<()> {
        let n = self.x.len();
        if i >= n || j >= n {
            return Err(Error::invalid(
                "link",
                format!("particle index ({i}, {j}) out of range for {n} particles"),
            ));
        }
        if i == j {
            return Err(Error::invalid(
                "link",
                format!("joins particle {i} to itself"),
            ));
        }
        if k.is_nan() || k <= 0.0 {
            return Err(Error::invalid(
                "k",
                format!("stiffness must be > 0, got {k}"),
            ));
        }
        let rest = rest.unwrap_or_else(|| (self.xs()[i] - self.xs()[j]).norm());
        if !(rest.is_finite() && rest > 0.0) {
            return Err(Error::invalid(
                "rest",
                format!("rest length of link ({i}, {j}) must be > 0, got {rest}"),
            ));
        }
        self.links.push(Link {
            i,
            j,
            rest,
            compliance: 1.0 / k,
        });
        Ok(())
    }

    /// Adds a StVK membrane triangle with Young's modulus `young` (N/m) and Poisson ratio
    /// `poisson`; rest coordinates `uv` default to the triangle's current shape in its own
    /// plane.
    ///
    /// Errors: indices out of range or repeated, degenerate rest triangle, bad material.
    pub fn add_fem_triangle(
        &mut self,
        idx: [usize; 3],
        uv: Option<[[f64; 2]; 3]>,
        young: f64,
        poisson: f64,
    ) -> Result<()> {
        let n = self.x.len();
        if idx.iter().any(|&p| p >= n) || idx[0] == idx[1] || idx[1] == idx[2] || idx[0] == idx[2] {
            return Err(Error::invalid(
                "triangle",
                format!("indices {idx:?} must be distinct and below {n}"),
            ));
        }
        let uv = uv.unwrap_or_else(|| FemTri::local_uv(idx.map(|p| self.x[p])));
        self.tris.push(FemTri::new(idx, uv, young, poisson)?);
        Ok(())
    }

    /// Adds a roller keeping particle `p` on the plane `normal . x = offset`.
    ///
    /// Errors: index out of range, a zero or non-finite normal, a non-finite offset.
    pub fn add_roller(&mut self, p: usize, normal: [f64; 3], offset: f64) -> Result<()> {
        if p >= self.x.len() {
            return Err(Error::invalid(
                "roller",
                format!("particle {p} out of range"),
            ));
        }
        let normal = V3::from(normal);
        let len = normal.norm();
        if !(len.is_finite() && len > 0.0 && offset.is_finite()) {
            return Err(Error::invalid(
                "roller",
                "needs a finite non-zero normal and offset",
            ));
        }
        self.rollers.push(Roller {
            p,
            normal: (normal / len).into(),
            offset: offset / len,
        });
        Ok(())
    }

    /// Positions as the solvers' vectors (the same memory).
    pub(crate) fn xs(&self) -> &[V3] {
        v3s(&self.x)
    }

    /// Velocities as the solvers' vectors (the same memory).
    pub(crate) fn vs(&self) -> &[V3] {
        v3s(&self.v)
    }

    /// Gravity as the solvers' vector.
    pub(crate) fn g(&self) -> V3 {
        V3::from(self.gravity)
    }

    /// Number of constraint rows: one per link, three per triangle, one per roller.
    pub fn constraint_rows(&self) -> usize {
        self.links.len() + 3 * self.tris.len() + self.rollers.len()
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Checks sizes, finiteness and constraint indices.
    pub fn validate(&self) -> Result<()> {
        let n = self.x.len();
        if self.v.len() != n || self.inv_mass.len() != n {
            return Err(Error::ShapeMismatch(format!(
                "{n} positions, {} velocities, {} inverse masses",
                self.v.len(),
                self.inv_mass.len()
            )));
        }
        finite3("positions", &self.x)?;
        finite3("velocities", &self.v)?;
        wscg_math::error::ensure_finite("gravity", &self.gravity)?;
        if let Some(i) = self
            .inv_mass
            .iter()
            .position(|w| !(w.is_finite() && *w >= 0.0))
        {
            return Err(Error::invalid(
                "inv_mass",
                format!("particle {i} has inverse mass {}", self.inv_mass[i]),
            ));
        }
        for l in &self.links {
            let bad_rest = l.rest.is_nan() || l.rest <= 0.0;
            let bad_compliance = l.compliance.is_nan() || l.compliance < 0.0;
            if l.i >= n || l.j >= n || l.i == l.j || bad_rest || bad_compliance {
                return Err(Error::invalid("links", format!("invalid link {l:?}")));
            }
        }
        if let Some(r) = self.rollers.iter().find(|r| r.p >= n) {
            return Err(Error::invalid("rollers", format!("invalid roller {r:?}")));
        }
        for t in &self.tris {
            if t.idx.iter().any(|&p| p >= n) {
                return Err(Error::invalid(
                    "tris",
                    format!("invalid triangle {:?}", t.idx),
                ));
            }
        }
        Ok(())
    }

    /// A vertical chain hanging from its pinned top particle: `n` particles of `mass` spaced
    /// `rest` apart along -y, joined by links of stiffness `k`.
    pub fn chain(n: usize, mass: f64, rest: f64, k: f64) -> Result<Self> {
        if n < 2 {
            return Err(Error::invalid("n", "a chain needs at least 2 particles"));
        }
        let x = (0..n).map(|i| [0.0, -(i as f64) * rest, 0.0]).collect();
        let mut m = Self::new(x, &vec![mass; n], &[0])?;
        for i in 0..n - 1 {
            m.add_link(i, i + 1, k, Some(rest))?;
        }
        Ok(m)
    }

    /// A cloth from a triangle mesh: `total_mass` lumped to the vertices by area (a third of
    /// each adjacent triangle's), gravity along -y. With `young = Some(E)` every face becomes
    /// a StVK membrane triangle (Poisson ratio `poisson`, rest shape = the given one);
    /// otherwise every edge becomes a link of stiffness `k_edge`. With `k_bend`, in both
    /// cases, a bending link joins the opposite vertices of the two faces of every interior
    /// edge (the bending links for irregular meshes of the paper's section 8, after \[Erl05\];
    /// the paper's own dihedral formulas are not given).
    ///
    /// Errors: empty input, face index out of range or repeated, degenerate faces, bad
    /// material, non-finite vertices, a vertex in no face.
    pub fn from_trimesh(
        vertices: &[[f64; 3]],
        faces: &[[usize; 3]],
        total_mass: f64,
        young: Option<(f64, f64)>,
        k_edge: f64,
        k_bend: Option<f64>,
    ) -> Result<Self> {
        if faces.is_empty() {
            return Err(Error::Empty("faces"));
        }
        if !(total_mass.is_finite() && total_mass > 0.0) {
            return Err(Error::invalid(
                "total_mass",
                format!("must be > 0, got {total_mass}"),
            ));
        }
        let n = vertices.len();
        finite3("vertices", vertices)?;
        let mut area = vec![0.0; n];
        let p = v3s(vertices);
        for (fi, f) in faces.iter().enumerate() {
            if f.iter().any(|&p| p >= n) || f[0] == f[1] || f[1] == f[2] || f[0] == f[2] {
                return Err(Error::invalid(
                    "faces",
                    format!("face {fi} {f:?} has repeated or out-of-range indices ({n} vertices)"),
                ));
            }
            let a = 0.5 * (p[f[1]] - p[f[0]]).cross(&(p[f[2]] - p[f[0]])).norm();
            if a < 1e-14 {
                return Err(Error::invalid("faces", format!("face {fi} is degenerate")));
            }
            for &p in f {
                area[p] += a / 3.0;
            }
        }
        if let Some(p) = area.iter().position(|&a| a == 0.0) {
            return Err(Error::invalid(
                "vertices",
                format!("vertex {p} is in no face"),
            ));
        }
        let total: f64 = area.iter().sum();
        let mass: Vec<f64> = area.iter().map(|a| total_mass * a / total).collect();
        let mut m = Self::new(vertices.to_vec(), &mass, &[])?;
        if let Some((e, nu)) = young {
            for f in faces {
                m.add_fem_triangle(*f, None, e, nu)?;
            }
        }
        if young.is_none() {
            for (a, b) in mesh_edges(faces).into_keys() {
                m.add_link(a, b, k_edge, None)?;
            }
        }
        if let Some(kb) = k_bend {
            m.add_bending_links(faces, kb)?;
        }
        Ok(m)
    }

    /// Adds a bending link of stiffness `k` (N/m, rest length = current distance) between
    /// the opposite vertices of the two triangles of every interior edge of `faces`.
    ///
    /// Errors: indices out of range, `k <= 0`, coincident opposite vertices.
    pub fn add_bending_links(&mut self, faces: &[[usize; 3]], k: f64) -> Result<()> {
        for opposite in mesh_edges(faces).into_values() {
            if let [c, d] = opposite.as_slice() {
                if c != d {
                    self.add_link(*c, *d, k, None)?;
                }
            }
        }
        Ok(())
    }

    /// A horizontal `nx x ny` grid of StVK membrane triangles (two per quad, rest
    /// coordinates = the grid's `(x, z)`, so `u` is the warp and `v` the weft direction) with
    /// Young's modulus `young` (N/m) and Poisson ratio `poisson`, total mass `total_mass`;
    /// the two corners of the first row are pinned.
    pub fn fem_grid(
        nx: usize,
        ny: usize,
        size: (f64, f64),
        total_mass: f64,
        young: f64,
        poisson: f64,
    ) -> Result<Self> {
        let mut m = Self::grid(nx, ny, size, total_mass, 1.0, None, None)?;
        m.links.clear();
        for t in grid_triangles(nx, ny) {
            let r = t.map(|p| [m.x[p][0], m.x[p][2]]);
            m.add_fem_triangle(t, Some(r), young, poisson)?;
        }
        Ok(m)
    }

    /// A horizontal `nx x ny` grid of particles in the x-z plane (`size` metres), total mass
    /// `total_mass`, with the quad-grid links of the paper's section 8: structural links to
    /// the next particle in each direction (stiffness `k_stretch`), shear links on both
    /// diagonals (`k_shear`) and bending links to the particle two steps away (`k_bend`).
    /// Links with stiffness `None` are left out. The two corners of the first row are pinned.
    pub fn grid(
        nx: usize,
        ny: usize,
        size: (f64, f64),
        total_mass: f64,
        k_stretch: f64,
        k_shear: Option<f64>,
        k_bend: Option<f64>,
    ) -> Result<Self> {
        if nx < 2 || ny < 2 {
            return Err(Error::invalid(
                "nx, ny",
                "a grid needs at least 2 x 2 particles",
            ));
        }
        if !(size.0 > 0.0 && size.1 > 0.0) {
            return Err(Error::invalid("size", "must be positive"));
        }
        // Per particle: state vectors, masses, about six links and the solver's rows; 512
        // bytes bounds them all.
        wscg_math::alloc::ensure_shape::<[u8; 512]>("nx, ny", &[nx, ny])?;
        let id = |i: usize, j: usize| j * nx + i;
        let x = (0..ny)
            .flat_map(|j| {
                (0..nx).map(move |i| {
                    [
                        size.0 * i as f64 / (nx - 1) as f64,
                        0.0,
                        size.1 * j as f64 / (ny - 1) as f64,
                    ]
                })
            })
            .collect();
        let n = nx * ny;
        let mut m = Self::new(
            x,
            &vec![total_mass / n as f64; n],
            &[id(0, 0), id(nx - 1, 0)],
        )?;
        // Links to the particle `step` away along each grid axis.
        let axis_links = |m: &mut Self, step: usize, k: f64| -> Result<()> {
            for j in 0..ny {
                for i in 0..nx {
                    if i + step < nx {
                        m.add_link(id(i, j), id(i + step, j), k, None)?;
                    }
                    if j + step < ny {
                        m.add_link(id(i, j), id(i, j + step), k, None)?;
                    }
                }
            }
            Ok(())
        };
        axis_links(&mut m, 1, k_stretch)?;
        if let Some(k) = k_shear {
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    m.add_link(id(i, j), id(i + 1, j + 1), k, None)?;
                    m.add_link(id(i + 1, j), id(i, j + 1), k, None)?;
                }
            }
        }
        if let Some(k) = k_bend {
            axis_links(&mut m, 2, k)?;
        }
        Ok(m)
    }
}

/// The edges of a triangle mesh (sorted vertex pairs, in order) with the vertex opposite
/// the edge in each adjacent triangle.
fn mesh_edges(faces: &[[usize; 3]]) -> std::collections::BTreeMap<(usize, usize), Vec<usize>> {
    let mut edges: std::collections::BTreeMap<(usize, usize), Vec<usize>> = Default::default();
    for f in faces {
        for k in 0..3 {
            let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(c);
        }
    }
    edges
}

/// The triangles of an `nx x ny` particle grid (row-major indices `j * nx + i`), two per
/// quad split along the `(i, j)-(i+1, j+1)` diagonal, counter-clockwise seen from +y.
pub fn grid_triangles(nx: usize, ny: usize) -> Vec<[usize; 3]> {
    let id = |i: usize, j: usize| j * nx + i;
    (0..ny.saturating_sub(1))
        .flat_map(|j| (0..nx.saturating_sub(1)).map(move |i| (i, j)))
        .flat_map(|(i, j)| {
            [
                [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
            ]
        })
        .collect()
}
