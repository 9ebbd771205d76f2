//! `wscg._native.octree`: bindings of `wscg-octree` (paper 10, the unified triangle/voxel
//! octree). The documented API is `python/wscg/octree.py`.

use std::path::PathBuf;

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use wscg_octree::{
    build, render, scenes, BuildParams, BuildStats, Camera, Cube, Focus, Footprint, HitKind,
    HybridOctree, PointLight, Ray, Shading, TraceMode, TriangleBvh,
};

use crate::args::{self, uint};
use crate::convert::{array, rows3, values, Arr};
use crate::errors::{value_error, IntoPy};

/// The trace mode named `mode`.
fn mode_from(
    mode: &str,
    lod_scale: f32,
    blend: bool,
    small_leaves_as_voxels: bool,
    level: Option<u8>,
) -> PyResult<TraceMode> {
    if !(lod_scale.is_finite() && lod_scale > 0.0) {
        return Err(value_error(format!(
            "lod_scale must be positive and finite, got {lod_scale}"
        )));
    }
    match mode {
        "triangles" => Ok(TraceMode::Triangles),
        "voxels" => Ok(TraceMode::Voxels { level }),
        "hybrid" => Ok(TraceMode::Hybrid {
            lod_scale,
            blend,
            small_leaves_as_voxels,
        }),
        other => Err(value_error(format!(
            "mode {other:?} is not valid; valid: triangles, voxels, hybrid"
        ))),
    }
}

fn stats_dict<'py>(py: Python<'py>, s: &BuildStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("fragments", s.fragments)?;
    d.set_item("degenerate_triangles", s.degenerate_triangles)?;
    d.set_item("nodes", s.nodes)?;
    d.set_item("voxels", s.voxels)?;
    d.set_item("early_leaves", s.early_leaves)?;
    d.set_item("finest_leaves", s.finest_leaves)?;
    d.set_item("voxelize_s", s.voxelize_s)?;
    d.set_item("hierarchy_s", s.hierarchy_s)?;
    d.set_item("attributes_s", s.attributes_s)?;
    Ok(d)
}

/// Rays from `(N, 3)` origins and directions.
fn rays_in(origins: &Bound<'_, PyAny>, dirs: &Bound<'_, PyAny>) -> PyResult<Vec<Ray>> {
    let (origins, dirs) = (
        args::array::<f32>("origins", origins)?,
        args::array::<f32>("dirs", dirs)?,
    );
    let o = rows3("origins", &values(&origins), origins.shape())?;
    let d = rows3("dirs", &values(&dirs), dirs.shape())?;
    if o.len() != d.len() {
        return Err(value_error(format!(
            "origins has {} rows but dirs has {}",
            o.len(),
            d.len()
        )));
    }
    Ok(o.into_iter().zip(d).map(|(o, d)| Ray::new(o, d)).collect())
}

/// One ray's answer in `intersect`: the hit (ray parameter and kind) and, when shading, its
/// normal and colour (zeros otherwise).
type HitRow = (Option<(f32, HitKind)>, [[f32; 3]; 2]);

/// The point or vector argument `name`: 3 numbers (any array-like).
fn vec3(name: &str, v: &Bound<'_, PyAny>) -> PyResult<[f32; 3]> {
    Ok(args::triple(name, v)?.map(|c| c as f32))
}

/// The optional octree level `level`, an integer in `0..=255`.
fn level_arg(py: Python<'_>, level: Option<i128>) -> PyResult<Option<u8>> {
    level.map(|l| uint(py, "level", l, 0)).transpose()
}

/// A hybrid triangle/voxel octree.
#[pyclass(module = "wscg._native.octree", name = "HybridOctree", frozen)]
pub struct PyOctree {
    inner: HybridOctree,
}

#[pymethods]
impl PyOctree {
    /// Deepest level L.
    #[getter]
    fn depth(&self) -> u8 {
        self.inner.max_depth
    }

    /// Whether the tree stopped early at nodes with at most two triangles.
    #[getter]
    fn early_stop(&self) -> bool {
        self.inner.early_stop
    }

    /// Number of nodes (empty children included).
    #[getter]
    fn n_nodes(&self) -> usize {
        self.inner.nodes.len()
    }

    /// Number of voxels (non-empty nodes).
    #[getter]
    fn n_voxels(&self) -> usize {
        self.inner.voxels.len()
    }

    /// Number of triangles.
    #[getter]
    fn n_triangles(&self) -> usize {
        self.inner.mesh.faces.len()
    }

    /// The cube domain as ``(min_xyz, side)``.
    #[getter]
    fn cube(&self) -> ([f64; 3], f64) {
        (self.inner.cube.min, self.inner.cube.size)
    }

    /// Bytes per part: nodes, triangles, tri_index, voxels, total.
    fn memory_report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let m = self.inner.memory_report();
        let d = PyDict::new(py);
        d.set_item("nodes", m.nodes)?;
        d.set_item("triangles", m.triangles)?;
        d.set_item("tri_index", m.tri_index)?;
        d.set_item("voxels", m.voxels)?;
        d.set_item("total", m.total)?;
        Ok(d)
    }

    /// Nearest hits of `N` rays; without `shading`, no normals or colours.
    #[pyo3(signature = (origins, dirs, mode, footprint_spread, lod_scale, blend, small_leaves_as_voxels, level, shading))]
    #[allow(clippy::too_many_arguments)]
    fn intersect<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        dirs: &Bound<'py, PyAny>,
        mode: &str,
        footprint_spread: f32,
        lod_scale: f32,
        blend: bool,
        small_leaves_as_voxels: bool,
        level: Option<i128>,
        shading: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let level = level_arg(py, level)?;
        let mode = mode_from(mode, lod_scale, blend, small_leaves_as_voxels, level)?;
        if !(footprint_spread.is_finite() && footprint_spread >= 0.0) {
            return Err(value_error(format!(
                "footprint_spread must be >= 0, got {footprint_spread}"
            )));
        }
        let rays = rays_in(origins, dirs)?;
        let fp = (footprint_spread > 0.0).then_some(Footprint {
            width0: 0.0,
            spread: footprint_spread,
        });
        let oct = &self.inner;
        // Shading: the full hits; otherwise `cast`, which skips the normal and colour reads.
        let hits: Vec<HitRow> = crate::pool::detach(py, || {
            rays.par_iter()
                .map(|r| {
                    if shading {
                        oct.intersect(r, &mode, fp)
                            .map_or((None, [[0.0; 3]; 2]), |h| {
                                (Some((h.t, h.kind)), [h.normal, h.color])
                            })
                    } else {
                        (oct.cast(r, &mode, fp), [[0.0; 3]; 2])
                    }
                })
                .collect()
        })?;
        let n = hits.len();
        let mut t = Vec::with_capacity(n);
        let mut prim = Vec::with_capacity(n);
        let mut lvl = Vec::with_capacity(n);
        let mut normal = Vec::with_capacity(if shading { 3 * n } else { 0 });
        let mut color = Vec::with_capacity(if shading { 3 * n } else { 0 });
        for (h, nc) in &hits {
            let (ti, p, l) = match *h {
                Some((ti, HitKind::Triangle { prim: p, .. })) => (ti, i64::from(p), -1i8),
                Some((ti, HitKind::Voxel { level, .. })) => (ti, -1, level as i8),
                None => (f32::INFINITY, -1, -1),
            };
            t.push(ti);
            prim.push(p);
            lvl.push(l);
            if shading {
                normal.extend_from_slice(&nc[0]);
                color.extend_from_slice(&nc[1]);
            }
        }
        let d = PyDict::new(py);
        d.set_item("t", array(py, &[n], t)?)?;
        d.set_item("prim", array(py, &[n], prim)?)?;
        d.set_item("level", array(py, &[n], lvl)?)?;
        if shading {
            d.set_item("normal", array(py, &[n, 3], normal)?)?;
            d.set_item("color", array(py, &[n, 3], color)?)?;
        }
        Ok(d)
    }

    /// Renders an image (primary rays, Phong, one shadow ray).
    #[pyo3(signature = (eye, target, up, fov_deg, width, height, mode, light_pos, shadows, lod_scale, blend, small_leaves_as_voxels, level, focus, n_ao_samples, ao_radius))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        eye: &Bound<'py, PyAny>,
        target: &Bound<'py, PyAny>,
        up: &Bound<'py, PyAny>,
        fov_deg: f32,
        width: i128,
        height: i128,
        mode: &str,
        light_pos: Option<&Bound<'py, PyAny>>,
        shadows: bool,
        lod_scale: f32,
        blend: bool,
        small_leaves_as_voxels: bool,
        level: Option<i128>,
        focus: Option<&Bound<'py, PyAny>>,
        n_ao_samples: i128,
        ao_radius: f32,
    ) -> PyResult<(Arr<'py, f32>, Bound<'py, PyDict>)> {
        let level = level_arg(py, level)?;
        let (width, height): (usize, usize) =
            (uint(py, "width", width, 0)?, uint(py, "height", height, 0)?);
        let n_ao_samples: u32 = uint(py, "n_ao_samples", n_ao_samples, 0)?;
        let focus = focus
            .filter(|f| !f.is_none())
            .map(|f| args::numbers::<5>("focus", f))
            .transpose()?
            .map(|f| f.map(|c| c as f32));
        let mode = mode_from(mode, lod_scale, blend, small_leaves_as_voxels, level)?;
        let cam = Camera {
            eye: vec3("eye", eye)?,
            target: vec3("target", target)?,
            up: vec3("up", up)?,
            fov_y_deg: fov_deg,
            width,
            height,
        };
        let light = match light_pos.filter(|p| !p.is_none()) {
            Some(p) => PointLight {
                position: vec3("light_pos", p)?,
                intensity: 1.0,
            },
            None => scenes::default_light(&self.inner.cube),
        };
        let shading = Shading {
            shadows,
            ao_samples: n_ao_samples,
            ao_radius,
            focus: focus.map(|f| Focus {
                centre: [f[0], f[1]],
                radii: [f[2], f[3]],
                falloff: f[4],
            }),
            ..Default::default()
        };
        let oct = &self.inner;
        let (img, st) =
            crate::pool::detach(py, || render(oct, &cam, &light, &mode, &shading)).py_err()?;
        let d = PyDict::new(py);
        d.set_item("triangle_hits", st.triangle_hits)?;
        d.set_item("voxel_hits", st.voxel_hits)?;
        d.set_item("misses", st.misses)?;
        d.set_item("blend_min", st.blend_min)?;
        d.set_item("blend_max", st.blend_max)?;
        d.set_item("seconds", st.seconds)?;
        Ok((array(py, &[height, width, 3], img.into_data())?, d))
    }

    /// Cells `(k, j, i)` (array axis order: `i` along x) of the non-empty nodes at `level`.
    fn occupancy<'py>(&self, py: Python<'py>, level: i128) -> PyResult<Arr<'py, i64>> {
        let level: u8 = uint(py, "level", level, 0)?;
        if level > self.inner.max_depth {
            return Err(value_error(format!(
                "level {level} exceeds the tree's depth {}",
                self.inner.max_depth
            )));
        }
        let o = &self.inner;
        let data: Vec<i64> = crate::pool::detach(py, || {
            o.occupancy(level)
                .iter()
                .flat_map(|&[i, j, k]| [k, j, i].map(i64::from))
                .collect()
        })?;
        array(py, &[data.len() / 3, 3], data)
    }

    /// Voxel colours (RGB in [0, 1]) and unit normals of every non-empty node, in node order,
    /// with each node's level.
    fn voxels<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Arr<'py, f32>, Arr<'py, f32>, Arr<'py, i64>)> {
        let o = &self.inner;
        let (c, nn, lv) = crate::pool::detach(py, || {
            let levels = o.node_levels();
            let mut lv = Vec::with_capacity(o.voxels.len());
            for (i, n) in o.nodes.iter().enumerate() {
                if !n.is_empty() {
                    lv.push(i64::from(levels[i]));
                }
            }
            let c: Vec<f32> = o.voxels.iter().flat_map(|v| v.color()).collect();
            let nn: Vec<f32> = o.voxels.iter().flat_map(|v| v.normal()).collect();
            (c, nn, lv)
        })?;
        let m = o.voxels.len();
        Ok((
            array(py, &[m, 3], c)?,
            array(py, &[m, 3], nn)?,
            array(py, &[m], lv)?,
        ))
    }

    /// Writes the tree and its mesh to `path`.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        crate::pool::detach(py, || self.inner.save(path)).py_err()
    }

    /// The serialized tree (the file's bytes).
    fn to_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, pyo3::types::PyBytes>> {
        let bytes = crate::pool::detach(py, || self.inner.to_bytes())?;
        Ok(pyo3::types::PyBytes::new(py, &bytes))
    }
}

/// Builds the octree of a mesh.
#[pyfunction]
#[pyo3(signature = (vertices, faces, colors, depth, early_stop, domain))]
fn build_octree<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    colors: Option<&Bound<'py, PyAny>>,
    depth: i128,
    early_stop: bool,
    domain: Option<&Bound<'py, PyAny>>,
) -> PyResult<(PyOctree, Bound<'py, PyDict>)> {
    let mesh = args::colored_mesh(vertices, faces, colors)?;
    let depth: u8 = uint(py, "depth", depth, 0)?;
    let domain = match domain.filter(|d| !d.is_none()) {
        None => None,
        Some(d) => {
            let bad = || value_error("`domain` must be ((x, y, z), side): a corner and a side");
            let parts = d
                .try_iter()
                .map_err(|_| bad())?
                .collect::<PyResult<Vec<_>>>()?;
            let [corner, side] = parts.as_slice() else {
                return Err(bad());
            };
            let side: f64 = side.extract().map_err(|_| bad())?;
            Some(Cube::new(args::triple("domain", corner)?, side).py_err()?)
        }
    };
    let p = BuildParams::default()
        .max_depth(depth)
        .early_stop(early_stop)
        .domain(domain);
    let (oct, st) = crate::pool::detach(py, || build(&mesh, &p)).py_err()?;
    Ok((PyOctree { inner: oct }, stats_dict(py, &st)?))
}

/// Reads a tree saved by `HybridOctree.save`.
#[pyfunction]
fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyOctree> {
    Ok(PyOctree {
        inner: crate::pool::detach(py, || HybridOctree::load(path)).py_err()?,
    })
}

/// A tree from `HybridOctree.to_bytes`.
#[pyfunction]
fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<PyOctree> {
    Ok(PyOctree {
        inner: crate::pool::detach(py, || {
            HybridOctree::from_bytes(data, std::path::Path::new("<bytes>"))
        })
        .py_err()?,
    })
}

/// Exact surface voxelization: every (finest cell, triangle) pair whose closed boxes
/// overlap (separating-axis test), in the cube ``domain = (min_xyz, side)``. Returns integer
/// cells ``(K, 3)`` as ``(k, j, i)`` (array axis order, ``i`` along x; see the module
/// documentation) and triangle indices ``(K,)``, sorted by Morton code then triangle;
/// zero-area triangles produce nothing.
#[pyfunction]
fn voxelize<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    depth: i128,
    domain: ([f64; 3], f64),
) -> PyResult<(Arr<'py, i64>, Arr<'py, i64>)> {
    let mesh = args::mesh(vertices, faces)?;
    let depth = u8::try_from(depth)
        .map_err(|_| value_error(format!("depth must be in 0..=21, got {depth}")))?;
    wscg_octree::cube::check_depth(depth).py_err()?;
    let cube = Cube::new(domain.0, domain.1).py_err()?;
    if let Some((lo, hi)) = mesh.bounding_box() {
        if !cube.contains_box(lo, hi) {
            return Err(value_error("the domain cube does not contain the mesh"));
        }
    }
    let f = crate::pool::detach(py, || {
        wscg_octree::voxelize(&mesh.positions, &mesh.faces, None, &cube, depth)
    })
    .py_err()?;
    let cells = f
        .list
        .iter()
        .flat_map(|x| {
            let [i, j, k] = wscg_octree::cube::demorton(x.morton);
            [k, j, i].map(i64::from)
        })
        .collect();
    let prims = f.list.iter().map(|x| i64::from(x.prim)).collect();
    Ok((
        array(py, &[f.list.len(), 3], cells)?,
        array(py, &[f.list.len()], prims)?,
    ))
}

/// Nearest triangle hits by a binned-SAH BVH (the baseline): ``t`` (inf on a miss) and
/// ``prim`` (-1 on a miss).
#[pyfunction]
fn bvh_intersect<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    faces: &Bound<'py, PyAny>,
    origins: &Bound<'py, PyAny>,
    dirs: &Bound<'py, PyAny>,
) -> PyResult<(Arr<'py, f32>, Arr<'py, i64>)> {
    let mesh = args::mesh(vertices, faces)?;
    let rays = rays_in(origins, dirs)?;
    let bvh = crate::pool::detach(py, || TriangleBvh::build(&mesh)).py_err()?;
    let hits: Vec<_> =
        crate::pool::detach(py, || rays.par_iter().map(|r| bvh.intersect(r)).collect())?;
    let t = hits
        .iter()
        .map(|h| h.map_or(f32::INFINITY, |h| h.1))
        .collect();
    let p = hits
        .iter()
        .map(|h| h.map_or(-1, |h| i64::from(h.0)))
        .collect();
    Ok((array(py, &[hits.len()], t)?, array(py, &[hits.len()], p)?))
}

/// A synthetic scene ``(vertices, faces, colors)``: ``"atrium"`` (``size`` pillars per
/// row, default 10), ``"city"`` (``size x size`` buildings, default 40), ``"blob"``
/// (icosphere subdivisions, default 8: 1,310,720 triangles), ``"forest"`` (13 trees of
/// ``size`` branch levels, default 6: about 1.4 M triangles) or ``"square"`` (the exact
/// case: two triangles at z = 1/3 in the unit cube).
#[pyfunction]
#[pyo3(signature = (name, size=None, seed=3))]
fn make_scene<'py>(
    py: Python<'py>,
    name: &str,
    size: Option<i128>,
    seed: i128,
) -> PyResult<(Arr<'py, f64>, Arr<'py, i64>, Arr<'py, f32>)> {
    let default = match name {
        "atrium" => 10,
        "city" => 40,
        "blob" => 8,
        "forest" => 6,
        "square" => 0,
        other => {
            return Err(value_error(format!(
                "`name`: scene {other:?} is not valid; valid: atrium, city, blob, forest, square"
            )))
        }
    };
    let size = size.unwrap_or(default);
    if size < 0 {
        return Err(value_error(format!("size must be >= 0, got {size}")));
    }
    let size: usize = uint(py, "size", size, 0)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    match name {
        "blob" if size > 9 => {
            return Err(value_error(format!(
                "blob subdivisions must be at most 9, got {size}"
            )))
        }
        "forest" if size > 7 => {
            return Err(value_error(format!(
                "forest branch levels must be at most 7, got {size}"
            )))
        }
        _ => {}
    }
    let mesh = crate::pool::detach(py, || match name {
        "atrium" => scenes::atrium(size.max(2)),
        "city" => scenes::city(size.max(1), seed),
        "blob" => scenes::blob(size as u32),
        "forest" => scenes::forest(13, size, 64, seed),
        _ => scenes::exact_square().map(|(m, _)| m),
    })
    .py_err()?;
    let v = mesh.positions.iter().flatten().copied().collect();
    let f = mesh.faces.iter().flatten().map(|&i| i64::from(i)).collect();
    let colors = mesh
        .colors
        .clone()
        .unwrap_or_else(|| vec![[0.8; 3]; mesh.positions.len()]);
    let c = colors.iter().flatten().copied().collect();
    let (nv, nf) = (mesh.positions.len(), mesh.faces.len());
    Ok((
        array(py, &[nv, 3], v)?,
        array(py, &[nf, 3], f)?,
        array(py, &[nv, 3], c)?,
    ))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyOctree>()?;
    m.add_function(wrap_pyfunction!(build_octree, m)?)?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(from_bytes, m)?)?;
    m.add_function(wrap_pyfunction!(voxelize, m)?)?;
    m.add_function(wrap_pyfunction!(bvh_intersect, m)?)?;
    m.add_function(wrap_pyfunction!(make_scene, m)?)
}
