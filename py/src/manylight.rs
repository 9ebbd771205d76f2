//! Bindings of `wscg_raytrace::manylight` (paper 08: many-light rendering with adaptive
//! importance caching), registered in `wscg._native.raytrace`. The documented API is
//! `python/wscg/_manylight.py`, re-exported by `wscg.raytrace`.

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wscg_math::progress::NoProgress;
use wscg_math::vec3::add;
use wscg_raytrace::manylight::weights::record_weight;
use wscg_raytrace::manylight::{
    load_obj, run, scenes, Camera, ManyLightParams, Method, PixelFilter, Scene, Triangle,
};

use crate::args::{self, uint};
use crate::cfg::Cfg;
use crate::convert::{array, rows3, values, Arr};
use crate::errors::IntoPy;

/// A many-light scene: Lambertian triangles (some emissive) and a camera.
#[pyclass(module = "wscg._native.raytrace", name = "ManyLightScene", frozen)]
pub struct PyScene {
    scene: Scene,
    camera: Camera,
}

fn camera_dict<'py>(py: Python<'py>, c: &Camera) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("eye", c.eye)?;
    d.set_item("target", c.target)?;
    d.set_item("up", c.up)?;
    d.set_item("fov_deg", c.fov_deg)?;
    d.set_item("width", c.width)?;
    d.set_item("height", c.height)?;
    Ok(d)
}

/// `base` with the entries of `spec` (keys of [`camera_dict`]) replaced.
fn camera_from(spec: Option<&Bound<'_, PyDict>>, base: &Camera) -> PyResult<Camera> {
    let Some(spec) = spec else {
        return Ok(base.clone());
    };
    let c = Cfg(spec);
    let v = |k: &str, d: [f64; 3]| -> PyResult<[f64; 3]> { Ok(c.opt::<[f64; 3]>(k)?.unwrap_or(d)) };
    let cam = Camera {
        eye: v("eye", base.eye)?,
        target: v("target", base.target)?,
        up: v("up", base.up)?,
        fov_deg: c.get("fov_deg", base.fov_deg)?,
        width: c.get("width", base.width)?,
        height: c.get("height", base.height)?,
    };
    cam.frame().py_err()?;
    Ok(cam)
}

#[pymethods]
impl PyScene {
    /// Number of (non-degenerate) triangles.
    #[getter]
    fn n_triangles(&self) -> usize {
        self.scene.len()
    }

    /// Number of emissive triangles.
    #[getter]
    fn n_emitters(&self) -> usize {
        self.scene.emitters().len()
    }

    /// Degenerate input triangles that were skipped.
    #[getter]
    fn n_skipped_degenerate(&self) -> usize {
        self.scene.skipped_degenerate
    }

    /// The scene's camera as a dict (eye, target, up, fov_deg, width, height).
    #[getter]
    fn camera<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        camera_dict(py, &self.camera)
    }

    /// The triangles' corners, (F, 3, 3) float64.
    fn triangle_vertices<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        let t = self.scene.triangles();
        let data = t
            .iter()
            .flat_map(|t| {
                let (a, b, c) = (t.p0, add(t.p0, t.e1), add(t.p0, t.e2));
                [a, b, c].into_iter().flatten()
            })
            .collect();
        array(py, &[t.len(), 3, 3], data)
    }

    /// Per-triangle albedo, (F, 3) float64.
    fn triangle_albedo<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        let n = self.scene.len() as u32;
        let data = (0..n).flat_map(|i| self.scene.albedo(i)).collect();
        array(py, &[n as usize, 3], data)
    }

    /// Per-triangle emitted radiance, (F, 3) float64.
    fn triangle_emission<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f64>> {
        let n = self.scene.len() as u32;
        let data = (0..n).flat_map(|i| self.scene.emission(i)).collect();
        array(py, &[n as usize, 3], data)
    }

    /// Shadow rays: whether the segment from each origin (N, 3) to its target (N, 3) is
    /// blocked, in parallel.
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        origins: PyReadonlyArrayDyn<f64>,
        targets: PyReadonlyArrayDyn<f64>,
    ) -> PyResult<Arr<'py, bool>> {
        let o = rows3("origins", &values(&origins), origins.shape())?;
        let t = rows3("targets", &values(&targets), targets.shape())?;
        let hit = crate::pool::detach(py, || self.scene.occluded_batch(&o, &t)).py_err()?;
        array(py, &[hit.len()], hit)
    }

    /// Pickles as the scene's parts: the triangles as `(p0, e1, e2)` rows `(F, 3, 3)`, albedo
    /// and emission `(F, 3)`, the skipped count and the camera (the hierarchy is rebuilt).
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        Bound<'py, PyAny>,
        (
            Arr<'py, f64>,
            Arr<'py, f64>,
            Arr<'py, f64>,
            usize,
            Bound<'py, PyDict>,
        ),
    )> {
        let t = self.scene.triangles();
        let tris = t
            .iter()
            .flat_map(|t| [t.p0, t.e1, t.e2])
            .flatten()
            .collect();
        let restore = py
            .import("wscg._native.raytrace")?
            .getattr("_manylight_scene_from_parts")?;
        Ok((
            restore,
            (
                array(py, &[t.len(), 3, 3], tris)?,
                self.triangle_albedo(py)?,
                self.triangle_emission(py)?,
                self.scene.skipped_degenerate,
                camera_dict(py, &self.camera)?,
            ),
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "ManyLightScene({} triangles, {} emitters, camera {} x {})",
            self.scene.len(),
            self.scene.emitters().len(),
            self.camera.width,
            self.camera.height
        )
    }
}

/// A procedural scene with its camera.
///
/// ``name``: ``'cornell'`` (the Cornell box of the paper's Fig. 3), ``'colonnade'`` (a hall
/// of pillars lit through a roof opening, standing in for Sponza), ``'conference'`` (a room
/// with a table and chairs half under it, standing in for Conference) or ``'plane'`` (a
/// plane under a tiny light, for the closed-form check). ``subdiv`` splits every quad into
/// ``subdiv x subdiv`` cells (more triangles, same picture).
///
/// >>> s = make_manylight_scene("cornell", width=64, height=48)
/// >>> s.n_triangles, s.n_emitters
/// (36, 2)
#[pyfunction]
#[pyo3(signature = (name="cornell", subdiv=1, width=256, height=192))]
fn make_manylight_scene(
    py: Python<'_>,
    name: &str,
    subdiv: i128,
    width: i128,
    height: i128,
) -> PyResult<PyScene> {
    let subdiv: u32 = uint(py, "subdiv", subdiv, 0)?;
    let (width, height): (usize, usize) =
        (uint(py, "width", width, 0)?, uint(py, "height", height, 0)?);
    let (scene, camera) =
        crate::pool::detach(py, || scenes::by_name(name, subdiv, width, height)).py_err()?;
    Ok(PyScene { scene, camera })
}

/// The camera used when a user scene comes without one.
fn default_camera() -> Camera {
    Camera {
        eye: [0.0, 0.0, 5.0],
        target: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        fov_deg: 45.0,
        width: 256,
        height: 192,
    }
}

/// A scene from an indexed triangle mesh: ``vertices`` (V, 3), ``faces`` (F, 3)
/// (counter-clockwise seen from the front; emitters radiate from the front), per-face
/// ``albedo`` (F, 3) in [0, 1] and emitted radiance ``emission`` (F, 3) >= 0. ``camera``:
/// dict with ``eye``, ``target``, ``up``, ``fov_deg`` (vertical, degrees), ``width``,
/// ``height``. Degenerate triangles are skipped (counted by ``n_skipped_degenerate``).
#[pyfunction]
#[pyo3(signature = (vertices, faces, albedo, emission, camera=None))]
fn manylight_from_arrays(
    py: Python<'_>,
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    albedo: &Bound<'_, PyAny>,
    emission: &Bound<'_, PyAny>,
    camera: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyScene> {
    let vertices = args::array::<f64>("vertices", vertices)?;
    let faces = args::faces(faces)?;
    let albedo = args::array::<f64>("albedo", albedo)?;
    let emission = args::array::<f64>("emission", emission)?;
    let v = rows3("vertices", &values(&vertices), vertices.shape())?;
    let f = crate::convert::faces_u32(&faces)?;
    let a = rows3("albedo", &values(&albedo), albedo.shape())?;
    let e = rows3("emission", &values(&emission), emission.shape())?;
    let scene = crate::pool::detach(py, || Scene::from_triangles(&v, &f, &a, &e)).py_err()?;
    let camera = camera_from(camera, &default_camera())?;
    Ok(PyScene { scene, camera })
}

/// A scene from the parts that `ManyLightScene.__reduce__` pickles.
#[pyfunction]
fn _manylight_scene_from_parts(
    py: Python<'_>,
    triangles: PyReadonlyArrayDyn<f64>,
    albedo: PyReadonlyArrayDyn<f64>,
    emission: PyReadonlyArrayDyn<f64>,
    skipped: usize,
    camera: &Bound<'_, PyDict>,
) -> PyResult<PyScene> {
    let rows = match triangles.shape() {
        [f, 3, 3] => rows3("triangles", &values(&triangles), &[f * 3, 3])?,
        s => {
            return Err(crate::errors::value_error(format!(
                "`triangles` must have shape (F, 3, 3), got {s:?}"
            )))
        }
    };
    let tris = rows
        .chunks_exact(3)
        .enumerate()
        .map(|(i, r)| {
            Triangle::from_edges(r[0], r[1], r[2]).ok_or_else(|| {
                crate::errors::value_error(format!("triangle {i} of `triangles` is degenerate"))
            })
        })
        .collect::<PyResult<Vec<_>>>()?;
    let a = rows3("albedo", &values(&albedo), albedo.shape())?;
    let e = rows3("emission", &values(&emission), emission.shape())?;
    let scene = crate::pool::detach(py, || Scene::from_parts(tris, a, e, skipped)).py_err()?;
    let camera = camera_from(Some(camera), &default_camera())?;
    Ok(PyScene { scene, camera })
}

/// A scene from a Wavefront OBJ file and its MTL library (``Kd``: albedo, ``Ke``:
/// emitted radiance). The file is only read.
#[pyfunction]
#[pyo3(signature = (path, camera=None))]
fn load_manylight_obj(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    camera: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyScene> {
    let path = args::path("path", path)?;
    let scene = crate::pool::detach(py, || load_obj(&path)).py_err()?;
    let camera = camera_from(camera, &default_camera())?;
    Ok(PyScene { scene, camera })
}

/// Renders a scene with one method; the image (H, W, 3) float32 and a dict of statistics.
#[pyfunction]
#[pyo3(signature = (scene, method, params, camera=None))]
fn manylight_render<'py>(
    py: Python<'py>,
    scene: &PyScene,
    method: &str,
    params: &Bound<'py, PyDict>,
    camera: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Arr<'py, f32>, Bound<'py, PyDict>)> {
    let method = Method::parse(method).py_err()?;
    let c = Cfg(params);
    let camera = camera_from(camera, &scene.camera)?;
    let mut s = ManyLightParams::default();
    s.vpl.n_paths = c.count("n_vpl_paths", s.vpl.n_paths, 0)?;
    s.vpl.max_bounces = c.count("max_bounces", s.vpl.max_bounces, 0)?;
    s.vpl.seed = c.count("vpl_seed", s.vpl.seed, 0)?;
    let pixels = camera.width * camera.height;
    s.ic.n_cache = c.count("n_cache", (pixels / 100).max(1), 0)?;
    s.ic.m_nearest = c.count("m_nearest", s.ic.m_nearest, 0)?;
    s.ic.spp = c.count("spp", s.ic.spp, 0)?;
    s.ic.seed = c.count("seed", s.ic.seed, 0)?;
    s.ic.clamp_dist = c.opt("clamp_dist")?;
    s.adaptive.delta = c.get("delta", s.adaptive.delta)?;
    s.adaptive.init_fraction = c.get("init_fraction", s.adaptive.init_fraction)?;
    if let Some(f) = c.opt::<String>("pixel_filter")? {
        s.ic.filter = PixelFilter::parse(&f).py_err()?;
    }
    s.ic.pixel_samples = c.count("n_pixel_samples", s.ic.pixel_samples, 0)?;
    s.ic.near_share = c.get("near_share", s.ic.near_share)?;
    s.ic.near_vpls = c.count("n_near_vpls", s.ic.near_vpls, 1)?;
    s.weights = wscg_raytrace::manylight::Interp::Clarberg {
        theta_max: c.get("theta_max", std::f64::consts::FRAC_PI_6)?,
        lambda: c.get("lam", 5.0)?,
        dmax_factor: c.get("dmax_factor", 2.0)?,
        defensive: c.get("defensive", wscg_raytrace::manylight::DEFAULT_DEFENSIVE)?,
    };
    let out =
        crate::pool::detach(py, || run(&scene.scene, &camera, method, &s, &NoProgress)).py_err()?;
    let (h, w, _) = out.image.shape();
    let img = array(py, &[h, w, 3], out.image.into_data())?;
    let d = PyDict::new(py);
    d.set_item("method", method.name())?;
    d.set_item("n_vpls", out.n_vpls)?;
    d.set_item("setup_seconds", out.setup_seconds)?;
    d.set_item("cache_seconds", out.cache_seconds)?;
    d.set_item("render_seconds", out.render_seconds)?;
    let pos: Vec<f64> = out.records.iter().flat_map(|r| r.at.pos).collect();
    d.set_item("records", array(py, &[out.records.len(), 3], pos)?)?;
    let pix: Vec<i64> = out
        .records
        .iter()
        .map(|r| r.pixel.map_or(-1, |p| p as i64))
        .collect();
    d.set_item("record_pixels", array(py, &[out.records.len()], pix)?)?;
    let ins: Vec<bool> = out.records.iter().map(|r| r.inserted).collect();
    d.set_item("record_inserted", array(py, &[out.records.len()], ins)?)?;
    let nrm: Vec<f64> = out.records.iter().flat_map(|r| r.at.normal).collect();
    d.set_item("record_normals", array(py, &[out.records.len(), 3], nrm)?)?;
    let rad: Vec<f64> = out.records.iter().map(|r| r.radius).collect();
    d.set_item("record_radii", array(py, &[out.records.len()], rad)?)?;
    if let Some(cs) = out.cache {
        d.set_item("initial", cs.initial)?;
        d.set_item("n_records", cs.records)?;
        d.set_item("inserted", cs.inserted)?;
        d.set_item("passes", cs.passes)?;
        d.set_item("shadow_rays_cache", cs.shadow_rays)?;
        d.set_item("cache_bytes", cs.bytes)?;
    }
    Ok((img, d))
}

/// The paper's similarity weight (eqs. 2-4, after Clarberg and Akenine-Moller 2008) of
/// each record for the shading point ``x`` (3,) with unit ``normal`` (3,): records at
/// ``record_pos`` (K, 3) with unit normals ``record_normal`` (K, 3); returns (K,) float64
/// in [0, 1]: ``sqrt(1 - |n . v|) * w_hat(d, theta)``, ``v`` the unit vector to the record
/// (1 when it coincides with ``x``), ``d`` its distance, ``theta`` the angle between the
/// normals, ``w(d, theta) = (1 - theta / pi) (1 - d' / (1 + lam d'))`` with
/// ``d' = d / d_max``, and ``w_hat = max(0, (w - w0) / (1 - w0))``,
/// ``w0 = w(d_max, theta_max)``. A render normalises the weights of the ``M`` nearest
/// records within ``d_max`` (and blends them with uniform ones, see ``defensive`` of
/// :func:`render_manylight`).
///
/// >>> w = manylight_record_weight([0, 0, 0], [0, 0, 1], [[0.25, 0, 0], [0, 0, 0.25]],
/// ...                             [[0, 0, 1], [0, 0, 1]], d_max=1.0)
/// >>> np.round(w, 6).tolist()
/// [0.636364, 0.0]
#[pyfunction]
#[pyo3(
    signature = (x, normal, record_pos, record_normal, d_max, theta_max=std::f64::consts::FRAC_PI_6, lam=5.0),
    text_signature = "(x, normal, record_pos, record_normal, d_max, theta_max=0.5235987755982988, lam=5.0)"
)]
#[allow(clippy::too_many_arguments)]
fn manylight_record_weight<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    normal: &Bound<'py, PyAny>,
    record_pos: &Bound<'py, PyAny>,
    record_normal: &Bound<'py, PyAny>,
    d_max: f64,
    theta_max: f64,
    lam: f64,
) -> PyResult<Arr<'py, f64>> {
    let (x, normal) = (args::triple("x", x)?, args::triple("normal", normal)?);
    let record_pos = args::array::<f64>("record_pos", record_pos)?;
    let record_normal = args::array::<f64>("record_normal", record_normal)?;
    let p = rows3("record_pos", &values(&record_pos), record_pos.shape())?;
    let n = rows3(
        "record_normal",
        &values(&record_normal),
        record_normal.shape(),
    )?;
    if p.len() != n.len() {
        return Err(crate::errors::value_error(format!(
            "`record_pos` has {} rows but `record_normal` {}",
            p.len(),
            n.len()
        )));
    }
    if !(d_max.is_finite() && d_max > 0.0) {
        return Err(crate::errors::value_error(format!(
            "`d_max` must be finite and positive, got {d_max}"
        )));
    }
    wscg_raytrace::manylight::Interp::Clarberg {
        theta_max,
        lambda: lam,
        dmax_factor: 1.0,
        defensive: 0.0,
    }
    .validate()
    .py_err()?;
    let unit = |name: &str, v: [f64; 3]| -> PyResult<[f64; 3]> {
        let len = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !(len.is_finite() && (len - 1.0).abs() <= 1e-6) || v.iter().any(|c| !c.is_finite()) {
            return Err(crate::errors::value_error(format!(
                "`{name}` must hold finite unit vectors, got {v:?}"
            )));
        }
        Ok(v)
    };
    if x.iter().any(|c| !c.is_finite()) || p.iter().flatten().any(|c| !c.is_finite()) {
        return Err(crate::errors::value_error(
            "`x` and `record_pos` must be finite",
        ));
    }
    let normal = unit("normal", normal)?;
    let w = p
        .iter()
        .zip(&n)
        .map(|(pk, nk)| {
            let nk = unit("record_normal", *nk)?;
            Ok(record_weight(x, normal, *pk, nk, d_max, theta_max, lam))
        })
        .collect::<PyResult<Vec<f64>>>()?;
    array(py, &[w.len()], w)
}

/// Registers the many-light functions in the `raytrace` submodule.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScene>()?;
    m.add_function(wrap_pyfunction!(make_manylight_scene, m)?)?;
    m.add_function(wrap_pyfunction!(manylight_from_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(_manylight_scene_from_parts, m)?)?;
    m.add_function(wrap_pyfunction!(load_manylight_obj, m)?)?;
    m.add_function(wrap_pyfunction!(manylight_render, m)?)?;
    m.add_function(wrap_pyfunction!(manylight_record_weight, m)?)?;
    Ok(())
}
