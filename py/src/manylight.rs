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

use crate::convert::{array, rows3, values, Arr, Cfg};
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

/// A procedural scene: 'cornell', 'colonnade', 'conference' or 'plane'.
#[pyfunction]
fn make_manylight_scene(
    py: Python<'_>,
    name: &str,
    subdiv: u32,
    width: usize,
    height: usize,
) -> PyResult<PyScene> {
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

/// A scene from arrays: vertices (V, 3) float64, faces (F, 3) int64, albedo and emission
/// (F, 3) float64.
#[pyfunction]
#[pyo3(signature = (vertices, faces, albedo, emission, camera=None))]
fn manylight_from_arrays(
    py: Python<'_>,
    vertices: PyReadonlyArrayDyn<f64>,
    faces: PyReadonlyArrayDyn<i64>,
    albedo: PyReadonlyArrayDyn<f64>,
    emission: PyReadonlyArrayDyn<f64>,
    camera: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyScene> {
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

/// A scene from a Wavefront OBJ file (MTL `Kd` albedo, `Ke` emission).
#[pyfunction]
#[pyo3(signature = (path, camera=None))]
fn load_manylight_obj(
    py: Python<'_>,
    path: std::path::PathBuf,
    camera: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyScene> {
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
    s.vpl.n_paths = c.get("n_vpl_paths", s.vpl.n_paths)?;
    s.vpl.max_bounces = c.get("max_bounces", s.vpl.max_bounces)?;
    s.vpl.seed = c.get("vpl_seed", s.vpl.seed)?;
    let pixels = camera.width * camera.height;
    s.ic.n_cache = c.get("n_cache", (pixels / 100).max(1))?;
    s.ic.m_nearest = c.get("m_nearest", s.ic.m_nearest)?;
    s.ic.spp = c.get("spp", s.ic.spp)?;
    s.ic.seed = c.get("seed", s.ic.seed)?;
    s.ic.clamp_dist = c.opt("clamp_dist")?;
    s.adaptive.delta = c.get("delta", s.adaptive.delta)?;
    s.adaptive.init_fraction = c.get("init_fraction", s.adaptive.init_fraction)?;
    if let Some(f) = c.opt::<String>("pixel_filter")? {
        s.ic.filter = PixelFilter::parse(&f).py_err()?;
    }
    s.ic.pixel_samples = c.get("n_pixel_samples", s.ic.pixel_samples)?;
    s.weights = wscg_raytrace::manylight::Interp::Clarberg {
        theta_max: c.get("theta_max", std::f64::consts::FRAC_PI_6)?,
        lambda: c.get("lambda", 5.0)?,
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

/// The similarity weight of eqs. (2)-(4) of each record (positions and unit normals
/// (K, 3)) for the shading point `x` with unit normal `normal`.
#[pyfunction]
#[pyo3(signature = (x, normal, record_pos, record_normal, d_max, theta_max, lam))]
#[allow(clippy::too_many_arguments)]
fn manylight_record_weight<'py>(
    py: Python<'py>,
    x: [f64; 3],
    normal: [f64; 3],
    record_pos: PyReadonlyArrayDyn<f64>,
    record_normal: PyReadonlyArrayDyn<f64>,
    d_max: f64,
    theta_max: f64,
    lam: f64,
) -> PyResult<Arr<'py, f64>> {
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
