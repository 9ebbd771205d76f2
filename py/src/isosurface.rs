//! `wscg.isosurface`'s functions (paper 09, sparse-grid marching cubes with
//! tetrahedral-spline normals): bindings of `wscg-isosurface`. Those whose Python layer would
//! only convert and check their arguments (`sparsify`, `random_dropouts`, `angular_errors`,
//! `rotation_class`, `at_risk_configurations`, the `fields` functions) are called directly,
//! re-exported by `python/wscg/isosurface.py` (which holds the module's documentation); the
//! others return the dicts from which the Python layer builds its result classes. Arguments
//! are converted and checked by [`crate::args`]: array-likes of any real dtype (a float64
//! volume is processed in double precision, anything else in single precision), counts and
//! seeds as Python ints.

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

use crate::args::{self, uint, Floats};
use crate::convert::{array, choice, rows3, values, Arr};
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

/// The normal estimator `normals` (`None`: no normals) with its options: the spline's
/// `selection`, `eq8_literal` and `normalize_before_mean`, LSN's `ambiguous_face` (each read
/// by the estimator it belongs to).
fn method_from(
    normals: Option<&str>,
    selection: &str,
    eq8_literal: bool,
    normalize_before_mean: bool,
    ambiguous_face: &str,
) -> PyResult<NormalMethod> {
    let Some(name) = normals else {
        return Ok(NormalMethod::None);
    };
    let kinds = [("spline", 's'), ("lsn", 'l'), ("central", 'c')];
    Ok(match choice("normals", name, &kinds)? {
        's' => NormalMethod::Spline(
            SplineParams::default()
                .selection(choice(
                    "selection",
                    selection,
                    &[
                        ("mesh", TetSelection::MeshAware),
                        ("nearest", TetSelection::NearestCorner),
                        ("both", TetSelection::AverageBoth),
                    ],
                )?)
                .eq8_literal(eq8_literal)
                .normalize_before_mean(normalize_before_mean),
        ),
        'l' => NormalMethod::Lsn(LsnParams::default().ambiguous_face(rule_from(ambiguous_face)?)),
        _ => NormalMethod::CentralDifference,
    })
}

fn rule_from(name: &str) -> PyResult<AmbiguousRule> {
    choice(
        "ambiguous_face",
        name,
        &[
            ("inside", AmbiguousRule::IsolateInside),
            ("outside", AmbiguousRule::IsolateOutside),
        ],
    )
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

/// The `volume` argument: a `[z, y, x]` array of float64 or float32 samples (anything else
/// converted to float32); the extraction, the normals and the returned arrays keep its type.
fn samples<'py>(volume: &Bound<'py, PyAny>) -> PyResult<Floats<'py>> {
    let v = args::floats("volume", volume)?;
    dims_of(v.shape())?;
    Ok(v)
}

/// Runs `$body` with `$v` bound to the volume's typed array, whichever its sample type.
macro_rules! with_samples {
    ($volume:expr, $v:ident => $body:expr) => {
        match $volume {
            Floats::F64($v) => $body,
            Floats::F32($v) => $body,
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
fn spacing3<T: Sample>(spacing: [f64; 3]) -> [T; 3] {
    [spacing[2], spacing[1], spacing[0]].map(T::from_f64)
}

/// The volume's dims, spacing `(dz, dy, dx)`, normal method and packed side hints of a call.
struct Prepared {
    dims: [usize; 3],
    spacing: [f64; 3],
    method: NormalMethod,
    bits: Option<Vec<u8>>,
}

/// The arguments of `marching_cubes` and `estimate_normals` after the volume (see
/// `wscg.isosurface.marching_cubes`), converted and checked.
struct Estimator<'py> {
    spacing: Bound<'py, PyAny>,
    normals: Option<String>,
    side_hint: Option<Bound<'py, PyAny>>,
    selection: String,
    eq8_literal: bool,
    normalize_before_mean: bool,
    ambiguous_face: String,
}

impl Estimator<'_> {
    fn prepare(&self, shape: &[usize]) -> PyResult<Prepared> {
        let method = method_from(
            self.normals.as_deref(),
            &self.selection,
            self.eq8_literal,
            self.normalize_before_mean,
            &self.ambiguous_face,
        )?;
        let bits = match self.side_hint.as_ref().filter(|s| !s.is_none()) {
            Some(s) => Some(pack_sides(&args::array::<bool>("side_hint", s)?, shape)?),
            None => None,
        };
        Ok(Prepared {
            dims: dims_of(shape)?,
            spacing: args::triple("spacing", &self.spacing)?,
            method,
            bits,
        })
    }
}

impl Prepared {
    fn grid<'a, T: Sample>(&'a self, values: &'a [T]) -> PyResult<ScalarGrid<'a, T>> {
        let g = ScalarGrid::with_spacing(self.dims, spacing3(self.spacing), values).py_err()?;
        match &self.bits {
            Some(b) => g.with_side_hint(b).py_err(),
            None => Ok(g),
        }
    }
}

/// Moves the mesh's vertices by `o` `(x, y, z)` (rounded to the sample type).
fn shift<T: Sample>(mesh: &mut IsoMesh<T>, o: [f64; 3]) {
    if o != [0.0; 3] {
        let o = o.map(T::from_f64);
        for v in &mut mesh.vertices {
            *v = std::array::from_fn(|a| v[a] + o[a]);
        }
    }
}

/// Marching cubes with normals (see `wscg.isosurface.marching_cubes`, which builds the
/// `MeshInfo` from the dict), in the volume's sample type, vertices shifted by `origin`
/// `(oz, oy, ox)`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn marching_cubes<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    level: f64,
    spacing: Bound<'py, PyAny>,
    normals: Option<String>,
    side_hint: Option<Bound<'py, PyAny>>,
    selection: String,
    eq8_literal: bool,
    normalize_before_mean: bool,
    ambiguous_face: String,
    origin: &Bound<'py, PyAny>,
) -> PyResult<MeshOut<'py>> {
    let volume = samples(volume)?;
    let e = Estimator {
        spacing,
        normals,
        side_hint,
        selection,
        eq8_literal,
        normalize_before_mean,
        ambiguous_face,
    };
    let p = e.prepare(volume.shape())?;
    let [oz, oy, ox] = args::finite3("origin", args::triple("origin", origin)?)?;
    with_samples!(volume, vol => {
        let v = values(&vol);
        let g = p.grid(&v)?;
        let (method, level) = (p.method, Real::from_f64(level));
        let mut mesh =
            crate::pool::detach(py, || wscg_isosurface::marching_cubes(&g, level, method))
                .py_err()?;
        shift(&mut mesh, [ox, oy, oz]);
        mesh_out(py, mesh)
    })
}

/// Normals of given mesh edges (see `wscg.isosurface.estimate_normals`, which builds the
/// `NormalStats` from the dict), in the volume's sample type.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn estimate_normals<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    level: f64,
    edges: &Bound<'py, PyAny>,
    spacing: Bound<'py, PyAny>,
    normals: String,
    side_hint: Option<Bound<'py, PyAny>>,
    selection: String,
    eq8_literal: bool,
    normalize_before_mean: bool,
    ambiguous_face: String,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let volume = samples(volume)?;
    let e = Estimator {
        spacing,
        normals: Some(normals),
        side_hint,
        selection,
        eq8_literal,
        normalize_before_mean,
        ambiguous_face,
    };
    let p = e.prepare(volume.shape())?;
    let e = edges_in(&args::array::<i64>("edges", edges)?)?;
    with_samples!(volume, vol => {
        let v = values(&vol);
        let g = p.grid(&v)?;
        let (method, level) = (p.method, Real::from_f64(level));
        let (n, stats) = crate::pool::detach(py, || {
            wscg_isosurface::estimate_normals(&g, level, &e, method)
        })
        .py_err()?;
        let len = n.len();
        Ok((array(py, &[len, 3], n.concat())?.into_any(), stats_dict(py, &stats)?))
    })
}

/// The paper's sparsification protocol (section 5): keeps only the samples that are
/// endpoints of edges crossing ``level`` and sets the others to NaN. Returns
/// ``(sparse_volume, inside)`` where ``inside`` is the boolean side of every original sample
/// (pass it as ``side_hint``); the sparse volume is float64 for float64 input, float32
/// otherwise. The input is not modified.
#[pyfunction]
fn sparsify<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    level: f64,
) -> PyResult<(Bound<'py, PyAny>, Arr<'py, bool>)> {
    let volume = samples(volume)?;
    let shape = volume.shape().to_vec();
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

/// A copy of ``volume`` with a fraction ``rate`` of the samples set to NaN, uniformly at
/// random (seeded): simulated sensor failures.
#[pyfunction]
#[pyo3(signature = (volume, rate, seed=0))]
fn random_dropouts<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyAny>,
    rate: f64,
    seed: i128,
) -> PyResult<Bound<'py, PyAny>> {
    let volume = samples(volume)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    with_samples!(volume, vol => {
        let shape = vol.shape().to_vec();
        let mut v = values(&vol).into_owned();
        crate::pool::detach(py, || wscg_isosurface::random_dropouts(&mut v, rate, seed))
            .py_err()?;
        Ok(array(py, &shape, v)?.into_any())
    })
}

/// Rows of `(n, 3)` float32 normals.
type Normals = Vec<[f32; 3]>;

/// The `(n, 3)` normal arrays `a` and `b` (any real array-likes) as float32 rows.
fn normal_pairs(a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<(Normals, Normals)> {
    let (a, b) = (args::array::<f32>("a", a)?, args::array::<f32>("b", b)?);
    Ok((
        rows3("a", &values(&a), a.shape())?,
        rows3("b", &values(&b), b.shape())?,
    ))
}

/// Angles in radians between matching rows of two (n, 3) normal arrays; NaN where either
/// row is zero (an undefined normal).
#[pyfunction]
fn angular_errors<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Arr<'py, f32>> {
    let (x, y) = normal_pairs(a, b)?;
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

/// RMS angular error (see `wscg.isosurface.angular_rms`, which names the fields): (rms,
/// count, undefined).
#[pyfunction]
fn angular_rms(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
) -> PyResult<(f64, usize, usize)> {
    let (x, y) = normal_pairs(a, b)?;
    let r = crate::pool::detach(py, || {
        wscg_isosurface::angular_errors(&x, &y).map(|e| wscg_isosurface::rms(&e))
    })
    .py_err()?;
    Ok((r.rms, r.count, r.undefined))
}

/// Class (0..22) of an 8-bit cell configuration under the 24 cube rotations (section
/// 5.3). Bit c is corner (c & 1, c >> 1 & 1, c >> 2) (x, y, z offsets).
#[pyfunction]
fn rotation_class(config: i128) -> PyResult<u8> {
    let c = u8::try_from(config)
        .map_err(|_| value_error(format!("`config` must be in 0..255, got {config}")))?;
    Ok(wscg_isosurface::mc_rotation_class(c))
}

/// The Table 4 enumeration: configurations (corner values +-1, replicate padding) where an
/// LSN normal of the central cell diverges by at least ``threshold`` radians from central
/// differences.
#[pyfunction]
#[pyo3(name = "at_risk_configurations",
       signature = (threshold=std::f64::consts::FRAC_PI_2, ambiguous_face="inside"))]
fn at_risk(py: Python<'_>, threshold: f64, ambiguous_face: &str) -> PyResult<Vec<u16>> {
    let threshold = args::number("threshold", threshold)? as f32;
    let rule = rule_from(ambiguous_face)?;
    // A list of ints (a `Vec<u8>` would become `bytes`).
    let c = crate::pool::detach(py, || at_risk_configurations(rule, threshold))?;
    Ok(c.into_iter().map(u16::from).collect())
}

type SampledOut<'py> = (Arr<'py, f32>, (f32, f32, f32), (f64, f64, f64));

/// ``(volume [z, y, x] float32, spacing (dz, dy, dx), origin (oz, oy, ox))`` of a
/// named field on ``n^3`` samples over its domain: the sample ``[k, j, i]`` is the
/// field at ``(ox + i dx, oy + j dy, oz + k dz)``. Pass ``spacing`` and ``origin`` to
/// :func:`marching_cubes` to get vertices in the field's coordinates.
#[pyfunction]
#[pyo3(signature = (name, n=64))]
fn sample<'py>(py: Python<'py>, name: &str, n: i128) -> PyResult<SampledOut<'py>> {
    let n: usize = uint(py, "n", n, 0)?;
    let s = crate::pool::detach(py, || fields::named(name, n).map(|(_, s)| s)).py_err()?;
    let [nx, ny, nz] = s.dims;
    Ok((
        array(py, &[nz, ny, nx], s.values)?,
        (s.spacing[2], s.spacing[1], s.spacing[0]),
        (s.origin[2], s.origin[1], s.origin[0]),
    ))
}

/// Exact unit normals of the named field (sampled as by :meth:`sample` with the same
/// ``n``) at world points ``(x, y, z)``: the vertices :func:`marching_cubes` returns with
/// the field's ``spacing`` and ``origin``.
#[pyfunction]
fn exact_normals<'py>(
    py: Python<'py>,
    name: &str,
    n: i128,
    vertices: &Bound<'py, PyAny>,
) -> PyResult<Arr<'py, f32>> {
    let n: usize = uint(py, "n", n, 0)?;
    let vertices = args::array::<f32>("vertices", vertices)?;
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

/// An 8-bit-like noisy ball: ``round(255 / (1 + exp((r - radius) / width)) +
/// N(0, noise))`` clamped to [0, 255], float32 holding integers.
#[pyfunction]
#[pyo3(signature = (n=64, radius=20.0, width=1.5, noise=3.0, seed=0))]
fn make_noisy_sphere<'py>(
    py: Python<'py>,
    n: i128,
    radius: f64,
    width: f64,
    noise: f64,
    seed: i128,
) -> PyResult<Arr<'py, f32>> {
    let n: usize = uint(py, "n", n, 0)?;
    let seed: u64 = uint(py, "seed", seed, 0)?;
    let radius = args::number("radius", radius)?;
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
    volume: &Bound<'py, PyAny>,
    level: f32,
    spacing: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let volume = args::array::<f32>("volume", volume)?;
    let dims = dims_of(volume.shape())?;
    let [dz, dy, dx] = args::triple("spacing", spacing)?;
    let v = values(&volume);
    let c = crate::pool::detach(py, || {
        // In single precision, as the samples.
        let spacing = [dx, dy, dz].map(|d| f64::from(d as f32));
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
fn study_exact<'py>(py: Python<'py>, name: &str, n: i128) -> PyResult<Bound<'py, PyDict>> {
    let n: usize = uint(py, "n", n, 0)?;
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

/// Registers the submodule's functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(marching_cubes, m)?)?;
    m.add_function(wrap_pyfunction!(estimate_normals, m)?)?;
    m.add_function(wrap_pyfunction!(sparsify, m)?)?;
    m.add_function(wrap_pyfunction!(random_dropouts, m)?)?;
    m.add_function(wrap_pyfunction!(angular_errors, m)?)?;
    m.add_function(wrap_pyfunction!(angular_rms, m)?)?;
    m.add_function(wrap_pyfunction!(rotation_class, m)?)?;
    m.add_function(wrap_pyfunction!(at_risk, m)?)?;
    m.add_function(wrap_pyfunction!(sample, m)?)?;
    m.add_function(wrap_pyfunction!(exact_normals, m)?)?;
    m.add_function(wrap_pyfunction!(make_noisy_sphere, m)?)?;
    m.add_function(wrap_pyfunction!(study_full_cd, m)?)?;
    m.add_function(wrap_pyfunction!(study_exact, m)?)?;
    Ok(())
}
