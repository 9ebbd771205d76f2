//! `wscg._native.cloth`: bindings of `wscg-cloth` (paper 02, cloth with soft constraints).
//! `python/wscg/cloth.py` documents the module, re-exports the model and obstacle
//! constructors defined here (arguments converted by [`crate::args`]) and wraps the
//! simulation in its `Sim` class.

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_cloth::{
    ClothModel, Collider, Collisions, LambdaMode, MeshCollider, Method, NcgVariant, Relaxation,
    Simulation, SolverParams,
};

use crate::args::{self, uint};
use crate::cfg::Cfg;
use crate::convert::{self, array, index, values, Arr};
use crate::errors::{value_error, IntoPy};

fn points(name: &str, a: &PyReadonlyArrayDyn<f64>) -> PyResult<Vec<[f64; 3]>> {
    match a.shape() {
        [_, 3] => Ok(values(a)
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect()),
        s => Err(value_error(format!(
            "`{name}` must have shape (n, 3), got {s:?}"
        ))),
    }
}

fn points_out<'py>(py: Python<'py>, p: &[[f64; 3]]) -> PyResult<Arr<'py, f64>> {
    array(py, &[p.len(), 3], p.as_flattened().to_vec())
}

impl PyModel {
    /// One 3-vector per particle from the array-like argument `name`.
    fn per_particle(&self, name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<[f64; 3]>> {
        let a = crate::args::array::<f64>(name, obj)?;
        let p = points(name, &a)?;
        if let Some(i) = p.as_flattened().iter().position(|v| !v.is_finite()) {
            return Err(value_error(format!(
                "`{name}` contains a non-finite value (NaN or infinity) at flat index {i}"
            )));
        }
        if p.len() != self.inner.len() {
            return Err(value_error(format!(
                "`{name}` has {} rows for {} particles",
                p.len(),
                self.inner.len()
            )));
        }
        Ok(p)
    }

    /// Replaces the per-particle field that `field` selects by argument `name`; on a model
    /// that `validate` refuses, the old values are put back and the error raised.
    fn set_per_particle(
        &mut self,
        name: &str,
        obj: &Bound<'_, PyAny>,
        field: impl Fn(&mut ClothModel) -> &mut Vec<[f64; 3]>,
    ) -> PyResult<()> {
        let new = self.per_particle(name, obj)?;
        let old = std::mem::replace(field(&mut self.inner), new);
        if let Err(e) = self.inner.validate() {
            *field(&mut self.inner) = old;
            return Err::<(), _>(e).py_err();
        }
        Ok(())
    }
}

/// A cloth: particles and constraints.
#[pyclass(module = "wscg._native.cloth", name = "Model")]
#[derive(Clone)]
pub struct PyModel {
    inner: ClothModel,
}

#[pymethods]
impl PyModel {
    /// Positions `(n, 3)`.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        points_out(py, &self.inner.x)
    }

    /// Velocities `(n, 3)`.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        points_out(py, &self.inner.v)
    }

    /// Sets the velocities `(n, 3)` (m/s; any real array-like).
    fn set_velocities(&mut self, velocities: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_per_particle("velocities", velocities, |m| &mut m.v)
    }

    /// Sets the positions `(n, 3)` (m; any real array-like), for instance a pre-stretched
    /// start; the constraints keep their rest lengths and areas.
    fn set_positions(&mut self, positions: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_per_particle("positions", positions, |m| &mut m.x)
    }

    /// Inverse masses `(n,)` (0 for pinned particles).
    #[getter]
    fn inv_mass<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        array(py, &[self.inner.len()], self.inner.inv_mass.clone())
    }

    /// Number of links, triangles and rollers.
    #[getter]
    fn counts(&self) -> (usize, usize, usize) {
        (
            self.inner.links.len(),
            self.inner.tris.len(),
            self.inner.rollers.len(),
        )
    }

    /// Pins the listed particles (they no longer move).
    fn pin(&mut self, indices: Vec<i64>) -> PyResult<()> {
        pin(&mut self.inner, convert::indices("indices", &indices)?)
    }

    /// Sets gravity (m/s^2).
    fn set_gravity(&mut self, g: (f64, f64, f64)) -> PyResult<()> {
        let g = [g.0, g.1, g.2];
        wscg_math::error::ensure_finite("gravity", &g).py_err()?;
        self.inner.gravity = g;
        Ok(())
    }

    /// Adds a link of stiffness `k` (N/m) between particles `i` and `j`.
    #[pyo3(signature = (i, j, k, rest=None))]
    fn add_link(&mut self, i: i64, j: i64, k: f64, rest: Option<f64>) -> PyResult<()> {
        let (i, j) = (index("i", i)?, index("j", j)?);
        self.inner.add_link(i, j, k, rest).py_err()
    }

    /// Adds a roller keeping particle `p` on the plane `normal . x = offset`.
    fn add_roller(&mut self, p: i64, normal: (f64, f64, f64), offset: f64) -> PyResult<()> {
        let p = index("p", p)?;
        self.inner
            .add_roller(p, [normal.0, normal.1, normal.2], offset)
            .py_err()
    }

    /// Energy of the state as a `wscg.cloth.Energy`: kinetic, gravity, elastic, total (J).
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        energy_out(
            py,
            &crate::pool::detach(py, || wscg_cloth::Energy::of(&self.inner))?,
        )
    }

    /// Pickles as the model's state (particles, constraints, gravity).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::state::Reduced<'py>> {
        crate::state::reduce(py, "cloth", "_model_from_state", &self.inner)
    }
}

/// A model from the state that `Model.__reduce__` pickles.
#[pyfunction]
fn _model_from_state(py: Python<'_>, state: &[u8]) -> PyResult<PyModel> {
    let inner: ClothModel = crate::state::from_bytes(py, "cloth model", state)?;
    inner.validate().py_err()?;
    Ok(PyModel { inner })
}

/// Pins the particles `indices` of `model`; an index out of range is a `ValueError` and
/// pins nothing.
fn pin(model: &mut ClothModel, indices: Vec<usize>) -> PyResult<()> {
    let n = model.len();
    if let Some(&p) = indices.iter().find(|&&p| p >= n) {
        return Err(value_error(format!(
            "pin index {p} out of range for {n} particles"
        )));
    }
    for p in indices {
        model.inv_mass[p] = 0.0;
    }
    Ok(())
}

/// `e` as the Python result class `wscg.cloth.Energy` (a named tuple, joules).
fn energy_out<'py>(py: Python<'py>, e: &wscg_cloth::Energy) -> PyResult<Bound<'py, PyAny>> {
    py.import("wscg.cloth")?
        .getattr("Energy")?
        .call1((e.kinetic, e.gravity, e.elastic, e.total))
}

/// Particles at ``positions`` ``(n, 3)`` with ``masses`` ``(n,)`` (kg), no constraints
/// yet (add them with ``Model.add_link`` and ``Model.add_roller``); gravity 9.81 m/s^2
/// along -y.
#[pyfunction]
#[pyo3(signature = (positions, masses, pinned=None))]
fn particles(
    py: Python<'_>,
    positions: &Bound<'_, PyAny>,
    masses: &Bound<'_, PyAny>,
    pinned: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyModel> {
    let x = points("positions", &args::array("positions", positions)?)?;
    let m = values(&args::array::<f64>("masses", masses)?).into_owned();
    let pinned = args::indices("pinned", pinned)?;
    let inner = crate::pool::detach(py, || ClothModel::new(x, &m, &pinned)).py_err()?;
    Ok(PyModel { inner })
}

/// A horizontal ``nx x ny`` cloth in the x-z plane (``size`` metres, total ``mass`` kg),
/// hanging from its two first-row corners; ``pinned`` pins further particles.
///
/// ``model="links"``: structural links (``k_stretch``), shear links on both diagonals
/// (``k_shear``, omitted when None) and bending links two particles apart (``k_bend``).
/// ``model="fem"``: two StVK membrane triangles per quad with ``young`` (N/m) and
/// ``poisson``, warp along x and weft along z.
#[pyfunction]
#[pyo3(signature = (nx, ny, size=(1.0, 1.0), mass=0.1, model="links", k_stretch=2000.0,
                    k_shear=None, k_bend=None, young=1000.0, poisson=0.3, pinned=None),
       text_signature = "(nx, ny, size=(1.0, 1.0), mass=0.1, model='links', k_stretch=2000.0, \
                         k_shear=None, k_bend=None, young=1000.0, poisson=0.3, pinned=None)")]
#[allow(clippy::too_many_arguments)]
fn grid(
    py: Python<'_>,
    nx: i128,
    ny: i128,
    size: (f64, f64),
    mass: f64,
    model: &str,
    k_stretch: f64,
    k_shear: Option<f64>,
    k_bend: Option<f64>,
    young: f64,
    poisson: f64,
    pinned: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyModel> {
    let nx: usize = uint(py, "nx", nx, 0)?;
    let ny: usize = uint(py, "ny", ny, 0)?;
    let fem = match model {
        "links" => false,
        "fem" => true,
        other => {
            return Err(value_error(format!(
                "`model` must be 'links' or 'fem', got {other:?}"
            )))
        }
    };
    let mut inner = crate::pool::detach(py, || {
        if fem {
            ClothModel::fem_grid(nx, ny, size, mass, young, poisson)
        } else {
            ClothModel::grid(nx, ny, size, mass, k_stretch, k_shear, k_bend)
        }
    })
    .py_err()?;
    pin(&mut inner, args::indices("pinned", pinned)?)?;
    Ok(PyModel { inner })
}

/// Triangles `(m, 3)` of non-negative indices.
fn faces_in(faces: &PyReadonlyArrayDyn<i64>) -> PyResult<Vec<[usize; 3]>> {
    match faces.shape() {
        [_, 3] => values(faces)
            .chunks_exact(3)
            .map(|c| {
                Ok([
                    index("faces", c[0])?,
                    index("faces", c[1])?,
                    index("faces", c[2])?,
                ])
            })
            .collect(),
        s => Err(value_error(format!(
            "`faces` must have shape (m, 3), got {s:?}"
        ))),
    }
}

/// A static obstacle (see `wscg.cloth.plane`, `sphere`, `capsule`, `mesh_collider`).
#[pyclass(module = "wscg._native.cloth", name = "Collider")]
#[derive(Clone)]
pub struct PyCollider {
    inner: Collider,
}

#[pymethods]
impl PyCollider {
    /// Signed distance to the surface of each point `(n, 3)` (negative inside).
    fn signed_distance<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Arr<'py, f64>> {
        let p = self::points("points", &points)?;
        let d = crate::pool::detach(py, || {
            p.iter().map(|&q| self.inner.signed_distance(q).0).collect()
        })?;
        array(py, &[p.len()], d)
    }

    fn __repr__(&self) -> String {
        format!("{:?}", self.inner)
    }

    /// Pickles as the obstacle's parameters (a mesh as its vertices and triangles).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::state::Reduced<'py>> {
        crate::state::reduce(py, "cloth", "_collider_from_state", &self.inner)
    }
}

/// An obstacle from the state that `Collider.__reduce__` pickles.
#[pyfunction]
fn _collider_from_state(py: Python<'_>, state: &[u8]) -> PyResult<PyCollider> {
    let inner: Collider = crate::state::from_bytes(py, "cloth collider", state)?;
    inner.validate().py_err()?;
    Ok(PyCollider { inner })
}

/// The solid half-space below the plane through ``point`` with outward ``normal`` (a
/// floor: ``plane((0, 1, 0), (0, y, 0))``).
#[pyfunction]
#[pyo3(signature = (normal, point=[0.0; 3]), text_signature = "(normal, point=(0.0, 0.0, 0.0))")]
fn plane(normal: [f64; 3], point: [f64; 3]) -> PyResult<PyCollider> {
    let normal = args::finite3("normal", normal)?;
    let inner = Collider::plane(normal, args::finite3("point", point)?).py_err()?;
    Ok(PyCollider { inner })
}

/// A solid ball.
#[pyfunction]
fn sphere(center: [f64; 3], radius: f64) -> PyResult<PyCollider> {
    let inner = Collider::Sphere {
        center: args::finite3("center", center)?,
        radius,
    };
    inner.validate().py_err()?;
    Ok(PyCollider { inner })
}

/// A solid capsule: the points within ``radius`` of the segment ``a``-``b``.
#[pyfunction]
fn capsule(a: [f64; 3], b: [f64; 3], radius: f64) -> PyResult<PyCollider> {
    let inner = Collider::Capsule {
        a: args::finite3("a", a)?,
        b: args::finite3("b", b)?,
        radius,
    };
    inner.validate().py_err()?;
    Ok(PyCollider { inner })
}

/// A closed triangle mesh obstacle (``vertices`` ``(n, 3)``, ``faces`` ``(m, 3)``, outward
/// counter-clockwise winding), queried through a bounding volume hierarchy.
#[pyfunction]
fn mesh_collider(
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
) -> PyResult<PyCollider> {
    let v = points("vertices", &args::array("vertices", vertices)?)?;
    let f = faces_in(&args::faces(faces)?)?;
    Ok(PyCollider {
        inner: Collider::Mesh(crate::pool::detach(py, || MeshCollider::new(&v, &f)).py_err()?),
    })
}

/// A cloth from a triangle mesh (``vertices`` ``(n, 3)``, ``faces`` ``(m, 3)``), with
/// ``mass`` lumped to the vertices by area. ``model="fem"`` makes every face a StVK
/// membrane triangle with the mesh's shape at rest; ``model="links"`` makes every edge a link
/// (``k_edge``). With ``k_bend`` (N/m), in both models, a bending link joins the opposite
/// vertices of the two faces of every interior edge.
#[pyfunction]
#[pyo3(signature = (vertices, faces, mass=0.1, model="fem", young=1000.0, poisson=0.3,
                    k_edge=2000.0, k_bend=None, pinned=None))]
#[allow(clippy::too_many_arguments)]
fn from_mesh(
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    mass: f64,
    model: &str,
    young: f64,
    poisson: f64,
    k_edge: f64,
    k_bend: Option<f64>,
    pinned: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyModel> {
    let v = points("vertices", &args::array("vertices", vertices)?)?;
    let f = faces_in(&args::faces(faces)?)?;
    let material = match model {
        "fem" => Some((young, poisson)),
        "links" => None,
        other => {
            return Err(value_error(format!(
                "`model` must be 'links' or 'fem', got {other:?}"
            )))
        }
    };
    let mut inner = crate::pool::detach(py, || {
        ClothModel::from_trimesh(&v, &f, mass, material, k_edge, k_bend)
    })
    .py_err()?;
    pin(&mut inner, args::indices("pinned", pinned)?)?;
    Ok(PyModel { inner })
}

/// A running simulation.
#[pyclass(module = "wscg._native.cloth", name = "Sim")]
pub struct PySim {
    inner: Simulation,
}

/// The solver of `name` with its options from `spec` (absent or `None`: the defaults).
fn method_from(name: &str, spec: &Bound<'_, PyDict>) -> PyResult<Method> {
    let c = Cfg(spec);
    Ok(match name {
        "soft" => Method::SoftProjection,
        "pbd" => Method::PlainPbd {
            stiffness: c.get("stiffness", 1.0)?,
        },
        "symplectic" => Method::SymplecticEuler {
            substeps: c.count("n_substeps", 64, 1)?,
        },
        "ie_cg" => Method::ImplicitEulerCg {
            tol: c.get("tol", 1e-8)?,
            max_iter: c.count("max_iter", 1000, 0)?,
        },
        "ie_direct" => Method::ImplicitEulerDirect,
        "ie_newton" => Method::ImplicitEulerNewton {
            tol: c.get("tol", 1e-10)?,
        },
        "global_cr" => Method::GlobalCr {
            primal_residual: c.get("primal_residual", true)?,
            tol: c.get("tol", 1e-10)?,
        },
        "ncg" => Method::Ncg {
            variant: NcgVariant::Consistent,
        },
        "ncg_paper" => Method::Ncg {
            variant: NcgVariant::Paper,
        },
        other => {
            return Err(value_error(format!(
                "unknown method {other:?}; use 'soft', 'pbd', 'symplectic', 'ie_cg', \
                 'ie_direct', 'ie_newton', 'global_cr', 'ncg' or 'ncg_paper'"
            )))
        }
    })
}

fn relaxation_from(spec: &Bound<'_, PyDict>) -> PyResult<Relaxation> {
    let c = Cfg(spec);
    let name: String = c.get("relaxation", "gauss_seidel".to_string())?;
    Ok(match name.as_str() {
        "gauss_seidel" => Relaxation::GaussSeidel,
        "colored" => Relaxation::ColoredGaussSeidel,
        "jacobi" => Relaxation::Jacobi {
            omega: c.get("omega", 0.15)?,
        },
        "sor" => Relaxation::Sor {
            omega: c.get("omega", 1.5)?,
        },
        other => {
            return Err(value_error(format!(
                "unknown relaxation {other:?}; use 'gauss_seidel', 'colored', 'jacobi' or 'sor'"
            )))
        }
    })
}

#[pymethods]
impl PySim {
    #[new]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        model: &PyModel,
        method: &str,
        n_iter: i128,
        alpha: f64,
        beta: f64,
        gamma: f64,
        lambda_mode: &str,
        velocity_damping: f64,
        options: &Bound<'_, PyDict>,
    ) -> PyResult<Self> {
        let n_iter: usize = uint(py, "n_iter", n_iter, 1)?;
        let cfg = SolverParams::default()
            .method(method_from(method, options)?)
            .iterations(n_iter)
            .alpha(alpha)
            .beta(beta)
            .gamma(gamma)
            .lambda_mode(match lambda_mode {
                "accumulate" => LambdaMode::Accumulate,
                "paper" => LambdaMode::PaperReset,
                other => {
                    return Err(value_error(format!(
                        "`lambda_mode` must be 'accumulate' or 'paper', got {other:?}"
                    )))
                }
            })
            .velocity_damping(velocity_damping)
            .relaxation(relaxation_from(options)?);
        Ok(Self {
            inner: crate::pool::detach(py, || Simulation::new(model.inner.clone(), cfg))
                .py_err()?,
        })
    }

    /// Advances `n_steps` steps of `h` seconds; returns the energies after each step as a
    /// `(n_steps, 4)` array (kinetic, gravity, elastic, total).
    fn step<'py>(&mut self, py: Python<'py>, h: f64, n_steps: i128) -> PyResult<Arr<'py, f64>> {
        let n: usize = uint(py, "n_steps", n_steps, 0)?;
        let sim = &mut self.inner;
        let rows = crate::pool::detach(py, || -> wscg_math::Result<Vec<f64>> {
            let mut out = wscg_math::alloc::try_with_capacity(
                "n_steps",
                wscg_math::alloc::elements("n_steps", &[n, 4])?,
            )?;
            for _ in 0..n {
                sim.step(h)?;
                let e = sim.energy();
                out.extend([e.kinetic, e.gravity, e.elastic, e.total]);
            }
            Ok(out)
        })
        .py_err()?;
        array(py, &[n, 4], rows)
    }

    /// Sets the obstacles, thickness, friction and self contacts.
    fn set_collisions(
        &mut self,
        py: Python<'_>,
        colliders: Vec<PyRef<'_, PyCollider>>,
        thickness: f64,
        friction: f64,
        self_collision: bool,
    ) -> PyResult<()> {
        let c = Collisions {
            colliders: colliders.iter().map(|c| c.inner.clone()).collect(),
            thickness,
            friction,
            self_collision,
        };
        let sim = &mut self.inner;
        crate::pool::detach(py, || sim.set_collisions(c)).py_err()
    }

    /// Positions `(n, 3)`.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        points_out(py, &self.inner.model().x)
    }

    /// Velocities `(n, 3)`.
    #[getter]
    fn velocities<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        points_out(py, &self.inner.model().v)
    }

    /// Constraint multipliers of the last step.
    #[getter]
    fn multipliers<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        let l = self.inner.multipliers();
        array(py, &[l.len()], l.to_vec())
    }

    /// Reaction forces of the rollers in the last step (N along each roller's normal, in
    /// the order they were added), the same for every method that supports rollers.
    #[getter]
    fn roller_forces<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        let l = self.inner.roller_forces();
        array(py, &[l.len()], l.to_vec())
    }

    /// Steps taken.
    #[getter]
    fn n_steps(&self) -> u64 {
        self.inner.steps()
    }

    /// Current energy as a `wscg.cloth.Energy`.
    fn energy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        energy_out(py, &crate::pool::detach(py, || self.inner.energy())?)
    }

    /// The current state as a model.
    fn model(&self) -> PyModel {
        PyModel {
            inner: self.inner.model().clone(),
        }
    }

    /// Pickles as the simulation's state (model, parameters, multipliers of the last step,
    /// step count, collisions): the copy steps exactly as the original.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<crate::state::Reduced<'py>> {
        crate::state::reduce(py, "cloth", "_sim_from_state", &self.inner)
    }
}

/// A simulation from the state that `Sim.__reduce__` pickles.
#[pyfunction]
fn _sim_from_state(py: Python<'_>, state: &[u8]) -> PyResult<PySim> {
    Ok(PySim {
        inner: crate::state::from_bytes(py, "cloth simulation", state)?,
    })
}

/// Registers the submodule's functions and classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyModel>()?;
    m.add_class::<PySim>()?;
    m.add_function(wrap_pyfunction!(particles, m)?)?;
    m.add_function(wrap_pyfunction!(grid, m)?)?;
    m.add_function(wrap_pyfunction!(from_mesh, m)?)?;
    m.add_class::<PyCollider>()?;
    m.add_function(wrap_pyfunction!(plane, m)?)?;
    m.add_function(wrap_pyfunction!(sphere, m)?)?;
    m.add_function(wrap_pyfunction!(capsule, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_collider, m)?)?;
    m.add_function(wrap_pyfunction!(_model_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(_collider_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(_sim_from_state, m)?)?;
    Ok(())
}
