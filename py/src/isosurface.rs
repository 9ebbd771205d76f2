//! `wscg._native.isosurface`: bindings of `wscg-isosurface` (paper 09, sparse-grid marching
//! cubes with tetrahedral-spline normals). The documented API is `python/wscg/isosurface.py`.

use numpy::{Element, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use wscg_isosurface::fields;
use wscg_isosurface::study::{at_risk_configurations, compare_with_exact, compare_with_full_cd};
use wscg_isosurface::{
    AmbiguousRule, EdgeId, IsoMesh, LsnParams, NormalMethod, NormalStats, RmsSummary, Sample,
    ScalarGrid, SplineParams, TetSelection,
};
use wscg_math::volume::Real;
use wscg_math::VolumeView;

use crate::convert::{array, dict_item, rows3, values, Arr};
use crate::errors::{value_error, IntoPy};

/// `(nx, ny, nz)` of a `[z, y, x]` volume.
fn dims_of(shape: &[usize]) -> PyResult<[usize; 3]> {
    match *shape {
        [z, y, x] => Ok([x, y, z]),
        _ => Err(value_error(format!(
            "`volume` must be a 3-D array indexed [z, y, x], got shape {shape:?}"
        ))),
    }
}

/// Packs a boolean side array into the bit layout of `ScalarGrid::side_hint`.
fn pack_sides(sides: &PyReadonlyArrayDyn<bool>, shape: &[usize]) -> PyResult<Vec<u8>> {
    if sides.shape() != shape {
        return Err(value_error(format!(
            "`side_hint` has shape {:?} but the volume has shape {shape:?}",
            sides.shape()
        )));
    }
    let v = values(sides);
    let bits = crate::pool::detach(sides.py(), || {
        v.par_chunks(8)
            .map(|c| {
                c.iter()
                    .enumerate()
                    .fold(0u8, |acc, (i, &b)| acc | (u8::from(b) << i))
            })
            .collect()
    })?;
    Ok(bits)
}

/// The normal method named `name` with the estimator options of `options` (keys
/// `selection`, `eq8_literal`, `normalize_before_mean`, `ambiguous_face`; absent keys take
/// the defaults).
fn method_from(name: &str, options: &Bound<'_, PyDict>) -> PyResult<NormalMethod> {
    let m = NormalMethod::parse(name).py_err()?;
    Ok(match m {
        NormalMethod::Spline(_) => NormalMethod::Spline(
            SplineParams::default()
                .selection(
                    match dict_item::<String>(options, "selection")?.as_deref() {
                        None | Some("mesh") => TetSelection::MeshAware,
                        Some("nearest") => TetSelection::NearestCorner,
                        Some("both") => TetSelection::AverageBoth,
                        Some(other) => {
                            return Err(value_error(format!(
                                "selection {other:?} is not valid; valid: mesh, nearest, both"
                            )))
                        }
                    },
                )
                .eq8_literal(dict_item(options, "eq8_literal")?.unwrap_or(false))
                .normalize_before_mean(
                    dict_item(options, "normalize_before_mean")?.unwrap_or(false),
                ),
        ),
        NormalMethod::Lsn(_) => NormalMethod::Lsn(
            LsnParams::default().ambiguous_face(rule_from(
                dict_item::<String>(options, "ambiguous_face")?
                    .as_deref()
                    .unwrap_or("inside"),
            )?),
        ),
        other => other,
    })
}

fn rule_from(name: &str) -> PyResult<AmbiguousRule> {
    match name {
        "inside" => Ok(AmbiguousRule::IsolateInside),
        "outside" => Ok(AmbiguousRule::IsolateOutside),
        other => Err(value_error(format!(
            "ambiguous_face {other:?} is not valid; valid: inside, outside"
        ))),
    }
}

fn stats_dict<'py>(py: Python<'py>, s: &NormalStats) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("undefined", s.undefined)?;
    d.set_item("fallback", s.fallback)?;
    d.set_item("skipped_cells", s.skipped_cells)?;
    Ok(d)
}

/// Grid edges as `(n, 4)` rows `(k, j, i, a)`: the array index `[k, j, i]` of the edge's low
/// end and the array axis `a` it runs along (0: z, 1: y, 2: x), the order of `py/API.md`.
fn edges_out<'py>(py: Python<'py>, e: &[EdgeId]) -> PyResult<Arr<'py, i64>> {
    let data = crate::pool::detach(py, || {
        e.par_iter()
            .flat_map_iter(|e| {
                [
                    e.point[2] as i64,
                    e.point[1] as i64,
                    e.point[0] as i64,
                    2 - e.axis as i64,
                ]
            })
            .collect()
    })?;
    array(py, &[e.len(), 4], data)
}

/// Grid edges from `(n, 4)` rows `(k, j, i, a)` (see [`edges_out`]).
fn edges_in(a: &PyReadonlyArrayDyn<i64>) -> PyResult<Vec<EdgeId>> {
    let s = a.shape();
    if s.len() != 2 || s[1] != 4 {
        return Err(value_error(format!(
            "`edges` must be an (n, 4) integer array (k, j, i, axis), got shape {s:?}"
        )));
    }
    values(a)
        .chunks_exact(4)
        .map(|r| {
            if r.iter().any(|&v| v < 0 || v > u32::MAX as i64) || r[3] > 2 {
                return Err(value_error(format!("invalid edge {r:?}")));
            }
            Ok(EdgeId {
                point: [r[2] as u32, r[1] as u32, r[0] as u32],
                axis: 2 - r[3] as u8,
            })
        })
        .collect()
}

/// A `[z, y, x]` volume of float64 or float32 samples: the extraction, the normals and the
/// returned arrays keep its type.
#[derive(FromPyObject)]
enum Samples<'py> {
    F64(PyReadonlyArrayDyn<'py, f64>),
    F32(PyReadonlyArrayDyn<'py, f32>),
}

/// Runs `$body` with `$v` bound to the volume's typed array, whichever its sample type.
macro_rules! with_samples {
    ($volume:expr, $v:ident => $body:expr) => {
        match $volume {
            Samples::F64($v) => $body,
            Samples::F32($v) => $body,
        }
    };
}

type MeshOut<'py> = (
    Bound<'py, PyAny>,
    Arr<'py, i64>,
    Bound<'py, PyAny>,
    Bound<'py, PyDict>,
);

fn mesh_out<'py, T: Element + Copy>(py: Python<'py>, m: IsoMesh<T>) -> PyResult<MeshOut<'py>> {
    let info = stats_dict(py, &m.stats)?;
    info.set_item("edges", edges_out(py, &m.vertex_edge)?)?;
    let cells: Vec<i64> = m
        .cell_config
        .iter()
        .flat_map(|&(c, k)| [c as i64, k as i64])
        .collect();
    info.set_item("cells", array(py, &[m.cell_config.len(), 2], cells)?)?;
    let (nv, nt, nn) = (m.vertices.len(), m.triangles.len(), m.normals.len());
    let faces = crate::pool::detach(py, || {
        m.triangles
            .par_iter()
            .flat_map_iter(|t| t.map(|i| i as i64))
            .collect()
    })?;
    Ok((
        array(py, &[nv, 3], m.vertices.concat())?.into_any(),
        array(py, &[nt, 3], faces)?,
        array(py, &[nn, 3], m.normals.concat())?.into_any(),
        info,
    ))
}

/// Python spacing `(dz, dy, dx)` (array axis order) as the grid's `[sx, sy, sz]`, rounded to
/// the sample type.
fn spacing3<T: Sample>(spacing: (f64, f64, f64)) -> [T; 3] {
    [spacing.2, spacing.1, spacing.0].map(T::from_f64)
}

/// The volume's dims, the normal method and the packed side hints of a call.
struct Prepared {
    dims: [usize; 3],
    method: NormalMethod,
    bits: Option<Vec<u8>>,
}

fn prepare(
    shape: &[usize],
    normals: &str,
    side_hint: Option<PyReadonlyArrayDyn<bool>>,
    options: &Bound<'_, PyDict>,
) -> PyResult<Prepared> {
    Ok(Prepared {
        dims: dims_of(shape)?,
        method: method_from(normals, options)?,
        bits: side_hint.map(|s| pack_sides(&s, shape)).transpose()?,
    })
}

impl Prepared {
    fn grid<'a, T: Sample>(
        &'a self,
        values: &'a [T],
        spacing: (f64, f64, f64),
    ) -> PyResult<ScalarGrid<'a, T>> {
        let g = ScalarGrid::with_spacing(self.dims, spacing3(spacing), values).py_err()?;
        match &self.bits {
            Some(b) => g.with_side_hint(b).py_err(),
            None => Ok(g),
        }
    }
}

/// Marching cubes with normals (see `wscg.isosurface.marching_cubes`), in the volume's
/// sample type.
#[pyfunction]
fn marching_cubes<'py>(
    py: Python<'py>,
    volume: Samples<'py>,
    level: f64,
    spacing: (f64, f64, f64),
    normals: &str,
    side_hint: Option<PyReadonlyArrayDyn<bool>>,
    options: Bound<'py, PyDict>,
) -> PyResult<MeshOut<'py>> {
    let p = prepare(volume_shape(&volume), normals, side_hint, &options)?;
    with_samples!(volume, vol => {
        let v = values(&vol);
        let g = p.grid(&v, spacing)?;
        let (method, level) = (p.method, Real::from_f64(level));
        let mesh = crate::pool::detach(py, || wscg_isosurface::marching_cubes(&g, level, method))
            .py_err()?;
        mesh_out(py, mesh)
    })
}

/// The shape of a volume of either sample type.
fn volume_shape<'a>(volume: &'a Samples<'_>) -> &'a [usize] {
    with_samples!(volume, v => v.shape())
}

/// Normals of given mesh edges (see `wscg.isosurface.estimate_normals`), in the volume's
/// sample type.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn estimate_normals<'py>(
    py: Python<'py>,
    volume: Samples<'py>,
    level: f64,
    edges: PyReadonlyArrayDyn<i64>,
    spacing: (f64, f64, f64),
    normals: &str,
    side_hint: Option<PyReadonlyArrayDyn<bool>>,
    options: Bound<'py, PyDict>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let p = prepare(volume_shape(&volume), normals, side_hint, &options)?;
    let e = edges_in(&edges)?;
    with_samples!(volume, vol => {
        let v = values(&vol);
        let g = p.grid(&v, spacing)?;
        let (method, level) = (p.method, Real::from_f64(level));
        let (n, stats) = crate::pool::detach(py, || {
            wscg_isosurface::estimate_normals(&g, level, &e, method)
        })
        .py_err()?;
        let len = n.len();
        Ok((array(py, &[len, 3], n.concat())?.into_any(), stats_dict(py, &stats)?))
    })
}

/// The paper's sparsification (see `wscg.isosurface.sparsify`).
#[pyfunction]
fn sparsify<'py>(
    py: Python<'py>,
    volume: Samples<'py>,
    level: f64,
) -> PyResult<(Bound<'py, PyAny>, Arr<'py, bool>)> {
    let shape = volume_shape(&volume).to_vec();
    let dims = dims_of(&shape)?;
    with_samples!(volume, vol => {
        let v = values(&vol);
        let level = Real::from_f64(level);
        let (sparse, bits) = crate::pool::detach(py, || {
            wscg_isosurface::sparsify_for_isosurface(VolumeView::new(dims, [1.0; 3], &v)?, level)
        })
        .py_err()?;
        let sparse = sparse.into_data();
        let sides: Vec<bool> = (0..v.len())
            .map(|i| bits[i / 8] >> (i % 8) & 1 == 1)
            .collect();
        Ok((array(py, &shape, sparse)?.into_any(), array(py, &shape, sides)?))
    })
}

/// Random dropouts (see `wscg.isosurface.random_dropouts`).
#[pyfunction]
fn random_dropouts<'py>(
    py: Python<'py>,
    volume: Samples<'py>,
    rate: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyAny>> {
    with_samples!(volume, vol => {
        let shape = vol.shape().to_vec();
        let mut v = values(&vol).into_owned();
        crate::pool::detach(py, || wscg_isosurface::random_dropouts(&mut v, rate, seed))
            .py_err()?;
        Ok(array(py, &shape, v)?.into_any())
    })
}

/// Angular errors in radians (NaN where undefined).
#[pyfunction]
fn angular_errors<'py>(
    py: Python<'py>,
    a: PyReadonlyArrayDyn<f32>,
    b: PyReadonlyArrayDyn<f32>,
) -> PyResult<Arr<'py, f32>> {
    let x = rows3("a", &values(&a), a.shape())?;
    let y = rows3("b", &values(&b), b.shape())?;
    let e = crate::pool::detach(py, || wscg_isosurface::angular_errors(&x, &y)).py_err()?;
    let n = e.len();
    array(py, &[n], e)
}

fn rms_dict<'py>(py: Python<'py>, r: &RmsSummary) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("rms", r.rms)?;
    d.set_item("count", r.count)?;
    d.set_item("undefined", r.undefined)?;
    Ok(d)
}

/// RMS angular error (see `wscg.isosurface.angular_rms`): (rms, count, undefined).
#[pyfunction]
fn angular_rms(
    py: Python<'_>,
    a: PyReadonlyArrayDyn<f32>,
    b: PyReadonlyArrayDyn<f32>,
) -> PyResult<(f64, usize, usize)> {
    let x = rows3("a", &values(&a), a.shape())?;
    let y = rows3("b", &values(&b), b.shape())?;
    let r = crate::pool::detach(py, || {
        wscg_isosurface::angular_errors(&x, &y).map(|e| wscg_isosurface::rms(&e))
    })
    .py_err()?;
    Ok((r.rms, r.count, r.undefined))
}

/// Rotation class of a configuration (0..23).
#[pyfunction]
fn rotation_class(config: u8) -> u8 {
    wscg_isosurface::mc_rotation_class(config)
}

/// The Table 4 enumeration.
#[pyfunction]
fn at_risk(py: Python<'_>, ambiguous_face: &str, threshold: f32) -> PyResult<Vec<u8>> {
    let rule = rule_from(ambiguous_face)?;
    crate::pool::detach(py, || at_risk_configurations(rule, threshold))
}

type SampledOut<'py> = (Arr<'py, f32>, (f32, f32, f32), (f64, f64, f64));

/// A named analytic field on an n^3 grid: (volume [z, y, x], spacing (dz, dy, dx), origin
/// (oz, oy, ox)), both in array axis order: sample `[k, j, i]` lies at the field point
/// `(ox + i dx, oy + j dy, oz + k dz)`.
#[pyfunction]
fn sample_field<'py>(py: Python<'py>, name: &str, n: usize) -> PyResult<SampledOut<'py>> {
    let s = crate::pool::detach(py, || fields::named(name, n).map(|(_, s)| s)).py_err()?;
    let [nx, ny, nz] = s.dims;
    Ok((
        array(py, &[nz, ny, nx], s.values)?,
        (s.spacing[2], s.spacing[1], s.spacing[0]),
        (s.origin[2], s.origin[1], s.origin[0]),
    ))
}

/// Exact unit normals of a named field at world points `(x, y, z)` (the field's own
/// coordinates, origin included: where `marching_cubes` with the field's spacing and origin
/// puts its vertices).
#[pyfunction]
fn field_normals<'py>(
    py: Python<'py>,
    name: &str,
    n: usize,
    vertices: PyReadonlyArrayDyn<f32>,
) -> PyResult<Arr<'py, f32>> {
    let v = rows3("vertices", &values(&vertices), vertices.shape())?;
    let out = crate::pool::detach(py, || {
        fields::named(name, n).map(|(f, s)| {
            // `exact_normals` takes points relative to the grid's first sample.
            let rel: Vec<[f32; 3]> = v
                .iter()
                .map(|p| std::array::from_fn(|a| (p[a] as f64 - s.origin[a]) as f32))
                .collect();
            s.exact_normals(f.as_ref(), &rel)
        })
    })
    .py_err()?;
    let len = out.len();
    array(py, &[len, 3], out.concat())
}

/// The noisy 8-bit sphere stand-in.
#[pyfunction]
fn noisy_sphere<'py>(
    py: Python<'py>,
    n: usize,
    radius: f64,
    width: f64,
    noise: f64,
    seed: u64,
) -> PyResult<Arr<'py, f32>> {
    let centre = fields::grid_centre(n);
    let s = crate::pool::detach(py, || {
        fields::noisy_sphere_u8([n; 3], centre, radius, width, noise, seed)
    })
    .py_err()?;
    array(py, &[n, n, n], s.values)
}

/// Table 1/2 protocol at one isovalue.
#[pyfunction]
fn study_full_cd<'py>(
    py: Python<'py>,
    volume: PyReadonlyArrayDyn<f32>,
    level: f32,
    spacing: (f32, f32, f32),
) -> PyResult<Bound<'py, PyDict>> {
    let dims = dims_of(volume.shape())?;
    let v = values(&volume);
    let c = crate::pool::detach(py, || {
        let spacing = [spacing.2, spacing.1, spacing.0].map(f64::from);
        compare_with_full_cd(VolumeView::new(dims, spacing, &v)?, level)
    })
    .py_err()?;
    let d = PyDict::new(py);
    d.set_item("vertices", c.vertices)?;
    d.set_item("triangles", c.triangles)?;
    d.set_item("kept_fraction", c.kept_fraction)?;
    d.set_item("cd_defined_on_sparse", c.cd_defined_on_sparse)?;
    d.set_item("reference_undefined", c.reference_undefined)?;
    d.set_item("spline", rms_dict(py, &c.spline)?)?;
    d.set_item("lsn", rms_dict(py, &c.lsn)?)?;
    d.set_item("spline_undefined", c.spline_undefined)?;
    d.set_item("lsn_undefined", c.lsn_undefined)?;
    Ok(d)
}

/// Table 3 protocol on a named field.
#[pyfunction]
fn study_exact<'py>(py: Python<'py>, name: &str, n: usize) -> PyResult<Bound<'py, PyDict>> {
    let (iso, c) = crate::pool::detach(py, || -> wscg_math::Result<_> {
        let (f, s) = fields::named(name, n)?;
        let iso = f.iso() as f32;
        Ok((iso, compare_with_exact(f.as_ref(), &s, iso)?))
    })
    .py_err()?;
    let d = PyDict::new(py);
    d.set_item("vertices", c.vertices)?;
    d.set_item("central", rms_dict(py, &c.cd_full)?)?;
    d.set_item("spline", rms_dict(py, &c.spline)?)?;
    d.set_item("lsn", rms_dict(py, &c.lsn)?)?;
    d.set_item("level", iso)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(marching_cubes, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_normals, m)?)?;
    m.add_function(wrap_pyfunction!(sparsify, m)?)?;
    m.add_function(wrap_pyfunction!(random_dropouts, m)?)?;
    m.add_function(wrap_pyfunction!(angular_errors, m)?)?;
    m.add_function(wrap_pyfunction!(angular_rms, m)?)?;
    m.add_function(wrap_pyfunction!(rotation_class, m)?)?;
    m.add_function(wrap_pyfunction!(at_risk, m)?)?;
    m.add_function(wrap_pyfunction!(sample_field, m)?)?;
    m.add_function(wrap_pyfunction!(field_normals, m)?)?;
    m.add_function(wrap_pyfunction!(noisy_sphere, m)?)?;
    m.add_function(wrap_pyfunction!(study_full_cd, m)?)?;
    m.add_function(wrap_pyfunction!(study_exact, m)?)?;
    Ok(())
}
