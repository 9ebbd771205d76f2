//! `wscg._native.volren`: bindings of `wscg-volren` (paper 03, hybrid ROI visualisation; the
//! paper-15 functions live in [`crate::illum`] and register into the same submodule).
//! The documented API is `python/wscg/volren.py`; it re-exports the functions that need
//! no camera (`make_phantom`, `phantom_tfs`, `octree_address`, `haar_blocks`) as they are,
//! their arguments converted by [`crate::args`].
//!
//! Coordinates follow `py/API.md`: a box of voxels is given per array axis, `(z0, z1, y0, y1,
//! x0, x1)`, a voxel by its index `(k, j, i)`, and a point in space as `(x, y, z)` with the
//! centre of voxel `[k, j, i]` at `(i, j, k)` (the volumes of paper 03 have unit spacing).
//! The renderers of `wscg_volren` let voxel `(i, j, k)` cover `[i, i + 1) x ...` (its centre
//! at `i + 1/2`): [`camera`] shifts eye and target by half a voxel on the way in.

use numpy::{PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use wscg_math::Volume;
use wscg_volren::gradient_octree::octree_address as address;
use wscg_volren::phantoms;
use wscg_volren::wavelet::HaarQuant;
use wscg_volren::{
    render_reference as reference, Camera, HybridClient, HybridServer, PiecewiseTransferFunction,
    RenderParams, Roi, ServerParams,
};

use crate::args::{self, uint};
use crate::convert::{array, values, Arr};
use crate::errors::{value_error, IntoPy};

/// A `[z, y, x]` uint8 array as a volume.
fn volume_in(a: &PyReadonlyArrayDyn<u8>) -> PyResult<Volume<u8>> {
    match *a.shape() {
        [nz, ny, nx] => Volume::new([nx, ny, nz], [1.0; 3], values(a).into_owned()).py_err(),
        ref s => Err(value_error(format!(
            "`volume` must be a 3-D uint8 array indexed [z, y, x], got shape {s:?}"
        ))),
    }
}

fn volume_out<'py, T: numpy::Element + Clone>(
    py: Python<'py>,
    v: &Volume<T>,
) -> PyResult<Arr<'py, T>> {
    let [nx, ny, nz] = v.dims();
    array(py, &[nz, ny, nx], v.data().to_vec())
}

/// A transfer function from an `(n, 5)` array of `(density, r, g, b, a)` rows.
fn tf_in(a: &PyReadonlyArrayDyn<f64>) -> PyResult<PiecewiseTransferFunction> {
    match *a.shape() {
        [_, 5] => {
            let pts = values(a)
                .chunks_exact(5)
                .map(|r| {
                    (
                        r[0] as f32,
                        [r[1] as f32, r[2] as f32, r[3] as f32, r[4] as f32],
                    )
                })
                .collect();
            PiecewiseTransferFunction::new(pts).py_err()
        }
        ref s => Err(value_error(format!(
            "a transfer function is an (n, 5) array (density, r, g, b, a), got shape {s:?}"
        ))),
    }
}

fn tf_out<'py>(py: Python<'py>, t: &PiecewiseTransferFunction) -> PyResult<Arr<'py, f64>> {
    let data = t
        .points()
        .iter()
        .flat_map(|(d, c)| {
            [
                *d as f64,
                c[0] as f64,
                c[1] as f64,
                c[2] as f64,
                c[3] as f64,
            ]
        })
        .collect();
    array(py, &[t.points().len(), 5], data)
}

/// A camera from Python: eye, target, up, vertical field of view (degrees), width, height.
/// The `roi` argument, a box `(z0, z1, y0, y1, x0, x1)` (array axis order, half-open,
/// non-negative integers), as the min and max corners `[x, y, z]` of `wscg_volren`.
fn roi_arg(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<([u32; 3], [u32; 3])> {
    let r = args::counts(py, "roi", obj)?;
    let c = |i: usize| uint(py, "roi", r[i] as i128, 0u32);
    if r.len() != 6 {
        return Err(value_error(format!(
            "`roi` is (z0, z1, y0, y1, x0, x1) with non-negative ints, got {} values",
            r.len()
        )));
    }
    Ok(([c(4)?, c(2)?, c(0)?], [c(5)?, c(3)?, c(1)?]))
}

/// The camera of the arguments `eye` and `target` (`py/API.md` world points, voxel
/// `[k, j, i]` centred at `(i, j, k)`), `up`, `fov_deg` and `size` `(height, width)`, in the
/// renderers' coordinates (centred at `(i, j, k) + 1/2`).
fn camera_arg(
    py: Python<'_>,
    eye: &Bound<'_, PyAny>,
    target: &Bound<'_, PyAny>,
    up: &Bound<'_, PyAny>,
    fov_deg: f64,
    size: &Bound<'_, PyAny>,
) -> PyResult<Camera> {
    let (height, width) = args::size2(py, "size", size)?;
    Ok(Camera {
        eye: args::triple("eye", eye)?.map(|c| c + 0.5),
        target: args::triple("target", target)?.map(|c| c + 0.5),
        up: args::triple("up", up)?,
        fov_deg,
        width,
        height,
    })
}

/// The camera of a dict with `eye`, `target`, optional `up` (default `(0, 0, 1)`) and
/// `fov_deg` (default 30), e.g. from `orbit_camera`, at `size` `(height, width)`.
fn camera_dict(py: Python<'_>, c: &Bound<'_, PyDict>, size: &Bound<'_, PyAny>) -> PyResult<Camera> {
    let need = |k: &str| {
        c.get_item(k)?
            .ok_or_else(|| value_error(format!("the camera dict needs {k:?}")))
    };
    let up = match c.get_item("up")? {
        Some(u) => u,
        None => (0.0, 0.0, 1.0).into_pyobject(py)?.into_any(),
    };
    let fov_deg: f64 = crate::cfg::dict_item(c, "fov_deg")?.unwrap_or(30.0);
    camera_arg(py, &need("eye")?, &need("target")?, &up, fov_deg, size)
}

fn image_out<'py>(py: Python<'py>, img: wscg_math::Image<f32>) -> PyResult<Arr<'py, f32>> {
    let (h, w, c) = img.shape();
    array(py, &[h, w, c], img.into_data())
}

/// The hybrid server (see `wscg.volren.HybridServer`).
#[pyclass(module = "wscg._native.volren", name = "HybridServer")]
pub struct PyServer {
    inner: HybridServer,
}

#[pymethods]
impl PyServer {
    #[new]
    fn new(
        py: Python<'_>,
        volume: &Bound<'_, PyAny>,
        tfs: Vec<Bound<'_, PyAny>>,
        canonical: i128,
        steps_sent: i128,
        delta: f32,
    ) -> PyResult<Self> {
        let v = volume_in(&args::array("volume", volume)?)?;
        let tfs = tfs
            .iter()
            .map(|t| tf_in(&args::array("tfs", t)?))
            .collect::<PyResult<Vec<_>>>()?;
        let canonical: usize = uint(py, "canonical", canonical, 0)?;
        let steps_sent: u8 = uint(py, "steps_sent", steps_sent, 0)?;
        let opts = ServerParams::default()
            .steps_sent(steps_sent)
            .quant(HaarQuant { delta: [delta; 4] });
        let inner =
            crate::pool::detach(py, || HybridServer::new(&v, tfs, canonical, opts)).py_err()?;
        Ok(Self { inner })
    }

    fn static_package<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = crate::pool::detach(py, || self.inner.static_package())?;
        Ok(PyBytes::new(py, &bytes))
    }

    fn roi_package<'py>(
        &self,
        py: Python<'py>,
        roi: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyBytes>> {
        let (lo, hi) = roi_arg(py, roi)?;
        let p = crate::pool::detach(py, || self.inner.roi_package(lo, hi)).py_err()?;
        Ok(PyBytes::new(py, &p))
    }

    /// Stored (edge) voxels of the Gradient Octree.
    #[getter]
    fn leaf_count(&self) -> usize {
        self.inner.octree().leaves.len() - 1
    }

    /// Grey nodes per octree level 32, 64, ..., R.
    #[getter]
    fn node_counts(&self) -> Vec<usize> {
        self.inner.octree().structure.node_counts()
    }

    /// Pickles as the constructor's arguments (volume, transfer functions, canonical index,
    /// steps sent, quantisation step): the server is a function of them.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, pyo3::types::PyType>,
        (Arr<'py, u8>, Vec<Arr<'py, f64>>, usize, u8, f32),
    )> {
        let py = slf.py();
        let s = &slf.borrow().inner;
        let p = s.params();
        let tfs = s
            .tfs()
            .iter()
            .map(|t| tf_out(py, t))
            .collect::<PyResult<_>>()?;
        Ok((
            slf.get_type(),
            (
                volume_out(py, s.volume())?,
                tfs,
                s.canonical(),
                p.steps_sent,
                p.quant.delta[0],
            ),
        ))
    }

    fn size_report<'py>(
        &self,
        py: Python<'py>,
        roi: &Bound<'py, PyAny>,
        roi_tf: i128,
        thin_client_view: Option<&Bound<'py, PyDict>>,
        viewport: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (lo, hi) = roi_arg(py, roi)?;
        let roi_tf: usize = uint(py, "roi_tf", roi_tf, 0)?;
        let cam = thin_client_view
            .map(|c| camera_dict(py, c, viewport))
            .transpose()?;
        let r = crate::pool::detach(py, || self.inner.size_report(lo, hi, roi_tf, cam.as_ref()))
            .py_err()?;
        let d = PyDict::new(py);
        d.set_item("raw", r.raw)?;
        d.set_item("wavelets", r.wavelets)?;
        d.set_item("gradient_octree", r.gradient_octree)?;
        d.set_item("hybrid_static", r.hybrid_static)?;
        d.set_item("hybrid_roi", r.hybrid_roi)?;
        d.set_item("hybrid", r.hybrid())?;
        d.set_item("thin_client_frame", r.thin_client_frame)?;
        Ok(d)
    }
}

/// The hybrid client (see `wscg.volren.HybridClient`), with the packages it was given (its
/// pickled state).
#[pyclass(module = "wscg._native.volren", name = "HybridClient")]
pub struct PyClient {
    inner: HybridClient,
    /// The static package.
    static_package: Vec<u8>,
    /// The package of the current ROI.
    roi_package: Option<Vec<u8>>,
}

#[pymethods]
impl PyClient {
    #[new]
    #[pyo3(signature = (package, roi_package=None))]
    fn new(py: Python<'_>, package: &[u8], roi_package: Option<&[u8]>) -> PyResult<Self> {
        let inner = crate::pool::detach(py, || HybridClient::from_static(package)).py_err()?;
        let mut client = Self {
            inner,
            static_package: package.to_vec(),
            roi_package: None,
        };
        if let Some(roi) = roi_package {
            client.set_roi(py, roi)?;
        }
        Ok(client)
    }

    fn set_roi(&mut self, py: Python<'_>, package: &[u8]) -> PyResult<()> {
        let client = &mut self.inner;
        crate::pool::detach(py, || client.set_roi(package)).py_err()?;
        self.roi_package = Some(package.to_vec());
        Ok(())
    }

    fn clear_roi(&mut self) {
        self.inner.clear_roi();
        self.roi_package = None;
    }

    /// Pickles as the packages received: the static one and that of the current ROI.
    #[allow(clippy::type_complexity)]
    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(
        Bound<'py, pyo3::types::PyType>,
        (Bound<'py, PyBytes>, Option<Bound<'py, PyBytes>>),
    )> {
        let py = slf.py();
        let c = slf.borrow();
        Ok((
            slf.get_type(),
            (
                PyBytes::new(py, &c.static_package),
                c.roi_package.as_ref().map(|p| PyBytes::new(py, p)),
            ),
        ))
    }

    /// The ROI box `(z0, z1, y0, y1, x0, x1)` or None.
    #[getter]
    fn roi(&self) -> Option<(u32, u32, u32, u32, u32, u32)> {
        self.inner.roi.as_ref().map(|(r, _, _)| {
            let Roi { min, max } = *r;
            (min[2], max[2], min[1], max[1], min[0], max[0])
        })
    }

    /// The low-resolution volume `[z, y, x]` (float32).
    #[getter]
    fn lowres<'py>(&self, py: Python<'py>) -> PyResult<Arr<'py, f32>> {
        volume_out(py, &self.inner.lowres)
    }

    /// Volume shape `(z, y, x)`.
    #[getter]
    fn shape(&self) -> (usize, usize, usize) {
        let [nx, ny, nz] = self.inner.dims;
        (nz, ny, nx)
    }

    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        mode: &str,
        eye: &Bound<'py, PyAny>,
        target: &Bound<'py, PyAny>,
        up: &Bound<'py, PyAny>,
        fov_deg: f64,
        size: &Bound<'py, PyAny>,
        roi_tf: i128,
    ) -> PyResult<Arr<'py, f32>> {
        let roi_tf: usize = uint(py, "roi_tf", roi_tf, 0)?;
        let cam = camera_arg(py, eye, target, up, fov_deg, size)?;
        let o = RenderParams::default();
        let c = &self.inner;
        let img = crate::pool::detach(py, || match mode {
            "hybrid" => c.render(&cam, roi_tf, &o),
            "context" => c.render_context(&cam, &o),
            "octree" => c.render_octree(&cam, roi_tf, &o),
            other => Err(wscg_math::Error::invalid(
                "mode",
                format!("{other:?}; use 'hybrid', 'context' or 'octree'"),
            )),
        })
        .py_err()?;
        image_out(py, img)
    }
}

/// Full-resolution ray casting of ``volume`` (trilinear densities, central-difference
/// gradients, Phong shading) under ``tf``; with ``roi`` ``(z0, z1, y0, y1, x0, x1)`` and
/// ``roi_tf``, the full-resolution counterpart of the hybrid image (``tf`` unlit outside the
/// box, ``roi_tf`` shaded inside). The camera is that of :meth:`HybridClient.render`.
#[pyfunction]
#[pyo3(signature = (volume, tf, eye, target, up=None, fov_deg=30.0, size=None, roi=None,
                    roi_tf=None),
       text_signature = "(volume, tf, eye, target, up=(0.0, 0.0, 1.0), fov_deg=30.0, \
                         size=(512, 512), roi=None, roi_tf=None)")]
#[allow(clippy::too_many_arguments)]
fn render_reference<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    tf: &Bound<'py, PyAny>,
    eye: &Bound<'py, PyAny>,
    target: &Bound<'py, PyAny>,
    up: Option<&Bound<'py, PyAny>>,
    fov_deg: f64,
    size: Option<&Bound<'py, PyAny>>,
    roi: Option<&Bound<'py, PyAny>>,
    roi_tf: Option<&Bound<'py, PyAny>>,
) -> PyResult<Arr<'py, f32>> {
    let v = volume_in(&args::array("volume", volume)?)?;
    let tf = tf_in(&args::array("tf", tf)?)?;
    let roi = match (
        roi.filter(|r| !r.is_none()),
        roi_tf.filter(|t| !t.is_none()),
    ) {
        (Some(r), Some(t)) => {
            let (lo, hi) = roi_arg(py, r)?;
            Some((
                Roi::snapped(lo, hi, v.dims()).py_err()?,
                tf_in(&args::array("roi_tf", t)?)?,
            ))
        }
        (None, None) => None,
        _ => return Err(value_error("`roi` and `roi_tf` go together")),
    };
    let up = match up.filter(|u| !u.is_none()) {
        Some(u) => u.clone(),
        None => (0.0, 0.0, 1.0).into_pyobject(py)?.into_any(),
    };
    let size = match size.filter(|s| !s.is_none()) {
        Some(s) => s.clone(),
        None => (512, 512).into_pyobject(py)?.into_any(),
    };
    let cam = camera_arg(py, eye, target, &up, fov_deg, &size)?;
    let img = crate::pool::detach(py, || {
        reference(
            &v,
            &tf,
            roi.as_ref().map(|(r, t)| (r, t)),
            &cam,
            &RenderParams::default(),
        )
    })
    .py_err()?;
    image_out(py, img)
}

/// An analytic CT-like phantom ``[z, y, x]`` (uint8): ``"head"`` (3-D modified
/// Shepp-Logan; the paper's skull is ``(112, 256, 256)``, the default) or ``"thorax"``
/// (body, lungs with vessels, heart, spine, ribs; default ``(256, 256, 256)``, the paper's
/// is 512^3).
#[pyfunction]
#[pyo3(signature = (name="head", shape=None, seed=0))]
fn make_phantom<'py>(
    py: Python<'py>,
    name: &str,
    shape: Option<Vec<i128>>,
    seed: i128,
) -> PyResult<Arr<'py, u8>> {
    let make = match name {
        "head" => phantoms::head,
        "thorax" => phantoms::thorax,
        other => {
            return Err(value_error(format!(
                "unknown phantom {other:?}; use 'head' or 'thorax'"
            )))
        }
    };
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let [nz, ny, nx] = match shape.as_deref() {
        None if name == "head" => [112, 256, 256],
        None => [256; 3],
        Some(&[z, y, x]) => [
            uint(py, "shape", z, 0)?,
            uint(py, "shape", y, 0)?,
            uint(py, "shape", x, 0)?,
        ],
        Some(s) => {
            return Err(value_error(format!(
                "`shape` must be 3 integers (nz, ny, nx), got {s:?}"
            )))
        }
    };
    let v = crate::pool::detach(py, || make([nx, ny, nz], seed)).py_err()?;
    volume_out(py, &v)
}

/// The transfer functions of a phantom: head (soft tissue, canonical; bone), thorax (all
/// structures, canonical; bone; lungs; skin).
#[pyfunction]
#[pyo3(signature = (name="head"))]
fn phantom_tfs<'py>(py: Python<'py>, name: &str) -> PyResult<Vec<Arr<'py, f64>>> {
    let tfs = match name {
        "head" => phantoms::head_tfs(),
        "thorax" => phantoms::thorax_tfs(),
        other => {
            return Err(value_error(format!(
                "unknown phantom {other:?}; use 'head' or 'thorax'"
            )))
        }
    };
    tfs.iter().map(|t| tf_out(py, t)).collect()
}

/// The paper's eq. 1: the level-32 cell ``(k, j, i)`` of the voxel ``index`` ``(k, j,
/// i)`` (array axis order) in a cube of side ``r``, and the child slot taken at each level
/// 32, 64, ..., r/2.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn octree_address(
    py: Python<'_>,
    index: Vec<i128>,
    r: i128,
) -> PyResult<((u32, u32, u32), Vec<u16>)> {
    let r: usize = uint(py, "r", r, 0)?;
    let index: Vec<u32> = index
        .iter()
        .map(|&c| uint(py, "index", c, 0))
        .collect::<PyResult<_>>()?;
    let index: [u32; 3] = index.as_slice().try_into().map_err(|_| {
        value_error(format!(
            "`index` must be 3 integers (k, j, i), got {index:?}"
        ))
    })?;
    if !r.is_power_of_two() || r < 32 || index.iter().any(|&c| c as usize >= r) {
        return Err(value_error(format!(
            "needs r a power of two >= 32 and a voxel inside the cube, got r = {r}, `index` \
             {index:?}"
        )));
    }
    let [k, j, i] = index;
    let ([cx, cy, cz], slots) = address([i, j, k], r);
    Ok(((cz, cy, cx), slots.into_iter().map(u16::from).collect()))
}

/// The server's 4-step 3-D Haar transform (averaging normalisation) of ``(n, 16, 16, 16)``
/// blocks indexed ``[block, z, y, x]``: an ``(n, 4096)`` float32 array per block holding the
/// root (the block mean), then the details of steps 4, 3, 2, 1 (coarse to fine), each step's
/// parents in raster order (x fastest) with 7 details ``k = 4u + 2v + w`` (u, v, w the x,
/// y, z difference bits).
#[pyfunction]
fn haar_blocks<'py>(py: Python<'py>, blocks: &Bound<'py, PyAny>) -> PyResult<Arr<'py, f32>> {
    let blocks = args::array::<f32>("blocks", blocks)?;
    let n = match *blocks.shape() {
        [n, 16, 16, 16] => n,
        ref s => {
            return Err(value_error(format!(
                "`blocks` must have shape (n, 16, 16, 16), got {s:?}"
            )))
        }
    };
    let data = values(&blocks);
    let out = crate::pool::detach(py, || wscg_volren::wavelet::forward_blocks(&data)).py_err()?;
    array(py, &[n, 4096], out)
}

/// Registers the submodule's functions and classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyServer>()?;
    m.add_class::<PyClient>()?;
    m.add_function(wrap_pyfunction!(render_reference, m)?)?;
    m.add_function(wrap_pyfunction!(make_phantom, m)?)?;
    m.add_function(wrap_pyfunction!(phantom_tfs, m)?)?;
    m.add_function(wrap_pyfunction!(octree_address, m)?)?;
    m.add_function(wrap_pyfunction!(haar_blocks, m)?)?;
    crate::illum::register(m)
}
